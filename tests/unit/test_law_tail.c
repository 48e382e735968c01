/*
** The conical spring with a cylindrical tail (law family conical-tail): every evaluator against an
** independent long-double reference, which inverts the series spring's explicit deflection
** u(F) = u_cone(F) + F/k_t by bisection on F; the hard corners (beta near 1/4, beta small and
** large, near the cone's solid and near the tail's); region 3; the design checks on bad input.
*/
/* conifit: vector-level: the tailed law's lanes, the level CONIFIT_SIMD names */
#include <math.h>
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "model/law_internal.h"
#include "model/law_simd.h"
#include "testutil.h"

/* A tailed spring: cone D1 = rho, D2 = 1, n coils, wire d, G, H = 3 with the tail's n_t = tau n
** coils in H_tail (its gap per coil `gap` times the cone's). */
static cf_spring tailed(double rho, double n, double tau, double gap)
{
    const double d = 0.25 * rho / 3.0; /* index 3 at the small end: non-telescoping for small n */
    cf_spring p = {rho, 1.0, n, d, 8e4, 0};
    const double cone_free = 2.0;
    const double nt = tau * n;
    const double Lc = (0.5 * (1.0 - rho) >= n * d) ? d : n * d;
    const double s = cone_free - Lc;
    const double s_t = gap * (s / n) * nt;
    p.n_tail = nt;
    p.H_tail_mm = nt * d + s_t;
    p.H_mm = cone_free + p.H_tail_mm;
    return p;
}

/* ---- the reference: bisection on F in long double ---------------------------------------------*/

typedef struct ref_law {
    long double rho, r, s, FC, FT, k0c, kt, uTc, s_t;
} ref_law;

static ref_law ref_of(const cf_spring *p)
{
    ref_law R;
    long double D1 = p->D1_mm, D2 = p->D2_mm, n = p->n, d = p->d_mm, G = p->G_MPa;
    int tele = 0.5L * (D2 - D1) >= n * d;
    long double Lc = tele ? d : n * d;
    R.s = (long double)p->H_mm - (long double)p->H_tail_mm - Lc;
    R.rho = D1 / D2;
    R.r = (D2 - D1) / D1;
    R.FC = G * d * d * d * d * R.s / (8 * n * D1 * D1 * D1);
    R.FT = G * d * d * d * d * R.s / (8 * n * D2 * D2 * D2);
    R.k0c = G * d * d * d * d / (2 * n * (D1 + D2) * (D1 * D1 + D2 * D2));
    R.kt = G * d * d * d * d / (8 * (long double)p->n_tail * D1 * D1 * D1);
    R.uTc = R.s * (1 + R.rho) * (1 + R.rho * R.rho) / 4;
    R.s_t = (long double)p->H_tail_mm - (long double)p->n_tail * d;
    return R;
}

/* Compression of the series spring at force F in [0, k_t s_t]. */
static long double ref_u_of_F(const ref_law *R, long double F)
{
    long double uc;
    if (F <= R->FT)
        uc = F / R->k0c;
    else if (F >= R->FC)
        uc = R->s;
    else {
        long double y = cbrtl(F / R->FC), e = 1 - y;
        uc = R->s - R->s * e * e * (3 + 2 * y + y * y) / (4 * y) / R->r;
    }
    return uc + F / R->kt;
}

static long double reference_force(const cf_spring *p, long double u)
{
    ref_law R = ref_of(p);
    long double a = fabsl(u), sg = u < 0 ? -1 : 1;
    long double Fmax = R.kt * R.s_t;
    if (a >= ref_u_of_F(&R, Fmax))
        return sg * Fmax;
    long double lo = 0, hi = Fmax;
    for (int it = 0; it < 200; it++) {
        long double mid = 0.5L * (lo + hi);
        if (ref_u_of_F(&R, mid) < a)
            lo = mid;
        else
            hi = mid;
    }
    return sg * 0.5L * (lo + hi);
}

/* ---- the hard cases --------------------------------------------------------------------------*/

static const double rhos[] = {0.9, 0.5, 0.1, 0.03};

/* tau for beta = (1/rho - 1) tau in the corners: 1e-9, 1e-3, just under, at and over 1/4, 0.3,
** 1, 50 */
static const double betas[] = {1e-9, 1e-3, 0.25 * (1 - 1e-9), 0.25, 0.25 * (1 + 1e-9), 0.3, 1.0, 50.0};

/* Displacements: each region, near the transition, near the cone's solid (u_C) from both sides,
** near the tail's solid, stretch. */
static size_t probes(const cf_law *law, double *u)
{
    size_t k = 0;
    const double uT = law->u_T_mm, uC = law->u_C_mm, S = law->travel_mm;
    const double rel[] = {1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.01, 0.1, 0.3};
    u[k++] = 0.5 * uT;
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
        u[k++] = uT + (uC - uT) * rel[i];
        u[k++] = uC - (uC - uT) * rel[i];
        u[k++] = uC + (S - uC) * rel[i];
        u[k++] = S - (S - uC) * rel[i];
    }
    for (int i = 1; i < 20; i++)
        u[k++] = uT + (uC - uT) * i / 20.0;
    u[k++] = -(uT + 0.5 * (uC - uT));
    u[k++] = -(uC + 0.5 * (S - uC));
    u[k++] = 1.5 * S;
    return k;
}

static void check_against_reference(cf_law_method m, double tol, int rel_to_FC)
{
    double worst = 0;
    char where[96] = "";
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++)
        for (size_t b = 0; b < sizeof betas / sizeof betas[0]; b++) {
            const double rho = rhos[a], tau = betas[b] / (1 / rho - 1);
            cf_spring p = tailed(rho, 4, tau, 1.5);
            cf_law law;
            cf_error err = {0};
            assert_int_equal(cf_law_init(&law, &p, &err), CF_OK);
            assert_true(law.tail);
            if (m == CF_LAW_TABLE)
                assert_int_equal(cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, &err), CF_OK);
            double u[80];
            size_t np = probes(&law, u);
            for (size_t i = 0; i < np; i++) {
                const long double R = reference_force(&p, u[i]);
                const double F = cf_law_force(&law, m, u[i], NULL, NULL);
                assert_true(isfinite(F));
                /* relative to |F|, once the rounding of the displacement is allowed for: the
                ** derived lengths (u_T, u_C, s) carry a few ulps, which a stiff tail (small
                ** beta) turns into k ulp(u) of force (k the local stiffness); the evaluator must be
                ** exact for a displacement within 8 ulps of u_C */
                double k;
                int fl;
                cf_law_force(&law, CF_LAW_EXACT, u[i], &k, &fl);
                if (fl & CF_LAW_SOLID)
                    k = law.k_tail_N_per_mm; /* the stiffness just before solid */
                const long double slack = 8.0L * DBL_EPSILON * k * law.u_C_mm;
                const long double dev = fabsl((long double)F - R) - slack;
                const long double scale = rel_to_FC ? (long double)law.F_C_N : fabsl(R);
                const double rel = (double)(fmaxl(dev, 0.0L) / fmaxl(scale, 1e-300L));
                if (rel > worst) {
                    worst = rel;
                    snprintf(where, sizeof where, "rho %g beta %.3g u/u_C %.17g", rho, betas[b],
                             u[i] / law.u_C_mm);
                }
                if (rel > tol)
                    fail_msg("%s: rho %g beta %.10g u %.17g: F %.17g, reference %.17Lg (rel %.3g)",
                             cf_law_method_name(m), rho, betas[b], u[i], F, R, rel);
            }
            cf_law_free(&law);
        }
    printf("# %s: worst relative force error %.3g over the hard cases (beyond 8 ulps of u) at %s\n",
           cf_law_method_name(m), worst, where);
}

static void exact_matches_reference(void **state)
{
    (void)state;
    check_against_reference(CF_LAW_EXACT, 1e-12, 0);
}

static void closed_matches_reference(void **state)
{
    (void)state;
    check_against_reference(CF_LAW_CLOSED, 1e-12, 0);
    check_against_reference(CF_LAW_CLOSED_NEWTON, 1e-12, 0);
}

/* The table carries an interpolation error. With a tail it holds F/F_C on a grid in which the
** cone's solid is regular (law.c, struct cf_law_table): measured at the default size, at most
** 6.7e-8 of F_C over every hard case (rho 0.03 with beta 50, near the transition, where F is 1e-4
** of F_C); bound 1e-7 of F_C. */
static void table_is_within_its_bound(void **state)
{
    (void)state;
    check_against_reference(CF_LAW_TABLE, 1e-7, 1);
}

/* Regions by flag; the stiffness of each region against a central difference; continuity at the
** region boundaries; force-deflection inversion. */
static void regions_stiffness_and_inverse(void **state)
{
    (void)state;
    cf_spring p = tailed(0.4, 5, 0.3, 2.0);
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &p, &err), CF_OK);
    int fl;
    double k;
    cf_law_force(&law, CF_LAW_CLOSED, 0.5 * law.u_T_mm, &k, &fl);
    assert_int_equal(fl, CF_LAW_LINEAR);
    assert_true(k == law.k0_N_per_mm);
    const double F3 = cf_law_force(&law, CF_LAW_CLOSED, 0.5 * (law.u_C_mm + law.travel_mm), &k, &fl);
    assert_int_equal(fl, CF_LAW_TAIL);
    assert_close(k, law.k_tail_N_per_mm, 0);
    assert_true(F3 > law.F_C_N && F3 < law.F_solid_N);
    cf_law_force(&law, CF_LAW_CLOSED, 1.01 * law.travel_mm, &k, &fl);
    assert_int_equal(fl, CF_LAW_SOLID);
    /* series stiffness of region 1 from the parts: 1/k0 = 1/k_cone + 1/k_tail */
    cf_spring cone = p;
    cone.n_tail = 0;
    cone.H_tail_mm = 0;
    cone.H_mm = p.H_mm - p.H_tail_mm;
    cf_law lc;
    assert_int_equal(cf_law_init(&lc, &cone, &err), CF_OK);
    assert_close(1 / law.k0_N_per_mm, 1 / lc.k0_N_per_mm + 1 / law.k_tail_N_per_mm,
                        1e-13 / law.k0_N_per_mm);
    assert_close(law.F_C_N, lc.F_C_N, 1e-15 * lc.F_C_N);
    assert_close(law.u_C_mm, lc.travel_mm * (1 + p.n_tail / p.n), 1e-14 * law.u_C_mm);
    /* stiffness against a central difference and the inverse, across region 2 and 3 */
    for (int i = 1; i < 40; i++) {
        const double u = law.u_T_mm + (law.travel_mm - law.u_T_mm) * i / 40.0;
        const double h = 1e-6 * law.travel_mm;
        const double F = cf_law_force(&law, CF_LAW_CLOSED, u, &k, NULL);
        const double Fp = cf_law_force(&law, CF_LAW_EXACT, u + h, NULL, NULL);
        const double Fm = cf_law_force(&law, CF_LAW_EXACT, u - h, NULL, NULL);
        assert_close(k, (Fp - Fm) / (2 * h), 1e-6 * k);
        assert_close(cf_law_deflection(&law, F), u, 1e-12 * law.travel_mm);
    }
    /* continuous at u_T and u_C */
    const double eps = 1e-12;
    assert_close(cf_law_force(&law, CF_LAW_CLOSED, law.u_T_mm * (1 - eps), NULL, NULL),
                        cf_law_force(&law, CF_LAW_CLOSED, law.u_T_mm * (1 + eps), NULL, NULL),
                        1e-9 * law.F_T_N);
    assert_close(cf_law_force(&law, CF_LAW_CLOSED, law.u_C_mm * (1 - eps), NULL, NULL),
                        cf_law_force(&law, CF_LAW_CLOSED, law.u_C_mm * (1 + eps), NULL, NULL),
                        1e-9 * law.F_C_N);
    cf_law_free(&lc);
}

/* The batch evaluation of a tailed law equals the scalar one (the law's batch has no vector lanes
** for a tail: only the lattice step's polynomial, below, is one). */
static void batch_equals_scalar(void **state)
{
    (void)state;
    cf_spring p = tailed(0.2, 3, 0.5, 1.2);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    double u[80], F[80], k[80];
    size_t np = probes(&law, u);
    const cf_law_method ms[] = {CF_LAW_EXACT, CF_LAW_CLOSED, CF_LAW_CLOSED_NEWTON};
    for (size_t m = 0; m < 3; m++) {
        cf_law_force_many(&law, ms[m], np, u, F, NULL);
        cf_law_force_many(&law, ms[m], np, u, F, k);
        for (size_t i = 0; i < np; i++)
            assert_close(F[i], cf_law_force(&law, ms[m], u[i], NULL, NULL), 0);
    }
}

/* Displacements for the polynomial: the probes, every region boundary and one ulp either side,
** random ones in each region and past the tail's solid, half of them stretched, then NaN and
** +-Inf. */
static size_t poly_points(const cf_law *law, double *u, unsigned seed)
{
    size_t k = probes(law, u);
    const double b[] = {law->u_T_mm, law->u_C_mm, law->travel_mm};
    for (int i = 0; i < 3; i++) {
        u[k++] = nextafter(b[i], 0.0);
        u[k++] = b[i];
        u[k++] = -nextafter(b[i], INFINITY);
    }
    const double ends[5] = {0, law->u_T_mm, law->u_C_mm, law->travel_mm, 1.2 * law->travel_mm};
    srand(seed);
    for (int r = 0; r < 4; r++)
        for (int i = 0; i < 250; i++) {
            const double f = rand() / (double)RAND_MAX;
            const double a = ends[r] + (ends[r + 1] - ends[r]) * f;
            u[k++] = (i & 1) ? -a : a;
        }
    u[k++] = NAN;
    u[k++] = INFINITY;
    u[k++] = -INFINITY;
    return k;
}

/* The lattice step's polynomial of a tailed spring (law_poly.c, law_simd.h cf_lane_poly_tail),
** through the dispatched batch at the level CONIFIT_SIMD allows, against the scalar closed form:
** within CF_POLY_TOL of |F| at every point of every region, the boundaries and both solids
** included, in compression and stretch. It must fit for beta <= 0.2 down to rho = 0.03 (the plain
** law's range), for beta up to 0.3 down to rho = 0.1, up to 1 down to rho = 0.2 and for every
** beta at rho >= 0.5; elsewhere it may be refused, and the batch then runs the scalar law. */
static void polynomial_matches_the_closed_form(void **state)
{
    (void)state;
    static const double prho[] = {0.9, 0.5, 0.3, 0.2, 0.1, 0.05, 0.03, 0.02};
    static const double pbeta[] = {1e-9, 1e-3, 0.1, 0.2, 0.25 * (1 - 1e-9), 0.25,
                                   0.25 * (1 + 1e-9), 0.3, 1.0, 3.0, 50.0};
    static double u[1200], F[1200];
    double worst = 0;
    char where[96] = "";
    int fitted = 0, refused = 0;
    for (size_t a = 0; a < sizeof prho / sizeof prho[0]; a++)
        for (size_t b = 0; b < sizeof pbeta / sizeof pbeta[0]; b++) {
            const double rho = prho[a], beta = pbeta[b];
            cf_spring p = tailed(rho, 4, beta / (1 / rho - 1), 1.5);
            cf_law law;
            assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
            cf_law_lanes lanes;
            cf_law_lanes_init(&law, &lanes);
            double err;
            const int ok = cf_law_lanes_fit_poly(&law, &lanes, &err);
            const int must = (beta <= 0.2 && rho >= 0.03) || (beta <= 0.3 && rho >= 0.1) ||
                             (beta <= 1 && rho >= 0.2) || rho >= 0.5;
            if (must && !ok)
                fail_msg("rho %g beta %.10g: no polynomial (error %.3g)", rho, beta, err);
            if (ok) {
                assert_true(err <= CF_POLY_TOL);
                fitted++;
            } else {
                refused++;
            }
            const size_t np = poly_points(&law, u, (unsigned)(100 * a + b));
            assert_true(np <= sizeof u / sizeof u[0]);
            cf_law_force_lanes(&lanes, CF_LANE_POLY, np, u, F);
            for (size_t i = 0; i < np; i++) {
                const double R = cf_law_force(&law, CF_LAW_CLOSED, u[i], NULL, NULL);
                assert_true(isfinite(F[i]));
                const double dev = fabs(F[i] - R);
                const double rel = dev == 0 ? 0 : dev / fmax(fabs(R), DBL_MIN);
                if (ok && rel > worst) {
                    worst = rel;
                    snprintf(where, sizeof where, "rho %g beta %.3g u/u_C %.17g", rho, beta,
                             u[i] / law.u_C_mm);
                }
                if (rel > (ok ? CF_POLY_TOL : 0))
                    fail_msg("rho %g beta %.10g u %.17g: polynomial %.17g, closed form %.17g "
                             "(rel %.3g)", rho, beta, u[i], F[i], R, rel);
            }
            cf_law_free(&law);
        }
    printf("# tailed polynomial (%s): %d fitted, %d refused; worst relative force error %.3g "
           "against the closed form at %s\n",
           cf_simd_name(cf_simd_level()), fitted, refused, worst, where);
}

static void expect_refused(cf_spring p, const char *key)
{
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &p, &err), CF_E_DATA);
    if (!strstr(err.msg, key))
        fail_msg("message '%s' does not name %s", err.msg, key);
}

static void bad_tails_are_refused_naming_the_key(void **state)
{
    (void)state;
    const cf_spring good = tailed(0.4, 5, 0.3, 2.0);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &good, NULL), CF_OK);
    cf_spring p = good;
    p.n_tail = -1;
    expect_refused(p, "n_tail");
    p = good;
    p.n_tail = NAN;
    expect_refused(p, "n_tail");
    p = good;
    p.H_tail_mm = INFINITY;
    expect_refused(p, "H_tail_mm");
    p = good;
    p.n_tail = 0;
    expect_refused(p, "H_tail_mm"); /* a tail length without coils */
    p = good;
    p.H_tail_mm = p.n_tail * p.d_mm; /* no room for the tail's solid length */
    expect_refused(p, "H_tail_mm");
    p = good;
    p.H_tail_mm = p.H_mm - 0.5 * p.d_mm; /* no room for the cone */
    expect_refused(p, "H_tail_mm");
    p = good;
    /* tail gap per coil equal to the cone's: the tail would close with the cone */
    const double s = law.cone_travel_mm;
    p.H_tail_mm = p.n_tail * p.d_mm + s / p.n * p.n_tail;
    p.H_mm = good.H_mm - good.H_tail_mm + p.H_tail_mm;
    expect_refused(p, "H_tail_mm");
}

/* Without a tail the law's derived quantities keep the plain meanings. */
static void no_tail_is_the_plain_law(void **state)
{
    (void)state;
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    assert_int_equal(law.tail, 0);
    assert_true(law.u_C_mm == law.travel_mm);
    assert_true(law.cone_travel_mm == law.travel_mm);
    assert_true(law.F_solid_N == law.F_C_N);
    assert_true(law.beta == 0 && law.tau == 0 && law.k_tail_N_per_mm == 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exact_matches_reference),
        cmocka_unit_test(closed_matches_reference),
        cmocka_unit_test(table_is_within_its_bound),
        cmocka_unit_test(regions_stiffness_and_inverse),
        cmocka_unit_test(batch_equals_scalar),
        cmocka_unit_test(polynomial_matches_the_closed_form),
        cmocka_unit_test(bad_tails_are_refused_naming_the_key),
        cmocka_unit_test(no_tail_is_the_plain_law),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
