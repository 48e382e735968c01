/*
** Reading volume meshes for bodies (body.h) with Gmsh's library, and meshing a box with it.
*/
#ifndef CF_MESH_H
#define CF_MESH_H

#include "conifit/error.h"
#include "io/surface_types.h"
#include "model/body.h"

/* What Gmsh may spend. Every use of Gmsh runs in a process of its own (io/isolate.h): a mesh
** that makes Gmsh loop, exhaust memory or crash ends in an error, never in a hang or an abort of
** the caller, and the caller's end by a signal ends it too. Before Gmsh starts, the mesh's size is
** estimated (a file's after refinement from its element count, a surface's fill from the volume it
** encloses) and refused when Gmsh's memory for it, or node_bytes for each of its nodes, would pass
** max_bytes. */
typedef struct cf_mesh_limits {
    double max_bytes;   /* memory: Gmsh's process (beyond what the caller maps) and the estimate */
    double max_seconds; /* wall time of Gmsh's process */
    double node_bytes;  /* what the caller will spend for each node of the mesh (0: nothing) */
} cf_mesh_limits;

#define CF_MESH_MAX_BYTES_DEFAULT (2.0 * 1024 * 1024 * 1024) /* 2 GiB */
#define CF_MESH_MAX_SECONDS_DEFAULT 600.0

/* The default limits: 2 GiB, 600 s, no cost per node. */
cf_mesh_limits cf_mesh_limits_default(void);

/* Reads the volume mesh at path (Gmsh's mesh formats: .msh of every version, .mesh, .vtk, .unv,
** .bdf, .nas; a name with another ending is refused, since Gmsh would run it as a script) into m: its
** tetrahedra, and each hexahedron as six tetrahedra; higher-order elements by their corners.
** Coordinates are multiplied by unit_mm. Nodes that no volume element uses are dropped. The mesh
** is checked (cf_mesh_check). CF_E_NOINPUT when the file cannot be opened, CF_E_DATA for a file
** Gmsh cannot read, a mesh with no volume elements, another kind of volume element, or a
** degenerate or inverted element, a node the file defines twice at different places, or two
** nodes at one point (a crack: the message names the file and the elements' or nodes' numbers).
** The default limits (cf_mesh_limits_default). */
cf_status cf_mesh_read(const char *path, double unit_mm, cf_mesh *m, cf_error *err);

/* The same, with the mesh refined `refine` times (0 to 4) by Gmsh's uniform splitting (each
** tetrahedron into eight, new nodes at the edges' midpoints: the geometry of the mesh unchanged),
** under the limits lim (NULL: the default ones): the refined mesh's cost is checked before Gmsh
** refines it (CF_E_DATA "refused before meshing"); a Gmsh that runs out of time or memory gives
** CF_E_DATA. */
cf_status cf_mesh_read_refined(const char *path, double unit_mm, int refine,
                               const cf_mesh_limits *lim, cf_mesh *m, cf_error *err);

/* Fills the closed surface at path (Wavefront .obj or .stl, read by conifit as data, never by
** Gmsh's script reader) with tetrahedra by Gmsh's library: the surface classified into patches
** (edges sharper than 40 degrees kept), reparametrised and remeshed, and the volume meshed, all
** with the target element size size_mm (mm). Coordinates are multiplied by unit_mm. The surface is
** checked and a local self-crossing smoothed away first (surface.h; info, if not NULL, says what
** was found and done). CF_E_NOINPUT when the file cannot be opened; CF_E_DATA for a malformed
** file, a surface that is not closed, a shell inside another that faces outward too (a solid
** within a solid), a crossing that smoothing does not remove, an element size that would give
** more than CF_MESH_MAX_FILL_TETS tetrahedra (checked before the surface's crossings are sought),
** a fill over the limits lim (NULL: the default ones; checked before Gmsh starts), or a surface
** Gmsh cannot fill in them (its reason given). */
cf_status cf_mesh_from_surface(const char *path, double unit_mm, double size_mm,
                               const cf_mesh_limits *lim, cf_mesh *m,
                               cf_mesh_surface_info *info, cf_error *err);

/* Meshes the box lo..hi (mm) into tetrahedra with Gmsh (Delaunay, seed fixed): element size
** size_near at the point focus, growing by `growth` mm per mm of distance from it, at most
** size_far. CF_E_DATA for a bad box or sizes. */
cf_status cf_mesh_box(const double lo[3], const double hi[3], const double focus[3],
                      double size_near, double size_far, double growth, cf_mesh *m, cf_error *err);
/* The same graded about a ring instead of a point: the circle of radius ring_mm about focus in the
** plane z = focus z (a flat punch's rim), the size growing with the distance from it (ring_mm 0:
** cf_mesh_box). CF_E_DATA for a negative or non-finite ring too. */
cf_status cf_mesh_box_ring(const double lo[3], const double hi[3], const double focus[3],
                           double ring_mm, double size_near, double size_far, double growth,
                           cf_mesh *m, cf_error *err);

#endif
