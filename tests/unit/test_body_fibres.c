/*
** Fibre groups in a tissue body (body_fibres.c; src/notes/simulate.md, "Fibres in a body"):
**  - under a homogeneous deformation (a stretch along the fibres, and a general F) the fibres'
**    nodal forces vanish at every inner node and their moment -sum f X^T / V over the block is
**    the closed form P = phi (F a) a^T / lambda, phi = density Hf T / H^3 (fibre.h), and the
**    homogenised cell's stress with the same group less its stress without it, and every
**    node's dual-cell stress (the VTU's) gains the fibres' Cauchy stress F P^T / J, to 1e-9; the
**    same with the group recruited at strain 0.03 (T at Hf (lambda - 1 - 0.03)), and the largest
**    compression over travel (cf_body_fibre_umax) is the group's; a group stretched short of its
**    recruitment strain adds no force;
**  - the assembled tangent with fibres of a helix field, at a non-affine state with the fibres in
**    tension, is the central difference of the forces (1e-6 of its largest entry);
**  - the helix rule turns the direction linearly through the thickness in the plane normal to the
**    normal (1e-12);
**  - a slab with the field, held at its bottom and pressed by a sphere, converges to stable
**    equilibria, and the fibres carry part of the load.
*/
#include "testutil.h"

#include <math.h>

#include "model/body.h"
#include "model/body_internal.h"
#include "model/cell.h"

#define PI 3.14159265358979323846

static cf_law law_of(const cf_spring *p)
{
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, p, &err) != CF_OK)
        fail_msg("%s", err.msg);
    return law;
}

static const cf_spring matrix_spring = {10, 30, 4, 1, 8e4, 40};
static const cf_spring fibre_spring = {10, 30, 4, 1, 8e4, 30};

/* A block of nx x ny x nz cells over [0, lx] x [0, ly] x [0, lz] mm. */
static void block(cf_mesh *m, int nx, int ny, int nz, double lx, double ly, double lz)
{
    double xs[16], ys[16], zs[16];
    for (int i = 0; i <= nx; i++)
        xs[i] = lx * i / nx;
    for (int i = 0; i <= ny; i++)
        ys[i] = ly * i / ny;
    for (int i = 0; i <= nz; i++)
        zs[i] = lz * i / nz;
    cf_error err = {0};
    if (cf_mesh_block(m, xs, nx, ys, ny, zs, nz, &err) != CF_OK || cf_mesh_check(m, "block", &err))
        fail_msg("%s", err.msg);
}

/* The fibres' part of the nodal forces at positions x into f (3 nn). */
static void fibre_part(cf_body *b, const double *x, double *f)
{
    double *g0 = malloc(3 * b->nn * sizeof *g0);
    assert_non_null(g0);
    const size_t nf = b->nfibre;
    b->nfibre = 0;
    assert_false(isnan(cf_body_assemble(b, x, NULL, NULL, 0, NULL, g0, NULL, NULL)));
    b->nfibre = nf;
    assert_false(isnan(cf_body_assemble(b, x, NULL, NULL, 0, NULL, f, NULL, NULL)));
    for (size_t i = 0; i < 3 * b->nn; i++)
        f[i] -= g0[i];
    free(g0);
}

static void homogeneous_case(const double F[9], double slack, double *worst_inner,
                             double *worst_P, double *worst_sigma)
{
    cf_law law = law_of(&matrix_spring), fl = law_of(&fibre_spring);
    cf_mesh m;
    block(&m, 3, 3, 2, 12, 12, 8);
    cf_body b;
    cf_error err = {0};
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err), CF_OK);
    const double an = sqrt(1 + 1 + 0.25), a[3] = {1 / an, 1 / an, 0.5 / an}, density = 2.5;
    double *dir = malloc(3 * b.nt * sizeof *dir), *f = malloc(3 * b.nn * sizeof *f);
    double *x = malloc(3 * b.nn * sizeof *x);
    assert_true(dir && f && x);
    for (size_t t = 0; t < b.nt; t++)
        for (int i = 0; i < 3; i++)
            dir[3 * t + (size_t)i] = a[i];
    assert_int_equal(cf_body_add_fibres(&b, &fibre_spring, density, slack, dir, 0, "fibres[0]", &err),
                     CF_OK);
    for (size_t n = 0; n < b.nn; n++)
        for (int i = 0; i < 3; i++)
            x[3 * n + (size_t)i] = F[3 * i] * b.X[3 * n] + F[3 * i + 1] * b.X[3 * n + 1] +
                                   F[3 * i + 2] * b.X[3 * n + 2];
    fibre_part(&b, x, f);
    /* the closed form */
    double Fa[3];
    for (int i = 0; i < 3; i++)
        Fa[i] = F[3 * i] * a[0] + F[3 * i + 1] * a[1] + F[3 * i + 2] * a[2];
    const double lam = sqrt(Fa[0] * Fa[0] + Fa[1] * Fa[1] + Fa[2] * Fa[2]), H = law.p.H_mm;
    const double Hf = fl.p.H_mm, u = Hf * (lam - 1 - slack);
    const double T = cf_law_force(&fl, CF_LAW_CLOSED, u, NULL, NULL);
    assert_true(u > 0 && T > 0);
    /* the largest compression over travel is the group's at this stretch */
    assert_close(cf_body_fibre_umax(&b, x), u / cf_law_travel_at(&fl, u), 1e-12);
    const double phi = density * Hf * T / (H * H * H * lam);
    double M[9] = {0}, Pmax = 0, fmaxv = 0;
    for (int i = 0; i < 9; i++)
        Pmax = fmax(Pmax, fabs(phi * Fa[i / 3] * a[i % 3]));
    *worst_inner = 0;
    for (size_t n = 0; n < b.nn; n++) {
        const double *X = b.X + 3 * n;
        const int inner = X[0] > 1e-9 && X[0] < 12 - 1e-9 && X[1] > 1e-9 && X[1] < 12 - 1e-9 &&
                          X[2] > 1e-9 && X[2] < 8 - 1e-9;
        for (int i = 0; i < 3; i++) {
            fmaxv = fmax(fmaxv, fabs(f[3 * n + (size_t)i]));
            if (inner)
                *worst_inner = fmax(*worst_inner, fabs(f[3 * n + (size_t)i]));
            for (int j = 0; j < 3; j++)
                M[3 * i + j] += f[3 * n + (size_t)i] * X[j] / (12.0 * 12 * 8);
        }
    }
    *worst_inner /= fmaxv;
    /* the fields: every node's dual-cell stress gains the fibres' Cauchy stress F P^T / J */
    const double J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                     F[2] * (F[3] * F[7] - F[4] * F[6]);
    const double sf[6] = {phi * Fa[0] * Fa[0] / J, phi * Fa[1] * Fa[1] / J, phi * Fa[2] * Fa[2] / J,
                          phi * Fa[0] * Fa[1] / J, phi * Fa[1] * Fa[2] / J, phi * Fa[0] * Fa[2] / J};
    double *ns[2];
    for (int with = 0; with < 2; with++) {
        cf_body_fields q = {malloc(6 * b.nn * sizeof(double)), malloc(6 * b.nt * sizeof(double)),
                            malloc(b.nt * sizeof(double)), malloc(6 * b.nt * sizeof(double)),
                            malloc(b.ns * sizeof(double))};
        assert_true(q.node_stress && q.stress && q.mises && q.strain && q.force);
        b.nfibre = (size_t)with;
        assert_int_equal(cf_body_fields_at(&b, x, &q, &err), CF_OK);
        ns[with] = q.node_stress;
        free(q.stress);
        free(q.mises);
        free(q.strain);
        free(q.force);
    }
    *worst_sigma = 0;
    for (size_t n = 0; n < b.nn; n++)
        for (int k = 0; k < 6; k++)
            *worst_sigma = fmax(*worst_sigma, fabs(ns[1][6 * n + (size_t)k] - ns[0][6 * n + (size_t)k] -
                                                  sf[k]) / (phi * lam * lam / J));
    free(ns[0]);
    free(ns[1]);
    /* the homogenised cell with the same group: its stress with the group less without it */
    const double w[CF_FAMILY_COUNT] = {1, 0.6, 0.6};
    const cf_fibre_group fg = {&fl, CF_LAW_CLOSED, {a[0], a[1], a[2]}, density, slack};
    cf_cell cell;
    cf_cell_state cs[2];
    assert_int_equal(cf_cell_init(&cell, &law, CF_LAW_CLOSED, w, &err), CF_OK);
    cell.fibre = &fg;
    for (int with = 0; with < 2; with++) {
        cell.nfibre = with;
        assert_int_equal(cf_cell_stress(&cell, F, NULL, &cs[with], &err), CF_OK);
    }
    *worst_P = 0;
    for (int i = 0; i < 9; i++) {
        const double Pc = cs[1].P_MPa[i / 3][i % 3] - cs[0].P_MPa[i / 3][i % 3];
        *worst_P = fmax(*worst_P, fabs(M[i] - phi * Fa[i / 3] * a[i % 3]) / Pmax);
        *worst_P = fmax(*worst_P, fabs(M[i] - Pc) / Pmax);
    }
    free(dir);
    free(f);
    free(x);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    cf_law_free(&fl);
}

static void a_homogeneous_block_carries_the_closed_form_fibre_stress(void **state)
{
    (void)state;
    const double an = sqrt(2.25), a[3] = {1 / an, 1 / an, 0.5 / an}, e = 0.08;
    double Fu[9], Fg[9] = {1.05, 0.07, -0.03, 0.02, 0.97, 0.04, -0.05, 0.06, 1.09};
    for (int i = 0; i < 9; i++)
        Fu[i] = (i % 4 == 0) + e * a[i / 3] * a[i % 3]; /* stretch 1.08 along a */
    double inner, dP, ds;
    homogeneous_case(Fu, 0, &inner, &dP, &ds);
    print_message("fibre stretch: inner-node force %.3g of the largest, moment vs P (closed form, cell) %.3g, node "
                  "stress vs F P^T/J %.3g\n", inner, dP, ds);
    assert_true(inner <= 1e-9 && dP <= 1e-9 && ds <= 1e-9);
    homogeneous_case(Fu, 0.03, &inner, &dP, &ds); /* recruited at 0.03: taut from 1.03 on */
    print_message("fibre recruited at 0.03, stretch 1.08: %.3g, %.3g, %.3g\n", inner, dP, ds);
    assert_true(inner <= 1e-9 && dP <= 1e-9 && ds <= 1e-9);
    homogeneous_case(Fg, 0, &inner, &dP, &ds);
    print_message("general F: inner-node force %.3g of the largest, moment vs P (closed form, cell) %.3g, node "
                  "stress vs F P^T/J %.3g\n", inner, dP, ds);
    assert_true(inner <= 1e-9 && dP <= 1e-9 && ds <= 1e-9);
}

/* A block stretched 8 % along its fibres, recruited at 0.1: no fibre force, umax 0. */
static void a_fibre_short_of_its_recruitment_adds_nothing(void **state)
{
    (void)state;
    cf_law law = law_of(&matrix_spring);
    cf_mesh m;
    block(&m, 2, 2, 2, 8, 8, 8);
    cf_body b;
    cf_error err = {0};
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err), CF_OK);
    double *dir = malloc(3 * b.nt * sizeof *dir), *f = malloc(3 * b.nn * sizeof *f);
    double *x = malloc(3 * b.nn * sizeof *x);
    assert_true(dir && f && x);
    for (size_t t = 0; t < b.nt; t++)
        dir[3 * t] = 1, dir[3 * t + 1] = dir[3 * t + 2] = 0;
    assert_int_equal(cf_body_add_fibres(&b, &fibre_spring, 2, 0.1, dir, 0, "fibres[0]", &err),
                     CF_OK);
    for (size_t n = 0; n < 3 * b.nn; n++)
        x[n] = b.X[n] * (n % 3 == 0 ? 1.08 : 1.0);
    fibre_part(&b, x, f);
    for (size_t n = 0; n < 3 * b.nn; n++)
        assert_true(f[n] == 0);
    assert_true(cf_body_fibre_umax(&b, x) == 0);
    assert_int_equal(cf_body_add_fibres(&b, &fibre_spring, 2, 1.0, dir, 0, "fibres[1]", &err),
                     CF_E_DATA);
    assert_non_null(strstr(err.msg, "fibres[1]: recruitment_strain = 1"));
    free(dir);
    free(f);
    free(x);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

/* A slab with the helix field -60 to 60 degrees through z from x, fibres of density 3. */
static void helix_slab(cf_body *b, cf_mesh *m, cf_law *law, int nx, int nz, double lz)
{
    block(m, nx, nx, nz, 20, 20, lz);
    cf_error err = {0};
    const double kappa = cf_body_kappa_for_nu(cf_body_mu_of_law(law), 0.45);
    assert_int_equal(cf_body_create(b, m, law, CF_LAW_CLOSED, kappa, &err), CF_OK);
    double *dir = malloc(3 * b->nt * sizeof *dir);
    assert_non_null(dir);
    const double n[3] = {0, 0, 1}, ref[3] = {1, 0, 0};
    assert_int_equal(cf_body_helix_dirs(b, n, ref, -60, 60, dir, &err), CF_OK);
    assert_int_equal(cf_body_add_fibres(b, &fibre_spring, 3, 0, dir, 0, "fibres[0]", &err), CF_OK);
    free(dir);
}

static void the_tangent_with_fibres_is_the_difference_of_the_forces(void **state)
{
    (void)state;
    cf_law law = law_of(&matrix_spring);
    cf_mesh m;
    cf_body b;
    helix_slab(&b, &m, &law, 2, 1, 5);
    b.kappa_MPa = 0; /* the springs' and the fibres' tangent on the plain pattern */
    const size_t n3 = 3 * b.nn;
    double *x = malloc(n3 * sizeof *x), *g = malloc(n3 * sizeof *g), *gp = malloc(n3 * sizeof *gp);
    double *gm = malloc(n3 * sizeof *gm);
    assert_true(x && g && gp && gm);
    unsigned s = 12345;
    for (size_t i = 0; i < b.nn; i++) /* stretched 10 % in x and y, 5 % thinner, perturbed */
        for (int c = 0; c < 3; c++) {
            s = s * 1103515245u + 12345u;
            const double r = ((s >> 8) & 0xffff) / 65536.0 - 0.5;
            x[3 * i + (size_t)c] = b.X[3 * i + (size_t)c] * (c < 2 ? 1.1 : 0.95) + 0.05 * r;
        }
    assert_true(cf_body_admissible(&b, x));
    assert_true(cf_body_fibre_umax(&b, x) > 0); /* fibres in tension */
    pattern P;
    assert_true(cf_body_pattern_build(&b, &P, 0));
    assert_false(isnan(cf_body_assemble(&b, x, NULL, NULL, 0, NULL, g, &P, NULL)));
    double Kmax = 0, worst = 0;
    for (int k = 0; k < P.colptr[P.n]; k++)
        Kmax = fmax(Kmax, fabs(P.val[k]));
    double *col = calloc(n3, sizeof *col);
    assert_non_null(col);
    const double h = 1e-6 * b.mean_edge_mm;
    for (size_t j = 0; j < n3; j++) {
        const double x0 = x[j];
        x[j] = x0 + h;
        cf_body_assemble(&b, x, NULL, NULL, 0, NULL, gp, NULL, NULL);
        x[j] = x0 - h;
        cf_body_assemble(&b, x, NULL, NULL, 0, NULL, gm, NULL, NULL);
        x[j] = x0;
        memset(col, 0, n3 * sizeof *col);
        for (int k = P.colptr[j]; k < P.colptr[j + 1]; k++)
            col[P.rowidx[k]] = P.val[k];
        for (size_t i = 0; i < n3; i++)
            worst = fmax(worst, fabs(col[i] - (gp[i] - gm[i]) / (2 * h)));
    }
    print_message("tangent with fibres vs central difference: %.3g of its largest entry %.4g N/mm\n",
                  worst / Kmax, Kmax);
    assert_true(worst <= 1e-6 * Kmax);
    free(col);
    free(x);
    free(g);
    free(gp);
    free(gm);
    cf_body_pattern_free(&P);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

static void the_helix_turns_through_the_thickness(void **state)
{
    (void)state;
    cf_law law = law_of(&matrix_spring);
    cf_mesh m;
    cf_body b;
    helix_slab(&b, &m, &law, 2, 4, 5);
    double worst = 0, amin = 90, amax = -90;
    for (size_t t = 0; t < b.nt; t++) {
        double zc = 0;
        for (int k = 0; k < 4; k++)
            zc += b.X[3 * b.tet[4 * t + (size_t)k] + 2] / 4;
        const double th = (-60 + 120 * zc / 5) * PI / 180;
        const double *a = b.fdir + 3 * CF_FIBRE_MAX * t;
        worst = fmax(worst, fabs(a[0] - cos(th)) + fabs(a[1] - sin(th)) + fabs(a[2]));
        amin = fmin(amin, atan2(a[1], a[0]) * 180 / PI);
        amax = fmax(amax, atan2(a[1], a[0]) * 180 / PI);
    }
    print_message("helix: %.3g from the rule; angles %.4g to %.4g degrees\n", worst, amin, amax);
    assert_true(worst <= 1e-12);
    assert_true(amin < -45 && amax > 45);
    cf_error err = {0};
    double dir[3];
    const double n[3] = {0, 0, 1}, bad[3] = {0, 0, 2};
    assert_int_equal(cf_body_helix_dirs(&b, n, bad, -60, 60, dir, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "parallel"));
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

/* The force of a sphere (radius 10 mm) at each of 3 steps to 0.4 mm on the helix slab, with or without fibres. */
static void punch(int fibres, double force[3])
{
    cf_law law = law_of(&matrix_spring);
    cf_mesh m;
    cf_body b;
    cf_error err = {0};
    helix_slab(&b, &m, &law, 8, 4, 5);
    if (!fibres)
        b.nfibre = 0;
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] <= 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    const cf_probe pr = {CF_PROBE_SPHERE, 10, {10, 10, 15.001}, {0, 0, -1}, 0.401, 3, 0};
    for (int k = 1; k <= 3; k++) {
        cf_body_step st = {0};
        if (cf_body_solve(&b, &pr, pr.depth_mm * k / 3, 0, &st, &err) != CF_OK)
            fail_msg("%s", err.msg);
        print_message("fibres %d step %d: %.6g N, %d contacts, %ld negative pivots, %d iterations\n",
                      fibres, k, st.force_N, st.contacts, st.neg_pivots, st.newton_iters);
        assert_true(st.contacts > 0);
        assert_int_equal(st.neg_pivots, 0);
        assert_true(st.max_u_over_travel < 1);
        force[k - 1] = st.force_N;
    }
    if (!fibres)
        b.nfibre = 1;
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

static void a_pressed_fibre_slab_is_stiffer(void **state)
{
    (void)state;
    double f0[3], f1[3];
    punch(0, f0);
    punch(1, f1);
    print_message("sphere 0.4 mm: %.6g N without fibres, %.6g N with the helix field\n", f0[2],
                  f1[2]);
    for (int k = 0; k < 3; k++)
        assert_true(f1[k] > f0[k] * 1.001 && (k == 0 || f1[k] > f1[k - 1]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_homogeneous_block_carries_the_closed_form_fibre_stress),
        cmocka_unit_test(a_fibre_short_of_its_recruitment_adds_nothing),
        cmocka_unit_test(the_tangent_with_fibres_is_the_difference_of_the_forces),
        cmocka_unit_test(the_helix_turns_through_the_thickness),
        cmocka_unit_test(a_pressed_fibre_slab_is_stiffer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
