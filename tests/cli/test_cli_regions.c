/*
** Regions of a body in `conifit simulate` (scene keys "fixed", "displaced", "loaded"; selectors
** below, above, box, sphere, group): a block whose top is displaced uniformly, free to expand
** sideways, gives the homogenised cell's uniaxial stress; a loaded region's force comes back
** as the supports' reaction, and a uniform traction on a free top gives the body's E; the liver's
** physical group (of ../shared/meshes/liver2.msh, skipped when absent) is its boundary; a
** region that selects nothing, two selectors, and two displacements of one component are refused
** with exit 65 naming the key, and nothing is written.
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

#include "model/body.h"
#include "model/calibration.h"
#include "model/cell.h"
#include "io/mesh.h"

TU_SCRATCH_GROUP("cli-regions")

/* The bottom on rollers (z held), x and y of the corner at the origin and y of the corner at
** x = 10 held: the cube is free to expand sideways, as the homogenised cell in uniaxial mode. */
#define ROLLERS                                                                                    \
    "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}, \"by_mm\": [null, null, 0]},\n"             \
    "{\"box\": {\"min_mm\": [0, 0, 0], \"max_mm\": [0, 0, 0]}, \"by_mm\": [0, 0, null]},\n"      \
    "{\"box\": {\"min_mm\": [10, 0, 0], \"max_mm\": [10, 0, 0]}, \"by_mm\": [null, 0, null]}"

/* Reads the CSV at path: its header into head (cap bytes) and up to maxrows rows of ncol numbers
** into v (row-major). Returns the number of rows. */
static int read_csv(const char *path, char *head, size_t cap, double *v, int ncol, int maxrows)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(head, (int)cap, f));
    char line[4096];
    int n = 0;
    while (n < maxrows && fgets(line, sizeof line, f)) {
        char *p = line;
        for (int c = 0; c < ncol; c++) {
            char *e;
            v[n * ncol + c] = strtod(p, &e);
            assert_true(e != p);
            p = *e == ',' ? e + 1 : e;
        }
        n++;
    }
    fclose(f);
    return n;
}

static void a_cube_displaced_at_the_top_gives_the_cells_uniaxial_stress(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/uniaxial.json", dir);
    snprintf(csv, sizeof csv, "%s/uniaxial.csv", dir);
    write_cube(mesh, 1.25);
    const double strain = -0.1; /* 10 % compression: into the law's stiffening */
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"steps\": 10},\n"
            " \"displaced\": [" ROLLERS ",\n"
            "  {\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"by_mm\": [null, null, %g]}]}\n",
            mesh, strain * 10);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    double v[11 * 13];
    assert_int_equal(read_csv(csv, head, sizeof head, v, 13, 11), 11);
    assert_non_null(strstr(head, "load_factor,displaced0_Fx_N"));
    assert_non_null(strstr(head, "displaced3_Fz_N\n"));
    /* the homogenised cell of the same spring (isotropic weights, no volume term: nu = 1/4, the
    ** body's) */
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    cf_cell cell;
    double w[CF_FAMILY_COUNT];
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    assert_int_equal(cf_cell_init(&cell, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
    double worst = 0, s_end = 0, c_end = 0, s_1 = 0, c_1 = 0;
    for (int k = 1; k <= 10; k++) {
        const double e = strain * v[k * 13];
        cf_cell_state cs;
        assert_int_equal(cf_cell_mode(&cell, CF_MODE_UNIAXIAL, e, NULL, &cs, NULL), CF_OK);
        const double body = v[k * 13 + 12] / 100; /* the top's support force over its area */
        worst = fmax(worst, fabs(body / cs.stress_MPa - 1));
        /* equilibrium: the bottom's rollers carry what the top's support applies */
        assert_close(v[k * 13 + 3] + v[k * 13 + 12], 0, 1e-6 * fabs(v[k * 13 + 12]));
        if (k == 1) {
            s_1 = body;
            c_1 = cs.stress_MPa;
        }
        s_end = body;
        c_end = cs.stress_MPa;
    }
    print_message("uniaxial cube (Gmsh, h 1.25 mm): stress at 1 %% %.5g kPa, cell %.5g kPa; at "
                  "10 %% %.5g kPa, cell %.5g kPa (secant over 10 x the first: %.3f, cell %.3f); worst "
                  "departure %.2f %%\n",
                  s_1 * 1e3, c_1 * 1e3, s_end * 1e3, c_end * 1e3, s_end / s_1 / 10,
                  c_end / c_1 / 10, 100 * worst);
    assert_true(worst < 0.06);
    cf_law_free(&law);
}

/* Parses "region KEY: N nodes; at the end support force [a, b, c] N" from the summary. */
static int region_line(const char *out, const char *key, double v[3])
{
    char pat[200];
    snprintf(pat, sizeof pat, "region %s:", key);
    const char *s = strstr(out, pat);
    if (!s)
        return -1;
    int n = 0;
    s = strstr(s, ": ") + 2;
    if (sscanf(s, "%d nodes", &n) != 1)
        return -1;
    s = strchr(s, '[');
    if (!s || sscanf(s, "[%lf, %lf, %lf]", &v[0], &v[1], &v[2]) != 3)
        return -1;
    return n;
}

static void a_loaded_top_is_carried_by_the_supports_and_gives_the_bodys_E(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/loaded.json", dir);
    snprintf(csv, sizeof csv, "%s/loaded.csv", dir);
    write_cube(mesh, 1.25);
    /* a small uniform traction on the top (linear range), a lateral pull on a sphere inside */
    const double F[3] = {0, 0, -2e-3}, Fs[3] = {1e-4, -2e-4, 0};
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"steps\": 2},\n"
            " \"displaced\": [" ROLLERS "],\n"
            " \"loaded\": [{\"above\": {\"normal\": [0, 0, 2], \"point_mm\": [3, 3, 10]}, "
            "\"force_N\": [%g, %g, %g]},\n"
            "  {\"sphere\": {\"center_mm\": [5, 5, 5], \"radius_mm\": 2}, \"force_N\": [%g, %g, "
            "%g]}]}\n",
            mesh, F[0], F[1], F[2], Fs[0], Fs[1], Fs[2]);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    double sup[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        char key[40];
        double r[3];
        snprintf(key, sizeof key, "displaced[%d].%s", k, k ? "box" : "below");
        assert_true(region_line(out, key, r) > 0);
        for (int a = 0; a < 3; a++)
            sup[a] += r[a];
    }
    /* the supports carry the applied forces: sum of the two loads, opposite */
    for (int a = 0; a < 3; a++) /* the summary's 6 digits */
        assert_close(sup[a], -(F[a] + Fs[a]), 1e-5 * 2e-3);
    /* the top's mean displacement under the uniform traction 2e-5 MPa: -sigma/E H (the lateral
    ** pull on the inside adds nothing to the top's mean z to first order) */
    double v[3 * 16];
    assert_int_equal(read_csv(csv, head, sizeof head, v, 16, 3), 3);
    assert_non_null(strstr(head, ",displaced2_Fz_N,loaded0_ux_mm,loaded0_uy_mm,loaded0_uz_mm,"
                                 "loaded1_ux_mm,loaded1_uy_mm,loaded1_uz_mm\n"));
    const char *s = strstr(out, "body: E = ");
    assert_non_null(s);
    double E_kPa, nu;
    assert_int_equal(sscanf(s, "body: E = %lf kPa, nu = %lf", &E_kPa, &nu), 2);
    const double expect = F[2] / 100 / (E_kPa * 1e-3) * 10;
    print_message("loaded cube: supports [%.6g, %.6g, %.6g] N against applied [%.6g, %.6g, %.6g] "
                  "N; top's mean uz %.6g mm, -sigma H / E %.6g mm (%.2f %%)\n",
                  sup[0], sup[1], sup[2], F[0] + Fs[0], F[1] + Fs[1], F[2] + Fs[2], v[2 * 16 + 12],
                  expect, 100 * (v[2 * 16 + 12] / expect - 1));
    assert_close(v[2 * 16 + 12] / expect, 1, 0.08);
    assert_close(v[1 * 16 + 12] / v[2 * 16 + 12], 0.5, 0.01); /* linear: half at half the load */
}

static void the_livers_physical_group_is_its_boundary(void **state)
{
    (void)state;
    const char *path = "../shared/meshes/liver2.msh";
    struct stat sb;
    if (stat(path, &sb) != 0)
        skip(); /* the shared meshes are absent */
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_read(path, 100, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    /* liver2.msh's elements carry physical numbers: its triangles and lines 1, its tetrahedra 2 */
    assert_true(m.ngroups >= 2);
    /* the boundary nodes: corners of the tetrahedra's faces met once */
    uint8_t *bnd = calloc(m.nn, 1), *sel = calloc(m.nn, 1), *all = calloc(m.nn, 1);
    assert_true(bnd && sel && all);
    static const int fv[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    uint64_t *key = malloc(4 * m.nt * 2 * sizeof *key);
    assert_non_null(key);
    for (size_t t = 0; t < m.nt; t++)
        for (int k = 0; k < 4; k++) {
            uint32_t c[3];
            for (int j = 0; j < 3; j++)
                c[j] = m.tet[4 * t + (size_t)fv[k][j]];
            for (int p = 0; p < 2; p++)
                for (int j = 0; j < 2 - p; j++)
                    if (c[j] > c[j + 1]) {
                        uint32_t x = c[j];
                        c[j] = c[j + 1];
                        c[j + 1] = x;
                    }
            key[2 * (4 * t + (size_t)k)] = ((uint64_t)c[0] << 32) | c[1];
            key[2 * (4 * t + (size_t)k) + 1] = c[2];
        }
    size_t nb = 0;
    for (size_t a = 0; a < 4 * m.nt; a++) {
        int twice = 0;
        for (size_t b = 0; b < 4 * m.nt && !twice; b++)
            twice = b != a && key[2 * a] == key[2 * b] && key[2 * a + 1] == key[2 * b + 1];
        if (!twice) {
            bnd[key[2 * a] >> 32] = bnd[key[2 * a] & 0xffffffffu] = bnd[key[2 * a + 1]] = 1;
        }
    }
    for (size_t i = 0; i < m.nn; i++)
        nb += bnd[i];
    cf_select s = {.kind = CF_SELECT_GROUP, .group_tag = 1, .group_dim = 2};
    size_t n = cf_mesh_select(&m, &s, sel);
    cf_select s3 = {.kind = CF_SELECT_GROUP, .group_tag = 2, .group_dim = -1};
    size_t n3 = cf_mesh_select(&m, &s3, all);
    cf_select none = {.kind = CF_SELECT_GROUP, .group_tag = 7, .group_dim = -1};
    uint8_t *z = calloc(m.nn, 1);
    assert_non_null(z);
    print_message("liver2.msh: %zu groups; group 1 (dim 2) %zu nodes, boundary %zu nodes; group 2 "
                  "%zu of %zu nodes\n",
                  m.ngroups, n, nb, n3, m.nn);
    assert_int_equal(n, nb);
    for (size_t i = 0; i < m.nn; i++)
        assert_int_equal(sel[i], bnd[i]);
    assert_int_equal(n3, m.nn);
    assert_int_equal(cf_mesh_select(&m, &none, z), 0);
    free(z);
    free(key);
    free(bnd);
    free(sel);
    free(all);
    cf_mesh_free(&m);
}

static void a_liver_pulled_by_its_group_and_a_sphere_is_carried_by_its_support(void **state)
{
    (void)state;
    struct stat sb;
    if (stat("../shared/meshes/liver2.msh", &sb) != 0)
        skip();
    char scene[600], csv[600], out[8192], err[8192];
    snprintf(scene, sizeof scene, "%s/liver.json", dir);
    snprintf(csv, sizeof csv, "%s/liver.csv", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    /* held below z = -60 mm; the whole surface (group 1) pushed down by 0.05 N, and the flat
    ** punch of the shipped scene pressed 2 mm */
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"../shared/meshes/liver2.msh\", "
               "\"unit_mm\": 100, \"poisson_ratio\": 0.45},\n"
               " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": -60}},\n"
               " \"loaded\": {\"group\": {\"tag\": 1, \"dim\": 2}, \"force_N\": [0, 0, -0.05]},\n"
               " \"probe\": {\"shape\": \"punch\", \"radius_mm\": 20, \"center_mm\": [77.56, "
               "3.07, 45.93], \"direction\": [0, 0, -1], \"depth_mm\": 2, \"steps\": 4}}\n");
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    double r[3], l[3];
    assert_true(region_line(out, "fixed.below", r) > 0);
    int n = region_line(out, "loaded.group", l);
    assert_true(n > 100);
    FILE *c = fopen(csv, "r");
    assert_non_null(c);
    char line[4096];
    double depth = 0, force = 0;
    assert_non_null(fgets(line, sizeof line, c));
    assert_string_equal(line, "depth_mm,force_N,loaded_ux_mm,loaded_uy_mm,loaded_uz_mm\n");
    while (fgets(line, sizeof line, c))
        assert_int_equal(sscanf(line, "%lf,%lf", &depth, &force), 2);
    fclose(c);
    print_message("liver2: group 1 loaded over %d nodes, punch %.6g N at %g mm; support [%.6g, "
                  "%.6g, %.6g] N\n", n, force, depth, r[0], r[1], r[2]);
    assert_close(depth, 2, 1e-12);
    assert_true(force > 0);
    /* the support carries the load (0.05 N down) and the punch's force (down) */
    assert_close(r[0], 0, 1e-10);
    assert_close(r[1], 0, 1e-10);
    assert_close(r[2], 0.05 + force, 1e-5 * (0.05 + force)); /* the summary's 6 digits */
    assert_true(l[2] < 0);
}

static void bad_regions_are_refused_naming_the_key_and_write_nothing(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/bad.json", dir);
    snprintf(csv, sizeof csv, "%s/bad.csv", dir);
    write_cube(mesh, 2.5);
    static const struct {
        const char *regions, *must;
    } cases[] = {
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"displaced\": [{\"box\": "
         "{\"min_mm\": [20, 20, 20], \"max_mm\": [30, 30, 30]}, \"by_mm\": [1, 0, 0]}]",
         "'displaced[0].box' selects no node"},
        {"\"fixed\": {\"sphere\": {\"center_mm\": [5, 5, 5], \"radius_mm\": 1}, \"below\": "
         "{\"axis\": \"z\", \"value_mm\": 0}}, \"loaded\": {\"group\": 1, \"force_N\": [0, 0, 1]}",
         "two selectors"},
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"loaded\": {\"group\": 1, "
         "\"force_N\": [0, 0, 1]}",
         "'loaded.group' selects no node"},
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"displaced\": {\"below\": "
         "{\"axis\": \"z\", \"value_mm\": 1}, \"by_mm\": [0, 0, 1]}",
         "keys 'fixed' and 'displaced' hold the z component"},
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"displaced\": {\"above\": "
         "{\"axis\": \"z\", \"value_mm\": 10}, \"by_mm\": [null, null, null]}",
         "'displaced.by_mm' prescribes no component"},
        {"\"loaded\": {\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, 1]}",
         "missing key 'fixed'"},
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}",
         "missing key 'probe'"},
        {"\"fixed\": {\"box\": {\"min_mm\": [0, 0, 0], \"max_mm\": [10, -1, 10]}}, \"loaded\": "
         "{\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, 1]}",
         "'fixed.box': max_mm[1] = -1 is below min_mm[1] = 0"},
        {"\"fixed\": {\"below\": {\"normal\": [0, 0, 0], \"point_mm\": [0, 0, 0]}}, \"loaded\": "
         "{\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, 1]}",
         "'fixed.below.normal' = [0, 0, 0]"},
        {"\"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"loaded\": {\"above\": "
         "{\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, 1], \"by_mm\": [0, 0, 1]}",
         "unknown key 'loaded.by_mm'"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f, "{" SPRING ", \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1}, %s}\n", mesh,
                cases[k].regions);
        fclose(f);
        int rc = tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv);
        if (rc != 65 || !strstr(err, cases[k].must))
            fail_msg("case %zu: exit %d, expected 65 with \"%s\"; stderr: %s", k, rc,
                     cases[k].must, err);
        struct stat sb;
        assert_true(stat(csv, &sb) != 0);
    }
}

/* Runs the cube on rollers probed by a sphere from above, to `drive` ("depth_mm": D or
** "force_N": F) in 4 steps; reads the CSV's depth and force into d[5], F[5]. */
static void probe_cube(const char *name, const char *drive, double d[5], double F[5])
{
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    write_cube(mesh, 1.25);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 3, \"center_mm\": [5, 5, 13.2], "
            "\"direction\": [0, 0, -1], %s, \"steps\": 4}}\n",
            mesh, drive);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    double v[10];
    assert_int_equal(read_csv(csv, head, sizeof head, v, 2, 5), 5);
    assert_string_equal(head, "depth_mm,force_N\n");
    for (int k = 0; k < 5; k++) {
        d[k] = v[2 * k];
        F[k] = v[2 * k + 1];
    }
}

static void a_probe_pressed_to_a_force_stops_at_the_depth_of_that_force(void **state)
{
    (void)state;
    double dd[5], Fd[5], df[5], Ff[5];
    probe_cube("bydepth", "\"depth_mm\": 1", dd, Fd);
    char drive[100];
    snprintf(drive, sizeof drive, "\"force_N\": %.17g", Fd[4]);
    probe_cube("byforce", drive, df, Ff);
    print_message("sphere on the cube: to depth 1 mm %.6g N; to that force: depth %.9g mm, "
                  "force %.9g N; steps at %.5g %.5g %.5g mm\n",
                  Fd[4], df[4], Ff[4], df[1], df[2], df[3]);
    for (int k = 1; k <= 4; k++) {
        assert_close(Ff[k], Fd[4] * k / 4, 2e-6 * Fd[4]); /* the ramp of forces */
        assert_true(df[k] > df[k - 1]);
    }
    assert_close(df[4], 1, 1e-5);
    /* the sphere touches at 0.2 mm: a quarter of the force is reached past it, deeper than a
    ** quarter of the depth (Hertz: F ~ d^1.5) */
    assert_true(df[1] > 0.2 && df[1] < 1);
}

static void a_probe_with_two_drives_or_none_to_touch_is_refused(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/drive.json", dir);
    snprintf(csv, sizeof csv, "%s/drive.csv", dir);
    write_cube(mesh, 2.5);
    static const struct {
        const char *probe, *must;
    } cases[] = {
        {"\"direction\": [0, 0, -1], \"depth_mm\": 1, \"force_N\": 1", "exclude each other"},
        {"\"direction\": [0, 0, 1], \"force_N\": 1", "key 'probe.force_N' = 1: body: the probe moves past"},
        {"\"direction\": [0, 0, -1], \"force_N\": -1", "'probe.force_N' = -1"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f, "{" SPRING ", \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1}, \"fixed\": "
                   "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"probe\": {\"shape\": "
                   "\"sphere\", \"radius_mm\": 3, \"center_mm\": [5, 5, 14], %s}}\n",
                mesh, cases[k].probe);
        fclose(f);
        int rc = tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv);
        if (rc != 65 || !strstr(err, cases[k].must))
            fail_msg("case %zu: exit %d, expected 65 with \"%s\"; stderr: %s", k, rc,
                     cases[k].must, err);
        struct stat sb;
        assert_true(stat(csv, &sb) != 0);
    }
}

static void a_probe_on_a_path_in_time_follows_it(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/path.json", dir);
    snprintf(csv, sizeof csv, "%s/path.csv", dir);
    write_cube(mesh, 1.25);
    /* straight down 1 mm in the first second (as probe_cube's depth-driven run, in 4 of the 16
    ** steps), 2 mm across and back, and up again */
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 3, \"direction\": [0, 0, -1], "
            "\"steps\": 16, \"path\": {\"t_s\": [0, 1, 2, 3, 4], \"center_mm\": [[5, 5, 13.2], "
            "[5, 5, 12.2], [3, 5, 12.2], [5, 5, 12.2], [5, 5, 13.2]]}}}\n",
            mesh);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    double v[17 * 3], dd[5], Fd[5];
    assert_int_equal(read_csv(csv, head, sizeof head, v, 3, 17), 17);
    assert_string_equal(head, "time_s,depth_mm,force_N\n");
    probe_cube("bydepth2", "\"depth_mm\": 1", dd, Fd);
    for (int k = 0; k <= 4; k++) { /* the way down is the depth-driven run */
        assert_close(v[3 * k], 0.25 * k, 1e-12);
        assert_close(v[3 * k + 1], dd[k], 1e-12);
        assert_close(v[3 * k + 2], Fd[k], 1e-9 * Fd[4]);
    }
    /* elastic and static: back at a place and depth, the force of the way down */
    print_message("path: down %.6g %.6g N; across and back %.6g %.6g %.6g N; up %.6g %.6g N\n",
                  v[3 * 2 + 2], v[3 * 4 + 2], v[3 * 6 + 2], v[3 * 8 + 2], v[3 * 12 + 2],
                  v[3 * 14 + 2], v[3 * 16 + 2]);
    for (int k = 12; k <= 16; k++) {
        assert_close(v[3 * k + 1], dd[16 - k], 1e-12);
        assert_close(v[3 * k + 2], Fd[16 - k], 0.01 * Fd[4]);
    }
    for (int k = 5; k <= 11; k++) /* across the top of the block, about the same force */
        assert_close(v[3 * k + 2] / Fd[4], 1, 0.2);
    assert_true(strstr(out, "along a path of 5 points over 4 s in 16 steps") != NULL);
    /* a path beside center_mm, or with times that do not increase, is refused */
    static const char *const bad[][2] = {
        {"\"center_mm\": [5, 5, 13], \"path\": {\"t_s\": [0, 1], \"center_mm\": [[5, 5, 13], [5, "
         "5, 12]]}",
         "'probe.path' takes the place of"},
        {"\"path\": {\"t_s\": [0, 0], \"center_mm\": [[5, 5, 13], [5, 5, 12]]}",
         "'probe.path.t_s[1]'"},
    };
    for (size_t k = 0; k < 2; k++) {
        f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f, "{" SPRING ", \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1}, \"fixed\": "
                   "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"probe\": {\"shape\": "
                   "\"sphere\", \"radius_mm\": 1, \"direction\": [0, 0, -1], %s}}\n",
                mesh, bad[k][0]);
        fclose(f);
        remove(csv);
        int rc = tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv);
        if (rc != 65 || !strstr(err, bad[k][1]))
            fail_msg("bad path %zu: exit %d, expected 65 with \"%s\"; stderr: %s", k, rc,
                     bad[k][1], err);
        struct stat sb;
        assert_true(stat(csv, &sb) != 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_cube_displaced_at_the_top_gives_the_cells_uniaxial_stress),
        cmocka_unit_test(a_loaded_top_is_carried_by_the_supports_and_gives_the_bodys_E),
        cmocka_unit_test(the_livers_physical_group_is_its_boundary),
        cmocka_unit_test(a_liver_pulled_by_its_group_and_a_sphere_is_carried_by_its_support),
        cmocka_unit_test(bad_regions_are_refused_naming_the_key_and_write_nothing),
        cmocka_unit_test(a_probe_pressed_to_a_force_stops_at_the_depth_of_that_force),
        cmocka_unit_test(a_probe_with_two_drives_or_none_to_touch_is_refused),
        cmocka_unit_test(a_probe_on_a_path_in_time_follows_it),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
