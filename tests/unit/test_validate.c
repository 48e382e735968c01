/*
** Tests of the validation of fits in the lattice (validate.h) through `conifit fit --validate`
** and `--through-msm`: the JSON keys and their values recomputed from the lattice directly, the
** axial-only lattice reproducing the single spring's error, the fit through the lattice lowering
** the validation error, and bad scenes refused before anything is written.
*/
#include <math.h>
#include <sys/stat.h>

#include <jansson.h>

#include "testutil.h"

#include "io/measure.h"
#include "model/msm.h"
#include "check/validate.h"

static char out[1 << 16], errb[1 << 14];

/* The spring of the shipped uniaxial scene; only the lattice of a validation scene matters. */
#define SCENE_SPRING "\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, " \
                     "\"d_mm\": 2, \"G_MPa\": 26, \"H_mm\": 10}}"
#define RAMP "\"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.3, \"duration_s\": 1}"

static int exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* Reads a fit file and returns fits[i] (borrowed from *root, which the caller frees). */
static json_t *fit_of(const char *path, int i, json_t **root)
{
    json_error_t e;
    *root = json_load_file(path, 0, &e);
    if (!*root)
        fail_msg("%s: %s", path, e.text);
    json_t *f = json_array_get(json_object_get(*root, "fits"), (size_t)i);
    assert_non_null(f);
    return f;
}

static double num_at(json_t *obj, const char *key)
{
    json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("key '%s' is missing or not a number", key);
    double x = json_number_value(v);
    assert_true(isfinite(x));
    return x;
}

static int close_rel(double a, double b, double rel)
{
    return fabs(a - b) <= rel * fmax(fabs(a), fabs(b));
}

/* --validate --target spring (the bare spring, then checked in the default lattice) writes
** finite validation keys whose RMSE equals the one recomputed here from cf_msm_uniaxial with the
** written spring. */
static void validate_writes_keys_consistent_with_the_lattice(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-val-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/v.json", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping_noise1pct.csv --type telescoping --validate --target spring "
                    "-o %s", json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "lattice RMSE"));
    assert_non_null(strstr(out, "fit target: the single spring"));
    json_t *root;
    json_t *f = fit_of(json, 0, &root);
    json_t *v = json_object_get(f, "validation");
    assert_non_null(v);
    double rmse = num_at(v, "rmse"), r2 = num_at(v, "r2"), mx = num_at(v, "max_abs_error");
    num_at(v, "wall_time_s");
    assert_true(rmse >= 0 && mx >= rmse && r2 <= 1);
    json_t *lat = json_object_get(v, "lattice");
    assert_int_equal(json_integer_value(json_object_get(lat, "nx")), 3);
    assert_string_equal(json_string_value(json_object_get(lat, "calibration")), "isotropic");
    json_t *lw = json_object_get(lat, "weights");
    assert_true(fabs(num_at(lw, "edge") - 0.6085) < 1e-4);
    assert_true(fabs(num_at(lw, "face") - 0.2708) < 1e-4 && num_at(lw, "body") == num_at(lw, "face"));
    assert_true(fabs(num_at(lat, "poisson_ratio") - 0.25) < 1e-12);
    assert_true(fabs(num_at(lat, "modulus_ratio") - 1) < 1e-12);
    assert_string_equal(json_string_value(json_object_get(lat, "bottom")), "axial");
    /* recompute */
    json_t *p = json_object_get(f, "params");
    cf_spring sp = {num_at(p, "D1_mm"), num_at(p, "D2_mm"), num_at(p, "n"),
                    num_at(p, "d_mm"),  num_at(p, "G_MPa"), num_at(p, "H_mm")};
    double fit_rmse = num_at(f, "rmse");
    json_decref(root);
    cf_measure_options mo = cf_measure_default_options();
    cf_table m;
    cf_error err = {0};
    assert_int_equal(cf_measure_load("data/telescoping_noise1pct.csv", &mo, &m, &err), CF_OK);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    double *s = malloc(sizeof(double) * m.count);
    assert_non_null(s);
    cf_msm_config cfg = cf_msm_default();
    assert_int_equal(cf_msm_uniaxial(&law, CF_LAW_CLOSED_NEWTON, &cfg, m.x, m.count, s, NULL,
                                     &err),
                     CF_OK);
    double rss = 0, emax = 0;
    for (size_t i = 0; i < m.count; i++) {
        double e = (s[i] - m.y[i]) * m.y_to_file;
        rss += e * e;
        emax = fmax(emax, fabs(e));
    }
    double want = sqrt(rss / (double)m.count);
    if (!close_rel(rmse, want, 1e-9) || !close_rel(mx, emax, 1e-9))
        fail_msg("written rmse %.17g max %.17g, recomputed %.17g %.17g", rmse, mx, want, emax);
    /* the calibrated lattice is close to the law but not equal to it (its diagonals rotate and
    ** strain less than the axis): a small multiple of the fit's error, not zero */
    if (!(want > fit_rmse && want < 6 * fit_rmse))
        fail_msg("lattice rmse %.6g against fit rmse %.6g", want, fit_rmse);
    free(s);
    cf_table_free(&m);
    remove(json);
    rmdir(dir);
}

/* A lattice of axial springs alone (no diagonals) carries sigma = F/H^2 of one spring in every
** layer: its validation error equals the single-spring fit error, for both types. */
static void axial_only_lattice_reproduces_the_fit_error(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-val-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char scene[256], json[256], text[1024];
    snprintf(scene, sizeof scene, "%s/axial.json", dir);
    snprintf(json, sizeof json, "%s/a.json", dir);
    snprintf(text, sizeof text,
             "{" SCENE_SPRING ", \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, \"diagonals\": "
             "\"none\", \"bottom\": \"axial\"}, " RAMP "}\n");
    write_text(scene, text);
    const char *tables[] = {"data/non_telescoping_noise1pct.csv", "data/telescoping_compression.csv"};
    double ymax[2] = {0, 0};
    for (int t = 0; t < 2; t++) {
        cf_measure_options mo = cf_measure_default_options();
        cf_table m;
        assert_int_equal(cf_measure_load(tables[t], &mo, &m, NULL), CF_OK);
        for (size_t i = 0; i < m.count; i++)
            ymax[t] = fmax(ymax[t], fabs(m.y[i]) * m.y_to_file);
        cf_table_free(&m);
    }
    for (int t = 0; t < 2; t++) {
        int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s --validate %s -o %s --quiet",
                        tables[t], scene, json);
        if (st != 0)
            fail_msg("%s: exit %d: %s", tables[t], st, errb);
        for (int i = 0; i < 2; i++) {
            json_t *root;
            json_t *f = fit_of(json, i, &root);
            json_t *v = json_object_get(f, "validation");
            double a = num_at(f, "rmse"), b = num_at(v, "rmse");
            double ma = num_at(f, "max_abs_error"), mb = num_at(v, "max_abs_error");
            json_t *lw = json_object_get(json_object_get(v, "lattice"), "weights");
            assert_true(num_at(lw, "edge") == 1 && num_at(lw, "face") == 0 &&
                        num_at(lw, "body") == 0);
            json_decref(root);
            /* 1e-9 relative, with a floor at rounding level of the table (a noiseless table is
            ** fitted to ~1e-15 of its largest stress, where a relative test means nothing) */
            double floor_ = 1e-12 * ymax[t];
            if (fabs(a - b) > 1e-9 * fmax(a, b) + floor_ ||
                fabs(ma - mb) > 1e-9 * fmax(ma, mb) + floor_)
                fail_msg("%s fit %d: fit rmse %.17g, lattice %.17g (max %.17g, %.17g)",
                         tables[t], i, a, b, ma, mb);
        }
    }
    remove(json);
    remove(scene);
    rmdir(dir);
}

/* With diagonals the lattice is stiffer than one spring; fitting through it never raises the
** validation error and here lowers it severalfold. The written validation is the new spring's. */
static void through_msm_lowers_the_validation_error(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-val-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char scene[256], json[256], text[1024];
    snprintf(scene, sizeof scene, "%s/cube.json", dir);
    snprintf(json, sizeof json, "%s/t.json", dir);
    /* one cell keeps the test quick; the diagonals make it differ from the spring */
    snprintf(text, sizeof text,
             "{" SCENE_SPRING ", \"lattice\": {\"nx\": 1, \"ny\": 1, \"nz\": 1, \"diagonals\": "
             "\"face+body\"}, " RAMP "}\n");
    write_text(scene, text);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping_noise1pct.csv --type telescoping --through-msm %s -o %s",
                    scene, json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "through lattice"));
    json_t *root;
    json_t *f = fit_of(json, 0, &root);
    json_t *t = json_object_get(f, "through_msm");
    json_t *v = json_object_get(f, "validation");
    assert_non_null(t);
    double before = num_at(t, "rmse_before"), after = num_at(t, "rmse_after");
    assert_true(num_at(t, "evaluations") >= 1);
    num_at(t, "wall_time_s");
    assert_true(after <= before);
    if (!(after < 0.5 * before))
        fail_msg("through the lattice: rmse %.6g -> %.6g, expected at least halved", before,
                 after);
    assert_true(close_rel(num_at(v, "rmse"), after, 1e-12));
    assert_true(json_is_true(json_object_get(t, "improved")));
    /* the reported spring is feasible and still a telescoping spring */
    assert_true(json_is_true(json_object_get(f, "feasible")));
    assert_string_equal(json_string_value(json_object_get(f, "type")), "telescoping");
    json_decref(root);
    remove(json);
    remove(scene);
    rmdir(dir);
}

/* A scene that is not a static uniaxial one, or not a valid scene, exits 65 naming the key, and
** no fit file or plot is written. */
static void bad_scene_exits_65_naming_the_key(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-val-XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const struct {
        const char *body;
        const char *key;
    } cases[] = {
        {"{" SCENE_SPRING ", " RAMP ", \"effects\": {\"damping\": {\"eta_kPa_s\": 5}}}", "effects"},
        {"{" SCENE_SPRING ", \"protocol\": {\"kind\": \"cycles\", \"to_strain\": 0.3, "
         "\"period_s\": 60, \"count\": 2}}",
         "protocol.kind"},
        {"{" SCENE_SPRING ", \"lattise\": {\"nx\": 2}, " RAMP "}", "lattise"},
        {"{" SCENE_SPRING ", \"lattice\": {\"nx\": 0}, " RAMP "}", "nx"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char scene[256], json[256], png[256];
        snprintf(scene, sizeof scene, "%s/bad%zu.json", dir, i);
        snprintf(json, sizeof json, "%s/out.json", dir);
        snprintf(png, sizeof png, "%s/out.png", dir);
        write_text(scene, cases[i].body);
        for (int through = 0; through < 2; through++) {
            int st = tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv %s %s -o %s --plot %s",
                            through ? "--through-msm" : "--validate", scene, json, png);
            if (st != 65)
                fail_msg("case %zu: exit %d, expected 65: %s", i, st, errb);
            if (!strstr(errb, cases[i].key) || !strstr(errb, scene))
                fail_msg("case %zu: message does not name '%s' and the scene: %s", i,
                         cases[i].key, errb);
            assert_false(exists(json));
            assert_false(exists(png));
        }
        remove(scene);
    }
    /* a scene that does not exist: 66 */
    char json[256];
    snprintf(json, sizeof json, "%s/out.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --validate %s/none.json -o %s", dir, json),
                     66);
    assert_false(exists(json));
    rmdir(dir);
}

/* A force-displacement table is fitted as usual; its validation is skipped with a note. */
static void force_displacement_table_is_skipped_with_a_note(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-val-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char table[256], json[256];
    snprintf(table, sizeof table, "%s/fd.csv", dir);
    snprintf(json, sizeof json, "%s/fd.json", dir);
    cf_spring sp = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, NULL), CF_OK);
    FILE *f = fopen(table, "w");
    assert_non_null(f);
    fprintf(f, "displacement_mm,force_N\n");
    for (int i = 0; i <= 20; i++) {
        double u = 0.9 * law.travel_mm * i / 20;
        fprintf(f, "%.17g,%.17g\n", u, cf_law_force(&law, CF_LAW_EXACT, u, NULL, NULL));
    }
    fclose(f);
    int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s --through-msm -o %s", table, json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "validation in the lattice: skipped"));
    json_t *root;
    json_t *fit = fit_of(json, 0, &root);
    json_t *v = json_object_get(fit, "validation");
    assert_non_null(v);
    const char *note = json_string_value(json_object_get(v, "skipped"));
    assert_non_null(note);
    assert_non_null(strstr(note, "stress-strain"));
    assert_null(json_object_get(v, "rmse"));
    json_decref(root);
    remove(json);
    remove(table);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(validate_writes_keys_consistent_with_the_lattice),
        cmocka_unit_test(axial_only_lattice_reproduces_the_fit_error),
        cmocka_unit_test(through_msm_lowers_the_validation_error),
        cmocka_unit_test(bad_scene_exits_65_naming_the_key),
        cmocka_unit_test(force_displacement_table_is_skipped_with_a_note),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
