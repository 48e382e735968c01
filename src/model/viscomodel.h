/*
** The time-dependent model that conifit fits to a measured time series: the lattice of msm.h made
** of one conical spring (its elastic, instantaneous response) with a Prony series of Maxwell
** branches on every spring (quasi-linear viscoelasticity) and optionally a dashpot, driven by a
** strain history (piecewise linear in time through the measured points) and sampled at the
** measured times. It is the same machinery `conifit simulate` runs, so a scene built from the
** fitted parameters and the same history reproduces the fitted curve.
**
** The nominal stress depends on the spring only through the identifiable quantities rho = D1/D2,
** the solid strain s/H and the stress scale F_C/H^2: at a prescribed displacement every force of
** the lattice (law and branches) is proportional to F_C, so the equilibrium does not depend on
** it, except through the dashpot, which the model therefore takes relative to the stress scale.
** A spring with a cylindrical tail adds a fourth quantity, the tail's compliance e_t: the model
** then runs the member of cf_ident_member_tail, whose tail closes near the free length, past any
** strain a series can reach.
**
** Sign: the series is read in the table's own sign (tension positive, compression negative) and
** the stress returned in it.
*/
#ifndef CF_VISCOMODEL_H
#define CF_VISCOMODEL_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/family.h"
#include "model/law_internal.h"
#include "model/msm.h"

/* The parameters of the time-dependent model. */
typedef struct cf_visco_params {
    cf_ident ident;                   /* the spring's family (family.h) of a stress-strain
                                      ** table: rho [-], s/H [-], F_C/H^2 [MPa] */
    double e_tail;                    /* the compliance F_C/(k_t H) of a cylindrical tail in
                                      ** series with the cone (the conical-tail law, law.md), - ;
                                      ** 0: none, the conical law */
    int nbranch;                      /* Prony terms, 0..CF_PRONY_MAX */
    double g[CF_PRONY_MAX];           /* relative moduli, - */
    double tau_s[CF_PRONY_MAX];       /* time constants, s */
    double k[CF_PRONY_MAX];           /* growth of g_i per unit |strain| of a spring (msm.h
                                      ** prony_k), - ; all 0: quasi-linear */
    double eta_MPa_s;                 /* dashpot beside every spring, MPa s (0 = none) */
} cf_visco_params;

/* A strain history: count points, time strictly increasing, strain in the table's sign. */
typedef struct cf_visco_series {
    size_t count;
    const double *t_s;
    const double *strain;
} cf_visco_series;

/* Where the model is evaluated. With `cell` (the default) the lattice's homogenised cell (cell.h)
** in uniaxial loading with free sides: the lattice's stress wherever its deformation stays
** homogeneous, at microseconds a step. Otherwise the full lattice of cfg.lattice (msm.h). Both
** take quasi_substeps implicit steps per sample interval (cfg.dt_s = 0) with the same update, so
** they agree to the solvers' tolerance; the cell cannot leave the homogeneous state, the lattice
** can (a small lattice may buckle sideways while its branches relax). */
typedef struct cf_visco_setup {
    int cell;                 /* 1: the homogenised cell (default); 0: the lattice */
    cf_msm_config cfg;        /* lattice (weights for the cell) and solver settings */
    cf_law_method method;     /* law evaluator */
} cf_visco_setup;

/* The default setup: the cell with the weights of cf_msm_default(), 10 implicit steps per
** measured interval, law evaluator CF_LAW_CLOSED. */
cf_visco_setup cf_visco_default(void);

/* The spring the model runs for p: cf_ident_member, or cf_ident_member_tail with tau = e_t/(s/H)
** when p has a tail. Free length 1 mm. */
cf_spring cf_visco_member(const cf_visco_params *p);

/* The effects of p (Prony terms and dashpot) as msm.h takes them. */
cf_msm_effects cf_visco_effects(const cf_visco_params *p);

/* The model's stress (MPa, table's sign) at every point of the series. CF_E_DATA for invalid
** parameters or series (message says which), CF_E_NOCONV when a lattice solve fails (e.g. a
** spring would pass solid), CF_E_INTERNAL when memory runs out. stats may be NULL. */
cf_status cf_visco_curve(const cf_visco_params *p, const cf_visco_setup *s,
                         const cf_visco_series *series, double *stress_MPa, cf_msm_stats *stats,
                         cf_error *err);

/* The static elastic (instantaneous) curve of the model at unit branch state: its stress (MPa,
** table sign) at each strain, in the cell or the lattice as s says. */
cf_status cf_visco_elastic_curve(const cf_visco_params *p, const cf_visco_setup *s,
                                 const double *strain, size_t count, double *stress_MPa,
                                 cf_error *err);

/* A run of the same model along a loading path of msm.h (compressive-positive values: strain,
** or stress in MPa for a force drive), sampled at sample_t_s; fills out (nsamples). Used for the
** predicted hysteresis loop and creep. */
cf_status cf_visco_run(const cf_visco_params *p, const cf_visco_setup *s, const cf_msm_path *path,
                       const double *sample_t_s, size_t nsamples, cf_msm_sample *out,
                       cf_error *err);

#endif
