/*
** Stage A of the fit (see fit.h): the three identifiable quantities over every spring, by a global
** grid over (rho, length scale) with the load scale in closed form, the paper's two-point start,
** and Levenberg-Marquardt (GSL) on the canonical law's analytic Jacobian; their standard errors
** and correlation from that Jacobian.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_vector.h>

#include "fit/fit_ctx.h"
#include "fit/lm.h"
#include "fit/lsq.h"
#include "fit/subsample.h"

/* The fit's random numbers: GSL's mt19937 (the generator conifit uses everywhere), one stream
** per use, seeded from the fit's seed, local to one call (no shared state between threads). */
gsl_rng *cf_fit_seeded_rng(unsigned long seed, unsigned long stream)
{
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    if (r)
        gsl_rng_set(r, seed * 4u + stream);
    return r;
}

/* A uniform number in [0, 1); 0.5 (the cell's centre) when no generator could be made. */
double cf_fit_jitter(gsl_rng *r)
{
    return r ? gsl_rng_uniform(r) : 0.5;
}

static double sigmoid(double t) { return 1.0 / (1.0 + exp(-t)); }

/* Weighted objective of the reduced model with the load scale A solved in closed form; *sgg_out
** (may be NULL) the sum of the weighted model's squares. */
static double reduced_fit(fit_ctx *c, double rho, double B, double *A_out, double *sgg_out)
{
    if (sgg_out)
        *sgg_out = 0;
    if (cf_ident_canon_many_rho(rho, B, c->n, c->data->x, c->model, NULL, NULL) != CF_OK) {
        *A_out = 1e-300;
        return CF_LSQ_HUGE_OBJ;
    }
    double sgy = 0, sgg = 0, syy = 0;
    for (size_t i = 0; i < c->n; i++) {
        double g = c->sw[i] * c->model[i];
        double y = c->sw[i] * c->data->y[i];
        sgy += g * y;
        sgg += g * g;
        syy += y * y;
    }
    c->evals++;
    if (sgg_out)
        *sgg_out = sgg;
    double A = sgg > 0 ? sgy / sgg : 0;
    if (!(A > 0) || !isfinite(A)) {
        *A_out = 1e-300;
        return syy;
    }
    *A_out = A;
    return fmax(syy - A * sgy, 0.0);
}

/* The grid of stage A: GRID x GRID points over (rho, B), seeded jitter in each cell (stream 1);
** rho half log-spaced from rho_lo, half approaching rho_hi geometrically (resolves nearly
** cylindrical springs); B half quadratic in its range, half geometric towards its lower end. */
void cf_fit_grid_points(fit_ctx *c, grid_point pts[GRID * GRID])
{
    gsl_rng *rng = cf_fit_seeded_rng(c->opt->seed, 1);
    c->oom |= !rng;
    size_t k = 0;
    for (int i = 0; i < GRID; i++) {
        double ti = (i + cf_fit_jitter(rng)) / GRID;
        double rho = (i % 2 == 0)
                         ? c->rho_lo * pow(c->rho_hi / c->rho_lo, ti)
                         : c->rho_hi - (c->rho_hi - c->rho_lo) * pow(1e-7, ti);
        for (int j = 0; j < GRID; j++) {
            double tj = (j + cf_fit_jitter(rng)) / GRID;
            pts[k].rho = rho;
            pts[k].B = (j % 2 == 0) ? c->b_lo + (c->b_hi - c->b_lo) * tj * tj
                                    : c->b_lo + (c->b_hi - c->b_lo) * pow(1e-7, 1 - tj);
            pts[k].done = 0;
            k++;
        }
    }
    gsl_rng_free(rng);
}

void cf_fit_grid_value(fit_ctx *c, grid_point *p)
{
    p->rss = reduced_fit(c, p->rho, p->B, &p->A, &p->sgg);
    p->done = 1;
}

/* ---- stage A: Levenberg-Marquardt on the three identifiable quantities ----------------------- */

static void unpack3(const fit_ctx *c, const gsl_vector *th, double *rho, double *B, double *A)
{
    *rho = c->rho_lo + (c->rho_hi - c->rho_lo) * sigmoid(gsl_vector_get(th, 0));
    *B = c->b_lo + (c->b_hi - c->b_lo) * sigmoid(gsl_vector_get(th, 1));
    *A = exp(gsl_vector_get(th, 2));
}

/* The quantities at th and the canonical law there (g, and with gt and gr its derivatives, at
** every row: cf_ident_canon_many_rho); GSL_EDOM where there is none. */
static int canon_at(fit_ctx *c, const gsl_vector *th, double *rho, double *B, double *A,
                    double *gt, double *gr)
{
    unpack3(c, th, rho, B, A);
    if (!isfinite(*A) ||
        cf_ident_canon_many_rho(*rho, *B, c->n, c->data->x, c->model, gt, gr) != CF_OK)
        return GSL_EDOM;
    return GSL_SUCCESS;
}

/* The residuals at th. The law's derivatives come with them (a fifth more than the law alone) and
** are kept with th: GSL asks for the Jacobian at the point whose residuals it has just accepted,
** which lm_df then takes from here instead of evaluating the law there again (the same values:
** the lanes' g is the same with or without derivatives). */
static int lm_f(const gsl_vector *th, void *params, gsl_vector *f)
{
    fit_ctx *c = params;
    double rho, B, A;
    c->lm_have = 0;
    if (canon_at(c, th, &rho, &B, &A, c->gt, c->gr) != GSL_SUCCESS)
        return GSL_EDOM;
    for (int k = 0; k < 3; k++)
        c->lm_at[k] = gsl_vector_get(th, k);
    c->lm_have = 1;
    /* residuals scaled so that the zero model has |f| = 1: GSL's gradient test is absolute
    ** below |f| = 1, which would stop early on tables in MPa of tissue (tiny numbers) */
    const double sc = 1.0 / sqrt(c->ynorm);
    for (size_t i = 0; i < c->n; i++)
        gsl_vector_set(f, i, sc * c->sw[i] * (A * c->model[i] - c->data->y[i]));
    c->evals++;
    return GSL_SUCCESS;
}

/* Analytic Jacobian of lm_f in the transformed variables. */
static int lm_df(const gsl_vector *th, void *params, gsl_matrix *J)
{
    fit_ctx *c = params;
    double rho, B, A;
    const int kept = c->lm_have && gsl_vector_get(th, 0) == c->lm_at[0] &&
                     gsl_vector_get(th, 1) == c->lm_at[1] && gsl_vector_get(th, 2) == c->lm_at[2];
    if (kept)
        unpack3(c, th, &rho, &B, &A);
    else if (canon_at(c, th, &rho, &B, &A, c->gt, c->gr) != GSL_SUCCESS)
        return GSL_EDOM;
    const double s0 = sigmoid(gsl_vector_get(th, 0)), s1 = sigmoid(gsl_vector_get(th, 1));
    const double drho = (c->rho_hi - c->rho_lo) * s0 * (1 - s0);
    const double dB = (c->b_hi - c->b_lo) * s1 * (1 - s1);
    const double sc = 1.0 / sqrt(c->ynorm);
    for (size_t i = 0; i < c->n; i++) {
        double t = c->data->x[i] / B;
        double w = sc * c->sw[i];
        gsl_matrix_set(J, i, 0, w * A * c->gr[i] * drho);
        gsl_matrix_set(J, i, 1, w * (-A * c->gt[i] * t / B) * dB);
        gsl_matrix_set(J, i, 2, w * A * c->model[i]);
    }
    c->evals += !kept;
    return GSL_SUCCESS;
}

/* Whether the position th of stage A's Levenberg-Marquardt lies below rho_min (outside the limits
** of every type). */
static int below_rho_min(const gsl_vector *th, void *arg)
{
    const fit_ctx *c = arg;
    double rho, B, A;
    unpack3(c, th, &rho, &B, &A);
    return rho < c->opt->rho_min;
}

double cf_fit_lm_run(fit_ctx *c, double rho0, double B0, double A0, double out[3])
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.fdtype = GSL_MULTIFIT_NLINEAR_CTRDIFF;
    /* above LM_QR_ROWS rows the normal equations, not a QR: GSL's Householder passes and column
    ** norms over the rows were a quarter of a 1000-row fit, which then cost more than a 1001-row
    ** one (searched on its 1000-row subsample, polished by normal equations: fit_long.c) */
    if (c->n > LM_QR_ROWS)
        fp.solver = gsl_multifit_nlinear_solver_cholesky;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    c->lm_have = 0;
    fdf.f = lm_f;
    fdf.df = lm_df;
    fdf.n = c->n;
    fdf.p = 3;
    fdf.params = c;
    double th0[3] = {cf_logit((rho0 - c->rho_lo) / (c->rho_hi - c->rho_lo)),
                     cf_logit((B0 - c->b_lo) / (c->b_hi - c->b_lo)), log(A0)};
    int ist;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, th0, &ist);
    if (!w) {
        c->oom = 1;
        return CF_LSQ_HUGE_OBJ;
    }
    double best = CF_LSQ_HUGE_OBJ;
    if (ist == GSL_ENOMEM)
        c->oom = 1;
    if (ist == GSL_SUCCESS) {
        /* an optimum on a bound of rho or of the length scale lies at infinity in the logit
        ** coordinates: the stall rule stops there (residuals are scaled by 1/sqrt(ynorm)) */
        cf_lm_stop stop = {LM_MAX_ITER, 1e-15, 1e-15, 1e-15, LM_STALL, LM_STALL_REL, LM_FLOOR_REL};
        if (c->stat_tol > 0) {
            stop.stall = LM_STALL_LONG;
            stop.stall_rel = c->stat_tol;
        } else if (c->crawl_stop && c->region && c->n > 3) {
            /* the strict polish: where it crawls below rho_min (an optimum at the bound of rho,
            ** at infinity in the logit coordinate: 300 steps that each gain a millionth of the
            ** residual variance), every type fits again under its limits and this point only
            ** says that it lies outside them: there the statistical rule stops it */
            stop.outside = below_rho_min;
            stop.outside_arg = c;
            stop.outside_rel = LONG_TOL / (double)(c->n - 3);
            stop.outside_stall = LM_STALL_LONG;
        }
        if (cf_lm_iterate(w, &stop) != 0)
            c->oom = 1;
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        double chi2;
        gsl_blas_ddot(f, f, &chi2);
        if (isfinite(chi2)) {
            unpack3(c, gsl_multifit_nlinear_position(w), &out[0], &out[1], &out[2]);
            best = chi2;
        }
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

/* The paper's two-point start: the maximum point gives the solid strain and the load scale,
** the transition point (last point on the initial line within 5 %) gives rho = (F_T/F_C)^(1/3). */
static void two_point_start(const fit_ctx *c, double *rho, double *B, double *A)
{
    const double *x = c->data->x, *y = c->data->y;
    size_t imax = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(x[i]) > fabs(x[imax]))
            imax = i;
    /* initial slope from the points in the first tenth of the range */
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(x[i]) <= 0.1 * c->xmax) {
            sxy += x[i] * y[i];
            sxx += x[i] * x[i];
        }
    double k = sxx > 0 ? sxy / sxx : y[imax] / x[imax];
    double yT = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(y[i] - k * x[i]) <= 0.05 * fabs(y[i]) && fabs(y[i]) > yT)
            yT = fabs(y[i]);
    double ymax = fabs(y[imax]);
    double r = (yT > 0 && ymax > 0) ? cbrt(fmin(yT / ymax, 1.0)) : 0.5;
    *rho = fmin(fmax(r, c->rho_lo + 1e-9 * (c->rho_hi - c->rho_lo)), c->rho_hi);
    *B = fmin(fmax(c->travel_ok ? c->xmax * (1 + 2 * CF_FIT_TRAVEL_MARGIN) : 0.5 * c->b_hi,
                   c->b_lo + 1e-6 * (c->b_hi - c->b_lo)),
              c->b_hi - 1e-6 * (c->b_hi - c->b_lo));
    *A = ymax > 0 ? ymax : 1.0;
}

static void record(start4 *found, int *nfound, double obj, const double v[3])
{
    if (found && obj < CF_LSQ_HUGE_OBJ && *nfound < STAGE_A_RUNS) {
        found[*nfound].obj = obj;
        memcpy(found[*nfound].v, v, sizeof found[0].v);
        (*nfound)++;
    }
}

int cf_fit_cmp_start4(const void *a, const void *b)
{
    double x = ((const start4 *)a)->obj, y = ((const start4 *)b)->obj;
    return (x > y) - (x < y);
}

int cf_fit_cmp_start(const void *a, const void *b)
{
    double x = ((const start *)a)->obj, y = ((const start *)b)->obj;
    return (x > y) - (x < y);
}

/* Global stage over (rho, B) with A in closed form (cf_fit_grid_points), then LM from the best
** starts. Each LM result (objective, rho, B, A) goes to found[] when found is not NULL (at most
** STAGE_A_RUNS, counted in *nfound); the grid's points with their fits go to pts when it is not
** NULL (the constrained stage ranks its starts from them). */
double cf_fit_stage_a(fit_ctx *c, double best3[3], start4 *found, int *nfound, grid_point *pts)
{
    grid_point own[GRID * GRID];
    grid_point *gp = pts ? pts : own;
    cf_fit_grid_points(c, gp);
    start grid[GRID * GRID];
    size_t k = 0;
    for (; k < GRID * GRID; k++) {
        cf_fit_grid_value(c, &gp[k]);
        grid[k].obj = gp[k].rss;
        grid[k].rho = gp[k].rho;
        grid[k].B = gp[k].B;
    }
    qsort(grid, k, sizeof grid[0], cf_fit_cmp_start);
    double best = CF_LSQ_HUGE_OBJ;
    double r, B, A, out[3];
    two_point_start(c, &r, &B, &A);
    reduced_fit(c, r, B, &A, NULL);
    best = cf_fit_lm_run(c, r, B, A, best3);
    record(found, nfound, best, best3);
    int used = 0;
    for (size_t i = 0; i < k && used < c->opt->multistart; i++) {
        /* skip starts that lie next to one already used */
        int near = 0;
        for (size_t j = 0; j < i && !near; j++)
            near = fabs(grid[j].rho - grid[i].rho) < 0.02 && fabs(grid[j].B - grid[i].B) <
                                                                  0.02 * (c->b_hi - c->b_lo);
        if (near && i > 0)
            continue;
        used++;
        reduced_fit(c, grid[i].rho, grid[i].B, &A, NULL);
        double v = cf_fit_lm_run(c, grid[i].rho, grid[i].B, A, out);
        record(found, nfound, v, out);
        if (v < best) {
            best = v;
            memcpy(best3, out, sizeof out);
        }
    }
    return best;
}

/* Standard errors of (rho, B, A) at a solution: s^2 (J^T J)^-1 with the analytic Jacobian of the
** weighted residuals (cf_ident_canon_many); the correlation matrix (NAN where not determined).
** Returns 1 when J^T J is numerically singular (then the errors stay -1). */
int cf_fit_stage_a_errors(fit_ctx *c, const double v[3], double se[3], double corr[3][3])
{
    se[0] = se[1] = se[2] = -1;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            corr[a][b] = NAN;
    const double rho = v[0], B = v[1], A = v[2];
    cf_law lc;
    if (cf_ident_canon_law(rho, &lc) != CF_OK || c->n <= 3)
        return 0;
    double jtj[3][3] = {{0}};
    double rss = 0;
    cf_ident_canon_many(&lc, B, c->n, c->data->x, c->model, c->gt, c->gr);
    for (size_t i = 0; i < c->n; i++) {
        double x = c->data->x[i], g = c->model[i];
        double m = A * g;
        double row[3] = {A * c->gr[i], -A * c->gt[i] * x / (B * B), g};
        double r = c->sw[i] * (m - c->data->y[i]);
        rss += r * r;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                jtj[a][b] += c->sw[i] * c->sw[i] * row[a] * row[b];
    }
    c->evals += 3;
    int rank_def = cf_lsq_covariance(jtj, rss, c->n, se, corr);
    if (rank_def < 0)
        c->oom = 1;
    return rank_def > 0;
}
