/*
** Tissue bodies (body.h): the workspace the solves keep between calls, and the body as a
** mechanical system (mech.h) for the Newton driver: its residual, its tangent written into the
** linear solver's values, held components and admissible steps.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* The residual: the energy's gradient with the probe's contact and an implicit step's inertia,
** zero at the held components; the probe's reaction kept in the system. */
static cf_status sys_residual(void *ctx, double *r, cf_error *err)
{
    body_sys *s = ctx;
    s->force = cf_body_assemble(s->b, s->b->x, s->probe, s->c, s->kp, s->w->active, r, NULL,
                                &s->contacts);
    if (isnan(s->force))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
    cf_body_add_inertia(s->b, s->w, s->b->x, r, NULL);
    cf_body_apply_fixed(s->b, NULL, r);
    return CF_OK;
}

/* The tangent at the current state into v (the linear solver's values, the pattern's order). */
static void sys_tangent(void *ctx, double *v)
{
    body_sys *s = ctx;
    pattern *P = s->P;
    double *keep = P->val;
    P->val = v;
    /* the memory for the volume term's scratch ran out: the values are NaN, which the solver's
    ** cascade refuses (the sparse factorisation's finiteness check) */
    if (isnan(cf_body_assemble(s->b, s->b->x, s->probe, s->c, s->kp, s->w->active, s->w->gt, P,
                               NULL)))
        for (size_t k = 0; k < (size_t)P->colptr[P->n]; k++)
            v[k] = NAN;
    cf_body_add_inertia(s->b, s->w, s->b->x, s->w->gt, P);
    cf_body_apply_fixed(s->b, P, s->w->gt);
    P->val = keep;
}

static void sys_project(void *ctx, double *dx)
{
    const cf_body *b = ((body_sys *)ctx)->b;
    for (size_t i = 0; i < b->nn; i++)
        for (int a = 0; a < 3; a++)
            if ((b->fix[i] >> a) & 1)
                dx[3 * i + (size_t)a] = 0;
}

static void sys_save(void *ctx)
{
    body_sys *s = ctx;
    memcpy(s->w->xt, s->b->x, 3 * s->b->nn * sizeof *s->w->xt);
}

static int sys_trial(void *ctx, const double *dx, double alpha)
{
    body_sys *s = ctx;
    for (size_t i = 0; i < 3 * s->b->nn; i++)
        s->b->x[i] = s->w->xt[i] - alpha * dx[i];
    return cf_body_admissible(s->b, s->b->x);
}

static const cf_mech_ops body_ops = {sys_residual, sys_tangent, sys_project, sys_save, sys_trial,
                                     NULL, NULL};

void cf_body_work_free(body_work *w)
{
    if (!w)
        return;
    cf_mech_free(&w->mech);
    cf_mech_free(&w->hmech); /* the haptic loop's system (body_haptic.c) */
    free(w->hsys.list);
    free(w->hsys.nv);
    free(w->hsys.M);
    free(w->hsys.rhs);
    free(w->hactive);
    free(w->slot);
    free(w->Z);
    free(w->hgi);
    free(w->hxg);
    free(w->hrhs);
    cf_body_pattern_free(&w->P);
    cf_body_pattern_free(&w->Pa);
    free(w->g);
    free(w->dx);
    free(w->xt);
    free(w->gt);
    free(w->active);
    free(w->touch);
    free(w->xs);
    free(w);
}

/* The linear solver with the pattern of the static solve (the augmented form's with a volume
** term, else the condensed one's), which then serves as that pattern's own (one copy). */
static cf_status work_mech(cf_body *b, body_work *w, cf_error *err)
{
    const int aug = b->kappa_MPa > 0;
    pattern *P = aug ? &w->Pa : &w->P;
    if (aug && !cf_body_pattern_build(b, P, 1))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    w->sys.b = b;
    w->sys.w = w;
    w->sys.P = P;
    cf_status st = cf_mech_create(&w->mech, 3 * b->nn, aug ? b->nn : 0, &body_ops, &w->sys,
                                  P->colptr, P->rowidx, 0, err);
    if (st != CF_OK)
        return st;
    const int *colp, *rowi;
    cf_linsolve_pattern(w->mech.ls, &colp, &rowi);
    free(P->colptr);
    free(P->rowidx);
    P->colptr = (int *)colp; /* read only, by the assembly and the haptic loop's factors */
    P->rowidx = (int *)rowi;
    P->borrowed = 1;
    /* converged when the residual is below 1e-8 of the body's force scale, or a full step below
    ** rounding */
    w->mech.tol = 1e-8 * b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    w->mech.step_tol = 1e-14 * b->mean_edge_mm;
    return CF_OK;
}

/* The workspace without the condensed pattern (with a volume term the static solve needs only the
** augmented one). */
static cf_status work_make(cf_body *b, body_work **out, cf_error *err)
{
    const size_t n = 3 * b->nn, na = n + (b->kappa_MPa > 0 ? b->nn : 0);
    body_work *w = calloc(1, sizeof *w);
    if (!w || (!(b->kappa_MPa > 0) && !cf_body_pattern_build(b, &w->P, 0))) {
        free(w);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    }
    w->g = malloc(na * sizeof *w->g);
    w->dx = malloc(na * sizeof *w->dx);
    w->xt = malloc(n * sizeof *w->xt);
    w->gt = malloc(n * sizeof *w->gt);
    w->active = malloc(b->nn);
    w->touch = malloc(b->nn);
    w->neg_last = -1;
    cf_status st = CF_OK;
    if (!w->g || !w->dx || !w->xt || !w->gt || !w->active || !w->touch ||
        !cf_body_touchable(b, w->touch))
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    else
        st = work_mech(b, w, err);
    if (st != CF_OK) {
        cf_body_work_free(w);
        return st;
    }
    b->work = w;
    *out = w;
    return CF_OK;
}

cf_status cf_body_work_static(cf_body *b, body_work **out, cf_error *err)
{
    if (b->work) {
        *out = b->work;
        return CF_OK;
    }
    return work_make(b, out, err);
}

cf_status cf_body_work_get(cf_body *b, body_work **out, cf_error *err)
{
    cf_status st = cf_body_work_static(b, out, err);
    if (st != CF_OK || (*out)->P.colptr)
        return st;
    /* the haptic loop's condensed pattern, made at its first call */
    if (!cf_body_pattern_build(b, &(*out)->P, 0))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    return CF_OK;
}
