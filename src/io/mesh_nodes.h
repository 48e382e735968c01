/*
** What mesh.c asks of a mesh's nodes outside Gmsh (mesh_nodes.c): a node an ASCII .msh file
** defines twice, two nodes at one point, and the mesh's bytes through the pipe from Gmsh's
** process (io/isolate.h). Private to the io layer.
*/
#ifndef CF_IO_MESH_NODES_H
#define CF_IO_MESH_NODES_H

#include "io/isolate.h"
#include "model/body.h"
#include "conifit/error.h"

/* A node an ASCII .msh file (versions 2, 4.0, 4.1) defines twice: CF_E_DATA naming the file, the
** line and the node (Gmsh would keep the last coordinates without a word). Other files, binary
** ones and a section Gmsh's reader must judge pass. */
cf_status cf_mesh_msh_nodes_once(const char *path, cf_error *err);

/* Two nodes of m at one point (the elements on either side not joined: a crack the file does not
** show): CF_E_DATA naming both, m freed. */
cf_status cf_mesh_check_coincident(cf_mesh *m, const char *name, cf_error *err);

/* m as bytes into the pipe, and back (CF_E_INTERNAL when they are short or inconsistent). */
void cf_mesh_put(cf_isolate_buf *o, const cf_mesh *m);
cf_status cf_mesh_get(cf_isolate_buf *in, const char *name, cf_mesh *m, cf_error *err);

#endif
