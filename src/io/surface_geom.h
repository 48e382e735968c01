/*
** The geometry of closed surfaces that cf_surface_prepare (surface.c) asks about, in
** surface_geom.c: which edges cross a triangle not their own (through a bounding-volume tree),
** and how the closed shells lie in one another. Private to the io layer.
*/
#ifndef CF_IO_SURFACE_GEOM_H
#define CF_IO_SURFACE_GEOM_H

#include <stddef.h>
#include <stdint.h>

#include "conifit/error.h"
#include "io/surface_types.h"

static inline void sub3(const double *a, const double *b, double *c)
{
    for (int k = 0; k < 3; k++)
        c[k] = a[k] - b[k];
}

static inline void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Marks (mark[v] = 1) the corners of every edge of s that crosses a triangle not its own, and
** that triangle's corners; returns the number of crossings, or -1 when memory runs out. *fa, *fb
** and *ft get the first crossing found; *tests counts the edge-triangle tests made. */
long cf_surface_crossings(const cf_surface *s, uint8_t *mark, uint32_t *fa, uint32_t *fb,
                          uint32_t *ft, size_t *tests);

/* The closed shells of s (info->shells); a shell that faces outward inside the solid of another
** (the winding number of the other shells at one of its vertices at least 1: a solid within a
** solid, which Gmsh would mesh as a hollow body) is refused naming one of its vertices (CF_E_DATA).
** A cavity's shell, facing into it, is not. */
cf_status cf_surface_nested_shells(const cf_surface *s, const char *name, double unit_mm,
                                   cf_mesh_surface_info *info, cf_error *err);

#endif
