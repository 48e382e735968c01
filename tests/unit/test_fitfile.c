/*
** Tests of the fit-file reader (src/io/fitfile.c): a good fit file and an exported spring load with
** their provenance; every malformed case is refused with a message naming its key and value.
*/
#include "testutil.h"

#include "io/fitfile.h"
#include "model/calibration.h"

static char dir[64];
static char path[128];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/conifit-fitfile-XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *write_file(const char *name, const char *text)
{
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

#define TEL "{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,\"d_mm\":1," \
            "\"G_MPa\":80000,\"H_mm\":40},\"rmse\":0.5}"
#define NON "{\"type\":\"non-telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":20,\"n\":6,\"d_mm\":1," \
            "\"G_MPa\":80000,\"H_mm\":40},\"rmse\":0.7}"
#define HEAD "{\"conifit_version\":\"0.1.0\",\"data\":{\"file\":\"data/t.csv\",\"y_unit\":\"kPa\"},"
/* TEL's cone with a cylindrical tail of NT coils in HT mm of the free length */
#define TAILED(NT, HT)                                                                             \
    "{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,\"d_mm\":1,"        \
    "\"G_MPa\":80000,\"H_mm\":40,\"n_tail\":" NT ",\"H_tail_mm\":" HT "}}"

static void good_file_loads_both_types_and_provenance(void **state)
{
    (void)state;
    cf_fitted_spring fs;
    cf_error err = {0};
    const char *p = write_file("good.json", HEAD "\"fits\":[" TEL "," NON
                                                 "],\"better_type\":\"non-telescoping\"}");
    assert_int_equal(cf_fitfile_load(p, NULL, &fs, &err), CF_OK);
    assert_int_equal(fs.type, CF_NON_TELESCOPING); /* the better type by default */
    assert_close(fs.params.D2_mm, 20.0, 0.0);
    assert_close(fs.rmse, 0.7, 0.0);
    assert_string_equal(fs.data_file, "data/t.csv");
    assert_string_equal(fs.y_unit, "kPa");
    assert_string_equal(fs.version, "0.1.0");
    assert_int_equal(cf_fitfile_load(p, "telescoping", &fs, &err), CF_OK);
    assert_int_equal(fs.type, CF_TELESCOPING);
    assert_close(fs.params.n, 4.0, 0.0);
    char spec[256];
    snprintf(spec, sizeof spec, "%s:telescoping", p);
    assert_int_equal(cf_fitfile_load_spec(spec, &fs, &err), CF_OK);
    assert_int_equal(fs.type, CF_TELESCOPING);
}

static void exported_spring_file_loads_and_checks_its_type(void **state)
{
    (void)state;
    cf_fitted_spring fs;
    cf_error err = {0};
    const char *p = write_file(
        "spring.json", "{\"schema\":\"conifit-spring-1\",\"conifit_version\":\"0.1.0\","
                       "\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,"
                       "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},\"provenance\":{\"data_file\":"
                       "\"data/t.csv\",\"rmse\":0.25,\"rmse_unit\":\"kPa\"}}");
    assert_int_equal(cf_fitfile_load(p, NULL, &fs, &err), CF_OK);
    assert_int_equal(fs.type, CF_TELESCOPING);
    assert_close(fs.rmse, 0.25, 0.0);
    assert_string_equal(fs.data_file, "data/t.csv");
    assert_int_equal(cf_fitfile_load(p, "non-telescoping", &fs, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "non-telescoping"));
}

/* Each malformed file: its text, and two pieces the message must contain (key and value). */
/* TEL fitted in a lattice of weights edge E, face = body F (a joint fit's "lattice") */
#define WEIGHTED(E, F)                                                                             \
    "{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,\"d_mm\":1,"        \
    "\"G_MPa\":80000,\"H_mm\":40},\"lattice\":{\"weights\":{\"edge\":" E ",\"face\":" F       \
    ",\"body\":" F "}}}"

/* A joint fit's lattice weights come with its spring: fitted ones are the fit's own lattice, the
** isotropic calibration's are not (the default lattice is already theirs), a fit without them
** has none. */
static void a_joint_fits_weights_come_with_its_spring(void **state)
{
    (void)state;
    double iso[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, iso, NULL), CF_OK);
    char e[32], f[32], text[1024];
    cf_fitted_spring fs;
    cf_error err = {0};
    snprintf(text, sizeof text, HEAD "\"fits\":[" WEIGHTED("0.676", "0.2088") "]}");
    assert_int_equal(cf_fitfile_load_element(write_file("w.json", text), NULL, &fs, &err), CF_OK);
    assert_true(fs.has_weight);
    assert_true(cf_fitted_own_weights(&fs));
    assert_true(fs.weight[0] == 0.676 && fs.weight[1] == 0.2088 && fs.weight[2] == 0.2088);
    snprintf(e, sizeof e, "%.17g", iso[0]);
    snprintf(f, sizeof f, "%.17g", iso[1]);
    snprintf(text, sizeof text,
             HEAD "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,"
                  "\"n\":4,\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},\"lattice\":{\"weights\":"
                  "{\"edge\":%s,\"face\":%s,\"body\":%s}}}]}",
             e, f, f);
    assert_int_equal(cf_fitfile_load_element(write_file("w.json", text), NULL, &fs, &err), CF_OK);
    assert_true(fs.has_weight);
    assert_false(cf_fitted_own_weights(&fs));
    assert_int_equal(
        cf_fitfile_load_element(write_file("w.json", HEAD "\"fits\":[" TEL "]}"), NULL, &fs, &err),
        CF_OK);
    assert_false(fs.has_weight);
    assert_false(cf_fitted_own_weights(&fs));
}

static void every_malformed_file_is_refused_naming_key_and_value(void **state)
{
    (void)state;
    static const struct {
        const char *text, *type, *key, *value;
    } cases[] = {
        {"{\"fits\": [", NULL, "bad.json:1:", "not a valid fit file"},
        {HEAD "\"better_type\":\"telescoping\"}", NULL, "'fits'", "missing"},
        {HEAD "\"fits\":[]}", NULL, "'fits'", "non-empty"},
        {HEAD "\"fits\":[" TEL "]}", "non-telescoping", "no fit of type", "'non-telescoping'"},
        {HEAD "\"fits\":[" TEL "," NON "]}", NULL, "better_type", "several fits"},
        {HEAD "\"fits\":[{\"type\":\"conical\",\"params\":{}}]}", NULL, "fits[0].type",
         "'conical'"},
        {HEAD "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D2_mm\":30,\"n\":4,\"d_mm\":1,"
              "\"G_MPa\":80000,\"H_mm\":40}}]}",
         NULL, "fits[0].params.D1_mm", "(missing)"},
        {HEAD "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":"
              "\"four\",\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}",
         NULL, "fits[0].params.n", "\"four\""},
        {HEAD "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":40,\"D2_mm\":30,\"n\":4,"
              "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}",
         NULL, "D1_mm", "40"},
        {HEAD "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":20,\"n\":6,"
              "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}",
         NULL, "fits[0] says type 'telescoping'", "non-telescoping"},
        {"{\"schema\":\"conifit-spring-1\",\"type\":\"telescoping\",\"params\":{\"D1_mm\":10}}",
         NULL, "spring.params.D2_mm", "(missing)"},
        /* the tail's keys: a number, >= 0, room for its solid length, closing after the cone */
        {HEAD "\"fits\":[" TAILED("\"x\"", "10") "]}", NULL, "fits[0].params.n_tail", "\"x\""},
        {HEAD "\"fits\":[" TAILED("-1", "10") "]}", NULL, "n_tail", "-1"},
        {HEAD "\"fits\":[" TAILED("0", "10") "]}", NULL, "H_tail_mm", "10"},
        {HEAD "\"fits\":[" TAILED("1", "0.5") "]}", NULL, "H_tail_mm = 0.5", "no room"},
        {HEAD "\"fits\":[" TAILED("1", "7") "]}", NULL, "H_tail_mm = 7", "before the cone"},
        {HEAD "\"fits\":[" TAILED("1", "39.5") "]}", NULL, "H_tail_mm = 39.5", "no travel"},
        /* a joint fit's lattice weights: each a number, none negative */
        {HEAD "\"fits\":[" WEIGHTED("\"x\"", "0.2") "]}", NULL, "fits[0].lattice.weights",
         "\"x\""},
        {HEAD "\"fits\":[" WEIGHTED("0.6", "-1") "]}", NULL, "lattice.weights.face", "-1"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cf_fitted_spring fs;
        cf_error err = {0};
        const char *p = write_file("bad.json", cases[i].text);
        cf_status st = cf_fitfile_load(p, cases[i].type, &fs, &err);
        if (st != CF_E_DATA || !strstr(err.msg, cases[i].key) || !strstr(err.msg, cases[i].value))
            fail_msg("case %zu: status %d, message '%s' lacks '%s' or '%s'", i, (int)st, err.msg,
                     cases[i].key, cases[i].value);
    }
}

/* A tailed spring goes out through the exported spring file and comes back bit for bit, with the
** tail's derived values beside it; a plain spring's file has no tail key at all; a bad tail in a
** fit file stops the export with status 65 naming the key, and nothing is written. */
static void a_tailed_spring_round_trips_and_a_plain_file_has_no_tail_keys(void **state)
{
    (void)state;
    char in[160], out[160], so[1024], se[2048];
    snprintf(in, sizeof in, "%s", write_file("tail.json", HEAD "\"fits\":[" TAILED("1.25", "10.5")
                                                          "]}"));
    snprintf(out, sizeof out, "%s/tail_spring.json", dir);
    assert_int_equal(tu_run(so, sizeof so, se, sizeof se, "export %s --format json -o %s", in, out),
                     0);
    cf_fitted_spring fs;
    cf_error err = {0};
    assert_int_equal(cf_fitfile_load(out, NULL, &fs, &err), CF_OK);
    const cf_spring want = {10, 30, 4, 1, 80000, 40, 1.25, 10.5};
    for (int k = 0; k < CF_P_ALL; k++)
        assert_true(cf_spring_get(&fs.params, k) == cf_spring_get(&want, k));
    char *text = tu_slurp(out);
    assert_non_null(text);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &want, &err), CF_OK);
    const struct { const char *key; double v; } derived[] = {
        {"\"u_C_mm\": ", law.u_C_mm}, {"\"F_solid_N\": ", law.F_solid_N},
        {"\"k_tail_N_per_mm\": ", law.k_tail_N_per_mm}, {"\"tau\": ", law.tau},
        {"\"travel_mm\": ", law.travel_mm}};
    for (size_t i = 0; i < sizeof derived / sizeof derived[0]; i++) {
        const char *at = strstr(text, derived[i].key);
        if (!at)
            fail_msg("exported tailed spring lacks %s", derived[i].key);
        assert_true(strtod(at + strlen(derived[i].key), NULL) == derived[i].v);
    }
    assert_true(law.travel_mm > law.u_C_mm); /* the whole spring's travel, past the cone's */
    free(text);
    /* a plain spring: no tail key, and it reads back with no tail */
    snprintf(in, sizeof in, "%s", write_file("plain.json", HEAD "\"fits\":[" TEL "]}"));
    assert_int_equal(tu_run(so, sizeof so, se, sizeof se, "export %s --format json -o %s", in, out),
                     0);
    text = tu_slurp(out);
    assert_non_null(text);
    assert_null(strstr(text, "tail"));
    assert_null(strstr(text, "u_C_mm"));
    free(text);
    assert_int_equal(cf_fitfile_load(out, NULL, &fs, &err), CF_OK);
    assert_false(cf_spring_has_tail(&fs.params));
    assert_true(fs.params.H_tail_mm == 0);
    /* a bad tail: 65, the key and value named, nothing written */
    unlink(out);
    snprintf(in, sizeof in, "%s", write_file("bad_tail.json", HEAD "\"fits\":[" TAILED("-2", "10")
                                                              "]}"));
    assert_int_equal(tu_run(so, sizeof so, se, sizeof se, "export %s --format json -o %s", in, out),
                     65);
    assert_non_null(strstr(se, "n_tail = -2"));
    assert_int_equal(access(out, F_OK), -1);
}

static void missing_file_is_noinput(void **state)
{
    (void)state;
    cf_fitted_spring fs;
    cf_error err = {0};
    char p[128];
    snprintf(p, sizeof p, "%s/absent.json", dir);
    assert_int_equal(cf_fitfile_load(p, NULL, &fs, &err), CF_E_NOINPUT);
    assert_non_null(strstr(err.msg, "absent.json"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(good_file_loads_both_types_and_provenance),
        cmocka_unit_test(exported_spring_file_loads_and_checks_its_type),
        cmocka_unit_test(a_joint_fits_weights_come_with_its_spring),
        cmocka_unit_test(every_malformed_file_is_refused_naming_key_and_value),
        cmocka_unit_test(a_tailed_spring_round_trips_and_a_plain_file_has_no_tail_keys),
        cmocka_unit_test(missing_file_is_noinput),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
