/*
** Tests of the double-acting element (law.h, cf_law.extension) and the volume term (cell.h,
** volume_modulus_MPa): a pair of equal springs is the odd law bit for bit in every evaluator and
** in the cell; each side is its own spring; an independent reference of the cell (long double, the
** law's quartic and the free stretch both by bisection) agrees with the cell in all five modes to
** 1e-12 relative, with the pair and the volume term; the volume term adds kappa to Lame's lambda at
** small strain (nu = (mu + kappa)/(2 (2 mu + kappa))) and nothing in simple shear; the full lattice
** with a pair equals the cell under homogeneous uniaxial loading (every lateral spring crossing
** zero on the other side from the loaded ones) and stays at rest at rest.
*/
/* conifit: vector-level: the double-acting law's lanes and explicit step */
#include "testutil.h"

#include "model/cell.h"
#include "model/msm.h"
#include "model/lattice_step.h"

/* The compression spring (non-telescoping, solid strain 0.5, H 10 mm) and an extension spring
** of the same H: a stiffer, nearly cylindrical one, and a strongly conical one. */
static const cf_spring comp_p = {6, 15, 2.5, 2, 26, 10};
static const cf_spring ext_p[2] = {{9, 9.5, 3, 1.5, 40, 10}, {3, 14, 3, 1.0, 300, 10}};

static cf_law law_of(const cf_spring *p)
{
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, p, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

static void equal_springs_give_the_odd_law_bit_for_bit(void **state)
{
    (void)state;
    cf_law odd = law_of(&comp_p), pair = law_of(&comp_p), twin = law_of(&comp_p);
    assert_int_equal(cf_law_pair(&pair, &twin, NULL), CF_OK);
    assert_int_equal(cf_law_table_build(&odd, CF_LAW_TABLE_DEFAULT, NULL), CF_OK);
    assert_int_equal(cf_law_table_build(&twin, CF_LAW_TABLE_DEFAULT, NULL), CF_OK);
    pair.table = odd.table; /* the same table for the compression side */
    const cf_law_method ms[4] = {CF_LAW_EXACT, CF_LAW_CLOSED, CF_LAW_CLOSED_NEWTON, CF_LAW_TABLE};
    double u[64], F1[64], F2[64], k1[64], k2[64];
    for (int i = 0; i < 64; i++)
        u[i] = odd.travel_mm * (-0.999 + 1.998 * i / 63.0);
    for (int m = 0; m < 4; m++) {
        for (int i = 0; i < 64; i++) {
            int f1, f2;
            const double a = cf_law_force(&odd, ms[m], u[i], &k1[i], &f1);
            const double b = cf_law_force(&pair, ms[m], u[i], &k2[i], &f2);
            if (memcmp(&a, &b, sizeof a) != 0 || memcmp(&k1[i], &k2[i], sizeof a) != 0 || f1 != f2)
                fail_msg("method %d, u %.17g: odd %.17g (k %.17g), pair %.17g (k %.17g)", m, u[i],
                         a, k1[i], b, k2[i]);
            assert_true(memcmp((double[]){cf_law_deflection(&odd, a)},
                               (double[]){cf_law_deflection(&pair, b)}, sizeof a) == 0);
        }
        /* the batch evaluation: forces and stiffness (the pair takes the scalar path) */
        cf_law_force_many(&odd, ms[m], 64, u, F1, k1);
        cf_law_force_many(&pair, ms[m], 64, u, F2, k2);
        assert_true(memcmp(F1, F2, sizeof F1) == 0 && memcmp(k1, k2, sizeof k1) == 0);
    }
    pair.table = NULL;
    cf_law_free(&odd);
    cf_law_free(&twin);
}

static void each_side_is_its_own_spring(void **state)
{
    (void)state;
    for (int e = 0; e < 2; e++) {
        cf_law comp = law_of(&comp_p), ext = law_of(&ext_p[e]), pair = comp;
        assert_int_equal(cf_law_pair(&pair, &ext, NULL), CF_OK);
        for (int i = 1; i < 40; i++) {
            const double t = i / 40.0;
            double kp, ke, kc;
            /* compression: the compression spring; extension: -F_e(-u), stiffness k_e(-u) */
            const double uc = t * comp.travel_mm, ue = -t * ext.travel_mm;
            const double fc = cf_law_force(&comp, CF_LAW_EXACT, uc, &kc, NULL);
            assert_true(cf_law_force(&pair, CF_LAW_EXACT, uc, &kp, NULL) == fc && kp == kc);
            const double fe = cf_law_force(&ext, CF_LAW_EXACT, -ue, &ke, NULL);
            assert_true(cf_law_force(&pair, CF_LAW_EXACT, ue, &kp, NULL) == -fe && kp == ke);
            assert_true(cf_law_deflection(&pair, -fe) == -cf_law_deflection(&ext, fe));
        }
        /* the travel on each side; the stiffness jumps at u = 0 from k0_e to k0_c */
        assert_true(cf_law_travel_at(&pair, 1) == comp.travel_mm);
        assert_true(cf_law_travel_at(&pair, -1) == ext.travel_mm);
        double k;
        cf_law_force(&pair, CF_LAW_CLOSED, -1e-12, &k, NULL);
        assert_true(k == ext.k0_N_per_mm);
        cf_law_force(&pair, CF_LAW_CLOSED, 0.0, &k, NULL);
        assert_true(k == comp.k0_N_per_mm);
        assert_true(ext.k0_N_per_mm != comp.k0_N_per_mm);
    }
    /* refused: another free length, an extension with its own extension */
    cf_spring other = ext_p[0];
    other.H_mm = 11;
    cf_law a = law_of(&comp_p), b = law_of(&other), c = law_of(&ext_p[0]), d = law_of(&comp_p);
    cf_error err = {0};
    assert_int_equal(cf_law_pair(&a, &b, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "free length"));
    assert_int_equal(cf_law_pair(&d, &c, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&a, &d, &err), CF_E_DATA);
}

/* ---- the independent reference: long double, the law's quartic by bisection ---- */

typedef struct ref_law {
    long double H, s, rho, FC, k0, uT;
} ref_law;

static ref_law ref_of(const cf_spring *p)
{
    const long double D1 = p->D1_mm, D2 = p->D2_mm, n = p->n, d = p->d_mm, G = p->G_MPa;
    const int tele = (D2 - D1) / 2 >= n * d;
    ref_law r;
    r.H = p->H_mm;
    r.s = r.H - (tele ? d : n * d);
    r.rho = D1 / D2;
    r.FC = G * d * d * d * d * r.s / (8 * n * D1 * D1 * D1);
    r.k0 = G * d * d * d * d / (2 * n * (D1 + D2) * (D1 * D1 + D2 * D2));
    r.uT = r.s * (1 + r.rho) * (1 + r.rho * r.rho) / 4;
    return r;
}

/* The force of one spring at compression u >= 0: region 1 linear, region 2 F_C y^3 with y the root
** in [rho, 1] of y^4 - 4 c y + 3 = 0 (bisection), c = 1/rho - (u/s)(1/rho - 1). */
static long double ref_side(const ref_law *r, long double u)
{
    if (u <= r->uT)
        return r->k0 * u;
    const long double c = 1 / r->rho - (u / r->s) * (1 / r->rho - 1);
    long double lo = r->rho, hi = 1; /* f(lo) >= 0 >= f(hi) */
    for (int it = 0; it < 200; it++) {
        const long double m = 0.5L * (lo + hi);
        if (m * m * m * m - 4 * c * m + 3 > 0)
            lo = m;
        else
            hi = m;
    }
    const long double y = 0.5L * (lo + hi);
    return r->FC * y * y * y;
}

typedef struct ref_cell {
    ref_law c, e;
    long double w[3], kappa;
} ref_cell;

/* The nominal stress of the reference cell at F (long double). */
static void ref_stress(const ref_cell *rc, const long double F[9], long double P[3][3])
{
    memset(P, 0, 9 * sizeof(long double));
    const long double H = rc->c.H;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], fam;
        cf_cell_direction(d, N, &fam);
        long double X[3] = {H * N[0], H * N[1], H * N[2]}, x[3], L2 = 0, L02 = 0;
        for (int i = 0; i < 3; i++) {
            x[i] = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
            L2 += x[i] * x[i];
            L02 += X[i] * X[i];
        }
        const long double L = sqrtl(L2), L0 = sqrtl(L02), u = H * (L0 - L) / L0;
        const long double f = u >= 0 ? ref_side(&rc->c, u) : -ref_side(&rc->e, -u);
        const long double T = -rc->w[fam] * f;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                P[i][j] += T * x[i] * X[j] / (L * H * H * H);
    }
    /* the volume term: kappa (J - 1) cof F */
    const long double *a = F;
    long double C[9] = {a[4] * a[8] - a[5] * a[7], a[5] * a[6] - a[3] * a[8],
                        a[3] * a[7] - a[4] * a[6], a[2] * a[7] - a[1] * a[8],
                        a[0] * a[8] - a[2] * a[6], a[1] * a[6] - a[0] * a[7],
                        a[1] * a[5] - a[2] * a[4], a[2] * a[3] - a[0] * a[5],
                        a[0] * a[4] - a[1] * a[3]};
    const long double J = a[0] * C[0] + a[1] * C[1] + a[2] * C[2];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            P[i][j] += rc->kappa * (J - 1) * C[3 * i + j];
}

/* The mode's stress with its free stretch found by bisection on the lateral stress. */
static long double ref_mode(const ref_cell *rc, cf_mode m, long double e)
{
    long double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, P[3][3];
    int free_i = -1, zero = -1, si = 2, sj = 2;
    switch (m) {
    case CF_MODE_UNIAXIAL: F[8] = 1 + e, free_i = 0, zero = 0; break;
    case CF_MODE_SHEAR: F[2] = e, si = 0; break;
    case CF_MODE_PLANAR: F[0] = 1 + e, free_i = 8, zero = 2, si = sj = 0; break;
    case CF_MODE_EQUIBIAXIAL: F[0] = F[4] = 1 + e, free_i = 8, zero = 2, si = sj = 0; break;
    case CF_MODE_BIAXIAL: /* at the ratio the cell is given below, k = 0.6 */
        F[0] = 1 + e, F[4] = 1 + 0.6L * e, free_i = 8, zero = 2, si = sj = 0;
        break;
    default: F[8] = 1 + e; break;
    }
    if (free_i >= 0) {
        long double lo = 0.5L, hi = 1.5L; /* the lateral stress increases with the stretch */
        for (int it = 0; it < 200; it++) {
            const long double a = 0.5L * (lo + hi);
            if (m == CF_MODE_UNIAXIAL)
                F[0] = F[4] = a;
            else
                F[8] = a;
            ref_stress(rc, F, P);
            if (P[zero][zero] > 0)
                hi = a;
            else
                lo = a;
        }
        const long double a = 0.5L * (lo + hi);
        if (m == CF_MODE_UNIAXIAL)
            F[0] = F[4] = a;
        else
            F[8] = a;
    }
    ref_stress(rc, F, P);
    return P[si][sj];
}

static void cell_with_the_pair_and_the_volume_term_equals_an_independent_reference(void **state)
{
    (void)state;
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    /* kappa 0, 0.3 and 8 times the compression spring's k0/H (nu 0.25, 0.30, 0.46): a kappa
    ** far above the springs' moduli leaves the uniaxial stress a small difference of the volume
    ** term's large lateral and axial parts, known only to its rounding times their ratio */
    const double k0H = law_of(&comp_p).k0_N_per_mm / comp_p.H_mm;
    const double kappas[3] = {0, 0.3 * k0H, 8 * k0H};
    for (int e = 0; e < 2; e++)
        for (int kk = 0; kk < 3; kk++) {
            cf_law comp = law_of(&comp_p), ext = law_of(&ext_p[e]);
            assert_int_equal(cf_law_pair(&comp, &ext, NULL), CF_OK);
            ref_cell rc = {ref_of(&comp_p), ref_of(&ext_p[e]), {w[0], w[1], w[2]}, kappas[kk]};
            const cf_law_method ms[2] = {CF_LAW_EXACT, CF_LAW_CLOSED};
            for (int mi = 0; mi < 2; mi++) {
                cf_cell c;
                assert_int_equal(cf_cell_init(&c, &comp, ms[mi], w, NULL), CF_OK);
                c.volume_modulus_MPa = kappas[kk];
                c.biaxial_k = 0.6;
                for (int md = 0; md < CF_MODE_COUNT; md++) {
                    /* strains to 0.35 (0.7 of the compression spring's travel, 0.39 and 0.64
                    ** of the extension springs': both past their transitions, inside every
                    ** mode's reach); the points near zero strain are rounding, compared to 1e-2
                    ** of the curve's largest stress */
                    const double reach = md == CF_MODE_EQUIBIAXIAL || md == CF_MODE_BIAXIAL ? 0.2 : 0.35; /* free
                    ** stretch grows twice as fast: 0.35 takes the nearly cylindrical extension
                    ** spring to solid */
                    double peak = 0, got[13];
                    long double want[13];
                    for (int i = 0; i < 13; i++) {
                        const double x = reach * (i - 6) / 6.0;
                        cf_cell_state s;
                        cf_error err = {0};
                        if (cf_cell_mode(&c, (cf_mode)md, x, NULL, &s, &err) != CF_OK)
                            fail_msg("%s at %g: %s", cf_mode_name((cf_mode)md), x, err.msg);
                        got[i] = s.stress_MPa;
                        want[i] = ref_mode(&rc, (cf_mode)md, x);
                        peak = fmax(peak, fabs((double)want[i]));
                    }
                    for (int i = 0; i < 13; i++)
                        if (!(fabsl(got[i] - want[i]) <=
                              1e-12L * fmaxl(fabsl(want[i]), 1e-2L * peak)))
                            fail_msg("extension %d, kappa %g, method %d, %s, point %d: cell %.17g, "
                                     "reference %.17Lg",
                                     e, kappas[kk], mi, cf_mode_name((cf_mode)md), i, got[i],
                                     want[i]);
                }
            }
        }
}

static void volume_term_adds_kappa_to_lambda_and_nothing_to_shear(void **state)
{
    (void)state;
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_law law = law_of(&comp_p);
    const double k0H = law.k0_N_per_mm / law.p.H_mm;
    const cf_cubic_moduli cm = cf_cubic_moduli_of(w);
    const double mu = cm.C44 * k0H;
    for (int k = 0; k < 4; k++) {
        const double nu_want = (double[]){0.25, 0.3, 0.45, 0.49}[k];
        const double kappa = cf_cubic_kappa_of_nu(w, k0H, nu_want);
        /* the isotropic lattice: kappa = mu (4 nu - 1)/(1 - 2 nu) */
        assert_close(kappa, mu * (4 * nu_want - 1) / (1 - 2 * nu_want), 1e-12 * (mu + kappa));
        assert_close(cf_cubic_nu_of_kappa(w, k0H, kappa), nu_want, 1e-14);
        cf_cell c;
        assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, w, NULL), CF_OK);
        c.volume_modulus_MPa = kappa;
        const double e = 1e-7;
        cf_cell_state s;
        assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, e, NULL, &s, NULL), CF_OK);
        /* lateral over axial strain: -nu = -(mu + kappa)/(2 (2 mu + kappa)) */
        assert_close((1 - s.free_stretch) / e, (mu + kappa) / (2 * (2 * mu + kappa)), 1e-6);
        assert_close((1 - s.free_stretch) / e, nu_want, 1e-6);
        /* confined: C11 + kappa = lambda + 2 mu + kappa */
        assert_int_equal(cf_cell_mode(&c, CF_MODE_CONFINED, e, NULL, &s, NULL), CF_OK);
        assert_close(s.stress_MPa / e, cm.C11 * k0H + kappa, 1e-6 * (cm.C11 * k0H + kappa));
        /* simple shear: J = 1, the stress of the springs alone to rounding */
        cf_cell c0 = c;
        c0.volume_modulus_MPa = 0;
        for (int i = 1; i <= 5; i++) {
            cf_cell_state s0;
            const double g = 0.02 * i;
            assert_int_equal(cf_cell_mode(&c, CF_MODE_SHEAR, g, NULL, &s, NULL), CF_OK);
            assert_int_equal(cf_cell_mode(&c0, CF_MODE_SHEAR, g, NULL, &s0, NULL), CF_OK);
            assert_true(s.stress_MPa == s0.stress_MPa);
        }
    }
}

/* The tangent of the cell with the pair and the volume term is the derivative of its stress
** (central differences, away from u = 0 where the pair's stiffness jumps). */
static void tangent_with_the_volume_term_is_the_stress_derivative(void **state)
{
    (void)state;
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_law comp = law_of(&comp_p), ext = law_of(&ext_p[1]);
    assert_int_equal(cf_law_pair(&comp, &ext, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &comp, CF_LAW_EXACT, w, NULL), CF_OK);
    c.volume_modulus_MPa = 0.7;
    const double F[9] = {1.04, 0.03, -0.02, 0.01, 0.93, 0.05, -0.03, 0.02, 1.07};
    double A[81];
    cf_cell_state s;
    assert_int_equal(cf_cell_tangent(&c, F, NULL, &s, A, NULL), CF_OK);
    for (int kl = 0; kl < 9; kl++) {
        double Fp[9], Fm[9];
        memcpy(Fp, F, sizeof Fp);
        memcpy(Fm, F, sizeof Fm);
        const double h = 1e-6;
        Fp[kl] += h, Fm[kl] -= h;
        cf_cell_state sp, sm;
        assert_int_equal(cf_cell_stress(&c, Fp, NULL, &sp, NULL), CF_OK);
        assert_int_equal(cf_cell_stress(&c, Fm, NULL, &sm, NULL), CF_OK);
        for (int ij = 0; ij < 9; ij++) {
            const double fd = (sp.P_MPa[ij / 3][ij % 3] - sm.P_MPa[ij / 3][ij % 3]) / (2 * h);
            assert_close(A[9 * ij + kl], fd, 1e-6 * (fabs(fd) + 1));
        }
    }
}

/* The full lattice with a pair at rest stays at rest, and under homogeneous uniaxial loading
** (the lateral springs on the other side of zero from the loaded ones: every Newton solve
** crosses the stiffness jump) equals the cell. */
static void full_lattice_with_the_pair_equals_the_cell(void **state)
{
    (void)state;
    for (int e = 0; e < 2; e++) {
        cf_law comp = law_of(&comp_p), ext = law_of(&ext_p[e]);
        assert_int_equal(cf_law_pair(&comp, &ext, NULL), CF_OK);
        const double sH = fmin(comp.travel_mm, ext.travel_mm) / comp.p.H_mm;
        double x[] = {-0.3 * sH, -0.1 * sH, -1e-6, 0, 1e-6, 0.1 * sH, 0.3 * sH, 0.5 * sH};
        const size_t n = sizeof x / sizeof x[0];
        double w[3];
        assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
        cf_cell c;
        assert_int_equal(cf_cell_init(&c, &comp, CF_LAW_CLOSED, w, NULL), CF_OK);
        double cell[8], full[8];
        cf_error err = {0};
        if (cf_cell_curve(&c, CF_MODE_UNIAXIAL, x, n, cell, &err) != CF_OK)
            fail_msg("cell: %s", err.msg);
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = 2, cfg.lattice.ny = 3, cfg.lattice.nz = 2;
        memcpy(cfg.lattice.weight, w, sizeof w);
        if (cf_msm_uniaxial(&comp, CF_LAW_CLOSED, &cfg, x, n, full, NULL, &err) != CF_OK)
            fail_msg("lattice: %s", err.msg);
        /* the static solve's tolerance is absolute (1e-12 of the springs' loads): a floor of
        ** 1e-10 of the curve's largest stress at the two tiny strains */
        double peak = 0;
        for (size_t i = 0; i < n; i++)
            peak = fmax(peak, fabs(cell[i]));
        for (size_t i = 0; i < n; i++)
            if (!(fabs(cell[i] - full[i]) <= 1e-9 * fabs(cell[i]) + 1e-10 * peak))
                fail_msg("extension %d, strain %g: cell %.17g, lattice %.17g", e, x[i], cell[i],
                         full[i]);
        assert_true(full[3] == 0);
        /* the two sides differ: tension is not the mirror of compression */
        assert_true(fabs(cell[6] + cell[0]) > 1e-3 * fabs(cell[6]));
    }
}

/* The full lattice with the volume term (lattice.h, volume_modulus_MPa): a cell's J is det F under
** a homogeneous F, its volume gradient and Hessian are the derivatives of its volume, and under
** uniaxial loading the lattice with a pair and kappa equals the cell. */
static void full_lattice_with_the_volume_term_equals_the_cell(void **state)
{
    (void)state;
    cf_law comp = law_of(&comp_p), ext = law_of(&ext_p[1]);
    assert_int_equal(cf_law_pair(&comp, &ext, NULL), CF_OK);
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    const double kappa = 3 * comp.k0_N_per_mm / comp.p.H_mm;
    /* the cell's volume under a homogeneous F, and its derivatives by central differences */
    cf_lattice_config lc = cf_lattice_default();
    lc.nx = 2, lc.ny = 1, lc.nz = 2;
    lc.volume_modulus_MPa = kappa;
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, &comp, CF_LAW_CLOSED, &lc, NULL), CF_OK);
    const double F[9] = {1.05, 0.02, -0.03, 0.01, 0.97, 0.04, 0.02, -0.01, 1.1};
    const double detF = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                        F[2] * (F[3] * F[7] - F[4] * F[6]);
    for (size_t p = 0; p < lat.nn; p++) {
        const double X[3] = {lat.X[p], lat.Y[p], lat.Z[p]};
        lat.x[p] = F[0] * X[0] + F[1] * X[1] + F[2] * X[2];
        lat.y[p] = F[3] * X[0] + F[4] * X[1] + F[5] * X[2];
        lat.z[p] = F[6] * X[0] + F[7] * X[1] + F[8] * X[2];
    }
    uint32_t node[8];
    double g[8][3], g2[8][3], hess[8][8][3][3];
    for (size_t c = 0; c < 4; c++)
        assert_close(cf_lattice_cell_volume(&lat, c, node, g, hess), detF, 1e-14);
    /* a non-affine state: move one node, then check g and the Hessian of cell 3 */
    lat.x[node[5]] += 0.7, lat.z[node[2]] -= 0.4;
    const double J0 = cf_lattice_cell_volume(&lat, 3, node, g, hess), H3 = 1000;
    double *coord[3] = {lat.x, lat.y, lat.z};
    for (int b = 0; b < 8; b++)
        for (int k = 0; k < 3; k++) {
            const double h = 1e-4, keep = coord[k][node[b]];
            coord[k][node[b]] = keep + h;
            const double Jp = cf_lattice_cell_volume(&lat, 3, node, g2, NULL);
            double gp[8][3];
            memcpy(gp, g2, sizeof gp);
            coord[k][node[b]] = keep - h;
            const double Jm = cf_lattice_cell_volume(&lat, 3, node, g2, NULL);
            coord[k][node[b]] = keep;
            assert_close(g[b][k], (Jp - Jm) * H3 / (2 * h), 1e-6 * (fabs(g[b][k]) + 1));
            for (int a = 0; a < 8; a++)
                for (int i = 0; i < 3; i++)
                    assert_close(hess[a][b][i][k], (gp[a][i] - g2[a][i]) / (2 * h),
                                 1e-6 * (fabs(hess[a][b][i][k]) + 1));
        }
    (void)J0;
    cf_lattice_free(&lat);
    /* the full lattice against the cell, uniaxial, tension and compression */
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &comp, CF_LAW_CLOSED, w, NULL), CF_OK);
    c.volume_modulus_MPa = kappa;
    double x[] = {-0.3, -0.15, -1e-3, 1e-3, 0.1, 0.3};
    const size_t n = sizeof x / sizeof x[0];
    double cell[6], full[6];
    cf_error err = {0};
    if (cf_cell_curve(&c, CF_MODE_UNIAXIAL, x, n, cell, &err) != CF_OK)
        fail_msg("cell: %s", err.msg);
    const int sizes[2][3] = {{1, 1, 1}, {2, 3, 2}};
    for (int z = 0; z < 2; z++) {
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = sizes[z][0], cfg.lattice.ny = sizes[z][1], cfg.lattice.nz = sizes[z][2];
        memcpy(cfg.lattice.weight, w, sizeof w);
        cfg.lattice.volume_modulus_MPa = kappa;
        if (cf_msm_uniaxial(&comp, CF_LAW_CLOSED, &cfg, x, n, full, NULL, &err) != CF_OK)
            fail_msg("lattice: %s", err.msg);
        /* the static solve's absolute tolerance: a floor of 1e-10 of the largest stress */
        for (size_t i = 0; i < n; i++)
            if (!(fabs(cell[i] - full[i]) <= 1e-9 * fabs(cell[i]) + 1e-10 * fabs(cell[0])))
                fail_msg("%dx%dx%d cells, strain %g: cell %.17g, lattice %.17g", sizes[z][0],
                         sizes[z][1], sizes[z][2], x[i], cell[i], full[i]);
    }
    /* kappa changes the lattice's answer (the comparison is not of two lattices without it) */
    c.volume_modulus_MPa = 0;
    double bare[6];
    assert_int_equal(cf_cell_curve(&c, CF_MODE_UNIAXIAL, x, n, bare, NULL), CF_OK);
    assert_true(fabs(bare[0] - cell[0]) > 1e-3 * fabs(cell[0]));
}

/* The explicit step of a lattice of double-acting elements (lattice_step.c) through both springs'
** vector lanes: for both extension springs, with the closed form (the pair's polynomial when both
** fit, else its closed form), the tables and exact (the scalar law), the node forces of a jittered
** lattice squeezed and stretched (every spring region of both sides seen) equal an independent sum
** over the springs with the exact law of the pair, within 1e-12 of the largest, and the step's
** largest |u| equals it over the smaller travel. */
static void explicit_step_runs_the_pair_through_its_lanes(void **state)
{
    (void)state;
    int lanes_seen[6] = {0};
    for (int ei = 0; ei < 2; ei++) {
        cf_law lc = law_of(&comp_p), le = law_of(&ext_p[ei]);
        cf_error err = {0};
        assert_int_equal(cf_law_table_build(&lc, 4096, &err), CF_OK);
        assert_int_equal(cf_law_table_build(&le, 4096, &err), CF_OK);
        assert_int_equal(cf_law_pair(&lc, &le, &err), CF_OK);
        const cf_law_method methods[3] = {CF_LAW_CLOSED, CF_LAW_TABLE, CF_LAW_EXACT};
        /* the axial springs half way into region 2 of each side */
        const double squeeze[2] = {1 - 0.5 * (lc.u_T_mm + lc.travel_mm) / lc.p.H_mm,
                                   1 + 0.5 * (le.u_T_mm + le.travel_mm) / le.p.H_mm};
        for (int mi = 0; mi < 3; mi++) {
            int seen[2][2] = {{0}}; /* [side][past u_T] over both loadings */
            for (int qi = 0; qi < 2; qi++) {
                cf_lattice_config c = cf_lattice_default();
                c.nx = 4, c.ny = 3, c.nz = 5;
                cf_lattice lat;
                assert_int_equal(cf_lattice_create(&lat, &lc, methods[mi], &c, &err), CF_OK);
                srand((unsigned)(10 * ei + 3 * mi + qi + 1));
                const double jit = 0.01 * fmin(lc.travel_mm - lc.u_T_mm, le.travel_mm - le.u_T_mm);
                for (size_t p = 0; p < lat.nn; p++) {
                    lat.x[p] += jit * (rand() / (double)RAND_MAX - 0.5);
                    lat.y[p] += jit * (rand() / (double)RAND_MAX - 0.5);
                    lat.z[p] = squeeze[qi] * lat.Z[p] + jit * (rand() / (double)RAND_MAX - 0.5);
                }
                double *g = calloc(3 * lat.nn, sizeof(double));
                assert_non_null(g);
                double scale = 0, umax = 0;
                for (size_t q = 0; q < lat.ns; q++) {
                    const uint32_t i = lat.si[q], j = lat.sj[q];
                    const double d[3] = {lat.x[j] - lat.x[i], lat.y[j] - lat.y[i],
                                         lat.z[j] - lat.z[i]};
                    const double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    const double u = (lat.L0_mm[q] - L) * lat.a[q];
                    const cf_law *side = u < 0 ? &le : &lc;
                    assert_true(fabs(u) < side->travel_mm);
                    seen[u < 0][fabs(u) > side->u_T_mm] = 1;
                    umax = fmax(umax, fabs(u));
                    const double T = -lat.w[q] * cf_law_force(&lc, CF_LAW_EXACT, u, NULL, NULL);
                    scale = fmax(scale, fabs(T));
                    for (int a = 0; a < 3; a++) {
                        g[3 * i + a] += T * d[a] / L;
                        g[3 * j + a] -= T * d[a] / L;
                    }
                }
                cf_lattice_stepper st;
                assert_int_equal(cf_lattice_stepper_init(&st, &lat, NULL, &err), CF_OK);
                if (mi == 2)
                    assert_int_equal(st.form, -1);
                else
                    assert_true(st.form == CF_STEP_PAIR_POLY ||
                                st.form == (mi ? CF_STEP_PAIR_TABLE : CF_STEP_PAIR_CLOSED));
                /* the form chosen, then the method's own lanes forced (the polynomial fits these
                ** springs, so the closed form and the tables run only when asked) */
                const int forms[2] = {st.form, mi == 2   ? -1
                                               : mi == 1 ? CF_STEP_PAIR_TABLE
                                                         : CF_STEP_PAIR_CLOSED};
                for (int fi = 0; fi < 2; fi++) {
                    st.form = forms[fi];
                    if (st.form >= CF_STEP_PAIR_CLOSED)
                        lanes_seen[st.form] = 1;
                    memset(lat.fx, 0, lat.nn * sizeof(double));
                    memset(lat.fy, 0, lat.nn * sizeof(double));
                    memset(lat.fz, 0, lat.nn * sizeof(double));
                    assert_close(cf_lattice_stepper_forces(&st), umax / lat.travel_mm, 1e-15);
                    /* the tables' own error (4096 intervals) is far below 1e-10 of the force */
                    const double tol = (st.form == CF_STEP_PAIR_TABLE ? 1e-10 : 1e-12) * scale;
                    for (size_t p = 0; p < lat.nn; p++) {
                        assert_close(lat.fx[p], g[3 * p], tol);
                        assert_close(lat.fy[p], g[3 * p + 1], tol);
                        assert_close(lat.fz[p], g[3 * p + 2], tol);
                    }
                }
                free(g);
                cf_lattice_stepper_free(&st);
                cf_lattice_free(&lat);
            }
            if (!(seen[0][0] && seen[0][1] && seen[1][0] && seen[1][1]))
                fail_msg("extension spring %d: regions seen: compression %d %d, extension %d %d",
                         ei, seen[0][0], seen[0][1], seen[1][0], seen[1][1]);
        }
        cf_law_free(&lc);
        cf_law_free(&le);
    }
    /* every form of the pair's lanes ran */
    assert_true(lanes_seen[CF_STEP_PAIR_POLY] && lanes_seen[CF_STEP_PAIR_CLOSED] &&
                lanes_seen[CF_STEP_PAIR_TABLE]);
    print_message("pair lanes seen: closed %d, table %d, polynomial %d\n",
                  lanes_seen[CF_STEP_PAIR_CLOSED], lanes_seen[CF_STEP_PAIR_TABLE],
                  lanes_seen[CF_STEP_PAIR_POLY]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(equal_springs_give_the_odd_law_bit_for_bit),
        cmocka_unit_test(each_side_is_its_own_spring),
        cmocka_unit_test(cell_with_the_pair_and_the_volume_term_equals_an_independent_reference),
        cmocka_unit_test(volume_term_adds_kappa_to_lambda_and_nothing_to_shear),
        cmocka_unit_test(tangent_with_the_volume_term_is_the_stress_derivative),
        cmocka_unit_test(full_lattice_with_the_pair_equals_the_cell),
        cmocka_unit_test(full_lattice_with_the_volume_term_equals_the_cell),
        cmocka_unit_test(explicit_step_runs_the_pair_through_its_lanes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
