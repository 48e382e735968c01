/*
** The law as branch-free lane functions, for loops the compiler vectorises (`#pragma omp simd`):
** every region is computed and the result selected, so a vector of displacements in different
** regions takes one path. Forces only (an explicit step needs no stiffness); the scalar evaluators
** of law.c keep the stiffness and the other methods.
**
** Closed form (region 2), with delta = (1/rho - 1)(s - |u|)/s and c = 1 + delta:
**   t = cbrt(c^2 + sqrt(c^4 - 1)) from a division-free inverse cube root r = 1/t (an exponent-
**   thirding start good to 3.4 %, two fourth-order steps, one Newton step on t), mu = (t - 1)^2 r,
**   m = 2 + mu, Q = 2 sqrt2 c sqrt(m) + m^2, P = 12 (c^2 - 1 - mu/2) Q, and
**   y = 6 sqrt(m) Q / ((m sqrt(m) + sqrt2 c)(sqrt2 sqrt(m) Q + sqrt(P))),   F = F_C y^3:
** Ferrari's root of y^4 - 4 c y + 3 = 0 (law.c, region2_closed) with its divisions gathered into
** one. All terms are positive, so y carries a relative error of a few ulps; t - 1 is formed by a
** plain subtraction, which near solid loses relative digits of mu but only absolute ones of y
** (measured against the long-double reference of tests/unit/test_law.c: 2.4e-15 of |F| at worst over
** every hard case). Costs one division per lane; its three square roots are x times 1/sqrt(x)
** from cf_lane_rsqrt (multiplies and adds, no square-root instruction).
** Table: the cubic Hermite table of law.c, stored per interval as the coefficients of its
** polynomial in the local coordinate (one cache line per lookup); the same values as law.c's.
** Polynomial (one spring, many evaluations: the lattice's explicit step): region 2 as a function
** of w = sqrt((s - |u|)/s) alone, fitted for one spring by law_poly.c. With e = 1 - y = w P and
** r = 1/rho - 1, the quartic divided by w^2 reads
**   h(P) = P^2 (6 - 4e + e^2) - 4 r (1 - e) = 0,   regular at w = 0 (P(0) = sqrt(2r/3)),
** and P(w) is analytic on [0, w_T] (its singularities lie where c^4 = 1, delta = -2 or -1 +- i,
** off the real axis). Two polynomials of degree CF_POLY_DEGREE_LOW or, where that is not enough,
** CF_POLY_DEGREE, in w, from Chebyshev interpolation of the exact solution: P0(w) ~ P and
** K(w) ~ 1/h'(P) (for a strongly conical spring, whose w_T lies far out relative to those
** singularities, two pieces of degree CF_POLY_DEGREE split at w_split, the piece of each lane
** chosen by selection); then one division-free Newton step
** P1 = P0 - h(P0) K, whose error is about the product of the two fits' errors, and y = 1 - w P1.
** No lookup, no division, one square root: every lane runs the same few multiply-adds. The fit
** is kept only where it is measured within CF_POLY_TOL of the closed form (law_poly.c).
**
** Vectorisation: every loop over lanes must if-convert, so no lane's work may sit behind a
** condition the compiler keeps as a branch (a table lookup inside the region selection, a clamp it
** specialises): the table's lookup is a loop of its own, and the build passes -fno-trapping-math
** so that both sides of a selection may be computed. Each copy (baseline SSE2, AVX2, AVX-512)
** vectorises, at its own width.
**
** Private to the model layer.
*/
#ifndef CF_MODEL_LAW_SIMD_H
#define CF_MODEL_LAW_SIMD_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "model/law_internal.h"
#include "model/simd.h"

#if defined(__GNUC__)
#define CF_LANE static inline __attribute__((always_inline))
#else
#define CF_LANE static inline
#endif

/* Run-time dispatch. A function is written once as a macro DEF(attr, sfx, ...) that defines
** `attr static ... name##sfx(...)`; CF_SIMD_COPIES(DEF, ...) expands it for baseline x86-64 (SSE2,
** suffix _v1), x86-64-v3 (AVX2, FMA; _v3) and x86-64-v4 (AVX-512; _v4), and CF_SIMD_CALL(name, args)
** calls the widest copy that the processor has and that the environment variable CONIFIT_SIMD
** allows (cf_simd_level, model/simd.h): so the tests run every copy on a machine that has it, not
** only the widest. A copy is a whole function, its OpenMP regions included, so the threads of a
** parallel loop run the same instruction set as the copy. Elsewhere (clang, other processors, the
** sanitizer build) one baseline copy. The copies evaluate the same expressions, but their widths
** differ, and so may the vector libraries they call and the order of a reduction: they agree to a
** few ulps, not bit for bit. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
#define CF_SIMD_MULTI 1
#define CF_SIMD_COPIES(DEF, ...)                                                                   \
    DEF(, _v1, __VA_ARGS__)                                                                        \
    DEF(__attribute__((target("arch=x86-64-v3"))), _v3, __VA_ARGS__)                               \
    DEF(__attribute__((target("arch=x86-64-v4"))), _v4, __VA_ARGS__)
#define CF_SIMD_CALL(name, args)                                                                   \
    (cf_simd_level() >= CF_SIMD_AVX512 ? name##_v4 args                                            \
     : cf_simd_level() >= CF_SIMD_AVX2 ? name##_v3 args                                            \
                                       : name##_v1 args)
#else
#define CF_SIMD_MULTI 0
#define CF_SIMD_COPIES(DEF, ...) DEF(, _v1, __VA_ARGS__)
#define CF_SIMD_CALL(name, args) (name##_v1 args)
#endif

#define CF_POLY_DEGREE 12    /* the largest degree */
#define CF_POLY_DEGREE_LOW 8 /* the degree tried first (rho down to about 0.4) */
#define CF_POLY_TOL 1e-13 /* largest relative error of F, against the closed form, for a fit */

/* Everything a lane needs, copied by value into the loop (loads the compiler can hoist). */
typedef struct cf_law_lanes {
    double u_T, s, inv_s, k0, F_C, rim1; /* law.h: u_T_mm, travel_mm, inv_travel, k0, F_C, 1/rho-1 */
    const double *coef; /* table: 4 coefficients per interval (NULL: no table) */
    double inv_h;       /* table: intervals per unit of w */
    double xmax;        /* table: intervals - 1, the last interval's index */
    /* polynomial (poly_fit set by cf_law_lanes_fit_poly): w is clamped to w_T; piece q (0, or 1
    ** above w_split when there are two) maps it to x = w px_a[q] + px_b[q] in [-1, 1], where
    ** pa[q] and pb[q] are P0 and K in powers of x, of degree poly_degree */
    int poly_fit, poly_degree, poly_pieces;
    double w_T, w_split, r4; /* w_T, the pieces' boundary, 4 (1/rho - 1) */
    double px_a[2], px_b[2];
    double pa[2][CF_POLY_DEGREE + 1], pb[2][CF_POLY_DEGREE + 1];
    /* a spring with a cylindrical tail (tail = 1; law.md): the lanes hold its polynomial only
    ** (cf_lane_poly_tail), s is the whole travel to solid and inv_s the cone's 1/s; the
    ** polynomial's variable is z = sqrt((u_C - |u|)/s + kappa2), clamped to w_T (the fit's end,
    ** the transition) and from z0 = sqrt(kappa2) (the cone's solid); law: the law itself, which
    ** cf_law_force_lanes runs for any other form */
    int tail, tail_form; /* tail_form: CF_TAIL_NEAR, CF_TAIL_W or CF_TAIL_V (below) */
    const cf_law *law;
    double u_C, k_t, F_sol, kappa2, z0, b4; /* u_C, k_tail, F_solid, kappa^2, kappa, 4 beta */
    double e_star, q0, q1, q2; /* CF_TAIL_NEAR: e* and Q(e) = q0 + q1 e + q2 e^2 */
} cf_law_lanes;

/* Fills lanes from law; the table coefficients are those of law's table when it has one. No
** polynomial (poly_fit = 0). */
void cf_law_lanes_init(const cf_law *law, cf_law_lanes *lanes);

/* Fits the polynomial of region 2 to law (law_poly.c): one piece of degree CF_POLY_DEGREE_LOW,
** else of CF_POLY_DEGREE, else two pieces of CF_POLY_DEGREE, each measured against the closed form
** over region 2; keeps the first whose largest relative error of F is within CF_POLY_TOL
** (poly_fit = 1, poly_degree, poly_pieces) and returns 1, else 0 (the spring is too conical even
** for two pieces: about rho < 0.05, or has no region 2). *worst (may be NULL) receives the measured
** error of the last fit tried, or NAN when nothing was fitted. */
int cf_law_lanes_fit_poly(const cf_law *law, cf_law_lanes *lanes, double *worst);

/* The same force of one lane for any form: the caller has chosen it at compile time. */
enum { CF_LANE_CLOSED = 0, CF_LANE_TABLE = 1, CF_LANE_POLY = 2 };

/* Regions 1 and 3 around a region-2 value F2 computed for a = |u|; NaN gives 0. */
CF_LANE double cf_lane_regions(const cf_law_lanes *c, double u, double a, double F2)
{
    const double F1 = c->k0 * a, F3 = c->F_C;
    double F = a < c->s ? F2 : F3;
    F = a <= c->u_T ? F1 : F;
    F = copysign(F, u);
    return u != u ? 0.0 : F;
}

/* 1/sqrt(x) for x = 0 (a large finite value, so that x times it is 0) or a normal positive x,
** without a square root or a division (both share one slow unit of the processor): a start from
** the exponent good to 3.5 %, a fourth-order step (to 4e-7), a second-order one; within 3e-16
** of 1/sqrt(x), and x times it within 3e-16 of sqrt(x). */
CF_LANE double cf_lane_rsqrt(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    b = UINT64_C(0x5FE6EB50C7B537A9) - (b >> 1);
    double r;
    memcpy(&r, &b, sizeof r);
    /* (x r) r, not x (r r): at x = 0 the start is near 2^511, whose square overflows */
    double e = 1.0 - (x * r) * r;
    r = r + r * e * (0.5 + e * (0.375 + e * (0.3125 + e * 0.2734375)));
    e = 1.0 - (x * r) * r;
    return r + r * e * (0.5 + e * 0.375);
}

/* Region 2's root y (F = F_C y^3) at a = |u| for every lane whatever its region (the caller
** selects): past solid delta is 0 and y 1. */
CF_LANE double cf_lane_closed_y(const cf_law_lanes *c, double a)
{
    const double sa = c->s - a;
    const double delta = c->rim1 * ((sa > 0.0 ? sa : 0.0) * c->inv_s);
    const double cc = 1.0 + delta;
    const double dd = delta * (2.0 + delta); /* c^2 - 1 without cancellation */
    const double X1 = dd * (1.0 + cc * cc);
    const double X = cc * cc + X1 * cf_lane_rsqrt(X1);
    /* r = X^(-1/3): start from the exponent, then two steps of
    ** r <- r (1 + e/3 + 2e^2/9 + 14e^3/81), e = 1 - X r^3 (fourth order, no division) */
    uint64_t bits;
    memcpy(&bits, &X, sizeof bits);
    const int32_t hi = (int32_t)(bits >> 32);
    const int32_t hr = (int32_t)0x553EF100 - (int32_t)((double)hi * (1.0 / 3.0));
    bits = (uint64_t)(uint32_t)hr << 32;
    double r;
    memcpy(&r, &bits, sizeof r);
    double e = 1.0 - X * (r * r * r);
    r = r + r * e * ((1.0 / 3.0) + e * ((2.0 / 9.0) + e * (14.0 / 81.0)));
    e = 1.0 - X * (r * r * r);
    r = r + r * e * ((1.0 / 3.0) + e * ((2.0 / 9.0) + e * (14.0 / 81.0)));
    double t = X * r * r;
    t = t - (t * t * t - X) * (r * r) * (1.0 / 3.0); /* Newton on t^3 = X, 1/(3t^2) ~ r^2/3 */
    const double tm1 = t - 1.0;
    const double mu = tm1 * tm1 * r;
    const double m = 2.0 + mu, rm = m * cf_lane_rsqrt(m);
    const double Q = 2.0 * M_SQRT2 * cc * rm + m * m;
    const double P0 = 12.0 * (dd - 0.5 * mu) * Q;
    const double P = P0 > 0.0 ? P0 : 0.0;
    return 6.0 * rm * Q / ((m * rm + M_SQRT2 * cc) * (M_SQRT2 * rm * Q + P * cf_lane_rsqrt(P)));
}

CF_LANE double cf_lane_closed(const cf_law_lanes *c, double u)
{
    const double a = fabs(u);
    const double y = cf_lane_closed_y(c, a);
    return cf_lane_regions(c, u, a, c->F_C * y * y * y);
}

/* Region 2's y from the table, for every lane whatever its region (the caller selects): the
** interval index is clamped into the table, so the four coefficient loads are always in bounds
** and need no mask. */
CF_LANE double cf_lane_table_y(const cf_law_lanes *c, double u)
{
    const double sa = c->s - fabs(u);
    const double w = sqrt((sa > 0.0 ? sa : 0.0) * c->inv_s);
    const double x = w * c->inv_h;
    /* x >= 0 (or NaN); NaN and region 1 land on the last interval */
    const double xi = x < c->xmax ? x : c->xmax;
    const int32_t i = (int32_t)xi;
    const double q = x - (double)i;
    const double *k = c->coef;
    const int32_t j = 4 * i;
    return k[j] + q * (k[j + 1] + q * (k[j + 2] + q * k[j + 3]));
}

/* The fitted polynomials P and K of a spring's law (law_poly.c) at the variable w (w in the plain
** law, z with a tail), from the piece w falls in: Horner's rule over both at once. */
CF_LANE void cf_lane_poly_pk(const cf_law_lanes *c, double w, int deg, int pieces, double *P_out,
                             double *K_out)
{
    const int q = pieces == 2 && w > c->w_split;
    const double x = w * (q ? c->px_a[1] : c->px_a[0]) + (q ? c->px_b[1] : c->px_b[0]);
    double P = q ? c->pa[1][deg] : c->pa[0][deg], K = q ? c->pb[1][deg] : c->pb[0][deg];
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 32
#endif
    for (int j = deg - 1; j >= 0; j--) {
        P = P * x + (q ? c->pa[1][j] : c->pa[0][j]);
        K = K * x + (q ? c->pb[1][j] : c->pb[0][j]);
    }
    *P_out = P;
    *K_out = K;
}

/* The force from the fitted polynomial of degree deg in pieces pieces (constants where it is
** inlined; they must be c->poly_degree and c->poly_pieces), for every lane (the caller selects
** the region). */
CF_LANE double cf_lane_poly(const cf_law_lanes *c, double u, int deg, int pieces)
{
    const double a = fabs(u), sa = c->s - a;
    double w = sqrt((sa > 0.0 ? sa : 0.0) * c->inv_s);
    w = w < c->w_T ? w : c->w_T; /* region 1 maps to the fit's end; NaN to 0 */
    double P, K;
    cf_lane_poly_pk(c, w, deg, pieces, &P, &K);
    const double e = w * P;
    const double h = P * P * (6.0 + e * (-4.0 + e)) - c->r4 * (1.0 - e);
    const double y = 1.0 - w * (P - h * K);
    return cf_lane_regions(c, u, a, c->F_C * y * y * y);
}

/* The force of a spring with a tail from its fitted polynomial (law_poly.c), in one of three forms
** (form: a constant where it is inlined, c->tail_form), each followed by one division-free Newton
** step on the tailed relation Phi(e) = Delta (law.c) multiplied by 4 (1 - e) = 4 y,
**   N(e) - 4 (1 - e)(Delta - Phi*) = 0,
**   N(e) = e^2 (6 - 4e + e^2) + 4 beta e (1 - e)(3 - 3e + e^2) - 4 (1 - e) Phi*:
** - CF_TAIL_NEAR (beta < 1/4): Phi's minimum e* < 0 (struct cf_law_table, law_internal.h) is a double root
**   of N for Phi* = Phi(e*) = -r kappa^2, N = (e - e*)^2 Q(e) with Q quadratic; in
**   z = sqrt(v + kappa^2), v = (u_C - |u|)/s, Delta - Phi* = r z^2, so e = e* + z P with P regular
**   and h(P) = P^2 Q(e) - 4 r (1 - e) = 0: the plain law's relation (e* = 0, Q = 6 - 4e + e^2),
**   shifted. The polynomials are P0(z) ~ P and K(z) ~ 1/h'(P), as for the plain law. (A form in e
**   itself would need 1/h'(e), which has a pole at distance ~ beta from the cone's solid.)
** - CF_TAIL_W and CF_TAIL_V (Phi* = 0): E(z) ~ e and K(z) ~ 1/h'(e), z = sqrt(v) or v, with
**   h(e) = N(e) - 4 (1 - e) Delta, whose derivative at the root, 4 y Phi'(e), is at least about
**   12 beta there. e is analytic in Delta at the cone's solid once beta is not small; which
**   variable converges faster depends on rho and beta (law_poly.c tries both).
** Delta is formed as the scalar law forms it. Regions 1 and 3 and the two solids by selection, in
** the scalar law's order (law.c, law_eval): region 1 up to u_T, the tail's line
** F_C + k_t (|u| - u_C) from u_C, F_solid from s. */
enum { CF_TAIL_NEAR = 0, CF_TAIL_W = 1, CF_TAIL_V = 2 };
CF_LANE double cf_lane_poly_tail(const cf_law_lanes *c, double u, int deg, int pieces, int form)
{
    const double a = fabs(u), va = (c->u_C - a) * c->inv_s;
    const double v = va > 0.0 ? va : 0.0; /* region 3, the solid and NaN map to the cone's solid */
    double z = form == CF_TAIL_V ? v : sqrt(v + c->kappa2);
    z = z < c->w_T ? z : c->w_T; /* region 1 maps to the fit's end */
    double P, K;
    cf_lane_poly_pk(c, z, deg, pieces, &P, &K);
    double y;
    if (form == CF_TAIL_NEAR) {
        const double e = c->e_star + z * P;
        const double h = P * P * (c->q0 + e * (c->q1 + e * c->q2)) - c->r4 * (1.0 - e);
        y = (1.0 - c->e_star) - z * (P - h * K);
    } else {
        const double om = 1.0 - P;
        const double h = P * P * (6.0 + P * (-4.0 + P)) +
                         c->b4 * (P * om) * (3.0 + P * (-3.0 + P)) - 4.0 * om * (c->rim1 * v);
        y = om + h * K;
    }
    const double F2 = c->F_C * y * y * y;
    const double F3 = c->F_C + c->k_t * (a - c->u_C);
    double F = a < c->s ? F3 : c->F_sol;
    F = a < c->u_C ? F2 : F;
    F = a <= c->u_T ? c->k0 * a : F;
    F = copysign(F, u);
    return u != u ? 0.0 : F;
}

/* Forces F[k] of count displacements u[k] (F may be u), each form a few vectorised loops over
** chunks: the table's y of every lane first, stored, then the regions; a lookup inside the
** region selection would be a conditional load, which the compiler does not vectorise. */
#define CF_LANE_CHUNK 256

CF_LANE void cf_lanes_closed(const cf_law_lanes *c, size_t count, const double *u, double *F)
{
#pragma omp simd
    for (size_t k = 0; k < count; k++)
        F[k] = cf_lane_closed(c, u[k]);
}

#define CF_LANES_POLY_TAIL(form)                                                                   \
    do {                                                                                           \
        if (c->poly_pieces == 2) {                                                                 \
            _Pragma("omp simd") for (size_t k = 0; k < count; k++)                                 \
                F[k] = cf_lane_poly_tail(c, u[k], CF_POLY_DEGREE, 2, form);                        \
        } else if (c->poly_degree == CF_POLY_DEGREE_LOW) {                                         \
            _Pragma("omp simd") for (size_t k = 0; k < count; k++)                                 \
                F[k] = cf_lane_poly_tail(c, u[k], CF_POLY_DEGREE_LOW, 1, form);                    \
        } else {                                                                                   \
            _Pragma("omp simd") for (size_t k = 0; k < count; k++)                                 \
                F[k] = cf_lane_poly_tail(c, u[k], CF_POLY_DEGREE, 1, form);                        \
        }                                                                                          \
    } while (0)

CF_LANE void cf_lanes_poly_tail(const cf_law_lanes *c, size_t count, const double *u, double *F)
{
    if (c->tail_form == CF_TAIL_NEAR)
        CF_LANES_POLY_TAIL(CF_TAIL_NEAR);
    else if (c->tail_form == CF_TAIL_W)
        CF_LANES_POLY_TAIL(CF_TAIL_W);
    else
        CF_LANES_POLY_TAIL(CF_TAIL_V);
}

/* The spring's polynomial, with or without a tail. */
CF_LANE void cf_lanes_poly(const cf_law_lanes *c, size_t count, const double *u, double *F)
{
    if (c->tail) {
        cf_lanes_poly_tail(c, count, u, F);
        return;
    }
    if (c->poly_pieces == 2) {
#pragma omp simd
        for (size_t k = 0; k < count; k++)
            F[k] = cf_lane_poly(c, u[k], CF_POLY_DEGREE, 2);
    } else if (c->poly_degree == CF_POLY_DEGREE_LOW) {
#pragma omp simd
        for (size_t k = 0; k < count; k++)
            F[k] = cf_lane_poly(c, u[k], CF_POLY_DEGREE_LOW, 1);
    } else {
#pragma omp simd
        for (size_t k = 0; k < count; k++)
            F[k] = cf_lane_poly(c, u[k], CF_POLY_DEGREE, 1);
    }
}

CF_LANE void cf_lanes_table(const cf_law_lanes *c, size_t count, const double *u, double *F)
{
    double yv[CF_LANE_CHUNK];
    for (size_t b = 0; b < count; b += CF_LANE_CHUNK) {
        const size_t m = count - b < CF_LANE_CHUNK ? count - b : CF_LANE_CHUNK;
        const double *ub = u + b;
        double *Fb = F + b;
#pragma omp simd
        for (size_t k = 0; k < m; k++)
            yv[k] = cf_lane_table_y(c, ub[k]);
#pragma omp simd
        for (size_t k = 0; k < m; k++) {
            const double yk = yv[k];
            Fb[k] = cf_lane_regions(c, ub[k], fabs(ub[k]), c->F_C * yk * yk * yk);
        }
    }
}

/* Forces of count displacements with the closed form, the table (lanes->coef not NULL) or the
** polynomial (lanes->poly_fit): F[i] for u[i]. Vectorised, dispatched at run time. A form whose
** data lanes lacks runs the closed form; a spring with a tail has the polynomial only, and any
** other form (or no fitted polynomial) runs its scalar closed form. */
void cf_law_force_lanes(const cf_law_lanes *lanes, int form, size_t count, const double *u,
                        double *F);

#endif
