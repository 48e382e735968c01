/*
** The Newton driver over a mechanical system (mech.h): chord steps on the last factors while they
** converge fast, the tangent afresh through the linear solver's cascade otherwise, and a step
** halved until the system admits the state it leads to.
*/
#include "model/mech.h"

#include <math.h>
#include <string.h>

cf_status cf_mech_create(cf_mech *m, size_t n, size_t n_aux, const cf_mech_ops *ops, void *ctx,
                         const int *colp, const int *rowi, cf_error *err)
{
    memset(m, 0, sizeof *m);
    m->n = n;
    m->n_aux = n_aux;
    m->ops = ops;
    m->ctx = ctx;
    m->tol = 0;
    m->step_tol = 0;
    m->max_iter = 200;
    m->chord_rate = 0.25;
    m->max_halvings = 40;
    m->min_alpha = 0x1p-20;
    m->fresh = 1;
    cf_status st = cf_linsolve_create(&m->ls, n + n_aux, colp, rowi, ops->tangent, ctx, 0, err);
    if (st == CF_OK && n_aux > 0)
        cf_linsolve_indefinite(m->ls); /* the auxiliary block is negative definite */
    return st;
}

void cf_mech_free(cf_mech *m)
{
    if (!m)
        return;
    cf_linsolve_free(m->ls);
    m->ls = NULL;
}

static double norm_inf(const double *v, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    return m;
}

/* The direction dx for residual r: from the last factors (a chord step) unless m->fresh, else
** (or when the chord step is refused) from the tangent here. Sets *fresh_used. */
static cf_status direction(cf_mech *m, const double *r, double *dx, int *fresh_used,
                           cf_mech_result *res, cf_error *err)
{
    *fresh_used = 0;
    if (!m->fresh && cf_linsolve_factored(m->ls)) {
        int fatal = 0;
        if (cf_linsolve_chord(m->ls, r, dx, &fatal, err))
            return CF_OK;
        if (fatal)
            return CF_E_INTERNAL;
    }
    cf_status st = cf_linsolve_direction(m->ls, r, dx, NULL, err);
    if (st != CF_OK)
        return st;
    *fresh_used = 1;
    res->factorizations++;
    const long neg = cf_linsolve_neg_pivots(m->ls);
    res->neg_pivots = neg >= (long)m->n_aux ? neg - (long)m->n_aux : -1;
    return CF_OK;
}

/* The step -alpha dx, alpha halved from 1 until the state is admissible. Returns alpha, 0 when no
** admissible state came within max_halvings (the state then back at the origin). */
static double admissible_step(cf_mech *m, const double *dx)
{
    m->ops->save(m->ctx);
    double alpha = 1;
    for (int h = 0; h < m->max_halvings; h++, alpha *= 0.5)
        if (m->ops->trial(m->ctx, dx, alpha))
            return alpha;
    m->ops->trial(m->ctx, dx, 0);
    return 0;
}

cf_status cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res, cf_error *err)
{
    memset(res, 0, sizeof *res);
    res->neg_pivots = -1;
    double rprev = INFINITY;
    cf_status st;
    for (int k = 0; k < m->max_iter; k++) {
        if ((st = m->ops->residual(m->ctx, r, err)) != CF_OK)
            return st;
        const double rn = norm_inf(r, m->n);
        res->rnorm = rn;
        if (rn <= m->tol) {
            res->conv = 1;
            return CF_OK;
        }
        if (!m->fresh && !(rn <= m->chord_rate * rprev))
            m->fresh = 1; /* the old factors no longer converge fast: take the tangent here */
        for (size_t i = m->n; i < m->n + m->n_aux; i++)
            r[i] = 0; /* the auxiliary unknowns' equations hold at every state */
        int fresh_used;
        if ((st = direction(m, r, dx, &fresh_used, res, err)) != CF_OK)
            return st;
        if (m->ops->project)
            m->ops->project(m->ctx, dx);
        m->fresh = 0;
        rprev = rn;
        res->iters++;
        const double alpha = admissible_step(m, dx);
        if (!(alpha >= m->min_alpha)) {
            if (alpha > 0) /* admissible but too short: back to where the step started */
                m->ops->trial(m->ctx, dx, 0);
            res->inadmissible = 1;
            return CF_OK;
        }
        if (alpha < 0.99)
            m->fresh = 1; /* a shortened step: take the tangent where it landed */
        else if (norm_inf(dx, m->n) <= m->step_tol) {
            res->conv = 1; /* a full step below rounding (a cut one says nothing of convergence) */
            return CF_OK;
        }
    }
    return CF_OK;
}
