/*
** Tests of the acoustic tensor's smallest eigenvalue and the cell's strong ellipticity
** (src/model/cell_elliptic.c): an isotropic linear material, Q(n) = (lambda + 2 mu) n n +
** mu (I - n n), elliptic exactly when mu > 0 and lambda + 2 mu > 0; a material soft along one
** direction m, found there off the sampled grid; the isotropic cell at rest, where every
** direction gives its shear modulus; and the cortex's kept pair, stable in the lattice but not
** elliptic in tension past 5.6 %, where the smallest eigenvalue changes sign.
*/
#include "testutil.h"

#include "model/cell_elliptic.h"

/* A_ijkl = lambda d_ij d_kl + mu (d_ik d_jl + d_il d_jk) + beta m_i m_j m_k m_l. */
static void moduli(double lambda, double mu, double beta, const double m[3], double A[81])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++)
                for (int l = 0; l < 3; l++)
                    A[27 * i + 9 * j + 3 * k + l] =
                        lambda * (i == j) * (k == l) +
                        mu * ((i == k) * (j == l) + (i == l) * (j == k)) +
                        beta * m[i] * m[j] * m[k] * m[l];
}

static void isotropic_linear_material(void **state)
{
    (void)state;
    const double m[3] = {0, 0, 1};
    const double cases[][3] = {/* lambda, mu, the smallest eigenvalue: min(mu, lambda + 2 mu) */
                               {1.0, 1.0, 1.0},   {-0.5, 2.0, 2.0},  {-3.0, 1.0, -1.0},
                               {1.0, -0.1, -0.1}, {-1.9, 1.0, 0.1}, {5.0, 1e-3, 1e-3}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double A[81], q = 0, n[3];
        moduli(cases[c][0], cases[c][1], 0.0, m, A);
        assert_int_equal(cf_acoustic_min(A, &q, n, NULL), CF_OK);
        assert_true(fabs(q - cases[c][2]) <= 1e-12 * (1 + fabs(cases[c][2])));
        assert_true(fabs(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1) < 1e-12);
    }
}

/* Soft along m = (1, 2, 2)/3 (on no grid point): Q(m) has 2 mu + beta = -1 along m, every other
** direction more; the refinement finds it to rounding. */
static void soft_direction_found(void **state)
{
    (void)state;
    const double m[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
    double A[81], q = 0, n[3];
    moduli(0.0, 1.0, -3.0, m, A);
    assert_int_equal(cf_acoustic_min(A, &q, n, NULL), CF_OK);
    assert_true(fabs(q + 1.0) < 1e-9);
    assert_true(fabs(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) > 1 - 1e-9);
    assert_true(n[1] > 0 || n[2] > 0); /* the sign of the largest component */
    A[40] = NAN;
    assert_int_equal(cf_acoustic_min(A, &q, n, NULL), CF_E_DATA);
}

static cf_law law_of(void)
{
    cf_spring b = {8, 20, 2.5, 1.2, 100, 5};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &b, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

/* The isotropic cell at rest: no prestress, so Q(n) = C(n) and every direction's softest wave is
** the shear modulus A_xzxz. */
static void isotropic_cell_at_rest(void **state)
{
    (void)state;
    cf_law law = law_of();
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double A[81], q = 0, n[3];
    cf_cell_state s;
    assert_int_equal(cf_cell_tangent(&c, I, NULL, &s, A, NULL), CF_OK);
    assert_int_equal(cf_acoustic_min(A, &q, n, NULL), CF_OK);
    const double mu = A[27 * 0 + 9 * 2 + 3 * 0 + 2];
    assert_true(mu > 0);
    assert_true(fabs(q - mu) <= 1e-9 * mu);
    double limit = 0, nl[3];
    int lost = 1;
    assert_int_equal(cf_cell_elliptic_to(&c, CF_MODE_SHEAR, 0.1, &limit, &lost, nl, NULL), CF_OK);
    assert_int_equal(lost, 0);
    assert_true(limit == 0.1);
    assert_int_equal(cf_cell_elliptic_to(&c, CF_MODE_SHEAR, NAN, &limit, &lost, nl, NULL),
                     CF_E_DATA);
    cf_law_free(&law);
}

/* The double-acting element and volume term the cortex joint fit keeps (its placed springs,
** weights and kappa, written here so no data set is needed): stable in the lattice over the
** tables' ranges, yet its cell loses strong ellipticity in uniaxial tension at strain 0.05584,
** for a direction normal to the load; elliptic in compression and shear to 1.05x the tables'
** ranges. Across the limit the smallest eigenvalue changes sign. */
static void cortex_pair_loses_ellipticity_in_tension(void **state)
{
    (void)state;
    const cf_spring sc = {0.46145949727262353, 2.1820760139457613, 5.592966167537142,
                          0.15381983242420783, 23010.13512586006,  10.0,
                          18.642809294715978,  8.094328817761534};
    const cf_spring se = {1.752283017588974, 19.250008852901402, 14.97851003403528,
                          0.5840943391379154, 7725.410265974434, 10.0};
    cf_law law, ext;
    assert_int_equal(cf_law_init(&law, &sc, NULL), CF_OK);
    assert_int_equal(cf_law_init(&ext, &se, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&law, &ext, NULL), CF_OK);
    const double w[3] = {0.6084898469281491, 0.27083625580635917, 0.27083625580635917};
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
    c.volume_modulus_MPa = 0.012890005109405987;
    double limit = 0, n[3];
    int lost = 0;
    assert_int_equal(cf_cell_elliptic_to(&c, CF_MODE_UNIAXIAL, 0.105, &limit, &lost, n, NULL),
                     CF_OK);
    assert_int_equal(lost, 1);
    assert_true(fabs(limit - 0.05584) < 1e-4);
    assert_true(fabs(n[2]) < 1e-6 && fabs(n[0] * n[0] + n[1] * n[1] - 1) < 1e-9);
    for (int side = -1; side <= 1; side += 2) { /* the sign changes across the limit */
        cf_cell_state s;
        double A[81], q = 0, m[3];
        assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, limit * (1 + 0.01 * side), NULL, &s,
                                      NULL),
                         CF_OK);
        assert_int_equal(cf_cell_tangent(&c, s.F, NULL, &s, A, NULL), CF_OK);
        assert_int_equal(cf_acoustic_min(A, &q, m, NULL), CF_OK);
        assert_true(side < 0 ? q > 0 : q < 0);
    }
    assert_int_equal(cf_cell_elliptic_to(&c, CF_MODE_UNIAXIAL, -0.105, &limit, &lost, n, NULL),
                     CF_OK);
    assert_int_equal(lost, 0);
    assert_int_equal(cf_cell_elliptic_to(&c, CF_MODE_SHEAR, 0.21, &limit, &lost, n, NULL), CF_OK);
    assert_int_equal(lost, 0);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(isotropic_linear_material),
        cmocka_unit_test(soft_direction_found),
        cmocka_unit_test(isotropic_cell_at_rest),
        cmocka_unit_test(cortex_pair_loses_ellipticity_in_tension),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
