/*
** The family's canonical law over many points at once (see family.h, cf_ident_canon_many): the
** closed form of law_simd.h in vector lanes, with the derivatives the fits' Jacobians need.
*/
#include "model/family.h"

#include <float.h>
#include <string.h>

#include "model/law_simd.h"

/* What every lane of one call shares: the canonical law's lanes and its constants. */
typedef struct canon_consts {
    cf_law_lanes l;
    double inv_B;  /* 1/B: t = x/B */
    double h;      /* region 1's slope g = h t */
    double h_rho;  /* its derivative in rho over h */
    double inv_r2; /* 1/rho^2 */
} canon_consts;

/* g(t) and, in region 2, dg/dt and dg/drho from the root y = 1 - e of y^4 - 4 c y + 3 = 0,
** c = 1 + delta, delta = (1/rho - 1)(1 - |t|): dg/dc = -4 y^4/(e (1 + y)(1 + y^2)), the
** denominator being 4 y (c - y^3)/3 without cancellation once e is polished by one Newton step
** on e^2 (6 - 4e + e^2) = 4 delta (1 - e) (the relative digits of e, which 1 - y loses near
** solid). Region 1 is linear, region 3 (|t| >= 1) constant; NaN gives 0. */
CF_LANE void canon_lane(const canon_consts *k, double x, double *g, double *gt, double *gr)
{
    const double t = x * k->inv_B, a = fabs(t);
    const double y = cf_lane_closed_y(&k->l, a);
    const double one_a = 1.0 - a;
    const double delta = k->l.rim1 * (one_a > 0.0 ? one_a : 0.0);
    double e = 1.0 - y;
    const double f = e * e * (6.0 + e * (-4.0 + e)) - 4.0 * delta * (1.0 - e);
    const double fp = e * (12.0 + e * (-12.0 + 4.0 * e)) + 4.0 * delta;
    const double en = e - f / (fp > 0.0 ? fp : 1.0);
    e = fp > 0.0 && en > 0.0 && en < 1.0 ? en : e;
    const double yy = 1.0 - e;
    const double den = e * (1.0 + yy) * (1.0 + yy * yy);
    const double y2 = y * y;
    const double q = den > 0.0 ? 4.0 * y2 * y2 / den : 0.0; /* -dg/dc */
    const double sg = t < 0.0 ? -1.0 : 1.0;
    const int lin = a <= k->l.u_T, solid = !(a < 1.0);
    double G = sg * y2 * y, Gt = q * k->l.rim1, Gr = sg * q * one_a * k->inv_r2;
    G = solid ? sg : G;
    Gt = solid ? 0.0 : Gt;
    Gr = solid ? 0.0 : Gr;
    G = lin ? k->h * t : G;
    Gt = lin ? k->h : Gt;
    Gr = lin ? t * k->h * k->h_rho : Gr;
    const int bad = t != t;
    *g = bad ? 0.0 : G;
    *gt = bad ? 0.0 : Gt;
    *gr = bad ? 0.0 : Gr;
}

/* The points in whole blocks of the copy's width (CANON_BLOCK_v1, _v3, _v4), then the last few
** copied into one padded block (padded with the last point) and run through the same loop: no
** scalar remainder, whose four points cost a fifth of a 100-point call at eight lanes. */
#define CANON_BLOCK_v1 2
#define CANON_BLOCK_v3 4
#define CANON_BLOCK_v4 8
#define CANON_MANY(attr, sfx, unused)                                                              \
    attr static void canon_run##sfx(const canon_consts *kp, size_t count, const double *x,         \
                                    double *g, double *gt, double *gr)                             \
    {                                                                                              \
        const canon_consts k = *kp; /* by value: its loads leave the loop */                       \
        if (!gt || !gr) {                                                                          \
            _Pragma("omp simd") for (size_t i = 0; i < count; i++)                                 \
                g[i] = cf_lane_closed(&k.l, x[i] * k.inv_B);                                       \
            return;                                                                                \
        }                                                                                          \
        _Pragma("omp simd") for (size_t i = 0; i < count; i++)                                     \
            canon_lane(&k, x[i], &g[i], &gt[i], &gr[i]);                                           \
    }                                                                                              \
    attr static void canon_many##sfx(const canon_consts *kp, size_t count, const double *x,        \
                                     double *g, double *gt, double *gr)                            \
    {                                                                                              \
        const size_t whole = count - count % CANON_BLOCK##sfx, rest = count - whole;               \
        canon_run##sfx(kp, whole, x, g, gt, gr);                                                   \
        if (rest == 0)                                                                             \
            return;                                                                                \
        enum { W = CANON_BLOCK##sfx };                                                             \
        double px[W], pg[W], pt[W], pr[W];                                                         \
        for (size_t i = 0; i < W; i++)                                                             \
            px[i] = x[whole + (i < rest ? i : rest - 1)];                                          \
        const int d = gt && gr;                                                                    \
        canon_run##sfx(kp, W, px, pg, d ? pt : NULL, d ? pr : NULL);                               \
        for (size_t i = 0; i < rest; i++) {                                                        \
            g[whole + i] = pg[i];                                                                  \
            if (d) {                                                                               \
                gt[whole + i] = pt[i];                                                             \
                gr[whole + i] = pr[i];                                                             \
            }                                                                                      \
        }                                                                                          \
    }
CF_SIMD_COPIES(CANON_MANY, 0)

/* The constants every call shares, from the lanes of the canonical law and its rho and k0. */
static void canon_consts_of(canon_consts *k, double rho, double k0, double B)
{
    k->inv_B = 1.0 / B;
    k->h = k0;
    k->h_rho = 3 / rho - 1 / (1 + rho) - 2 * rho / (1 + rho * rho);
    k->inv_r2 = 1.0 / (rho * rho);
}

void cf_ident_canon_many(const cf_law *canon, double B, size_t count, const double *x, double *g,
                         double *dg_dt, double *dg_drho)
{
    canon_consts k;
    cf_law_lanes_init(canon, &k.l);
    canon_consts_of(&k, canon->rho, canon->k0_N_per_mm, B);
    CF_SIMD_CALL(canon_many, (&k, count, x, g, dg_dt, dg_drho));
}

/* The canonical spring (family.c: D1 = rho, D2 = 1, n = 2, d = 0.5, G = 256 rho^3, H = 2 mm) as
** cf_law_init derives it: travel 2 - 1 = 1 mm; F_C = G s d/(8 n c^3) with c = 2 rho, where
** G = 256 fl(fl(rho^2) rho) and c^3 = 8 fl(fl(rho^2) rho) (powers of two scale exactly), so
** F_C = 1 exactly; k0 = G d/(2 n c2^3 shape) = 4 fl(fl(rho^2) rho)/shape with c2 = 2, shape =
** (1 + rho)(1 + rho^2); u_T = min(shape/4, 1); 1/rho - 1 = (1 - rho)/rho. The law's other checks
** hold for every rho in (0, 1] whose cube is a normal number. */
cf_status cf_ident_canon_many_rho(double rho, double B, size_t count, const double *x, double *g,
                                  double *dg_dt, double *dg_drho)
{
    const double r3 = rho * rho * rho;
    if (!(rho > 0 && rho <= 1) || !(256.0 * r3 >= DBL_MIN))
        return CF_E_DATA;
    const double shape = (1.0 + rho) * (1.0 + rho * rho);
    canon_consts k;
    memset(&k.l, 0, sizeof k.l);
    k.l.u_T = cf_ident_canon_transition(rho);
    k.l.s = 1.0;
    k.l.inv_s = 1.0;
    k.l.k0 = 128.0 * r3 / (32.0 * shape);
    k.l.F_C = 1.0;
    k.l.rim1 = (1.0 - rho) / rho;
    canon_consts_of(&k, rho, k.l.k0, B);
    CF_SIMD_CALL(canon_many, (&k, count, x, g, dg_dt, dg_drho));
    return CF_OK;
}
