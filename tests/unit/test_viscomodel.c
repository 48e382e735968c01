/*
** The time-dependent model (viscomodel.h): Prony branches in the lattice (exact relaxation during
** a hold, no effect when switched off, constraints), the model along a measured history (one
** cell = 27 cells under uniaxial loading), relaxation growing with strain, and inertia.
*/
#include "testutil.h"

#include "model/cell.h"
#include "model/msm.h"
#include "model/viscomodel.h"
#include "viscoutil.h"

/* During a hold the law force is constant, so every branch decays exactly as exp(-t/tau): in a
** lattice of axial springs alone sigma(t) - g_inf sigma_e = (sigma(t_r) - g_inf sigma_e)
** exp(-(t - t_r)/tau), to rounding. */
static void test_hold_relaxes_exactly(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.nbranch = 1;
    cf_visco_setup s = cf_visco_default();
    s.cfg.lattice.weight[CF_FAMILY_EDGE] = 1; /* axial springs alone: the lattice is one spring */
    s.cfg.lattice.weight[CF_FAMILY_FACE] = s.cfg.lattice.weight[CF_FAMILY_BODY] = 0;
    double pt[3] = {0, 10, 100}, pv[3] = {0, 0.2, 0.2};
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 3, pt, pv};
    double ts[5] = {0, 10, 20, 40, 100};
    cf_msm_sample out[5];
    cf_error err = {0};
    assert_int_equal(cf_visco_run(&p, &s, &path, ts, 5, out, &err), CF_OK);
    cf_spring sp = cf_ident_member(&p.ident);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    double se = cf_law_force(&law, CF_LAW_EXACT, 0.2 * sp.H_mm, NULL, NULL) / (sp.H_mm * sp.H_mm);
    double eq = (1 - p.g[0]) * se;
    double d0 = out[1].stress_MPa - eq;
    assert_true(d0 > 0.01 * se); /* the ramp left the branch loaded */
    for (int k = 2; k < 5; k++)
        assert_close((out[k].stress_MPa - eq) / d0, exp(-(ts[k] - 10) / p.tau_s[0]), 1e-9);
    assert_close(out[0].stress_MPa, 0, 1e-15);
}

/* Prony terms with g = 0 change nothing: the run is the static curve. */
static void test_zero_branches_are_elastic(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.g[0] = p.g[1] = 0;
    cf_visco_setup s = cf_visco_default();
    double t[NS], x[NS], y[NS], ys[NS];
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(&p, &s, &ser, y, NULL, &err), CF_OK);
    cf_spring sp = cf_ident_member(&p.ident);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    assert_int_equal(cf_msm_uniaxial(&law, s.method, &s.cfg, x, NS, ys, NULL, &err), CF_OK);
    for (int k = 0; k < NS; k++)
        assert_close(y[k], ys[k], 1e-10 * fabs(ys[NS - 1]));
}

static void test_prony_constraints(void **state)
{
    (void)state;
    cf_msm_effects fx;
    memset(&fx, 0, sizeof fx);
    cf_error err = {0};
    fx.prony_count = 2;
    fx.prony_g[0] = 0.6;
    fx.prony_g[1] = 0.4;
    fx.prony_tau_s[0] = fx.prony_tau_s[1] = 1;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "below 1"));
    fx.prony_g[1] = -0.1;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    fx.prony_g[1] = 0.1;
    fx.prony_tau_s[1] = 0;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    fx.prony_tau_s[1] = 2;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_OK);
    fx.prony_k[1] = NAN; /* a change with strain must be finite (either sign) */
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "g_per_strain"));
    fx.prony_k[1] = -0.3;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_OK);
    fx.prony_count = CF_PRONY_MAX + 1;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
}

/* Uniaxial loading with free sides deforms the lattice homogeneously, so the homogenised cell
** gives the stress of a 27-cell lattice along the whole history, dashpot included. */
/* The model in the cell against the 27-cell lattice, along the ramp and hold (stresses in y3) and
** under a held half of the ramp's peak stress (creep), to 1e-8. */
static void assert_cell_is_block(const cf_visco_params *p, double *y3)
{
    cf_visco_setup s1 = cf_visco_default(), s3 = s1;
    assert_int_equal(s1.cell, 1);
    s3.cell = 0;
    s3.cfg.lattice.nx = s3.cfg.lattice.ny = s3.cfg.lattice.nz = 3;
    double t[NS], x[NS], y1[NS];
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(p, &s1, &ser, y1, NULL, &err), CF_OK);
    assert_int_equal(cf_visco_curve(p, &s3, &ser, y3, NULL, &err), CF_OK);
    for (int k = 0; k < NS; k++)
        assert_close(y1[k], y3[k], 1e-8 * fabs(y3[15]));
    double pt[3] = {0, 30, 330}, pv[3] = {0, 0.5 * fabs(y3[15]), 0.5 * fabs(y3[15])};
    cf_msm_path path = {CF_DRIVE_FORCE, 3, pt, pv};
    double ts[4] = {0, 30, 100, 330};
    cf_msm_sample o1[4], o3[4];
    assert_int_equal(cf_visco_run(p, &s1, &path, ts, 4, o1, &err), CF_OK);
    assert_int_equal(cf_visco_run(p, &s3, &path, ts, 4, o3, &err), CF_OK);
    assert_true(o3[3].strain > o3[1].strain * 1.05); /* it creeps */
    for (int k = 0; k < 4; k++)
        assert_close(o1[k].strain, o3[k].strain, 1e-8 * o3[3].strain);
}

static void test_cell_is_the_block(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.eta_MPa_s = 1e-3;
    double y3[NS];
    assert_cell_is_block(&p, y3);
}

/* A series that starts strained starts relaxed, in the cell as in the lattice (the cell once gave
** the elastic stress at the first sample: 2.2 times the lattice's for these terms). */
static void test_strained_start_is_relaxed(void **state)
{
    (void)state;
    double t[6] = {0, 1, 2, 3, 10, 30}, x[6] = {-0.1, -0.1, -0.15, -0.2, -0.2, -0.2};
    double y1[6], y2[6], ye[1];
    for (int strain = 0; strain < 2; strain++) {
        cf_visco_params p = known();
        p.k[0] = strain ? -0.5 : 0.0;
        cf_visco_setup s1 = cf_visco_default(), s2 = s1;
        s2.cell = 0;
        s2.cfg.lattice.nx = s2.cfg.lattice.ny = s2.cfg.lattice.nz = 2;
        cf_visco_series ser = {6, t, x};
        cf_error err = {0};
        assert_int_equal(cf_visco_curve(&p, &s1, &ser, y1, NULL, &err), CF_OK);
        assert_int_equal(cf_visco_curve(&p, &s2, &ser, y2, NULL, &err), CF_OK);
        for (int k = 0; k < 6; k++)
            assert_close(y1[k], y2[k], 1e-8 * fabs(y2[5]));
        /* quasi-linear: relaxed is g_inf times the elastic stress (every spring scaled alike) */
        assert_int_equal(cf_visco_elastic_curve(&p, &s1, x, 1, ye, &err), CF_OK);
        if (!strain)
            assert_close(y1[0], (1 - p.g[0] - p.g[1]) * ye[0], 1e-9 * fabs(ye[0]));
    }
}

/* Relaxation depending on strain (g_i + k_i |e|): the cell is still the 27-cell block, in a ramp
** and hold and under a held stress, and the moduli really change the curve. */
static void test_strain_relaxation_cell_is_the_block(void **state)
{
    (void)state;
    cf_visco_params p = known(), q = known();
    p.k[0] = -0.8; /* the fast term relaxes less at larger strain */
    p.k[1] = 0.5;
    double y[NS], yq[NS], t[NS], x[NS];
    assert_cell_is_block(&p, y);
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_visco_setup s3 = cf_visco_default();
    s3.cell = 0;
    s3.cfg.lattice.nx = s3.cfg.lattice.ny = s3.cfg.lattice.nz = 3;
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(&q, &s3, &ser, yq, NULL, &err), CF_OK);
    assert_true(fabs(yq[NS - 1] - y[NS - 1]) > 0.05 * fabs(yq[NS - 1])); /* they matter */
    /* moduli that would pass 1 in sum (or fall below 0) where the run goes: refused, named, in the
    ** lattice and in the cell */
    for (int cell = 0; cell < 2; cell++) {
        s3.cell = cell;
        p.k[1] = 3.0; /* 0.35 - 0.8 e + 0.2 + 3 e > 1 past e = 0.2 */
        assert_int_equal(cf_visco_curve(&p, &s3, &ser, y, NULL, &err), CF_E_DATA);
        assert_non_null(strstr(err.msg, "sum"));
        p.k[1] = 0.5;
        p.k[0] = -2.0; /* 0.35 - 2 e < 0 past e = 0.175 */
        assert_int_equal(cf_visco_curve(&p, &s3, &ser, y, NULL, &err), CF_E_DATA);
        assert_non_null(strstr(err.msg, "Prony term 1"));
        p.k[0] = -0.8;
    }
}

/* Each step's lateral solve in the cell starts from the stretch carried on along the step before;
** where the sampling jumps from 0.01 s to 5 s intervals and back, and the strain rate turns,
** that start lands far from the answer, and the answer is still the 27-cell block's (quasi-linear
** and changing with strain). */
static void test_uneven_steps_cell_is_the_block(void **state)
{
    (void)state;
    enum { M = 10 };
    double t[M] = {0, 0.01, 0.02, 5, 5.001, 60, 60.5, 61, 61.01, 200};
    double x[M] = {0, -0.001, -0.002, -0.25, -0.25, -0.25, -0.1, -0.12, -0.1201, -0.1201};
    cf_visco_series ser = {M, t, x};
    cf_visco_setup s1 = cf_visco_default(), s3 = s1;
    s3.cell = 0;
    s3.cfg.lattice.nx = s3.cfg.lattice.ny = s3.cfg.lattice.nz = 3;
    for (int strain = 0; strain < 2; strain++) {
        cf_visco_params p = known();
        p.k[0] = strain ? -0.8 : 0.0;
        p.eta_MPa_s = 1e-3;
        double y1[M], y3[M];
        cf_error err = {0};
        assert_int_equal(cf_visco_curve(&p, &s1, &ser, y1, NULL, &err), CF_OK);
        assert_int_equal(cf_visco_curve(&p, &s3, &ser, y3, NULL, &err), CF_OK);
        assert_true(fabs(y3[5]) < 0.9 * fabs(y3[3])); /* it relaxed in the hold */
        for (int k = 0; k < M; k++)
            assert_close(y1[k], y3[k], 1e-8 * fabs(y3[3]));
    }
}

/* The stability of a homogeneous state, from one factorisation at the cell's lateral stretch,
** agrees with the scan of the static lattice (cf_msm_stability_limit) on both sides of its
** limit. */
static void test_homogeneous_inertia(void **state)
{
    (void)state;
    const cf_ident q = {.rho = 0.05, .solid = 0.4608, .scale = 1.0};
    cf_spring sp = cf_ident_member(&q);
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    for (int cells = 1; cells <= 2; cells++) {
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = cells;
        double lim;
        assert_int_equal(cf_msm_stability_limit(&law, CF_LAW_CLOSED, &cfg, -1, &lim, &err), CF_OK);
        assert_true(lim < -0.2 && lim > -0.3);
        cf_cell c;
        assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, cfg.lattice.weight, &err), CF_OK);
        for (int side = 0; side < 2; side++) {
            double e = lim * (side ? 1.001 : 0.999);
            cf_cell_state s;
            long neg = -1;
            assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, e, NULL, &s, &err), CF_OK);
            cf_status st = cf_msm_homogeneous_inertia(&law, CF_LAW_CLOSED, &cfg, e,
                                                      s.free_stretch, &neg, &err);
            if (side == 0) {
                assert_int_equal(st, CF_OK);
                assert_int_equal(neg, 0);
            } else {
                assert_true(st != CF_OK || neg > 0);
            }
        }
        /* a clamped bottom is never homogeneous: refused */
        cfg.lattice.bottom = CF_BOTTOM_CLAMPED;
        long neg;
        assert_int_equal(cf_msm_homogeneous_inertia(&law, CF_LAW_CLOSED, &cfg, -0.1, 1.02, &neg,
                                                    &err),
                         CF_E_DATA);
    }
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hold_relaxes_exactly),
        cmocka_unit_test(test_zero_branches_are_elastic),
        cmocka_unit_test(test_prony_constraints),
        cmocka_unit_test(test_cell_is_the_block),
        cmocka_unit_test(test_strained_start_is_relaxed),
        cmocka_unit_test(test_strain_relaxation_cell_is_the_block),
        cmocka_unit_test(test_uneven_steps_cell_is_the_block),
        cmocka_unit_test(test_homogeneous_inertia),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
