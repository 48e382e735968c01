/*
** `conifit fit` with biaxial tables: a ratio that the strains contradict exits 65 naming the
** file, line and column; --plane names a shear table's plane, and a joint fit with a biaxial
** table reports the Holzapfel-Ogden baselines beside the lattice, in the text and in the fit
** file (holzapfel_ogden: the full and the transversely isotropic law, the cross-fibre direction
** along s and along n); without --plane it says why they were not fitted. The shared myocardium
** tables are used (skipped when ../shared is absent).
*/
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

TU_SCRATCH_GROUP("cli-biaxial")

static void a_contradicted_ratio_exits_65_with_its_place(void **state)
{
    (void)state;
    char path[512], errb[4096];
    snprintf(path, sizeof path, "%s/bad.csv", dir);
    const char *text = "# mode: biaxial\n# ratio: 1:0.5\nstrain_f,strain_c,stress_f_kPa,"
                       "stress_c_kPa\n0,0,0,0\n0.02,0.01,1,0.4\n0.04,0.03,2.5,1\n0.06,0.03,4.5,"
                       "1.9\n0.08,0.04,7,3\n0.1,0.05,10,4.4\n";
    assert_int_equal(tu_write_bytes(path, text, strlen(text)), 0);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit --joint %s -q", path), 65);
    if (!strstr(errb, "bad.csv:6:2:") || !strstr(errb, "ratio 1:0.5"))
        fail_msg("%s", errb);
}

static void joint_report_shows_the_holzapfel_ogden_baselines(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        printf("skipped: ../shared/datasets is absent\n");
        skip();
    }
    static char out[1 << 16], errb[4096];
    char json[512];
    snprintf(json, sizeof json, "%s/joint.json", dir);
    int rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit --joint --type non-telescoping --plane heart_myocardium_shear_fs=fs "
                    "%s/heart_myocardium_biaxial_1to075.csv %s/heart_myocardium_shear_fs.csv "
                    "-o %s", d, d, json);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, errb);
    assert_non_null(strstr(out, "Holzapfel-Ogden baselines"));
    assert_non_null(strstr(out, "transversely isotropic (4): a "));
    assert_non_null(strstr(out, "the isotropic lattice (non-telescoping): weighted objective"));
    json_error_t je;
    json_t *root = json_load_file(json, 0, &je);
    assert_non_null(root);
    json_t *ho = json_object_get(root, "holzapfel_ogden");
    assert_true(json_is_array(ho) && json_array_size(ho) == 4);
    for (size_t k = 0; k < 4; k++) {
        const double obj = json_number_value(json_object_get(json_array_get(ho, k), "objective"));
        assert_true(obj > 0 && obj < 1); /* the lattice's is about 0.5 on these two */
    }
    json_decref(root);
    rc = tu_run(out, sizeof out, errb, sizeof errb,
                "fit --joint --type non-telescoping %s/heart_myocardium_biaxial_1to075.csv "
                "%s/heart_myocardium_shear_fs.csv", d, d);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "not fitted: "));
    assert_non_null(strstr(out, "states no plane in the fibre frame"));
    assert_non_null(strstr(out, "--plane"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_contradicted_ratio_exits_65_with_its_place),
        cmocka_unit_test(joint_report_shows_the_holzapfel_ogden_baselines),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
