/*
** The body as a spring network, one type for every body the model builds: nodes at their
** reference positions with the components held, springs between two nodes with their rest lengths
** and force weights (the factor on the law's force), and volume elements as lists of nodes of one
** kind (a row of the kind table: four-node tetrahedra, eight-node hexahedra).
**
** Two generators make a net: the cubic lattice's (cf_net_lattice: the block of nx x ny x nz cells
** of lattice.h with its cell shares and family weights) and the tetrahedral mesh's (cf_net_mesh:
** the mesh's edges with the calibration of body.h). cf_lattice_create and cf_body_create build from
** them (the lattice copies the net into its structures of arrays, whose force kernel and stencil
** step stay the box's fast path), and the exports write a net's nodes and springs through one
** function.
*/
#ifndef CF_MODEL_NET_H
#define CF_MODEL_NET_H

#include <stddef.h>
#include <stdint.h>

#include "model/body.h"
#include "conifit/error.h"
#include "model/lattice.h"
#include "model/law_internal.h"

/* The kinds of volume element: a row each in the table of net.c (its name and node count). */
typedef enum cf_net_cell_kind {
    CF_NET_TET4 = 0, /* four corners, positively oriented (body.h) */
    CF_NET_HEX8 = 1  /* eight corners, corner di + 2 dj + 4 dk of the cell (the C3D8 / HEX8 order
                     ** of the lattice's cells, cf_lattice_cell_volume) */
} cf_net_cell_kind;

/* Nodes of a volume element of the kind, and its name ("tet4", "hex8"). */
int cf_net_cell_size(cf_net_cell_kind kind);
const char *cf_net_cell_name(cf_net_cell_kind kind);

typedef struct cf_net {
    size_t nn;            /* nodes */
    double *X;            /* 3 nn reference positions, mm (x, y, z of each node in turn) */
    uint8_t *fix;         /* nn: CF_FIX_X | CF_FIX_Y | CF_FIX_Z held at the reference position */
    size_t ns;            /* springs */
    uint32_t *si, *sj;    /* ns end nodes, si < sj */
    double *L0_mm;        /* ns rest lengths, mm */
    double *w;            /* ns force weights on the law's force (in strain form for L0 != H), - */
    uint8_t *family;      /* ns CF_FAMILY_* of each spring (the lattice's), or NULL (a mesh's) */
    cf_net_cell_kind cell_kind; /* the kind of every volume element */
    size_t nc;            /* volume elements */
    uint32_t *cell;       /* nc cf_net_cell_size(cell_kind) node indices */
} cf_net;

/* The cubic lattice of cfg with cell edge H_mm (> 0): nodes at (i, j, k) H with index i + (nx + 1)
** (j + (ny + 1) k); the springs of the families of non-zero weight from each node in that order
** (the cell directions of cell.h), rest length H sqrt(1, 2 or 3) and weight the family's times the
** share of the cells that hold the spring (cf_lattice_axis_share); the bottom face's fixity of
** cfg->bottom (a sliding bottom also pins node (0,0,0) in x and y, node (nx,0,0) in y); every
** cell as a hexahedron, x fastest. CF_E_DATA for cells out of range, CF_E_INTERNAL when memory
** runs out (n is then empty). */
cf_status cf_net_lattice(cf_net *n, const cf_lattice_config *cfg, double H_mm, cf_error *err);

/* The cell counts of cfg: each between 1 and 10000, else CF_E_DATA naming the key
** (lattice.nx ...). cf_net_lattice and the lattice's own check use it. */
cf_status cf_net_lattice_check_cells(const cf_lattice_config *cfg, cf_error *err);

/* The nodes and springs cf_net_lattice makes of cfg (cells >= 1 along each axis), counted without
** making them (exact integers below 2^53), for the budgets of scenes. */
void cf_net_lattice_size(const cf_lattice_config *cfg, double *nodes, double *springs);

/* The net of the tetrahedral mesh m (checked by cf_mesh_check): its nodes, none held; its edges
** as springs in the order of their end nodes, rest length the edge's, weight the calibration of
** body.h for law (per tetrahedron the edge stiffnesses that best match an isotropic tensor, the
** whole network scaled to the shear modulus cf_body_mu_of_law); its tetrahedra. CF_E_DATA when
** the calibration finds no stiffness, CF_E_INTERNAL when memory runs out. */
cf_status cf_net_mesh(cf_net *n, const cf_mesh *m, const cf_law *law, cf_error *err);

/* A net that views b's arrays (nodes, fixity, springs, tetrahedra; nothing owned: not for
** cf_net_free), for the exports. */
cf_net cf_net_of_body(const cf_body *b);

/* Releases the arrays. Safe on a zeroed net. */
void cf_net_free(cf_net *n);

#endif
