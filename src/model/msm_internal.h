/*
** The workspace the lattice solvers share (msm.c, msm_newton.c, msm_tangent.c, msm_visco.c,
** msm_dynamic.c, msm_uniaxial.c) and the functions they call in one another. Private to the model
** layer.
*/
#ifndef CF_MODEL_MSM_INTERNAL_H
#define CF_MODEL_MSM_INTERNAL_H

#include <math.h>
#include <stddef.h>

#include "model/msm.h"
#include "model/lattice_step.h"
#include "model/mech.h"

/* Bisections of a load increment (or time step) before a solve is declared non-converged. */
#define MAX_BISECT 12

/* ---- workspace ------------------------------------------------------------------------------- */

/* One solver of one lattice: set up by cf_msm_solver_init for a run, a curve or a scan. */
typedef struct solver {
    cf_lattice *lat;
    const cf_msm_effects *fx;
    const cf_msm_config *cfg;
    cf_msm_drive drive;
    size_t ndof;              /* free DOFs */
    long *eq;                 /* node*3+axis -> equation or -1 */
    double *R, *dx;           /* residual, update (ndof) */
    double *xsave;            /* 3 nn positions for backtracking */
    double *Tx0, *kx, *Lprev; /* quasi-static extras per spring (NULL when static) */
    double *sigm;             /* Maxwell branch stress per spring, MPa (NULL when off) */
    double *hq;               /* Prony branch forces, N per unit weight, compression positive:
                                 branch i of spring q at hq[q * prony_count + i] (NULL when off) */
    double *Fprev;            /* law force of every spring at the start of the step, N */
    double qlv_scale;         /* step's law-force factor minus 1 (Prony terms; 0 when off) */
    double qlv_slope;         /* its growth per unit |strain| of the spring (0: quasi-linear) */
    double *tmp;              /* per-spring scratch */
    /* the lattice as a mechanical system (msm_newton.c) for the Newton driver (mech.h), whose
    ** linear solver holds the tangent's pattern (msm_tangent.c), its scale and its factors */
    cf_mech mech;             /* mech.ls NULL until the first solve; it assembles through a
                                 pointer to this struct, which must not move while it is there */
    size_t nnz;               /* entries of the tangent's pattern */
    int *map;                 /* spring q's blocks ii, jj, ij, ji: entry (a, b) of block blk at
                                 index map[q * 36 + 9 * blk + 3 a + b] of the values, -1 fixed */
    int *vmap;                /* the cells' blocks (volume term, hourglass, fibres): cell c's
                                 (a, b) entry (i, k) at
                                 vmap[((c * 8 + a) * 8 + b) * 9 + i * 3 + k] (NULL without one) */
    long neg_pivots;          /* negative pivots of the last factored tangent, -1 unknown */
    int chord;                /* reuse factorisations across iterations and load steps (chord
                                 and Krylov steps, cf_msm_newton) */
    int refactor;             /* the next solve starts with a fresh tangent (the driver keeps the
                                 stage between solves otherwise: mech.fresh, mech.krylov) */
    /* the last residual (cf_msm_residual): max |u|/travel, the residual's and the forces' largest
    ** components; r_ready 1 when s->R holds it at the current positions, not yet handed to the
    ** driver (msm_newton.c); the force floor of the current solve's tolerance */
    double um, rn, fs;
    int r_ready;
    double floor_f;
    /* secant predictor of the static load steps (the uniaxial curve): the converged positions at
    ** the drive value before the current one (xprev, 3 nn as cf_msm_positions_get), vprev that
    ** value, prev_ok whether they are there; xcur scratch. NULL/0 unless secant is set. */
    int secant, prev_ok;
    double vprev;
    double *xprev, *xcur;
    double load;              /* current drive value: strain or stress, MPa */
    int extras;               /* quasi-static extras active */
    int homogeneous;          /* every cell deformed alike (cf_msm_homogeneous_inertias): the
                                 volume term's tangent is computed at the first cell only */
    cf_msm_stats *st;
} solver;

/* The step's law-force factor minus 1 on spring q at its current strain (qlv_scale + qlv_slope
** |u| / H), and its derivative with respect to the law compression u. */
static inline double qlv_factor(const solver *s, size_t q, double *d_du)
{
    const cf_lattice *lat = s->lat;
    if (s->qlv_slope == 0) {
        if (d_du)
            *d_du = 0;
        return s->qlv_scale;
    }
    if (d_du)
        *d_du = s->qlv_slope * copysign(1.0, lat->u_mm[q]) / lat->H_mm;
    return s->qlv_scale + s->qlv_slope * fabs(lat->u_mm[q]) / lat->H_mm;
}

static inline double *coord(cf_lattice *lat, int a)
{
    return a == 0 ? lat->x : a == 1 ? lat->y : lat->z;
}

static inline double *force(cf_lattice *lat, int a)
{
    return a == 0 ? lat->fx : a == 1 ? lat->fy : lat->fz;
}

/* The state of an explicit run (msm_dynamic.c). */
typedef struct dyn {
    double *vx, *vy, *vz;     /* node velocities, mm/s */
    double *Ld, *Tt;          /* per spring: rate of its length, mm/s; dashpot + Maxwell force, N */
    int fused;                /* elastic springs only: the fused step of lattice_step.h */
    cf_lattice_stepper step;  /* its state (when fused) */
} dyn;

/* msm_newton.c: the workspace, the residual and the static load steps */
cf_status cf_msm_solver_init(solver *s, cf_lattice *lat, const cf_msm_effects *fx,
                             const cf_msm_config *cfg, cf_msm_drive drive, cf_msm_stats *st,
                             cf_error *err);
void cf_msm_solver_free(solver *s);
/* Turns on the secant predictor of static load steps (displacement drive): the caller sets
** s->prev_ok = 0 whenever it moves the lattice other than through cf_msm_static_to. */
cf_status cf_msm_solver_secant(solver *s, cf_error *err);
void cf_msm_place_top(cf_lattice *lat, double e);
void cf_msm_add_external(solver *s);
double cf_msm_residual(solver *s, double *rnorm, double *fscale);
cf_status cf_msm_static_to(solver *s, double v, cf_error *err);
double cf_msm_top_stress(const cf_lattice *lat);
double cf_msm_reported_stress(solver *s);
/* Copies the positions of every node into buf (3 nn doubles: x, then y, then z), and back. */
void cf_msm_positions_get(const cf_lattice *lat, double *buf);
void cf_msm_positions_set(cf_lattice *lat, const double *buf);

/* msm_tangent.c: the tangent K = -dR/dx at the state of the last cf_msm_residual(), written into
** the values of its pattern (the system's tangent hook), and s->mech made with that pattern and
** the hooks ops (CF_E_INTERNAL when memory runs out; s->mech.ls stays NULL). */
void cf_msm_tangent_fill(void *ctx, double *v);
cf_status cf_msm_tangent_build(solver *s, const cf_mech_ops *ops, cf_error *err);

/* msm_newton.c: the lattice as a mechanical system and its solves on the Newton driver.
** cf_msm_newton: Newton from the current positions (prescribed DOFs already placed); on failure
** the positions are put back where they started. cf_msm_direction: the tangent at the state of
** the last cf_msm_residual() factored afresh and the update s->dx it gives for s->R (a stability
** check), its inertia in s->neg_pivots and the statistics. */
cf_status cf_msm_newton(solver *s, cf_error *err);
cf_status cf_msm_direction(solver *s, cf_error *err);

/* msm_visco.c: implicit quasi-static steps with dashpots, Maxwell branches and Prony terms */
cf_status cf_msm_relaxed_share_check(const solver *s, cf_error *err);
cf_status cf_msm_quasi_advance(solver *s, const cf_msm_path *p, double t0, double t1, int n,
                               int depth, cf_error *err);

/* msm_dynamic.c: explicit dynamics */
cf_status cf_msm_dyn_init(dyn *d, solver *s, cf_error *err);
void cf_msm_dyn_free(dyn *d);
cf_status cf_msm_explicit_interval(solver *s, dyn *d, const cf_msm_path *path, double t,
                                   double tk, cf_msm_stats *st, cf_error *err);
double cf_msm_kinetic(const cf_lattice *lat, const dyn *d);
double cf_msm_total_energy(solver *s, const dyn *d);

#endif
