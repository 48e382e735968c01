/*
** Tests of the conical spring law (src/model/law.c): hand-computed values, the evaluators against an
** independent long-double evaluation over the hard corners of the domain, the invariants of the
** law, parameter checks, and the force/curve/info command line.
*/
/* conifit: vector-level: the law's lanes against the scalar law */
#include <float.h>
#include <math.h>

#include "testutil.h"

#include "model/law_internal.h"
#include "model/law_simd.h"

/* Error bounds (relative to |F| unless said otherwise). */
#define EXACT_TOL 1e-14   /* exact (Brent to the last bits) against the long-double reference */
#define CLOSED_TOL 1e-12  /* closed form and closed+newton against the reference (issue target) */
/* The table of 256 intervals: measured 2.3e-10 relative to |F| at rho = 0.1 and 6.5e-7 relative
** to F_C at rho = 1e-3 (law.h); the bounds leave a factor of 4 to 8. */
#define TABLE_TOL_256 1e-9 /* relative to |F|, rho >= 0.1 */
#define TABLE_TOL_FC 5e-6  /* relative to F_C, any rho down to 1e-3 */

static cf_spring spring(double D1, double D2, double n, double d, double G, double H)
{
    cf_spring p = {D1, D2, n, d, G, H};
    return p;
}

static void init_ok(cf_law *law, cf_spring p)
{
    cf_error err = {0};
    cf_status st = cf_law_init(law, &p, &err);
    if (st != CF_OK)
        fail_msg("cf_law_init refused a valid spring: %s", err.msg);
}

/* ---- an independent evaluation: bisection in long double on the explicit u(y) ---------------- */

/* F(u) for 0 <= u < s from the explicit inverse u(y) = s (1/rho - c(y))/(1/rho - 1),
** c(y) = (3 + y^4)/(4y), solved by plain bisection on y in [rho, 1] in long double. */
static long double reference_force(const cf_spring *p, long double u)
{
    long double D1 = p->D1_mm, D2 = p->D2_mm, n = p->n, d = p->d_mm, G = p->G_MPa;
    /* The travel is rounded to double as the spring defines it: near solid the force depends on
    ** s - u at the last bit, and u is a double measured against that same s. */
    double Lmin_d = ((p->D2_mm - p->D1_mm) / 2 >= p->n * p->d_mm) ? p->d_mm : p->n * p->d_mm;
    long double s = (double)(p->H_mm - Lmin_d);
    long double rho = D1 / D2;
    long double FC = G * d * d * d * d * s / (8 * n * D1 * D1 * D1);
    long double k0 = G * d * d * d * d / (2 * n * (D1 + D2) * (D1 * D1 + D2 * D2));
    long double uT = s * (1 + rho) * (1 + rho * rho) / 4;
    long double a = fabsl(u), sg = u < 0 ? -1 : 1;
    if (a <= uT)
        return k0 * u;
    if (a >= s)
        return sg * FC;
    /* target: s - a = s (c - 1)/(1/rho - 1)  =>  c - 1 = (D2 - D1)/D1 (s - a)/s */
    long double delta = (D2 - D1) / D1 * ((s - a) / s);
    long double lo = rho, hi = 1; /* c(y) - 1 = (1-y)^2 (3 + 2y + y^2)/(4y), decreasing */
    for (int it = 0; it < 200; it++) {
        long double mid = 0.5L * (lo + hi);
        long double e = 1 - mid;
        long double dm = e * e * (3 + 2 * mid + mid * mid) / (4 * mid);
        if (dm > delta)
            lo = mid;
        else
            hi = mid;
        if (hi - lo <= LDBL_EPSILON * hi)
            break;
    }
    long double y = 0.5L * (lo + hi);
    return sg * FC * y * y * y;
}

/* ---- hand-computed values -------------------------------------------------------------------- */

/* Telescoping: D1=10, D2=30, n=4, d=1, G=80000, H=40. (30-10)/2 = 10 >= 4 so L_min = 1, s = 39;
** F_C = 80000*39/(8*4*1000) = 97.5 N; F_T = F_C/27; k0 = 80000/(2*4*40*1000) = 0.25 N/mm;
** at y = 1/2: c = (3 + 1/16)/2 = 1.53125, u = 39 (3 - 1.53125)/2 = 28.640625 mm and
** F = 97.5/8 = 12.1875 N, k = 4*97.5*(1/16)*2/(39*(15/16)) = 4/3 N/mm. */
static void telescoping_spring_matches_hand_values(void **state)
{
    (void)state;
    cf_law law;
    init_ok(&law, spring(10, 30, 4, 1, 80000, 40));
    assert_int_equal(law.type, CF_TELESCOPING);
    assert_close(law.L_min_mm, 1.0, 0);
    assert_close(law.travel_mm, 39.0, 0);
    assert_close(law.L_max_mm, 79.0, 0);
    assert_close(law.F_C_N, 97.5, 1e-13);
    assert_close(law.F_T_N, 97.5 / 27.0, 1e-14);
    assert_close(law.k0_N_per_mm, 0.25, 1e-16);
    assert_close(law.u_T_mm, 39.0 * 40.0 / 108.0, 1e-13);
    assert_close(law.index_c, 10.0, 0);
    for (int m = CF_LAW_EXACT; m <= CF_LAW_CLOSED_NEWTON; m++) {
        double k;
        double F = cf_law_force(&law, (cf_law_method)m, 28.640625, &k, NULL);
        assert_close(F, 12.1875, 12.1875 * 1e-14);
        assert_close(k, 4.0 / 3.0, 1e-12);
        assert_close(cf_law_force(&law, (cf_law_method)m, -28.640625, NULL, NULL),
                            -12.1875, 12.1875 * 1e-14);
    }
    /* region 1 is exactly linear */
    assert_close(cf_law_force(&law, CF_LAW_CLOSED, 10.0, NULL, NULL), 2.5, 1e-15);
}

/* Non-telescoping: D1=10, D2=14, n=5, d=1.5, G=80000, H=30. (14-10)/2 = 2 < 7.5 so L_min = 7.5,
** s = 22.5; F_C = 80000*1.5^4*22.5/(8*5*1000) = 227.8125 N; at y = 0.9: c = 3.6561/3.6,
** u = 22.5 (1.4 - c)/0.4 = 21.6234375 mm, F = 227.8125*0.729 = 166.0753125 N. */
static void non_telescoping_spring_matches_hand_values(void **state)
{
    (void)state;
    cf_law law;
    init_ok(&law, spring(10, 14, 5, 1.5, 80000, 30));
    assert_int_equal(law.type, CF_NON_TELESCOPING);
    assert_close(law.L_min_mm, 7.5, 0);
    assert_close(law.travel_mm, 22.5, 0);
    assert_close(law.F_C_N, 227.8125, 1e-12);
    for (int m = CF_LAW_EXACT; m <= CF_LAW_CLOSED_NEWTON; m++) {
        double F = cf_law_force(&law, (cf_law_method)m, 21.6234375, NULL, NULL);
        assert_close(F, 166.0753125, 166.0753125 * 1e-13);
    }
}

/* ---- evaluators against the reference over the hard cases ------------------------------------ */

typedef struct geometry {
    const char *name;
    cf_spring p;
} geometry;

/* Builds a spring with the given rho and scales for G and H. */
static cf_spring scaled(double rho, double n, double Gs, double Hs)
{
    double D2 = 30 * Hs, D1 = rho * D2;
    double d = fmin(D1 / 4.0, 0.4 * Hs / n);
    return spring(D1, D2, n, d, 8e4 * Gs, 40 * Hs);
}

static const double rhos[] = {1 - 1e-12, 1 - 1e-6, 0.9, 0.5, 0.1, 1e-3};
static const double scales[] = {1e-6, 1, 1e9};
static const double coils[] = {2, 7.5, 1e4};

/* Displacements that probe every corner: 0, u_T and one ulp either side, near solid, solid,
** beyond solid, and a dense sweep over (-s, s) that is denser near solid. */
static size_t probe_points(const cf_law *law, double *u, size_t cap)
{
    size_t k = 0;
    const double s = law->travel_mm, uT = law->u_T_mm;
    const double fixed[] = {0.0, uT, nextafter(uT, 0), nextafter(uT, INFINITY), s * (1 - 1e-15),
                            s * (1 - 1e-12), s * (1 - 1e-9), s, 1.5 * s, nextafter(s, 0)};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0] && k < cap; i++) {
        u[k++] = fixed[i];
        u[k++] = -fixed[i];
    }
    for (int i = 1; i < 400 && k < cap; i++) {
        double x = (double)i / 400.0;
        u[k++] = s * x;
        u[k++] = s * (1 - x * x * x * x); /* clusters near solid */
    }
    return k;
}

static void check_method(const cf_law *law, cf_law_method m, double tol, int rel_to_FC)
{
    double u[1024];
    size_t np = probe_points(law, u, 1024);
    for (size_t i = 0; i < np; i++) {
        double k;
        int flags;
        double F = cf_law_force(law, m, u[i], &k, &flags);
        long double R = reference_force(&law->p, u[i]);
        assert_true(isfinite(F) && isfinite(k) && k >= 0);
        double scale = rel_to_FC ? law->F_C_N : fabs((double)R);
        double errv = fabs(F - (double)R);
        if (errv > tol * scale && errv > 0)
            fail_msg("%s: rho=%.17g n=%g G=%g H=%g u=%.17g F=%.17g ref=%.17Lg rel=%.3g",
                     cf_law_method_name(m), law->rho, law->p.n, law->p.G_MPa, law->p.H_mm, u[i],
                     F, R, errv / scale);
    }
}

/* Forces F at the probe points u of law followed by NaN, +Inf and -Inf (np in all), as a batch
** evaluator gives them: NaN to 0, +-Inf to +-F_C, every point within tol of the long-double
** reference (relative to F_C or to the force itself). what names the evaluator in a failure. */
static void check_batch_values(const cf_law *law, const double *u, const double *F, size_t np,
                               double tol, int rel_to_FC, const char *what)
{
    assert_close(F[np - 3], 0.0, 0);
    assert_close(F[np - 2], law->F_C_N, 0);
    assert_close(F[np - 1], -law->F_C_N, 0);
    for (size_t i = 0; i + 3 < np; i++) {
        long double R = reference_force(&law->p, u[i]);
        double scale = rel_to_FC ? law->F_C_N : fabs((double)R);
        double errv = fabs(F[i] - (double)R);
        if (!isfinite(F[i]) || (errv > tol * scale && errv > 0))
            fail_msg("%s: rho=%.17g n=%g G=%g H=%g u=%.17g F=%.17g ref=%.17Lg rel=%.3g", what,
                     law->rho, law->p.n, law->p.G_MPa, law->p.H_mm, u[i], F[i], R, errv / scale);
    }
}

/* The probe points of law and the three non-finite ones; returns their count. */
static size_t batch_points(const cf_law *law, double *u)
{
    size_t np = probe_points(law, u, 1024);
    u[np++] = NAN;
    u[np++] = INFINITY;
    u[np++] = -INFINITY;
    return np;
}

/* The same points through cf_law_force_many without stiffness: for the closed form and the table
** that is the vectorised, branch-free path (law_simd.h), whose points of different regions share
** one vector; it must keep the scalar evaluator's bound, and map NaN to 0 and +-Inf to +-F_C. */
static void check_batch(const cf_law *law, cf_law_method m, double tol, int rel_to_FC)
{
    double u[1030], F[1030];
    const size_t np = batch_points(law, u);
    cf_law_force_many(law, m, np, u, F, NULL);
    char what[64];
    snprintf(what, sizeof what, "%s batch", cf_law_method_name(m));
    check_batch_values(law, u, F, np, tol, rel_to_FC, what);
}

static void closed_and_exact_match_reference_in_every_corner(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++)
        for (size_t b = 0; b < sizeof scales / sizeof scales[0]; b++)
            for (size_t c = 0; c < sizeof coils / sizeof coils[0]; c++) {
                cf_law law;
                init_ok(&law, scaled(rhos[a], coils[c], scales[b], scales[(b + 1) % 3]));
                check_method(&law, CF_LAW_EXACT, EXACT_TOL, 0);
                check_method(&law, CF_LAW_CLOSED, CLOSED_TOL, 0);
                check_batch(&law, CF_LAW_CLOSED, CLOSED_TOL, 0);
                check_method(&law, CF_LAW_CLOSED_NEWTON, CLOSED_TOL, 0);
            }
}

/* The polynomial of region 2 of law, fitted: within the closed form's 1e-12 of the long-double
** reference at every hard case, through the dispatched batch (NaN to 0, +-Inf to +-F_C). Returns
** its degree, times 10 for two pieces. */
static int check_poly(const cf_law *law)
{
    cf_law_lanes lanes;
    cf_law_lanes_init(law, &lanes);
    double worst;
    assert_int_equal(cf_law_lanes_fit_poly(law, &lanes, &worst), 1);
    assert_int_equal(lanes.poly_fit, 1);
    assert_true(worst <= CF_POLY_TOL);
    double u[1030], F[1030];
    const size_t np = batch_points(law, u);
    cf_law_force_lanes(&lanes, CF_LANE_POLY, np, u, F);
    char what[64];
    snprintf(what, sizeof what, "polynomial of degree %d", lanes.poly_degree);
    check_batch_values(law, u, F, np, CLOSED_TOL, 0, what);
    return lanes.poly_degree * (lanes.poly_pieces == 2 ? 10 : 1);
}

/* The polynomial of region 2 (law_poly.c, law_simd.h): of the low degree down to rho = 0.5 in this
** list, of the high degree at rho = 0.25 and 0.2, in two pieces at 0.1, 0.05 and 0.03, refused at
** 0.02 and 1e-3 (the caller keeps the closed form), and where fitted within the closed form's
** bound at every hard case. */
static void polynomial_form_matches_reference_where_it_fits(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++)
        for (size_t b = 0; b < sizeof scales / sizeof scales[0]; b++)
            for (size_t c = 0; c < sizeof coils / sizeof coils[0]; c++) {
                cf_law law;
                init_ok(&law, scaled(rhos[a], coils[c], scales[b], scales[(b + 1) % 3]));
                if (rhos[a] >= 0.5) {
                    assert_int_equal(check_poly(&law), CF_POLY_DEGREE_LOW);
                    continue;
                }
                if (rhos[a] >= 0.1) {
                    assert_int_equal(check_poly(&law), 10 * CF_POLY_DEGREE);
                    continue;
                }
                cf_law_lanes lanes;
                cf_law_lanes_init(&law, &lanes);
                double worst;
                assert_int_equal(cf_law_lanes_fit_poly(&law, &lanes, &worst), 0);
                assert_int_equal(lanes.poly_fit, 0);
                assert_true(!(worst <= CF_POLY_TOL));
            }
    static const double more[] = {0.25, 0.2, 0.05, 0.03, 0.02};
    for (size_t a = 0; a < sizeof more / sizeof more[0]; a++)
        for (size_t c = 0; c < sizeof coils / sizeof coils[0]; c++) {
            cf_law law;
            init_ok(&law, scaled(more[a], coils[c], 1, 1));
            if (more[a] >= 0.2)
                assert_int_equal(check_poly(&law), CF_POLY_DEGREE);
            else if (more[a] >= 0.03)
                assert_int_equal(check_poly(&law), 10 * CF_POLY_DEGREE);
            else {
                cf_law_lanes lanes;
                cf_law_lanes_init(&law, &lanes);
                assert_int_equal(cf_law_lanes_fit_poly(&law, &lanes, NULL), 0);
            }
        }
}

static void table_error_is_within_its_stated_bound(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++) {
        cf_law law;
        cf_error err = {0};
        init_ok(&law, scaled(rhos[a], 5, 1, 1));
        assert_int_equal(cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, &err), CF_OK);
        check_method(&law, CF_LAW_TABLE, TABLE_TOL_FC, 1);
        check_batch(&law, CF_LAW_TABLE, TABLE_TOL_FC, 1);
        if (rhos[a] >= 0.1) {
            check_method(&law, CF_LAW_TABLE, TABLE_TOL_256, 0);
            check_batch(&law, CF_LAW_TABLE, TABLE_TOL_256, 0);
        }
        cf_law_free(&law);
    }
}

static void table_error_falls_with_table_size(void **state)
{
    (void)state;
    cf_law law;
    cf_error err = {0};
    double prev = INFINITY;
    init_ok(&law, scaled(0.3, 4, 1, 1));
    for (size_t n = 16; n <= 1024; n *= 4) {
        assert_int_equal(cf_law_table_build(&law, n, &err), CF_OK);
        double worst = 0;
        for (int i = 1; i < 5000; i++) {
            double u = law.travel_mm * (double)i / 5000.0;
            double F = cf_law_force(&law, CF_LAW_TABLE, u, NULL, NULL);
            worst = fmax(worst, fabs(F - (double)reference_force(&law.p, u)) / law.F_C_N);
        }
        assert_true(worst < prev / 50); /* fourth-order: 4x the size, ~256x smaller error */
        prev = worst;
    }
    cf_law_free(&law);
}

/* ---- invariants ------------------------------------------------------------------------------ */

static void law_is_odd_increasing_and_c1_at_transition(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++) {
        cf_law law;
        init_ok(&law, scaled(rhos[a], 3, 1, 1));
        const double s = law.travel_mm;
        double prev = -INFINITY;
        for (int i = -2000; i <= 2000; i++) {
            double u = s * (double)i / 2000.5;
            double Fp = cf_law_force(&law, CF_LAW_CLOSED_NEWTON, u, NULL, NULL);
            double Fm = cf_law_force(&law, CF_LAW_CLOSED_NEWTON, -u, NULL, NULL);
            assert_true(Fp == -Fm);
            assert_true(Fp > prev);
            prev = Fp;
        }
        /* C^1 at the transition: force and stiffness agree one ulp either side */
        double kl, kr;
        double Fl = cf_law_force(&law, CF_LAW_CLOSED_NEWTON, law.u_T_mm, &kl, NULL);
        double Fr = cf_law_force(&law, CF_LAW_CLOSED_NEWTON, nextafter(law.u_T_mm, INFINITY),
                                 &kr, NULL);
        /* u is known to one ulp, and region 2 spans s - u_T: the stiffness just past u_T is
        ** defined only to ulp(s)/(s - u_T) (6e-4 for rho = 1 - 1e-12) */
        double cond = 4 * DBL_EPSILON * s / (s - law.u_T_mm);
        assert_close(Fr, Fl, 1e-12 * Fl);
        assert_close(kr, kl, (1e-9 + cond) * kl);
    }
}

static void deflection_inverts_force_to_rounding(void **state)
{
    (void)state;
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++) {
        cf_law law;
        init_ok(&law, scaled(rhos[a], 3, 1, 1));
        for (int i = 1; i < 1000; i++) {
            double u = law.travel_mm * (double)i / 1000.0;
            double F = cf_law_force(&law, CF_LAW_EXACT, u, NULL, NULL);
            double back = cf_law_deflection(&law, F);
            assert_close(back, u, 1e-12 * law.travel_mm);
            assert_close(cf_law_deflection(&law, -F), -back, 0);
        }
    }
}

static void stiffness_matches_finite_difference(void **state)
{
    (void)state;
    for (size_t a = 2; a < sizeof rhos / sizeof rhos[0]; a++) { /* rho with a real region 2 */
        cf_law law;
        cf_error err = {0};
        init_ok(&law, scaled(rhos[a], 3, 1, 1));
        assert_int_equal(cf_law_table_build(&law, 1024, &err), CF_OK);
        for (int i = 1; i < 200; i++) {
            double u = law.travel_mm * (double)i / 200.0;
            if (fabs(u - law.u_T_mm) < 1e-3 * law.travel_mm)
                continue; /* the one-sided kink of the second derivative */
            double h = 1e-6 * law.travel_mm;
            double fd = (cf_law_force(&law, CF_LAW_EXACT, u + h, NULL, NULL) -
                         cf_law_force(&law, CF_LAW_EXACT, u - h, NULL, NULL)) / (2 * h);
            for (int m = CF_LAW_EXACT; m <= CF_LAW_TABLE; m++) {
                double k;
                cf_law_force(&law, (cf_law_method)m, u, &k, NULL);
                assert_close(k, fd, 1e-5 * fd);
            }
        }
        cf_law_free(&law);
    }
}

static void cylindrical_spring_is_linear_up_to_solid(void **state)
{
    (void)state;
    cf_law law;
    init_ok(&law, spring(10, 10, 6, 1, 80000, 20));
    assert_int_equal(law.type, CF_NON_TELESCOPING);
    assert_close(law.u_T_mm, law.travel_mm, 0);
    assert_close(law.F_T_N, law.F_C_N, 0);
    for (int i = 0; i <= 100; i++) {
        double u = law.travel_mm * (double)i / 100.0;
        int flags;
        double k;
        double F = cf_law_force(&law, CF_LAW_CLOSED, u, &k, &flags);
        assert_close(F, law.k0_N_per_mm * u, 1e-14 * law.F_C_N);
        assert_true(i == 100 ? flags == CF_LAW_LINEAR || flags == CF_LAW_SOLID
                             : flags == CF_LAW_LINEAR);
    }
}

static void past_solid_reports_clamp_never_nan(void **state)
{
    (void)state;
    cf_law law;
    init_ok(&law, spring(10, 30, 4, 1, 80000, 40));
    const double us[] = {39, 40, 1e300, INFINITY, -INFINITY, NAN, -39};
    for (size_t i = 0; i < sizeof us / sizeof us[0]; i++)
        for (int m = CF_LAW_EXACT; m <= CF_LAW_TABLE; m++) {
            double k;
            int flags;
            double F = cf_law_force(&law, (cf_law_method)m, us[i], &k, &flags);
            assert_true(isfinite(F) && isfinite(k) && k >= 0);
            assert_int_equal(flags, CF_LAW_SOLID);
            if (!isnan(us[i]))
                assert_close(F, copysign(law.F_C_N, us[i]), 0);
        }
}

static void many_matches_single_evaluations(void **state)
{
    (void)state;
    cf_law law;
    cf_error err = {0};
    init_ok(&law, spring(10, 30, 4, 1, 80000, 40));
    assert_int_equal(cf_law_table_build(&law, 64, &err), CF_OK);
    double u[101], F[101], k[101];
    for (int i = 0; i <= 100; i++)
        u[i] = -45 + 0.9 * i;
    for (int m = CF_LAW_EXACT; m <= CF_LAW_TABLE; m++) {
        cf_law_force_many(&law, (cf_law_method)m, 101, u, F, k);
        for (int i = 0; i <= 100; i++) {
            double kk;
            assert_true(F[i] == cf_law_force(&law, (cf_law_method)m, u[i], &kk, NULL));
            assert_true(k[i] == kk);
        }
    }
    cf_law_free(&law);
}

/* ---- parameter checks ------------------------------------------------------------------------ */

static void invalid_parameters_are_refused_with_their_name(void **state)
{
    (void)state;
    struct {
        cf_spring p;
        const char *needle;
    } bad[] = {
        {{NAN, 30, 4, 1, 8e4, 40}, "D1_mm"},  {{10, INFINITY, 4, 1, 8e4, 40}, "D2_mm"},
        {{10, 30, 1.5, 1, 8e4, 40}, "n = 1.5"}, {{10, 30, 4, 0, 8e4, 40}, "d_mm"},
        {{10, 30, 4, 1, -1, 40}, "G_MPa"},    {{10, 30, 4, 1, 8e4, -40}, "H_mm"},
        {{31, 30, 4, 1, 8e4, 40}, "D1_mm = 31"}, {{10, 30, 4, 1, 8e4, 1}, "travel"},
        {{10, 12, 4, 1, 8e4, 4}, "travel"},   {{1e-300, 1e300, 4, 1e-300, 1e300, 1e300}, "range"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cf_law law;
        cf_error err = {0};
        assert_int_equal(cf_law_init(&law, &bad[i].p, &err), CF_E_DATA);
        if (!strstr(err.msg, bad[i].needle))
            fail_msg("case %zu: message '%s' does not name '%s'", i, err.msg, bad[i].needle);
    }
}

static void method_names_round_trip(void **state)
{
    (void)state;
    for (int m = CF_LAW_EXACT; m <= CF_LAW_TABLE; m++) {
        cf_law_method back;
        assert_int_equal(cf_law_method_parse(cf_law_method_name((cf_law_method)m), &back, NULL),
                         CF_OK);
        assert_int_equal(back, m);
    }
    cf_law_method back;
    cf_error err = {0};
    assert_int_equal(cf_law_method_parse("fast", &back, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "'fast'"));
}

/* ---- command line ---------------------------------------------------------------------------- */

#define SPRING_ARGS "--D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 40"

static void cli_force_prints_the_law_to_17_digits(void **state)
{
    (void)state;
    char out[256], errb[512];
    const char *methods[] = {"exact", "closed", "closed+newton"};
    for (int m = 0; m < 3; m++) {
        assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                                "force " SPRING_ARGS " --u 28.640625 --method %s", methods[m]),
                         0);
        assert_close(strtod(out, NULL), 12.1875, 12.1875 * 1e-14);
        assert_string_equal(errb, "");
    }
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "force " SPRING_ARGS " --u=-5"),
                     0);
    assert_string_equal(out, "-1.25\n");
}

/* The command line at the hard corners: conifit force with --method exact and closed agrees with
** the long-double reference to 1e-12 relative (u printed with %.17g, so it reaches the binary as
** the same double). */
static void cli_force_matches_reference_at_hard_cases(void **state)
{
    (void)state;
    const char *methods[] = {"exact", "closed"};
    for (size_t a = 0; a < sizeof rhos / sizeof rhos[0]; a++)
        for (size_t c = 0; c < sizeof coils / sizeof coils[0]; c += 2) {
            cf_law law;
            init_ok(&law, scaled(rhos[a], coils[c], 1, 1));
            const cf_spring *p = &law.p;
            const double s = law.travel_mm, uT = law.u_T_mm;
            const double us[] = {0.0, uT, nextafter(uT, 0), nextafter(uT, INFINITY),
                                 s * (1 - 1e-15), s, 1.5 * s, -0.5 * (uT + s)};
            for (size_t i = 0; i < sizeof us / sizeof us[0]; i++)
                for (int m = 0; m < 2; m++) {
                    char out[128], errb[256];
                    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                                            "force --D1 %.17g --D2 %.17g --n %.17g --d %.17g "
                                            "--G %.17g --H %.17g --u %.17g --method %s",
                                            p->D1_mm, p->D2_mm, p->n, p->d_mm, p->G_MPa, p->H_mm,
                                            us[i], methods[m]),
                                     0);
                    double F = strtod(out, NULL);
                    double R = (double)reference_force(p, us[i]);
                    assert_close(F, R, 1e-12 * fabs(R));
                }
        }
}

static void cli_bad_arguments_exit_2_with_a_message(void **state)
{
    (void)state;
    char out[256], errb[512];
    struct {
        const char *args, *needle;
    } cases[] = {
        {"force " SPRING_ARGS, "missing option --u"},
        {"force --D1 10 --D2 30 --n 4 --d 1 --G 80000 --u 1", "--H"},
        {"force " SPRING_ARGS " --u abc", "'abc' is not a number"},
        {"force " SPRING_ARGS " --u nan", "not a finite number"},
        {"force " SPRING_ARGS " --u 1 --method fast", "'fast'"},
        {"force " SPRING_ARGS " --u 1 --bogus", "'--bogus'"},
        {"force --D1 40 --D2 30 --n 4 --d 1 --G 80000 --H 40 --u 1", "D1_mm = 40"},
        {"force --D1 10 --D2 30 --n 1 --d 1 --G 80000 --H 40 --u 1", "n = 1"},
        {"curve " SPRING_ARGS " --points 1", "--points"},
        {"info --D1 10", "--D2"},
        {"frobnicate", "unknown command"},
        {"force " SPRING_ARGS " --u", "needs a value"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int rc = tu_run(out, sizeof out, errb, sizeof errb, "%s", cases[i].args);
        if (rc != 2 || !strstr(errb, cases[i].needle) || out[0] != '\0')
            fail_msg("'%s': exit %d, stderr '%s', stdout '%s'", cases[i].args, rc, errb, out);
        assert_null(strchr(errb, '\n') == errb + strlen(errb) - 1 ? NULL : "multi-line message");
    }
}

static void cli_curve_spans_stretch_to_solid(void **state)
{
    (void)state;
    static char out[1 << 16];
    char errb[256];
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "curve " SPRING_ARGS " --points 5"),
                     0);
    /* reference at u = 19.5 mm from a 50-digit decimal bisection on u(y):
    ** F = 5.24677016928952994 N, k = 0.414757380464917678 N/mm */
    const double F195 = 5.24677016928952994, k195 = 0.414757380464917678;
    const double rows[5][3] = {{-39, -97.5, 0}, {-19.5, -F195, k195}, {0, 0, 0.25},
                               {19.5, F195, k195}, {39, 97.5, 0}};
    assert_true(strncmp(out, "u_mm,force_N,stiffness_N_per_mm\n", 32) == 0);
    char *line = strchr(out, '\n') + 1;
    for (int r = 0; r < 5; r++) {
        double v[3];
        assert_int_equal(sscanf(line, "%lf,%lf,%lf", &v[0], &v[1], &v[2]), 3);
        for (int c = 0; c < 3; c++)
            assert_close(v[c], rows[r][c], 1e-14 * fabs(rows[r][c]));
        line = strchr(line, '\n') + 1;
    }
    assert_string_equal(line, "");
}

static void cli_info_and_help_and_version(void **state)
{
    (void)state;
    static char out[8192];
    char errb[256];
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "info " SPRING_ARGS), 0);
    assert_non_null(strstr(out, "telescoping"));
    assert_non_null(strstr(out, "97.5 N"));
    assert_non_null(strstr(out, "0.25 N/mm"));
    /* the design parameters as the spring's field table names and describes them, with units */
    for (int k = 0; k < CF_P_COUNT; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        char want[160];
        const int bare = strcmp(sp->unit, "-") == 0;
        snprintf(want, sizeof want, "\n  %-4s %.10g%s%s", sp->name,
                 (double[]){10, 30, 4, 1, 80000, 40}[k], bare ? "" : " ", bare ? "" : sp->unit);
        const char *line = strstr(out, want);
        if (!line)
            fail_msg("info: no line '%s' in:\n%s", want + 1, out);
        char text[256]; /* that line alone */
        if (sscanf(line + 1, "%255[^\n]", text) != 1 || !strstr(text, sp->meaning))
            fail_msg("info: the line of %s does not say '%s'", sp->name, sp->meaning);
    }
    const char *cmds[] = {"force", "curve", "info"};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "%s --help", cmds[i]), 0);
        assert_non_null(strstr(out, "usage: conifit"));
        assert_non_null(strstr(out, "--D1 MM"));
    }
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "--version"), 0);
    assert_non_null(strstr(out, "conifit "));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, ""), 2);
}

/* The lanes' square roots without a square-root instruction (law_simd.h): 1/sqrt(x) and
** x / sqrt(x) within 4e-16 of the long-double values over the normal range, and 0 maps to a
** finite value whose product with 0 is 0. */
static void lane_rsqrt_is_accurate_over_the_normal_range(void **state)
{
    (void)state;
    double worst = 0;
    for (int k = -30000; k <= 30000; k++) {
        const double x = exp(0.0235 * k) * (1.0 + 1e-3 * (k % 7)); /* 1e-306 to 1e306 */
        const double r = cf_lane_rsqrt(x);
        const long double ref = 1.0L / sqrtl((long double)x);
        worst = fmax(worst, (double)fabsl((r - ref) / ref));
        worst = fmax(worst, (double)fabsl((x * r - (long double)x * ref) / ((long double)x * ref)));
    }
    assert_true(worst < 4e-16);
    const double r0 = cf_lane_rsqrt(0.0);
    assert_true(isfinite(r0));
    assert_true(0.0 * r0 == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(telescoping_spring_matches_hand_values),
        cmocka_unit_test(non_telescoping_spring_matches_hand_values),
        cmocka_unit_test(closed_and_exact_match_reference_in_every_corner),
        cmocka_unit_test(polynomial_form_matches_reference_where_it_fits),
        cmocka_unit_test(table_error_is_within_its_stated_bound),
        cmocka_unit_test(table_error_falls_with_table_size),
        cmocka_unit_test(law_is_odd_increasing_and_c1_at_transition),
        cmocka_unit_test(deflection_inverts_force_to_rounding),
        cmocka_unit_test(stiffness_matches_finite_difference),
        cmocka_unit_test(cylindrical_spring_is_linear_up_to_solid),
        cmocka_unit_test(past_solid_reports_clamp_never_nan),
        cmocka_unit_test(many_matches_single_evaluations),
        cmocka_unit_test(invalid_parameters_are_refused_with_their_name),
        cmocka_unit_test(method_names_round_trip),
        cmocka_unit_test(cli_force_prints_the_law_to_17_digits),
        cmocka_unit_test(cli_force_matches_reference_at_hard_cases),
        cmocka_unit_test(lane_rsqrt_is_accurate_over_the_normal_range),
        cmocka_unit_test(cli_bad_arguments_exit_2_with_a_message),
        cmocka_unit_test(cli_curve_spans_stretch_to_solid),
        cmocka_unit_test(cli_info_and_help_and_version),
    };
    return cmocka_run_group_tests_name("law", tests, NULL, NULL);
}
