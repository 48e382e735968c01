/*
** conifit predict (pipeline/predict.h): a saved fit evaluated at tables without refitting.
** Consistency first: predicting the very tables a fit was fitted to reproduces the fit file's own
** per-table RMSE (a single fit to the spring and through the lattice; a joint fit with a volume
** term) and, for a joint fit, each table's objective term and their sum, the fit's objective, to
** 1e-9 relative. Then tables the fit never saw (the cortex shear, another tissue) get finite
** figures; a double-acting element written into a fit file reaches the cell; rows past the
** springs' solid length are left out with a note, never NaN; bad inputs exit 66, 65 and 2 with a
** message naming what is wrong. A joint fit of two biaxial tables at unequal ratios reproduces
** its lattice's RMSE and its Holzapfel-Ogden baselines' (fit file's holzapfel_ogden). The joint
** fits here take the conical law (under a second each).
*/
#include "testutil.h"

#include <math.h>
#include <sys/stat.h>

#include <jansson.h>

#include "model/cell.h"
#include "io/fitfile.h"
#include "io/measure.h"
#include "pipeline/predict.h"

static char out[1 << 16], errb[1 << 12];

TU_SCRATCH_GROUP("predict")

/* Reads table path as the command does. */
static void load_table(const char *path, cf_table *t)
{
    cf_measure_options mo = cf_measure_default_options();
    cf_error err = {0};
    if (cf_measure_load(path, &mo, t, &err) != CF_OK)
        fail_msg("%s: %s", path, err.msg);
}

/* Predicts the n tables at paths from fit file json into r (the tables into t). */
static void predict(const char *json, const char *const *paths, size_t n, cf_table *t,
                    cf_predict_result *r)
{
    const cf_table *tp[8];
    for (size_t k = 0; k < n; k++) {
        load_table(paths[k], &t[k]);
        tp[k] = &t[k];
    }
    cf_error err = {0};
    if (cf_predict(json, NULL, tp, n, r, &err) != CF_OK)
        fail_msg("cf_predict %s: %s", json, err.msg);
}

static void release(cf_table *t, size_t n, cf_predict_result *r)
{
    cf_predict_free(r);
    for (size_t k = 0; k < n; k++)
        cf_table_free(&t[k]);
}

/* The number at a key path of the fit file's better (or only) fit: "rmse", or "tables[K].rmse" */
static double fit_number(const char *json, const char *key, size_t k)
{
    json_error_t je;
    json_t *root = json_load_file(json, 0, &je);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    json_t *obj = strcmp(key, "objective") == 0 || strcmp(key, "rmse") == 0
                      ? fit
                      : json_array_get(json_object_get(fit, "tables"), k);
    const char *leaf = strcmp(key, "table_rmse") == 0 ? "rmse" : key;
    json_t *v = json_object_get(obj, leaf);
    assert_true(json_is_number(v));
    const double x = json_number_value(v);
    json_decref(root);
    return x;
}

static void assert_rel(double a, double b, double rel)
{
    if (!(fabs(a - b) <= rel * fabs(b)))
        fail_msg("%.17g against %.17g: off by %.3g relative (bound %.3g)", a, b,
                 fabs(a - b) / fabs(b), rel);
}

/* A single fit of data/telescoping_noise1pct.csv (noise: the noise-free table's RMSE is rounding,
** 2e-15 kPa), to the spring and through the lattice: predicting the table gives the fit file's
** RMSE, the table marked fitted, the term (RMSE/RMS)^2. */
static void single_fit_reproduces_its_rmse(void **state)
{
    (void)state;
    static const char *const target[2] = {"spring", "lattice"};
    for (int i = 0; i < 2; i++) {
        char json[300];
        snprintf(json, sizeof json, "%s/single_%s.json", dir, target[i]);
        int rc = tu_run(out, sizeof out, errb, sizeof errb,
                        "fit data/telescoping_noise1pct.csv --type telescoping --target %s -q "
                        "-o %s", target[i], json);
        if (rc != 0)
            fail_msg("fit --target %s exited %d: %s", target[i], rc, errb);
        const char *paths[1] = {"data/telescoping_noise1pct.csv"};
        cf_table t[1];
        cf_predict_result r;
        predict(json, paths, 1, t, &r);
        assert_int_equal(r.model, i == 0 ? CF_PREDICT_SPRING : CF_PREDICT_CELL);
        assert_int_equal(r.tab[0].fitted, 1);
        assert_int_equal(r.tab[0].followed, t[0].count);
        const double rmse_kpa = r.tab[0].rmse * t[0].y_to_file;
        assert_rel(rmse_kpa, fit_number(json, "rmse", 0), 1e-9);
        assert_rel(r.tab[0].fit_rmse, r.tab[0].rmse, 1e-9);
        assert_rel(r.tab[0].term, (r.tab[0].rmse / r.tab[0].rms) * (r.tab[0].rmse / r.tab[0].rms),
                   1e-12);
        assert_true(r.tab[0].r2 > 0.99);
        assert_close(r.tab[0].share, 1.0, 1e-15);
        release(t, 1, &r);
    }
}

/* A force-displacement fit (the thrombus table, whose '# mode:' a force table does not honour)
** predicts its table: the fit file's RMSE in its force unit, whatever the mode comment says. */
static void force_fit_reproduces_its_rmse(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        print_message("skipped: ../shared/datasets is absent (the thrombus table)\n");
        skip();
    }
    char json[300], table[300];
    snprintf(json, sizeof json, "%s/thrombus.json", dir);
    snprintf(table, sizeof table, "%s/thrombus_pureshear_force_displacement.csv", d);
    int rc = tu_run(out, sizeof out, errb, sizeof errb, "fit %s --type telescoping -q -o %s",
                    table, json);
    if (rc != 0)
        fail_msg("fit exited %d: %s", rc, errb);
    const char *paths[1] = {table};
    cf_table t[1];
    cf_predict_result r;
    predict(json, paths, 1, t, &r);
    assert_int_equal(r.model, CF_PREDICT_SPRING);
    assert_true(cf_table_is_force(&t[0]));
    assert_int_equal(r.tab[0].fitted, 1);
    assert_rel(r.tab[0].rmse * t[0].y_to_file, fit_number(json, "rmse", 0), 1e-9);
    release(t, 1, &r);
}


/* The joint fit of the cortex's tension and compression with a fitted volume term (json), made
** once; the test skips, saying why, when the published tables are absent. */
static void cortex_joint(char *json, size_t cap)
{
    const char *d = tu_datasets();
    if (!d) {
        print_message("skipped: ../shared/datasets is absent (the brain cortex tables)\n");
        skip();
    }
    snprintf(json, cap, "%s/cortex_tc.json", dir);
    struct stat st;
    if (stat(json, &st) == 0)
        return;
    int rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s/brain_cortex_tension.csv %s/brain_cortex_compression.csv --joint "
                    "--law conical --volume fit --type telescoping -q -o %s",
                    d, d, json);
    if (rc != 0)
        fail_msg("joint fit exited %d: %s", rc, errb);
}

/* Tension and compression reproduce the joint fit's per-table RMSE and terms and their sum its
** objective; the shear table, never fitted, gets a finite RMSE and term of its own. */
static void joint_fit_reproduces_its_terms(void **state)
{
    (void)state;
    char json[300];
    cortex_joint(json, sizeof json);
    const char *paths[3] = {"../shared/datasets/brain_cortex_tension.csv",
                            "../shared/datasets/brain_cortex_compression.csv",
                            "../shared/datasets/brain_cortex_shear.csv"};
    cf_table t[3];
    cf_predict_result r;
    predict(json, paths, 3, t, &r);
    assert_int_equal(r.model, CF_PREDICT_CELL);
    assert_true(r.fit.joint);
    assert_true(r.fit.spring.volume_modulus_MPa > 0);
    double sum = 0;
    for (size_t k = 0; k < 2; k++) {
        const cf_predict_table *p = &r.tab[k];
        assert_int_equal(p->fitted, (int)k + 1);
        assert_int_equal(p->followed, t[k].count);
        const double rmse = fit_number(json, "table_rmse", k);
        const double scale = fit_number(json, "scale", k);
        assert_rel(p->rmse * t[k].y_to_file, rmse, 1e-9);
        assert_rel(p->rms * t[k].y_to_file, scale, 1e-12);
        assert_rel(p->term, (rmse / scale) * (rmse / scale), 1e-9);
        assert_rel(p->term, p->fit_term, 1e-9);
        sum += p->term;
    }
    assert_rel(sum, fit_number(json, "objective", 0), 1e-9);
    const cf_predict_table *s = &r.tab[2];
    assert_int_equal(s->fitted, 0);
    assert_int_equal(s->followed, t[2].count);
    assert_true(isfinite(s->rmse) && s->rmse > 0);
    assert_true(isfinite(s->r2) && isfinite(s->term) && s->term > 0);
    assert_rel(r.sum_terms, sum + s->term, 1e-12);
    assert_rel(s->share, s->term / r.sum_terms, 1e-12);
    release(t, 3, &r);
}

/* A joint fit of two biaxial tables at ratios 1:0.5 and 0.5:1 (each row along its own direction,
** the other at the ratio): predicting them reproduces the isotropic lattice's per-table RMSE and
** objective (1e-9), and the fit file's Holzapfel-Ogden baselines (full and TI, cross-fibre s and
** n), read back and evaluated at the same rows, reproduce the RMSE each records. */
static void biaxial_joint_reproduces_lattice_and_baselines(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        print_message("skipped: ../shared/datasets is absent (the myocardium tables)\n");
        skip();
    }
    char json[300], p0[256], p1[256];
    snprintf(json, sizeof json, "%s/biaxial.json", dir);
    snprintf(p0, sizeof p0, "%s/heart_myocardium_biaxial_1to05.csv", d);
    snprintf(p1, sizeof p1, "%s/heart_myocardium_biaxial_05to1.csv", d);
    int rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s %s --joint --law conical --type telescoping -q -o %s", p0, p1, json);
    if (rc != 0)
        fail_msg("joint fit exited %d: %s", rc, errb);
    const char *paths[2] = {p0, p1};
    cf_table t[2];
    cf_predict_result r;
    predict(json, paths, 2, t, &r);
    for (size_t k = 0; k < 2; k++)
        assert_rel(r.tab[k].rmse * t[k].y_to_file, fit_number(json, "table_rmse", k), 1e-9);
    assert_rel(r.sum_terms, fit_number(json, "objective", 0), 1e-9);
    assert_int_equal(r.fibre.n, 4);
    json_error_t je;
    json_t *root = json_load_file(json, 0, &je);
    assert_non_null(root);
    for (int j = 0; j < 4; j++) {
        const json_t *rm = json_object_get(json_array_get(json_object_get(root, "holzapfel_ogden"),
                                                          (size_t)j), "rmse_kPa");
        assert_int_equal(r.fibre.m[j].kind, j % 2 ? CF_PF_HO_TI : CF_PF_HO);
        for (size_t k = 0; k < 2; k++)
            assert_rel(r.fibre.m[j].rmse_MPa[k] * 1e3,
                       json_number_value(json_array_get(rm, k)), 1e-9);
    }
    json_decref(root);
    release(t, 2, &r);
}

/* Another tissue from the cortex fit (chicken breast, every mode): finite figures, not fitted;
** the command's CSV holds every row and no NaN, its report the units. */
static void other_tissue_and_csv(void **state)
{
    (void)state;
    char json[300];
    cortex_joint(json, sizeof json);
    const char *paths[3] = {"../shared/datasets/chicken_breast_tension.csv",
                            "../shared/datasets/chicken_breast_compression.csv",
                            "../shared/datasets/chicken_breast_shear.csv"};
    cf_table t[3];
    cf_predict_result r;
    predict(json, paths, 3, t, &r);
    size_t rows = 0;
    for (size_t k = 0; k < 3; k++) {
        assert_int_equal(r.tab[k].fitted, 0);
        assert_true(r.tab[k].ok);
        assert_true(isfinite(r.tab[k].rmse) && r.tab[k].rmse > 0 && isfinite(r.tab[k].term));
        rows += t[k].count;
    }
    release(t, 3, &r);
    char csv[300];
    snprintf(csv, sizeof csv, "%s/chicken.csv", dir);
    int rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s %s %s %s -o %s", json,
                    paths[0], paths[1], paths[2], csv);
    if (rc != 0)
        fail_msg("predict exited %d: %s", rc, errb);
    assert_non_null(strstr(out, " kPa"));
    assert_non_null(strstr(out, "not fitted to it"));
    char *text = tu_slurp(csv);
    assert_non_null(text);
    assert_null(strstr(text, "nan"));
    assert_null(strstr(text, "inf"));
    size_t lines = 0;
    for (const char *p = strstr(text, "table,mode,row"); p && *p; p++)
        lines += *p == '\n';
    assert_int_equal(lines, rows + 1);
    free(text);
}

/* A double-acting element (an extension spring of half the compression spring's wire modulus
** written into the fit file) reaches the cell: the tension table's prediction is the cell of the
** pair and the file's kappa, and differs from the compression spring's odd law. */
static void pair_reaches_the_cell(void **state)
{
    (void)state;
    char json[300], pair[300];
    cortex_joint(json, sizeof json);
    json_error_t je;
    json_t *root = json_load_file(json, 0, &je);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    json_t *ext = json_deep_copy(json_object_get(fit, "params"));
    json_object_set_new(ext, "G_MPa",
                        json_real(0.5 * json_number_value(json_object_get(ext, "G_MPa"))));
    json_object_set_new(fit, "params_extension", ext);
    snprintf(pair, sizeof pair, "%s/pair.json", dir);
    assert_int_equal(json_dump_file(root, pair, JSON_REAL_PRECISION(17)), 0);
    json_decref(root);
    const char *paths[1] = {"../shared/datasets/brain_cortex_tension.csv"};
    cf_table t[1], t0[1];
    cf_predict_result r, r0;
    predict(pair, paths, 1, t, &r);
    predict(json, paths, 1, t0, &r0);
    assert_true(r.fit.spring.has_extension);
    cf_law lc, le;
    assert_int_equal(cf_law_init(&lc, &r.fit.spring.params, NULL), CF_OK);
    assert_int_equal(cf_law_init(&le, &r.fit.spring.extension, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&lc, &le, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &lc, CF_LAW_CLOSED, r.fit.weight, NULL), CF_OK);
    c.volume_modulus_MPa = r.fit.spring.volume_modulus_MPa;
    double ss = 0;
    for (size_t i = 0; i < t[0].count; i++) {
        double y;
        assert_int_equal(cf_cell_curve(&c, CF_MODE_UNIAXIAL, &t[0].x[i], 1, &y, NULL), CF_OK);
        assert_close(r.tab[0].model[i], y, 1e-15 + 1e-12 * fabs(y));
        ss += (y - t[0].y[i]) * (y - t[0].y[i]);
    }
    assert_rel(r.tab[0].rmse, sqrt(ss / (double)t[0].count), 1e-12);
    assert_true(fabs(r.tab[0].rmse - r0.tab[0].rmse) > 1e-3 * r0.tab[0].rmse);
    release(t, 1, &r);
    release(t0, 1, &r0);
}

/* Rows past the springs' solid length (rubber to stretch 7 from the cortex fit): left out with a
** note naming the limit, the others' figures finite; the CSV leaves their prediction empty. */
static void rows_past_solid_are_noted(void **state)
{
    (void)state;
    char json[300];
    cortex_joint(json, sizeof json);
    const char *paths[1] = {"../shared/datasets/treloar1944_rubber_uniaxial.csv"};
    cf_table t[1];
    cf_predict_result r;
    predict(json, paths, 1, t, &r);
    const cf_predict_table *p = &r.tab[0];
    assert_true(p->followed > 0 && p->followed < t[0].count);
    assert_true(p->reach_to > 0 && p->reach_to < t[0].x[t[0].count - 1]);
    assert_non_null(strstr(p->note, "beyond the model's reach"));
    assert_true(isfinite(p->rmse) && isfinite(p->r2) && isfinite(p->term));
    for (size_t i = 0; i < t[0].count; i++)
        assert_int_equal(p->follows[i], t[0].x[i] < p->reach_to);
    release(t, 1, &r);
}

/* Bad inputs: a missing fit file 66, a fit file without a parameter or without the lattice's
** weights 65 naming the key, a shear table against a fit to the spring 65 saying why, a missing
** table operand 2, a force-displacement table against a stress-strain fit 65. */
static void bad_inputs(void **state)
{
    (void)state;
    char spring[300], nokey[300], noweights[300];
    snprintf(spring, sizeof spring, "%s/single_spring.json", dir);
    int rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping.csv --type telescoping --target spring -q -o %s",
                    spring);
    assert_int_equal(rc, 0);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s/none.json data/telescoping.csv",
                dir);
    assert_int_equal(rc, 66);
    assert_non_null(strstr(errb, "none.json"));
    snprintf(nokey, sizeof nokey, "%s/nokey.json", dir);
    snprintf(noweights, sizeof noweights, "%s/noweights.json", dir);
    json_error_t je;
    json_t *root = json_load_file("fits/telescoping.json", 0, &je);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    json_object_del(json_object_get(json_object_get(json_object_get(fit, "validation"),
                                                    "lattice"), "weights"), "face");
    assert_int_equal(json_dump_file(root, noweights, JSON_REAL_PRECISION(17)), 0);
    json_object_del(json_object_get(fit, "params"), "D1_mm");
    assert_int_equal(json_dump_file(root, nokey, JSON_REAL_PRECISION(17)), 0);
    json_decref(root);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s data/telescoping.csv", nokey);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(errb, "D1_mm"));
    rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s data/telescoping.csv", noweights);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(errb, "weights.face"));
    const char *d = tu_datasets();
    if (d) {
        rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s %s/brain_cortex_shear.csv",
                    spring, d);
        assert_int_equal(rc, 65);
        assert_non_null(strstr(errb, "uniaxial curve only"));
        rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "predict %s %s/thrombus_pureshear_force_displacement.csv", spring, d);
        assert_int_equal(rc, 65);
        assert_non_null(strstr(errb, "force-displacement"));
    }
    rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s", spring);
    assert_int_equal(rc, 2);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "predict %s data/telescoping.csv --type x",
                spring);
    assert_int_equal(rc, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(single_fit_reproduces_its_rmse),
        cmocka_unit_test(force_fit_reproduces_its_rmse),
        cmocka_unit_test(joint_fit_reproduces_its_terms),
        cmocka_unit_test(biaxial_joint_reproduces_lattice_and_baselines),
        cmocka_unit_test(other_tissue_and_csv),
        cmocka_unit_test(pair_reaches_the_cell),
        cmocka_unit_test(rows_past_solid_are_noted),
        cmocka_unit_test(bad_inputs),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
