/*
** A body's probe on the command line beyond the CSV: its FEBio export through `conifit export`
** (well-formed for xmllint, with the body's volume elements and punch), the depth-force plot of
** `simulate --plot` (a valid PNG; a folder that cannot be written gives exit 73 and writes
** nothing), and the haptic loop of `simulate --haptic` (one force per millisecond of simulated
** time; at rest the force of the static solve within 5 %, stable).
*/
#include "testutil.h"

#include <sys/stat.h>

#include "conifit/body.h"

TU_SCRATCH_GROUP("cli-probe")

#define SPRING "\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, " \
               "\"G_MPa\": 80000, \"H_mm\": 40}}"

/* A block of 6 x 6 x 3 cells over 30 x 30 x 15 mm, as a Gmsh 2.2 file. */
static void write_block(const char *path)
{
    double xs[7], zs[4];
    for (int i = 0; i <= 6; i++)
        xs[i] = 5.0 * i;
    for (int i = 0; i <= 3; i++)
        zs[i] = 5.0 * i;
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, xs, 6, xs, 6, zs, 3, NULL), CF_OK);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", m.nn);
    for (size_t i = 0; i < m.nn; i++)
        fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, m.X[3 * i], m.X[3 * i + 1], m.X[3 * i + 2]);
    fprintf(f, "$EndNodes\n$Elements\n%zu\n", m.nt);
    for (size_t t = 0; t < m.nt; t++)
        fprintf(f, "%zu 4 2 0 1 %u %u %u %u\n", t + 1, m.tet[4 * t] + 1, m.tet[4 * t + 1] + 1,
                m.tet[4 * t + 2] + 1, m.tet[4 * t + 3] + 1);
    fprintf(f, "$EndElements\n");
    fclose(f);
    cf_mesh_free(&m);
}

/* A scene of the block held at its bottom, nu = 0.45, pressed by a probe (sphere or punch) on the
** top's centre 1 mm down in 4 steps; `extra` adds keys at the top level (",\n ..."). */
static void write_scene(const char *path, const char *shape, const char *extra)
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
            "\"direction\": [0, 0, -1], \"depth_mm\": 1, \"steps\": 4}%s}\n",
            mesh, shape, strcmp(shape, "sphere") ? "15" : "20", extra);
    fclose(f);
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* `conifit export FIT --lattice BODY_SCENE --format febio`: a well-formed FEBio 4 file (xmllint,
** when installed) holding the block's 196 nodes, its 648 tetrahedra of the volume term and the
** punch; the same scene with a sphere is refused, exit 65 naming the probe, nothing written. */
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
                           "<SolidDomain name=\"volume\" mat=\"volume\"/>",
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_body_scene_exports_to_febio),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
