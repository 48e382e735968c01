/*
** The body as a spring network, one type for every body the model builds: nodes at their
** reference positions with the components held, springs between two nodes with their rest lengths
** and force weights (the factor on the law's force), and volume elements as lists of nodes of one
** kind (a row of the kind table: four-node tetrahedra, eight-node hexahedra).
**
** Two generators make a net, each declared with its user (a type does not include its users): the
** cubic lattice's (cf_net_lattice in lattice.h: the block of nx x ny x nz cells with its cell
** shares and family weights) and the tetrahedral mesh's (cf_net_mesh in body.h: the mesh's edges
** with the calibration of body.h). cf_lattice_create and cf_body_create build from
** them (the lattice copies the net into its structures of arrays, whose force kernel and stencil
** step stay the box's fast path), and the exports write a net's nodes and springs through one
** function.
*/
#ifndef CF_MODEL_NET_H
#define CF_MODEL_NET_H

#include <stddef.h>
#include <stdint.h>

#include "conifit/error.h"

/* The kinds of volume element: a row each in the table of net.c (its name and node count). */
/* How far a spring group's law may differ in free length from the net's law, relative (two fits
** of one free length agree to rounding; the lattice's cell edge and the body's calibration are of
** the net law's H). */
#define CF_GROUP_H_REL 1e-9

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

/* Releases the arrays. Safe on a zeroed net. */
void cf_net_free(cf_net *n);

#endif
