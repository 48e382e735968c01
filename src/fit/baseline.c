/*
** Baseline fits (see baseline.h): the linear and Duffing laws are linear in their coefficients
** and solved in closed form; Fung's law is linear in A for a fixed B, so B is found by a scan and
** a golden-section refinement of the profile RSS(B).
*/
#include "conifit/baseline.h"

#include <float.h>
#include <math.h>

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

/* RSS of Fung's law with A solved for the given B (A returned). */
static double fung_profile(const cf_table *d, double B, double *A)
{
    double sgy = 0, sgg = 0, syy = 0;
    for (size_t i = 0; i < d->count; i++) {
        double g = expm1(B * d->x[i]);
        sgy += g * d->y[i];
        sgg += g * g;
        syy += d->y[i] * d->y[i];
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

void cf_baseline_fit_all(const cf_table *d, cf_baseline out[CF_BASE_COUNT])
{
    double xmax = 0, ymax = 0;
    double s2 = 0, s4 = 0, s6 = 0, sy1 = 0, sy3 = 0;
    for (size_t i = 0; i < d->count; i++) {
        double x = d->x[i], y = d->y[i], x2 = x * x;
        xmax = fmax(xmax, fabs(x));
        ymax = fmax(ymax, fabs(y));
        s2 += x2;
        s4 += x2 * x2;
        s6 += x2 * x2 * x2;
        sy1 += x * y;
        sy3 += x2 * x * y;
    }
    cf_baseline *L = &out[CF_BASE_LINEAR], *D = &out[CF_BASE_DUFFING], *F = &out[CF_BASE_FUNG];
    *L = (cf_baseline){CF_BASE_LINEAR, 1, {s2 > 0 ? sy1 / s2 : 0, 0}, 0, 0, 0};
    /* normal equations of (k1, k3): [s2 s4; s4 s6] k = [sy1; sy3] */
    double det = s2 * s6 - s4 * s4;
    *D = (cf_baseline){CF_BASE_DUFFING, 2, {0, 0}, 0, 0, 0};
    if (det > 1e-14 * s2 * s6) {
        D->coef[0] = (sy1 * s6 - sy3 * s4) / det;
        D->coef[1] = (s2 * sy3 - s4 * sy1) / det;
    } else {
        D->coef[0] = L->coef[0];
    }
    /* Fung: scan B over +-50/xmax (exp(50) covers any stiffening a table shows), then refine */
    *F = (cf_baseline){CF_BASE_FUNG, 2, {0, 0}, 0, 0, 0};
    double bmax = xmax > 0 ? 50.0 / xmax : 1.0;
    double bestB = bmax / 400, bestR = INFINITY, A;
    const int N = 400;
    for (int i = -N; i <= N; i++) {
        if (i == 0)
            continue;
        double B = bmax * (double)i / N;
        double r = fung_profile(d, B, &A);
        if (r < bestR) {
            bestR = r;
            bestB = B;
        }
    }
    double a = bestB - bmax / N, b = bestB + bmax / N;
    const double g = 0.5 * (sqrt(5.0) - 1);
    double c1 = b - g * (b - a), c2 = a + g * (b - a);
    double f1 = fung_profile(d, c1, &A), f2 = fung_profile(d, c2, &A);
    for (int it = 0; it < 200 && (b - a) > 1e-15 * fabs(b) + 1e-300; it++) {
        if (f1 < f2) {
            b = c2;
            c2 = c1;
            f2 = f1;
            c1 = b - g * (b - a);
            f1 = fung_profile(d, c1, &A);
        } else {
            a = c1;
            c1 = c2;
            f1 = f2;
            c2 = a + g * (b - a);
            f2 = fung_profile(d, c2, &A);
        }
    }
    double Bf = 0.5 * (a + b);
    if (fung_profile(d, Bf, &A) > bestR)
        Bf = bestB;
    fung_profile(d, Bf, &A);
    F->coef[0] = A;
    F->coef[1] = Bf;
    finish(d, L, ymax);
    finish(d, D, ymax);
    finish(d, F, ymax);
}
