/*
** The Newton driver over a mechanical system (mech.h): directions from kept factors while they
** converge fast (chord steps, then Krylov steps), the tangent afresh through the linear solver's
** cascade otherwise, and each step halved until the system admits the state it leads to (and,
** where the system asks, until the residual there has dropped).
*/
#include "model/mech.h"

#include <math.h>
#include <string.h>

/* The stages a direction comes from. */
enum { STAGE_FRESH, STAGE_CHORD, STAGE_KRYLOV };

cf_status cf_mech_create(cf_mech *m, size_t n, size_t n_aux, const cf_mech_ops *ops, void *ctx,
                         const int *colp, const int *rowi, int banded_only, cf_error *err)
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
    m->use_krylov = 0;
    m->judge_fresh = 1;
    m->decrease = 0;
    m->accept_after = 0;
    m->max_halvings = 40;
    m->reuse_halvings = 40;
    m->min_alpha = 0x1p-20;
    m->fresh = 1;
    cf_status st =
        cf_linsolve_create(&m->ls, n + n_aux, colp, rowi, ops->tangent, ctx, banded_only, err);
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

/* The tolerance at the state of the last residual, and whether that state may end the
** iteration. */
static double gauge(const cf_mech *m, int *may_end)
{
    *may_end = 1;
    return m->ops->tolerance ? m->ops->tolerance(m->ctx, may_end) : m->tol;
}

/* The residual at the current state, its largest component *rn and the tolerance there. */
static cf_status evaluate(const cf_mech *m, double *r, double *rn, double *tol, int *may_end,
                          cf_mech_result *res, cf_error *err)
{
    cf_status st = m->ops->residual(m->ctx, r, err);
    if (st != CF_OK)
        return st;
    *rn = res->rnorm = norm_inf(r, m->n);
    *tol = gauge(m, may_end);
    return CF_OK;
}

/* The stage of the next direction. */
static int stage_of(const cf_mech *m)
{
    if (m->chord_only)
        return STAGE_CHORD;
    if (m->fresh || !(m->chord_rate > 0) || !cf_linsolve_factored(m->ls))
        return STAGE_FRESH;
    return m->krylov ? STAGE_KRYLOV : STAGE_CHORD;
}

/* A direction of this stage did not do: the next one from the next stage. */
static void escalate(cf_mech *m, int stage)
{
    if (stage == STAGE_CHORD && m->use_krylov)
        m->krylov = 1;
    else
        m->fresh = 1;
}

/* Notes the inertia of the fresh tangent just solved. */
static void note_inertia(const cf_mech *m, cf_mech_result *res)
{
    const long neg = cf_linsolve_neg_pivots(m->ls);
    const long sys = neg >= (long)m->n_aux ? neg - (long)m->n_aux : -1;
    res->tangents++;
    res->neg_pivots = sys;
    if (sys > 0)
        res->indefinite++;
    if (sys > res->neg_pivots_max)
        res->neg_pivots_max = sys;
}

/* The direction dx for residual r from this stage; *got 0 when kept factors refused it (too
** stale: not an error). need is the residual's reduction that would end the iteration (the
** Krylov step's accuracy). CF_E_INTERNAL when memory ran out, the linear solver's error when a
** fresh tangent could not be solved. */
static cf_status direction(cf_mech *m, int stage, const double *r, double *dx, double need,
                           int *got, cf_mech_result *res, cf_error *err)
{
    *got = 0;
    if (stage == STAGE_CHORD && m->ops->chord) {
        cf_status st = m->ops->chord(m->ctx, r, dx, err);
        *got = st == CF_OK;
        res->reused += *got;
        return st;
    }
    if (stage != STAGE_FRESH) {
        int fatal = 0;
        const int ok = stage == STAGE_KRYLOV
                           ? cf_linsolve_krylov(m->ls, r, dx, need, &fatal, err)
                           : cf_linsolve_chord(m->ls, r, dx, &fatal, err);
        if (fatal)
            return CF_E_INTERNAL;
        res->reused += ok;
        *got = ok;
        return CF_OK;
    }
    cf_status st = cf_linsolve_direction(m->ls, r, dx, &res->linear_solves, err);
    note_inertia(m, res);
    if (st != CF_OK)
        return st;
    res->factorizations++;
    m->fresh = 0;
    m->krylov = 0;
    *got = 1;
    return CF_OK;
}

/* The step along dx from the origin (the current state, residual norm rn0), alpha halved from 1
** until the state is acceptable: admissible, and with m->decrease, its residual (into r, norm
** *rn; *evaluated set) lower. Returns alpha, 0 when none came (the state then back at the
** origin); *st an error of the residual (the state then at that trial). */
static double search(cf_mech *m, int stage, const double *dx, double *r, double rn0, double *rn,
                     int *evaluated, cf_status *st, cf_mech_result *res, cf_error *err)
{
    const int halvings = stage == STAGE_FRESH ? m->max_halvings : m->reuse_halvings;
    *evaluated = 0;
    *st = CF_OK;
    m->ops->save(m->ctx);
    double alpha = 1;
    for (int h = 0; h < halvings && alpha >= m->min_alpha; h++, alpha *= 0.5) {
        if (!m->ops->trial(m->ctx, dx, alpha))
            continue;
        if (!(m->decrease > 0))
            return alpha;
        *evaluated = 1;
        if ((*st = m->ops->residual(m->ctx, r, err)) != CF_OK)
            return 0;
        *rn = res->rnorm = norm_inf(r, m->n);
        if (isfinite(*rn) && (*rn < (1 - m->decrease * alpha) * rn0 || h >= m->accept_after))
            return alpha;
    }
    m->ops->trial(m->ctx, dx, 0);
    return 0;
}

/* The last step, for the test of its rate at the next state. */
typedef struct last_step {
    int judged; /* held to chord_rate */
    int stage;
    double alpha, rn0;
} last_step;

/* One Newton step from the state with residual r (norm *rn, tolerance *tol): the direction, the
** step and the residual where it lands. *done 1 when the iteration ends here (converged by a
** full step within step_tol, or no acceptable state from a fresh tangent). */
static cf_status newton_step(cf_mech *m, double *r, double *dx, double *rn, double *tol,
                             int *may_end, last_step *last, int *done, cf_mech_result *res,
                             cf_error *err)
{
    const int stage = stage_of(m);
    for (size_t i = m->n; i < m->n + m->n_aux; i++)
        r[i] = 0; /* the auxiliary unknowns' equations hold at every state */
    int got;
    cf_status st = direction(m, stage, r, dx, *tol / *rn, &got, res, err);
    if (st != CF_OK || !got) {
        if (st == CF_OK)
            escalate(m, stage);
        return st;
    }
    if (m->ops->project)
        m->ops->project(m->ctx, dx);
    const double rn0 = *rn;
    int evaluated;
    const double alpha = search(m, stage, dx, r, rn0, rn, &evaluated, &st, res, err);
    if (st != CF_OK)
        return st;
    if (alpha == 0) {
        if (stage == STAGE_FRESH || m->chord_only) {
            res->inadmissible = 1;
            *done = 1;
            return CF_OK;
        }
        escalate(m, stage); /* stale factors: the next direction does better */
        return evaluated ? evaluate(m, r, rn, tol, may_end, res, err) : CF_OK;
    }
    if (alpha == 1 && m->step_tol > 0 && norm_inf(dx, m->n) <= m->step_tol) {
        res->conv = 1; /* a full step below rounding (a cut one says nothing of convergence) */
        *done = 1;
        return CF_OK;
    }
    *last = (last_step){(stage != STAGE_FRESH || m->judge_fresh) && !m->chord_only, stage, alpha,
                        rn0};
    if (alpha < 1 && m->judge_fresh && !m->chord_only)
        m->fresh = 1; /* a shortened step: the tangent where it landed, converged there or not */
    if (m->last_unevaluated && res->iters == m->max_iter) {
        *done = 1; /* the fixed count reached: the caller reads the state */
        return CF_OK;
    }
    if (!evaluated)
        return evaluate(m, r, rn, tol, may_end, res, err);
    *tol = gauge(m, may_end);
    return CF_OK;
}

cf_status cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res, cf_error *err)
{
    memset(res, 0, sizeof *res);
    res->neg_pivots = res->neg_pivots_max = -1;
    double rn, tol;
    int may_end;
    cf_status st = evaluate(m, r, &rn, &tol, &may_end, res, err);
    last_step last = {0};
    for (int k = 0; st == CF_OK; k++) {
        if (may_end && rn <= tol) {
            res->conv = 1;
            break;
        }
        /* a slow or shortened step: the next direction from the next stage */
        if (last.judged && (last.alpha < 1 || !(rn <= m->chord_rate * last.rn0)))
            escalate(m, last.stage);
        last.judged = 0;
        if (k == m->max_iter)
            break;
        res->iters++;
        int done = 0;
        st = newton_step(m, r, dx, &rn, &tol, &may_end, &last, &done, res, err);
        if (done)
            break;
    }
    return st;
}

cf_status cf_mech_inertia(cf_mech *m, const double *r, double *dx, cf_mech_result *res,
                          cf_error *err)
{
    memset(res, 0, sizeof *res);
    res->neg_pivots = res->neg_pivots_max = -1;
    cf_status st = cf_linsolve_direction(m->ls, r, dx, &res->linear_solves, err);
    note_inertia(m, res);
    res->factorizations += st == CF_OK;
    return st;
}
