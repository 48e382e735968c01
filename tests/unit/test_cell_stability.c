/*
** Tests of the cell's stability (src/model/cell_stability.c): the full tangent is the derivative
** of the stress (finite differences) and symmetric; the unstrained cell is stable; in uniaxial
** compression the cell loses stability no later than the full lattice's negative-pivot scan finds
** (a homogeneous loss is a loss of the lattice too); in every mode the limit found is where the
** smallest eigenvalue changes sign.
*/
#include "testutil.h"

#include "model/cell_stability.h"
#include "model/msm.h"

static cf_law law_of(int which)
{
    cf_spring a = {6, 15, 2.5, 2, 26, 10};
    cf_spring b = {8, 20, 2.5, 1.2, 100, 5};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, which ? &b : &a, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

static cf_cell iso_cell(const cf_law *law)
{
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, law, CF_LAW_CLOSED, w, NULL), CF_OK);
    return c;
}

/* The full tangent is the derivative of the nominal stress (central differences) and symmetric. */
static void tangent_is_the_derivative_of_the_stress(void **state)
{
    (void)state;
    cf_law law = law_of(1);
    cf_cell c = iso_cell(&law);
    const double F[9] = {1.05, 0.08, -0.02, 0.01, 0.93, 0.04, 0.03, -0.05, 1.1};
    double A[81];
    cf_cell_state s;
    assert_int_equal(cf_cell_tangent(&c, F, NULL, &s, A, NULL), CF_OK);
    const double h = 1e-6;
    for (int q = 0; q < 9; q++) {
        double Fp[9], Fm[9];
        memcpy(Fp, F, sizeof Fp);
        memcpy(Fm, F, sizeof Fm);
        Fp[q] += h, Fm[q] -= h;
        cf_cell_state sp, sm;
        assert_int_equal(cf_cell_stress(&c, Fp, NULL, &sp, NULL), CF_OK);
        assert_int_equal(cf_cell_stress(&c, Fm, NULL, &sm, NULL), CF_OK);
        for (int p = 0; p < 9; p++) {
            double fd = (sp.P_MPa[p / 3][p % 3] - sm.P_MPa[p / 3][p % 3]) / (2 * h);
            assert_true(fabs(fd - A[9 * p + q]) <= 1e-5 * (1 + fabs(A[9 * p + q])));
            assert_true(fabs(A[9 * p + q] - A[9 * q + p]) <= 1e-9 * (1 + fabs(A[9 * p + q])));
        }
    }
    cf_law_free(&law);
}

/* The unstrained cell is stable (its smallest eigenvalue is positive); its limit in every mode
** is where the smallest eigenvalue changes sign. */
static void limit_is_where_the_smallest_eigenvalue_changes_sign(void **state)
{
    (void)state;
    for (int which = 0; which < 2; which++) {
        cf_law law = law_of(which);
        cf_cell c = iso_cell(&law);
        const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, sH = law.travel_mm / law.p.H_mm;
        double l0 = 0;
        assert_int_equal(cf_cell_min_stiffness(&c, I, &l0, NULL), CF_OK);
        assert_true(l0 > 0);
        int losses = 0;
        for (int m = 0; m < 4; m++)
            for (int side = -1; side <= 1; side += 2) {
                const double reach = side * 0.99 * sH;
                double lim = 0;
                int lost = -1;
                assert_int_equal(cf_cell_stable_to(&c, (cf_mode)m, reach, &lim, &lost, NULL),
                                 CF_OK);
                assert_true(lim * reach > 0 && fabs(lim) <= fabs(reach));
                if (!lost) {
                    assert_true(lim == reach);
                    continue;
                }
                losses++;
                double in, out;
                cf_cell_state s;
                assert_int_equal(cf_cell_mode(&c, (cf_mode)m, lim * (1 - 1e-3), NULL, &s, NULL),
                                 CF_OK);
                assert_int_equal(cf_cell_min_stiffness(&c, s.F, &in, NULL), CF_OK);
                assert_int_equal(cf_cell_mode(&c, (cf_mode)m, lim * (1 + 1e-3), NULL, &s, NULL),
                                 CF_OK);
                assert_int_equal(cf_cell_min_stiffness(&c, s.F, &out, NULL), CF_OK);
                assert_true(in > 0);
                assert_true(out <= 0);
            }
        /* compression loses stability before solid in uniaxial, planar and equibiaxial; simple
        ** shear (either sign) and tension stay stable */
        assert_int_equal(losses, 3);
        cf_law_free(&law);
    }
}

/* Uniaxial, where the full lattice exists: past the cell's limit the full lattice's homogeneous
** state has negative pivots, and the full lattice's own scan never finds it stable further than
** the cell (a homogeneous loss is a loss of the lattice; the lattice may buckle earlier). */
static void cell_limit_agrees_with_the_full_lattice(void **state)
{
    (void)state;
    for (int which = 0; which < 2; which++) {
        cf_law law = law_of(which);
        cf_cell c = iso_cell(&law);
        const double sH = law.travel_mm / law.p.H_mm;
        double lim = 0, full = 0;
        int lost = 0;
        assert_int_equal(cf_cell_stable_to(&c, CF_MODE_UNIAXIAL, -0.99 * sH, &lim, &lost, NULL),
                         CF_OK);
        assert_int_equal(lost, 1);
        cf_error err = {0};
        if (cf_msm_stability_limit(&law, CF_LAW_CLOSED, NULL, -1, &full, &err) != CF_OK)
            fail_msg("full lattice: %s", err.msg);
        assert_true(full < 0 && full >= lim - 1e-6);
        cf_cell_state s;
        const double past = lim * (1 + 1e-2);
        assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, past, NULL, &s, NULL), CF_OK);
        long neg = 0;
        if (cf_msm_homogeneous_inertia(&law, CF_LAW_CLOSED, NULL, past, s.free_stretch, &neg,
                                       &err) != CF_OK)
            fail_msg("inertia: %s", err.msg);
        assert_true(neg > 0);
        cf_law_free(&law);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tangent_is_the_derivative_of_the_stress),
        cmocka_unit_test(limit_is_where_the_smallest_eigenvalue_changes_sign),
        cmocka_unit_test(cell_limit_agrees_with_the_full_lattice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
