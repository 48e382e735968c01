/*
** Tests of tissue bodies (conifit/body.h, conifit/mesh.h): meshes read with Gmsh and refused when
** they are not volumes or hold degenerate or inverted elements; the calibrated network's measured
** small-strain E and nu against the reported ones; load propagation against contact mechanics
** (Hertz's sphere and Boussinesq's flat punch on a half-space) at nu = 0.25 and 0.45, on two
** meshes, the finer one closer; and a probe deep into the fitted law's nonlinear range.
*/
#include "testutil.h"

#include "conifit/body.h"
#include "conifit/mesh.h"

TU_SCRATCH_GROUP("body")

/* The spring of the tests: a telescoping cone (k0/H gives E0 = 6.25 kPa). */
static cf_law test_law(void)
{
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    return law;
}

static void write_text(const char *name, const char *text, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* A Gmsh 2.2 file of one tetrahedron per element line given. */
#define MSH_HEAD "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n" \
                 "4 0 0 1\n5 1 1 1\n$EndNodes\n$Elements\n"

static void bad_meshes_are_refused_naming_file_and_element(void **state)
{
    (void)state;
    static const struct {
        const char *name, *text, *must;
        cf_status st;
    } cases[] = {
        {"surface.msh", MSH_HEAD "1\n1 2 2 0 1 1 2 3\n$EndElements\n", "not a volume mesh",
         CF_E_DATA},
        {"inverted.msh", MSH_HEAD "3\n1 4 2 0 1 1 2 3 4\n2 4 2 0 1 2 3 4 5\n7 4 2 0 1 2 4 3 5\n"
                                  "$EndElements\n",
         "element 7 is inverted", CF_E_DATA},
        {"flat.msh",
         "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
         "4 1 1 0\n$EndNodes\n$Elements\n1\n9 4 2 0 1 1 2 3 4\n$EndElements\n",
         "element 9 is degenerate", CF_E_DATA},
        {"garbage.msh", "$MeshFormat\nthis is not a mesh\n", "garbage.msh", CF_E_DATA},
        {"script.geo", "Point(1) = {0, 0, 0};\n", "not a mesh file name", CF_E_DATA},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char path[600];
        write_text(cases[k].name, cases[k].text, path, sizeof path);
        cf_mesh m;
        cf_error err = {0};
        cf_status st = cf_mesh_read(path, 1, &m, &err);
        if (st != cases[k].st || !strstr(err.msg, cases[k].must) || !strstr(err.msg, path))
            fail_msg("%s: status %d, message '%s'; expected '%s'", cases[k].name, st, err.msg,
                     cases[k].must);
    }
    cf_mesh m;
    cf_error err = {0};
    char path[600];
    snprintf(path, sizeof path, "%s/absent.msh", dir);
    assert_int_equal(cf_mesh_read(path, 1, &m, &err), CF_E_NOINPUT);
    /* a good file: two tetrahedra, one given with the other orientation is still inverted;
    ** both negatively oriented are renumbered */
    write_text("good.msh", MSH_HEAD "2\n1 4 2 0 1 1 3 2 4\n2 4 2 0 1 2 4 3 5\n$EndElements\n", path,
               sizeof path);
    if (cf_mesh_read(path, 10, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(m.nn, 5);
    assert_int_equal(m.nt, 2);
    assert_close(m.X[3 * 4], 10, 0); /* node 5 at (1, 1, 1) times unit_mm 10 */
    cf_mesh_free(&m);
}

static void liver_meshes_are_read_when_present(void **state)
{
    (void)state;
    FILE *f = fopen("../shared/meshes/liver2.msh", "r");
    if (!f)
        skip(); /* ../shared/meshes absent: nothing to read */
    fclose(f);
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_read("../shared/meshes/liver2.msh", 100, &m, &err), CF_OK);
    assert_int_equal(m.nn, 507);
    assert_int_equal(m.nt, 1493);
    cf_mesh_free(&m);
    assert_int_equal(cf_mesh_read("../shared/meshes/liver.msh", 10, &m, &err), CF_OK);
    assert_int_equal(m.nt, 596);
    cf_mesh_free(&m);
}

static void the_block_generator_gives_conforming_positive_tetrahedra(void **state)
{
    (void)state;
    double g[4] = {0, 1, 3, 4};
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, g, 3, g, 3, g, 3, NULL), CF_OK);
    assert_int_equal(m.nn, 64);
    assert_int_equal(m.nt, 6 * 27);
    assert_int_equal(cf_mesh_check(&m, "block", NULL), CF_OK);
    /* volumes add up to the box's: no overlap, no gap */
    double V = 0;
    for (size_t t = 0; t < m.nt; t++) {
        const double *p[4];
        for (int k = 0; k < 4; k++)
            p[k] = m.X + 3 * m.tet[4 * t + k];
        double u[3], v[3], w[3];
        for (int a = 0; a < 3; a++) {
            u[a] = p[1][a] - p[0][a];
            v[a] = p[2][a] - p[0][a];
            w[a] = p[3][a] - p[0][a];
        }
        double v6 = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                    u[2] * (v[0] * w[1] - v[1] * w[0]);
        assert_true(v6 > 0);
        V += v6 / 6;
    }
    assert_close(V, 64, 1e-12);
    cf_mesh_free(&m);
    double bad[3] = {0, 1, 1};
    cf_error err = {0};
    assert_int_equal(cf_mesh_block(&m, bad, 2, g, 3, g, 3, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "along x"));
}

/* Uniaxial stretch of a Gmsh-meshed cube with lubricated faces: the measured E and nu against the
** reported ones. */
static void measure_uniaxial(double nu, double *E_ratio, double *nu_meas, double *nu_rep)
{
    cf_law law = test_law();
    double lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10}, f[3] = {5, 5, 5};
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, f, 1, 1, 0, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_body b;
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                                    cf_body_kappa_for_nu(cf_body_mu_of_law(&law), nu), &err),
                     CF_OK);
    const double eps = 1e-4, tol = 1e-9;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] |= (X[0] < tol) | (X[1] < tol) << 1 | (X[2] < tol) << 2;
        if (X[2] > 10 - tol) {
            b.fix[i] |= 4;
            b.x[3 * i + 2] = X[2] * (1 - eps);
        }
    }
    cf_probe none = {0};
    none.dir[2] = 1;
    cf_body_step st;
    assert_int_equal(cf_body_solve(&b, &none, 0, 0, &st, &err), CF_OK);
    double *g = malloc(3 * b.nn * sizeof *g);
    assert_non_null(g);
    assert_int_equal(cf_body_internal_force(&b, g, &err), CF_OK);
    double F = 0, lat = 0;
    int nl = 0;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        if (X[2] > 10 - tol)
            F -= g[3 * i + 2];
        if (X[0] > 10 - tol) {
            lat += b.x[3 * i] - X[0];
            nl++;
        }
    }
    *E_ratio = F / 100 / eps / b.E_MPa;
    *nu_meas = lat / nl / 10 / eps;
    *nu_rep = b.nu;
    free(g);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

static void the_network_has_the_reported_small_strain_moduli(void **state)
{
    (void)state;
    const double nus[2] = {0.25, 0.45};
    for (int k = 0; k < 2; k++) {
        double Er, num, nur;
        measure_uniaxial(nus[k], &Er, &num, &nur);
        print_message("uniaxial, nu %.2f: measured E / reported %.4f, nu %.4f (reported %.4f)\n",
                      nus[k], Er, num, nur);
        assert_close(nur, nus[k], 1e-12);
        assert_close(Er, 1, 0.05);
        assert_close(num, nur, 0.03);
    }
}

/* A quarter of a half-space (symmetry planes x = 0 and y = 0, bottom held) meshed finer towards
** the contact at refinement r, probed by a sphere of radius R to depth d (punch: a flat punch of
** radius R); returns the force over the analytic one for the body's reported E and nu. */
static double half_space(int punch, double nu, double r)
{
    cf_law law = test_law();
    const double W = 30, D = 30, R = punch ? 2 : 10, d = punch ? 0.01 : 0.1;
    double lo[3] = {0, 0, -D}, hi[3] = {W, W, 0}, f[3] = {0, 0, 0};
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_box(lo, hi, f, 0.3 / r, 8 / r, 0.4 / r, &m, &err), CF_OK);
    cf_body b;
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                                    cf_body_kappa_for_nu(cf_body_mu_of_law(&law), nu), &err),
                     CF_OK);
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] = (X[0] < 1e-9) | (X[1] < 1e-9) << 1;
        if (X[2] < -D + 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    }
    cf_probe pr = {0};
    pr.shape = punch ? CF_PROBE_PUNCH : CF_PROBE_SPHERE;
    pr.radius_mm = R;
    pr.dir[2] = -1;
    pr.center_mm[2] = punch ? 0 : R;
    assert_int_equal(cf_body_probe_inside(&b, &pr), -1);
    cf_body_step st;
    for (int k = 1; k <= 2; k++)
        if (cf_body_solve(&b, &pr, d * k / 2, 0, &st, &err) != CF_OK)
            fail_msg("%s", err.msg);
    assert_true(st.min_J > 0);
    const double Es = b.E_MPa / (1 - b.nu * b.nu);
    const double analytic = punch ? 2 * R * d * Es : 4.0 / 3 * Es * sqrt(R) * pow(d, 1.5);
    const double ratio = 4 * st.force_N / analytic;
    print_message("%s, nu %.2f, refinement %.0f: %zu nodes, %d in contact, force / analytic "
                  "%.4f\n",
                  punch ? "Boussinesq punch" : "Hertz sphere", nu, r, b.nn, st.contacts, ratio);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    return ratio;
}

static void contact_converges(int punch, double nu)
{
    double coarse = half_space(punch, nu, 1), fine = half_space(punch, nu, 2);
    assert_close(fine, 1, 0.10);
    assert_true(fabs(fine - 1) < fabs(coarse - 1));
}

static void hertz_sphere_nu_025(void **state)
{
    (void)state;
    contact_converges(0, 0.25);
}

static void hertz_sphere_nu_045(void **state)
{
    (void)state;
    contact_converges(0, 0.45);
}

static void boussinesq_punch_nu_025(void **state)
{
    (void)state;
    contact_converges(1, 0.25);
}

static void boussinesq_punch_nu_045(void **state)
{
    (void)state;
    contact_converges(1, 0.45);
}

static void a_probe_inside_the_body_is_found(void **state)
{
    (void)state;
    double g[3] = {0, 1, 2};
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, g, 2, g, 2, g, 2, NULL), CF_OK);
    cf_law law = test_law();
    cf_body b;
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, NULL), CF_OK);
    cf_probe pr = {CF_PROBE_SPHERE, 0.5, {1, 1, 2.6}, {0, 0, -1}, 1, 1};
    assert_int_equal(cf_body_probe_inside(&b, &pr), -1);
    pr.center_mm[2] = 2.3; /* the top centre node (1, 1, 2) is 0.3 from it */
    assert_int_equal(cf_body_probe_inside(&b, &pr), 1 + 3 * 1 + 9 * 2);
    cf_body_free(&b);
    cf_error err = {0};
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, -1, &err), CF_E_DATA);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bad_meshes_are_refused_naming_file_and_element),
        cmocka_unit_test(liver_meshes_are_read_when_present),
        cmocka_unit_test(the_block_generator_gives_conforming_positive_tetrahedra),
        cmocka_unit_test(the_network_has_the_reported_small_strain_moduli),
        cmocka_unit_test(hertz_sphere_nu_025),
        cmocka_unit_test(hertz_sphere_nu_045),
        cmocka_unit_test(boussinesq_punch_nu_025),
        cmocka_unit_test(boussinesq_punch_nu_045),
        cmocka_unit_test(a_probe_inside_the_body_is_found),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
