/*
** conifit fit --shard K/N and conifit merge: a study of 52 synthetic tables fitted in one process
** and split four ways gives the same fit files and, merged, the same summary; a shard run again
** fits only the tables whose fit file is missing or incomplete; a --shard out of range is a usage
** error (2); a merge of an incomplete or overlapping split is refused (65).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "testutil.h"

#define NTABLES 52

TU_SCRATCH_GROUP("shard")

static char err[8192];

/* The study: 52 tables of springs of several shapes, with noise, in dir/t/. */
static void make_study(void)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/t' '%s/one' '%s/split'", dir, dir, dir);
    assert_int_equal(system(cmd), 0);
    for (int i = 0; i < NTABLES; i++)
        assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                                "synth --D1 %g --D2 %g --n %g --d 0.8 --G 800 --H 10 --noise 0.01 "
                                "--seed %d --points 20 -q -o '%s/t/s%02d.csv'",
                                3.0 + (i % 5) * 0.7, 12.0 + (i % 3), 4.0 + (i % 4), i + 1, dir, i),
                         0);
}

static void test_split_equals_one_process(void **state)
{
    (void)state;
    make_study();
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/*.csv --shard 1/1 -j 2 -q -o '%s/one/'",
                            dir, dir), 0);
    for (int k = 1; k <= 4; k++)
        assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                                "fit '%s'/t/*.csv --shard %d/4 -q -o '%s/split/'", dir, k, dir), 0);
    /* every table once, in one of the four summaries */
    char a[4200], b[4200];
    int rows = 0;
    for (int k = 1; k <= 4; k++) {
        snprintf(a, sizeof a, "%s/split/summary-%d-of-4.tsv", dir, k);
        char *text = tu_slurp(a);
        assert_non_null(text);
        assert_non_null(strstr(text, "of 52 tables\n"));
        for (char *p = text; (p = strstr(p, ".csv\t")); p++)
            rows++;
        free(text);
    }
    assert_int_equal(rows, NTABLES);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/split/summary-*-of-4.tsv -o '%s/merged.tsv'",
                            dir, dir), 0);
    snprintf(a, sizeof a, "%s/merged.tsv", dir);
    snprintf(b, sizeof b, "%s/one/summary-1-of-1.tsv", dir);
    assert_text_close(a, b, 1e-9);
    for (int i = 0; i < NTABLES; i++) {
        snprintf(a, sizeof a, "%s/one/s%02d.json", dir, i);
        snprintf(b, sizeof b, "%s/split/s%02d.json", dir, i);
        assert_text_close(a, b, 1e-9);
    }
}

static void test_resume(void **state)
{
    (void)state;
    char path[4200], cmd[4400], sum[4200];
    struct stat before, after;
    /* shard 2 of 4 holds s01, s05, ...: lose one fit file, truncate another */
    snprintf(path, sizeof path, "%s/split/s05.json", dir);
    assert_int_equal(remove(path), 0);
    snprintf(cmd, sizeof cmd, "head -c 100 '%s/one/s09.json' > '%s/split/s09.json'", dir, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(path, sizeof path, "%s/split/s13.json", dir);
    assert_int_equal(stat(path, &before), 0);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/*.csv --shard 2/4 -q -o '%s/split/'", dir, dir), 0);
    assert_int_equal(stat(path, &after), 0);
    assert_int_equal(before.st_ino, after.st_ino); /* complete: not written again */
    assert_int_equal(before.st_mtime, after.st_mtime);
    for (int i = 5; i <= 9; i += 4) {
        char a[4200], b[4200];
        snprintf(a, sizeof a, "%s/one/s%02d.json", dir, i);
        snprintf(b, sizeof b, "%s/split/s%02d.json", dir, i);
        assert_text_close(a, b, 1e-9);
    }
    snprintf(sum, sizeof sum, "%s/merged2.tsv", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/split/summary-*-of-4.tsv -o '%s'", dir, sum), 0);
    snprintf(path, sizeof path, "%s/one/summary-1-of-1.tsv", dir);
    assert_text_close(sum, path, 1e-9);
}

static void test_bad_shards(void **state)
{
    (void)state;
    const char *bad[] = {"0/4", "5/4", "4/0", "-1/4", "a/b", "1/", "/4", "1/4x", "2"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/s00.csv --shard '%s' -o '%s/x/'",
                                dir, bad[i], dir), 2);
        assert_non_null(strstr(err, "--shard"));
    }
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/s00.csv --shard", dir), 2);
    /* a shard writes one fit file per table: a folder is needed */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/s00.csv --shard 1/2 -o '%s/x.json'", dir, dir), 2);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/t/s00.csv --shard 1/2", dir), 2);
    /* merges of an incomplete split, of a shard twice, of two splits, of something else */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/split/summary-1-of-4.tsv '%s'/split/summary-2-of-4.tsv", dir, dir), 65);
    assert_non_null(strstr(err, "shard 3/4 is missing"));
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/split/summary-*-of-4.tsv '%s'/split/summary-1-of-4.tsv", dir, dir), 65);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/split/summary-*-of-4.tsv '%s'/one/summary-1-of-1.tsv", dir, dir), 65);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/t/s00.csv", dir), 65);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/nothing.tsv", dir), 66);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge"), 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_equals_one_process),
        cmocka_unit_test(test_resume),
        cmocka_unit_test(test_bad_shards),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
