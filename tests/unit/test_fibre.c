/*
** Fibre groups in the homogenised cell (model/fibre.c, cell.c's cf_cell_load_state):
**  - the cell's analytic tangent with two fibre groups along a turned frame is the central
**    difference of its stress at a general F (1e-6 relative);
**  - a fibre group adds exactly density Hf T(lambda) / (H^3 lambda) (F a) a^T, T the law's force at
**    u = Hf (lambda - 1), and nothing while lambda <= 1 (slack); a group recruited at strain s
**    nothing up to 1 + s, then the same with u = Hf (lambda - 1 - s), its tangent the stress's
**    central difference; the other cases run with the sheet group recruited at 0.01;
**  - without fibres, every mode placed on the frame's axes (cf_cell_load_state) is the cell's own
**    mode (cf_cell_mode) to 1e-12 relative;
**  - with fibres, each free stretch zeroes its stress (1e-12 of the loaded stress), biaxial rows
**    of both directions and simple shear in all six planes of the fibre frame: in mode (fs) the
**    fibre adds phi gamma to the shear stress, in (sf) nothing (the fibre keeps its length);
**  - the full lattice with the same fibre groups (2 x 3 x 2 cells, volume term), placed at the
**    cell's F of a biaxial row (either direction) or a simple shear in any of the six planes, with
**    the frame on the lattice's axes and turned: no force on any node off its faces, and its
**    nodal forces' moment -sum f X^T / V is the cell's nominal stress, 1e-9 relative;
**  - the static solvers' tangent (msm_tangent.c) carries the fibre groups: at a perturbed state of
**    a turned frame its Newton direction dx gives dR/dx dx = -R (central differences, 1e-6);
**  - the solver itself (cf_msm_newton, the one of `conifit simulate`) takes a 3 x 3 x 3 lattice
**    whose faces are held at the cell's F, its inner nodes displaced, back to the homogeneous
**    state: inner nodes at F X and the nodal moment the cell's stress, 1e-9 relative, and the
**    tangent there positive definite (no negative pivot), in biaxial and shear rows, frame on
**    the axes and turned.
*/
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/cell.h"
#include "model/family.h"
#include "model/fibre.h"
#include "model/lattice.h"
#include "model/msm.h"
#include "model/msm_internal.h"

typedef struct fixture {
    cf_law matrix, fib, sheet;
    cf_fibre_group g[2];
    cf_cell cell;
} fixture;

static void make_law(cf_law *law, double rho, double solid, double scale)
{
    const cf_ident q = {.rho = rho, .solid = solid, .scale = scale};
    cf_spring p = cf_ident_member(&q);
    cf_error err = {0};
    if (cf_law_init(law, &p, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

/* A matrix lattice with kappa, a fibre group along f and one along s of the frame R (rows), the
** second recruited at strain 0.01 (slack below stretch 1.01). */
static void setup_cell(fixture *x, const double R[9], int nfibre)
{
    const double w[CF_FAMILY_COUNT] = {1, 0.6, 0.6};
    make_law(&x->matrix, 0.6, 0.3, 2e-3);
    make_law(&x->fib, 0.4, 0.25, 8e-3);
    make_law(&x->sheet, 0.7, 0.35, 3e-3);
    assert_int_equal(cf_cell_init(&x->cell, &x->matrix, CF_LAW_CLOSED, w, NULL), CF_OK);
    x->cell.volume_modulus_MPa = 5e-3;
    memcpy(x->cell.frame, R, sizeof x->cell.frame);
    x->g[0] = (cf_fibre_group){&x->fib, CF_LAW_CLOSED, {R[0], R[1], R[2]}, 1.0};
    x->g[1] = (cf_fibre_group){&x->sheet, CF_LAW_CLOSED, {R[3], R[4], R[5]}, 0.5, 0.01};
    for (int k = 0; k < 2; k++)
        assert_int_equal(cf_fibre_check(&x->g[k], NULL), CF_OK);
    x->cell.fibre = x->g;
    x->cell.nfibre = nfibre;
}

/* A frame turned about z by 30 degrees and then about x by 20. */
static void turned(double R[9])
{
    const double a = 30 * M_PI / 180, b = 20 * M_PI / 180;
    const double Rz[9] = {cos(a), sin(a), 0, -sin(a), cos(a), 0, 0, 0, 1};
    const double Rx[9] = {1, 0, 0, 0, cos(b), sin(b), 0, -sin(b), cos(b)};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            R[3 * i + j] = 0;
            for (int k = 0; k < 3; k++)
                R[3 * i + j] += Rz[3 * i + k] * Rx[3 * k + j];
        }
}

static void tangent_is_the_difference_of_the_stress(void **state)
{
    (void)state;
    fixture x;
    double R[9];
    turned(R);
    setup_cell(&x, R, 2);
    const double F[9] = {1.08, 0.05, -0.02, 0.03, 1.04, 0.06, 0.01, -0.04, 0.93};
    double A[81];
    cf_cell_state s, sp, sm;
    cf_error err = {0};
    if (cf_cell_tangent(&x.cell, F, NULL, &s, A, &err) != CF_OK)
        fail_msg("%s", err.msg);
    double Fa[3];
    assert_true(cf_fibre_stretch(&x.g[0], F, Fa) > 1.01); /* both groups taut */
    assert_true(cf_fibre_stretch(&x.g[1], F, Fa) > 1.005 + x.g[1].slack);
    const double h = 1e-6;
    double amax = 0;
    for (int i = 0; i < 81; i++)
        amax = fmax(amax, fabs(A[i]));
    for (int kl = 0; kl < 9; kl++) {
        double Fp[9], Fm[9];
        memcpy(Fp, F, sizeof Fp);
        memcpy(Fm, F, sizeof Fm);
        Fp[kl] += h, Fm[kl] -= h;
        assert_int_equal(cf_cell_stress(&x.cell, Fp, NULL, &sp, NULL), CF_OK);
        assert_int_equal(cf_cell_stress(&x.cell, Fm, NULL, &sm, NULL), CF_OK);
        for (int ij = 0; ij < 9; ij++) {
            const double fd = ((&sp.P_MPa[0][0])[ij] - (&sm.P_MPa[0][0])[ij]) / (2 * h);
            assert_close(A[9 * ij + kl], fd, 1e-6 * amax);
        }
    }
}

static void a_group_adds_its_closed_form(void **state)
{
    (void)state;
    fixture x;
    double R[9];
    turned(R);
    setup_cell(&x, R, 1);
    cf_cell plain = x.cell;
    plain.nfibre = 0;
    const double Fs[2][9] = {{1.08, 0.05, -0.02, 0.03, 1.04, 0.06, 0.01, -0.04, 0.93},
                             {0.95, 0.01, 0, 0, 1.02, 0, 0.02, 0, 1.01}};
    for (int c = 0; c < 2; c++) {
        cf_cell_state a, b;
        assert_int_equal(cf_cell_stress(&x.cell, Fs[c], NULL, &a, NULL), CF_OK);
        assert_int_equal(cf_cell_stress(&plain, Fs[c], NULL, &b, NULL), CF_OK);
        double Fa[3];
        const double l = cf_fibre_stretch(&x.g[0], Fs[c], Fa), Hf = x.fib.p.H_mm, H = 1;
        const double T = l > 1 ? cf_law_force(&x.fib, CF_LAW_CLOSED, Hf * (l - 1), NULL, NULL) : 0;
        if (c == 0)
            assert_true(l > 1 && T > 0);
        else
            assert_true(l < 1); /* slack: the fibre adds nothing */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                const double want = Hf * T / (H * H * H * l) * Fa[i] * x.g[0].dir[j];
                assert_close(a.P_MPa[i][j] - b.P_MPa[i][j], want, 1e-13);
            }
    }
}

/* A group recruited at strain s adds nothing up to stretch 1 + s and then the closed form with
** u = Hf (lambda - 1 - s); its tangent there is the difference of its stress. */
static void a_recruited_group_is_slack_until_its_strain(void **state)
{
    (void)state;
    fixture x;
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    setup_cell(&x, I, 1);
    x.g[0].slack = 0.03;
    assert_int_equal(cf_fibre_check(&x.g[0], NULL), CF_OK);
    cf_cell plain = x.cell;
    plain.nfibre = 0;
    const double lam[4] = {1.02, 1.0299, 1.04, 1.07}, Hf = x.fib.p.H_mm;
    for (int c = 0; c < 4; c++) {
        const double F[9] = {lam[c], 0.01, 0, 0, 0.99, 0, 0, 0, 1.0};
        cf_cell_state a, b;
        assert_int_equal(cf_cell_stress(&x.cell, F, NULL, &a, NULL), CF_OK);
        assert_int_equal(cf_cell_stress(&plain, F, NULL, &b, NULL), CF_OK);
        double Fa[3];
        const double l = cf_fibre_stretch(&x.g[0], F, Fa);
        const double T = l > 1.03 ? cf_law_force(&x.fib, CF_LAW_CLOSED, Hf * (l - 1.03), NULL,
                                                 NULL)
                                  : 0;
        assert_true(c < 2 ? T == 0 : T > 0);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                assert_close(a.P_MPa[i][j] - b.P_MPa[i][j], Hf * T / (l * 1.0) * Fa[i] *
                             x.g[0].dir[j], 1e-13);
        if (c < 3)
            continue;
        double A[81] = {0};
        assert_int_equal(cf_fibre_add_tangent(&x.g[0], 1.0, F, A, NULL), CF_OK);
        for (int kl = 0; kl < 9; kl++) {
            const double h = 1e-6;
            double Fp[9], Fm[9], Pp[3][3] = {{0}}, Pm[3][3] = {{0}}, Tp, Tm, r;
            memcpy(Fp, F, sizeof Fp);
            memcpy(Fm, F, sizeof Fm);
            Fp[kl] += h, Fm[kl] -= h;
            assert_int_equal(cf_fibre_add_stress(&x.g[0], 1.0, Fp, Pp, &Tp, &r, NULL), CF_OK);
            assert_int_equal(cf_fibre_add_stress(&x.g[0], 1.0, Fm, Pm, &Tm, &r, NULL), CF_OK);
            for (int ij = 0; ij < 9; ij++)
                assert_close(A[9 * ij + kl], (Pp[ij / 3][ij % 3] - Pm[ij / 3][ij % 3]) / (2 * h),
                             1e-6 * fabs(A[0]));
        }
    }
    x.g[0].slack = 1.0;
    assert_int_equal(cf_fibre_check(&x.g[0], NULL), CF_E_DATA);
    x.g[0].slack = -0.01;
    assert_int_equal(cf_fibre_check(&x.g[0], NULL), CF_E_DATA);
}

static void loads_without_fibres_are_the_cells_modes(void **state)
{
    (void)state;
    fixture x;
    const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    setup_cell(&x, I, 0);
    x.cell.biaxial_k = 0.6;
    const cf_cell_load loads[6] = {{CF_MODE_UNIAXIAL, {2, 0}, 0}, {CF_MODE_SHEAR, {2, 0}, 0},
                                   {CF_MODE_PLANAR, {0, 1}, 0},   {CF_MODE_EQUIBIAXIAL, {0, 1}, 0},
                                   {CF_MODE_CONFINED, {2, 0}, 0}, {CF_MODE_BIAXIAL, {0, 1}, 0.6}};
    const double es[4] = {-0.08, 0.03, 0.1, 0.15};
    for (int m = 0; m < 6; m++)
        for (int i = 0; i < 4; i++) {
            cf_cell_state a, b;
            cf_error err = {0};
            if (cf_cell_mode(&x.cell, loads[m].mode, es[i], NULL, &a, &err) != CF_OK)
                fail_msg("%s", err.msg);
            if (cf_cell_load_state(&x.cell, &loads[m], es[i], &b, &err) != CF_OK)
                fail_msg("%s", err.msg);
            assert_close(b.stress_MPa, a.stress_MPa, 1e-12 * fabs(a.stress_MPa));
            assert_close(b.free_stretch, a.free_stretch, 1e-12);
        }
}

/* P' = R P R^T, component (a, b). */
static double in_frame(const double R[9], const cf_cell_state *s, int a, int b)
{
    double v = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            v += R[3 * a + i] * s->P_MPa[i][j] * R[3 * b + j];
    return v;
}

static void fibre_modes_in_every_plane(void **state)
{
    (void)state;
    fixture x;
    double R[9];
    turned(R);
    setup_cell(&x, R, 2);
    cf_cell bare = x.cell;
    bare.nfibre = 0;
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 3; q++) {
            if (p == q)
                continue;
            const int r = 3 - p - q;
            for (double e = 0.02; e < 0.13; e += 0.05) {
                const cf_cell_load bi = {CF_MODE_BIAXIAL, {p, q}, 0.75};
                cf_cell_state s, t;
                cf_error err = {0};
                if (cf_cell_load_state(&x.cell, &bi, e, &s, &err) != CF_OK)
                    fail_msg("biaxial %d%d at %g: %s", p, q, e, err.msg);
                assert_close(in_frame(R, &s, r, r), 0, 1e-12 * fabs(s.stress_MPa));
                assert_close(s.stress_MPa, in_frame(R, &s, p, p), 1e-15);
                const cf_cell_load uni = {CF_MODE_UNIAXIAL, {p, q}, 0};
                if (cf_cell_load_state(&x.cell, &uni, e, &s, &err) != CF_OK)
                    fail_msg("uniaxial %d at %g: %s", p, e, err.msg);
                assert_close(in_frame(R, &s, q, q), 0, 1e-12 * fabs(s.stress_MPa));
                assert_close(in_frame(R, &s, r, r), 0, 1e-12 * fabs(s.stress_MPa));
                /* simple shear (pq): the f group adds phi gamma when p = f, q = s ... */
                const cf_cell_load sh = {CF_MODE_SHEAR, {p, q}, 0};
                const double g = 4 * e;
                assert_int_equal(cf_cell_load_state(&x.cell, &sh, g, &s, NULL), CF_OK);
                assert_int_equal(cf_cell_load_state(&bare, &sh, g, &t, NULL), CF_OK);
                double add = 0;
                for (int k = 0; k < 2; k++) /* group k along axis k: stretched when p = k */
                    if (p == k) {
                        const double l = sqrt(1 + g * g), Hf = x.g[k].law->p.H_mm;
                        const double u = Hf * (l - 1 - x.g[k].slack);
                        const double T = u > 0 ? cf_law_force(x.g[k].law, CF_LAW_CLOSED, u, NULL,
                                                              NULL)
                                               : 0;
                        add += x.g[k].density * Hf * T / l * g;
                    }
                assert_close(s.stress_MPa - t.stress_MPa, add, 1e-13);
                if (p == 0 || (p == 1 && sqrt(1 + g * g) > 1 + x.g[1].slack))
                    assert_true(add > 0);
            }
        }
}

/* The lattice config of x's laws and groups: nx x ny x nz cells, no hourglass control. */
static cf_lattice_config fibre_lattice(const fixture *x, int nx, int ny, int nz)
{
    cf_lattice_config lc = cf_lattice_default();
    lc.nx = nx, lc.ny = ny, lc.nz = nz;
    lc.volume_modulus_MPa = x->cell.volume_modulus_MPa;
    lc.hourglass = 0;
    memcpy(lc.weight, x->cell.weight, sizeof lc.weight);
    lc.fibre = x->cell.fibre;
    lc.nfibre = x->cell.nfibre;
    return lc;
}

/* Every node p of lat at F X_p. */
static void place_at(cf_lattice *lat, const double F[9])
{
    for (size_t p = 0; p < lat->nn; p++) {
        const double X[3] = {lat->X[p], lat->Y[p], lat->Z[p]};
        lat->x[p] = F[0] * X[0] + F[1] * X[1] + F[2] * X[2];
        lat->y[p] = F[3] * X[0] + F[4] * X[1] + F[5] * X[2];
        lat->z[p] = F[6] * X[0] + F[7] * X[1] + F[8] * X[2];
    }
}

/* Deterministic numbers in [-1, 1]. */
static double rnd(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return ((*s >> 8) & 0xffff) / 32767.5 - 1.0;
}

/* The lattice of x's laws and groups at the cell's state s: checks node by node. */
static void lattice_is_the_cell(const fixture *x, const cf_cell_state *s, const char *what)
{
    cf_lattice_config lc = fibre_lattice(x, 2, 3, 2);
    cf_lattice lat;
    cf_error err = {0};
    if (cf_lattice_create(&lat, &x->matrix, CF_LAW_CLOSED, &lc, &err) != CF_OK)
        fail_msg("%s", err.msg);
    place_at(&lat, s->F);
    cf_lattice_forces(&lat);
    const double H = x->matrix.p.H_mm, ext[3] = {lc.nx * H, lc.ny * H, lc.nz * H};
    double big = 0, M[3][3] = {{0}}, pmax = 0;
    for (size_t p = 0; p < lat.nn; p++)
        big = fmax(big, fabs(lat.fx[p]) + fabs(lat.fy[p]) + fabs(lat.fz[p]));
    for (size_t p = 0; p < lat.nn; p++) {
        const double X[3] = {lat.X[p], lat.Y[p], lat.Z[p]}, f[3] = {lat.fx[p], lat.fy[p], lat.fz[p]};
        int inside = 1;
        for (int i = 0; i < 3; i++)
            inside &= X[i] != 0 && X[i] != ext[i];
        for (int i = 0; i < 3 && inside; i++)
            if (!(fabs(f[i]) <= 1e-9 * big))
                fail_msg("%s: inner node %zu carries %g N along %d (largest %g N)", what, p, f[i],
                         i, big);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                M[i][j] -= f[i] * X[j] / (ext[0] * ext[1] * ext[2]);
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            pmax = fmax(pmax, fabs(s->P_MPa[i][j]));
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!(fabs(M[i][j] - s->P_MPa[i][j]) <= 1e-9 * pmax))
                fail_msg("%s: P[%d][%d] of the lattice %.17g, of the cell %.17g", what, i, j,
                         M[i][j], s->P_MPa[i][j]);
    cf_lattice_free(&lat);
}

static void cell_equals_the_full_lattice(void **state)
{
    (void)state;
    for (int turn = 0; turn < 2; turn++) {
        fixture x;
        double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        if (turn)
            turned(R);
        setup_cell(&x, R, 2);
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++) {
                if (p == q)
                    continue;
                char what[64];
                cf_cell_state s;
                const cf_cell_load bi = {CF_MODE_BIAXIAL, {p, q}, 0.75}, sh = {CF_MODE_SHEAR,
                                                                              {p, q}, 0};
                assert_int_equal(cf_cell_load_state(&x.cell, &bi, 0.08, &s, NULL), CF_OK);
                snprintf(what, sizeof what, "biaxial %d%d, frame %d", p, q, turn);
                lattice_is_the_cell(&x, &s, what);
                assert_int_equal(cf_cell_load_state(&x.cell, &sh, 0.3, &s, NULL), CF_OK);
                snprintf(what, sizeof what, "shear %d%d, frame %d", p, q, turn);
                lattice_is_the_cell(&x, &s, what);
            }
    }
}

/* The lattice solver's tangent with fibres: at a state off equilibrium (a biaxial row of a turned
** frame, every free node moved), the Newton direction dx = K^-1 R satisfies dR/dx dx = -R. */
static void lattice_tangent_carries_the_fibres(void **state)
{
    (void)state;
    fixture x;
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    turned(R);
    setup_cell(&x, R, 2);
    cf_msm_config cfg = cf_msm_default();
    cfg.lattice = fibre_lattice(&x, 2, 3, 2);
    cf_lattice lat;
    cf_error err = {0};
    assert_int_equal(cf_lattice_create(&lat, &x.matrix, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const cf_cell_load bi = {CF_MODE_BIAXIAL, {0, 1}, 0.75};
    cf_cell_state cs;
    assert_int_equal(cf_cell_load_state(&x.cell, &bi, 0.08, &cs, NULL), CF_OK);
    solver s;
    assert_int_equal(cf_msm_solver_init(&s, &lat, NULL, &cfg, CF_DRIVE_DISPLACEMENT, NULL, &err),
                     CF_OK);
    place_at(&lat, cs.F);
    unsigned seed = 7;
    double *co[3] = {lat.x, lat.y, lat.z};
    const double H = lat.H_mm;
    for (size_t p = 0; p < lat.nn; p++)
        for (int a = 0; a < 3; a++)
            if (s.eq[3 * p + a] >= 0)
                co[a][p] += 0.01 * H * rnd(&seed);
    double rn, fs;
    cf_msm_residual(&s, &rn, &fs);
    const size_t n = s.ndof;
    double *R0 = malloc(n * sizeof *R0), *Rp = malloc(n * sizeof *Rp), *dx = malloc(n * sizeof *dx);
    assert_non_null(R0);
    assert_non_null(Rp);
    assert_non_null(dx);
    memcpy(R0, s.R, n * sizeof *R0);
    if (cf_msm_direction(&s, &err) != CF_OK)
        fail_msg("%s", err.msg);
    memcpy(dx, s.dx, n * sizeof *dx);
    double dmax = 0;
    for (size_t e = 0; e < n; e++)
        dmax = fmax(dmax, fabs(dx[e]));
    const double eps = 1e-5 * H / dmax;
    for (int sgn = 0; sgn < 2; sgn++) {
        const double step = sgn ? -2 * eps : eps; /* +eps, then -eps */
        for (size_t p = 0; p < lat.nn; p++)
            for (int a = 0; a < 3; a++)
                if (s.eq[3 * p + a] >= 0)
                    co[a][p] += step * dx[s.eq[3 * p + a]];
        cf_msm_residual(&s, &rn, &fs);
        if (!sgn)
            memcpy(Rp, s.R, n * sizeof *Rp);
    }
    double num = 0, den = 0;
    for (size_t e = 0; e < n; e++) {
        const double d = (Rp[e] - s.R[e]) / (2 * eps) + R0[e];
        num += d * d;
        den += R0[e] * R0[e];
    }
    if (!(sqrt(num / den) < 1e-6))
        fail_msg("|dR/dx dx + R| / |R| = %.3g", sqrt(num / den));
    free(R0);
    free(Rp);
    free(dx);
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
}

/* One solve: the 3 x 3 x 3 lattice's faces held at the cell's F (state cs), its inner nodes moved
** off F X, then Newton; the inner nodes come back to F X, the nodal moment is the cell's stress
** (both 1e-9 relative) and the tangent there has no negative pivot. */
static void solver_returns_to_the_cell(const fixture *x, const cf_cell_state *cs, const char *what)
{
    cf_msm_config cfg = cf_msm_default();
    cfg.lattice = fibre_lattice(x, 3, 3, 3);
    cfg.newton_rtol = 1e-13;
    cf_lattice lat;
    cf_error err = {0};
    assert_int_equal(cf_lattice_create(&lat, &x->matrix, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const double H = lat.H_mm, ext = 3 * H;
    for (size_t p = 0; p < lat.nn; p++) {
        const double X[3] = {lat.X[p], lat.Y[p], lat.Z[p]};
        int inside = 1;
        for (int i = 0; i < 3; i++)
            inside &= X[i] != 0 && X[i] != ext;
        lat.fix[p] = inside ? 0 : 7; /* every axis of a face node held */
    }
    place_at(&lat, cs->F);
    solver s;
    assert_int_equal(cf_msm_solver_init(&s, &lat, NULL, &cfg, CF_DRIVE_DISPLACEMENT, NULL, &err),
                     CF_OK);
    assert_int_equal(s.ndof, 24); /* the 8 inner nodes */
    unsigned seed = 3;
    double *co[3] = {lat.x, lat.y, lat.z};
    for (size_t p = 0; p < lat.nn; p++)
        for (int a = 0; a < 3; a++)
            if (s.eq[3 * p + a] >= 0)
                co[a][p] += 0.02 * H * rnd(&seed);
    if (cf_msm_newton(&s, &err) != CF_OK)
        fail_msg("%s: %s", what, err.msg);
    double rn, fs;
    cf_msm_residual(&s, &rn, &fs);
    if (cf_msm_direction(&s, &err) != CF_OK)
        fail_msg("%s: %s", what, err.msg);
    if (s.neg_pivots != 0)
        fail_msg("%s: %ld negative pivots", what, s.neg_pivots);
    const double *F = cs->F;
    for (size_t p = 0; p < lat.nn; p++) {
        const double X[3] = {lat.X[p], lat.Y[p], lat.Z[p]}, xp[3] = {lat.x[p], lat.y[p], lat.z[p]};
        for (int i = 0; i < 3; i++) {
            const double want = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
            if (!(fabs(xp[i] - want) <= 1e-9 * H))
                fail_msg("%s: node %zu axis %d at %.17g mm, F X %.17g mm", what, p, i, xp[i], want);
        }
    }
    cf_lattice_forces(&lat);
    double M[3][3] = {{0}}, pmax = 0;
    for (size_t p = 0; p < lat.nn; p++) {
        const double X[3] = {lat.X[p], lat.Y[p], lat.Z[p]}, f[3] = {lat.fx[p], lat.fy[p], lat.fz[p]};
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                M[i][j] -= f[i] * X[j] / (ext * ext * ext);
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            pmax = fmax(pmax, fabs(cs->P_MPa[i][j]));
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!(fabs(M[i][j] - cs->P_MPa[i][j]) <= 1e-9 * pmax))
                fail_msg("%s: P[%d][%d] of the solved lattice %.17g MPa, of the cell %.17g MPa", what,
                         i, j, M[i][j], cs->P_MPa[i][j]);
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
}

static void solver_reaches_the_cell_with_fibres(void **state)
{
    (void)state;
    for (int turn = 0; turn < 2; turn++) {
        fixture x;
        double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        if (turn)
            turned(R);
        setup_cell(&x, R, 2);
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++) {
                if (p == q)
                    continue;
                char what[64];
                cf_cell_state cs;
                const cf_cell_load bi = {CF_MODE_BIAXIAL, {p, q}, 0.75}, sh = {CF_MODE_SHEAR,
                                                                              {p, q}, 0};
                assert_int_equal(cf_cell_load_state(&x.cell, &bi, 0.08, &cs, NULL), CF_OK);
                snprintf(what, sizeof what, "biaxial %d%d, frame %d", p, q, turn);
                solver_returns_to_the_cell(&x, &cs, what);
                assert_int_equal(cf_cell_load_state(&x.cell, &sh, 0.3, &cs, NULL), CF_OK);
                snprintf(what, sizeof what, "shear %d%d, frame %d", p, q, turn);
                solver_returns_to_the_cell(&x, &cs, what);
            }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tangent_is_the_difference_of_the_stress),
        cmocka_unit_test(a_group_adds_its_closed_form),
        cmocka_unit_test(a_recruited_group_is_slack_until_its_strain),
        cmocka_unit_test(loads_without_fibres_are_the_cells_modes),
        cmocka_unit_test(fibre_modes_in_every_plane),
        cmocka_unit_test(cell_equals_the_full_lattice),
        cmocka_unit_test(lattice_tangent_carries_the_fibres),
        cmocka_unit_test(solver_reaches_the_cell_with_fibres),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
