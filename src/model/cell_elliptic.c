/*
** The acoustic tensor of the homogenised cell and its smallest eigenvalue over every direction
** (see cell_elliptic.h).
*/
#include "model/cell_elliptic.h"

#include <math.h>
#include <string.h>

/* Steps of the scan from 0 to the reach, and bisections of a step where ellipticity is lost. */
#define SCAN_STEPS 32
#define BISECTIONS 20
/* Grid directions the pattern search starts from, and its first and last angular step, rad. */
#define REFINE_STARTS 2
#define STEP_FIRST 0.1
#define STEP_LAST 1e-7

/* The smallest eigenvalue of the symmetric 3 x 3 matrix a (row-major; overwritten) by cyclic
** Jacobi rotations (Golub & Van Loan, Matrix Computations, 4th ed., sec. 8.5): accurate to
** rounding also for a repeated eigenvalue, where the closed form of the cubic's roots loses half
** the digits. */
static double sym3_min_eigen(double a[9])
{
    for (int sweep = 0; sweep < 50; sweep++) {
        const double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
        const double diag = a[0] * a[0] + a[4] * a[4] + a[8] * a[8];
        if (off <= 1e-32 * diag || off == 0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                const double apq = a[3 * p + q];
                if (apq == 0)
                    continue;
                const double theta = (a[3 * q + q] - a[3 * p + p]) / (2.0 * apq);
                const double t =
                    (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                const double c = 1.0 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* columns p, q of a J */
                    const double akp = a[3 * k + p], akq = a[3 * k + q];
                    a[3 * k + p] = c * akp - s * akq;
                    a[3 * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* rows p, q of J^T (a J) */
                    const double apk = a[3 * p + k], aqk = a[3 * q + k];
                    a[3 * p + k] = c * apk - s * aqk;
                    a[3 * q + k] = s * apk + c * aqk;
                }
                a[3 * p + q] = a[3 * q + p] = 0.0;
            }
    }
    return fmin(a[0], fmin(a[4], a[8]));
}

/* The smallest eigenvalue of Q(n) for unit n. */
static double q_min_at(const double A[81], const double n[3])
{
    double Q[9] = {0};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double s = 0;
            for (int j = 0; j < 3; j++)
                for (int l = 0; l < 3; l++)
                    s += A[27 * i + 9 * j + 3 * k + l] * n[j] * n[l];
            Q[3 * i + k] = s;
        }
    for (int i = 0; i < 3; i++) /* symmetric up to rounding: average the two halves */
        for (int k = i + 1; k < 3; k++)
            Q[3 * i + k] = Q[3 * k + i] = 0.5 * (Q[3 * i + k] + Q[3 * k + i]);
    return sym3_min_eigen(Q);
}

/* Direction i of the Fibonacci sphere of CF_ACOUSTIC_DIRECTIONS points. */
static void fibonacci(int i, double n[3])
{
    const double golden = M_PI * (3.0 - sqrt(5.0));
    const double z = 1.0 - (2.0 * i + 1.0) / CF_ACOUSTIC_DIRECTIONS;
    const double r = sqrt(fmax(0.0, 1.0 - z * z));
    n[0] = r * cos(golden * i);
    n[1] = r * sin(golden * i);
    n[2] = z;
}

/* Two unit vectors orthogonal to unit n and to each other. */
static void tangents(const double n[3], double t1[3], double t2[3])
{
    const double e[3] = {fabs(n[0]) < 0.6 ? 1.0 : 0.0, fabs(n[0]) < 0.6 ? 0.0 : 1.0, 0.0};
    t1[0] = n[1] * e[2] - n[2] * e[1];
    t1[1] = n[2] * e[0] - n[0] * e[2];
    t1[2] = n[0] * e[1] - n[1] * e[0];
    const double m = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int a = 0; a < 3; a++)
        t1[a] /= m;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

/* Pattern search on the sphere from n (value *q there): moves along the two tangents while that
** lowers the smallest eigenvalue, halving the angular step when no move does. */
static void refine(const double A[81], double n[3], double *q)
{
    for (double h = STEP_FIRST; h > STEP_LAST;) {
        double t1[3], t2[3], best[3] = {n[0], n[1], n[2]};
        tangents(n, t1, t2);
        double qb = *q;
        for (int s = 0; s < 4; s++) {
            const double c = cos(h), sn = sin(h) * (s & 1 ? -1.0 : 1.0);
            const double *t = s < 2 ? t1 : t2;
            double m[3];
            for (int a = 0; a < 3; a++)
                m[a] = c * n[a] + sn * t[a];
            const double qm = q_min_at(A, m);
            if (qm < qb) {
                qb = qm;
                memcpy(best, m, sizeof best);
            }
        }
        if (qb < *q) {
            *q = qb;
            const double len = sqrt(best[0] * best[0] + best[1] * best[1] + best[2] * best[2]);
            for (int a = 0; a < 3; a++)
                n[a] = best[a] / len;
        } else {
            h *= 0.5;
        }
    }
}

cf_status cf_acoustic_min(const double A[81], double *q_min_MPa, double n[3], cf_error *err)
{
    for (int p = 0; p < 81; p++)
        if (!isfinite(A[p]))
            return cf_error_set(err, CF_E_DATA, "elasticity tensor entry %d: %g, not finite", p,
                                A[p]);
    /* the REFINE_STARTS lowest grid directions, lowest first */
    double qs[REFINE_STARTS], ns[REFINE_STARTS][3];
    int have = 0;
    for (int i = 0; i < CF_ACOUSTIC_DIRECTIONS; i++) {
        double m[3];
        fibonacci(i, m);
        const double qm = q_min_at(A, m);
        int at = have;
        while (at > 0 && qs[at - 1] > qm)
            at--;
        if (at >= REFINE_STARTS)
            continue;
        const int last = have < REFINE_STARTS ? have : REFINE_STARTS - 1;
        for (int j = last; j > at; j--) {
            qs[j] = qs[j - 1];
            memcpy(ns[j], ns[j - 1], sizeof ns[j]);
        }
        qs[at] = qm;
        memcpy(ns[at], m, sizeof ns[at]);
        if (have < REFINE_STARTS)
            have++;
    }
    double qb = INFINITY, nb[3] = {0, 0, 1};
    for (int s = 0; s < have; s++) {
        refine(A, ns[s], &qs[s]);
        if (qs[s] < qb) {
            qb = qs[s];
            memcpy(nb, ns[s], sizeof nb);
        }
    }
    int big = 0; /* Q(n) = Q(-n): the sign that makes the largest component positive */
    for (int a = 1; a < 3; a++)
        if (fabs(nb[a]) > fabs(nb[big]))
            big = a;
    const double sign = nb[big] < 0 ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++) /* rounding-level components as zero (no "-0.000" printed) */
        n[a] = fabs(nb[a]) < 1e-9 ? 0.0 : sign * nb[a];
    *q_min_MPa = qb;
    return CF_OK;
}

/* 1: the state of mode m at strain e exists and is strongly elliptic; 0: it is not (n the
** softest direction) or cannot be reached (n zero). */
static int elliptic_at(const cf_cell *c, cf_mode m, double e, double n[3])
{
    cf_cell_state s;
    double A[81], q = 0;
    memset(n, 0, 3 * sizeof(double));
    if (cf_cell_mode(c, m, e, NULL, &s, NULL) != CF_OK ||
        cf_cell_tangent(c, s.F, NULL, &s, A, NULL) != CF_OK)
        return 0;
    if (cf_acoustic_min(A, &q, n, NULL) != CF_OK) {
        memset(n, 0, 3 * sizeof(double));
        return 0;
    }
    return q > 0;
}

cf_status cf_cell_elliptic_to(const cf_cell *c, cf_mode m, double reach, double *limit, int *lost,
                              double n[3], cf_error *err)
{
    *limit = reach;
    *lost = 0;
    memset(n, 0, 3 * sizeof(double));
    if (!isfinite(reach))
        return cf_error_set(err, CF_E_DATA, "strain %g: not finite", reach);
    double good = 0, nb[3];
    for (int k = 0; k <= SCAN_STEPS; k++) {
        const double e = reach * k / SCAN_STEPS;
        if (elliptic_at(c, m, e, nb)) {
            good = e;
            continue;
        }
        memcpy(n, nb, sizeof nb);
        if (k == 0) {
            *limit = 0;
            *lost = 1;
            return CF_OK;
        }
        double bad = e;
        for (int b = 0; b < BISECTIONS && fabs(bad - good) > 1e-6 * fabs(reach); b++) {
            const double mid = 0.5 * (good + bad);
            if (elliptic_at(c, m, mid, nb)) {
                good = mid;
            } else {
                bad = mid;
                memcpy(n, nb, sizeof nb);
            }
        }
        *limit = good;
        *lost = 1;
        return CF_OK;
    }
    return CF_OK;
}
