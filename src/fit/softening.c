/*
** Softening (concave) parts of a table's loading side (see softening.h).
*/
#include "fit/softening.h"

#include <math.h>
#include <stdlib.h>

/* Window positions along the range and the least number of points a window holds. */
#define POSITIONS 24
#define MIN_POINTS 6
#define WIDTH 0.25
#define T_LIMIT 4.0

typedef struct pt {
    double u, v;
} pt;

static int by_u(const void *a, const void *b)
{
    const double x = ((const pt *)a)->u, y = ((const pt *)b)->u;
    return (x > y) - (x < y);
}

/* Least-squares v = a + b t + q t^2 over points [lo, hi) of p, t = (u - c) / w. 1 when the fit is
** regular; *q its curvature (per t^2) and *se its standard error. */
static int quadratic(const pt *p, size_t lo, size_t hi, double c, double w, double *q, double *se)
{
    double S[5] = {0}, R[3] = {0};
    const size_t n = hi - lo;
    for (size_t i = lo; i < hi; i++) {
        const double t = (p[i].u - c) / w;
        double tk = 1;
        for (int k = 0; k < 5; k++, tk *= t)
            S[k] += tk;
        R[0] += p[i].v, R[1] += t * p[i].v, R[2] += t * t * p[i].v;
    }
    /* the normal equations' 3 x 3 matrix M = [S0 S1 S2; S1 S2 S3; S2 S3 S4], by its adjugate */
    const double m00 = S[2] * S[4] - S[3] * S[3], m01 = S[2] * S[3] - S[1] * S[4],
                 m02 = S[1] * S[3] - S[2] * S[2], m11 = S[0] * S[4] - S[2] * S[2],
                 m12 = S[1] * S[2] - S[0] * S[3], m22 = S[0] * S[2] - S[1] * S[1];
    const double det = S[0] * m00 + S[1] * m01 + S[2] * m02;
    if (!(fabs(det) > 1e-12 * fabs(S[0] * S[2] * S[4])) || n <= 3)
        return 0;
    const double a = (m00 * R[0] + m01 * R[1] + m02 * R[2]) / det,
                 b = (m01 * R[0] + m11 * R[1] + m12 * R[2]) / det,
                 qq = (m02 * R[0] + m12 * R[1] + m22 * R[2]) / det;
    double rss = 0;
    for (size_t i = lo; i < hi; i++) {
        const double t = (p[i].u - c) / w, r = p[i].v - (a + b * t + qq * t * t);
        rss += r * r;
    }
    const double s2 = rss / (double)(n - 3), var = s2 * m22 / det;
    *q = qq;
    *se = sqrt(fmax(var, 0));
    return isfinite(qq) && isfinite(*se);
}

cf_softening cf_softening_of(const cf_table *d)
{
    cf_softening r = {0, 0, 0, 0};
    double xmax = 0, sgn = 1, vmax = 0;
    for (size_t i = 0; i < d->count; i++)
        if (fabs(d->x[i]) > xmax)
            xmax = fabs(d->x[i]), sgn = d->x[i] < 0 ? -1 : 1;
    pt *p = malloc(sizeof(pt) * (d->count ? d->count : 1));
    if (!p || !(xmax > 0)) {
        free(p);
        return r;
    }
    size_t n = 0;
    for (size_t i = 0; i < d->count; i++)
        if (sgn * d->x[i] >= 0) {
            p[n].u = sgn * d->x[i], p[n].v = sgn * d->y[i];
            vmax = fmax(vmax, fabs(p[n].v));
            n++;
        }
    if (n < 8 || !(vmax > 0)) {
        free(p);
        return r;
    }
    qsort(p, n, sizeof *p, by_u);
    double lo_c = HUGE_VAL, hi_c = -HUGE_VAL;
    for (int k = 0; k < POSITIONS; k++) {
        /* a window of WIDTH of the range, widened to MIN_POINTS points about its centre */
        const double c = xmax * (0.5 * WIDTH + (1 - WIDTH) * k / (POSITIONS - 1));
        double w = 0.5 * WIDTH * xmax;
        size_t lo = 0, hi = 0;
        for (int grow = 0; grow < 64; grow++, w *= 1.1) {
            for (lo = 0; lo < n && p[lo].u < c - w; lo++)
                ;
            for (hi = lo; hi < n && p[hi].u <= c + w; hi++)
                ;
            if (hi - lo >= MIN_POINTS)
                break;
        }
        double q = 0, se = 0;
        if (hi - lo < MIN_POINTS || !quadratic(p, lo, hi, c, w, &q, &se))
            continue;
        /* the bend away from the chord over the window: the chord through the ends passes q above
        ** (or below) the quadratic at the centre */
        const double bend = -q;
        if (q < 0 && q < -T_LIMIT * se && bend > CF_SOFTENING_BEND * vmax) {
            lo_c = fmin(lo_c, p[lo].u);
            hi_c = fmax(hi_c, p[hi - 1].u);
        }
    }
    free(p);
    if (hi_c > lo_c && (hi_c - lo_c) / xmax >= CF_SOFTENING_SHARE) {
        r.found = 1;
        r.from = sgn * lo_c;
        r.to = sgn * hi_c;
        r.share = (hi_c - lo_c) / xmax;
    }
    return r;
}
