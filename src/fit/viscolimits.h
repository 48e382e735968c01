/*
** The limits of the viscoelastic fit (viscofit.h) in the space of its elastic quantities rho, s/H
** and F_C/H^2, so that the fitted spring is one that can be built and its lattice follows the fit:
**   design: a spring of one of the allowed types within the design limits of fit.h can be placed
**           at (rho, s/H) and carries at most A_max = F_C/H^2 there (cf_fit_ident_limit);
**   stability: the static lattice of n^3 cells built from the spring stays stable (its tangent
**           positive definite at the homogeneous state) up to the series' largest strains, in
**           compression and in tension (each side the series reaches). At
**           fixed rho that holds for s/H above a bound (a spring further from solid stiffens
**           less at the same strain); the bound is tabulated over log rho once per fit and
**           interpolated (Steffen's monotone cubic, GSL: smooth for the optimiser), with a
**           small safety margin, and checked exactly where the fit ends.
** Private to the fit layer.
*/
#ifndef CF_FIT_VISCOLIMITS_H
#define CF_FIT_VISCOLIMITS_H

#include <gsl/gsl_interp.h>

#include "fit/fit.h"
#include "model/viscomodel.h"

#define CF_VISCO_STAB_GRID 25

typedef struct cf_visco_limits {
    const cf_fit_options *design; /* NULL: no design cap */
    unsigned types;               /* bits 1 << CF_TELESCOPING / CF_NON_TELESCOPING */
    int cells;                    /* lattice n^3 checked for stability; 0: not checked */
    cf_visco_setup setup;         /* weights and law evaluator */
    double xlo, xhi;              /* the series' most compressive (<= 0) and most tensile (>= 0)
                                     strains: the lattice is checked at each that is nonzero */
    double e_lo, e_hi;            /* bounds of s/H without the stability bound */
    double lrho[CF_VISCO_STAB_GRID], B[CF_VISCO_STAB_GRID]; /* the stability bound by log rho */
    int unstable_everywhere;      /* 1: no s/H below e_hi keeps the lattice stable at any rho */
    gsl_interp *interp;           /* the bound's interpolant (owned) */
} cf_visco_limits;

/* Fills l and tabulates the stability bound over rho in [rho_lo, rho_hi]. */
void cf_visco_limits_init(cf_visco_limits *l, const cf_fit_options *design, unsigned types,
                          int cells, const cf_visco_setup *setup, double xlo, double xhi,
                          double rho_lo, double rho_hi, double e_lo, double e_hi);

/* Releases the interpolant. */
void cf_visco_limits_free(cf_visco_limits *l);

/* The smallest s/H allowed at rho (e_lo when stability is not checked). */
double cf_visco_limits_solid_min(const cf_visco_limits *l, double rho);

/* The largest F_C/H^2 (MPa) of a spring within the design limits at (rho, s/H): INFINITY without
** design limits or when a parameter is fixed, 0 when no spring of the allowed types fits there. */
double cf_visco_limits_scale_max(const cf_visco_limits *l, double rho, double B);

/* 1 when the lattice of l->cells^3 cells of the spring (rho, s/H) is stable at the strains xlo
** and xhi (those that are nonzero). */
int cf_visco_limits_stable(const cf_visco_limits *l, double rho, double B);

#endif
