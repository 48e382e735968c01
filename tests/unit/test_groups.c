/*
** Tests of spring groups (a law per family of the lattice: cf_lattice_config.group_law, and the
** homogenised cell's family_law): the cell equals the full lattice in uniaxial tension and
** compression with two groups of different laws to 1e-9; a group given the lattice's own law
** (another copy) changes nothing; the explicit step's lanes per group (and its scalar path with a
** tailed group) agree with the kernel; a group law of another free length is refused.
*/
#include "testutil.h"

#include "model/cell.h"
#include "model/lattice.h"
#include "model/lattice_step.h"
#include "model/msm.h"
#include "model/mode.h"

/* The edges' spring (solid strain 0.5, H = 10 mm) and the diagonals' (another cone and wire, the
** same free length, about three times stiffer at rest). */
static cf_law law_of(int which)
{
    cf_spring a = {6, 15, 2.5, 2, 26, 10};
    cf_spring b = {5, 18, 3, 1.8, 200, 10};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, which ? &b : &a, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

static void cell_equals_the_full_lattice_with_two_groups(void **state)
{
    (void)state;
    cf_law edge = law_of(0), diag = law_of(1);
    const double sH = fmin(edge.travel_mm, diag.travel_mm) / edge.p.H_mm;
    double e[] = {-0.5 * sH, -0.3 * sH, -0.1 * sH, -0.01 * sH, 0.01 * sH, 0.2 * sH, 0.5 * sH,
                  0.8 * sH};
    const size_t n = sizeof e / sizeof e[0];
    const int sizes[3][3] = {{1, 1, 1}, {2, 3, 2}, {3, 3, 3}};
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &edge, CF_LAW_CLOSED, w, NULL), CF_OK);
    c.family_law[CF_FAMILY_FACE] = c.family_law[CF_FAMILY_BODY] = &diag;
    double cell[8], one[8];
    cf_error err = {0};
    if (cf_cell_curve(&c, CF_MODE_UNIAXIAL, e, n, cell, &err) != CF_OK)
        fail_msg("cell: %s", err.msg);
    cf_cell c1;
    assert_int_equal(cf_cell_init(&c1, &edge, CF_LAW_CLOSED, w, NULL), CF_OK);
    assert_int_equal(cf_cell_curve(&c1, CF_MODE_UNIAXIAL, e, n, one, NULL), CF_OK);
    for (int z = 0; z < 3; z++) {
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = sizes[z][0];
        cfg.lattice.ny = sizes[z][1];
        cfg.lattice.nz = sizes[z][2];
        memcpy(cfg.lattice.weight, w, sizeof w);
        cfg.lattice.group_law[CF_FAMILY_FACE] = cfg.lattice.group_law[CF_FAMILY_BODY] = &diag;
        double full[8];
        if (cf_msm_uniaxial(&edge, CF_LAW_CLOSED, &cfg, e, n, full, NULL, &err) != CF_OK)
            fail_msg("lattice %dx%dx%d: %s", sizes[z][0], sizes[z][1], sizes[z][2], err.msg);
        for (size_t i = 0; i < n; i++) {
            if (!(fabs(cell[i] - full[i]) <= 1e-9 * fabs(full[i])))
                fail_msg("%dx%dx%d cells, strain %g: cell %.17g, lattice %.17g", sizes[z][0],
                         sizes[z][1], sizes[z][2], e[i], cell[i], full[i]);
            /* the groups show: the diagonals' stiffer law carries more than the edges' */
            if (!(fabs(full[i]) > 1.3 * fabs(one[i])))
                fail_msg("strain %g: two groups %.6g MPa, one law %.6g MPa", e[i], full[i],
                         one[i]);
        }
    }
    cf_law_free(&edge);
    cf_law_free(&diag);
}

/* Every group given a copy of the lattice's law: the kernel's grouped path gives the one law's
** forces and stiffnesses (the same evaluations, gathered). */
static void groups_of_the_same_law_change_nothing(void **state)
{
    (void)state;
    cf_law law = law_of(0), copy = law_of(0);
    cf_lattice_config cfg = cf_lattice_default();
    cf_lattice a, b;
    assert_int_equal(cf_lattice_create(&a, &law, CF_LAW_CLOSED, &cfg, NULL), CF_OK);
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        cfg.group_law[f] = &copy;
    assert_int_equal(cf_lattice_create(&b, &law, CF_LAW_CLOSED, &cfg, NULL), CF_OK);
    assert_int_equal(a.grouped, 0);
    assert_int_equal(b.grouped, 1);
    for (size_t p = 0; p < a.nn; p++) { /* a deformation every spring feels */
        const double d = 0.02 * sin(1.0 + 0.7 * (double)p);
        a.x[p] = b.x[p] = a.X[p] * (1 + d);
        a.y[p] = b.y[p] = a.Y[p] * (1 - 0.5 * d);
        a.z[p] = b.z[p] = a.Z[p] * (1 - d);
    }
    const double ra = cf_lattice_forces(&a), rb = cf_lattice_forces(&b);
    assert_close(ra, rb, 1e-15 * ra);
    for (size_t s = 0; s < a.ns; s++) {
        assert_close(a.F_N[s], b.F_N[s], 1e-14 * fabs(a.F_N[s]) + 1e-300);
        assert_close(a.k_N_per_mm[s], b.k_N_per_mm[s], 1e-14 * fabs(a.k_N_per_mm[s]));
    }
    for (size_t p = 0; p < a.nn; p++)
        assert_close(a.fz[p], b.fz[p], 1e-12 * law.F_C_N);
    assert_close(cf_lattice_elastic_energy(&a), cf_lattice_elastic_energy(&b),
                 1e-12 * cf_lattice_elastic_energy(&a));
    cf_lattice_free(&a);
    cf_lattice_free(&b);
    cf_law_free(&law);
    cf_law_free(&copy);
}

/* The explicit step's stencil with a law per group (the scalar law of each direction's group)
** gives the force kernel's node forces. */
static void explicit_step_takes_each_groups_law(void **state)
{
    (void)state;
    cf_law edge = law_of(0), diag = law_of(1);
    cf_lattice_config cfg = cf_lattice_default();
    cfg.nx = 3, cfg.ny = 2, cfg.nz = 4;
    cfg.group_law[CF_FAMILY_BODY] = &diag;
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, &edge, CF_LAW_CLOSED, &cfg, NULL), CF_OK);
    for (size_t p = 0; p < lat.nn; p++) {
        const double d = 0.03 * cos(0.3 + 1.3 * (double)p);
        lat.x[p] = lat.X[p] + d;
        lat.y[p] = lat.Y[p] - 0.5 * d;
        lat.z[p] = lat.Z[p] * (1 - 0.05) + d;
    }
    cf_lattice_forces(&lat);
    double *fz = malloc(lat.nn * sizeof *fz);
    assert_non_null(fz);
    memcpy(fz, lat.fz, lat.nn * sizeof *fz);
    cf_lattice_stepper st;
    assert_int_equal(cf_lattice_stepper_init(&st, &lat, NULL, NULL), CF_OK);
    /* both plain cones: each group its own polynomial lanes (within CF_POLY_TOL of the closed
    ** form the kernel evaluates) */
    assert_int_equal(st.form, CF_LANE_POLY);
    assert_true(st.poly_error <= CF_POLY_TOL);
    memset(lat.fx, 0, lat.nn * sizeof *lat.fx);
    memset(lat.fy, 0, lat.nn * sizeof *lat.fy);
    memset(lat.fz, 0, lat.nn * sizeof *lat.fz);
    cf_lattice_stepper_forces(&st);
    double scale = 0;
    for (size_t p = 0; p < lat.nn; p++)
        scale = fmax(scale, fabs(fz[p]));
    assert_true(scale > 0);
    for (size_t p = 0; p < lat.nn; p++)
        assert_close(lat.fz[p], fz[p], 1e-12 * scale);
    cf_lattice_stepper_free(&st);
    /* a tailed group: the scalar law of each group, the same forces */
    cf_spring t = {5, 18, 3, 1.8, 200, 10, 1, 4};
    cf_law tailed;
    assert_int_equal(cf_law_init(&tailed, &t, NULL), CF_OK);
    lat.glaw[CF_FAMILY_BODY] = &tailed;
    cf_lattice_forces(&lat);
    memcpy(fz, lat.fz, lat.nn * sizeof *fz);
    assert_int_equal(cf_lattice_stepper_init(&st, &lat, NULL, NULL), CF_OK);
    assert_int_equal(st.form, -1);
    memset(lat.fx, 0, lat.nn * sizeof *lat.fx);
    memset(lat.fy, 0, lat.nn * sizeof *lat.fy);
    memset(lat.fz, 0, lat.nn * sizeof *lat.fz);
    cf_lattice_stepper_forces(&st);
    for (size_t p = 0; p < lat.nn; p++)
        assert_close(lat.fz[p], fz[p], 1e-12 * scale);
    cf_lattice_stepper_free(&st);
    cf_law_free(&tailed);
    free(fz);
    cf_lattice_free(&lat);
    cf_law_free(&edge);
    cf_law_free(&diag);
}

static void a_group_law_of_another_free_length_is_refused(void **state)
{
    (void)state;
    cf_law law = law_of(0), other;
    cf_spring s = {8, 20, 2.5, 1.2, 100, 5};
    assert_int_equal(cf_law_init(&other, &s, NULL), CF_OK);
    cf_lattice_config cfg = cf_lattice_default();
    cfg.group_law[CF_FAMILY_FACE] = &other;
    cf_lattice lat;
    cf_error err = {0};
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "group 'face'"));
    assert_non_null(strstr(err.msg, "H = 5 mm"));
    cf_lattice_free(&lat);
    cf_law_free(&law);
    cf_law_free(&other);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cell_equals_the_full_lattice_with_two_groups),
        cmocka_unit_test(groups_of_the_same_law_change_nothing),
        cmocka_unit_test(explicit_step_takes_each_groups_law),
        cmocka_unit_test(a_group_law_of_another_free_length_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
