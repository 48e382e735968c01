/*
** Closed triangulated surfaces (Wavefront OBJ, STL ASCII or binary) read as data, checked and
** made fit for a volume mesher (surface.c): every edge in exactly two triangles of opposite
** orientation, the normals outward, and local self-crossings smoothed away. Private to the io
** layer; mesh.c hands the result to Gmsh (cf_mesh_from_surface, io/mesh.h).
*/
#ifndef CF_IO_SURFACE_H
#define CF_IO_SURFACE_H

#include <stddef.h>
#include <stdint.h>

#include "conifit/error.h"
#include "io/surface_types.h"

/* The most tetrahedra a surface is filled with. */
#define CF_MESH_MAX_FILL_TETS 5e6

void cf_surface_free(cf_surface *s);

/* 1 when path names a surface file this reader takes (.obj, .stl). */
int cf_surface_name(const char *path);

/* Reads the OBJ or STL file at path (by its ending; polygons of an OBJ split into fans; an STL's
** repeated vertices merged). CF_E_NOINPUT when it cannot be opened, CF_E_DATA naming the file and
** line (or triangle) for anything malformed or not finite. */
cf_status cf_surface_read(const char *path, cf_surface *s, cf_error *err);

/* Checks s as the boundary of a solid and prepares it (info filled in mm, with unit_mm): no
** triangle of zero area, every edge in two triangles of opposite orientation (else "not a closed
** surface" naming the vertices), the triangles turned outward when they enclose a negative volume;
** edges that cross a triangle not their own are removed by moving the corners of the triangles
** involved to the mean of their neighbours, up to CF_SURFACE_SMOOTH_ROUNDS rounds (else refused
** naming the crossing); the element size's fill is counted (info->estimated_tets) and refused
** over CF_MESH_MAX_FILL_TETS before crossings are sought; a shell that faces outward inside the
** solid of another is refused (a solid within a solid). A surface of fewer than
** CF_SURFACE_MIN_TRIANGLES triangles is then split, each triangle into four at its edges'
** midpoints (the same shape), until it has as many: Gmsh 4.8's classification of a tetrahedron's
** four triangles never ends. CF_E_DATA / CF_E_INTERNAL. */
#define CF_SURFACE_SMOOTH_ROUNDS 5
#define CF_SURFACE_MIN_TRIANGLES 64
cf_status cf_surface_prepare(cf_surface *s, const char *name, double unit_mm, double size_mm,
                             cf_mesh_surface_info *info, cf_error *err);

#endif
