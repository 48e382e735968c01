/*
** Tests of `conifit fit` through the program: the bad-input catalogue (exact exit status, a
** message naming file, line and column, no output file), the JSON fit file read back by the
** fit-file reader, determinism, batch runs with -j, plots and a missing gnuplot; the Yeoh and
** Ogden baselines in the report, the fit file and the batch summary, and where they are not fitted.
*/
#include <math.h>
#include <sys/stat.h>

#include <jansson.h>

#include "testutil.h"

#include "io/fitfile.h"

static char out[1 << 16], errb[1 << 14];

static int exists(const char *path)
{
    struct stat s;
    return stat(path, &s) == 0;
}

static void write_file(const char *path, const char *text, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite(text, 1, len, f);
    fclose(f);
}

static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static char buf[1 << 17];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* Removes the "wall_time_s": ... lines (the one thing allowed to differ between runs). */
static void strip_wall_time(char *s)
{
    char *p;
    while ((p = strstr(s, "\"wall_time_s\"")) != NULL) {
        char *e = strchr(p, '\n');
        memmove(p, e ? e : p + strlen(p), strlen(e ? e : p + strlen(p)) + 1);
    }
}

typedef struct bad_case {
    const char *name;
    const char *text;
    size_t len; /* 0: strlen(text) */
    const char *where; /* expected "line:col" fragment after the file name, or NULL */
} bad_case;

/* Each bad table ends with exit 65, a message naming the file, and no fit file. */
static void bad_tables_exit_65_and_write_nothing(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const char junk[] = "\x7f" "ELF\x02\x01\x01\x00\x00\x00\xff\xfe\x00\x01";
    const bad_case cases[] = {
        {"no_header.csv", "0.0,0.0\n0.1,1.0\n0.2,2.0\n0.3,3.1\n0.4,4.3\n0.5,5.8\n0.6,7.9\n", 0,
         NULL},
        {"unknown_unit.csv", "strain,stress_furlongs\n0,0\n0.1,1\n0.2,2\n0.3,3.1\n0.4,4.3\n0.5,5.8\n",
         0, NULL},
        {"non_numeric.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2,abc\n0.3,3.1\n0.4,4.3\n0.5,5.8\n0.6,7\n",
         0, ":4:"},
        {"non_finite.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,inf\n0.4,4.3\n0.5,5.8\n0.6,7\n",
         0, ":5:"},
        {"short_row.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2\n0.3,3.1\n0.4,4.3\n0.5,5.8\n0.6,7\n", 0,
         ":4:"},
        {"too_few.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n", 0, NULL},
        {"empty.csv", "", 0, NULL},
        {"binary.csv", junk, sizeof junk - 1, NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[256], json[256];
        snprintf(path, sizeof path, "%s/%s", dir, cases[i].name);
        snprintf(json, sizeof json, "%s/out.json", dir);
        write_file(path, cases[i].text, cases[i].len ? cases[i].len : strlen(cases[i].text));
        int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s --plot %s/p.png", path,
                        json, dir);
        if (st != 65)
            fail_msg("%s: exit %d, expected 65 (stderr: %s)", cases[i].name, st, errb);
        assert_non_null(strstr(errb, cases[i].name));
        if (cases[i].where && !strstr(errb, cases[i].where))
            fail_msg("%s: message lacks line:column %s: %s", cases[i].name, cases[i].where, errb);
        assert_false(exists(json));
        char png[300];
        snprintf(png, sizeof png, "%s/p.png", dir);
        assert_false(exists(png));
        remove(path);
    }
    /* a missing file: 66, nothing written */
    char json[256];
    snprintf(json, sizeof json, "%s/out.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s/nope.csv -o %s", dir,
                            json),
                     66);
    assert_false(exists(json));
    /* one bad table among good ones fails alone: exit 65, nothing of its own written, the good
    ** table's fit file written */
    char bad[256];
    snprintf(bad, sizeof bad, "%s/bad.csv", dir);
    write_file(bad, "strain,stress_kPa\n0,0\n0.1,x\n", 26);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv %s -o %s/", bad, dir),
                     65);
    assert_non_null(strstr(errb, "bad.csv:3"));
    snprintf(json, sizeof json, "%s/bad.json", dir);
    assert_false(exists(json));
    snprintf(json, sizeof json, "%s/telescoping.json", dir);
    assert_true(exists(json));
    remove(json);
    remove(bad);
    rmdir(dir);
}

/* Usage errors exit 2 before reading anything. */
static void bad_options_exit_2(void **state)
{
    (void)state;
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit"), 2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --type conical"), 2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --fix Q=3"), 2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --optimizer newton"), 2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --index-max 2"), 2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv data/non_telescoping.csv -o one.json"),
                     2);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit --help"), 0);
    assert_non_null(strstr(out, "--fix NAME=VALUE"));
}

/* The JSON reads back through cf_fitfile_load: the spring of each type, its rmse and units. */
static void json_fit_file_round_trips_through_the_reader(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/t.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping_noise1pct.csv -o %s --quiet", json),
                     0);
    char *text = read_all(json);
    assert_null(strstr(text, "nan"));
    assert_null(strstr(text, "inf"));
    assert_non_null(strstr(text, "\"stress_scale_MPa\""));
    assert_non_null(strstr(text, "\"baselines\""));
    for (int t = 0; t < 2; t++) {
        cf_fitted_spring s;
        cf_error err = {0};
        const char *type = t ? "non-telescoping" : "telescoping";
        if (cf_fitfile_load(json, type, &s, &err) != CF_OK)
            fail_msg("%s", err.msg);
        assert_int_equal(s.type, (cf_spring_type)t);
        assert_string_equal(s.y_unit, "kPa");
        /* 1 % noise of a 7.3 kPa table: the RMSE is about 0.07 kPa */
        assert_true(s.rmse > 0.03 && s.rmse < 0.15);
        /* the spring read back reproduces the written derived quantities */
        cf_law law;
        assert_int_equal(cf_law_init(&law, &s.params, NULL), CF_OK);
    }
    cf_fitted_spring best;
    cf_error err = {0};
    assert_int_equal(cf_fitfile_load(json, NULL, &best, &err), CF_OK);
    remove(json);
    rmdir(dir);
}

/* The baselines of a published table in the report, the fit file (five, in their order) and the
** batch summary; a force-displacement table leaves Yeoh and Ogden out with the reason. */
static void yeoh_and_ogden_baselines_are_reported_or_left_out_with_why(void **state)
{
    (void)state;
    const char *ds = tu_datasets();
    if (!ds) {
        print_message("test_cli_fit: ../shared/datasets absent: the baselines are not checked\n");
        skip();
    }
    char dir[] = "/tmp/conifit-base-XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const char *const names[] = {"linear", "duffing", "fung", "yeoh", "ogden"};
    const char *tables[2] = {"hydrogel_fibre_reinforced_compression",
                             "thrombus_pureshear_force_displacement"};
    for (int k = 0; k < 2; k++) {
        char json[256];
        snprintf(json, sizeof json, "%s/%s.json", dir, tables[k]);
        assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s/%s.csv -o %s", ds,
                                tables[k], json),
                         0);
        json_error_t je;
        json_t *root = json_load_file(json, JSON_REJECT_DUPLICATES, &je);
        if (!root)
            fail_msg("%s: %s", json, je.text);
        json_t *base = json_object_get(root, "baselines");
        assert_int_equal(json_array_size(base), 5);
        for (size_t b = 0; b < 5; b++)
            assert_string_equal(json_string_value(json_object_get(json_array_get(base, b), "model")),
                                names[b]);
        json_t *yeoh = json_array_get(base, 3), *ogden = json_array_get(base, 4);
        if (k == 0) { /* compression, uniaxial: fitted, Yeoh better than Duffing's cubic */
            assert_non_null(strstr(out, "  yeoh     C1 = "));
            assert_non_null(strstr(out, " MPa RMSE"));
            assert_non_null(strstr(out, "  ogden    mu = "));
            assert_non_null(strstr(out, "Yeoh and Ogden in the uniaxial form"));
            assert_string_equal(json_string_value(json_object_get(yeoh, "form")), "uniaxial");
            assert_true(json_number_value(json_object_get(yeoh, "rmse")) <
                        0.5 * json_number_value(json_object_get(json_array_get(base, 1), "rmse")));
            assert_non_null(json_object_get(json_object_get(ogden, "coefficients"), "alpha"));
            /* a fit file written before Yeoh and Ogden (three baselines) still loads */
            json_array_remove(base, 4);
            json_array_remove(base, 3);
            assert_int_equal(json_dump_file(root, json, JSON_INDENT(2)), 0);
            cf_fitted_spring fs;
            cf_error err = {0};
            if (cf_fitfile_load(json, NULL, &fs, &err) != CF_OK)
                fail_msg("%s", err.msg);
            char csv[300];
            snprintf(csv, sizeof csv, "%s/spring.csv", dir);
            assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                                    "export %s --format csv -o %s", json, csv),
                             0);
            remove(csv);
        } else { /* force against displacement: no stretch, no form */
            assert_non_null(strstr(out, "  yeoh     not fitted: a force-displacement table"));
            assert_non_null(strstr(out, "  ogden    not fitted: a force-displacement table"));
            for (int j = 0; j < 2; j++) {
                json_t *o = j ? ogden : yeoh;
                assert_non_null(strstr(json_string_value(json_object_get(o, "reason")),
                                       "no stretch"));
                assert_null(json_object_get(o, "rmse"));
                assert_null(json_object_get(o, "coefficients"));
            }
        }
        json_decref(root);
        remove(json);
    }
    /* the summary's best baseline may be one of the new ones */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit %s/%s.csv data/telescoping.csv -o %s/", ds, tables[0], dir),
                     0);
    const char *row = strstr(out, "hydrogel_fibre_reinforced_compression.csv");
    assert_non_null(row);
    assert_non_null(strstr(row, " yeoh 0.00"));
    char path[300];
    snprintf(path, sizeof path, "%s/%s.json", dir, tables[0]);
    remove(path);
    snprintf(path, sizeof path, "%s/telescoping.json", dir);
    remove(path);
    rmdir(dir);
}

/* Same seed, same file (apart from the wall time). */
static void same_seed_gives_identical_json(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    static char a[1 << 17];
    char j1[256], j2[256];
    snprintf(j1, sizeof j1, "%s/a.json", dir);
    snprintf(j2, sizeof j2, "%s/b.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/non_telescoping_noise1pct.csv --seed 7 -o %s --quiet", j1),
                     0);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/non_telescoping_noise1pct.csv --seed 7 -o %s --quiet", j2),
                     0);
    snprintf(a, sizeof a, "%s", read_all(j1));
    char *b = read_all(j2);
    strip_wall_time(a);
    strip_wall_time(b);
    assert_string_equal(a, b);
    remove(j1);
    remove(j2);
    rmdir(dir);
}

/* A batch with -j writes one fit file per table, and each equals the single-table run. */
static void batch_in_parallel_writes_one_file_per_table(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv data/non_telescoping.csv "
                            "data/strongly_conical.csv -j 3 -o %s/",
                            dir),
                     0);
    assert_non_null(strstr(out, "Summary"));
    const char *names[3] = {"telescoping", "non_telescoping", "strongly_conical"};
    for (int i = 0; i < 3; i++) {
        char p[300], q[300];
        snprintf(p, sizeof p, "%s/%s.json", dir, names[i]);
        snprintf(q, sizeof q, "%s/single.json", dir);
        assert_true(exists(p));
        assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                                "fit data/%s.csv -o %s --quiet", names[i], q),
                         0);
        static char a[1 << 17];
        snprintf(a, sizeof a, "%s", read_all(p));
        char *b = read_all(q);
        strip_wall_time(a);
        strip_wall_time(b);
        assert_string_equal(a, b);
        remove(p);
        remove(q);
    }
    rmdir(dir);
}

/* --plot writes a PNG; with gnuplot missing the run ends with 70 and leaves no file. */
static void plot_is_written_or_fails_cleanly_without_gnuplot(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char png[256];
    snprintf(png, sizeof png, "%s/t.png", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping.csv --plot %s --quiet", png);
    if (st == 0) {
        char *img = read_all(png);
        assert_memory_equal(img, "\x89PNG", 4);
        remove(png);
    } else {
        /* no gnuplot on this machine: then the error path must hold */
        assert_int_equal(st, 70);
    }
    char cmd[600];
    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=/nonexistent/gnuplot %s fit data/telescoping.csv --plot %s "
             "--quiet >/dev/null 2>%s/err",
             tu_conifit(), png, dir);
    int rc = system(cmd);
    assert_true(WIFEXITED(rc));
    assert_int_equal(WEXITSTATUS(rc), 70);
    assert_false(exists(png));
    char ep[300];
    snprintf(ep, sizeof ep, "%s/err", dir);
    assert_non_null(strstr(read_all(ep), "gnuplot"));
    remove(ep);
    /* a wrong extension is a usage error */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --plot %s/t.gif --quiet", dir),
                     2);
    rmdir(dir);
}

/* --fix holds the parameter in the fit file; the report states the family. */
static void fixed_parameter_is_in_the_fit_file(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/f.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/non_telescoping.csv --type non-telescoping --fix H=7.5 -o %s",
                            json),
                     0);
    assert_non_null(strstr(out, "one member of a family"));
    cf_fitted_spring s;
    cf_error err = {0};
    assert_int_equal(cf_fitfile_load(json, NULL, &s, &err), CF_OK);
    assert_close(s.params.H_mm, 7.5, 0);
    assert_true(s.rmse < 1e-9);
    remove(json);
    rmdir(dir);
}

/* Refuses to write the fit file over its own input (73), leaving the input intact. */
static void output_over_input_is_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-fit-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/t.csv", dir);
    char *text = read_all("data/telescoping.csv");
    size_t len = strlen(text);
    write_file(path, text, len);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s --quiet", path,
                            path),
                     73);
    assert_int_equal((int)strlen(read_all(path)), (int)len);
    remove(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bad_tables_exit_65_and_write_nothing),
        cmocka_unit_test(bad_options_exit_2),
        cmocka_unit_test(json_fit_file_round_trips_through_the_reader),
        cmocka_unit_test(same_seed_gives_identical_json),
        cmocka_unit_test(yeoh_and_ogden_baselines_are_reported_or_left_out_with_why),
        cmocka_unit_test(batch_in_parallel_writes_one_file_per_table),
        cmocka_unit_test(plot_is_written_or_fails_cleanly_without_gnuplot),
        cmocka_unit_test(fixed_parameter_is_in_the_fit_file),
        cmocka_unit_test(output_over_input_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
