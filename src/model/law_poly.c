/*
** The polynomial form of region 2 for one spring (law_simd.h says what a lane computes with it):
** Chebyshev interpolation of P(w) = e/w and K(w) = 1/h'(P(w)) on [0, w_T] at degree + 1 Chebyshev
** points from the exact solver, turned into powers of x = 2w/w_T - 1, then measured against the
** closed form (closed+newton, within 2e-15 of exact) over region 2; degree 8 first, 12 where 8
** falls short (degree 8 spares 8 multiply-adds per spring, measured 9 % of the whole step).
**
** Why it converges: P is analytic wherever the quartic's root is simple, i.e. away from c^4 = 1;
** in z = sqrt(1/rho - 1) w those points lie 1.19 from the origin at +-67.5 degrees and at +-1.41i,
** so over [0, z_T] the Chebyshev coefficients fall geometrically, fast while z_T (which grows as
** rho falls: 0.73 at rho = 0.5, 1.66 at 0.2, 27 at 1e-3) stays near 1. Measured in double (F
** after the Newton step): degree 8, 1.4e-15 at rho = 0.5, 8e-15 at 0.4, 2e-10 at 0.2; degree 12,
** 1e-15 at 0.4, 2e-14 at 0.2, 2e-11 at 0.1; two pieces of degree 12, 5e-15 at 0.1, 9e-15 at
** 0.05, 8e-13 at 0.02 (pieces of equal width: 3e-13 at 0.05). A fit above CF_POLY_TOL is refused
** and the caller keeps the closed form.
*/
#include "model/law_simd.h"

#include <math.h>
#include <string.h>

#define MAX_TERMS (CF_POLY_DEGREE + 1)
#define CHECK_POINTS 2048 /* per sweep: uniform in w, then uniform in u */

/* Chebyshev interpolant of the terms values f at the points cos(pi (j + 1/2)/terms) as powers
** of x. */
static void cheb_to_powers(const long double *f, int terms, double *out)
{
    long double c[MAX_TERMS] = {0}, m[MAX_TERMS] = {0}, t0[MAX_TERMS] = {0}, t1[MAX_TERMS] = {0},
                              t2[MAX_TERMS];
    const long double pi = 3.141592653589793238462643383279502884L;
    for (int k = 0; k < terms; k++) {
        long double sum = 0;
        for (int j = 0; j < terms; j++)
            sum += f[j] * cosl(pi * k * (j + 0.5L) / terms);
        c[k] = sum * 2 / terms;
    }
    c[0] /= 2;
    t0[0] = 1; /* T_0 and T_1 as powers of x, then T_{k+1} = 2x T_k - T_{k-1} */
    t1[1] = 1;
    m[0] = c[0];
    for (int i = 0; i < terms; i++)
        m[i] += c[1] * t1[i];
    for (int k = 2; k < terms; k++) {
        for (int i = 0; i < terms; i++)
            t2[i] = (i ? 2 * t1[i - 1] : 0) - t0[i];
        for (int i = 0; i < terms; i++) {
            m[i] += c[k] * t2[i];
            t0[i] = t1[i];
            t1[i] = t2[i];
        }
    }
    for (int i = 0; i < terms; i++)
        out[i] = (double)m[i];
}

/* The largest relative error of the lanes' force against closed+newton at the region-2 points
** among count displacements u (work: scratch for the forces). */
static double worst_error(const cf_law *law, const cf_law_lanes *lanes, const double *u,
                          size_t count, double *work)
{
    cf_law_force_lanes(lanes, CF_LANE_POLY, count, u, work);
    double worst = 0;
    for (size_t i = 0; i < count; i++) {
        int flags;
        const double R = cf_law_force(law, CF_LAW_CLOSED_NEWTON, u[i], NULL, &flags);
        if (flags != 0) /* regions 1 and 3 are the closed form's own, exactly */
            continue;
        const double rel = fabs(work[i] - R) / fabs(R);
        worst = rel > worst || rel != rel ? rel : worst;
    }
    return worst;
}

/* Interpolates P and K of degree deg on [w0, w1] into piece q. */
static void fit_piece(const cf_law *law, cf_law_lanes *lanes, int q, double w0, double w1, int deg)
{
    const double r = law->rho_inv_m1;
    const int terms = deg + 1;
    long double Pv[MAX_TERMS], Kv[MAX_TERMS];
    const long double pi = 3.141592653589793238462643383279502884L;
    for (int j = 0; j < terms; j++) {
        const long double x = cosl(pi * (j + 0.5L) / terms);
        const double w = (double)(w0 + (x + 1) * 0.5L * (w1 - w0));
        const long double P = (long double)cf_law_region2_e(law, r * w * w) / w;
        Pv[j] = P;
        Kv[j] = 1 / (12 * P - 12 * w * P * P + 4 * (long double)w * w * P * P * P + 4 * r * w);
    }
    memset(lanes->pa[q], 0, sizeof lanes->pa[q]);
    memset(lanes->pb[q], 0, sizeof lanes->pb[q]);
    cheb_to_powers(Pv, terms, lanes->pa[q]);
    cheb_to_powers(Kv, terms, lanes->pb[q]);
    lanes->px_a[q] = 2.0 / (w1 - w0);
    lanes->px_b[q] = -1.0 - 2.0 * w0 / (w1 - w0);
}

/* Fits deg in pieces pieces (the second from W 2^-1.5: the coefficients of P fall slowest near
** w = 0, where its singularities are nearest) and measures it; 1 when it is kept. */
static int fit_degree(const cf_law *law, cf_law_lanes *lanes, int deg, int pieces, double *worst)
{
    const double W = law->w_T, s = law->travel_mm;
    lanes->poly_degree = deg;
    lanes->poly_pieces = pieces;
    lanes->w_T = W;
    lanes->w_split = pieces == 2 ? W * 0.35355339059327373 : W;
    lanes->r4 = 4.0 * law->rho_inv_m1;
    fit_piece(law, lanes, 0, 0.0, lanes->w_split, deg);
    if (pieces == 2)
        fit_piece(law, lanes, 1, lanes->w_split, W, deg);
    lanes->poly_fit = 1;

    double u[CHECK_POINTS], F[CHECK_POINTS], err = 0;
    for (int sweep = 0; sweep < 2; sweep++) {
        for (int i = 0; i < CHECK_POINTS; i++) {
            const double f = (i + 0.5) / CHECK_POINTS, w = f * W;
            const double a = sweep == 0 ? s - s * (w * w) : law->u_T_mm + (s - law->u_T_mm) * f;
            u[i] = (i & 1) ? -a : a;
        }
        const double e = worst_error(law, lanes, u, CHECK_POINTS, F);
        err = e > err || e != e ? e : err;
    }
    *worst = err;
    if (!(err <= CF_POLY_TOL)) {
        lanes->poly_fit = 0;
        return 0;
    }
    return 1;
}

int cf_law_lanes_fit_poly(const cf_law *law, cf_law_lanes *lanes, double *worst)
{
    double err = NAN;
    lanes->poly_fit = 0;
    const int ok = !law->tail && law->w_T > 0 && law->rho_inv_m1 > 0 && law->u_T_mm < law->travel_mm &&
                   (fit_degree(law, lanes, CF_POLY_DEGREE_LOW, 1, &err) ||
                    fit_degree(law, lanes, CF_POLY_DEGREE, 1, &err) ||
                    fit_degree(law, lanes, CF_POLY_DEGREE, 2, &err));
    if (worst)
        *worst = err;
    return ok;
}
