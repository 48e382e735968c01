/*
** The explicit step of the lattice in two fused passes, for runs where every step counts (haptic
** rates, large lattices):
**   springs: in blocks of CF_STEP_BLOCK springs, vectorised loops over the block gather the end
**            positions and form lengths and compressions, evaluate the law (law_simd.h) and the
**            tension vectors; then a scalar loop scatters the equal and opposite forces into the
**            node forces, summing each first node's run of springs in registers (a sum through
**            memory would wait on its own store at every spring);
**   nodes:   symplectic Euler (v += h f/m, x += h v) and the node forces reset for the next step.
** Springs are visited in their storage order, which is by first node, so the gathers and scatters
** of a block fall on a few layers of nodes that stay in cache. Per spring the pass reads the two
** node indices and three constants (L0, H/L0, weight), 40 bytes, and writes nothing.
**
** Threads: the springs are grouped in slabs, one per layer of first nodes; a spring of slab k
** touches nodes of layers k and k + 1 only, so the even slabs can run in parallel, then the odd
** ones. The order of the sums does not depend on the number of threads (same results with one
** thread or many). Threads start only from CF_STEP_THREADS_MIN springs, below which they cost
** more than they save.
**
** Private to the model layer (msm.c's explicit dynamics; the benchmark).
*/
#ifndef CF_MODEL_LATTICE_STEP_H
#define CF_MODEL_LATTICE_STEP_H

#include <stddef.h>

#include "conifit/error.h"
#include "conifit/lattice.h"
#include "model/law_simd.h"

#define CF_STEP_BLOCK 256
#define CF_STEP_THREADS_MIN 1000000

typedef struct cf_lattice_stepper {
    cf_lattice *lat;       /* not owned */
    cf_law_lanes lanes;
    int form;              /* CF_LANE_CLOSED, CF_LANE_TABLE, or -1: the scalar law per block */
    size_t nslab;          /* slabs (layers of first nodes) */
    size_t *slab;          /* nslab + 1 spring indices: slab k is [slab[k], slab[k + 1]) */
    double *inv_mass[3];   /* per axis: 1/m for a free DOF, 0 for a prescribed one */
    int threads;           /* 1: the lattice is large enough for threads */
} cf_lattice_stepper;

/* Prepares the step for lat. eq[3 * node + axis] < 0 marks a prescribed DOF (NULL: those of
** lat->fix), which keeps its velocity (its position moves by that velocity only). CF_E_INTERNAL
** when memory runs out. */
cf_status cf_lattice_stepper_init(cf_lattice_stepper *st, cf_lattice *lat, const long *eq,
                                  cf_error *err);

/* Adds every spring's force to the node forces lat->fx, fy, fz (which the caller has zeroed, or
** the last cf_lattice_stepper_advance has). Writes no per-spring output. Returns the largest
** |u| / travel (>= 1: a spring at solid). */
double cf_lattice_stepper_forces(cf_lattice_stepper *st);

/* v += h f inv_mass and x += h v on every node, then the node forces are set to zero. */
void cf_lattice_stepper_advance(cf_lattice_stepper *st, double h, double *vx, double *vy,
                                double *vz);

void cf_lattice_stepper_free(cf_lattice_stepper *st);

#endif
