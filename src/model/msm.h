/*
** Solvers for the mass-spring lattice (lattice.h): static equilibria, quasi-static time stepping
** with dashpots, Maxwell branches and Prony terms, and explicit symplectic dynamics with inertia;
** plus the uniaxial curve used to validate a fitted spring and its stability.
**
** What runs depends only on the effects asked for:
**   no time effect          -> a sequence of static equilibria (Newton with the law's tangent,
**                              backtracking so that no spring is driven to solid); the sparse
**                              tangent is factored by CHOLMOD's Cholesky, or as L D L^T by MUMPS
**                              when it is indefinite, with banded LDL^T, dense LU and GMRES as
**                              fallbacks; no time stepping.
**   damping, Maxwell and/or -> implicit quasi-static steps (backward Euler for the dashpots, the
**   Prony terms, no inertia    exact exponential update for the Maxwell branches, the exact
**                              recursive one for the Prony terms with the law force linear in
**                              time over a step), each a Newton solve; unconditionally stable.
**   inertia                 -> explicit symplectic Euler with the stable step computed from the
**                              stiffest spring tangent and the lightest mass.
** An effect that is off has no loop at all.
**
** Sign convention: strain and stress are compressive-positive here (u > 0 shortens). A tension-
** positive table (compression negative) maps by changing the sign of both columns; that is what
** cf_msm_uniaxial does for its caller.
*/
#ifndef CF_MSM_H
#define CF_MSM_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/lattice.h"
#include "model/law_internal.h"

/* Most Prony terms of a reduced relaxation function. */
#define CF_PRONY_MAX 8

/* The explicit step as a fraction of the stable step (cf_msm_stable_step), automatic or not. */
#define CF_MSM_DT_SAFETY 0.9

/* Time-dependent effects; all zero = static. */
typedef struct cf_msm_effects {
    int inertia;               /* 1: solve the dynamics with node masses */
    double eta_MPa_s;          /* dashpot beside every spring (paper eq. 14): sigma = eta d(eps)/dt,
                                  MPa s; 0 = off */
    double maxwell_E_MPa;      /* modulus of the Maxwell branch beside every spring, MPa; 0 = off */
    double maxwell_tau_s;      /* relaxation time of the Maxwell branch, s */
    double gravity_mm_per_s2;  /* acceleration along -z, mm/s^2 (9810 on earth); 0 = off */
    /* Quasi-linear viscoelasticity (Fung): every spring's force is its law force convolved with
    ** the reduced relaxation function G(t) = g_inf + sum g_i exp(-t/tau_i), g_inf = 1 - sum g_i,
    ** i.e. the law is the instantaneous response and g_inf times the law the equilibrium one.
    ** Each term is a Maxwell branch whose force h_i obeys dh_i/dt = g_i dF/dt - h_i/tau_i,
    ** advanced by its exact recursive update over a step along which F varies linearly in time.
    ** The state at the first sample is relaxed (h_i = 0). Quasi-static runs only (no inertia). */
    int prony_count;                   /* number of terms, 0 = off, at most CF_PRONY_MAX */
    double prony_g[CF_PRONY_MAX];      /* relative moduli g_i >= 0, sum < 1, - */
    double prony_tau_s[CF_PRONY_MAX];  /* time constants tau_i > 0, s */
    /* Relaxation that grows with strain (all 0 = quasi-linear): term i's relative modulus at the
    ** spring's strain e = u / H (law compression over free length) is g_i + prony_k[i] |e|, and
    ** its branch relaxes that share of the law force: dh_i/dt = d((g_i + k_i |e|) F)/dt -
    ** h_i/tau_i. The equilibrium response is (1 - sum (g_i + k_i |e|)) F, which must stay
    ** positive wherever a spring goes (a run that takes a spring past it fails with CF_E_DATA). */
    double prony_k[CF_PRONY_MAX];      /* growth of g_i per unit strain, >= 0, - */
} cf_msm_effects;

/* Checks the Prony terms of fx (count within 0..CF_PRONY_MAX, g_i >= 0 and finite, sum g_i < 1,
** tau_i > 0 and finite, prony_k[i] >= 0 and finite); CF_E_DATA naming the offending term
** otherwise. */
cf_status cf_msm_prony_check(const cf_msm_effects *fx, cf_error *err);

/* 1 when a Prony term of fx changes with strain (some prony_k[i] != 0), 0 when quasi-linear. */
int cf_msm_prony_depends_on_strain(const cf_msm_effects *fx);

/* Checks the relative moduli of fx's Prony terms at a spring's |strain| e (g_i + k_i e each >= 0,
** their sum below 1); CF_E_DATA naming the term and the strain otherwise. */
cf_status cf_msm_prony_at_strain(const cf_msm_effects *fx, double e, cf_error *err);

typedef enum cf_msm_drive {
    CF_DRIVE_DISPLACEMENT = 0, /* the top face follows a prescribed compressive strain */
    CF_DRIVE_FORCE = 1         /* the top face carries a prescribed compressive stress */
} cf_msm_drive;

/* A loading path: piecewise linear in time through (t_s[i], value[i]); value is the compressive
** strain (-) for displacement drive, the compressive nominal stress (MPa) for force drive. Samples
** are reported at every time in sample_t_s (increasing, inside the path). */
typedef struct cf_msm_path {
    cf_msm_drive drive;
    size_t count;
    const double *t_s;
    const double *value;
} cf_msm_path;

/* The path's value at time t (linear between its points, held outside them). */
double cf_msm_path_value(const cf_msm_path *p, double t);

/* Solver settings. */
typedef struct cf_msm_config {
    cf_lattice_config lattice;
    double newton_rtol;        /* Newton: residual tolerance relative to the force scale, - */
    int newton_max_iter;       /* Newton iterations per solve */
    double dt_s;               /* time step, s: 0 = automatic (quasi-static: sample interval
                                  split in quasi_substeps; dynamic: 0.9 of the stable step) */
    int quasi_substeps;        /* implicit steps per sample interval when dt_s = 0 */
    int banded_only;           /* 1: solve tangents with the banded LDL^T (and its fallbacks)
                                  instead of the sparse Cholesky, for comparisons; default 0 */
    /* Called by cf_msm_run after every reported sample (done of total) when not NULL, so that a
    ** caller can show progress; the library itself never prints. */
    void (*progress)(void *ctx, size_t done, size_t total, double t_s);
    void *progress_ctx;
} cf_msm_config;

/* 3 x 3 x 3 cells, face and body diagonals, bottom axial; Newton 1e-11, 50 iterations. */
cf_msm_config cf_msm_default(void);

/* What a run did. */
typedef struct cf_msm_stats {
    size_t solves;             /* static / quasi-static Newton solves */
    size_t newton_iters;       /* Newton iterations in all */
    size_t linear_iters;       /* linear solves: sparse, banded or dense factorisations plus
                                  GMRES cycles */
    size_t chord_iters;        /* Newton iterations that reused an earlier factorisation instead
                                  (uniaxial curves: chord steps, and Krylov steps on the current
                                  tangent preconditioned by it) */
    size_t indefinite_tangents;/* factored tangents with negative pivots (unstable states) */
    long neg_pivots_max;       /* most negative pivots of any factored tangent (0: every tangent
                                  was positive definite); -1 if none had a known inertia */
    size_t steps;              /* time steps taken */
    double dt_used_min_s;      /* smallest step used, s (0 for static runs) */
    double dt_stable_s;        /* stable explicit step at the start, s (0 if not explicit) */
    size_t substepped;         /* sample intervals where stiffening forced a smaller step */
    double max_u_over_travel;  /* largest spring compression reached, in units of the travel */
    double max_energy_drift;   /* explicit, no damping: max |E - E0| relative to the work done */
} cf_msm_stats;

/* One reported sample. */
typedef struct cf_msm_sample {
    double t_s;                /* time, s */
    double strain;             /* compressive nominal strain of the top face, - */
    double stress_MPa;         /* compressive nominal stress: top reaction / (nx ny H^2), MPa */
    double kinetic_mJ;         /* kinetic energy, mJ = N mm (0 without inertia) */
    double lateral_stretch;    /* the lattice's width along x over its rest width
                                  (cf_lattice_lateral_stretch), - (1 at rest; in a uniaxial run
                                  lateral strain over axial strain is -nu) */
    long neg_pivots;           /* negative pivots (negative eigenvalues) of the tangent factored in
                                  the last Newton iteration of this sample's solve: 0 a stable
                                  equilibrium, > 0 an unstable one; -1 unknown (explicit dynamics,
                                  or a solve that needed no factorisation and none came before) */
} cf_msm_sample;

/* Runs the lattice along a path; fills out[k] for k < path sample count. Status CF_E_NOCONV when
** a solve does not converge or a spring would have to pass solid (message: time and strain),
** CF_E_DATA for an unstable requested step or an invalid path, CF_E_INTERNAL when energy or
** positions become non-finite. On failure out holds the samples done so far, *done says how many. */
cf_status cf_msm_run(cf_lattice *lat, const cf_msm_effects *fx, const cf_msm_config *cfg,
                     const cf_msm_path *path, const double *sample_t_s, size_t nsamples,
                     cf_msm_sample *out, size_t *done, cf_msm_stats *stats, cf_error *err);

/* The static uniaxial curve of the lattice (cfg->lattice) built from law: the nominal stress at
** each strain, in the table's own sign (negative strain = compression gives negative stress).
** Strains are visited from 0 outwards, compression and tension separately, each solve starting
** from the previous one. cfg may be NULL (cf_msm_default()); stats may be NULL. With
** CF_LAW_TABLE the law's table must be built. */
cf_status cf_msm_uniaxial(const cf_law *law, cf_law_method m, const cf_msm_config *cfg,
                          const double *strain, size_t count, double *stress_MPa,
                          cf_msm_stats *stats, cf_error *err);

/* Where the static uniaxial lattice (cfg->lattice, cfg NULL: cf_msm_default()) built from law
** first loses stability on one side (side < 0: compression, > 0: tension): the strain, in the
** table's sign, at which the tangent of the homogeneous equilibrium first has a negative pivot
** (a column of cells can buckle sideways; a dynamic run leaves the static curve there), found by
** steps of 1/32 up to 0.995 of the solid strain and bisection to about 1e-5 of it. *limit = 0
** when the lattice stays stable up to there. A static solve that fails counts as unstable. */
cf_status cf_msm_stability_limit(const cf_law *law, cf_law_method m, const cf_msm_config *cfg,
                                 int side, double *limit, cf_error *err);

/* Negative pivots (*neg) of the tangent of the static lattice (cfg->lattice, cfg NULL:
** cf_msm_default()) built from law, at the homogeneous uniaxial state of table strain `strain`
** (negative = compression) with lateral stretch `lateral`, F = diag(lateral, lateral, 1 + strain):
** the state the homogenised cell (cell.h) gives, which is the lattice's equilibrium for a bottom
** 'axial' (CF_E_DATA for a clamped bottom, or when the residual is not at rounding level).
** 0: a stable equilibrium; > 0: a column of cells can leave it. No Newton solve: one
** assembly and banded L D L^T factorisation of the tangent (safe on any thread). */
cf_status cf_msm_homogeneous_inertia(const cf_law *law, cf_law_method m, const cf_msm_config *cfg,
                                     double strain, double lateral, long *neg, cf_error *err);

/* The same for count states (strains[q], laterals[q]) of one lattice, built once: *neg is the
** first state's with a negative pivot (the scan stops there), else 0. Failures as above, for the
** first state that fails. */
cf_status cf_msm_homogeneous_inertias(const cf_law *law, cf_law_method m,
                                      const cf_msm_config *cfg, const double *strains,
                                      const double *laterals, size_t count, long *neg,
                                      cf_error *err);

/* The explicit stable step (s) of the lattice at its current state for the given effects
** (stiffest spring tangent, lightest mass, most springs at one node; the dashpots shorten it).
** Calls cf_lattice_forces. An explicit run steps at most CF_MSM_DT_SAFETY times it. */
double cf_msm_stable_step(cf_lattice *lat, const cf_msm_effects *fx);

#endif
