/*
** Tests of input opening (src/base/input.c): regular files (and links to them) are read; a FIFO,
** a device and a folder are refused at once with the kind named, never waited on; through the
** program, a table, a scene or a fit file that is a FIFO is exit 66.
*/
#include "testutil.h"

#include <sys/stat.h>

#include "base/input.h"

static void expect_refused(const char *path, const char *kind)
{
    cf_error err = {0};
    FILE *f = cf_input_open(path, "table", &err);
    if (f)
        fclose(f);
    assert_null(f);
    assert_int_equal(err.status, CF_E_NOINPUT);
    if (!strstr(err.msg, kind) || !strstr(err.msg, path) || !strstr(err.msg, "table"))
        fail_msg("message '%s' does not name %s, %s and table", err.msg, path, kind);
}

static void only_regular_files_are_opened(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-input-XXXXXX", fifo[300], file[300], link[300];
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/fifo.csv", dir);
    snprintf(file, sizeof file, "%s/t.csv", dir);
    snprintf(link, sizeof link, "%s/link.csv", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    FILE *w = fopen(file, "w");
    assert_non_null(w);
    fputs("strain,stress\n", w);
    fclose(w);
    assert_int_equal(symlink("t.csv", link), 0);

    expect_refused(fifo, "a FIFO"); /* no writer: would block a plain open */
    expect_refused("/dev/null", "a character device");
    expect_refused(dir, "a folder");
    cf_error err = {0};
    FILE *f = cf_input_open("/nonexistent/conifit.csv", "table", &err);
    assert_null(f);
    assert_int_equal(err.status, CF_E_NOINPUT);
    assert_non_null(strstr(err.msg, "No such file"));

    const char *ok[] = {file, link};
    for (int k = 0; k < 2; k++) {
        f = cf_input_open(ok[k], "table", &err);
        assert_non_null(f);
        char line[64];
        assert_non_null(fgets(line, sizeof line, f));
        assert_string_equal(line, "strain,stress\n");
        fclose(f);
    }
    unlink(fifo);
    unlink(link);
    unlink(file);
    rmdir(dir);
}

/* Through the program: a table, a scene or a fit file that is a FIFO (no writer) is exit 66, at
** once. */
static void inputs_that_are_fifos_are_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-input-XXXXXX", fifo[300], se[4096];
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/input.json", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    assert_int_equal(tu_run(NULL, 0, se, sizeof se, "simulate %s -o %s/out.csv", fifo, dir), 66);
    assert_non_null(strstr(se, "a FIFO"));
    assert_int_equal(tu_run(NULL, 0, se, sizeof se, "fit %s --quiet", fifo), 66);
    assert_non_null(strstr(se, "a FIFO"));
    assert_int_equal(tu_run(NULL, 0, se, sizeof se, "export %s --format json", fifo), 66);
    assert_non_null(strstr(se, "a FIFO"));
    unlink(fifo);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(only_regular_files_are_opened),
        cmocka_unit_test(inputs_that_are_fifos_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
