/*
** A closed triangulated surface as data, and what preparing and meshing it found and did: the
** types that the surface reader (surface.h), its geometry (surface_geom.h) and the mesher
** (mesh.h, cf_mesh_from_surface) share. A header of its own, so that each depends on these types
** and none on the others' functions.
*/
#ifndef CF_IO_SURFACE_TYPES_H
#define CF_IO_SURFACE_TYPES_H

#include <stddef.h>
#include <stdint.h>

typedef struct cf_surface {
    size_t nv, nf;
    double *X;      /* 3 nv vertex coordinates, in the file's units */
    uint32_t *tri;  /* 3 nf vertex indices */
} cf_surface;

/* What meshing a closed surface found and did (cf_mesh_from_surface). */
typedef struct cf_mesh_surface_info {
    size_t vertices, triangles;  /* of the surface as read */
    double enclosed_mm3;         /* the volume it encloses (after any smoothing), mm^3 */
    size_t crossings;            /* edges found crossing a triangle not their own (first round) */
    size_t smoothed;             /* vertices moved to remove them (over all rounds) */
    double max_move_mm;          /* the largest move, mm */
    int reversed;                /* 1: the triangles were turned to face outward */
    size_t shells;               /* closed shells: one, or a solid and its cavities */
    size_t pair_tests;           /* edge-triangle tests the search for crossings made */
    double estimated_tets;       /* the fill's tetrahedra, about (from the volume and size) */
    double estimated_nodes;      /* and its nodes: an eighth of that, and the surface's at that
                                 ** size (1.15 area / h^2); 1.2 to 1.4 times Gmsh's count */
} cf_mesh_surface_info;

#endif
