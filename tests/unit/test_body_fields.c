/*
** The stress and strain fields of a body (cf_body_fields_at): at any state the tetrahedra's
** stresses times their volumes sum to the virial of the nodal forces (every spring and the volume
** term counted once, with its sign); a rigid motion stresses and strains nothing; the strain is
** the Green-Lagrange strain of an affine deformation; on rollers the mean stress is the support
** force over the area (and what E it gives, printed). The uniaxial block against sigma = E eps is
** tests/cli/test_cli_vtu.c's (read back from the ParaView files).
*/
#include "bodyutil.h"
#include "testutil.h"

#include "model/body.h"
#include "io/mesh.h"

static cf_law test_law(void)
{
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    return law;
}

typedef struct fields {
    cf_body_fields f;
} fields;

static void fields_alloc(const cf_body *b, fields *q)
{
    q->f.node_stress = malloc(6 * b->nn * sizeof(double));
    q->f.stress = malloc(6 * b->nt * sizeof(double));
    q->f.strain = malloc(6 * b->nt * sizeof(double));
    q->f.mises = malloc(b->nt * sizeof(double));
    q->f.force = malloc(b->ns * sizeof(double));
    assert_true(q->f.node_stress && q->f.stress && q->f.strain && q->f.mises && q->f.force);
}

static void fields_free(fields *q)
{
    free(q->f.node_stress);
    free(q->f.stress);
    free(q->f.strain);
    free(q->f.mises);
    free(q->f.force);
}

/* The cube 10 x 10 x 10 mm meshed by Gmsh at element size h. */
static void cube(cf_mesh *m, double h)
{
    double lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10}, f[3] = {5, 5, 5};
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, f, h, h, 0, m, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

static void make_body(cf_body *b, cf_mesh *m, const cf_law *law, double h, double nu)
{
    cube(m, h);
    cf_error err = {0};
    assert_int_equal(cf_body_create(b, m, law, CF_LAW_CLOSED,
                                    cf_body_kappa_for_nu(cf_body_mu_of_law(law), nu), &err),
                     CF_OK);
}

/* Six times a tetrahedron's volume at x. */
static double vol(const cf_body *b, const double *x, size_t t)
{
    const uint32_t *v = b->tet + 4 * t;
    double u[3][3];
    for (int m = 0; m < 3; m++)
        for (int a = 0; a < 3; a++)
            u[m][a] = x[3 * v[m + 1] + a] - x[3 * v[0] + a];
    return (u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) -
            u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0]) +
            u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0])) / 6;
}

/* At a state far from rest (every node moved at random by up to 3 % of the mean edge, then the
** block stretched 20 % along x), the tetrahedra's stresses times their current volumes sum to
** the virial sum_i x_i (x) g_i of the elastic nodal forces, component by component: every
** spring's force and the volume term's pressure are counted once, with the right sign. */
static void the_stresses_sum_to_the_virial_of_the_nodal_forces(void **state)
{
    (void)state;
    cf_law law = test_law();
    cf_mesh m;
    cf_body b;
    make_body(&b, &m, &law, 2, 0.45);
    unsigned seed = 12345;
    for (size_t q = 0; q < 3 * b.nn; q++) {
        seed = seed * 1103515245u + 12345u;
        const double r = ((seed >> 8) & 0xffff) / 65535.0 - 0.5;
        b.x[q] = b.X[q] * (q % 3 == 0 ? 1.2 : 1) + 0.06 * r * b.mean_edge_mm;
    }
    fields q;
    fields_alloc(&b, &q);
    assert_int_equal(cf_body_fields_at(&b, b.x, &q.f, NULL), CF_OK);
    double *g = malloc(3 * b.nn * sizeof *g);
    assert_non_null(g);
    assert_int_equal(cf_body_internal_force(&b, g, NULL), CF_OK);
    static const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    double worst = 0, scale = 0;
    for (int k = 0; k < 6; k++) {
        double vir = 0, sum = 0;
        for (size_t i = 0; i < b.nn; i++)
            vir += b.x[3 * i + ij[k][0]] * g[3 * i + ij[k][1]];
        for (size_t t = 0; t < b.nt; t++)
            sum += vol(&b, b.x, t) * q.f.stress[6 * t + k];
        scale = fmax(scale, fabs(vir));
        worst = fmax(worst, fabs(sum - vir));
    }
    print_message("virial: largest component %.6g N mm, largest departure %.3g N mm\n", scale,
                  worst);
    assert_true(scale > 0);
    assert_true(worst < 1e-9 * scale);
    free(g);
    fields_free(&q);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

/* A rigid rotation stresses nothing and strains nothing; an affine stretch gives every
** tetrahedron the Green-Lagrange strain of its deformation gradient. */
static void rotations_are_stress_free_and_the_strain_is_green_lagranges(void **state)
{
    (void)state;
    cf_law law = test_law();
    cf_mesh m;
    cf_body b;
    make_body(&b, &m, &law, 2.5, 0.45);
    const double c = cos(0.7), s = sin(0.7);
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.x[3 * i] = c * X[0] - s * X[1] + 3;
        b.x[3 * i + 1] = s * X[0] + c * X[1] - 2;
        b.x[3 * i + 2] = X[2] + 1;
    }
    fields q;
    fields_alloc(&b, &q);
    assert_int_equal(cf_body_fields_at(&b, b.x, &q.f, NULL), CF_OK);
    double smax = 0, emax = 0, fmax_ = 0;
    for (size_t t = 0; t < b.nt; t++) {
        smax = fmax(smax, q.f.mises[t]);
        for (int k = 0; k < 6; k++)
            emax = fmax(emax, fabs(q.f.strain[6 * t + k]));
    }
    for (size_t sp = 0; sp < b.ns; sp++)
        fmax_ = fmax(fmax_, fabs(q.f.force[sp]));
    assert_true(smax < 1e-9 * b.E_MPa);
    assert_true(emax < 1e-12);
    assert_true(fmax_ < 1e-9 * b.E_MPa * b.mean_edge_mm * b.mean_edge_mm);
    /* x = F X with F = [[1.1, 0.2, 0], [0, 0.9, 0], [0.05, 0, 1.3]]: E = (F^T F - I)/2 */
    const double F[3][3] = {{1.1, 0.2, 0}, {0, 0.9, 0}, {0.05, 0, 1.3}};
    for (size_t i = 0; i < b.nn; i++)
        for (int a = 0; a < 3; a++)
            b.x[3 * i + a] = F[a][0] * b.X[3 * i] + F[a][1] * b.X[3 * i + 1] +
                             F[a][2] * b.X[3 * i + 2];
    assert_int_equal(cf_body_fields_at(&b, b.x, &q.f, NULL), CF_OK);
    static const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    for (int k = 0; k < 6; k++) {
        double E = 0;
        for (int a = 0; a < 3; a++)
            E += F[a][ij[k][0]] * F[a][ij[k][1]];
        E = (E - (ij[k][0] == ij[k][1])) / 2;
        for (size_t t = 0; t < b.nt; t++)
            assert_close(q.f.strain[6 * t + k], E, 1e-12);
    }
    fields_free(&q);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

/* A 10 mm block on rollers compressed 1e-4 along z (free to expand sideways), meshed by Gmsh at
** h (h 0: Kuhn's cells, n per side, of cf_mesh_block): the volume mean of the tetrahedra's sigma_zz
** is the top's support force over its area (the virial of the boundary's forces), and the lateral
** means vanish. Returns the mean sigma_zz over E eps, E the body's calibrated modulus. */
static double rollers(int n, double h, double nu)
{
    cf_law law = test_law();
    cf_mesh m;
    if (h > 0)
        cube(&m, h);
    else {
        double g[17];
        for (int i = 0; i <= n; i++)
            g[i] = 10.0 * i / n;
        assert_int_equal(cf_mesh_block(&m, g, n, g, n, g, n, NULL), CF_OK);
    }
    cf_body b;
    cf_error err = {0};
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                                    cf_body_kappa_for_nu(cf_body_mu_of_law(&law), nu), &err),
                     CF_OK);
    const double eps = -1e-4, tol = 1e-9;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] |= (X[0] < tol) | (X[1] < tol) << 1 | (X[2] < tol) << 2;
        if (X[2] > 10 - tol) {
            b.fix[i] |= 4;
            b.x[3 * i + 2] = X[2] * (1 + eps);
        }
    }
    b.reaction = calloc(3 * b.nn, sizeof *b.reaction);
    assert_non_null(b.reaction);
    cf_probe none = {0};
    none.dir[2] = 1;
    cf_body_step st;
    assert_int_equal(cf_body_solve(&b, &none, 0, 0, &st, &err), CF_OK);
    fields q;
    fields_alloc(&b, &q);
    assert_int_equal(cf_body_fields_at(&b, b.x, &q.f, &err), CF_OK);
    double F = 0, V = 0, s[3] = {0, 0, 0};
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] > 10 - tol)
            F += b.reaction[3 * i + 2];
    for (size_t t = 0; t < b.nt; t++) {
        const double v = vol(&b, b.x, t);
        V += v;
        for (int k = 0; k < 3; k++)
            s[k] += v * q.f.stress[6 * t + k];
    }
    for (int k = 0; k < 3; k++)
        s[k] /= V;
    const double ratio = s[2] / (b.E_MPa * eps);
    print_message("%s, nu %.2f, %zu nodes: mean sigma_zz / (E eps) %.4f\n",
                  h > 0 ? "Gmsh cube" : "Kuhn block", nu, b.nn, ratio);
    assert_close(s[2], F / (V / (10 * (1 + eps))), 1e-4 * fabs(s[2])); /* the mean section */
    if (!(fabs(s[0]) < 1e-5 * fabs(s[2]) && fabs(s[1]) < 1e-5 * fabs(s[2]))) /* Newton's tolerance */
        fail_msg("lateral %g %g of %g", s[0], s[1], s[2]);
    fields_free(&q);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    return ratio;
}

static void on_rollers_the_mean_stress_is_the_support_force(void **state)
{
    (void)state;
    assert_close(rollers(0, 1, 0.25), 1, 0.02);
    rollers(0, 2, 0.25);
    rollers(0, 1, 0.45);
    /* the Kuhn block: its network is much stiffer along the axes than its isotropic part */
    assert_true(rollers(4, 0, 0.25) > 1.3);
    rollers(4, 0, 0.45);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_stresses_sum_to_the_virial_of_the_nodal_forces),
        cmocka_unit_test(rotations_are_stress_free_and_the_strain_is_green_lagranges),
        cmocka_unit_test(on_rollers_the_mean_stress_is_the_support_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
