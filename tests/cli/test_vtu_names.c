/*
** `conifit simulate BODY -o CSV --vtu DIR`: an -o naming one of the files --vtu writes
** (DIR/body.pvd, DIR/body_NNNN.vtu, DIR/springs_NNNN.vtu) would have the CSV replace a ParaView
** file (a --plot name ends in .png, .svg or .pdf, so it cannot); it is refused with exit 2 before the run, naming the file and the
** option, and nothing is written. Names beside them (another step number, another folder) run.
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

TU_SCRATCH_GROUP("vtu-names")

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* A block probed by a sphere in 4 steps (files body_0000.vtu .. body_0004.vtu). */
static void write_scene(const char *path)
{
    char mesh[600];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    write_block(mesh);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 5, \"center_mm\": [15, 15, 20], "
            "\"direction\": [0, 0, -2], \"depth_mm\": 1, \"steps\": 4}}\n",
            mesh);
    fclose(f);
}

static void an_output_naming_a_paraview_file_is_refused(void **state)
{
    (void)state;
    char scene[600], vtu[600], out[8192], err[8192];
    snprintf(scene, sizeof scene, "%s/probe.json", dir);
    snprintf(vtu, sizeof vtu, "%s/vtu", dir);
    write_scene(scene);
    assert_int_equal(mkdir(vtu, 0777), 0);
    const char *names[] = {"body.pvd", "body_0000.vtu", "body_0004.vtu", "springs_0002.vtu"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        /* as -o, through another spelling of the folder too */
        int rc = tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/../vtu/%s --vtu %s",
                        scene, vtu, names[k], vtu);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(err, names[k]));
        assert_non_null(strstr(err, "--vtu"));
        char path[800];
        snprintf(path, sizeof path, "%s/%s", vtu, names[k]);
        assert_false(exists(path));
    }
    /* the error names the option and says what --vtu writes */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/body.pvd --vtu %s",
                            scene, vtu, vtu),
                     2);
    assert_non_null(strstr(err, "-o"));
    assert_non_null(strstr(err, "springs_NNNN.vtu"));
}

static void names_beside_the_paraview_files_run(void **state)
{
    (void)state;
    char scene[600], vtu[600], out[8192], err[8192], path[800];
    snprintf(scene, sizeof scene, "%s/probe2.json", dir);
    snprintf(vtu, sizeof vtu, "%s/vtu2", dir);
    write_scene(scene);
    assert_int_equal(mkdir(vtu, 0777), 0);
    /* a step the run does not have, in the --vtu folder itself: no clash */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "simulate %s -o %s/body_0005.vtu --vtu %s -q", scene, vtu, vtu),
                     0);
    snprintf(path, sizeof path, "%s/body_0005.vtu", vtu);
    char *text = tu_slurp(path);
    assert_non_null(text);
    assert_int_equal(strncmp(text, "depth_mm,force_N\n", 17), 0); /* the CSV */
    free(text);
    snprintf(path, sizeof path, "%s/body.pvd", vtu);
    text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "<VTKFile")); /* the ParaView file, not the CSV */
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(an_output_naming_a_paraview_file_is_refused),
        cmocka_unit_test(names_beside_the_paraview_files_run),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
