/*
** The fit of the conical-tail law (fit.h, cf_fit_tail_run): the cone's three identifiable quantities
** and the tail's compliance e_t, then a buildable spring of that family placed in closed form.
**
** A table sees the series spring as y = A g(x/B; rho, tau): g the canonical law of a cone of travel
** 1 and solid load 1 with a tail of tau = n_t/n coils per cone coil (law.h), A the load scale and
** B the length scale as for the plain law (family.h), and the tail's compliance e_t = tau B
** (F_C/(k_t H) of a stress-strain table, F_C/k_t in mm of a force table). The search: a grid over
** (rho, B, tau) with A in closed form (the model is linear in it), then Levenberg-Marquardt (GSL,
** central differences) in (logit rho, logit B, log A, log tau) from the best grid points and from
** the plain fit's quantities with a small tail; standard errors from the Jacobian at the optimum.
** The standard errors, the placement of a buildable spring and the profile intervals are tail.c's,
** shared with the fits through the cell.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>

#include "fit/clock.h"
#include "base/gslguard.h"
#include "fit/fit_ctx.h"
#include "fit/lm.h"
#include "fit/lsq.h"
#include "fit/profile.h"
#include "fit/tail.h"

#define TAIL_GRID_RHO 10
#define TAIL_GRID_B 12
#define TAIL_GRID_TAU 9
#define TAIL_STARTS 6
#define TAIL_SEARCH_ROWS 1000 /* the grid runs on at most this many rows, evenly spaced */

typedef struct tail_ctx {
    const cf_table *data;
    const cf_fit_options *opt;
    int fd;
    size_t n;
    const double *sw; /* residual weights (lsq.h) */
    double ynorm;
    double *t, *g;    /* scratch: x/B and the canonical law at it */
    double rho_lo, rho_hi, b_lo, b_hi;
    size_t stride;    /* the grid's row stride */
    cf_spring_type type;
    double need;      /* the table's largest strain with the travel margin (stress-strain) */
    long evals;
} tail_ctx;

/* The canonical tailed law: the family's canonical cone (family.c: travel 1, solid load 1) with
** 2 tau tail coils of its wire and a tail travel so long that the data never reach its solid. */
static cf_status tail_canon(double rho, double tau, cf_law *law)
{
    const double n = 2.0, d = 0.5, nt = n * tau, st = tau * (1.0 + 1e6);
    cf_spring p = {rho, 1.0, n, d, 256.0 * rho * rho * rho, 2.0 + nt * d + st};
    p.n_tail = nt;
    p.H_tail_mm = nt * d + st;
    return cf_law_init(law, &p, NULL);
}

/* The canonical law at x[i]/B for the rows i = 0, stride, 2 stride, ... (into c->g, compacted);
** returns how many. */
static size_t canon_rows(tail_ctx *c, const cf_law *canon, double B, size_t stride)
{
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride)
        c->t[m++] = c->data->x[i] / B;
    cf_law_force_many(canon, CF_LAW_CLOSED, m, c->t, c->g, NULL);
    c->evals++;
    return m;
}

/* The weighted RSS with A in closed form (rows by stride); *A_out the load scale. */
static double tail_profile(tail_ctx *c, double rho, double B, double tau, size_t stride,
                           double *A_out)
{
    cf_law canon;
    *A_out = 0;
    if (tail_canon(rho, tau, &canon) != CF_OK)
        return INFINITY;
    canon_rows(c, &canon, B, stride);
    double sgy = 0, sgg = 0, syy = 0;
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride, m++) {
        const double g = c->sw[i] * c->g[m], y = c->sw[i] * c->data->y[i];
        sgy += g * y;
        sgg += g * g;
        syy += y * y;
    }
    const double A = sgg > 0 ? sgy / sgg : 0;
    if (!(A > 0) || !isfinite(A))
        return syy;
    *A_out = A;
    return fmax(syy - A * sgy, 0.0);
}

/* The weighted RSS at a given load scale A (rows by stride). */
static double tail_objective(tail_ctx *c, double rho, double B, double tau, double A,
                             size_t stride)
{
    cf_law canon;
    if (tail_canon(rho, tau, &canon) != CF_OK)
        return INFINITY;
    canon_rows(c, &canon, B, stride);
    double rss = 0;
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride, m++) {
        const double r = c->sw[i] * (A * c->g[m] - c->data->y[i]);
        rss += r * r;
    }
    return rss;
}

/* ---- Levenberg-Marquardt in (logit rho, logit B, log A, log tau) ----------------------------- */

static double amax_at(const tail_ctx *c, double rho, double B, double tau);

static double tau_of(const tail_ctx *c, double B, double th3)
{
    return cf_tail_tau(c->fd, B, th3);
}

static double th3_of(const tail_ctx *c, double B, double tau)
{
    return cf_tail_coord(c->fd, B, tau);
}

/* The load scale: of a stress-strain table below the largest a spring of the family carries with
** G <= G_max (a logit of A/A_max), of a force table free (log A). */
static void unpack(const tail_ctx *c, const double *th, double v[4])
{
    v[0] = c->rho_lo + (c->rho_hi - c->rho_lo) * cf_logistic(th[0]);
    v[1] = c->b_lo + (c->b_hi - c->b_lo) * cf_logistic(th[1]);
    v[3] = fmin(tau_of(c, v[1], th[3]), cf_tail_tau_max(c->opt));
    v[2] = c->fd ? exp(th[2]) : amax_at(c, v[0], v[1], v[3]) * cf_logistic(th[2]);
}

/* Weighted residuals at the quantities v = (rho, B, A, tau), scaled by sc; GSL_EDOM where the
** law has no spring. */
static int residuals(tail_ctx *c, const double v[4], double sc, gsl_vector *f)
{
    cf_law canon;
    if (!isfinite(v[2]) || tail_canon(v[0], v[3], &canon) != CF_OK)
        return GSL_EDOM;
    canon_rows(c, &canon, v[1], 1);
    for (size_t i = 0; i < c->n; i++)
        gsl_vector_set(f, i, sc * c->sw[i] * (v[2] * c->g[i] - c->data->y[i]));
    return GSL_SUCCESS;
}

static int resid_at(void *ctx, const double v[4], gsl_vector *f)
{
    return residuals(ctx, v, 1.0, f);
}

/* The weighted residuals of the rows by c->stride, each times sqrt(stride): the subsample's RSS
** stands for the whole table's, so that a long table's profiles cost what its grid costs, not a
** pass over every row per point. With stride 1 they are resid_at's. */
static int resid_stride(void *ctx, const double v[4], gsl_vector *f)
{
    tail_ctx *c = ctx;
    cf_law canon;
    if (!isfinite(v[2]) || tail_canon(v[0], v[3], &canon) != CF_OK)
        return GSL_EDOM;
    canon_rows(c, &canon, v[1], c->stride);
    const double w = sqrt((double)c->stride);
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += c->stride, m++)
        gsl_vector_set(f, m, w * c->sw[i] * (v[2] * c->g[m] - c->data->y[i]));
    return GSL_SUCCESS;
}

static int lm_f(const gsl_vector *th, void *params, gsl_vector *f)
{
    tail_ctx *c = params;
    double v[4];
    unpack(c, th->data, v);
    return residuals(c, v, 1.0 / sqrt(c->ynorm), f);
}

/* One LM run from v0 (rho, B, A, tau); returns the weighted RSS and the optimum in out. */
static double lm_run(tail_ctx *c, const double v0[4], double out[4])
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.fdtype = GSL_MULTIFIT_NLINEAR_CTRDIFF;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.n = c->n;
    fdf.p = 4;
    fdf.params = c;
    double th0[4] = {cf_logit((v0[0] - c->rho_lo) / (c->rho_hi - c->rho_lo)),
                     cf_logit((v0[1] - c->b_lo) / (c->b_hi - c->b_lo)),
                     c->fd ? log(v0[2]) : cf_logit(v0[2] / amax_at(c, v0[0], v0[1], v0[3])),
                     th3_of(c, v0[1], fmin(v0[3], cf_tail_tau_max(c->opt)))};
    int ist;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, th0, &ist);
    if (!w)
        return INFINITY;
    double best = INFINITY;
    if (ist == GSL_SUCCESS) {
        cf_lm_stop stop = {LM_MAX_ITER, 1e-15, 1e-15, 1e-15, LM_STALL, LM_STALL_REL, LM_FLOOR_REL};
        cf_lm_iterate(w, &stop);
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        double chi2;
        gsl_blas_ddot(f, f, &chi2);
        if (isfinite(chi2)) {
            unpack(c, gsl_multifit_nlinear_position(w)->data, out);
            best = chi2 * c->ynorm;
        }
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

typedef struct tail_start {
    double obj, v[4];
} tail_start;

static int cmp_start(const void *a, const void *b)
{
    const double x = ((const tail_start *)a)->obj, y = ((const tail_start *)b)->obj;
    return (x > y) - (x < y);
}

static double amax_at(const tail_ctx *c, double rho, double B, double tau)
{
    return cf_tail_A_max(rho, B, tau, c->type, c->need, c->opt);
}

/* ---- the fit --------------------------------------------------------------------------------- */

/* The fit's context over table data (its weights and scratch in buf, 3 n doubles): the ranges
** the search takes and the rows its grid and profiles run on. */
static void ctx_init(tail_ctx *c, const cf_table *data, const cf_fit_options *opt,
                     cf_spring_type type, double *buf)
{
    memset(c, 0, sizeof *c);
    c->data = data;
    c->opt = opt;
    c->fd = cf_table_is_force(data);
    c->n = data->count;
    double *sw = buf;
    c->t = buf + c->n;
    c->g = c->t + c->n;
    c->ynorm = cf_lsq_weights(data, opt->relative, sw);
    c->sw = sw;
    const double xmax = cf_lsq_xmax(data);
    c->type = type;
    c->need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    c->rho_lo = fmax(CF_IDENT_RHO_LO, opt->rho_min * (1 - CF_IDENT_RHO_MIN_TOL));
    c->rho_hi = cf_ident_rho_hi(type, opt->index_max);
    /* the cone may close inside the data (the tail carries on); a stress-strain table's cone
    ** travel is below 1 */
    c->b_lo = 1e-3 * xmax;
    c->b_hi = c->fd ? 1e3 * xmax : 1 - 1e-9;
    c->stride = c->n > TAIL_SEARCH_ROWS ? (c->n + TAIL_SEARCH_ROWS - 1) / TAIL_SEARCH_ROWS : 1;
}

/* The weighted RSS of c's profile rows at v (rho, B, A, tau); CF_LSQ_HUGE_OBJ where the law has
** no value. */
static double stride_rss(tail_ctx *c, const double v[4])
{
    const size_t m = (c->n + c->stride - 1) / c->stride;
    gsl_vector *fv = gsl_vector_alloc(m);
    double rss = CF_LSQ_HUGE_OBJ;
    if (fv && resid_stride(c, v, fv) == GSL_SUCCESS) {
        gsl_blas_ddot(fv, fv, &rss);
        rss = isfinite(rss) ? rss : CF_LSQ_HUGE_OBJ;
    }
    gsl_vector_free(fv);
    return rss;
}

/* Whether two points (rho, B, A, tau) agree to 1e-3 of each coordinate. */
static int same_point(const double a[4], const double b[4])
{
    for (int k = 0; k < 4; k++)
        if (!(fabs(a[k] - b[k]) <= 1e-3 * fmax(fabs(a[k]), fabs(b[k]))))
            return 0;
    return 1;
}

static cf_tail_profile profile_of(tail_ctx *c)
{
    const cf_tail_profile tp = {resid_stride, c, (c->n + c->stride - 1) / c->stride, c->ynorm,
                                c->opt, c->type, c->fd, c->need, c->rho_lo, c->rho_hi, c->b_lo,
                                c->b_hi};
    return tp;
}

/* The fit's search: a grid over (rho, B, tau) with A in closed form, then Levenberg-Marquardt from
** its best points and from the plain fit (may be NULL) with a small tail. The best point goes to v
** (its objective returned, INFINITY when none), every start's end to ends and end_obj, *ns of
** them. */
static double tail_search(tail_ctx *c, const cf_fit_result *plain, double v[4],
                          double ends[TAIL_STARTS + 2][4], double *end_obj, int *ns_out)
{
    const double xmax = cf_lsq_xmax(c->data);

    /* the grid over (rho, B, tau), A in closed form */
    tail_start grid[TAIL_GRID_RHO * TAIL_GRID_B * TAIL_GRID_TAU];
    size_t k = 0;
    for (int i = 0; i < TAIL_GRID_RHO; i++) {
        const double rho = c->rho_lo * pow(c->rho_hi / c->rho_lo, (i + 0.5) / TAIL_GRID_RHO);
        for (int j = 0; j < TAIL_GRID_B; j++) {
            const double Bmax = c->fd ? 5 * xmax : fmin(0.999, 5 * xmax);
            const double B = 0.1 * xmax * pow(Bmax / (0.1 * xmax), (j + 0.5) / TAIL_GRID_B);
            if (!(B > c->b_lo && B < c->b_hi))
                continue;
            for (int l = 0; l < TAIL_GRID_TAU; l++) {
                const double tau = 1e-3 * pow(1e5, (double)l / (TAIL_GRID_TAU - 1));
                if ((!c->fd && B * (1 + tau) >= 1) || tau > cf_tail_tau_max(c->opt))
                    continue;
                double A;
                grid[k].obj = tail_profile(c, rho, B, tau, c->stride, &A);
                if (!c->fd && A > 0.999 * amax_at(c, rho, B, tau)) {
                    /* beyond what a spring carries: the profile at the limit */
                    A = 0.999 * amax_at(c, rho, B, tau);
                    grid[k].obj = tail_objective(c, rho, B, tau, A, c->stride);
                }
                grid[k].v[0] = rho, grid[k].v[1] = B, grid[k].v[2] = A, grid[k].v[3] = tau;
                if (A > 0)
                    k++;
            }
        }
    }
    qsort(grid, k, sizeof grid[0], cmp_start);
    /* LM from the best grid points and from the plain fit with a small tail */
    double best = INFINITY;
    v[0] = 0.5, v[1] = 0.5 * (c->b_lo + c->b_hi), v[2] = 1, v[3] = 0.1;
    tail_start starts[TAIL_STARTS + 2];
    int ns = 0;
    for (size_t i = 0; i < k && ns < TAIL_STARTS; i++)
        starts[ns++] = grid[i];
    if (plain && plain->ident.rho > 0 && plain->ident.solid > c->b_lo && plain->ident.solid < c->b_hi) {
        const double taus[2] = {1e-3, 0.1};
        for (int q = 0; q < 2; q++) {
            starts[ns].v[0] = fmin(fmax(plain->ident.rho, c->rho_lo * 1.001), c->rho_hi * 0.999);
            starts[ns].v[1] = plain->ident.solid / (1 + taus[q]);
            starts[ns].v[2] = plain->ident.scale;
            starts[ns].v[3] = taus[q];
            ns++;
        }
    }
    for (int i = 0; i < ns; i++) {
        double out[4];
        if (!c->fd)
            starts[i].v[2] = fmin(starts[i].v[2],
                                  0.999 * amax_at(c, starts[i].v[0], starts[i].v[1], starts[i].v[3]));
        const double obj = lm_run(c, starts[i].v, out);
        memcpy(ends[i], out, sizeof out);
        end_obj[i] = obj;
        if (obj < best) {
            best = obj;
            memcpy(v, out, sizeof out);
        }
    }
    *ns_out = ns;
    return best;
}

/* The end of the search within limit_obj of its objective that lies farthest from v (in the
** largest log ratio of a coordinate; none within 1e-3 of v): the profiles' second start
** (cf_tail_profile.alt), which reaches a piece of a flat valley that a local search from v does
** not; 1 when there is one, else 0. One is enough on the published tables: every other one as
** well moved no interval end by more than 0.16 of its distance from the value and cost up to half
** again the tailed fit (the thrombus table 1.2 -> 1.8 s). */
static int tail_alternative(double ends[TAIL_STARTS + 2][4], const double *end_obj, int ns,
                            const double v[4], double limit_obj, double alt[4])
{
    double far = 0;
    for (int i = 0; i < ns; i++) {
        if (!(end_obj[i] <= limit_obj) || same_point(ends[i], v))
            continue;
        double d = 0;
        for (int k = 0; k < 4; k++)
            d = fmax(d, fabs(log(ends[i][k] / v[k])));
        if (d > far) {
            far = d;
            memcpy(alt, ends[i], 4 * sizeof(double));
        }
    }
    return far > 0;
}

double cf_tail_profile_at(const cf_table *data, const cf_fit_options *opt,
                          const cf_fit_result *plain, const cf_fit_result *fit, int k,
                          double value, double *limit)
{
    *limit = NAN;
    const size_t n = data->count;
    double *buf = n >= 6 ? malloc(3 * sizeof(double) * n) : NULL;
    if (!buf)
        return NAN;
    tail_ctx c;
    ctx_init(&c, data, opt, fit->type, buf);
    const double B = fit->ident.solid, tau = fit->q[CF_Q_TAIL] / B;
    const double v[4] = {fit->ident.rho, B, fit->ident.scale, tau};
    const double rss = fit->objective, rss0 = stride_rss(&c, v);
    *limit = rss0 + cf_profile_limit_np(n, 4, rss, c.ynorm) - rss;
    cf_tail_profile tp = profile_of(&c);
    /* the fit's search again, for its other optima (the profiles' second starts) */
    double w[4], ends[TAIL_STARTS + 2][4], end_obj[TAIL_STARTS + 2], alt[1][4];
    int ns = 0;
    const double best = tail_search(&c, plain, w, ends, end_obj, &ns);
    tp.nalt = tail_alternative(ends, end_obj, ns, v, cf_profile_limit_np(n, 4, best, c.ynorm),
                               alt[0]);
    tp.alt = (const double(*)[4])alt;
    double x[4] = {v[0], v[1], v[2], v[3]};
    const double f = cf_tail_profile_point(&tp, k, value, rss0, *limit, x);
    free(buf);
    return f;
}

cf_status cf_fit_tail_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                          const cf_fit_result *plain, cf_fit_result *res, cf_error *err)
{
    CF_GSL_GUARD;
    memset(res, 0, sizeof *res);
    const double t0 = cf_clock_s();
    tail_ctx c;
    if (data->count < 6)
        return cf_error_set(err, CF_E_DATA,
                            "the conical-tail law needs at least 6 rows (the table has %zu)",
                            data->count);
    double *buf = malloc(3 * sizeof(double) * data->count);
    if (!buf)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", data->count);
    ctx_init(&c, data, opt, type, buf);
    double v[4], ends[TAIL_STARTS + 2][4], end_obj[TAIL_STARTS + 2];
    int ns = 0;
    const double best = tail_search(&c, plain, v, ends, end_obj, &ns);
    if (!isfinite(best)) {
        free(buf);
        /* the conical law the tailed law contains: its fit with no tail */
        if (plain && !plain->tail && isfinite(plain->objective)) {
            res->evaluations = res->evaluations_full = c.evals;
            res->feasible = 0;
            res->objective = INFINITY;
            res->rmse = 0;
            cf_tail_nest(plain, res);
            res->wall_time_s = cf_clock_s() - t0;
            return CF_OK;
        }
        return cf_error_set(err, CF_E_DATA, "%s: no conical-tail law fits the table",
                            data->path);
    }
    /* the identifiable quantities, their errors, the spring */
    double se[4], corr[4][4], cov_Bt;
    cf_tail_errors(resid_at, &c, c.n, v, 1e-6, best, se, corr, &cov_Bt);
    cf_status st = cf_tail_result(data, opt, type, v, se, corr, cov_Bt, res, err);
    if (st != CF_OK) {
        free(buf);
        return st;
    }
    /* profile intervals where the errors say nothing, on the grid's rows (every row of a table
    ** of up to TAIL_SEARCH_ROWS), against the whole table's threshold: the rise F s^2 of the
    ** F-test with 1 and N - 4 degrees of freedom */
    const double rss0 = stride_rss(&c, v);
    cf_tail_profile tp = profile_of(&c);
    const double rise = cf_profile_limit_np(c.n, 4, best, c.ynorm) - best;
    /* a start that ended elsewhere within the threshold: the profiles' second start */
    double alt[1][4];
    tp.nalt = tail_alternative(ends, end_obj, ns, v, best + rise, alt[0]);
    tp.alt = (const double(*)[4])alt;
    const int pst = cf_tail_intervals(&tp, v, rss0, rss0 + rise, res);
    free(buf);
    if (pst < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the profiles of %zu rows", c.n);
    res->optimizer = "lm";
    res->evaluations = c.evals;
    res->evaluations_full = c.evals;
    res->wall_time_s = cf_clock_s() - t0;
    /* never reported worse than the conical law it contains */
    cf_tail_nest(plain, res);
    return CF_OK;
}
