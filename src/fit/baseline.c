/*
** Baseline fits (see baseline.h): the linear, Duffing and Yeoh laws are linear in their
** coefficients and solved as linear least-squares problems (GSL, through the QR factorisation of
** the design matrix, never the squared normal equations); Fung's law is linear in A for a fixed
** B, and one-term Ogden's in mu for a fixed alpha, so B and alpha are found by a scan and a
** refinement of the profile RSS with GSL's Brent minimiser. Yeoh's and Ogden's stress in the
** table's test mode: hyperelastic.h.
*/
#include "fit/baseline.h"
#include "model/mode.h"
#include "base/gslguard.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>
#include <gsl/gsl_linalg.h>

#include "fit/hyperelastic.h"
#include "fit/subsample.h"

const char *cf_baseline_name(cf_baseline_kind kind)
{
    switch (kind) {
    case CF_BASE_LINEAR: return "linear";
    case CF_BASE_DUFFING: return "duffing";
    case CF_BASE_FUNG: return "fung";
    case CF_BASE_YEOH: return "yeoh";
    case CF_BASE_OGDEN: return "ogden";
    case CF_BASE_COUNT: break;
    }
    return "?";
}

const char *cf_baseline_formula(cf_baseline_kind kind, cf_mode m)
{
    const cf_mode_row *row = cf_mode_row_of(m) ? cf_mode_row_of(m) : cf_mode_row_of(0);
    switch (kind) {
    case CF_BASE_LINEAR: return "y = E x";
    case CF_BASE_DUFFING: return "y = k1 x + k3 x^3";
    case CF_BASE_FUNG: return "y = A (exp(B x) - 1)";
    case CF_BASE_YEOH: return row->yeoh ? row->yeoh : "(no form in this mode)";
    case CF_BASE_OGDEN: return row->ogden ? row->ogden : "(no form in this mode)";
    case CF_BASE_COUNT: break;
    }
    return "?";
}

double cf_baseline_eval(const cf_baseline *b, double x)
{
    if (!b->fitted)
        return NAN;
    switch (b->kind) {
    case CF_BASE_LINEAR: return b->coef[0] * x;
    case CF_BASE_DUFFING: return b->coef[0] * x + b->coef[1] * x * x * x;
    case CF_BASE_FUNG: return b->coef[0] * expm1(b->coef[1] * x);
    case CF_BASE_YEOH: {
        double g[3];
        if (!cf_hyper_in_domain(b->form, x))
            return NAN;
        cf_yeoh_basis(b->form, x, g);
        return b->coef[0] * g[0] + b->coef[1] * g[1] + b->coef[2] * g[2];
    }
    case CF_BASE_OGDEN:
        if (!cf_hyper_in_domain(b->form, x))
            return NAN;
        return b->coef[0] * cf_ogden_basis(b->form, cf_ogden_log_stretch(b->form, x), b->coef[1]);
    case CF_BASE_COUNT: break;
    }
    return NAN;
}

double cf_baseline_aic(size_t n, double rss, int k, double ymax)
{
    double floor = (double)n * (DBL_EPSILON * ymax) * (DBL_EPSILON * ymax);
    double r = fmax(rss, fmax(floor, DBL_MIN));
    return (double)n * log(r / (double)n) + 2.0 * k;
}

/* The profile RSS of a law linear in one coefficient for a fixed shape parameter p: the RSS with
** the coefficient solved (returned in *A), weighted by d->w when weighted (the subsample of a
** long table, whose weights stand for the rows of each bin); scratch is the law's own. */
typedef double (*profile_fn)(const cf_table *d, int weighted, double p, double *A, void *scratch);

/* RSS of Fung's law with A solved for the given B. */
static double fung_profile(const cf_table *d, int weighted, double B, double *A, void *scratch)
{
    (void)scratch;
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

/* What Ogden's profile needs: the mode and room for the basis of every row. */
typedef struct ogden_scratch {
    cf_mode mode;
    double *g;
} ogden_scratch;

/* RSS of Ogden's law with mu solved for the given alpha, on a table whose x holds the log
** stretch (cf_ogden_log_stretch). The RSS is summed from the residuals (a second pass over the
** stored basis), not as syy - mu sgy, so that it resolves alpha near an exact fit. */
static double ogden_profile(const cf_table *d, int weighted, double alpha, double *mu,
                            void *scratch)
{
    const ogden_scratch *s = scratch;
    double sgy = 0, sgg = 0;
    for (size_t i = 0; i < d->count; i++) {
        double g = cf_ogden_basis(s->mode, d->x[i], alpha), w = weighted ? d->w[i] : 1.0;
        s->g[i] = g;
        sgy += w * g * d->y[i];
        sgg += w * g * g;
    }
    *mu = 0;
    if (!(sgg > 0 && isfinite(sgg) && isfinite(sgy)))
        return INFINITY;
    *mu = sgy / sgg;
    double rss = 0;
    for (size_t i = 0; i < d->count; i++) {
        double r = d->y[i] - *mu * s->g[i];
        rss += (weighted ? d->w[i] : 1.0) * r * r;
    }
    return isfinite(rss) ? rss : INFINITY;
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

/* A baseline left out, with why. */
static void unfit(cf_baseline *b, const char *why)
{
    b->fitted = 0;
    b->why = why;
    b->coef[0] = b->coef[1] = b->coef[2] = 0;
    b->rss = b->rmse = b->aic = NAN;
}

/* The basis of a law linear in its ncol coefficients at x (row[j]: its value per unit
** coefficient j). */
typedef void (*basis_fn)(const void *ctx, double x, double *row);

static void duffing_basis(const void *ctx, double x, double *row)
{
    (void)ctx;
    row[0] = x;
    row[1] = x * x * x;
}

static void yeoh_basis(const void *ctx, double x, double *row)
{
    cf_yeoh_basis(*(const cf_mode *)ctx, x, row);
}

/* Least squares on the design matrix of the basis by its QR factorisation (GSL's Householder QR,
** never the squared normal equations), its columns first scaled by powers of two to norms near
** one (exact, so a column's size neither changes the result nor the rank test), in workspaces
** allocated here and checked: gsl_multifit_linear allocates inside its SVD without checking and
** crashes when memory runs out. 1 with coef[0..ncol-1]; 0 when the matrix is singular (a table
** without x, fewer distinct rows than columns), -1 when memory runs out. */
static int linear_fit(const cf_table *d, size_t ncol, basis_fn basis, const void *ctx,
                      double *coef)
{
    gsl_matrix *X = gsl_matrix_alloc(d->count, ncol);
    gsl_vector *y = gsl_vector_alloc(d->count), *r = gsl_vector_alloc(d->count);
    gsl_vector *c = gsl_vector_alloc(ncol), *tau = gsl_vector_alloc(ncol);
    int ok = X && y && r && c && tau;
    int oom = !ok;
    int scale[3] = {0, 0, 0};
    if (ok) {
        double row[3], big[3] = {0, 0, 0};
        for (size_t i = 0; i < d->count; i++) {
            basis(ctx, d->x[i], row);
            for (size_t j = 0; j < ncol; j++) {
                gsl_matrix_set(X, i, j, row[j]);
                big[j] = fmax(big[j], fabs(row[j]));
                ok = ok && isfinite(row[j]);
            }
            gsl_vector_set(y, i, d->y[i]);
        }
        for (size_t j = 0; j < ncol; j++) {
            ok = ok && big[j] > 0;
            if (ok) {
                gsl_vector_view col = gsl_matrix_column(X, j);
                scale[j] = ilogb(gsl_blas_dnrm2(&col.vector)) + 1;
                gsl_vector_scale(&col.vector, ldexp(1.0, -scale[j]));
            }
        }
        ok = ok && gsl_linalg_QR_decomp(X, tau) == GSL_SUCCESS;
        for (size_t j = 1; ok && j < ncol; j++)
            ok = fabs(gsl_matrix_get(X, j, j)) > 1e-14 * fabs(gsl_matrix_get(X, 0, 0));
        ok = ok && gsl_linalg_QR_lssolve(X, tau, y, c, r) == GSL_SUCCESS;
        for (size_t j = 0; ok && j < ncol; j++) {
            coef[j] = ldexp(gsl_vector_get(c, j), -scale[j]);
            ok = isfinite(coef[j]);
        }
    }
    gsl_matrix_free(X);
    gsl_vector_free(y);
    gsl_vector_free(r);
    gsl_vector_free(c);
    gsl_vector_free(tau);
    return oom ? -1 : ok;
}

/* Entries of a profile's memory of the points it was evaluated at. */
#define PROFILE_SEEN 4

/* A profile and the table it runs on (weighted: a subsample's weights count), for the
** minimisers; with the last points it was evaluated at (a pass over the rows each) and their
** RSS. GSL's Brent minimiser, once its bracket is as narrow as it can resolve, asks for the same
** point at every further iteration: on a 100-row table 619 calls went to 42 distinct points. */
typedef struct profile_call {
    const cf_table *d;
    int weighted;
    profile_fn f;
    void *scratch;
    int seen, next;
    double seen_p[PROFILE_SEEN], seen_r[PROFILE_SEEN];
} profile_call;

static double profile_rss(double p, void *data)
{
    profile_call *c = data;
    for (int k = 0; k < c->seen; k++)
        if (memcmp(&c->seen_p[k], &p, sizeof p) == 0)
            return c->seen_r[k];
    double A;
    const double r = c->f(c->d, c->weighted, p, &A, c->scratch);
    c->seen_p[c->next] = p;
    c->seen_r[c->next] = r;
    c->next = (c->next + 1) % PROFILE_SEEN;
    c->seen += c->seen < PROFILE_SEEN;
    return r;
}

/* Refines the scan's best p in (lo, hi) with Brent's method on the profile RSS; returns p
** (*oom = 1 when the minimiser cannot be allocated). */
static double refine(profile_call *call, double p, double lo, double hi, int *oom)
{
    gsl_function f = {profile_rss, call};
    gsl_min_fminimizer *m = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    if (!m) {
        *oom = 1;
        return p;
    }
    /* Brent's bracket needs the scan's best point strictly below its neighbours (a flat or
    ** non-finite profile, or a best point at the end of the scan, keeps the grid's point) */
    const double fp = profile_rss(p, call), flo = profile_rss(lo, call),
                 fhi = profile_rss(hi, call);
    if (fp < flo && fp < fhi &&
        gsl_min_fminimizer_set_with_values(m, &f, p, fp, lo, flo, hi, fhi) == GSL_SUCCESS) {
        for (int it = 0; it < 200; it++) {
            if (gsl_min_fminimizer_iterate(m) != GSL_SUCCESS)
                break;
            double a = gsl_min_fminimizer_x_lower(m), b = gsl_min_fminimizer_x_upper(m);
            if (gsl_min_test_interval(a, b, 0, 1e-14) == GSL_SUCCESS)
                break;
        }
        p = gsl_min_fminimizer_x_minimum(m);
    }
    gsl_min_fminimizer_free(m);
    return p;
}

/* Newton's method on the profile from p near its minimum, with the derivatives from the profile at
** p and p +- 1e-6 |p| (the vertex of their parabola), at most six steps, each no longer than a
** tenth of |p| and kept only where the RSS does not grow; stops once a step is below 1e-13 |p|.
** It goes past Brent's resolution (GSL's Brent steps no finer than sqrt(DBL_EPSILON) of p) to
** about 1e-12 of p, as the profile is summed from its residuals and resolves that; and from the
** minimum of a subsample's profile to that of every row in a few steps. */
static double polish(profile_call *call, double p)
{
    double fp = profile_rss(p, call);
    for (int it = 0; it < 6 && isfinite(fp) && p != 0; it++) {
        const double h = 1e-6 * fabs(p);
        const double fm = profile_rss(p - h, call), fq = profile_rss(p + h, call);
        const double curv = fm - 2 * fp + fq;
        if (!(curv > 0) || !isfinite(fm) || !isfinite(fq))
            break;
        const double q = p - 0.5 * h * (fq - fm) / curv, fnew = profile_rss(q, call);
        if (!(fnew <= fp) || fabs(q - p) > 0.1 * fabs(p))
            break;
        const int done = fabs(q - p) < 1e-13 * fabs(p);
        p = q;
        fp = fnew;
        if (done)
            break;
    }
    return p;
}

/* Points of the scan of a shape parameter on each side of 0. */
#define SCAN_SIDE 400

/* The profile RSS at every point of a scan, r[i + SCAN_SIDE] at p = pmax i/SCAN_SIDE (r[SCAN_SIDE]
** for p = 0 left to the caller), from the table t (weighted: its weights count); 0, or -1 when it
** cannot (memory), and the scan then evaluates the profile at each point. */
typedef int (*scan_fn)(const cf_table *t, int weighted, double pmax, void *scratch, double *r);

/* The scans of Fung's and Ogden's profiles from powers: both laws are sums of exponentials
** exp(p z_i) of the shape parameter p, and along the scan's even grid p = k dp the k-th power of
** exp(dp z_i), one multiplication a row and point where the profile calls exp or expm1 (the two
** scans were most of the baselines' time). The k-th power carries at most k rounding errors (4e-14
** of it at the scan's ends); the scan only ranks the grid's points, and each one kept is evaluated
** again on the profile itself (from_grid_point), so that the refinement and the comparison with
** its result are the profile's own. */
static void scan_side(const cf_table *t, int weighted, double pmax, int side, int two,
                      const double *c, const double *z1, const double *z2, double *u, double *v,
                      double *g, double *r)
{
    const int N = SCAN_SIDE;
    const size_t n = t->count;
    const double dp = side * pmax / N;
    for (size_t i = 0; i < n; i++) {
        u[n + i] = exp(dp * z1[i]);
        u[i] = 1.0;
        if (two) {
            v[n + i] = exp(dp * z2[i]);
            v[i] = 1.0;
        }
    }
    for (int k = 1; k <= N; k++) {
        const double p = pmax * (double)(side * k) / N;
        double sgy = 0, sgg = 0, syy = 0;
        for (size_t i = 0; i < n; i++) {
            u[i] *= u[n + i];
            double gi;
            if (two) {
                v[i] *= v[n + i];
                gi = c[i] * (u[i] - v[i]) / p;
            } else {
                gi = u[i] - 1.0;
            }
            g[i] = gi;
            const double w = weighted ? t->w[i] : 1.0;
            sgy += w * gi * t->y[i];
            sgg += w * gi * gi;
            syy += w * t->y[i] * t->y[i];
        }
        double rss;
        if (!two) { /* as fung_profile */
            const double A = (sgg > 0 && isfinite(sgg)) ? sgy / sgg : 0;
            rss = syy - A * sgy;
            rss = isfinite(rss) ? fmax(rss, 0.0) : INFINITY;
        } else if (!(sgg > 0 && isfinite(sgg) && isfinite(sgy))) { /* as ogden_profile */
            rss = INFINITY;
        } else {
            const double mu = sgy / sgg;
            rss = 0;
            for (size_t i = 0; i < n; i++) {
                const double e = t->y[i] - mu * g[i];
                rss += (weighted ? t->w[i] : 1.0) * e * e;
            }
            rss = isfinite(rss) ? rss : INFINITY;
        }
        r[N + side * k] = rss;
    }
}

static int fung_scan(const cf_table *t, int weighted, double pmax, void *scratch, double *r)
{
    (void)scratch;
    const size_t n = t->count;
    double *u = malloc(sizeof(double) * 3 * (n ? n : 1));
    if (!u)
        return -1;
    for (int side = -1; side <= 1; side += 2)
        scan_side(t, weighted, pmax, side, 0, NULL, t->x, NULL, u, NULL, u + 2 * n, r);
    free(u);
    return 0;
}

/* Ogden's basis in the table's mode as c_i (exp(alpha z1_i) - exp(alpha z2_i))/alpha (see
** cf_ogden_basis): with L the log stretch, c = 2 exp(-L), z1 = L, z2 = -q L off shear, and
** c = 1/cosh(L), z1 = L, z2 = -L in shear. */
static int ogden_scan(const cf_table *t, int weighted, double pmax, void *scratch, double *r)
{
    const ogden_scratch *s = scratch;
    const size_t n = t->count, m = n ? n : 1;
    double *buf = malloc(sizeof(double) * 7 * m);
    if (!buf)
        return -1;
    double *c = buf, *z2 = buf + m, *u = buf + 2 * m, *v = buf + 4 * m, *g = buf + 6 * m;
    const int shear = cf_mode_row_of(s->mode)->any_sign;
    const double q = cf_mode_row_of(s->mode)->q;
    for (size_t i = 0; i < n; i++) {
        const double L = t->x[i];
        c[i] = shear ? 1.0 / cosh(L) : 2.0 * exp(-L);
        z2[i] = -q * L;
    }
    for (int side = -1; side <= 1; side += 2)
        scan_side(t, weighted, pmax, side, 1, c, t->x, z2, u, v, g, r);
    free(buf);
    return 0;
}

/* From grid point ib of a scan over +-pmax, on every row of d (weighted when dw): when the scan ran
** on a subsample, to the nearest minimum along the grid; then Brent between the grid's
** neighbours, kept where it does not raise the RSS. Returns p. */
static double from_grid_point(const cf_table *d, int dw, int subsampled, profile_fn prof,
                              void *scratch, double pmax, int ib, int *oom)
{
    const int N = SCAN_SIDE;
    double A;
    profile_call call = {d, dw, prof, scratch, 0, 0, {0}, {0}};
    /* the scan's value may come from its powers (scan_fn), a few ulps off the profile's */
    double bestR = profile_rss(pmax * (double)ib / N, &call);
    if (subsampled) {
        for (int dir = -1; dir <= 1; dir += 2)
            for (;;) {
                int j = ib + dir == 0 ? ib + 2 * dir : ib + dir;
                double r = j >= -N && j <= N ? prof(d, dw, pmax * (double)j / N, &A, scratch)
                                             : INFINITY;
                if (!(r < bestR))
                    break;
                bestR = r;
                ib = j;
            }
    }
    double best = pmax * (double)ib / N;
    double p = refine(&call, best, best - pmax / N, best + pmax / N, oom);
    return prof(d, dw, p, &A, scratch) > bestR ? best : p;
}

/* The shape parameter p of a profile (0 excluded) on d (weighted when dw): a scan over +-pmax,
** SCAN_SIDE points a side, on scan (d itself, or its subsample, whose weights then count); then
** from_grid_point from the
** scan's best point and, when tries > 1, from the lowest other local minima of the scan, up to
** tries in all (a profile with more than one valley); the lowest on every row is kept. Returns p
** with its coefficient in *A. */
static double shape_fit(const cf_table *d, int dw, const cf_table *scan, profile_fn prof,
                        scan_fn sfn, void *scratch, double pmax, int tries, int *oom, double *A)
{
    const int N = SCAN_SIDE;
    double r[2 * SCAN_SIDE + 1], bestR = INFINITY;
    int cand[3] = {1, 0, 0}, ncand = 1;
    const int powers = sfn && sfn(scan, scan != d || dw, pmax, scratch, r) == 0;
    for (int i = -N; i <= N; i++) {
        if (!powers || i == 0)
            r[i + N] = i == 0 ? INFINITY
                              : prof(scan, scan != d || dw, pmax * (double)i / N, A, scratch);
        if (r[i + N] < bestR) {
            bestR = r[i + N];
            cand[0] = i;
        }
    }
    tries = tries < 3 ? tries : 3;
    while (ncand < tries) { /* the next lowest local minimum of the grid */
        int next = 0;
        for (int i = -N; i <= N; i++) {
            const double ri = r[i + N];
            int taken = 0;
            for (int c = 0; c < ncand; c++)
                taken = taken || cand[c] == i;
            if (taken || i == 0 || !isfinite(ri) || (i > -N && !(ri < r[i + N - 1])) ||
                (i < N && !(ri <= r[i + N + 1])))
                continue;
            if (next == 0 || ri < r[next + N])
                next = i;
        }
        if (next == 0)
            break;
        cand[ncand++] = next;
    }
    double p = pmax * (double)cand[0] / N, pbest = p, rbest = INFINITY;
    for (int c = 0; c < ncand; c++) {
        p = from_grid_point(d, dw, scan != d, prof, scratch, pmax, cand[c], oom);
        const double rc = ncand > 1 ? prof(d, dw, p, A, scratch) : 0;
        if (c == 0 || rc < rbest) {
            rbest = rc;
            pbest = p;
        }
    }
    prof(d, dw, pbest, A, scratch);
    return pbest;
}

/* Yeoh's C1, C2, C3 in the table's mode. */
static void yeoh_fit(const cf_table *d, cf_baseline *Y, int *oom)
{
    int st = linear_fit(d, 3, yeoh_basis, &d->mode, Y->coef);
    *oom = *oom || st < 0;
    if (st <= 0)
        unfit(Y, st < 0 ? "out of memory"
                        : "the table does not determine three coefficients (fewer than three "
                          "distinct stretches)");
}

/* Ogden's mu and alpha in the table's mode: a scan of alpha over |alpha| <= max(50, 50/L), L the
** largest |log stretch| of the table (so that |alpha| L reaches 50, as far as Fung's |B x|), on
** the log stretches of scan's rows, then on every row. 0, or -1 when memory runs out. */
static int ogden_fit(const cf_table *d, const cf_table *scan, cf_baseline *O, int *oom)
{
    double *L = malloc(sizeof(double) * (d->count + scan->count));
    double *g = malloc(sizeof(double) * (d->count ? d->count : 1));
    if (!L || !g) {
        free(L);
        free(g);
        unfit(O, "out of memory");
        return -1;
    }
    double Lmax = 0;
    for (size_t i = 0; i < d->count; i++) {
        L[i] = cf_ogden_log_stretch(d->mode, d->x[i]);
        Lmax = fmax(Lmax, fabs(L[i]));
    }
    cf_table dl = *d, sl = *scan;
    dl.x = L;
    if (scan != d) {
        sl.x = L + d->count;
        for (size_t i = 0; i < scan->count; i++)
            sl.x[i] = cf_ogden_log_stretch(d->mode, scan->x[i]);
    }
    ogden_scratch s = {d->mode, g};
    double mu, amax = fmax(50.0, 50.0 / Lmax);
    /* the valleys are told apart on the subsample of a long table, whose minimum Newton's steps
    ** then take to that of every row */
    double alpha = scan != d ? shape_fit(&sl, 1, &sl, ogden_profile, ogden_scan, &s, amax, 3,
                                         oom, &mu)
                             : shape_fit(&dl, 0, &dl, ogden_profile, ogden_scan, &s, amax, 3,
                                         oom, &mu);
    profile_call call = {&dl, 0, ogden_profile, &s, 0, 0, {0}, {0}};
    alpha = polish(&call, alpha);
    if (cf_mode_row_of(d->mode)->q == 1.0) /* q = 1: even in alpha */
        alpha = fabs(alpha);
    const int finite = isfinite(ogden_profile(&dl, 0, alpha, &mu, &s));
    free(L);
    free(g);
    O->coef[0] = mu;
    O->coef[1] = alpha;
    if (!finite)
        unfit(O, "no exponent in the scanned range gives a finite stress at every row");
    return 0;
}

cf_status cf_baseline_fit_all(const cf_table *d, cf_baseline out[CF_BASE_COUNT], cf_error *err)
{
    CF_GSL_GUARD;
    double xmax = 0, ymax = 0, s2 = 0, sy1 = 0;
    for (size_t i = 0; i < d->count; i++) {
        double x = d->x[i], y = d->y[i];
        xmax = fmax(xmax, fabs(x));
        ymax = fmax(ymax, fabs(y));
        s2 += x * x;
        sy1 += x * y;
    }
    for (int k = 0; k < CF_BASE_COUNT; k++)
        out[k] = (cf_baseline){.kind = (cf_baseline_kind)k, .fitted = 1, .form = d->mode};
    cf_baseline *L = &out[CF_BASE_LINEAR], *D = &out[CF_BASE_DUFFING], *F = &out[CF_BASE_FUNG];
    cf_baseline *Y = &out[CF_BASE_YEOH], *O = &out[CF_BASE_OGDEN];
    L->k = 1;
    D->k = 2;
    F->k = 2;
    Y->k = 3;
    O->k = 2;
    L->coef[0] = s2 > 0 ? sy1 / s2 : 0;
    int du = linear_fit(d, 2, duffing_basis, NULL, D->coef), oom = du < 0;
    if (du <= 0) {
        D->coef[0] = L->coef[0];
        D->coef[1] = 0;
    }
    /* a long table is scanned on its subsample (subsample.h) */
    cf_table sub;
    const cf_table *scan = d;
    if (d->count > CF_FIT_SUBSAMPLE_ABOVE) {
        if (cf_subsample(d, CF_SUBSAMPLE_ROWS, &sub, NULL) != CF_OK)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory fitting the baselines");
        scan = &sub;
    }
    /* Fung: B over +-50/xmax (exp(50) covers any stiffening a table shows) */
    F->coef[1] = shape_fit(d, 0, scan, fung_profile, fung_scan, NULL,
                           xmax > 0 ? 50.0 / xmax : 1.0, 1,
                           &oom, &F->coef[0]);
    const char *why = cf_hyper_unfit(d);
    if (why) {
        unfit(Y, why);
        unfit(O, why);
    } else {
        yeoh_fit(d, Y, &oom);
        oom = ogden_fit(d, scan, O, &oom) < 0 || oom;
    }
    if (scan != d)
        cf_table_free(&sub);
    for (int k = 0; k < CF_BASE_COUNT; k++)
        if (out[k].fitted)
            finish(d, &out[k], ymax);
    if (oom)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the baselines' solvers (GSL)");
    return CF_OK;
}
