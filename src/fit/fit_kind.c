/*
** The generic fit of a law kind (lawkind.h, cf_law_kind_fit): what a kind without a fitter of
** its own gets. Weighted least squares over the logarithms of its quantities within the row's
** range (NLopt BOBYQA, derivative-free and bounded), the errors s^2 (J^T W J)^-1 of the
** quantities, and profile intervals (profile.h) where a quantity sits on its range or is not
** determined. Its spring is the row's member, checked against the design limits.
*/
#include "fit/lawkind.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <nlopt.h>

#include "fit/clock.h"
#include "fit/lsq.h"
#include "fit/profile.h"

typedef struct kfit {
    const cf_law_row *row;
    const cf_table *t;
    int fd, nq;
    double *sw;    /* sqrt(w) / scale per row (lsq.h) */
    long evals;
    int fixed_k;   /* the quantity a profile holds (-1: none) */
    double fixed_u; /* at this log value */
    double z[CF_Q_MAX]; /* the full point of a profile's inner search */
} kfit;

/* Weighted RSS at log quantities z. */
static double wrss(kfit *c, const double *z)
{
    double q[CF_Q_MAX];
    for (int k = 0; k < c->nq; k++)
        q[k] = exp(z[k]);
    double s = 0;
    for (size_t i = 0; i < c->t->count; i++) {
        const double y = c->row->eval(q, c->fd, c->t->x[i]);
        const double r = c->sw[i] * (y - c->t->y[i]);
        s += r * r;
    }
    c->evals++;
    return isfinite(s) ? s : CF_LSQ_HUGE_OBJ;
}

/* NLopt's objective: the free quantities x, with a profile's held one put back in place. */
static double nl_obj(unsigned n, const double *x, double *grad, void *data)
{
    (void)grad;
    kfit *c = data;
    for (int k = 0, j = 0; k < c->nq; k++)
        c->z[k] = k == c->fixed_k ? c->fixed_u : x[j++];
    (void)n;
    return wrss(c, c->z);
}

/* Minimises over the free quantities (all but fixed_k) from z within [lo, hi]; z moves to the
** minimiser. Returns its weighted RSS, or CF_LSQ_HUGE_OBJ when NLopt cannot run. */
static double minimise(kfit *c, double *z, const double *lo, const double *hi, double xtol)
{
    double x[CF_Q_MAX], l[CF_Q_MAX], h[CF_Q_MAX];
    unsigned n = 0;
    for (int k = 0; k < c->nq; k++)
        if (k != c->fixed_k)
            x[n] = z[k], l[n] = lo[k], h[n] = hi[k], n++;
    if (n == 0)
        return wrss(c, z);
    nlopt_opt o = nlopt_create(n >= 2 ? NLOPT_LN_BOBYQA : NLOPT_LN_COBYLA, n);
    if (!o)
        return CF_LSQ_HUGE_OBJ;
    double f = CF_LSQ_HUGE_OBJ;
    nlopt_set_min_objective(o, nl_obj, c);
    nlopt_set_lower_bounds(o, l);
    nlopt_set_upper_bounds(o, h);
    nlopt_set_xtol_rel(o, xtol);
    nlopt_set_ftol_rel(o, 1e-15);
    nlopt_set_maxeval(o, 4000 * (int)n);
    nlopt_result rc = nlopt_optimize(o, x, &f);
    nlopt_destroy(o);
    if (rc < 0)
        f = wrss(c, z); /* the start stands */
    else
        for (int k = 0, j = 0; k < c->nq; k++)
            if (k != c->fixed_k)
                z[k] = x[j++];
    return f;
}

/* The errors of the quantities (linear units) from J^T W J by central differences in log q:
** se_k = q_k sqrt(s^2 [(J^T W J)^-1]_kk), and their correlation. Returns 1 when J^T W J is
** singular (smallest singular value of its unit-diagonal form below 1e-10 of the largest), -1
** when memory runs out, else 0. */
static int errors(kfit *c, const double *z, double wrss0, cf_fit_result *res)
{
    const size_t n = c->t->count;
    const int m = c->nq;
    for (int a = 0; a < CF_Q_MAX; a++) {
        res->q_se[a] = a < m ? -1 : 0;
        for (int b = 0; b < CF_Q_MAX; b++)
            res->corr[a][b] = NAN;
    }
    if (n <= (size_t)m)
        return 1;
    gsl_matrix *J = gsl_matrix_alloc(n, (size_t)m);
    gsl_matrix *A = gsl_matrix_calloc((size_t)m, (size_t)m);
    gsl_matrix *V = gsl_matrix_alloc((size_t)m, (size_t)m);
    gsl_vector *S = gsl_vector_alloc((size_t)m), *W = gsl_vector_alloc((size_t)m);
    int ret = -1;
    if (!J || !A || !V || !S || !W)
        goto done;
    double q[CF_Q_MAX];
    for (int k = 0; k < m; k++)
        q[k] = exp(z[k]);
    for (int k = 0; k < m; k++) {
        double qp[CF_Q_MAX], qm[CF_Q_MAX];
        memcpy(qp, q, sizeof q);
        memcpy(qm, q, sizeof q);
        const double h = 1e-6;
        qp[k] = q[k] * exp(h);
        qm[k] = q[k] * exp(-h);
        for (size_t i = 0; i < n; i++) {
            const double d = (c->row->eval(qp, c->fd, c->t->x[i]) -
                              c->row->eval(qm, c->fd, c->t->x[i])) / (2 * h);
            gsl_matrix_set(J, i, (size_t)k, c->sw[i] * d);
        }
    }
    gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, J, J, 0.0, A);
    double dg[CF_Q_MAX];
    int ok = 1;
    for (int k = 0; k < m; k++) {
        dg[k] = sqrt(gsl_matrix_get(A, (size_t)k, (size_t)k));
        ok = ok && dg[k] > 0 && isfinite(dg[k]);
    }
    ret = 1;
    if (!ok)
        goto done;
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++)
            gsl_matrix_set(A, (size_t)a, (size_t)b,
                           gsl_matrix_get(A, (size_t)a, (size_t)b) / (dg[a] * dg[b]));
    if (gsl_linalg_SV_decomp(A, V, S, W) != GSL_SUCCESS ||
        !(gsl_vector_get(S, (size_t)m - 1) > 1e-10 * gsl_vector_get(S, 0)))
        goto done;
    /* A = U S V^T is symmetric: its inverse is V S^-1 U^T */
    const double s2 = wrss0 / (double)(n - (size_t)m);
    double cov[CF_Q_MAX][CF_Q_MAX];
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++) {
            double v = 0;
            for (int j = 0; j < m; j++)
                v += gsl_matrix_get(V, (size_t)a, (size_t)j) *
                     gsl_matrix_get(A, (size_t)b, (size_t)j) / gsl_vector_get(S, (size_t)j);
            cov[a][b] = s2 * v / (dg[a] * dg[b]);
        }
    for (int a = 0; a < m; a++)
        res->q_se[a] = q[a] * sqrt(fmax(cov[a][a], 0.0));
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++)
            res->corr[a][b] = fmax(-1.0, fmin(1.0, cov[a][b] / sqrt(cov[a][a] * cov[b][b])));
    ret = 0;
done:
    gsl_matrix_free(J);
    gsl_matrix_free(A);
    gsl_matrix_free(V);
    gsl_vector_free(S);
    gsl_vector_free(W);
    return ret;
}

typedef struct pctx {
    kfit *c;
    const double *lo, *hi;
    double xtol;
} pctx;

/* The profile's RSS with quantity k at exp(u): the others minimised from x (the full point). */
static double prof_at(void *ctx, int k, double u, double limit, double *x)
{
    pctx *p = ctx;
    (void)limit;
    double z[CF_Q_MAX];
    memcpy(z, x, sizeof z);
    p->c->fixed_k = k;
    p->c->fixed_u = u;
    z[k] = u;
    const double f = minimise(p->c, z, p->lo, p->hi, p->xtol);
    p->c->fixed_k = -1;
    if (f <= limit)
        memcpy(x, z, sizeof z);
    return f;
}

static unsigned prof_closed(void *ctx, int k, double u, const double *x)
{
    (void)ctx, (void)k, (void)u, (void)x;
    return CF_C_BOUNDS;
}

static void prof_start(void *ctx, int k, const double *v, double *x)
{
    pctx *p = ctx;
    (void)k;
    for (int j = 0; j < CF_Q_MAX; j++)
        x[j] = j < p->c->nq ? log(v[j]) : 0;
}

/* Profile intervals where a quantity sits on its range or has no error: every quantity then, as
** the other fitters do (profile.h). */
static void intervals(kfit *c, const double *z, double wrss0, double ynorm, const double *lo,
                      const double *hi, double xtol, int singular, cf_fit_result *res)
{
    unsigned why = singular ? CF_FIT_RANK_DEFICIENT : 0;
    for (int k = 0; k < c->nq; k++)
        if (z[k] <= lo[k] + 1e-6 || z[k] >= hi[k] - 1e-6)
            why |= CF_C_BOUNDS;
    if (!why)
        return;
    pctx p = {c, lo, hi, xtol};
    cf_profile pr;
    memset(&pr, 0, sizeof pr);
    pr.ctx = &p;
    for (int k = 0; k < c->nq; k++) {
        pr.lo[k] = lo[k], pr.hi[k] = hi[k];
        pr.lo_bit[k] = pr.hi_bit[k] = CF_C_BOUNDS;
    }
    pr.at = prof_at;
    pr.closed = prof_closed;
    pr.start = prof_start;
    const double limit = cf_profile_limit_np(c->t->count, c->nq, wrss0, ynorm);
    for (int k = 0; k < c->nq; k++) {
        cf_profile_interval(&pr, k, res->q, limit, res->q_se[k], res->interval[k],
                            res->interval_end[k]);
        res->interval_ok[k] = 1;
        res->interval_why[k] = why;
    }
}

/* Fills res from the optimum z: quantities, quality, spring and its check. */
static void summarise(kfit *c, const cf_fit_options *opt, cf_spring_type type, const double *z,
                      double *model, cf_fit_result *res)
{
    for (int k = 0; k < c->nq; k++)
        res->q[k] = exp(z[k]);
    for (size_t i = 0; i < c->t->count; i++)
        model[i] = c->row->eval(res->q, c->fd, c->t->x[i]);
    cf_lsq_quality ql = cf_lsq_quality_of(c->t, model);
    res->rss = ql.rss;
    res->rmse = ql.rmse;
    res->max_abs_error = ql.max_abs_error;
    res->r2 = ql.r2;
    res->params = c->row->member(res->q, c->fd, type);
    /* the kind's own law where its row brings its mechanics (lawmech.h: quantities of a
    ** stress-strain fit), else the conical law of its member */
    if (!c->row->mech || c->fd ||
        cf_law_init_kind(&res->law, c->row->mech, res->q, res->params.H_mm, NULL) != CF_OK)
        cf_law_init(&res->law, &res->params, NULL);
    res->feasible = cf_fit_check(&res->params, type, c->t, opt, &res->active, &res->violated);
    const cf_ident fam = cf_ident_of_type(&res->params, type, c->fd);
    const double xmax = cf_lsq_xmax(c->t);
    res->solid_table_strain = fam.solid;
    res->solid_ratio = xmax > 0 ? fam.solid / xmax : INFINITY;
}

static cf_status generic_fit(const cf_law_row *row, const cf_table *t, const cf_fit_options *opt,
                             cf_spring_type type, cf_fit_result *res, cf_error *err)
{
    if (!row->eval || !row->range || !row->member || row->nq < 1 || row->nq > CF_Q_MAX)
        return cf_error_set(err, CF_E_INTERNAL, "law kind '%s' has neither a fitter nor a "
                                                "complete set of evaluators", row->name);
    if (t->count <= (size_t)row->nq)
        return cf_error_set(err, CF_E_DATA, "%s: %zu rows cannot determine the %d quantities "
                                            "of the %s", t->path, t->count, row->nq, row->title);
    const double t0 = cf_clock_s();
    kfit c = {row, t, cf_table_is_force(t), row->nq, NULL, 0, -1, 0, {0}};
    c.sw = malloc(t->count * sizeof *c.sw);
    double *model = malloc(t->count * sizeof *model);
    if (!c.sw || !model) {
        free(c.sw);
        free(model);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu rows", t->count);
    }
    const double ynorm = cf_lsq_weights(t, opt->relative, c.sw);
    double start[CF_Q_MAX], lo[CF_Q_MAX], hi[CF_Q_MAX], z[CF_Q_MAX] = {0};
    row->range(t, start, lo, hi);
    for (int k = 0; k < row->nq; k++) {
        lo[k] = log(lo[k]), hi[k] = log(hi[k]), z[k] = log(start[k]);
        if (!(lo[k] <= z[k] && z[k] <= hi[k])) {
            free(c.sw);
            free(model);
            return cf_error_set(err, CF_E_INTERNAL, "law kind '%s': quantity %s has no "
                                "positive range around its start", row->name, row->q[k].key);
        }
    }
    memset(res, 0, sizeof *res);
    res->kind = row;
    res->type = type;
    const double f = minimise(&c, z, lo, hi, opt->xtol_rel);
    res->objective = f;
    res->objective_zero = ynorm;
    summarise(&c, opt, type, z, model, res);
    const int se = errors(&c, z, f, res);
    if (se >= 0)
        intervals(&c, z, f, ynorm, lo, hi, opt->xtol_rel, se == 1, res);
    free(c.sw);
    free(model);
    if (se < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the errors of %zu rows",
                            t->count);
    res->optimizer = "bobyqa";
    res->evaluations = res->evaluations_full = c.evals;
    res->wall_time_s = cf_clock_s() - t0;
    return CF_OK;
}

cf_status cf_law_kind_fit(const cf_law_row *row, const cf_table *t, const cf_fit_options *opt,
                          cf_spring_type type, const cf_fit_result *plain, cf_fit_result *res,
                          cf_error *err)
{
    cf_status st = row->fit ? row->fit(t, opt, type, plain, res, err)
                            : generic_fit(row, t, opt, type, res, err);
    if (st == CF_OK)
        res->kind = row;
    return st;
}
