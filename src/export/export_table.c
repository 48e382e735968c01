/*
** The export table (see export_table.h): the law as a piecewise-linear force-displacement table whose
** nodes are placed where the interpolation error is, checked afterwards on a grid that knows
** nothing of the nodes.
**
** Placement. Linear interpolation over an interval of width h errs by about h^2 |F''| / 8, so the
** nodes that make that error equal on every interval have a density proportional to |F''|^(1/2)
** (de Boor, A Practical Guide to Splines, ch. III, on equidistributing the interpolation error).
** Region 1 is linear (one interval, exact). In region 2 the law is written through
** r = (F_C/F)^(1/3) in [1, 1/rho] (MODEL.md):
**     u = s - A (r - 1)^2 (6 + 8q + 3q^2) / (4 (1 + q)^3),  q = r - 1,  A = s / (1/rho - 1)
**     F'' = 64 F r^10 / (3 A^2 (r^4 - 1)^3)
** and with r = 1 + t^2 the density sqrt(F''/F_C) |du/dt| becomes the smooth, bounded
**     g(t) = 4 sqrt(3) r^(-1/2) / sqrt(4 + 6q + 4q^2 + q^3)
** (A cancels: the row count depends on rho and the tolerance only). Nodes are equally spaced in
** the running integral of g.
**
** Values. A table's values need not be samples of the law: moving each interior node towards the
** concave side by half the interpolation error of its two intervals makes the error swing between
** -e/2 and +e/2 instead of 0 and e, so the same tolerance needs about 1/sqrt(2) of the rows. The
** rows at 0, +-u_T and the table's two ends stay on the law (region 1 stays exact, and a simulator
** that holds the last force beyond the table starts from the law's value), and the intervals next
** to the ends are halved so that they meet the same bound without the shift.
**
** The count is then settled by measurement: the maximum error on the check grid sets the next
** count (error ~ count^-2) until it is within the tolerance.
**
** A spring with a cylindrical tail (law.h): region 2 is placed the same way in r (the tail's F/k_t
** added to the cone's deflection), ends at u_C where the cone closes (a row on the law), and the
** tail's region 3 beyond it is straight, one exact interval to the table's end.
*/
#include "export/export_table.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The placement aims at this fraction of the tolerance; the measured error decides. */
#define TABLE_AIM 0.9
/* Points of the running integral of g over region 2. */
#define TABLE_QUAD 4096
/* Points of each half of the check grid: uniform in u, and uniform in w = sqrt(1 - |u|/s), which
** crowds towards solid where the intervals are short. */
#define TABLE_CHECK 20000
/* Placement rounds before giving up (each one corrects the count from the measured error). */
#define TABLE_ROUNDS 12
/* Probes per interval when measuring its interpolation error for the shift. */
#define TABLE_PROBES 15
/* Most region-2 intervals of one half. The tightest tolerance (1e-9) needs about 30000 on the
** springs tried (rho 0.003 to 0.997, tails of 1e-6 to 1 coils); a law whose error does not fall as the rows grow (a tail so stiff that its
** deflection is below rounding of the cone's travel) would otherwise grow the table without
** bound: the placement stops there and the table is refused. */
#define TABLE_MAX_INTERVALS 200000
/* settle_half's answer when the next round would pass TABLE_MAX_INTERVALS. */
#define TABLE_TOO_MANY ((size_t)-1)
/* A law kind's rows on a side when its row gives no samples (and the first try's), evenly spaced;
** doubled until the tolerance is met. */
#define TABLE_KIND_SAMPLES 16

/* ---- one half of the table (compression side, 0 <= u <= U) ----------------------------------- */

typedef struct half {
    size_t n;
    double *u, *F;
} half;

/* The density g(t) of the top of this file. */
static double density(double t)
{
    const double q = t * t, r = 1.0 + q;
    return 4.0 * sqrt(3.0) / (sqrt(r) * sqrt(4.0 + q * (6.0 + q * (4.0 + q))));
}

/* A law kind's half (lawmech.h): its row's samples over (0, U] on the side of sign when it gives
** them and intervals is 0, else intervals + 1 rows evenly spaced over [0, U]; the values on the law
** (h->F = sign F(sign u), which join mirrors back for the stretch side). 0, or -1 out of memory. */
static int kind_place(const cf_law *law, double U, size_t intervals, double sign, half *h)
{
    free(h->u), free(h->F);
    memset(h, 0, sizeof *h);
    const size_t cap = (intervals ? intervals : TABLE_KIND_SAMPLES) + 1;
    h->u = malloc(cap * sizeof *h->u);
    h->F = malloc(cap * sizeof *h->F);
    if (!h->u || !h->F)
        return -1;
    h->u[h->n++] = 0.0;
    size_t m = 0;
    if (!intervals && law->mech->samples)
        m = law->mech->samples(law->q, law->p.H_mm, sign < 0 ? -1 : 1, U, cap - 1, h->u + 1);
    for (size_t i = 0; i < m && i < cap - 1; i++)
        if (h->u[i + 1] > h->u[h->n - 1] && h->u[i + 1] <= U)
            h->u[h->n++] = h->u[i + 1];
    if (h->n == 1 || h->u[h->n - 1] < U) { /* no samples, or not to U: evenly spaced */
        const size_t N = intervals ? intervals : TABLE_KIND_SAMPLES;
        h->n = 1;
        for (size_t i = 1; i <= N; i++)
            h->u[h->n++] = U * (double)i / (double)N;
    }
    for (size_t i = 0; i < h->n; i++)
        h->F[i] = sign * cf_law_force(law, CF_LAW_EXACT, sign * h->u[i], NULL, NULL);
    return 0;
}

/* Compression (mm) of the point of region 2 at r = 1 + t^2, written without cancellation near
** solid. With a tail the cone's gap is measured from its own travel s and the tail adds F/k_t. */
static double u_of_t(const cf_law *law, double t)
{
    const double q = t * t, A = law->cone_travel_mm / law->rho_inv_m1;
    const double gap = A * q * q * (6.0 + q * (8.0 + 3.0 * q)) / (4.0 * (1.0 + q) * (1.0 + q) * (1.0 + q));
    if (law->tail) {
        const double r = 1.0 + q, F = law->F_C_N / (r * r * r);
        return law->cone_travel_mm - gap + F / law->k_tail_N_per_mm;
    }
    return law->travel_mm - gap;
}

/* t of the region-2 point at compression u (u_T < u < s). */
static double t_of_u(const cf_law *law, double u)
{
    const double F = cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL);
    /* r - 1 = (F_C/F)^(1/3) - 1 from the force deficit, without cancellation near solid */
    const double q = expm1(log1p((law->F_C_N - F) / F) / 3.0);
    return sqrt(fmax(q, 0.0));
}

/* Fills h with the nodes of [0, U] for `intervals` region-2 intervals (before the halving of the
** end intervals) and the law's values at them, shifted as described at the top. A tail's region 3
** (from u_C, where the cone closes, to solid) is linear: region 2 ends at min(U, u_C), a node on
** the law, and one interval reaches U; a cylindrical cone with a tail has no region 2, a node at
** u_T and one interval beyond it. */
static int half_place(const cf_law *law, double U, size_t intervals, half *h)
{
    free(h->u), free(h->F);
    memset(h, 0, sizeof *h);
    const int linear_only = !(U > law->u_T_mm) || !(law->rho_inv_m1 > 0.0);
    const size_t cap = linear_only ? 3 : intervals + 6;
    h->u = malloc(cap * sizeof *h->u);
    h->F = malloc(cap * sizeof *h->F);
    if (!h->u || !h->F)
        return -1;
    h->u[h->n++] = 0.0;
    size_t end2 = 0; /* the node where a tail's region 2 ends (0: none) */
    const double U2 = law->tail ? fmin(U, law->u_C_mm) : U;
    if (linear_only) {
        if (law->tail && U > law->u_T_mm)
            h->u[h->n++] = law->u_T_mm;
        h->u[h->n++] = U;
    } else {
        h->u[h->n++] = law->u_T_mm;
        /* running integral of g from t_T (at u_T) down to t_U (at U2) */
        const double tT = sqrt(law->rho_inv_m1), tU = U2 < U ? 0.0 : t_of_u(law, U);
        double G[TABLE_QUAD + 1];
        G[0] = 0.0;
        const double dt = (tT - tU) / TABLE_QUAD;
        for (int i = 1; i <= TABLE_QUAD; i++) { /* Simpson on each cell */
            const double a = tT - (i - 1) * dt, b = tT - i * dt;
            G[i] = G[i - 1] + dt / 6.0 * (density(a) + 4.0 * density(0.5 * (a + b)) + density(b));
        }
        /* nodes at equal steps of G; the first and last intervals halved */
        const size_t N = intervals < 2 ? 2 : intervals;
        size_t j = 0;
        for (size_t k = 0; k <= 2 * N; k++) {
            /* positions (in units of one interval): 0.5, 1, 2, ..., N-1, N-0.5, N */
            double pos;
            if (k == 0)
                pos = 0.5;
            else if (k <= N - 1)
                pos = (double)k;
            else if (k == N)
                pos = (double)N - 0.5;
            else
                break;
            const double target = pos / (double)N * G[TABLE_QUAD];
            while (j < TABLE_QUAD - 1 && G[j + 1] < target)
                j++;
            const double f = (target - G[j]) / (G[j + 1] - G[j]);
            const double t = tT - (j + f) * dt;
            const double u = u_of_t(law, t);
            if (u > h->u[h->n - 1] && u < U2)
                h->u[h->n++] = u;
        }
        h->u[h->n++] = U2;
        if (U2 < U) {
            end2 = h->n - 1;
            h->u[h->n++] = U;
        }
    }
    for (size_t i = 0; i < h->n; i++)
        h->F[i] = cf_law_force(law, CF_LAW_EXACT, h->u[i], NULL, NULL);
    /* shift the interior region-2 nodes by half the interpolation error of their intervals (a
    ** tail's u_C stays on the law: the straight region 3 beyond it is exact) */
    if (h->n > 4) {
        double *e = malloc(h->n * sizeof *e);
        if (!e)
            return -1;
        for (size_t i = 1; i + 1 < h->n; i++) { /* interval [u_i, u_i+1] */
            double worst = 0.0;
            for (int p = 1; p <= TABLE_PROBES; p++) {
                const double f = p / (TABLE_PROBES + 1.0);
                const double u = h->u[i] + f * (h->u[i + 1] - h->u[i]);
                const double chord = h->F[i] + f * (h->F[i + 1] - h->F[i]);
                worst = fmax(worst, chord - cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL));
            }
            e[i] = worst;
        }
        for (size_t i = 2; i + 1 < (end2 ? end2 + 1 : h->n); i++) /* strictly between u_T and U2 */
            h->F[i] -= 0.25 * (e[i - 1] + e[i]);
        free(e);
    }
    return 0;
}

/* ---- the whole table -------------------------------------------------------------------------- */

double cf_export_table_eval(const cf_export_table *t, double u_mm)
{
    if (t->rows == 0)
        return 0.0;
    if (!(u_mm > t->u_mm[0]))
        return t->F_N[0];
    if (u_mm >= t->u_mm[t->rows - 1])
        return t->F_N[t->rows - 1];
    size_t lo = 0, hi = t->rows - 1; /* u[lo] < u <= u[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->u_mm[mid] < u_mm)
            lo = mid;
        else
            hi = mid;
    }
    const double f = (u_mm - t->u_mm[lo]) / (t->u_mm[hi] - t->u_mm[lo]);
    return t->F_N[lo] + f * (t->F_N[hi] - t->F_N[lo]);
}

void cf_export_table_free(cf_export_table *t)
{
    if (!t)
        return;
    free(t->u_mm);
    free(t->F_N);
    free(t->k_N_per_mm);
    memset(t, 0, sizeof *t);
}

double cf_export_table_end(const cf_law *law, double tol)
{
    /* where the law is within tol F_C of its solid force: holding the last row's force beyond
    ** the table stays within tol F_C of the law up to solid (a tail's region 3 is linear) */
    if (law->tail)
        return cf_law_deflection(law, law->F_solid_N - tol * law->F_C_N);
    return cf_law_deflection(law, law->F_C_N * (1.0 - tol));
}

/* The spring that carries the side of sign (the extension spring of a double-acting element on
** the stretch side, law.h; the law itself otherwise). */
static const cf_law *side_law(const cf_law *law, double sign)
{
    return sign < 0 && law->extension ? law->extension : law;
}

/* The stretch end of a table of law (the extension spring's end for a pair), mm, positive. */
static double stretch_end(const cf_law *law, double tol)
{
    if (law->mech) /* a law kind's own stretch side */
        return -cf_law_deflection(law, cf_law_solid_force(law, -1.0) * (1.0 - tol));
    return cf_export_table_end(side_law(law, -1.0), tol);
}

/* The i-th point (0 <= i < 2 TABLE_CHECK) of the check grid over the half [0, U]. */
static double check_point(const cf_law *law, double U, size_t i)
{
    const size_t N = TABLE_CHECK;
    if (i < N)
        return U * ((double)i + 0.5) / (double)N;
    i -= N;
    const double s = law->u_C_mm; /* the travel without a tail */
    const double w_end = sqrt(fmax(0.0, 1.0 - U / s));
    const double w = w_end + (1.0 - w_end) * ((double)i + 0.5) / (double)N;
    return fmin(s * (1.0 - w * w), U);
}

/* Largest |table - law| over the half [0, U] (sign = +1) or [-U, 0] (sign = -1), N. */
static double half_error(const cf_law *law, const cf_export_table *t, double U, double sign,
                         double *where)
{
    double worst = 0.0;
    for (size_t i = 0; i < 2 * (size_t)TABLE_CHECK; i++) {
        const double u = sign * check_point(side_law(law, sign), U, i);
        const double e = fabs(cf_export_table_eval(t, u) - cf_law_force(law, CF_LAW_EXACT, u, NULL,
                                                                        NULL));
        if (e > worst) {
            worst = e;
            *where = u;
        }
    }
    return worst;
}

/* Joins the stretch half (mirrored) and the compression half into t. */
static int join(const cf_law *law, const half *st, const half *co, cf_export_table *t)
{
    const size_t n = st->n + co->n - 1;
    double *u = malloc(n * sizeof *u), *F = malloc(n * sizeof *F), *k = malloc(n * sizeof *k);
    if (!u || !F || !k) {
        free(u), free(F), free(k);
        return -1;
    }
    size_t r = 0;
    for (size_t i = st->n; i-- > 1;) {
        u[r] = -st->u[i];
        F[r++] = -st->F[i];
    }
    for (size_t i = 0; i < co->n; i++) {
        u[r] = co->u[i];
        F[r++] = co->F[i];
    }
    for (size_t i = 0; i < n; i++)
        cf_law_force(law, CF_LAW_EXACT, u[i], &k[i], NULL);
    free(t->u_mm), free(t->F_N), free(t->k_N_per_mm);
    t->u_mm = u;
    t->F_N = F;
    t->k_N_per_mm = k;
    t->rows = n;
    return 0;
}

/* settle_half for a law kind: its samples first, then evenly spaced rows doubled until the
** half meets tol F_C (its solid force on the side). */
static size_t settle_kind(const cf_law *law, double tol, double U, double sign, half *h,
                          cf_export_table *scratch, double *err_N, double *where)
{
    const double goal = tol * fabs(cf_law_solid_force(law, sign));
    half empty = {0}, one = {1, (double[]){0.0}, (double[]){0.0}};
    for (size_t N = 0; N <= TABLE_MAX_INTERVALS; N = N ? 2 * N : TABLE_KIND_SAMPLES) {
        if (kind_place(law, U, N, sign, h) != 0)
            return 0;
        const half *co = sign > 0 ? h : &empty, *st = sign > 0 ? &empty : h;
        if (join(law, st->n ? st : &one, co->n ? co : &one, scratch) != 0)
            return 0;
        if ((*err_N = half_error(law, scratch, U, sign, where)) <= goal)
            return h->n - 1;
    }
    return TABLE_TOO_MANY;
}

/* Places one half to the tolerance: returns its region-2 interval count, 0 on failure (memory),
** TABLE_TOO_MANY when the count would pass TABLE_MAX_INTERVALS (*err_N: the last error). */
static size_t settle_half(const cf_law *law, double tol, double U, double sign, half *h,
                          cf_export_table *scratch, double *err_N, double *where)
{
    const double goal = tol * law->F_C_N;
    /* first guess from the integral of g: error per interval ~ (dG)^2 / 16 in units of F_C */
    double G = 0.0;
    if (law->mech)
        return settle_kind(law, tol, U, sign, h, scratch, err_N, where);
    if (U > law->u_T_mm && law->rho_inv_m1 > 0.0) {
        const double tT = sqrt(law->rho_inv_m1);
        const double tU = law->tail && U >= law->u_C_mm ? 0.0 : t_of_u(law, U);
        const int M = 512;
        for (int i = 0; i < M; i++)
            G += density(tT - (i + 0.5) * (tT - tU) / M) * (tT - tU) / M;
    }
    const double first = ceil(G / sqrt(16.0 * TABLE_AIM * tol)) + 1;
    if (!(first <= TABLE_MAX_INTERVALS))
        return TABLE_TOO_MANY;
    size_t N = (size_t)first;
    half empty = {0};
    for (int round = 0; round < TABLE_ROUNDS; round++) {
        if (half_place(law, U, N, h) != 0)
            return 0;
        /* a table with this half on its own side and a copy mirrored on the other */
        const half *co = sign > 0 ? h : &empty, *st = sign > 0 ? &empty : h;
        half one = {1, (double[]){0.0}, (double[]){0.0}};
        if (join(law, st->n ? st : &one, co->n ? co : &one, scratch) != 0)
            return 0;
        *err_N = half_error(law, scratch, U, sign, where);
        if (*err_N <= goal)
            return N;
        if (h->n <= 2) /* region 1 only: exact, cannot improve */
            return N;
        double next = fmax((double)N + 1.0, ceil(N * sqrt(*err_N / (TABLE_AIM * goal))));
        if (!(next <= TABLE_MAX_INTERVALS))
            return TABLE_TOO_MANY;
        N = (size_t)next;
    }
    return N; /* the caller sees *err_N > goal */
}

/* The tolerance and the range [u_lo, u_hi] of a table: CF_E_DATA naming what is wrong. */
static cf_status range_check(const cf_law *law, double tol, double u_lo_mm, double u_hi_mm,
                             cf_error *err)
{
    if (!isfinite(tol) || tol < CF_EXPORT_TOL_MIN || tol > CF_EXPORT_TOL_MAX)
        return cf_error_set(err, CF_E_DATA, "tolerance %g is outside [%g, %g]", tol,
                            CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
    const double u_end = cf_export_table_end(law, tol), s_end = stretch_end(law, tol);
    if (!isfinite(u_lo_mm) || !isfinite(u_hi_mm) || u_lo_mm > 0.0 || u_hi_mm < 0.0 ||
        !(u_hi_mm > u_lo_mm))
        return cf_error_set(err, CF_E_DATA,
                            "range [%g, %g] mm must contain the rest state u = 0 and be wider "
                            "than a point",
                            u_lo_mm, u_hi_mm);
    if (!law->extension && !law->mech && (u_hi_mm > u_end || -u_lo_mm > u_end))
        return cf_error_set(err, CF_E_DATA,
                            "range [%g, %g] mm passes the end of the spring's travel: the table "
                            "reaches |u| <= %.10g mm (where the law carries F_C (1 - tol); solid "
                            "at %.10g mm)",
                            u_lo_mm, u_hi_mm, u_end, law->travel_mm);
    if (u_hi_mm > u_end || -u_lo_mm > s_end) /* a pair: each side its own spring's */
        return cf_error_set(err, CF_E_DATA,
                            "range [%g, %g] mm passes the end of a spring's travel: the table "
                            "reaches u <= %.10g mm (the compression spring) and u >= -%.10g mm "
                            "(the extension spring), where each carries its F_C (1 - tol); solid "
                            "at %.10g and -%.10g mm",
                            u_lo_mm, u_hi_mm, u_end, s_end, law->travel_mm,
                            cf_law_travel(law, -1.0));
    return CF_OK;
}

/* The adaptive table over [u_lo, u_hi]: the compression and stretch sides of u = 0 grown until
** each meets tol (one side mirrored when the range is symmetric), joined, and the joined table's
** error measured on each side's check grid. Kept as one function because both sides share the
** law, the tolerance and the output table. */
cf_status cf_export_table_build_range(const cf_law *law, double tol, double u_lo_mm,
                                      double u_hi_mm, cf_export_table *t, cf_error *err)
{
    memset(t, 0, sizeof *t);
    cf_status status = range_check(law, tol, u_lo_mm, u_hi_mm, err);
    if (status != CF_OK)
        return status;
    half co = {0}, st = {0};
    cf_export_table scratch = {0};
    double eco = 0.0, est = 0.0, wco = 0.0, wst = 0.0;
    const double Uco = u_hi_mm, Ust = -u_lo_mm;
    size_t Nco = 0, Nst = 0;
    if (Uco > 0.0 && (Nco = settle_half(law, tol, Uco, +1.0, &co, &scratch, &eco, &wco)) == 0)
        goto oom;
    if (Nco == TABLE_TOO_MANY)
        goto too_many;
    if (Ust > 0.0) {
        if (law->extension) { /* a pair: the extension spring's own half, mirrored by join */
            if ((Nst = settle_half(law->extension, tol, Ust, +1.0, &st, &scratch, &est, &wst)) ==
                0)
                goto oom;
            if (Nst == TABLE_TOO_MANY)
                goto too_many;
        } else if (Ust == Uco && !law->mech) { /* the law is odd: the stretch half mirrors */
            st.n = co.n;
            st.u = malloc(co.n * sizeof *st.u);
            st.F = malloc(co.n * sizeof *st.F);
            if (!st.u || !st.F)
                goto oom;
            memcpy(st.u, co.u, co.n * sizeof *st.u);
            memcpy(st.F, co.F, co.n * sizeof *st.F);
            est = eco;
            wst = -wco;
            Nst = Nco;
        } else if ((Nst = settle_half(law, tol, Ust, -1.0, &st, &scratch, &est, &wst)) == 0) {
            goto oom;
        } else if (Nst == TABLE_TOO_MANY) {
            goto too_many;
        }
    }
    {
        half one = {1, (double[]){0.0}, (double[]){0.0}};
        if (join(law, st.n ? &st : &one, co.n ? &co : &one, t) != 0)
            goto oom;
    }
    t->tol = tol;
    t->u_lo_mm = t->req_lo_mm = u_lo_mm;
    t->u_hi_mm = t->req_hi_mm = u_hi_mm;
    /* the achieved error of the joined table, on the check grid of each side */
    eco = Uco > 0.0 ? half_error(law, t, Uco, +1.0, &wco) : 0.0;
    est = Ust > 0.0 ? half_error(law, t, Ust, -1.0, &wst) : 0.0;
    {   /* each side's error in its own spring's F_C (the same spring unless a pair) */
        const double rco = eco / law->F_C_N,
                     rst = est / (law->mech ? fabs(cf_law_solid_force(law, -1.0))
                                            : side_law(law, -1.0)->F_C_N);
        t->max_err_N = fmax(eco, est);
        t->max_err_u_mm = rco >= rst ? wco : wst;
        t->max_err_rel = fmax(rco, rst);
    }
    for (size_t i = 0; i < t->rows; i++)
        if (!isfinite(t->u_mm[i]) || !isfinite(t->F_N[i]) || !isfinite(t->k_N_per_mm[i])) {
            status = cf_error_set(err, CF_E_INTERNAL, "export table row %zu is not finite", i);
            cf_export_table_free(t);
            goto done;
        }
    if (t->max_err_rel > tol) { /* the spring, not the program: bad data (exit 65) */
        status = cf_error_set(err, CF_E_DATA,
                              "the spring (rho = %.4g) cannot be tabulated within the tolerance "
                              "%g of F_C: %zu rows reach %.3g; loosen the tolerance to at least "
                              "%.2g",
                              law->rho, tol, t->rows, t->max_err_rel, t->max_err_rel);
        cf_export_table_free(t);
    }
    (void)Nst;
    goto done;
too_many:
    if (law->tail)
        status = cf_error_set(err, CF_E_DATA,
                              "the spring cannot be tabulated within the tolerance %g of F_C in "
                              "%d rows (the error stops falling as rows are added): its tail "
                              "(n_tail = %g, H_tail = %g mm) is %.3g times as stiff as the cone "
                              "(deflection %.3g mm at F_C beside the cone's travel %g mm); "
                              "loosen the tolerance, or for a tail that stiff use none (n_tail 0)",
                              tol, 2 * TABLE_MAX_INTERVALS, law->p.n_tail, law->p.H_tail_mm,
                              law->k_tail_N_per_mm * (law->cone_travel_mm / law->F_C_N),
                              law->F_C_N / law->k_tail_N_per_mm, law->cone_travel_mm);
    else
        status = cf_error_set(err, CF_E_DATA,
                              "the spring (rho = %.4g) cannot be tabulated within the tolerance "
                              "%g of F_C in %d rows; loosen the tolerance",
                              law->rho, tol, 2 * TABLE_MAX_INTERVALS);
    cf_export_table_free(t);
    goto done;
oom:
    status = cf_error_set(err, CF_E_INTERNAL, "out of memory building the export table");
    cf_export_table_free(t);
done:
    free(co.u), free(co.F), free(st.u), free(st.F);
    cf_export_table_free(&scratch);
    return status;
}

/* ---- the evenly spaced table (targets that resample curves evenly: LS-DYNA) ------------------ */

/* The even table's placement aims its estimate at this fraction of the tolerance; the measured
** error decides, lowering the aim by EVEN_SHRINK until it passes. */
#define EVEN_AIM 0.95
#define EVEN_SHRINK 0.9
#define EVEN_ROUNDS 12

/* Sets t to n >= 2 rows evenly spaced over [a, b], on the law. 0, or -1 out of memory. */
static int even_fill(const cf_law *law, double a, double b, size_t n, cf_export_table *t)
{
    double *u = malloc(n * sizeof *u), *F = malloc(n * sizeof *F), *k = malloc(n * sizeof *k);
    if (!u || !F || !k) {
        free(u), free(F), free(k);
        return -1;
    }
    for (size_t i = 0; i < n; i++) {
        u[i] = i + 1 == n ? b : a + (b - a) * (double)i / (double)(n - 1);
        F[i] = cf_law_force(law, CF_LAW_EXACT, u[i], &k[i], NULL);
    }
    free(t->u_mm), free(t->F_N), free(t->k_N_per_mm);
    t->u_mm = u;
    t->F_N = F;
    t->k_N_per_mm = k;
    t->rows = n;
    t->u_lo_mm = a;
    t->u_hi_mm = b;
    t->even = 1;
    return 0;
}

/* The largest distance (N) of the law from the chord of [x0, x1], probed at EVEN_PROBES points. */
#define EVEN_PROBES 7
static double chord_error(const cf_law *law, double x0, double x1)
{
    const double F0 = cf_law_force(law, CF_LAW_EXACT, x0, NULL, NULL);
    const double F1 = cf_law_force(law, CF_LAW_EXACT, x1, NULL, NULL);
    double worst = 0.0;
    for (int p = 1; p <= EVEN_PROBES; p++) {
        const double f = p / (EVEN_PROBES + 1.0);
        const double F = cf_law_force(law, CF_LAW_EXACT, x0 + f * (x1 - x0), NULL, NULL);
        worst = fmax(worst, fabs(F - (F0 + f * (F1 - F0))));
    }
    return worst;
}

/* The interpolation error (N) of n evenly spaced rows over [a, b], estimated on the two outermost
** intervals at each end, where the law's curvature is largest (it grows with |u| in region 2 and
** is 0 in region 1), or on every interval when there are few. */
static double even_estimate(const cf_law *law, double a, double b, size_t n)
{
    const double h = (b - a) / (double)(n - 1);
    double worst = 0.0;
    /* a tail's curvature is largest where the cone closes (+-u_C), inside the range: the
    ** intervals around those two points count too */
    const double uc = law->u_C_mm;
    const int tail = law->tail && n > 16;
    for (size_t i = 0; i + 1 < n; i++) {
        if (tail && i >= 2 && i + 3 < n) {
            const double x = a + h * (double)i;
            if (fabs(fabs(x) - uc) > 3.0 * h)
                continue;
        } else if (n > 16 && i >= 2 && i + 3 < n)
            i = n - 3; /* the middle: smaller curvature */
        worst = fmax(worst, chord_error(law, a + h * (double)i,
                                        i + 2 == n ? b : a + h * (double)(i + 1)));
    }
    return worst;
}

/* The fewest rows (2 .. cap) whose estimate over [a, b] is within goal_N; cap + 1 when none is.
** The estimate falls as the rows grow (like their spacing squared): a doubling search, then
** bisection. */
static size_t even_rows(const cf_law *law, double a, double b, double goal_N, size_t cap)
{
    size_t lo = 1, hi = 2; /* lo fails (or is below 2), hi is the candidate */
    while (even_estimate(law, a, b, hi) > goal_N) {
        if (hi >= cap)
            return cap + 1;
        lo = hi;
        hi = hi * 2 > cap ? cap : hi * 2;
    }
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        if (mid >= 2 && even_estimate(law, a, b, mid) <= goal_N)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}

/* The range [lo, hi] cut at |u| <= U for the largest U whose n even rows are estimated within
** goal_N, by bisection on U (region 1 is linear, so U = u_T always works). */
static void even_cut(const cf_law *law, double lo, double hi, size_t n, double goal_N, double *a,
                     double *b)
{
    double good = fmin(fmin(law->u_T_mm, side_law(law, -1.0)->u_T_mm), fmax(-lo, hi));
    double bad = fmax(-lo, hi);
    for (int i = 0; i < 200 && bad - good > 1e-13 * bad; i++) {
        const double U = 0.5 * (good + bad);
        if (even_estimate(law, fmax(lo, -U), fmin(hi, U), n) <= goal_N)
            good = U;
        else
            bad = U;
    }
    *a = fmax(lo, -good);
    *b = fmin(hi, good);
}

cf_status cf_export_table_build_even(const cf_law *law, double tol, double u_lo_mm,
                                     double u_hi_mm, size_t max_rows, cf_export_table *t,
                                     cf_error *err)
{
    memset(t, 0, sizeof *t);
    cf_status status = range_check(law, tol, u_lo_mm, u_hi_mm, err);
    if (status != CF_OK)
        return status;
    if (max_rows < 2)
        max_rows = 2;
    /* a pair: the rows placed for the weaker spring's F_C, each side measured against its own */
    const double goal = tol * fmin(law->F_C_N, side_law(law, -1.0)->F_C_N);
    const double goal_lo = tol * side_law(law, -1.0)->F_C_N, goal_hi = tol * law->F_C_N;
    double aim = EVEN_AIM, e_hi = 0.0, e_lo = 0.0, w_hi = 0.0, w_lo = 0.0;
    for (int round = 0; round < EVEN_ROUNDS; round++, aim *= EVEN_SHRINK) {
        double a = u_lo_mm, b = u_hi_mm;
        size_t n = even_rows(law, a, b, aim * goal, max_rows);
        if (n > max_rows) {
            n = max_rows;
            even_cut(law, u_lo_mm, u_hi_mm, n, aim * goal, &a, &b);
        }
        if (even_fill(law, a, b, n, t) != 0) {
            cf_export_table_free(t);
            return cf_error_set(err, CF_E_INTERNAL, "out of memory building the export table");
        }
        /* measured on the check grid of each side, which knows nothing of the rows */
        e_hi = b > 0.0 ? half_error(law, t, b, +1.0, &w_hi) : 0.0;
        e_lo = a < 0.0 ? half_error(law, t, -a, -1.0, &w_lo) : 0.0;
        if (e_hi <= goal_hi && e_lo <= goal_lo)
            break;
    }
    t->tol = tol;
    t->req_lo_mm = u_lo_mm;
    t->req_hi_mm = u_hi_mm;
    t->max_err_N = fmax(e_hi, e_lo);
    t->max_err_u_mm = e_hi / goal_hi >= e_lo / goal_lo ? w_hi : w_lo;
    t->max_err_rel = fmax(e_hi / law->F_C_N, e_lo / side_law(law, -1.0)->F_C_N);
    if (t->max_err_rel > tol) {
        status = cf_error_set(err, CF_E_DATA,
                              "the spring (rho = %.4g) cannot be tabulated evenly within the "
                              "tolerance %g of F_C: %zu rows reach %.3g",
                              law->rho, tol, t->rows, t->max_err_rel);
        cf_export_table_free(t);
    }
    return status;
}

cf_status cf_export_table_build(const cf_law *law, double tol, cf_export_table *t, cf_error *err)
{
    if (!isfinite(tol) || tol < CF_EXPORT_TOL_MIN || tol > CF_EXPORT_TOL_MAX) {
        memset(t, 0, sizeof *t);
        return cf_error_set(err, CF_E_DATA, "tolerance %g is outside [%g, %g]", tol,
                            CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
    }
    const double u_end = cf_export_table_end(law, tol);
    return cf_export_table_build_range(law, tol, -stretch_end(law, tol), u_end, t, err);
}
