/*
** No null, NaN or Inf in any JSON or text conifit writes: a value that is not determined (a
** standard error of a quantity the data leave open, a correlation, an interval not computed, the
** better type of a tie, a stability limit never reached) is left out with a reason beside it, and
** a document that would hold a non-finite number is refused (tests/unit/test_report.c). This test scans
** the committed fit files (every .json in fits/) and what the commands that write JSON or a report
** write on the shipped tables: fit (with --validate, --target lattice, --joint, a time series,
** -o -), export --format json, and their text on standard output and standard error.
*/
#include <ctype.h>
#include <dirent.h>
#include <sys/stat.h>

#include "testutil.h"

#include <jansson.h>

static char out[1 << 20], errb[1 << 16];

/* Fails when text holds the word nan, inf or infinity (any case; "-nan" included) or null. */
static void assert_no_bad_words(const char *what, const char *text)
{
    static const char *const bad[] = {"nan", "inf", "infinity", "null"};
    for (const char *p = text; *p; p++) {
        if (p > text && (isalnum((unsigned char)p[-1]) || p[-1] == '_'))
            continue;
        for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            size_t n = strlen(bad[k]);
            if (strncasecmp(p, bad[k], n) == 0 && !isalnum((unsigned char)p[n]) && p[n] != '_') {
                char ctx[81];
                snprintf(ctx, sizeof ctx, "%s", p > text + 30 ? p - 30 : text);
                fail_msg("%s holds '%s' near: ...%s...", what, bad[k], ctx);
            }
        }
    }
}

/* Fails when the JSON document holds a null anywhere (path in the message). */
static void walk(const char *what, json_t *v, const char *path)
{
    if (json_is_null(v))
        fail_msg("%s: null at %s", what, path);
    char sub[512];
    if (json_is_object(v)) {
        const char *key;
        json_t *item;
        json_object_foreach(v, key, item) {
            snprintf(sub, sizeof sub, "%s.%s", path, key);
            walk(what, item, sub);
        }
    } else if (json_is_array(v)) {
        size_t i;
        json_t *item;
        json_array_foreach(v, i, item) {
            snprintf(sub, sizeof sub, "%s[%zu]", path, i);
            walk(what, item, sub);
        }
    } else if (json_is_real(v) && !isfinite(json_real_value(v))) {
        fail_msg("%s: non-finite number at %s", what, path);
    }
}

static void assert_clean_json_text(const char *what, const char *text)
{
    json_error_t e;
    json_t *root = json_loads(text, 0, &e);
    if (!root)
        fail_msg("%s: not JSON: %s (line %d)", what, e.text, e.line);
    walk(what, root, "$");
    json_decref(root);
    /* NaN and Infinity are not JSON; a string value holding such a word is prose, checked apart */
}

static void assert_clean_json_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot read %s", path);
    size_t n = fread(out, 1, sizeof out - 1, f);
    fclose(f);
    out[n] = '\0';
    assert_true(n < sizeof out - 1);
    assert_clean_json_text(path, out);
}

/* Every JSON file in dir (not recursive); returns how many. */
static int scan_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int count = 0;
    struct dirent *e;
    char path[1024];
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n < 6 || strcmp(e->d_name + n - 5, ".json") != 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        assert_clean_json_file(path);
        count++;
    }
    closedir(d);
    return count;
}

static void committed_fit_files_hold_no_null(void **state)
{
    (void)state;
    assert_true(scan_dir("fits") >= 7);
    assert_true(scan_dir("fits/series") >= 2); /* the viscoelastic fits */
}

/* The shipped tables through fit, with the lattice validation, with standard errors that are and
** are not determined (the nearly cylindrical and strongly conical tables get profile intervals). */
static void fit_outputs_hold_no_null(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-nonull-XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const char *const tables[] = {"nearly_cylindrical", "non_telescoping",
                                         "strongly_conical", "telescoping",
                                         "telescoping_compression", "telescoping_noise1pct"};
    char cmd[2048], path[600];
    for (size_t k = 0; k < sizeof tables / sizeof tables[0]; k++) {
        snprintf(path, sizeof path, "%s/%s.json", dir, tables[k]);
        snprintf(cmd, sizeof cmd, "fit data/%s.csv --validate -o %s", tables[k], path);
        int st = tu_run(out, sizeof out, errb, sizeof errb, "%s", cmd);
        if (st != 0)
            fail_msg("%s: exit %d: %s", cmd, st, errb);
        assert_no_bad_words(cmd, out);
        assert_no_bad_words(cmd, errb);
        assert_clean_json_file(path);
        /* the exported spring */
        int se = tu_run(out, sizeof out, errb, sizeof errb, "export %s --format json", path);
        if (se != 0)
            fail_msg("export %s: exit %d: %s", path, se, errb);
        assert_clean_json_text("export --format json", out);
        remove(path);
    }
    /* the fit through the lattice (placement: no standard errors, their reason instead), one
    ** lattice for two tables, and a viscoelastic fit of a time series (a writer of its own) */
    static const char *const runs[] = {
        "fit data/telescoping.csv --target lattice -o",
        "fit --joint data/telescoping.csv data/telescoping_compression.csv -o",
        "fit data/series/synthetic_relaxation.csv -o"};
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        snprintf(path, sizeof path, "%s/run%zu.json", dir, k);
        int sk = tu_run(out, sizeof out, errb, sizeof errb, "%s %s", runs[k], path);
        if (sk != 0)
            fail_msg("%s: exit %d: %s", runs[k], sk, errb);
        assert_no_bad_words(runs[k], out);
        assert_clean_json_file(path);
        remove(path);
    }
    /* the fit file on standard output */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit data/strongly_conical.csv -o -"),
                     0);
    assert_clean_json_text("fit -o -", out);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(committed_fit_files_hold_no_null),
        cmocka_unit_test(fit_outputs_hold_no_null),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
