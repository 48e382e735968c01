/*
** Tests of the identifiable family (src/model/family.c): the named and indexed views of cf_ident
** agree; a member built from a family belongs to it; the force-displacement scales are the
** stress-strain ones times H and H^2 and the law's own travel and solid load; the wire modulus
** of a solid load inverts the family's load scale; the family's reduced curve is the member's
** law, and its vectorised evaluation (with the derivatives the fits' Jacobians use) is the scalar
** one, as the six-parameter model over many points is; the design limits in the family's space
** at points worked out by hand.
*/
/* conifit: vector-level: the family's lanes, cf_ident_canon_many */
#include "testutil.h"

#include "model/family.h"
#include "fit/fit.h"
#include "model/law_internal.h"

static void named_and_indexed_views_agree(void **state)
{
    (void)state;
    cf_ident q = {.rho = 0.25, .solid = 0.4, .scale = 0.03};
    assert_true(sizeof q == CF_IDENT_COUNT * sizeof(double));
    assert_close(q.v[CF_IDENT_RHO], 0.25, 0);
    assert_close(q.v[CF_IDENT_SOLID], 0.4, 0);
    assert_close(q.v[CF_IDENT_SCALE], 0.03, 0);
    q.v[CF_IDENT_SCALE] = 2;
    assert_close(q.scale, 2, 0);
}

static void a_member_belongs_to_its_family(void **state)
{
    (void)state;
    const double rhos[] = {0.001, 0.05, 0.3, 0.7, 0.999}, es[] = {0.05, 0.5, 0.95};
    for (size_t i = 0; i < sizeof rhos / sizeof rhos[0]; i++)
        for (size_t j = 0; j < sizeof es / sizeof es[0]; j++) {
            const cf_ident q = {.rho = rhos[i], .solid = es[j], .scale = 0.0123};
            cf_spring p = cf_ident_member(&q);
            assert_close(p.H_mm, 1.0, 0);
            cf_law law;
            assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
            assert_int_equal(law.type, CF_NON_TELESCOPING);
            cf_law_free(&law);
            const cf_ident got = cf_ident_of(&p, 0);
            for (int k = 0; k < CF_IDENT_COUNT; k++)
                assert_close(got.v[k], q.v[k], 1e-12 * q.v[k]);
        }
}

static void force_scales_are_the_stress_scales_times_H(void **state)
{
    (void)state;
    const cf_spring springs[] = {{10, 30, 4, 1, 80000, 40}, {6, 15, 2.5, 2, 26, 10}};
    for (size_t i = 0; i < sizeof springs / sizeof springs[0]; i++) {
        const cf_spring *p = &springs[i];
        cf_law law;
        assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
        const cf_ident ss = cf_ident_of(p, 0), fd = cf_ident_of(p, 1);
        const double H = p->H_mm;
        assert_close(fd.rho, ss.rho, 0);
        assert_close(fd.rho, p->D1_mm / p->D2_mm, 0);
        assert_close(fd.solid, ss.solid * H, 1e-12 * fd.solid);
        assert_close(fd.scale, ss.scale * H * H, 1e-12 * fd.scale);
        assert_close(fd.solid, law.travel_mm, 1e-12 * fd.solid);
        assert_close(fd.scale, law.F_C_N, 1e-12 * fd.scale);
        /* the wire modulus of that solid load is the spring's own */
        const cf_ident t = cf_ident_of_type(p, law.type, 1);
        assert_close(cf_ident_G_of_FC(t.scale, p->n, p->D1_mm, p->d_mm, t.solid), p->G_MPa,
                     1e-12 * p->G_MPa);
        cf_law_free(&law);
    }
}

static void the_reduced_curve_is_the_member_law(void **state)
{
    (void)state;
    const cf_ident q = {.rho = 0.2, .solid = 0.6, .scale = 0.05};
    cf_spring p = cf_ident_member(&q);
    cf_law law, canon;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    assert_int_equal(cf_ident_canon_law(q.rho, &canon), CF_OK);
    for (int i = -10; i <= 10; i++) {
        const double x = 0.059 * i; /* past solid on both sides at the ends */
        const double F = cf_law_force(&law, CF_LAW_CLOSED, x * p.H_mm, NULL, NULL) /
                         (p.H_mm * p.H_mm);
        double dB;
        const double r = cf_ident_reduced(&canon, q.scale, q.solid, x, &dB);
        assert_close(r, F, 1e-12 * q.scale);
        /* d/dB against a central difference */
        const double h = 1e-6;
        const double num = (cf_ident_reduced(&canon, q.scale, q.solid + h, x, NULL) -
                            cf_ident_reduced(&canon, q.scale, q.solid - h, x, NULL)) /
                           (2 * h);
        if (fabs(x) < 0.95 * q.solid)
            assert_close(dB, num, 1e-5 * q.scale / q.solid);
    }
    cf_law_free(&law);
    cf_law_free(&canon);
}

/* The vectorised canonical law (cf_ident_canon_many, the fits' hot path) against the scalar
** closed form point by point, and its derivatives in t and rho against central differences of
** that scalar law: every region, both signs, points a hair from solid and from the transition,
** and a NaN. */
static void the_vectorised_canonical_law_is_the_scalar_one(void **state)
{
    (void)state;
    const double rhos[] = {0.06, 0.2, 0.45, 0.8, 0.97};
    enum { N = 403 };
    double x[N], g[N], gt[N], gr[N], g0[N];
    for (size_t r = 0; r < sizeof rhos / sizeof rhos[0]; r++) {
        const double rho = rhos[r], B = 0.7;
        cf_law canon;
        assert_int_equal(cf_ident_canon_law(rho, &canon), CF_OK);
        for (int i = 0; i < N - 3; i++)
            x[i] = B * (-1.1 + 2.2 * i / (N - 4.0));
        x[N - 3] = B * (1 - 1e-9);   /* next to solid */
        x[N - 2] = B * canon.u_T_mm * (1 + 1e-9); /* just past the transition */
        x[N - 1] = NAN;
        cf_ident_canon_many(&canon, B, N, x, g0, NULL, NULL);
        cf_ident_canon_many(&canon, B, N, x, g, gt, gr);
        for (int i = 0; i < N; i++) {
            if (isnan(x[i])) {
                assert_true(g[i] == 0 && gt[i] == 0 && gr[i] == 0 && g0[i] == 0);
                continue;
            }
            const double t = x[i] / B;
            const double ref = cf_law_force(&canon, CF_LAW_CLOSED, t, NULL, NULL);
            assert_close(g[i], ref, 1e-14);
            assert_close(g0[i], ref, 1e-14);
            double k;
            cf_law_force(&canon, CF_LAW_CLOSED, t, &k, NULL);
            assert_close(gt[i], k, 1e-9 * fmax(1.0, k));
            const double a = fabs(t);
            if (a >= 1 || fabs(a - canon.u_T_mm) < 1e-3 || 1 - a < 1e-3)
                continue; /* central differences straddle a region boundary */
            const double h = 1e-6;
            cf_law lp, lm;
            assert_int_equal(cf_ident_canon_law(rho + h, &lp), CF_OK);
            assert_int_equal(cf_ident_canon_law(rho - h, &lm), CF_OK);
            const double num = (cf_law_force(&lp, CF_LAW_CLOSED, t, NULL, NULL) -
                                cf_law_force(&lm, CF_LAW_CLOSED, t, NULL, NULL)) /
                               (2 * h);
            assert_close(gr[i], num, 1e-6 * fmax(1.0, fabs(num)));
            cf_law_free(&lp);
            cf_law_free(&lm);
        }
        /* every count, whole vectors or not (the last few points run in a padded block): each
        ** point as in the long call, the points after the count untouched */
        for (size_t count = 1; count <= 19; count++) {
            double h[24], ht[24], hr[24];
            for (int i = 0; i < 24; i++)
                h[i] = ht[i] = hr[i] = -7.0;
            const size_t at = N - count; /* the last points: by solid, the transition, NaN */
            cf_ident_canon_many(&canon, B, count, x + at, h, ht, hr);
            for (size_t i = 0; i < count; i++) {
                assert_close(h[i], g[at + i], 1e-15);
                assert_close(ht[i], gt[at + i], 1e-15 * fmax(1.0, fabs(gt[at + i])));
                assert_close(hr[i], gr[at + i], 1e-15 * fmax(1.0, fabs(gr[at + i])));
            }
            for (size_t i = count; i < 24; i++)
                assert_true(h[i] == -7.0 && ht[i] == -7.0 && hr[i] == -7.0);
            cf_ident_canon_many(&canon, B, count, x + at, h, NULL, NULL);
            for (size_t i = 0; i < count; i++)
                assert_close(h[i], g0[at + i], 1e-15);
        }
        cf_law_free(&canon);
    }
}

/* The six-parameter model over many points (the fits' objective) is the scalar one. */
/* The canonical law's lanes from rho alone are those of the built law, bit for bit: every rho of
** a log grid from 1e-3 to 1 and its neighbours one ulp away, values and derivatives; rho outside
** (0, 1] or NaN is refused with nothing written. */
static void the_canonical_lanes_of_rho_are_those_of_the_law(void **state)
{
    (void)state;
    enum { N = 37 };
    double x[N], g[N], gt[N], gr[N], h[N], ht[N], hr[N];
    for (int i = 0; i < N; i++)
        x[i] = -1.2 + 2.4 * i / (N - 1.0);
    for (int k = 0; k <= 60; k++) {
        const double r0 = pow(10.0, -3.0 + 3.0 * k / 60.0);
        const double rhos[3] = {nextafter(r0, 0), r0, fmin(nextafter(r0, 2), 1.0)};
        for (int j = 0; j < 3; j++) {
            const double B = 0.37 + 0.5 * j;
            cf_law canon;
            assert_int_equal(cf_ident_canon_law(rhos[j], &canon), CF_OK);
            assert_true(cf_ident_canon_transition(rhos[j]) == canon.u_T_mm);
            cf_ident_canon_many(&canon, B, N, x, g, gt, gr);
            assert_int_equal(cf_ident_canon_many_rho(rhos[j], B, N, x, h, ht, hr), CF_OK);
            assert_memory_equal(g, h, sizeof g);
            assert_memory_equal(gt, ht, sizeof gt);
            assert_memory_equal(gr, hr, sizeof gr);
            cf_ident_canon_many(&canon, B, N, x, g, NULL, NULL);
            assert_int_equal(cf_ident_canon_many_rho(rhos[j], B, N, x, h, NULL, NULL), CF_OK);
            assert_memory_equal(g, h, sizeof g);
            cf_law_free(&canon);
        }
    }
    const double bad[] = {0.0, -0.5, nextafter(1.0, 2.0), 2.0, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        h[0] = -7.0;
        assert_int_equal(cf_ident_canon_many_rho(bad[k], 0.5, N, x, h, NULL, NULL), CF_E_DATA);
        assert_true(h[0] == -7.0);
    }
}

static void the_vectorised_model_is_the_scalar_one(void **state)
{
    (void)state;
    const cf_spring springs[2] = {{8, 20, 2.5, 2, 100, 5}, {3, 9, 6, 0.8, 8e4, 30}};
    enum { N = 257 };
    double x[N], y[N];
    for (int s = 0; s < 2; s++) {
        cf_law law;
        assert_int_equal(cf_law_init(&law, &springs[s], NULL), CF_OK);
        for (int fd = 0; fd < 2; fd++) {
            const double xmax = fd ? law.travel_mm : law.travel_mm / springs[s].H_mm;
            for (int i = 0; i < N; i++)
                x[i] = xmax * (-1.05 + 2.1 * i / (N - 1.0));
            cf_fit_model_many(&law, fd, N, x, y);
            for (int i = 0; i < N; i++) {
                const double ref = cf_fit_model(&law, fd, x[i]);
                assert_close(y[i], ref, 1e-13 * fmax(fabs(ref), 1e-300) + 1e-300);
            }
        }
        cf_law_free(&law);
    }
}

static void the_design_limits_at_points_worked_by_hand(void **state)
{
    (void)state;
    assert_close(cf_ident_rho_hi(CF_NON_TELESCOPING, 12), 1.0, 0);
    assert_close(cf_ident_rho_hi(CF_TELESCOPING, 12), 0.75 * (1 - 1e-6), 1e-15);
    const cf_ident_design d = {2, 30, 80000, 10, 12, 0.01};
    /* non-telescoping at rho 0.5, s/H 0.5: n_lo = max(2, 1.5, 0.3) = 2, within n <= 30 (and
    ** rho well above rho_min: the margin is the largest of the limits' margins) */
    cf_ident_region r = cf_ident_region_at(&d, CF_NON_TELESCOPING, 0.5, 0.5, 0);
    assert_close(r.margin, log(2.0) - log(30.0), 1e-15);
    assert_close(r.A_max, 80000 * 0.25 / (8 * 27 * 4.0), 1e-12);
    assert_int_equal(r.lo_bit, CF_C_COILS);
    assert_int_equal(r.hi_bit, CF_C_COILS_MAX);
    /* telescoping at rho 0.1, s/H 0.5: c_lo = max(3, 4/9) = 3, c_hi = min(12, 2) = 2: outside */
    r = cf_ident_region_at(&d, CF_TELESCOPING, 0.1, 0.5, 0);
    assert_close(r.margin, log(3.0) - log(2.0), 1e-15);
    assert_int_equal(r.lo_bit, CF_C_INDEX_MIN);
    assert_int_equal(r.hi_bit, CF_C_D2_H);
    /* below rho_min (here 0.6), the diameter ratio is the limit; outside (0, 1), no family */
    const cf_ident_design d6 = {2, 30, 80000, 10, 12, 0.6};
    r = cf_ident_region_at(&d6, CF_NON_TELESCOPING, 0.5, 0.5, 0);
    assert_close(r.margin, log(0.6 * (1 - CF_IDENT_RHO_MIN_TOL)) - log(0.5), 1e-15);
    assert_int_equal(r.lo_bit, CF_C_RHO_MIN);
    assert_int_equal(r.hi_bit, 0);
    assert_close(cf_ident_region_at(&d, CF_NON_TELESCOPING, 1.0, 0.5, 0).margin, 50, 0);
    assert_close(cf_ident_region_at(&d, CF_TELESCOPING, 0.5, 0.0, 0).margin, 50, 0);
    /* `inside` keeps that fraction of the scale in reserve */
    const double A0 = cf_ident_region_at(&d, CF_NON_TELESCOPING, 0.5, 0.5, 0).A_max;
    assert_close(cf_ident_region_at(&d, CF_NON_TELESCOPING, 0.5, 0.5, 1e-4).A_max,
                 A0 * (1 - 1e-4), 1e-15 * A0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(named_and_indexed_views_agree),
        cmocka_unit_test(a_member_belongs_to_its_family),
        cmocka_unit_test(force_scales_are_the_stress_scales_times_H),
        cmocka_unit_test(the_reduced_curve_is_the_member_law),
        cmocka_unit_test(the_vectorised_canonical_law_is_the_scalar_one),
        cmocka_unit_test(the_canonical_lanes_of_rho_are_those_of_the_law),
        cmocka_unit_test(the_vectorised_model_is_the_scalar_one),
        cmocka_unit_test(the_design_limits_at_points_worked_by_hand),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
