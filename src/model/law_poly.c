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
**
** A spring with a tail (law.md) has three forms (law_simd.h, cf_lane_poly_tail), tried per size
** (degree 8, 12, two pieces of 12) in the order: the near form while beta < 1/4 (the plain law's
** P, shifted to the minimum e* of the tailed relation, in the table's variable z), then E(z) ~ e
** with z = v = (u_C - |u|)/s, then with z = sqrt(v). Measured (n = 4, the tail's gap 1.5 times the
** cone's): the near form holds the bound for beta up to 0.2 and rho down to 0.03, as the plain
** law does (two pieces below rho = 0.15); past beta = 1/4, where the tail's term changes the
** relation's shape, the direct forms hold it for every beta at rho >= 0.5, up to beta = 1 at
** rho >= 0.2, up to 0.3 at rho >= 0.1, and are refused for a stiffer cone or a softer tail
** (e.g. rho = 0.3 with beta = 3: 2e-8): such a lattice keeps the scalar law. The fit of a tailed
** spring costs 4 ms (the benchmark's, rho = 1/3 and beta = 0.5, two pieces in v) up to 15 ms (a
** refused one: each of its nine fits measured over 4096 points), once per lattice.
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

/* The same for a spring with a tail (law_simd.h, cf_lane_poly_tail) on [z0, z1], with
** Delta = r (z - kappa)(z + kappa) at each node: P = (e - e*)/z and K = 1/h'(P) in the near form,
** else E = e and K = 1/h'(e). */
static void fit_piece_tail(const cf_law *law, cf_law_lanes *lanes, int q, double z0, double z1,
                           int deg)
{
    const double r = law->rho_inv_m1;
    const long double b = law->beta, es = lanes->e_star;
    const int terms = deg + 1;
    long double Ev[MAX_TERMS], Kv[MAX_TERMS];
    const long double pi = 3.141592653589793238462643383279502884L;
    for (int j = 0; j < terms; j++) {
        const long double x = cosl(pi * (j + 0.5L) / terms);
        const double z = (double)(z0 + (x + 1) * 0.5L * (z1 - z0));
        const double dv = lanes->tail_form == CF_TAIL_V ? z : (z - lanes->z0) * (z + lanes->z0);
        const double d = r * (dv > 0 ? dv : 0.0);
        const long double e = cf_law_region2_e(law, d);
        if (lanes->tail_form == CF_TAIL_NEAR) {
            const long double P = (e - es) / z;
            const long double Q = lanes->q0 + e * (lanes->q1 + e * (long double)lanes->q2);
            const long double dQ = lanes->q1 + 2 * e * (long double)lanes->q2;
            Ev[j] = P;
            Kv[j] = 1 / (2 * P * Q + P * P * dQ * z + 4 * (long double)r * z);
        } else {
            Ev[j] = e;
            Kv[j] = 1 / (12 * e - 12 * e * e + 4 * e * e * e +
                         4 * b * (3 - 12 * e + 12 * e * e - 4 * e * e * e) + 4 * (long double)d);
        }
    }
    memset(lanes->pa[q], 0, sizeof lanes->pa[q]);
    memset(lanes->pb[q], 0, sizeof lanes->pb[q]);
    cheb_to_powers(Ev, terms, lanes->pa[q]);
    cheb_to_powers(Kv, terms, lanes->pb[q]);
    lanes->px_a[q] = 2.0 / (z1 - z0);
    lanes->px_b[q] = -1.0 - 2.0 * z0 / (z1 - z0);
}

/* Prepares form (law_simd.h, cf_lane_poly_tail) of a tailed spring: for CF_TAIL_NEAR, Phi's
** minimum e* = 1 - (1 - 4 beta)^(-1/4) < 0, kappa^2 = -Phi(e*)/r and the quotient
** Q = N(e)/(e - e*)^2 (N's remainder after the division is a rounding of Phi(e*), whose effect on h
** is at most that rounding over r z^2 >= r kappa^2, i.e. relative); 0 when the form does not
** exist (no minimum: beta >= 1/4). */
static int tail_variable(const cf_law *law, cf_law_lanes *lanes, int form)
{
    const long double beta = law->beta, r = law->rho_inv_m1;
    lanes->tail_form = form;
    lanes->kappa2 = 0.0;
    lanes->e_star = lanes->q0 = lanes->q1 = lanes->q2 = 0.0;
    lanes->z0 = 0.0;
    if (form != CF_TAIL_NEAR)
        return 1;
    if (!(beta < 0.25L))
        return 0;
    const long double e = -expm1l(-0.25L * log1pl(-4 * beta));
    const long double phi = e * e * (6 + e * (-4 + e)) / (4 * (1 - e)) + beta * e * (3 + e * (-3 + e));
    const double k2 = (double)(-phi / r);
    if (!(k2 > 0 && isfinite(k2)))
        return 0;
    lanes->kappa2 = k2;
    /* N(e) = (1 - 4b) e^4 + (16b - 4) e^3 + (6 - 24b) e^2 + ... over e^2 - 2 e* e + e*^2 */
    const long double q2 = 1 - 4 * beta, q1 = (16 * beta - 4) + 2 * e * q2,
                      q0 = (6 - 24 * beta) + 2 * e * q1 - e * e * q2;
    lanes->e_star = (double)e;
    lanes->q2 = (double)q2;
    lanes->q1 = (double)q1;
    lanes->q0 = (double)q0;
    lanes->z0 = sqrt(k2);
    return 1;
}

/* Fits deg in pieces pieces (and a tailed spring's form, prepared by tail_variable) (the second from W 2^-1.5: the coefficients of P fall slowest near
** w = 0, where its singularities are nearest) and measures it; 1 when it is kept. */
static int fit_degree(const cf_law *law, cf_law_lanes *lanes, int deg, int pieces, double *worst)
{
    const double s = law->travel_mm;
    lanes->poly_degree = deg;
    lanes->poly_pieces = pieces;
    lanes->r4 = 4.0 * law->rho_inv_m1;
    if (law->tail) {
        /* in z from z0 (the cone's solid) to the transition; u_C - s_c v at v = z^2 - kappa^2 */
        const double Z0 = lanes->z0,
                     Z = lanes->tail_form == CF_TAIL_V ? law->w_T * law->w_T
                                                       : sqrt(law->w_T * law->w_T + lanes->kappa2);
        lanes->w_T = Z;
        lanes->w_split = pieces == 2 ? Z0 + (Z - Z0) * 0.35355339059327373 : Z;
        fit_piece_tail(law, lanes, 0, Z0, lanes->w_split, deg);
        if (pieces == 2)
            fit_piece_tail(law, lanes, 1, lanes->w_split, Z, deg);
    } else {
        const double W = law->w_T;
        lanes->w_T = W;
        lanes->w_split = pieces == 2 ? W * 0.35355339059327373 : W;
        fit_piece(law, lanes, 0, 0.0, lanes->w_split, deg);
        if (pieces == 2)
            fit_piece(law, lanes, 1, lanes->w_split, W, deg);
    }
    lanes->poly_fit = 1;

    double u[CHECK_POINTS], F[CHECK_POINTS], err = 0;
    const double uC = law->u_C_mm, sc = law->cone_travel_mm, Z0 = lanes->z0, Z = lanes->w_T;
    for (int sweep = 0; sweep < 2; sweep++) {
        for (int i = 0; i < CHECK_POINTS; i++) {
            const double f = (i + 0.5) / CHECK_POINTS;
            double a;
            if (sweep == 1)
                a = law->u_T_mm + (uC - law->u_T_mm) * f;
            else if (law->tail) {
                const double z = Z0 + f * (Z - Z0);
                a = uC - sc * (lanes->tail_form == CF_TAIL_V ? z : (z - Z0) * (z + Z0));
            } else {
                const double w = f * Z;
                a = s - s * (w * w);
            }
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

/* The degrees and pieces in the order tried, cheapest first. */
static const int configs[3][2] = {{CF_POLY_DEGREE_LOW, 1}, {CF_POLY_DEGREE, 1}, {CF_POLY_DEGREE, 2}};

int cf_law_lanes_fit_poly(const cf_law *law, cf_law_lanes *lanes, double *worst)
{
    double err = NAN;
    lanes->poly_fit = 0;
    int ok = law->w_T > 0 && law->rho_inv_m1 > 0 && law->u_T_mm < law->travel_mm;
    if (ok && law->tail) {
        /* per size, the forms in the order near (the plain law's, shifted), then in v (no square
        ** root), then in w */
        static const int forms[3] = {CF_TAIL_NEAR, CF_TAIL_V, CF_TAIL_W};
        ok = 0;
        for (int k = 0; k < 3 && !ok; k++)
            for (int f = 0; f < 3 && !ok; f++)
                ok = tail_variable(law, lanes, forms[f]) &&
                     fit_degree(law, lanes, configs[k][0], configs[k][1], &err);
    } else if (ok) {
        ok = 0;
        for (int k = 0; k < 3 && !ok; k++)
            ok = fit_degree(law, lanes, configs[k][0], configs[k][1], &err);
    }
    if (worst)
        *worst = err;
    return ok;
}
