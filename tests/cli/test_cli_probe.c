/*
** A body's probe on the command line beyond the CSV: its FEBio export through `conifit export`
** (well-formed for xmllint, with the body's volume elements and punch), the depth-force plot of
** `simulate --plot` (a valid PNG; a folder that cannot be written gives exit 73 and writes
** nothing), and the haptic loop of `simulate --haptic` (one force per millisecond of simulated
** time; at rest the force of the static solve within 5 %, stable).
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

#include "model/body.h"
#include "io/mesh.h"

TU_SCRATCH_GROUP("cli-probe")

/* A scene of the block held at its bottom, nu = 0.45, pressed by a probe (sphere or punch) on the
** top's centre `depth` mm down in `steps` steps; `extra` adds keys at the top level (",\n ..."). */
static void write_scene_at(const char *path, const char *shape, double depth, int steps,
                           const char *extra)
{
    char mesh[600];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    write_block(mesh);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"%s\", \"radius_mm\": 5, \"center_mm\": [15, 15, %s], "
            "\"direction\": [0, 0, -1], \"depth_mm\": %.17g, \"steps\": %d}%s}\n",
            mesh, shape, strcmp(shape, "sphere") ? "15" : "20", depth, steps, extra);
    fclose(f);
}

static void write_scene(const char *path, const char *shape, const char *extra)
{
    write_scene_at(path, shape, 1, 4, extra);
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* `conifit export FIT --lattice BODY_SCENE --format febio`: a well-formed FEBio 4 file (xmllint,
** when installed) holding the block's 196 nodes, its 648 tetrahedra of the volume term (a ut4
** domain, alpha 0: J per node) and the punch's contact set; the same scene with a sphere is refused, exit 65 naming the probe, nothing written. */
static void a_body_scene_exports_to_febio(void **state)
{
    (void)state;
    const char *fit = "fits/series/muscle_compression_relaxation_fiber30.json";
    char scene[600], feb[600], out[4096], err[4096];
    snprintf(scene, sizeof scene, "%s/punch.json", dir);
    snprintf(feb, sizeof feb, "%s/punch.feb", dir);
    write_scene(scene, "sphere", "");
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "export %s --lattice %s --format febio -o %s", fit, scene, feb),
                     65);
    assert_non_null(strstr(err, "probe"));
    assert_false(exists(feb));
    write_scene(scene, "punch", "");
    if (tu_run(out, sizeof out, err, sizeof err, "export %s --lattice %s --format febio -o %s",
               fit, scene, feb) != 0)
        fail_msg("export: %s", err);
    char *x = tu_slurp(feb);
    assert_non_null(x);
    const char *order[] = {"<febio_spec version=\"4.0\">", "<Material>", "type=\"Mooney-Rivlin\"",
                           "<pressure_model>2</pressure_model>", "<Mesh>",
                           "<Elements type=\"tet4\" name=\"volume\">", "<elem id=\"648\">",
                           "</Elements>", "<NodeSet name=\"top\">", "<DiscreteSet name=\"G1\">",
                           "<SolidDomain name=\"volume\" mat=\"volume\" elem_type=\"ut4\">",
                           "<alpha>0</alpha>",
                           "type=\"prescribed displacement\"", "type=\"nonlinear spring\"",
                           "<LoadData>", "<Output>", "</febio_spec>"};
    const char *at = x;
    for (size_t i = 0; i < sizeof order / sizeof *order; i++) {
        const char *hit = strstr(at, order[i]);
        if (!hit)
            fail_msg("the body's FEBio file lacks '%s' in order", order[i]);
        at = hit;
    }
    assert_null(strstr(x, "<elem id=\"649\">"));
    assert_non_null(strstr(x, "<node id=\"196\">"));
    free(x);
    if (system("command -v xmllint >/dev/null 2>&1") == 0) {
        char cmd[1400];
        snprintf(cmd, sizeof cmd, "xmllint --noout --nonet '%s'", feb);
        assert_int_equal(system(cmd), 0);
    }
}

/* Reads a CSV of numeric rows after its header into cols columns (at most cap rows): the row
** count. */
static size_t read_csv(const char *path, const char *header, int cols, double *v, size_t cap)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[512];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, header);
    size_t n = 0;
    while (n < cap && fgets(line, sizeof line, f)) {
        double *r = v + (size_t)cols * n;
        const int got = cols == 2 ? sscanf(line, "%lf,%lf", &r[0], &r[1])
                                  : sscanf(line, "%lf,%lf,%lf", &r[0], &r[1], &r[2]);
        assert_int_equal(got, cols);
        for (int c = 0; c < cols; c++)
            assert_true(isfinite(r[c]));
        n++;
    }
    fclose(f);
    return n;
}

/* A PNG file: its signature, an IHDR chunk first, the width and height gnuplot was given. */
static void assert_png(const char *path, unsigned width, unsigned height)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    unsigned char h[24];
    assert_int_equal(fread(h, 1, 24, f), 24);
    fseek(f, 0, SEEK_END);
    const long size = ftell(f);
    fclose(f);
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    assert_memory_equal(h, sig, 8);
    assert_memory_equal(h + 12, "IHDR", 4);
    const unsigned w = (unsigned)h[16] << 24 | (unsigned)h[17] << 16 | (unsigned)h[18] << 8 | h[19];
    const unsigned ht = (unsigned)h[20] << 24 | (unsigned)h[21] << 16 | (unsigned)h[22] << 8 | h[23];
    assert_int_equal(w, width);
    assert_int_equal(ht, height);
    assert_true(size > 2000); /* axes, labels and a curve, not an empty frame */
}

/* `simulate BODY_SCENE -o probe.csv --plot probe.png`: the CSV and a valid PNG; a plot into a
** folder that does not exist exits 73 before anything runs, and writes neither file. */
static void a_probe_run_plots_its_depth_force_curve(void **state)
{
    (void)state;
    if (system("command -v gnuplot >/dev/null 2>&1") != 0 && !getenv("CONIFIT_GNUPLOT"))
        skip(); /* CI installs gnuplot-nox (Makefile DEBS) */
    char scene[600], csv[600], png[600], out[4096], err[4096];
    snprintf(scene, sizeof scene, "%s/plot.json", dir);
    snprintf(csv, sizeof csv, "%s/plot.csv", dir);
    snprintf(png, sizeof png, "%s/plot.png", dir);
    write_scene(scene, "sphere", "");
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s --plot %s", scene, csv, png) !=
        0)
        fail_msg("simulate --plot: %s", err);
    double v[2 * 8];
    assert_int_equal(read_csv(csv, "depth_mm,force_N\n", 2, v, 8), 5);
    assert_png(png, 800, 560);
    /* a folder that does not exist: 73, nothing written */
    char bad[700], csv2[600];
    snprintf(bad, sizeof bad, "%s/no/such/folder/plot.png", dir);
    snprintf(csv2, sizeof csv2, "%s/plot2.csv", dir);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s --plot %s",
                            scene, csv2, bad),
                     73);
    assert_non_null(strstr(err, "plot.png"));
    assert_false(exists(csv2));
    assert_false(exists(bad));
}

/* Runs `simulate HAPTIC_SCENE --haptic` and the static probe of STATIC_SCENE (`steps` equal steps
** to `depth`, the ramp's end, reached at t_ramp ms) and checks the haptic forces: one row per ms
** from 0 to t_end, the path's depth in each, every force finite and not above 1.05 times the
** static force at the end, at each static step's depth on the ramp and at rest the static force
** within 5 %. Returns the haptic force at rest over the static one. */
static double haptic_against_static(const char *hscene, const char *sscene, double depth,
                                    int steps, int t_ramp, int t_end, const char *tag)
{
    char hcsv[600], scsv[600], out[8192], err[4096];
    snprintf(hcsv, sizeof hcsv, "%s/%s_haptic.csv", dir, tag);
    snprintf(scsv, sizeof scsv, "%s/%s_static.csv", dir, tag);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s --haptic -o %s", hscene, hcsv) != 0)
        fail_msg("simulate --haptic: %s", err);
    assert_non_null(strstr(out, "wall time per update: median "));
    assert_non_null(strstr(out, "static solve"));
    const char *w = strstr(out, "wall time per update: median ");
    double median;
    assert_int_equal(sscanf(w, "wall time per update: median %lf ms", &median), 1);
    print_message("%s: %.4g ms wall per update (median)\n", tag, median);
    char tmp[8192];
    if (tu_run(tmp, sizeof tmp, err, sizeof err, "simulate %s -o %s", sscene, scsv) != 0)
        fail_msg("simulate: %s", err);
    double *h = malloc(3 * ((size_t)t_end + 8) * sizeof *h), st[2 * 64];
    assert_non_null(h);
    assert_int_equal(read_csv(hcsv, "t_ms,depth_mm,force_N\n", 3, h, (size_t)t_end + 8),
                     (size_t)t_end + 1);
    assert_int_equal(read_csv(scsv, "depth_mm,force_N\n", 2, st, 64), (size_t)steps + 1);
    const double top = st[2 * steps + 1];
    assert_true(top > 0);
    for (int k = 0; k <= t_end; k++) {
        assert_true(h[3 * k] == k);
        const double want = k >= t_ramp ? depth : depth * k / t_ramp;
        assert_close(h[3 * k + 1], want, 1e-12 * depth);
        if (!(h[3 * k + 2] >= 0 && h[3 * k + 2] <= 1.05 * top))
            fail_msg("%s: haptic force %g N at %d ms, beyond the static force at the end %g N",
                     tag, h[3 * k + 2], k, top);
    }
    for (int j = 1; j <= steps; j++) {
        const int k = t_ramp * j / steps; /* the update at the static step's depth */
        assert_close(h[3 * k + 1], st[2 * j], 1e-12 * depth);
        const double ratio = h[3 * k + 2] / st[2 * j + 1];
        if (!(fabs(ratio - 1) <= 0.05))
            fail_msg("%s: at depth %g mm (%d ms) haptic %g N, static %g N", tag, st[2 * j], k,
                     h[3 * k + 2], st[2 * j + 1]);
    }
    const double rest = h[3 * t_end + 2] / top;
    print_message("%s: haptic force at rest %.6g N, static %.6g N (ratio %.6f)\n", tag,
                  h[3 * t_end + 2], top, rest);
    free(h);
    return rest;
}

/* The haptic loop on the block: a sphere pressed 0.1 mm in 50 ms and held 100 ms, one force per
** ms; along the ramp and at rest the static solve's force within 5 %. Bad paths and options are
** refused, nothing written. */
static void the_haptic_loop_follows_the_static_force_on_a_block(void **state)
{
    (void)state;
    char hscene[600], sscene[600];
    snprintf(hscene, sizeof hscene, "%s/haptic.json", dir);
    snprintf(sscene, sizeof sscene, "%s/haptic_static.json", dir);
    write_scene_at(hscene, "sphere", 0.1, 5,
                   ",\n \"haptic\": {\"path\": [[0, 0], [50, 0.1], [150, 0.1]], \"iterations\": 3}");
    write_scene_at(sscene, "sphere", 0.1, 5, "");
    const double rest = haptic_against_static(hscene, sscene, 0.1, 5, 50, 150, "block");
    assert_true(fabs(rest - 1) <= 0.05);
    /* refused: times not increasing (65 naming the vertex), no "haptic" (65), --vtu (2), a
    ** lattice scene with "haptic" (65); nothing written */
    char csv[600], out[4096], err[4096];
    snprintf(csv, sizeof csv, "%s/refused.csv", dir);
    write_scene_at(hscene, "sphere", 0.1, 5,
                   ",\n \"haptic\": {\"path\": [[0, 0], [50, 0.1], [40, 0.1]]}");
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s --haptic -o %s",
                            hscene, csv),
                     65);
    assert_non_null(strstr(err, "haptic.path[2]"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s --haptic -o %s",
                            sscene, csv),
                     65);
    assert_non_null(strstr(err, "'haptic'"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "simulate %s --haptic --vtu %s/v -o %s", sscene, dir, csv),
                     2);
    char lat[600];
    snprintf(lat, sizeof lat, "%s/lattice.json", dir);
    FILE *f = fopen(lat, "w");
    assert_non_null(f);
    fprintf(f, "{" SPRING ", \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.1}, "
               "\"haptic\": {\"path\": [[0, 0], [1, 0]]}}");
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", lat, csv), 65);
    assert_non_null(strstr(err, "needs a 'body'"));
    assert_false(exists(csv));
}

/* The same on the shared liver mesh (skips without it): the fitted muscle spring at nu 0.45, held
** below z = -60 mm, a sphere of 10 mm pressed 1 mm into the top in 200 ms and held 100 ms. */
static void the_haptic_loop_follows_the_static_force_on_the_liver(void **state)
{
    (void)state;
    const char *liver = "../shared/meshes/liver2.msh";
    cf_mesh m;
    if (cf_mesh_read(liver, 100, &m, NULL) != CF_OK)
        skip(); /* ../shared/meshes absent */
    size_t top = 0;
    for (size_t i = 0; i < m.nn; i++)
        if (m.X[3 * i + 2] > m.X[3 * top + 2])
            top = i;
    char hscene[600], sscene[600];
    snprintf(hscene, sizeof hscene, "%s/liver_haptic.json", dir);
    snprintf(sscene, sizeof sscene, "%s/liver_static.json", dir);
    for (int hap = 0; hap < 2; hap++) {
        FILE *f = fopen(hap ? hscene : sscene, "w");
        assert_non_null(f);
        fprintf(f,
                "{\"spring\": {\"fit\": \"fits/series/muscle_compression_relaxation_fiber30.json\"},"
                " \"body\": {\"mesh\": \"%s\", \"unit_mm\": 100, \"poisson_ratio\": 0.45},"
                " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": -60}},"
                " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 10, \"center_mm\": [%.17g, "
                "%.17g, %.17g], \"direction\": [0, 0, -1], \"depth_mm\": 1, \"steps\": 10}%s}",
                liver, m.X[3 * top], m.X[3 * top + 1], m.X[3 * top + 2] + 10.001,
                hap ? ", \"haptic\": {\"path\": [[0, 0], [200, 1], [300, 1]]}" : "");
        fclose(f);
    }
    cf_mesh_free(&m);
    const double rest = haptic_against_static(hscene, sscene, 1, 10, 200, 300, "liver2");
    assert_true(fabs(rest - 1) <= 0.05);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_body_scene_exports_to_febio),
        cmocka_unit_test(a_probe_run_plots_its_depth_force_curve),
        cmocka_unit_test(the_haptic_loop_follows_the_static_force_on_a_block),
        cmocka_unit_test(the_haptic_loop_follows_the_static_force_on_the_liver),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
