/*
** Reading volume meshes for bodies (body.h) with Gmsh's library, and meshing a box with it.
*/
#ifndef CF_MESH_H
#define CF_MESH_H

#include "model/body.h"
#include "conifit/error.h"

/* Reads the volume mesh at path (Gmsh's mesh formats: .msh of every version, .mesh, .vtk, .unv,
** .bdf, .nas; a name with another ending is refused, since Gmsh would run it as a script) into m: its
** tetrahedra, and each hexahedron as six tetrahedra; higher-order elements by their corners.
** Coordinates are multiplied by unit_mm. Nodes that no volume element uses are dropped. The mesh
** is checked (cf_mesh_check). CF_E_NOINPUT when the file cannot be opened, CF_E_DATA for a file
** Gmsh cannot read, a mesh with no volume elements, another kind of volume element, or a
** degenerate or inverted element (the message names the file and the element's number). */
cf_status cf_mesh_read(const char *path, double unit_mm, cf_mesh *m, cf_error *err);

/* The same, with the mesh refined `refine` times (0 to 4) by Gmsh's uniform splitting (each
** tetrahedron into eight, new nodes at the edges' midpoints: the geometry of the mesh unchanged). */
cf_status cf_mesh_read_refined(const char *path, double unit_mm, int refine, cf_mesh *m,
                               cf_error *err);

/* What meshing a closed surface found and did (cf_mesh_from_surface). */
typedef struct cf_mesh_surface_info {
    size_t vertices, triangles;  /* of the surface as read */
    double enclosed_mm3;         /* the volume it encloses (after any smoothing), mm^3 */
    size_t crossings;            /* edges found crossing a triangle not their own (first round) */
    size_t smoothed;             /* vertices moved to remove them (over all rounds) */
    double max_move_mm;          /* the largest move, mm */
    int reversed;                /* 1: the triangles were turned to face outward */
} cf_mesh_surface_info;

/* Fills the closed surface at path (Wavefront .obj or .stl, read by conifit as data, never by
** Gmsh's script reader) with tetrahedra by Gmsh's library: the surface classified into patches
** (edges sharper than 40 degrees kept), reparametrised and remeshed, and the volume meshed, all
** with the target element size size_mm (mm). Coordinates are multiplied by unit_mm. The surface is
** checked and a local self-crossing smoothed away first (surface.h; info, if not NULL, says what
** was found and done). CF_E_NOINPUT when the file cannot be opened; CF_E_DATA for a malformed
** file, a surface that is not closed, a crossing that smoothing does not remove, an element size
** that would give more than 5e6 tetrahedra or a surface Gmsh cannot fill (its reason given). */
cf_status cf_mesh_from_surface(const char *path, double unit_mm, double size_mm, cf_mesh *m,
                               cf_mesh_surface_info *info, cf_error *err);

/* Meshes the box lo..hi (mm) into tetrahedra with Gmsh (Delaunay, seed fixed): element size
** size_near at the point focus, growing by `growth` mm per mm of distance from it, at most
** size_far. CF_E_DATA for a bad box or sizes. */
cf_status cf_mesh_box(const double lo[3], const double hi[3], const double focus[3],
                      double size_near, double size_far, double growth, cf_mesh *m, cf_error *err);

#endif
