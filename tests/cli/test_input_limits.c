/*
** Costs bounded by the input and limits stated (src/notes/commands.md, "Limits"): a comment of a
** megabyte is read in linear time and still yields its unit; the row, column, line and size limits
** of a table hold exactly where they are documented, with a message naming the line; a folder given
** as a table, fit file or scene is a missing input (66). Timings belong to the benchmark, not here.
*/
#include <sys/stat.h>

#include "testutil.h"

#include "io/fitfile.h"
#include "io/measure.h"
#include "io/scene.h"

TU_SCRATCH_GROUP("limits")

/* Opens dir/name for writing. */
static FILE *create(const char *name, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    return f;
}

static void rows(FILE *f, size_t n)
{
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%zu,%zu\n", i % 100, i % 1000);
}

/* A megabyte of repeated words naming the column, then the clause that states its unit: found. */
static void long_comment_still_gives_its_unit(void **state)
{
    (void)state;
    char path[512];
    FILE *f = create("comment.csv", path, sizeof path);
    fputs("# ", f);
    for (size_t n = 0; n < ((size_t)1 << 20); n += 26)
        fputs("stress strain stress [x] (", f);
    fputs("; stress [kPa]\n", f);
    fputs("# ", f);
    for (size_t n = 0; n < ((size_t)1 << 20); n += 8)
        fputs("stress [", f);
    fputs("\nstrain,stress\n", f);
    rows(f, 10);
    assert_int_equal(fclose(f), 0);
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_OK);
    assert_string_equal(t.y_unit, "kPa");
    assert_int_equal(t.count, 10);
    cf_table_free(&t);
}

/* CF_MEASURE_MAX_COLUMNS columns are read; one more is refused at its column. */
static void column_limit(void **state)
{
    (void)state;
    for (int extra = 0; extra < 2; extra++) {
        char path[512];
        FILE *f = create("wide.csv", path, sizeof path);
        fputs("strain,stress_kPa", f);
        for (int c = 3; c <= CF_MEASURE_MAX_COLUMNS + extra; c++)
            fprintf(f, ",c%d", c);
        fputc('\n', f);
        for (int r = 0; r < 8; r++) {
            fprintf(f, "%d,%d", r, r);
            for (int c = 3; c <= CF_MEASURE_MAX_COLUMNS + extra; c++)
                fputs(",0", f);
            fputc('\n', f);
        }
        assert_int_equal(fclose(f), 0);
        cf_table t;
        cf_error err = {0};
        cf_status st = cf_measure_load(path, NULL, &t, &err);
        if (!extra) {
            if (st != CF_OK)
                fail_msg("%s", err.msg);
            cf_table_free(&t);
        } else {
            assert_int_equal(st, CF_E_DATA);
            assert_non_null(strstr(err.msg, "wide.csv:1:1001:"));
            assert_non_null(strstr(err.msg, "at most 1000"));
        }
    }
}

/* CF_MEASURE_MAX_ROWS rows are read; one more is refused naming its line. */
static void row_limit(void **state)
{
    (void)state;
    for (int extra = 0; extra < 2; extra++) {
        char path[512];
        FILE *f = create("long.csv", path, sizeof path);
        fputs("strain,stress_kPa\n", f);
        rows(f, CF_MEASURE_MAX_ROWS + (size_t)extra);
        assert_int_equal(fclose(f), 0);
        cf_table t;
        cf_error err = {0};
        cf_status st = cf_measure_load(path, NULL, &t, &err);
        if (!extra) {
            assert_int_equal(st, CF_OK);
            assert_int_equal(t.count, CF_MEASURE_MAX_ROWS);
            cf_table_free(&t);
        } else {
            assert_int_equal(st, CF_E_DATA);
            char where[64];
            snprintf(where, sizeof where, "long.csv:%d:", CF_MEASURE_MAX_ROWS + 2);
            assert_non_null(strstr(err.msg, where));
        }
    }
}

/* Blank lines count against the line limit; a file past the size limit is refused before it is
** parsed (a sparse file: no disk is used). */
static void line_and_size_limits(void **state)
{
    (void)state;
    char path[512];
    FILE *f = create("blank.csv", path, sizeof path);
    for (long i = 0; i <= CF_MEASURE_MAX_LINES; i++)
        fputc('\n', f);
    assert_int_equal(fclose(f), 0);
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "more than 2000000 lines"));

    f = create("huge.csv", path, sizeof path);
    assert_int_equal(fclose(f), 0);
    assert_int_equal(truncate(path, (off_t)CF_MEASURE_MAX_BYTES + 1), 0);
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "larger than"));
}

/* A folder where a file is expected: 66 for a table, a fit file and a scene alike. */
static void folders_are_missing_inputs(void **state)
{
    (void)state;
    cf_table t;
    cf_fitted_spring fs;
    cf_scene sc;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(dir, NULL, &t, &err), CF_E_NOINPUT);
    assert_int_equal(cf_fitfile_load(dir, NULL, &fs, &err), CF_E_NOINPUT);
    assert_int_equal(cf_scene_load(dir, &sc, &err), CF_E_NOINPUT);
    assert_non_null(strstr(err.msg, "folder"));
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "simulate %s -o %s/x.csv", dir, dir), 66);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "export %s --format json", dir), 66);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "fit %s", dir), 66);
}

/* Finite values whose sums over the table would overflow are refused with line and column; names
** cut to fit are cut between characters; a file name in another encoding is reported as valid
** UTF-8, and its fit file is written (JSON with no NaN or Inf). */
static void values_and_names(void **state)
{
    (void)state;
    char path[512];
    FILE *f = create("big.csv", path, sizeof path);
    fputs("strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,1e308\n0.4,4\n0.5,5\n0.6,6\n", f);
    assert_int_equal(fclose(f), 0);
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "big.csv:5:2:"));

    f = create("n\xff\xfe.csv", path, sizeof path);
    fputs("strain,", f);
    for (int k = 0; k < 40; k++)
        fputs("\xcf\x83", f); /* a Greek sigma, two bytes */
    fputs("stress [kPa]\n", f);
    for (int k = 0; k < 8; k++)
        fprintf(f, "%g,%g\n", k / 10.0, k * (1 + k / 10.0));
    assert_int_equal(fclose(f), 0);
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_OK);
    size_t n = strlen(t.y_column);
    assert_true(n > 0 && n < sizeof t.y_column && n % 2 == 0); /* whole characters only */
    assert_non_null(strstr(t.path, "n??.csv"));
    cf_table_free(&t);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "%s fit '%s' -q -o %s/u.json 2>/dev/null", tu_conifit(), path, dir);
    assert_int_equal(WEXITSTATUS(system(cmd)), 0);
    snprintf(cmd, sizeof cmd, "%s/u.json", dir);
    f = fopen(cmd, "rb");
    assert_non_null(f);
    static char json[1 << 17];
    size_t len = fread(json, 1, sizeof json - 1, f);
    json[len] = '\0';
    fclose(f);
    assert_non_null(strstr(json, "n??.csv"));
    assert_null(strstr(json, "nan"));
    assert_null(strstr(json, "NaN"));
    assert_null(strstr(json, "inf"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(long_comment_still_gives_its_unit),
        cmocka_unit_test(column_limit),
        cmocka_unit_test(row_limit),
        cmocka_unit_test(line_and_size_limits),
        cmocka_unit_test(folders_are_missing_inputs),
        cmocka_unit_test(values_and_names),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
