/*
** The cells of a lattice (lattice.c): which nodes are a cell's corners, for the solvers' sparsity
** patterns and the exports, without the volume and gradient cf_lattice_cell_volume computes.
*/
#ifndef CF_MODEL_LATTICE_CELLS_H
#define CF_MODEL_LATTICE_CELLS_H

#include <stddef.h>
#include <stdint.h>

/* The lattice (lattice.h) by its name alone: this header is lattice.c's, which includes it. */
typedef struct cf_lattice cf_lattice;

/* The eight corner nodes of cell c (corner di + 2 dj + 4 dk), as cf_lattice_cell_volume gives
** them. */
void cf_lattice_cell_nodes(const cf_lattice *lat, size_t c, uint32_t node[8]);

/* 1 when the lattice's cells carry an energy (a volume term or hourglass control: their forces,
** their tangent blocks), 0 when only the springs do. */
int cf_lattice_has_cells(const cf_lattice *lat);

#endif
