/*
** Baseline fits (see baseline.h): the linear and Duffing laws are linear in their coefficients
** and solved as linear least-squares problems (GSL, through the QR factorisation of the design
** matrix, never the squared normal equations); Fung's law is linear in A for a fixed B, so B is
** found by a scan and a refinement of the profile RSS(B) with GSL's Brent minimiser.
*/
#include "conifit/baseline.h"

#include <float.h>
#include <math.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>
#include <gsl/gsl_linalg.h>

#include "fit/subsample.h"

const char *cf_baseline_name(cf_baseline_kind kind)
{
    switch (kind) {
    case CF_BASE_LINEAR: return "linear";
    case CF_BASE_DUFFING: return "duffing";
    case CF_BASE_FUNG: return "fung";
    case CF_BASE_COUNT: break;
    }
    return "?";
}

double cf_baseline_eval(const cf_baseline *b, double x)
{
    switch (b->kind) {
    case CF_BASE_LINEAR: return b->coef[0] * x;
    case CF_BASE_DUFFING: return b->coef[0] * x + b->coef[1] * x * x * x;
    case CF_BASE_FUNG: return b->coef[0] * expm1(b->coef[1] * x);
    case CF_BASE_COUNT: break;
    }
    return 0;
}

double cf_baseline_aic(size_t n, double rss, int k, double ymax)
{
    double floor = (double)n * (DBL_EPSILON * ymax) * (DBL_EPSILON * ymax);
    double r = fmax(rss, fmax(floor, DBL_MIN));
    return (double)n * log(r / (double)n) + 2.0 * k;
}

/* RSS of Fung's law with A solved for the given B (A returned); weighted by d->w when weighted
** (the subsample of a long table, whose weights stand for the rows of each bin). */
static double fung_profile(const cf_table *d, int weighted, double B, double *A)
{
    double sgy = 0, sgg = 0, syy = 0;
    for (size_t i = 0; i < d->count; i++) {
        double g = expm1(B * d->x[i]), w = weighted ? d->w[i] : 1.0;
        sgy += w * g * d->y[i];
        sgg += w * g * g;
        syy += w * d->y[i] * d->y[i];
    }
    *A = (sgg > 0 && isfinite(sgg)) ? sgy / sgg : 0;
    double rss = syy - *A * sgy;
    return isfinite(rss) ? fmax(rss, 0.0) : INFINITY;
}

static void finish(const cf_table *d, cf_baseline *b, double ymax)
{
    double rss = 0;
    for (size_t i = 0; i < d->count; i++) {
        double r = cf_baseline_eval(b, d->x[i]) - d->y[i];
        rss += r * r;
    }
    b->rss = rss;
    b->rmse = sqrt(rss / (double)d->count);
    b->aic = cf_baseline_aic(d->count, rss, b->k, ymax);
}

/* Duffing's k1, k3: least squares on the design matrix [x, x^3] by its QR factorisation (GSL's
** Householder QR, never the squared normal equations), in workspaces allocated here and checked:
** gsl_multifit_linear allocates inside its SVD without checking and crashes when memory runs
** out. 0 when the matrix is singular (a table without x), -1 when memory runs out. */
static int duffing_fit(const cf_table *d, double coef[2])
{
    gsl_matrix *X = gsl_matrix_alloc(d->count, 2);
    gsl_vector *y = gsl_vector_alloc(d->count), *r = gsl_vector_alloc(d->count);
    gsl_vector *c = gsl_vector_alloc(2), *tau = gsl_vector_alloc(2);
    int ok = X && y && r && c && tau;
    int oom = !ok;
    if (ok) {
        for (size_t i = 0; i < d->count; i++) {
            double x = d->x[i];
            gsl_matrix_set(X, i, 0, x);
            gsl_matrix_set(X, i, 1, x * x * x);
            gsl_vector_set(y, i, d->y[i]);
        }
        ok = gsl_linalg_QR_decomp(X, tau) == GSL_SUCCESS &&
             fabs(gsl_matrix_get(X, 1, 1)) > 1e-14 * fabs(gsl_matrix_get(X, 0, 0)) &&
             gsl_linalg_QR_lssolve(X, tau, y, c, r) == GSL_SUCCESS &&
             isfinite(gsl_vector_get(c, 0)) && isfinite(gsl_vector_get(c, 1));
        if (ok) {
            coef[0] = gsl_vector_get(c, 0);
            coef[1] = gsl_vector_get(c, 1);
        }
    }
    gsl_matrix_free(X);
    gsl_vector_free(y);
    gsl_vector_free(r);
    gsl_vector_free(c);
    gsl_vector_free(tau);
    return oom ? -1 : ok;
}

static double fung_rss(double B, void *data)
{
    double A;
    return fung_profile(data, 0, B, &A);
}

/* Refines the scan's best B in (lo, hi) with Brent's method on the profile RSS; returns B
** (*oom = 1 when the minimiser cannot be allocated). */
static double fung_refine(const cf_table *d, double B, double lo, double hi, int *oom)
{
    gsl_function f = {fung_rss, (void *)d};
    gsl_min_fminimizer *m = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    if (!m) {
        *oom = 1;
        return B;
    }
    /* the scan's minimum lies strictly below its neighbours, as Brent's bracket needs */
    if (gsl_min_fminimizer_set(m, &f, B, lo, hi) == GSL_SUCCESS) {
        for (int it = 0; it < 200; it++) {
            if (gsl_min_fminimizer_iterate(m) != GSL_SUCCESS)
                break;
            double a = gsl_min_fminimizer_x_lower(m), b = gsl_min_fminimizer_x_upper(m);
            if (gsl_min_test_interval(a, b, 0, 1e-14) == GSL_SUCCESS)
                break;
        }
        B = gsl_min_fminimizer_x_minimum(m);
    }
    gsl_min_fminimizer_free(m);
    return B;
}

cf_status cf_baseline_fit_all(const cf_table *d, cf_baseline out[CF_BASE_COUNT], cf_error *err)
{
    double xmax = 0, ymax = 0, s2 = 0, sy1 = 0;
    for (size_t i = 0; i < d->count; i++) {
        double x = d->x[i], y = d->y[i];
        xmax = fmax(xmax, fabs(x));
        ymax = fmax(ymax, fabs(y));
        s2 += x * x;
        sy1 += x * y;
    }
    cf_baseline *L = &out[CF_BASE_LINEAR], *D = &out[CF_BASE_DUFFING], *F = &out[CF_BASE_FUNG];
    *L = (cf_baseline){CF_BASE_LINEAR, 1, {s2 > 0 ? sy1 / s2 : 0, 0}, 0, 0, 0};
    *D = (cf_baseline){CF_BASE_DUFFING, 2, {0, 0}, 0, 0, 0};
    int du = duffing_fit(d, D->coef), oom = du < 0;
    if (du <= 0) {
        D->coef[0] = L->coef[0];
        D->coef[1] = 0;
    }
    /* Fung: scan B over +-50/xmax (exp(50) covers any stiffening a table shows), then refine. A
    ** long table is scanned on its subsample (subsample.h), then on every row from the best
    ** point of the scan to the nearest minimum along the scan's grid. */
    *F = (cf_baseline){CF_BASE_FUNG, 2, {0, 0}, 0, 0, 0};
    double bmax = xmax > 0 ? 50.0 / xmax : 1.0;
    double bestR = INFINITY, A;
    const int N = 400;
    int ib = 1;
    cf_table sub;
    const cf_table *scan = d;
    if (d->count > CF_FIT_SUBSAMPLE_ABOVE) {
        if (cf_subsample(d, CF_SUBSAMPLE_ROWS, &sub, NULL) != CF_OK)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory fitting the baselines");
        scan = &sub;
    }
    for (int i = -N; i <= N; i++) {
        if (i == 0)
            continue;
        double r = fung_profile(scan, scan != d, bmax * (double)i / N, &A);
        if (r < bestR) {
            bestR = r;
            ib = i;
        }
    }
    if (scan != d) {
        cf_table_free(&sub);
        bestR = fung_profile(d, 0, bmax * (double)ib / N, &A);
        for (int dir = -1; dir <= 1; dir += 2)
            for (;;) {
                int j = ib + dir == 0 ? ib + 2 * dir : ib + dir;
                double r = j >= -N && j <= N ? fung_profile(d, 0, bmax * (double)j / N, &A)
                                             : INFINITY;
                if (!(r < bestR))
                    break;
                bestR = r;
                ib = j;
            }
    }
    double bestB = bmax * (double)ib / N;
    double Bf = fung_refine(d, bestB, bestB - bmax / N, bestB + bmax / N, &oom);
    if (fung_profile(d, 0, Bf, &A) > bestR)
        Bf = bestB;
    fung_profile(d, 0, Bf, &A);
    F->coef[0] = A;
    F->coef[1] = Bf;
    finish(d, L, ymax);
    finish(d, D, ymax);
    finish(d, F, ymax);
    if (oom)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the baselines' solvers (GSL)");
    return CF_OK;
}
