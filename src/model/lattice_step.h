/*
** The explicit step of the lattice as a stencil, for runs where every step counts (haptic rates,
** large lattices). conifit's lattices are regular (lattice.h): node (i, j, k) is
** p = i + (nx + 1) (j + (ny + 1) k), and the springs of one cell direction (13 of them: 3 edges,
** 6 face diagonals, 4 body diagonals) join p to p + D with one flat offset D, one rest length and
** one H/L0. So the step needs no node indices and no per-spring constants:
**   springs: layer by layer, in chunks of CF_STEP_BLOCK nodes, and per direction: contiguous
**            loads of the positions at p and p + D, lengths and compressions, the law (law_simd.h)
**            and the tension vectors, then two contiguous loops that add them to the forces at p
**            and subtract them at p + D (no two lanes of a loop touch the same node). A spring's
**            weight (family weight times the share of the cells holding it) depends only on
**            whether it lies on the boundary: one table per direction over the nodes of a layer,
**            times a factor per layer. A flat run of one direction also passes the pairs that
**            wrap from the end of a row (or a layer's last row) to the start of the next: they are
**            not springs, have weight 0 in that table and are masked out of the forces and of the
**            largest compression;
**   nodes:   symplectic Euler (v += h f/m, x += h v) and the node forces reset for the next step.
** Per spring the pass reads about 12 bytes (positions and forces of nodes in cache, the weight
** table of the layer), against about 46 for a pass over an edge list.
**
** The forces are those of cf_lattice_forces (the edge-list kernel the statics and the viscous
** dynamics use) up to the order of the sums, i.e. to rounding.
**
** Threads: a slab is a layer of first nodes; a spring of slab k touches nodes of layers k and
** k + 1 only, so the even slabs can run in parallel, then the odd ones. The order of the sums does
** not depend on the number of threads (same results with one thread or many). Threads start only
** from CF_STEP_THREADS_MIN springs, below which they cost more than they save.
**
** Private to the model layer (msm_dynamic.c's explicit dynamics; the benchmark).
*/
#ifndef CF_MODEL_LATTICE_STEP_H
#define CF_MODEL_LATTICE_STEP_H

#include <stddef.h>

#include "model/cell.h"
#include "conifit/error.h"
#include "model/lattice.h"
#include "model/law_simd.h"

#define CF_STEP_BLOCK 256
/* the law runs over whole vectors of 8 lanes, padded within the block (lattice_step.c) */
_Static_assert(CF_STEP_BLOCK % 8 == 0, "CF_STEP_BLOCK must be a multiple of 8");
#define CF_STEP_THREADS_MIN 1000000

/* One cell direction of the stencil. */
typedef struct cf_step_dir {
    size_t D;            /* flat offset of the second node, > 0 */
    int di, dj, dk;      /* the offset in cells */
    double L0, a;        /* rest length, mm, and H/L0 */
    double wk[2];        /* layer factor: [0] inner layers, [1] the bottom and top layers */
    double *wl;          /* weight over the first nodes of a layer (0: no spring there) */
    const cf_law *law;   /* the law of its group (the scalar form's; lattice.h, group_law) */
    const cf_law_lanes *lanes; /* a lattice with groups: its group's lanes (NULL: the stepper's) */
} cf_step_dir;

/* The forms of a double-acting element's step (beside law_simd.h's CF_LANE_*): each spring of
** the pair through its own lanes in that form, every lane evaluated for both and the side chosen
** by the sign of u. */
enum { CF_STEP_PAIR_CLOSED = 3, CF_STEP_PAIR_TABLE = 4, CF_STEP_PAIR_POLY = 5 };

typedef struct cf_lattice_stepper {
    cf_lattice *lat;       /* not owned */
    cf_law_lanes lanes;
    cf_law_lanes ext_lanes; /* a double-acting element's extension spring (its H the same) */
    cf_law_lanes glanes[CF_FAMILY_COUNT]; /* a lattice with groups: each group's lanes */
    int form;              /* CF_LANE_POLY, CF_LANE_CLOSED, CF_LANE_TABLE, CF_STEP_PAIR_*, or -1:
                              the scalar law per block (each direction its group's law). With
                              groups, one form for every group (each its own lanes): the
                              polynomial when every group's fits, else the closed form or the
                              table; -1 when a group's law is a kind, a pair or tailed */
    double poly_error;     /* the polynomial's measured error (law_simd.h), NaN when not fitted */
    int ndir;              /* directions with springs (families of weight > 0) */
    cf_step_dir dir[CF_CELL_DIRS];
    size_t layer;          /* nodes per layer, (nx + 1)(ny + 1) */
    size_t nslab;          /* slabs (layers of first nodes), nz + 1 */
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
