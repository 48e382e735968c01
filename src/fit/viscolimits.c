/*
** The limits of the viscoelastic fit (see viscolimits.h).
*/
#include "fit/viscolimits.h"

#include <math.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_interp.h>

#include "model/cell.h"
#include "model/msm.h"

/* Bisection steps of the stability bound, and its safety margin (relative to s/H): the bound is
** interpolated between grid points, where it is smooth, well within this. */
#define STAB_BISECT 30
#define STAB_MARGIN 2e-3

int cf_visco_limits_stable(const cf_visco_limits *l, double rho, double B)
{
    if (l->cells <= 0)
        return 1;
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring sp = cf_ident_member(&q);
    cf_law law;
    cf_error e = {0};
    if (cf_law_init(&law, &sp, &e) != CF_OK)
        return 0;
    cf_cell cell;
    cf_msm_config cfg = l->setup.cfg;
    cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = l->cells;
    int ok = cf_cell_init(&cell, &law, l->setup.method, cfg.lattice.weight, &e) == CF_OK;
    const double at[2] = {l->xlo, l->xhi};
    for (int side = 0; ok && side < 2; side++) {
        if (at[side] == 0)
            continue;
        cf_cell_state s;
        long neg = -1;
        ok = cf_cell_mode(&cell, CF_MODE_UNIAXIAL, at[side], NULL, &s, &e) == CF_OK &&
             cf_msm_homogeneous_inertia(&law, l->setup.method, &cfg, at[side], s.free_stretch,
                                        &neg, &e) == CF_OK &&
             neg == 0;
    }
    cf_law_free(&law);
    return ok;
}

/* The smallest s/H in [e_lo, e_hi] at which the lattice is stable at xlo and xhi (bisection; the
** lattice is stable for every larger s/H), e_hi when none is. */
static double stable_bound(const cf_visco_limits *l, double rho)
{
    if (cf_visco_limits_stable(l, rho, l->e_lo))
        return l->e_lo;
    double lo = l->e_lo, hi = l->e_hi;
    if (!cf_visco_limits_stable(l, rho, hi))
        return l->e_hi;
    for (int k = 0; k < STAB_BISECT; k++) {
        double mid = 0.5 * (lo + hi);
        if (cf_visco_limits_stable(l, rho, mid))
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

void cf_visco_limits_init(cf_visco_limits *l, const cf_fit_options *design, unsigned types,
                          int cells, const cf_visco_setup *setup, double xlo, double xhi,
                          double rho_lo, double rho_hi, double e_lo, double e_hi)
{
    memset(l, 0, sizeof *l);
    l->design = design;
    l->types = types;
    l->cells = cells;
    l->setup = *setup;
    l->xlo = fmin(xlo, 0.0);
    l->xhi = fmax(xhi, 0.0);
    l->e_lo = e_lo;
    l->e_hi = e_hi;
    l->unstable_everywhere = cells > 0;
    for (int k = 0; k < CF_VISCO_STAB_GRID; k++) {
        l->lrho[k] = log(rho_lo) + (log(rho_hi) - log(rho_lo)) * k / (CF_VISCO_STAB_GRID - 1);
        l->B[k] = cells > 0 ? stable_bound(l, exp(l->lrho[k])) : e_lo;
        if (l->B[k] < e_hi)
            l->unstable_everywhere = 0;
    }
    /* Steffen's method keeps the interpolant monotone between the points (no overshoot below the
    ** tabulated bound) and continuously differentiable */
    if (cells > 0 && (l->interp = gsl_interp_alloc(gsl_interp_steffen, CF_VISCO_STAB_GRID)) &&
        gsl_interp_init(l->interp, l->lrho, l->B, CF_VISCO_STAB_GRID) != GSL_SUCCESS) {
        gsl_interp_free(l->interp);
        l->interp = NULL;
    }
}

double cf_visco_limits_solid_min(const cf_visco_limits *l, double rho)
{
    if (l->cells <= 0)
        return l->e_lo;
    const int n = CF_VISCO_STAB_GRID;
    double x = fmin(fmax(log(rho), l->lrho[0]), l->lrho[n - 1]), B;
    if (l->interp)
        B = gsl_interp_eval(l->interp, l->lrho, l->B, x, NULL);
    else
        B = l->B[0];
    if (!isfinite(B))
        B = l->e_hi;
    if (B <= l->e_lo)
        return l->e_lo;
    return fmin(B * (1 + STAB_MARGIN), l->e_hi);
}

void cf_visco_limits_free(cf_visco_limits *l)
{
    if (l->interp)
        gsl_interp_free(l->interp);
    l->interp = NULL;
}

double cf_visco_limits_scale_max(const cf_visco_limits *l, double rho, double B)
{
    if (!l->design)
        return INFINITY;
    double best = 0;
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        if (!(l->types & (1u << ty)))
            continue;
        double A_max;
        if (cf_fit_ident_limit(l->design, (cf_spring_type)ty, rho, B, &A_max, NULL) <= 0)
            best = fmax(best, A_max);
    }
    return best;
}
