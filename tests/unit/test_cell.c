/*
** Tests of the homogenised cell (src/model/cell.c): it equals the full lattice's static uniaxial
** solution to 1e-9 for several cell counts and calibrations, in tension and compression; its
** small-strain response in every mode is the one the Cauchy-Born constants predict; the stress is
** frame-indifferent; the free stretch leaves no lateral stress; extra tensions enter as forces on
** the faces; bad input is refused.
*/
#include "testutil.h"

#include "model/cell.h"
#include "model/msm.h"
#include "model/mode.h"

/* A soft, strongly stiffening non-telescoping spring (solid strain 0.5, H = 10 mm), and a
** telescoping one with a deeper nonlinear range. */
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

/* The isotropic cell of law with evaluator m. */
static cf_cell iso_cell(const cf_law *law, cf_law_method m)
{
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, law, m, w, NULL), CF_OK);
    return c;
}

static void cell_equals_the_full_lattice_in_uniaxial_tension_and_compression(void **state)
{
    (void)state;
    const int sizes[4][3] = {{1, 1, 1}, {2, 3, 2}, {3, 3, 3}, {4, 2, 3}};
    for (int which = 0; which < 2; which++) {
        cf_law law = law_of(which);
        double sH = law.travel_mm / law.p.H_mm;
        /* up to 0.9 of the solid strain in tension, 0.6 in compression (inside the stable range
        ** of the default lattice) */
        double e[] = {-0.6 * sH, -0.45 * sH, -0.3 * sH, -0.1 * sH, -0.01 * sH,
                      0.01 * sH,  0.2 * sH,  0.5 * sH,  0.75 * sH, 0.9 * sH};
        const size_t n = sizeof e / sizeof e[0];
        for (int cal = 0; cal < 3; cal++) {
            double w[3] = {1, 0.5, 0.3};
            if (cal < 2)
                assert_int_equal(cf_calibration_weights(cal ? CF_CAL_AXIAL : CF_CAL_ISOTROPIC, w,
                                                        NULL),
                                 CF_OK);
            cf_cell c;
            assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
            double cell[10];
            cf_error err = {0};
            if (cf_cell_curve(&c, CF_MODE_UNIAXIAL, e, n, cell, &err) != CF_OK)
                fail_msg("cell: %s", err.msg);
            for (int z = 0; z < 4; z++) {
                cf_msm_config cfg = cf_msm_default();
                cfg.lattice.nx = sizes[z][0];
                cfg.lattice.ny = sizes[z][1];
                cfg.lattice.nz = sizes[z][2];
                memcpy(cfg.lattice.weight, w, sizeof w);
                double full[10];
                if (cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, e, n, full, NULL, &err) != CF_OK)
                    fail_msg("lattice %dx%dx%d: %s", sizes[z][0], sizes[z][1], sizes[z][2],
                             err.msg);
                for (size_t i = 0; i < n; i++)
                    if (!(fabs(cell[i] - full[i]) <= 1e-9 * fabs(full[i])))
                        fail_msg("spring %d, weights %g/%g/%g, %dx%dx%d cells, strain %g: cell "
                                 "%.17g, lattice %.17g",
                                 which, w[0], w[1], w[2], sizes[z][0], sizes[z][1], sizes[z][2],
                                 e[i], cell[i], full[i]);
            }
        }
    }
}

/* At a small strain each mode's stress is the Cauchy-Born prediction from C11, C12 = C44 (in
** units of k0/H), and the uniaxial free stretch gives nu. */
static void small_strain_response_of_every_mode_follows_the_elastic_constants(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    const double E0 = law.k0_N_per_mm / law.p.H_mm;
    double weights[2][3] = {{0, 0, 0}, {1, 0.5, 0.3}};
    cf_calibration_weights(CF_CAL_ISOTROPIC, weights[0], NULL);
    for (int k = 0; k < 2; k++) {
        cf_cell c;
        assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, weights[k], NULL), CF_OK);
        cf_cubic_moduli m = cf_cubic_moduli_of(weights[k]);
        const double want[CF_MODE_COUNT] = {
            m.E, m.C44, m.C11 - m.C12 * m.C12 / m.C11,
            m.C11 + m.C12 - 2 * m.C12 * m.C12 / m.C11, m.C11,
            m.C11 + m.C12 - 2 * m.C12 * m.C12 / m.C11}; /* biaxial at the cell's k = 1 */
        const double e = 1e-7;
        for (int md = 0; md < CF_MODE_COUNT; md++) {
            cf_cell_state s;
            cf_error err = {0};
            if (cf_cell_mode(&c, (cf_mode)md, e, NULL, &s, &err) != CF_OK)
                fail_msg("%s: %s", cf_mode_name((cf_mode)md), err.msg);
            assert_close(s.stress_MPa / (e * E0), want[md], 1e-6 * want[md]);
            if (md == CF_MODE_UNIAXIAL) {
                assert_close((1 - s.free_stretch) / e, m.nu, 1e-6);
                /* rounding: the springs' compressions are formed from lengths, ~1e-16 H */
                assert_close(s.P_MPa[0][0], 0, 1e-14 * E0);
                assert_close(s.P_MPa[1][1], 0, 1e-14 * E0);
            }
            if (md == CF_MODE_PLANAR || md == CF_MODE_EQUIBIAXIAL || md == CF_MODE_BIAXIAL)
                assert_close(s.P_MPa[2][2], 0, 1e-14 * E0);
        }
        if (k == 0)
            assert_close(m.nu, 0.25, 1e-15);
    }
}

/* Deep in the nonlinear range the free stretch still leaves no lateral stress, and the uniaxial
** stress is continuous and increasing from compression to tension. */
/* cf_cubic_q_of_zener inverts the Zener ratio of weights {1, q, q}: q of ratio z gives back z
** (1e-12), the isotropic calibration's ratio q is that of z = 1, and a ratio past the limit or not
** positive has none (NAN). */
static void the_weight_ratio_of_a_zener_ratio(void **state)
{
    (void)state;
    const double z[] = {0.05, 0.5, 0.9, 1.0, 1.1, 2.0, 3.5};
    for (size_t k = 0; k < sizeof z / sizeof z[0]; k++) {
        const double q = cf_cubic_q_of_zener(z[k]);
        assert_true(q > 0);
        const double w[CF_FAMILY_COUNT] = {1, q, q};
        assert_close(cf_cubic_moduli_of(w).zener, z[k], 1e-12 * z[k]);
    }
    double iso[CF_FAMILY_COUNT];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, iso, NULL), CF_OK);
    assert_close(cf_cubic_q_of_zener(1.0), iso[CF_FAMILY_FACE] / iso[CF_FAMILY_EDGE], 1e-12);
    assert_true(isnan(cf_cubic_q_of_zener(0)));
    assert_true(isnan(cf_cubic_q_of_zener(-1)));
    assert_true(isnan(cf_cubic_q_of_zener(5.0))); /* the limit is 2 sqrt 2 (...) = 4.18 */
}

static void uniaxial_curve_is_monotonic_with_zero_lateral_stress(void **state)
{
    (void)state;
    cf_law law = law_of(1);
    cf_cell c = iso_cell(&law, CF_LAW_CLOSED);
    double sH = law.travel_mm / law.p.H_mm, prev = -INFINITY;
    for (int i = -95; i <= 95; i++) {
        cf_cell_state s;
        cf_error err = {0};
        double e = 0.01 * i * sH;
        if (cf_cell_mode(&c, CF_MODE_UNIAXIAL, e, NULL, &s, &err) != CF_OK)
            fail_msg("strain %g: %s", e, err.msg);
        assert_true(s.stress_MPa > prev);
        prev = s.stress_MPa;
        assert_true(fabs(s.P_MPa[0][0]) <= 1e-13 * (fabs(s.stress_MPa) + law.k0_N_per_mm / law.p.H_mm));
        assert_true(s.max_u_over_travel < 1);
    }
}

/* P(R U) = R P(U) for a rotation R: the stress of a rotated deformation is the rotated stress. */
static void stress_is_frame_indifferent(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    cf_cell c = iso_cell(&law, CF_LAW_EXACT);
    double U[9] = {1.1, 0.05, 0.02, 0.05, 0.92, -0.03, 0.02, -0.03, 1.04};
    double t = 0.7, R[9] = {cos(t), -sin(t), 0, sin(t), cos(t), 0, 0, 0, 1}, RU[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            RU[3 * i + j] = 0;
            for (int k = 0; k < 3; k++)
                RU[3 * i + j] += R[3 * i + k] * U[3 * k + j];
        }
    cf_cell_state a, b;
    assert_int_equal(cf_cell_stress(&c, U, NULL, &a, NULL), CF_OK);
    assert_int_equal(cf_cell_stress(&c, RU, NULL, &b, NULL), CF_OK);
    double scale = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            scale = fmax(scale, fabs(a.P_MPa[i][j]));
    assert_true(scale > 0);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double r = 0;
            for (int k = 0; k < 3; k++)
                r += R[3 * i + k] * a.P_MPa[k][j];
            assert_close(b.P_MPa[i][j], r, 1e-13 * scale);
        }
}

/* An extra tension T0 on the z edge of the undeformed cell is a traction T0/H^2 on the top face;
** an extra stiffness k on it adds k H / H^2 per unit confined strain (a dashpot's form). */
static void extra_tensions_act_as_spring_forces(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    const double H = law.p.H_mm;
    cf_cell c = iso_cell(&law, CF_LAW_CLOSED);
    int zedge = -1;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], f;
        cf_cell_direction(d, N, &f);
        if (N[0] == 0 && N[1] == 0 && N[2] == 1)
            zedge = d;
        assert_int_equal(f, abs(N[0]) + abs(N[1]) + abs(N[2]) - 1);
    }
    assert_true(zedge >= 0);
    cf_cell_extra x;
    memset(&x, 0, sizeof x);
    for (int d = 0; d < CF_CELL_DIRS; d++)
        x.Lref_mm[d] = H;
    x.T0_N[zedge] = 0.01;
    cf_cell_state s0, s1;
    assert_int_equal(cf_cell_mode(&c, CF_MODE_CONFINED, 0, &x, &s1, NULL), CF_OK);
    assert_close(s1.stress_MPa, 0.01 / (H * H), 1e-15);
    x.T0_N[zedge] = 0;
    x.k_N_per_mm[zedge] = 0.02;
    const double e = 0.05;
    assert_int_equal(cf_cell_mode(&c, CF_MODE_CONFINED, e, NULL, &s0, NULL), CF_OK);
    assert_int_equal(cf_cell_mode(&c, CF_MODE_CONFINED, e, &x, &s1, NULL), CF_OK);
    assert_close(s1.stress_MPa - s0.stress_MPa, 0.02 * e * H / (H * H), 1e-15);
}

/* The stress of the cell at F as the sum over every spring, each evaluated on its own (no
** sharing between springs in the same state), with the extra terms x (may be NULL). */
static void stress_spring_by_spring(const cf_cell *c, const double F[9], const cf_cell_extra *x,
                                    double P[9])
{
    const double H = c->law->p.H_mm;
    memset(P, 0, 9 * sizeof(double));
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], fam;
        cf_cell_direction(d, N, &fam);
        double X[3] = {H * N[0], H * N[1], H * N[2]}, xv[3];
        for (int i = 0; i < 3; i++)
            xv[i] = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
        const double L = sqrt(xv[0] * xv[0] + xv[1] * xv[1] + xv[2] * xv[2]);
        const double L0 = H * sqrt((double)(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]));
        double T = -c->weight[fam] * c->law_scale *
                   cf_law_force(c->law, c->method, H * (L0 - L) / L0, NULL, NULL);
        if (x)
            T += x->T0_N[d] + x->k_N_per_mm[d] * (L - x->Lref_mm[d]);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                P[3 * i + j] += T / L * xv[i] * X[j] / (H * H * H);
    }
}

/* Springs the deformation maps alike share one evaluation of the law: the stress is still that
** of every spring evaluated on its own, under uniaxial and equibiaxial loading (many springs
** alike), a general F (none alike), and extra terms that split springs of one length apart. */
static void springs_in_one_state_share_their_evaluation(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    const double H = law.p.H_mm;
    cf_cell c = iso_cell(&law, CF_LAW_CLOSED);
    const double Fs[3][9] = {{0.97, 0, 0, 0, 0.97, 0, 0, 0, 1.08},
                             {1.05, 0, 0, 0, 1.05, 0, 0, 0, 0.93},
                             {1.02, 0.03, -0.01, 0.02, 0.96, 0.04, 0.01, -0.02, 1.07}};
    cf_cell_extra x;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        x.Lref_mm[d] = H;
        x.k_N_per_mm[d] = 0.01;
        x.T0_N[d] = d == 0 ? 0.02 : 0.005; /* the x edge apart from the y edge */
    }
    for (int f = 0; f < 3; f++)
        for (int with = 0; with < 2; with++) {
            cf_cell_state s;
            double P[9];
            assert_int_equal(cf_cell_stress(&c, Fs[f], with ? &x : NULL, &s, NULL), CF_OK);
            stress_spring_by_spring(&c, Fs[f], with ? &x : NULL, P);
            double big = 0;
            for (int i = 0; i < 9; i++)
                big = fmax(big, fabs(P[i]));
            assert_true(big > 0);
            for (int i = 0; i < 9; i++)
                assert_close(s.P_MPa[i / 3][i % 3], P[i], 1e-12 * big);
        }
    /* in uniaxial tension the x edge carries the extra tension the y edge does not */
    cf_cell_state s;
    assert_int_equal(cf_cell_stress(&c, Fs[0], &x, &s, NULL), CF_OK);
    assert_true(s.T_N[0] != s.T_N[2]);
}

static void bad_input_is_refused(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    double w[3] = {1, -1, 0};
    cf_cell c;
    cf_error err = {0};
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "lattice.weights.face"));
    cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL);
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
    cf_mode m;
    assert_int_equal(cf_mode_parse("torsion", &m, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "'torsion'"));
    assert_int_equal(cf_mode_parse("planar", &m, NULL), CF_OK);
    assert_int_equal(m, CF_MODE_PLANAR);
    cf_cell_state s;
    /* past the solid strain 0.5 in compression, and a NaN */
    assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, -0.55, NULL, &s, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "solid"));
    assert_int_equal(cf_cell_mode(&c, CF_MODE_SHEAR, NAN, NULL, &s, &err), CF_E_DATA);
}

/* The table strain at which the first spring reaches solid: in uniaxial the loaded edge's, the
** solid strain itself; in simple shear the stretched face diagonal's, whose stretch is
** sqrt(((1 + g)^2 + 1) / 2): g = sqrt(2 (1 + s/H)^2 - 1) - 1 (about twice s/H), the same for
** either sign of shear. */
static void first_spring_at_solid_in_each_mode(void **state)
{
    (void)state;
    for (int which = 0; which < 2; which++) {
        cf_law law = law_of(which);
        cf_cell c = iso_cell(&law, CF_LAW_CLOSED);
        const double sH = law.travel_mm / law.p.H_mm;
        double e = 0;
        assert_int_equal(cf_cell_solid_strain(&c, CF_MODE_UNIAXIAL, 1, &e, NULL), CF_OK);
        assert_close(e, sH, 1e-8);
        const double g = sqrt(2 * (1 + sH) * (1 + sH) - 1) - 1;
        for (int side = -1; side <= 1; side += 2) {
            assert_int_equal(cf_cell_solid_strain(&c, CF_MODE_SHEAR, side, &e, NULL), CF_OK);
            assert_close(e, side * g, 1e-8);
        }
        assert_true(g > 1.6 * sH);
        /* equibiaxial and planar: reached, before |e| = 1 in compression */
        for (int m = CF_MODE_PLANAR; m <= CF_MODE_EQUIBIAXIAL; m++) {
            assert_int_equal(cf_cell_solid_strain(&c, (cf_mode)m, -1, &e, NULL), CF_OK);
            cf_cell_state st;
            assert_int_equal(cf_cell_mode(&c, (cf_mode)m, e * (1 - 1e-6), NULL, &st, NULL),
                             CF_OK);
            assert_true(st.max_u_over_travel > 0.99);
            assert_int_equal(cf_cell_mode(&c, (cf_mode)m, e * (1 + 1e-6), NULL, &st, NULL),
                             CF_E_DATA);
        }
        cf_law_free(&law);
    }
}

/* Simple shear has no stretch limit: gamma of -1 and beyond is a state like any other, and the
** stress is odd in gamma. */
static void shear_takes_either_sign_past_one(void **state)
{
    (void)state;
    cf_law law = law_of(1);
    cf_cell c = iso_cell(&law, CF_LAW_CLOSED);
    const double sH = law.travel_mm / law.p.H_mm;
    const double g = 0.95 * (sqrt(2 * (1 + sH) * (1 + sH) - 1) - 1);
    assert_true(g > 1);
    cf_cell_state a, b;
    assert_int_equal(cf_cell_mode(&c, CF_MODE_SHEAR, g, NULL, &a, NULL), CF_OK);
    assert_int_equal(cf_cell_mode(&c, CF_MODE_SHEAR, -g, NULL, &b, NULL), CF_OK);
    assert_true(a.stress_MPa > 0);
    assert_close(b.stress_MPa, -a.stress_MPa, 1e-12 * a.stress_MPa);
    cf_law_free(&law);
}


/* The mode table (src/model/mode.c): every mode's name parses back to it; its deformation is a
** consistent row (a free stretch is not a loaded one, the stretch it zeroes is free, the stress it
** reads is loaded); the cell's free stretch leaves exactly that stress at zero and the mode's
** stress is the one the row names (a shear stress in shear, a normal one elsewhere); the
** incompressible forms are there exactly where q says; an unknown mode has no row. */
static void every_mode_is_one_consistent_row(void **state)
{
    (void)state;
    cf_law law = law_of(0);
    cf_cell c = iso_cell(&law, CF_LAW_EXACT);
    for (int k = 0; k < CF_MODE_COUNT; k++) {
        const cf_mode_row *r = cf_mode_row_of((cf_mode)k);
        assert_non_null(r);
        cf_mode back = CF_MODE_COUNT;
        assert_int_equal(cf_mode_parse(cf_mode_name((cf_mode)k), &back, NULL), CF_OK);
        assert_int_equal(back, k);
        assert_int_equal(r->free_mask & r->strain_mask, 0u);
        if (r->zero >= 0)
            assert_true(r->free_mask & (1u << r->zero));
        else
            assert_int_equal(r->free_mask, 0u);
        if (r->si == r->sj)
            assert_true(r->strain_mask & (1u << r->si));
        else
            assert_true(r->shear_i == r->si && r->shear_j == r->sj);
        assert_int_equal(r->q > 0, r->ogden != NULL);
        assert_int_equal(r->q > 0, r->yeoh != NULL);
        assert_int_equal(r->q > 0, r->no_incompressible == NULL);
        double F[9];
        cf_mode_place((cf_mode)k, 0.05, 0.97, F);
        for (int i = 0; i < 3; i++)
            assert_true(F[4 * i] == (r->strain_mask & (1u << i)  ? 1.05
                                     : r->free_mask & (1u << i) ? 0.97
                                                                : 1.0));
        cf_cell_state s;
        assert_int_equal(cf_cell_mode(&c, (cf_mode)k, 0.05, NULL, &s, NULL), CF_OK);
        assert_true(s.P_MPa[r->si][r->sj] > 0);
        if (r->zero >= 0)
            assert_true(fabs(s.P_MPa[r->zero][r->zero]) <= 1e-12 * fabs(s.P_MPa[r->si][r->sj]));
    }
    assert_null(cf_mode_row_of(CF_MODE_COUNT));
    assert_null(cf_mode_row_of((cf_mode)-1));
    cf_mode m;
    cf_error err = {0};
    assert_int_equal(cf_mode_parse("torsion", &m, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "expected uniaxial, shear, planar, equibiaxial, confined or "
                                    "biaxial"));
    /* the list of the messages names every row, in order */
    const char *list = cf_mode_list(), *at = list;
    for (int k = 0; k < CF_MODE_COUNT; k++) {
        const char *hit = strstr(at, cf_mode_name((cf_mode)k));
        assert_non_null(hit);
        at = hit + strlen(cf_mode_name((cf_mode)k));
    }
    assert_string_equal(at, "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cell_equals_the_full_lattice_in_uniaxial_tension_and_compression),
        cmocka_unit_test(small_strain_response_of_every_mode_follows_the_elastic_constants),
        cmocka_unit_test(the_weight_ratio_of_a_zener_ratio),
        cmocka_unit_test(uniaxial_curve_is_monotonic_with_zero_lateral_stress),
        cmocka_unit_test(stress_is_frame_indifferent),
        cmocka_unit_test(extra_tensions_act_as_spring_forces),
        cmocka_unit_test(springs_in_one_state_share_their_evaluation),
        cmocka_unit_test(bad_input_is_refused),
        cmocka_unit_test(first_spring_at_solid_in_each_mode),
        cmocka_unit_test(shear_takes_either_sign_past_one),
        cmocka_unit_test(every_mode_is_one_consistent_row),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
