/*
** Messages and exit statuses of the command line (issue 37, item 12):
**  - a spring the law refuses in force, curve and info names the command that was run (it said
**    `conifit spring`, a command that does not exist);
**  - a spring outside the range where its loads can be represented names the quantity that fails
**    and never prints NaN (it said "derived value 4 = -nan");
**  - conifit merge takes `--` as the end of its options, refuses a folder as a missing input (66,
**    as every other command does; it was 65), and conifit fit refuses --shard given twice (2; the
**    last one was taken silently);
**  - (item 6) -o and --plot naming one file through a hard link: exit 2, the file untouched and
**    no temporary left.
*/
#include "testutil.h"

#include <ctype.h>
#include <limits.h>

TU_SCRATCH_GROUP("messages")

static char out[16384], err[8192];

/* 1 when text holds "nan" or "inf" as a word of its own (any case), as printf writes them. */
static int has_nan_or_inf(const char *text)
{
    for (const char *p = text; *p; p++) {
        if (p != text && isalnum((unsigned char)p[-1]))
            continue;
        const char *q = *p == '-' || *p == '+' ? p + 1 : p;
        if ((strncasecmp(q, "nan", 3) == 0 || strncasecmp(q, "inf", 3) == 0) &&
            !isalnum((unsigned char)q[3]))
            return 1;
    }
    return 0;
}

static void a_refused_spring_names_the_command_that_ran(void **state)
{
    (void)state;
    const char *cmds[3] = {"force", "curve", "info"};
    const char *springs[2] = {
        "--D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 50 --n_tail -1 --H_tail 10",
        "--D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 50 --n_tail 20 --H_tail 10"};
    for (int c = 0; c < 3; c++)
        for (int s = 0; s < 2; s++) {
            int rc = tu_run(out, sizeof out, err, sizeof err, "%s %s%s", cmds[c], springs[s],
                            c == 0 ? " --u 1" : "");
            assert_int_equal(rc, 2);
            char want[64];
            snprintf(want, sizeof want, "conifit %s: ", cmds[c]);
            if (!strstr(err, want))
                fail_msg("%s: '%s' does not start with '%s'", cmds[c], err, want);
            snprintf(want, sizeof want, "(see 'conifit %s --help')", cmds[c]);
            assert_non_null(strstr(err, want));
            assert_null(strstr(err, "conifit spring"));
            assert_non_null(strstr(err, "n_tail") ? err : strstr(err, "H_tail"));
        }
}

static void an_unrepresentable_spring_names_the_quantity_never_nan(void **state)
{
    (void)state;
    /* F_C = G s d/(8 n c^3) is inf/inf, rho underflows, F_C overflows */
    const struct {
        const char *spring, *says;
    } cases[] = {
        {"--D1 1e200 --D2 1e300 --n 2 --d 1e10 --G 1e300 --H 1e12",
         "F_C (the cone's solid load, N) cannot be computed in floating point"},
        {"--D1 1e-100 --D2 1e300 --n 2 --d 1e-200 --G 1e300 --H 1e12", "rho = D1/D2 underflows"},
        {"--D1 1e11 --D2 1e300 --n 2 --d 1e10 --G 1e300 --H 1e12",
         "F_C (the cone's solid load, N) overflows"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        for (int c = 0; c < 2; c++) {
            int rc = tu_run(out, sizeof out, err, sizeof err, "%s %s%s", c ? "info" : "force",
                            cases[i].spring, c ? "" : " --u 1");
            assert_int_equal(rc, 2);
            if (!strstr(err, cases[i].says))
                fail_msg("'%s' does not say '%s'", err, cases[i].says);
            if (has_nan_or_inf(err))
                fail_msg("a NaN or Inf in '%s'", err);
        }
}

/* Two shard summaries of a two-table study in dir/s/; a third file named "-x.tsv", a copy of
** the first. */
static void make_shards(void)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/s'", dir);
    assert_int_equal(system(cmd), 0);
    for (int k = 1; k <= 2; k++)
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                                "fit data/telescoping.csv data/non_telescoping.csv --shard %d/2 "
                                "-q -o '%s/s/'",
                                k, dir),
                         0);
    snprintf(cmd, sizeof cmd, "cp '%s/s/summary-1-of-2.tsv' '%s/s/-x.tsv'", dir, dir);
    assert_int_equal(system(cmd), 0);
}

static void merge_takes_double_dash_and_refuses_a_folder_as_missing(void **state)
{
    (void)state;
    make_shards();
    char want[16384];
    assert_int_equal(tu_run(want, sizeof want, err, sizeof err,
                            "merge '%s/s/summary-1-of-2.tsv' '%s/s/summary-2-of-2.tsv'", dir, dir),
                     0);
    assert_non_null(strstr(want, "telescoping.csv"));
    /* a name starting with '-' after --, from the folder itself */
    char cmd[8192], bin[PATH_MAX];
    assert_non_null(realpath(tu_conifit(), bin));
    snprintf(cmd, sizeof cmd, "cd '%s/s' && '%s' merge -- -x.tsv summary-2-of-2.tsv >'%s/m.tsv'",
             dir, bin, dir);
    assert_int_equal(system(cmd), 0);
    char path[512];
    snprintf(path, sizeof path, "%s/m.tsv", dir);
    char *got = tu_slurp(path);
    assert_non_null(got);
    assert_string_equal(got, want);
    free(got);
    /* without --, "-x.tsv" is an unknown option */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "merge -x.tsv"), 2);
    /* a folder is not a readable summary: 66, as for fit, export, simulate */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "merge '%s/s'", dir), 66);
    assert_non_null(strstr(err, "folder"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit '%s/s'", dir), 66);
}

static void a_repeated_shard_is_a_usage_error(void **state)
{
    (void)state;
    const char *forms[2] = {"--shard 1/2 --shard 2/2", "--shard=1/2 --shard=1/2"};
    for (int i = 0; i < 2; i++) {
        int rc = tu_run(out, sizeof out, err, sizeof err, "fit data/telescoping.csv %s -q -o '%s/r/'",
                        forms[i], dir);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(err, "--shard given twice"));
    }
    char path[512];
    snprintf(path, sizeof path, "%s/r", dir);
    assert_int_equal(access(path, F_OK), -1); /* nothing written */
}

static void one_file_for_the_fit_and_the_plot_is_refused(void **state)
{
    (void)state;
    char a[512], b[512], cmd[2400];
    snprintf(a, sizeof a, "%s/h/fit.json", dir);
    snprintf(b, sizeof b, "%s/h/fit.png", dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/h' && echo old > '%s' && ln '%s' '%s'", dir, a, a, b);
    assert_int_equal(system(cmd), 0);
    int rc = tu_run(out, sizeof out, err, sizeof err, "fit data/telescoping.csv -o '%s' --plot '%s'",
                    a, b);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(err, "both outputs name one file"));
    char *text = tu_slurp(a);
    assert_non_null(text);
    assert_string_equal(text, "old\n");
    free(text);
    snprintf(cmd, sizeof cmd, "test $(ls -A '%s/h' | wc -l) -eq 2", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_refused_spring_names_the_command_that_ran),
        cmocka_unit_test(an_unrepresentable_spring_names_the_quantity_never_nan),
        cmocka_unit_test(merge_takes_double_dash_and_refuses_a_folder_as_missing),
        cmocka_unit_test(a_repeated_shard_is_a_usage_error),
        cmocka_unit_test(one_file_for_the_fit_and_the_plot_is_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
