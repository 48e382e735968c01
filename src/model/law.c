/*
** The conical spring law (see law.h for the law, its units and its references).
**
** Region 2 is handled in two variables so that no evaluator loses digits:
**   delta = c - 1 = (1/rho - 1)(s - |u|)/s >= 0, zero at solid, formed from s - |u| directly;
**   e     = 1 - y, the near-solid variable, which obeys the explicit relation
**           delta(e) = e^2 (6 - 4e + e^2) / (4 (1 - e))      (increasing on [0, 1)),
**   y     itself for y < 1/2 (strongly conical springs far from solid), where 1 - y would lose
**           relative accuracy of y, through c(y) = (3 + y^4)/(4y).
** The stiffness is dF/du = k_scale y^4/(1 - y^4) with 1 - y^4 = e (4 - 6e + 4e^2 - e^3).
*/
#include "model/law_internal.h"
#include "base/gslguard.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

/* Switch from the e-form to the y-form at y = 1/2, i.e. at delta(1/2) = 0.53125. */
#define CF_DELTA_SWITCH 0.53125

void cf_law_free(cf_law *law)
{
    if (!law || !law->table)
        return;
    free(law->table->y);
    free(law->table->dy);
    free(law->table->coef);
    free(law->table);
    law->table = NULL;
}

/* ---- region-2 solvers: each returns y and 1 - y^4 ------------------------------------------- */

/* delta(e) - target, the e-form of the quartic. */
static double e_residual(double e, void *params)
{
    const double target = *(const double *)params;
    return e * e * (6.0 + e * (-4.0 + e)) / (4.0 * (1.0 - e)) - target;
}

/* c(y) - target, the y-form. */
static double y_residual(double y, void *params)
{
    const double target = *(const double *)params;
    return (3.0 + y * y * y * y) / (4.0 * y) - target;
}

/* 1 - y^4 from e, cancellation-free */
static inline double one_minus_y4_e(double e)
{
    return e * (4.0 + e * (-6.0 + e * (4.0 - e)));
}

/* Brent's method until the bracket stops shrinking; returns the midpoint of the last bracket. */
static double brent_solve(double (*f)(double, void *), void *params, double lo, double hi)
{
    CF_GSL_GUARD;
    gsl_function fn = {f, params};
    double flo = f(lo, params), fhi = f(hi, params);
    if (flo == 0)
        return lo;
    if (fhi == 0)
        return hi;
    if ((flo > 0) == (fhi > 0)) /* rounding at an end of the bracket: take the closer end */
        return fabs(flo) < fabs(fhi) ? lo : hi;
    gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!solver || gsl_root_fsolver_set(solver, &fn, lo, hi) != GSL_SUCCESS) {
        gsl_root_fsolver_free(solver);
        return 0.5 * (lo + hi); /* unreachable: the bracket was checked above */
    }
    double root = 0.5 * (lo + hi);
    for (int it = 0; it < 200; it++) {
        if (gsl_root_fsolver_iterate(solver) != GSL_SUCCESS)
            break;
        double a = gsl_root_fsolver_x_lower(solver), b = gsl_root_fsolver_x_upper(solver);
        root = gsl_root_fsolver_root(solver);
        if (b - a <= 2.0 * DBL_EPSILON * fmin(fabs(a), fabs(b)) || b - a <= DBL_MIN)
            break;
    }
    gsl_root_fsolver_free(solver);
    return root;
}

static void region2_exact(const cf_law *law, double delta, double *y, double *om, double *e_out)
{
    if (delta <= CF_DELTA_SWITCH) {
        const double e_max = fmin(0.5, law->p.D2_mm > law->p.D1_mm
                                           ? (law->p.D2_mm - law->p.D1_mm) / law->p.D2_mm
                                           : 0.0);
        double e = brent_solve(e_residual, &delta, 0.0, e_max);
        *y = 1.0 - e;
        *om = one_minus_y4_e(e);
        *e_out = e;
    } else {
        double target = 1.0 + delta;
        double yy = brent_solve(y_residual, &target, law->rho, 0.5);
        *y = yy;
        *om = 1.0 - yy * yy * yy * yy;
        *e_out = 1.0 - yy;
    }
}

static void region2_tail(const cf_law *law, int exact, double delta, double *y, double *om,
                         double *e_out);

double cf_law_region2_e(const cf_law *law, double delta)
{
    double y, om, e;
    if (law->tail)
        region2_tail(law, 1, delta, &y, &om, &e);
    else
        region2_exact(law, delta, &y, &om, &e);
    return e;
}

/* Cube root of x > 0 without libm's cbrt (which costs about twice as much here): an exponent-
** thirding bit trick good to a few percent, two Halley steps (cubic convergence) and a final
** Newton step; measured within 6e-16 relative of cbrt over [1, 1e7]. */
static inline double fast_cbrt(double x)
{
    uint64_t bits;
    double y;
    memcpy(&bits, &x, sizeof bits);
    bits = bits / 3 + UINT64_C(0x2A9F7893782DA1CE);
    memcpy(&y, &bits, sizeof y);
    for (int k = 0; k < 2; k++) {
        const double y3 = y * y * y;
        y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    }
    return y - (y * y * y - x) / (3.0 * y * y);
}

/* Ferrari's solution of y^4 - 4 c y + 3 = 0 with c = 1 + delta, written without cancellation:
**   resolvent m^3 - 3m - 2c^2 = 0 by Cardano as m = t + 1/t, t^3 = c^2 + sqrt(c^4 - 1),
**   c^4 - 1 = delta (2 + delta)(1 + c^2), mu = m - 2 = (t - 1)^2 / t,
**   t - 1 = (delta (2 + delta) + sqrt(c^4 - 1)) / (t^2 + t + 1);
**   b^2 = 4c sqrt(2/m) - 2m = 6 sqrt2 (2 delta + delta^2 - mu/2) / (sqrt m (2c + m sqrt(m/2)));
**   y = (sqrt(2m) - b)/2 = 6 / ((m + c sqrt(2/m)) (sqrt(2m) + b)),
**   e = 1 - y = b/2 - (mu/2) / (sqrt(1 + mu/2) + 1). */
static void region2_closed(double delta, double *y, double *om, double *e_out)
{
    const double c = 1.0 + delta;
    const double dd = delta * (2.0 + delta);
    const double sq = sqrt(dd * (1.0 + c * c));
    const double t = fast_cbrt(c * c + sq);
    const double tm1 = (dd + sq) / (t * t + t + 1.0);
    const double mu = tm1 * tm1 / t;
    const double m = 2.0 + mu;
    const double rm = sqrt(m);
    const double b2 = 6.0 * M_SQRT2 * (2.0 * delta + delta * delta - 0.5 * mu) /
                      (rm * (2.0 * c + m * rm * M_SQRT1_2));
    const double b = sqrt(fmax(b2, 0.0));
    if (delta <= CF_DELTA_SWITCH) {
        const double e = 0.5 * b - 0.5 * mu / (sqrt(1.0 + 0.5 * mu) + 1.0);
        *e_out = e;
        *y = 1.0 - e;
        *om = one_minus_y4_e(e);
    } else {
        const double yy = 6.0 / ((m + c * M_SQRT2 / rm) * (M_SQRT2 * rm + b));
        *e_out = 1.0 - yy;
        *y = yy;
        *om = 1.0 - yy * yy * yy * yy;
    }
}

/* One Newton step on the exact relation in the variable that carries the digits. */
static void region2_newton(double delta, double *y, double *om, double e)
{
    if (delta <= CF_DELTA_SWITCH) {
        /* f(e) = e^2 (6 - 4e + e^2) - 4 delta (1 - e) */
        const double f = e * e * (6.0 + e * (-4.0 + e)) - 4.0 * delta * (1.0 - e);
        const double fp = e * (12.0 + e * (-12.0 + 4.0 * e)) + 4.0 * delta;
        if (fp > 0) {
            const double en = e - f / fp;
            if (en >= 0 && en < 1)
                e = en;
        }
        *y = 1.0 - e;
        *om = one_minus_y4_e(e);
    } else {
        double yy = *y;
        const double c = 1.0 + delta;
        const double y3 = yy * yy * yy;
        const double f = y3 * yy - 4.0 * c * yy + 3.0;
        const double fp = 4.0 * (y3 - c);
        if (fp < 0) {
            const double yn = yy - f / fp;
            if (yn > 0 && yn < 1)
                yy = yn;
        }
        *y = yy;
        *om = 1.0 - yy * yy * yy * yy;
    }
}

/* ---- region 2 of a spring with a tail ------------------------------------------------------ */

/* With a tail the relation between Delta = (1/rho - 1)(u_C - |u|)/s and e = 1 - y gains the tail's
** deflection F/k_t = tau s y^3:
**   Phi(e) = delta(e) + beta psi(e) = Delta,  psi(e) = 1 - y^3 = e (3 - 3e + e^2),
** the sum of two increasing functions of e (the cone's delta(e), region2_closed's relation, and the
** tail's psi). Near the cone's solid Phi ~ 3 beta e, so e is regular in Delta there (no square
** root: region 3 continues linearly). For y < 1/2 the y-form c(y) - 1 + beta (1 - y^3) = Delta. */
typedef struct tail_target {
    double target, beta;
} tail_target;

/* Phi(e) - Delta and its derivative, e-form: delta'(e) = 3 (1 - y^4)/(4 y^2), psi'(e) = 3 y^2. */
static double tail_e_phi(double e, double beta, double *dphi)
{
    const double y = 1.0 - e;
    if (dphi)
        *dphi = 0.75 * one_minus_y4_e(e) / (y * y) + 3.0 * beta * y * y;
    return e * e * (6.0 + e * (-4.0 + e)) / (4.0 * (1.0 - e)) + beta * e * (3.0 + e * (-3.0 + e));
}

/* y-form: c(y) - 1 + beta (1 - y^3), decreasing in y; *dphi its derivative in y. */
static double tail_y_phi(double y, double beta, double *dphi)
{
    const double y2 = y * y;
    if (dphi)
        *dphi = 0.75 * (y2 * y2 - 1.0) / y2 - 3.0 * beta * y2;
    return (3.0 + y2 * y2) / (4.0 * y) - 1.0 + beta * (1.0 - y2 * y);
}

static double tail_e_residual(double e, void *params)
{
    const tail_target *t = params;
    return tail_e_phi(e, t->beta, NULL) - t->target;
}

static double tail_y_residual(double y, void *params)
{
    const tail_target *t = params;
    return tail_y_phi(y, t->beta, NULL) - t->target;
}

/* Phi at y = 1/2, where the e-form hands over to the y-form. */
static inline double tail_switch(double beta)
{
    return CF_DELTA_SWITCH + 0.875 * beta;
}

/* Newton's method on x in [lo, hi] for an increasing (sign = 1) or decreasing (sign = -1) residual
** phi(x) - target, started at x0, a bisection where a step leaves the bracket; stops when a step
** no longer changes x beyond rounding. */
static double tail_newton(int eform, double beta, double target, double x, double lo, double hi)
{
    const double sign = eform ? 1.0 : -1.0;
    for (int it = 0; it < 100; it++) {
        double dphi;
        const double f = (eform ? tail_e_phi(x, beta, &dphi) : tail_y_phi(x, beta, &dphi)) - target;
        if (f == 0)
            return x;
        if (sign * f > 0)
            hi = x;
        else
            lo = x;
        double xn = x - f / dphi;
        if (!(xn > lo && xn < hi))
            xn = 0.5 * (lo + hi);
        if (fabs(xn - x) <= 2.0 * DBL_EPSILON * fabs(x) || hi - lo <= 2.0 * DBL_EPSILON * hi)
            return xn;
        x = xn;
    }
    return x;
}

/* Region 2 with a tail at Delta >= 0: y, e = 1 - y, and 1 - y^4 + 4 beta y^4 (the stiffness's
** denominator). exact: Brent's method to the last bit (as region2_exact); otherwise Newton from a
** bound: e is at most the cone's alone, e_c(Delta), and at most the tail's alone,
** psi^-1(Delta/beta) = 1 - cbrt(1 - Delta/beta). */
static void region2_tail(const cf_law *law, int exact, double delta, double *y, double *om,
                         double *e_out)
{
    const double beta = law->beta;
    tail_target t = {delta, beta};
    double yy, e;
    if (delta <= tail_switch(beta)) {
        const double e_max = fmin(0.5, (law->p.D2_mm - law->p.D1_mm) / law->p.D2_mm);
        if (exact) {
            e = brent_solve(tail_e_residual, &t, 0.0, e_max);
        } else {
            double yc, omc, ec;
            region2_closed(delta, &yc, &omc, &ec);
            double e0 = fmin(e_max, ec);
            if (delta < beta)
                e0 = fmin(e0, -expm1(log1p(-delta / beta) / 3.0));
            e = tail_newton(1, beta, delta, fmax(e0, 0.0), 0.0, e_max);
        }
        yy = 1.0 - e;
        *om = one_minus_y4_e(e);
    } else {
        if (exact) {
            yy = brent_solve(tail_y_residual, &t, law->rho, 0.5);
        } else {
            double yc, omc, ec;
            region2_closed(delta, &yc, &omc, &ec); /* y >= the cone's alone */
            yy = tail_newton(0, beta, delta, fmin(fmax(yc, law->rho), 0.5), law->rho, 0.5);
        }
        e = 1.0 - yy;
        *om = 1.0 - yy * yy * yy * yy;
    }
    const double y2 = yy * yy;
    *om += 4.0 * beta * y2 * y2;
    *y = yy;
    *e_out = e;
}

/* ---- the table ------------------------------------------------------------------------------ */

cf_status cf_law_table_build(cf_law *law, size_t intervals, cf_error *err)
{
    if (intervals < 2 || intervals > ((size_t)1 << 26))
        return cf_error_set(err, CF_E_DATA, "table size %zu must be between 2 and %zu", intervals,
                            (size_t)1 << 26);
    if (law->mech) /* a law kind's row is evaluated as it is: no table */
        return CF_OK;
    struct cf_law_table *t = calloc(1, sizeof *t);
    if (t) {
        t->y = malloc((intervals + 1) * sizeof *t->y);
        t->dy = malloc((intervals + 1) * sizeof *t->dy);
        t->coef = malloc(4 * intervals * sizeof *t->coef);
    }
    if (!t || !t->y || !t->dy || !t->coef) {
        if (t) {
            free(t->y);
            free(t->dy);
            free(t->coef);
        }
        free(t);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a law table of %zu intervals",
                            intervals);
    }
    const double r = law->rho_inv_m1;
    t->intervals = intervals;
    const double beta = law->beta;
    t->kappa2 = 0.0;
    if (law->tail && r > 0) {
        if (beta < 0.2) { /* e* = 1 - y* = -expm1(-log1p(-4 beta)/4) ~ -beta */
            const double e_star = -expm1(-0.25 * log1p(-4.0 * beta));
            t->kappa2 = -tail_e_phi(e_star, beta, NULL) / r;
        } /* else Phi'(0) = 3 beta is large: e is analytic in w^2 and the grid stays in w */
    }
    t->z0 = sqrt(t->kappa2);
    t->w_max = law->tail ? sqrt(law->w_T * law->w_T + t->kappa2) : law->w_T;
    t->h = (t->w_max - t->z0) / (double)intervals;
    t->inv_h = t->h > 0 ? 1.0 / t->h : 0.0;
    for (size_t i = 0; i <= intervals; i++) {
        /* grid node w_i; delta = r w^2; dy/dw = dy/ddelta * 2 r w with
        ** dy/ddelta = -de/ddelta = -4 y^2 / (3 (1 - y^4)); with a tail the node is z_i, delta =
        ** r (z^2 - kappa^2), om = 1 - y^4 + 4 beta y^4 (dPhi/de = 3 om/(4 y^2)) and the same
        ** expression gives dy/dz */
        const double w = (i == intervals) ? t->w_max : t->z0 + t->h * (double)i;
        double y = 1, om = 0, e, dydw;
        if (r == 0 || (i == 0 && !law->tail)) {
            /* limit at solid: e ~ sqrt(2 delta / 3) = sqrt(2 r / 3) w */
            dydw = -sqrt(2.0 * r / 3.0);
        } else if (i == 0) { /* at the cone's solid with a tail: y = 1, om = 4 beta */
            om = 4.0 * beta;
            dydw = -8.0 * r * t->z0 / (3.0 * om);
        } else {
            if (law->tail)
                region2_tail(law, 1, r * ((w - t->z0) * (w + t->z0)), &y, &om, &e);
            else
                region2_exact(law, r * w * w, &y, &om, &e);
            dydw = -8.0 * r * w * y * y / (3.0 * om);
        }
        if (law->tail) { /* a tailed table holds f = y^3 = F/F_C: where the tail dominates,
                         ** y^3 ~ 1 - r w^2/beta is smooth and y, its cube root, is not */
            t->y[i] = y * y * y;
            t->dy[i] = 3.0 * y * y * dydw * t->h;
        } else {
            t->y[i] = y;
            t->dy[i] = dydw * t->h;
        }
    }
    t->y[intervals] = law->tail ? law->rho * law->rho * law->rho : law->rho; /* the transition */
    for (size_t i = 0; i < intervals; i++) {
        const double y0 = t->y[i], y1 = t->y[i + 1], m0 = t->dy[i], m1 = t->dy[i + 1];
        double *k = t->coef + 4 * i;
        k[0] = y0;
        k[1] = m0;
        k[2] = 3.0 * (y1 - y0) - 2.0 * m0 - m1;
        k[3] = 2.0 * (y0 - y1) + m0 + m1;
    }
    cf_law_free(law);
    law->table = t;
    return CF_OK;
}

/* Hermite interpolation of y(w) and dy/dw on the uniform grid. */
static inline double table_y(const struct cf_law_table *t, double w, double *dydw)
{
    double x = (w - t->z0) * t->inv_h;
    size_t i = (size_t)x;
    if (i >= t->intervals)
        i = t->intervals - 1;
    const double q = x - (double)i;
    /* cubic Hermite in q: p(q) = y0 + q (m0 + q (a + q b)) */
    const double *k = t->coef + 4 * i;
    const double y0 = k[0], m0 = k[1], a = k[2], b = k[3];
    *dydw = (m0 + q * (2.0 * a + 3.0 * q * b)) * t->inv_h;
    return y0 + q * (m0 + q * (a + q * b));
}

/* ---- evaluation ------------------------------------------------------------------------------ */

/* Region 2 from the table, for |u| = a in (u_T, u_C): F, and dF/du when k is not NULL
** (dF/du = 3 F_C y^2 dy/dw dw/du with dw/du = -1/(2 s w)). */
static inline double table_region2(const cf_law *law, double u, double a, double *k)
{
    const double v = (law->u_C_mm - a) * law->inv_travel;
    const double w = law->tail ? sqrt(v + law->table->kappa2) : sqrt(v);
    double dydw;
    const double y = table_y(law->table, w, &dydw);
    if (law->tail) { /* the table holds f = F/F_C and df/dz */
        if (k) {
            const double kk = -0.5 * law->F_C_N * law->inv_travel * dydw / w;
            *k = (kk >= 0 && kk <= DBL_MAX) ? kk : 0.0;
        }
        return copysign(law->F_C_N * y, u);
    }
    if (k) {
        const double kk = -1.5 * law->F_C_N * law->inv_travel * y * y * dydw / w;
        *k = (kk >= 0 && kk <= DBL_MAX) ? kk : 0.0;
    }
    return copysign(law->F_C_N * y * y * y, u);
}

/* The law at one displacement. k may be NULL (no stiffness work: inlined, always, with a constant
** method and a constant NULL, the unused paths disappear); flags is always written. */
#if defined(__GNUC__)
#define CF_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define CF_ALWAYS_INLINE inline
#endif

static CF_ALWAYS_INLINE double law_side(const cf_law *law, cf_law_method method, double u,
                                        double *k, int *flags)
{
    const double a = fabs(u);
    const double sign = (u < 0) ? -1.0 : 1.0;
    if (a <= law->u_T_mm) {
        if (k)
            *k = law->k0_N_per_mm;
        *flags = CF_LAW_LINEAR;
        return law->k0_N_per_mm * u;
    }
    if (!(a < law->travel_mm)) { /* at or past solid, or NaN */
        if (k)
            *k = 0.0;
        *flags = CF_LAW_SOLID;
        return isnan(u) ? 0.0 : sign * law->F_solid_N;
    }
    if (law->tail && a >= law->u_C_mm) { /* the cone is solid, the tail deflects */
        if (k)
            *k = law->k_tail_N_per_mm;
        *flags = CF_LAW_TAIL;
        return sign * (law->F_C_N + law->k_tail_N_per_mm * (a - law->u_C_mm));
    }
    *flags = 0;
    if (method == CF_LAW_TABLE && law->table)
        return table_region2(law, u, a, k);
    const double v = (law->u_C_mm - a) * law->inv_travel; /* (u_C - |u|)/s, in (0, 1) untailed */
    const double delta = law->rho_inv_m1 * v;
    double y, om, e;
    if (law->tail) {
        region2_tail(law, method == CF_LAW_EXACT, delta, &y, &om, &e);
    } else {
        switch (method) {
        case CF_LAW_EXACT:
            region2_exact(law, delta, &y, &om, &e);
            break;
        case CF_LAW_TABLE: /* no table built: closed form with Newton */
        case CF_LAW_CLOSED_NEWTON:
            region2_closed(delta, &y, &om, &e);
            region2_newton(delta, &y, &om, e);
            break;
        case CF_LAW_CLOSED:
        default:
            region2_closed(delta, &y, &om, &e);
            break;
        }
    }
    const double y2 = y * y;
    if (k) {
        const double kk = law->k_scale * y2 * y2 / om;
        *k = (kk >= 0 && isfinite(kk)) ? kk : 0.0;
    }
    return sign * law->F_C_N * y2 * y;
}

/* The extension side of a pair: -F_e(-u), its stiffness k_e(-u). */
static double law_extension(const cf_law *law, cf_law_method method, double u, double *k,
                            int *flags)
{
    return -law_side(law->extension, method, -u, k, flags);
}

/* The law at one displacement: the odd law, or a pair's side. */
static CF_ALWAYS_INLINE double law_eval(const cf_law *law, cf_law_method method, double u,
                                        double *k, int *flags)
{
    if (u < 0 && law->extension)
        return law_extension(law, method, u, k, flags);
    return law_side(law, method, u, k, flags);
}

cf_status cf_law_pair(cf_law *law, const cf_law *ext, cf_error *err)
{
    if (ext && ext->extension)
        return cf_error_set(err, CF_E_DATA, "an extension spring cannot have its own extension "
                                            "spring");
    if (ext && ext->p.H_mm != law->p.H_mm)
        return cf_error_set(err, CF_E_DATA,
                            "the extension spring's free length H = %.17g mm differs from the "
                            "compression spring's %.17g mm (a double-acting element shares it)",
                            ext->p.H_mm, law->p.H_mm);
    law->extension = ext;
    return CF_OK;
}

double cf_law_force(const cf_law *law, cf_law_method method, double u_mm, double *k_N_per_mm,
                    int *flags)
{
    if (law->mech)
        return cf_law_kind_force(law, u_mm, k_N_per_mm, flags);
    int fl;
    const double F = law_eval(law, method, u_mm, k_N_per_mm, &fl);
    if (flags)
        *flags = fl;
    return F;
}

/* One loop of the batch evaluation; called with a constant method so that each copy is
** specialised, and with the stiffness loop apart so that forces alone cost no stiffness work
** (the table's batch of forces, measured: 8-12 ns per spring, about 20 ns when every call
** also computed the stiffness). */
static inline void law_many(const cf_law *law, cf_law_method method, size_t count,
                            const double *u, double *F, double *k)
{
    int fl;
    if (k)
        for (size_t i = 0; i < count; i++)
            F[i] = law_eval(law, method, u[i], &k[i], &fl);
    else
        for (size_t i = 0; i < count; i++)
            F[i] = law_eval(law, method, u[i], NULL, &fl);
}

/* The scalar law over many points (law_simd.h): the batch's path for the exact method, the
** stiffness, and the laws the lanes do not carry. */
void cf_law_force_scalar_many(const cf_law *law, cf_law_method method, size_t count,
                              const double *u_mm, double *F_N, double *k_N_per_mm)
{
    if (law->mech) {
        cf_law_kind_force_many(law, count, u_mm, F_N, k_N_per_mm);
        return;
    }
    switch (method) { /* one branch per method so each loop body is specialised */
    case CF_LAW_EXACT:
        law_many(law, CF_LAW_EXACT, count, u_mm, F_N, k_N_per_mm);
        break;
    case CF_LAW_TABLE:
        law_many(law, CF_LAW_TABLE, count, u_mm, F_N, k_N_per_mm);
        break;
    case CF_LAW_CLOSED_NEWTON:
        law_many(law, CF_LAW_CLOSED_NEWTON, count, u_mm, F_N, k_N_per_mm);
        break;
    case CF_LAW_CLOSED:
    default:
        law_many(law, CF_LAW_CLOSED, count, u_mm, F_N, k_N_per_mm);
        break;
    }
}

double cf_law_deflection(const cf_law *law, double F_N)
{
    if (law->mech)
        return cf_law_kind_deflection(law, F_N);
    if (F_N < 0 && law->extension)
        return -cf_law_deflection(law->extension, -F_N);
    const double a = fabs(F_N);
    const double sign = (F_N < 0) ? -1.0 : 1.0;
    if (isnan(F_N))
        return 0.0;
    if (a >= law->F_solid_N)
        return sign * law->travel_mm;
    if (law->tail && a >= law->F_C_N)
        return sign * (law->u_C_mm + (a - law->F_C_N) / law->k_tail_N_per_mm);
    if (a <= law->F_T_N || law->rho_inv_m1 == 0)
        return fmin(a / law->k0_N_per_mm, law->u_T_mm) * sign;
    /* u = s (1/rho - 3/4 r - 1/4 r^-3)/(1/rho - 1), r = 1/y; as s - u = s delta/(1/rho - 1) with
    ** delta = c(y) - 1 = (3 + y^4)/(4y) - 1 = (1 - y)^2 (3 + 2y + y^2)/(4y) (no cancellation) */
    const double y = cbrt(a / law->F_C_N);
    const double e = 1.0 - y;
    const double delta = e * e * (3.0 + 2.0 * y + y * y) / (4.0 * y);
    const double s = law->cone_travel_mm;
    if (law->tail) /* the cone's deflection and the tail's F/k_t */
        return sign * (s - s * delta / law->rho_inv_m1 + a / law->k_tail_N_per_mm);
    return sign * (law->travel_mm - law->travel_mm * delta / law->rho_inv_m1);
}
