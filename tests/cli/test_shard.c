/*
** conifit fit --shard K/N and conifit merge: a study of 52 synthetic tables fitted in one process
** and split four ways gives the same fit files and, merged, the same summary; a shard run again
** fits only the tables whose fit file is missing or incomplete; a --shard out of range is a usage
** error (2); a merge of an incomplete or overlapping split is refused (65).
** Then (issue 37): a shard killed part way keeps every table it finished and its rerun fits only
** the rest, to a merge equal to one process's; a table that cannot be fitted is a "failed" row
** and the study still merges; two tables with one output name are refused in every shard; a
** merge refuses summaries that lost rows, of two studies, of impossible shards, FIFOs, and rows
** that are not their shard's; a rerun with other options fits again; an empty shard writes its
** summary; the summary says "tie" as the fit file does; table names with a tab, a newline or a
** byte that is not UTF-8 have one form and one order in shards and merge; a signal the parent
** ignored stays ignored.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>

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
        assert_non_null(strstr(text, "of 52 tables; study "));
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

/* ---- issue 37 ---- */

/* Runs `sh -c SCRIPT` (printf-formatted) and returns its exit status. */
static int sh(const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Fit files (NAME.json) in folder d. */
static int fit_files(const char *d)
{
    char cmd[4400], buf[64] = "";
    snprintf(cmd, sizeof cmd, "ls '%s' | grep -c '\\.json$'", d);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    if (!fgets(buf, sizeof buf, p))
        buf[0] = '\0';
    pclose(p);
    return atoi(buf);
}

/* Hidden temporaries (.NAME.conifit-...) in folder d. */
static int temporaries_in(const char *d)
{
    char cmd[4400], buf[64] = "";
    snprintf(cmd, sizeof cmd, "ls -A '%s' | grep -c '\\.conifit-'", d);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    if (!fgets(buf, sizeof buf, p))
        buf[0] = '\0';
    pclose(p);
    return atoi(buf);
}

/* The study of the kill test: the shipped tables of data/ and, when ../shared/datasets is there,
** three published uniaxial ones, as arguments for a shell. */
static void real_study(char *args, size_t cap)
{
    int n = snprintf(args, cap, "data/*.csv");
    const char *ds = tu_datasets();
    if (ds)
        snprintf(args + n, cap - (size_t)n, " %s/brain_cortex_tension.csv "
                 "%s/brain_coronaradiata_tension.csv %s/treloar1944_rubber_uniaxial.csv", ds, ds,
                 ds);
}

static void sleep_ms(long ms)
{
    struct timespec t = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* Starts `conifit ARGS` (through sh, exec'd so the PID is conifit's) with output to /dev/null. */
static pid_t start(const char *args)
{
    char cmd[8400];
    snprintf(cmd, sizeof cmd, "exec %s %s >/dev/null 2>&1", tu_conifit(), args);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    return pid;
}

/* A shard (validated: about half a second a table) killed (SIGKILL, then SIGTERM as a scheduler
** at its time limit) after its first fit files keeps them; the rerun fits only the others (the kept files untouched), and the merge of
** the resumed study equals the summary of one uninterrupted process, file for file. */
static void test_killed_shard_keeps_finished_tables(void **state)
{
    (void)state;
    char study[2048], args[8192], killed[4200], one[4200], a[4300], b[4300];
    real_study(study, sizeof study);
    snprintf(one, sizeof one, "%s/real-one", dir);
    snprintf(killed, sizeof killed, "%s/real-killed", dir);
    assert_int_equal(sh("mkdir -p '%s' '%s'", one, killed), 0);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit %s --validate --shard 1/1 -q -o '%s/'",
                            study, one), 0);
    const int total = fit_files(one);
    assert_true(total >= 7);
    const int sig[2] = {SIGKILL, SIGTERM};
    for (int round = 0; round < 2; round++) {
        assert_int_equal(sh("rm -f '%s'/*.json '%s'/.*.conifit-*", killed, killed), 0);
        snprintf(args, sizeof args, "fit %s --validate --shard 1/1 -q -o '%s/'", study,
                 killed);
        pid_t pid = start(args);
        for (int t = 0; t < 60000 && fit_files(killed) < 1; t += 5)
            sleep_ms(5);
        kill(pid, sig[round]);
        int st;
        assert_int_equal(waitpid(pid, &st, 0), pid);
        assert_true(WIFSIGNALED(st) && WTERMSIG(st) == sig[round]);
        const int kept = fit_files(killed);
        assert_true(kept >= 1); /* every table finished before the signal */
        assert_true(kept < total);
        if (sig[round] == SIGTERM) /* the handler removed its temporaries */
            assert_int_equal(temporaries_in(killed), 0);
        /* the kept files are not fitted again (a fit file is put in place by a rename: one
        ** written again has a new inode) and the others are fitted once */
        assert_int_equal(sh("cd '%s' && ls -i *.json > ../kept.txt", killed), 0);
        assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                                "fit %s --validate --shard 1/1 -q -o '%s/'", study, killed), 0);
        assert_int_equal(sh("cd '%s' && ls -i *.json > ../after.txt && [ $(grep -cFxf ../kept.txt "
                            "../after.txt) -eq %d ]", killed, kept), 0);
        assert_int_equal(fit_files(killed), total);
        assert_int_equal(temporaries_in(killed), 0);
        snprintf(a, sizeof a, "%s/real-merged.tsv", dir);
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s/summary-1-of-1.tsv' -o '%s'",
                                killed, a), 0);
        snprintf(b, sizeof b, "%s/summary-1-of-1.tsv", one);
        assert_text_close(a, b, 1e-9);
        assert_int_equal(sh("cd '%s' && for f in *.json; do cmp -s \"$f\" '%s'/\"$f\" || "
                            "{ diff \"$f\" '%s'/\"$f\" | head; exit 1; }; done", one, killed,
                            killed), 0);
    }
}

/* A table that cannot be fitted (5 rows) is a "failed" row with its reason: its shard exits 65
** but writes its other fit files and its summary; the study merges; a rerun tries it again. */
static void test_failed_table_is_a_row(void **state)
{
    (void)state;
    char t[4200], o[4200], path[4300];
    snprintf(t, sizeof t, "%s/fail-t", dir);
    snprintf(o, sizeof o, "%s/fail-o", dir);
    assert_int_equal(sh("mkdir -p '%s' '%s' && cp data/telescoping.csv data/non_telescoping.csv "
                        "data/strongly_conical.csv '%s/' && printf 'strain,stress_kPa\\n0,0\\n"
                        "0.1,1\\n0.2,2.5\\n0.3,4\\n0.4,7\\n' > '%s/five.csv'", t, o, t, t), 0);
    for (int run = 0; run < 2; run++) {
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/*.csv --shard 1/2 -q -o '%s/'",
                                t, o), 65); /* five.csv, strongly_conical.csv */
        assert_non_null(strstr(err, "only 5 data rows"));
        snprintf(path, sizeof path, "%s/strongly_conical.json", o);
        assert_int_equal(access(path, F_OK), 0);
        snprintf(path, sizeof path, "%s/five.json", o);
        assert_int_equal(access(path, F_OK), -1);
    }
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/*.csv --shard 2/2 -q -o '%s/'", t,
                            o), 0);
    snprintf(path, sizeof path, "%s/fail-merged.tsv", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/summary-*-of-2.tsv -o '%s'", o,
                            path), 0);
    assert_non_null(strstr(err, "1 of 4 tables failed"));
    char *text = tu_slurp(path);
    assert_non_null(text);
    char *row = strstr(text, "/five.csv\t");
    assert_non_null(row);
    assert_non_null(strstr(row, "\tfailed: "));
    assert_non_null(strstr(row, "only 5 data rows"));
    assert_non_null(strstr(text, "/strongly_conical.csv\t"));
    assert_non_null(strstr(strstr(text, "/strongly_conical.csv\t"), "\tok\n"));
    free(text);
}

/* Two tables of the study with one base name fall into different shards; both shards refuse the
** study (2), naming both, and write nothing. */
static void test_one_output_name_refused_in_every_shard(void **state)
{
    (void)state;
    char o[4200];
    snprintf(o, sizeof o, "%s/dup-o", dir);
    assert_int_equal(sh("mkdir -p '%s/dup/a' '%s/dup/b' '%s' && cp data/telescoping.csv "
                        "'%s/dup/a/x.csv' && cp data/non_telescoping.csv '%s/dup/b/x.csv'",
                        dir, dir, o, dir, dir), 0);
    for (int k = 1; k <= 2; k++) {
        assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                                "fit '%s'/dup/a/x.csv '%s'/dup/b/x.csv --shard %d/2 -q -o '%s/'",
                                dir, dir, k, o), 2);
        assert_non_null(strstr(err, "/dup/a/x.csv"));
        assert_non_null(strstr(err, "/dup/b/x.csv"));
        assert_non_null(strstr(err, "x.json"));
    }
    assert_int_equal(sh("[ -z \"$(ls -A '%s')\" ]", o), 0);
}

/* Writes a copy of summary src to dst with sed expression expr applied. */
static void edited(const char *src, const char *dst, const char *expr)
{
    assert_int_equal(sh("sed '%s' '%s' > '%s'", expr, src, dst), 0);
}

/* Merge refuses (65, naming the file and what is wrong): a summary that lost a row or holds only
** its header, shards of two studies, shards 0/2 and 3/2, a shard whose rows are another's, a
** FIFO (at once, without blocking), a row that is not a summary row. */
static void test_merge_refuses_what_is_not_one_whole_study(void **state)
{
    (void)state;
    char s[5][4300], x[4300], y[4300];
    for (int k = 1; k <= 4; k++)
        snprintf(s[k], sizeof s[k], "%s/split/summary-%d-of-4.tsv", dir, k);
    snprintf(x, sizeof x, "%s/edited.tsv", dir);
    snprintf(y, sizeof y, "%s/edited2.tsv", dir);
    /* one row lost; only the header left */
    const char *cut[] = {"$d", "3,$d"};
    for (int i = 0; i < 2; i++) {
        edited(s[2], x, cut[i]);
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], x,
                                s[3], s[4]), 65);
        assert_non_null(strstr(err, "edited.tsv"));
        assert_non_null(strstr(err, "not whole"));
    }
    /* a row of shard 2 moved into shard 1 (counts still right if one of 1 goes to 2) */
    assert_int_equal(sh("{ head -2 '%s'; sed -n 3p '%s'; sed -n '4,$p' '%s'; } > '%s'", s[1], s[2],
                        s[1], x), 0);
    assert_int_equal(sh("{ head -2 '%s'; sed -n 3p '%s'; sed -n '4,$p' '%s'; } > '%s'", s[2], s[1],
                        s[2], y), 0);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", x, y, s[3],
                            s[4]), 65);
    /* shards 0/2 and 3/2 */
    edited(s[1], x, "1s/shard 1\\/4/shard 0\\/2/");
    edited(s[2], y, "1s/shard 2\\/4/shard 3\\/2/");
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s'", x, y), 65);
    assert_non_null(strstr(err, "edited.tsv:1"));
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s'", y, x), 65);
    assert_non_null(strstr(err, "edited2.tsv:1"));
    /* a shard of another study (other options), with the same table count and shard numbers */
    edited(s[3], x, "1s/options: .*/options: --seed 7/");
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], s[2], x,
                            s[4]), 65);
    assert_non_null(strstr(err, "not one study"));
    /* ... or another study id */
    edited(s[3], x, "1s/study [0-9a-f]*/study 0123456789abcdef/");
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], s[2], x,
                            s[4]), 65);
    /* a table renamed in a row: the study's tables are not these */
    edited(s[4], x, "3s/s03/s03x/");
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], s[2],
                            s[3], x), 65);
    assert_non_null(strstr(err, "study"));
    /* a row cut short */
    edited(s[4], x, "3s/\\tok$//");
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], s[2],
                            s[3], x), 65);
    assert_non_null(strstr(err, "edited.tsv:3"));
    /* a FIFO: refused at once (the shell's timeout would stop a merge that blocks) */
    snprintf(x, sizeof x, "%s/fifo.tsv", dir);
    assert_int_equal(mkfifo(x, 0600), 0);
    assert_int_equal(sh("timeout 20 %s merge '%s' 2>/dev/null", tu_conifit(), x), 65);
    remove(x);
    /* the untouched split still merges */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s' '%s' '%s' '%s'", s[1], s[2],
                            s[3], s[4]), 0);
}

/* A shard rerun with other options fits every table again (the fit files record the options);
** with the same options, none; an empty shard writes its summary (exit 0), --validate included;
** the summary's better type is the fit file's ("tie" included). */
static void test_options_are_part_of_the_study(void **state)
{
    (void)state;
    char o[4200], path[4300], out[16384];
    snprintf(o, sizeof o, "%s/opt-o", dir);
    assert_int_equal(sh("mkdir -p '%s'", o), 0);
    const char *tables = "data/telescoping.csv data/strongly_conical.csv data/non_telescoping.csv";
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "fit %s --shard 1/1 --type telescoping -o '%s/'", tables, o), 0);
    snprintf(path, sizeof path, "%s/summary-1-of-1.tsv", o);
    char *text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "options: --type telescoping\n"));
    assert_non_null(strstr(text, "data/telescoping.csv\t"));
    assert_non_null(strstr(strstr(text, "data/telescoping.csv\t"), "\t-\tkPa\ttelescoping\t"));
    free(text);
    /* the same options given another way: nothing to fit */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "fit %s --shard=1/1 --type=telescoping -j 2 -o '%s/'", tables, o), 0);
    assert_null(strstr(out, "Fit file: "));
    /* other options: every table again; the tie is the fit file's */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit %s --shard 1/1 -o '%s/'",
                            tables, o), 0);
    int refitted = 0;
    for (const char *p = out; (p = strstr(p, "Fit file: ")); p++)
        refitted++;
    assert_int_equal(refitted, 3);
    text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "options: -\n"));
    const char *row = strstr(text, "data/telescoping.csv\t");
    assert_non_null(row);
    assert_true(strstr(row, "\ttie\t") && strstr(row, "\ttie\t") < strchr(row, '\n'));
    free(text);
    snprintf(path, sizeof path, "%s/telescoping.json", o);
    text = tu_slurp(path);
    assert_non_null(text);
    assert_null(strstr(text, "\"better_type\""));
    assert_non_null(strstr(text, "\"tie\": true"));
    free(text);
    /* empty shards: N past the study, and a complete shard run again, with --validate */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit %s --shard 5/5 --validate -q -o '%s/'",
                            tables, o), 0);
    snprintf(path, sizeof path, "%s/summary-5-of-5.tsv", o);
    text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "shard 5/5 of 3 tables; study "));
    assert_non_null(strstr(text, "options: --validate\n"));
    free(text);
    assert_int_equal(sh("mkdir -p '%s/one'", o), 0);
    for (int run = 0; run < 2; run++)
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit data/telescoping.csv --shard 1/1 "
                                "--validate -q -o '%s/one/'", o), 0);
}

/* Names with a tab, a newline, a byte that is not UTF-8, a backslash and a blank: one escaped
** form, one order (of the escaped names) in every shard and in the merge, equal to one process's
** summary; every table once. */
static void test_awkward_names_one_form_one_order(void **state)
{
    (void)state;
    char t[4200], o[4200], one[4200], a[4300], b[4300];
    snprintf(t, sizeof t, "%s/awk-t", dir);
    snprintf(o, sizeof o, "%s/awk-o", dir);
    snprintf(one, sizeof one, "%s/awk-one", dir);
    assert_int_equal(sh("mkdir -p '%s' '%s' '%s' && cd '%s' && cp ../t/s00.csv \"$(printf "
                        "'a\\tz.csv')\" && cp ../t/s01.csv aZ.csv && cp ../t/s02.csv \"$(printf "
                        "'b\\nx.csv')\" && cp ../t/s03.csv \"$(printf 'c\\260.csv')\" && cp "
                        "../t/s04.csv 'd\\x41.csv' && cp ../t/s05.csv 'e f.csv' && cp ../t/s06.csv "
                        "A.csv", t, o, one, t), 0);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/* --shard 1/1 -q -o '%s/'", t,
                            one), 0);
    for (int k = 1; k <= 3; k++)
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "fit '%s'/* --shard %d/3 -q -o '%s/'", t,
                                k, o), 0);
    snprintf(a, sizeof a, "%s/awk-merged.tsv", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "merge '%s'/summary-*-of-3.tsv -o '%s'", o,
                            a), 0);
    snprintf(b, sizeof b, "%s/summary-1-of-1.tsv", one);
    assert_text_close(a, b, 1e-9);
    char *text = tu_slurp(a);
    assert_non_null(text);
    const char *order[] = {"/A.csv\t", "/aZ.csv\t", "/a\\x09z.csv\t", "/b\\x0ax.csv\t",
                           "/c\\xb0.csv\t", "/d\\x5cx41.csv\t", "/e f.csv\t"};
    const char *at = text;
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
        const char *p = strstr(at, order[i]);
        if (!p)
            print_error("%s missing or out of order in\n%s", order[i], text);
        assert_non_null(p);
        at = p;
    }
    free(text);
    /* a rerun of every shard fits nothing: each name finds its own fit file */
    for (int k = 1; k <= 3; k++) {
        char out[8192];
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                                "fit '%s'/* --shard %d/3 -o '%s/'", t, k, o), 0);
        assert_null(strstr(out, "Fit file: "));
    }
}

/* Started with SIGHUP and SIGINT ignored (nohup; a script's background job), a batch of the 52
** tables that receives both, again and again while it runs, runs to its end and writes every
** fit file. */
static void test_ignored_signals_stay_ignored(void **state)
{
    (void)state;
    char o[4200], rc[4300];
    snprintf(o, sizeof o, "%s/sig-o", dir);
    snprintf(rc, sizeof rc, "%s/sig-rc", dir);
    assert_int_equal(sh("mkdir -p '%s'", o), 0);
    assert_int_equal(sh("trap '' HUP INT; %s fit '%s'/t/*.csv -q -o '%s/' 2>/dev/null & pid=$!; "
                        "n=0; while kill -HUP $pid 2>/dev/null; do kill -INT $pid 2>/dev/null; "
                        "n=$((n+1)); sleep 0.01; done; wait $pid; echo $? $n > '%s'",
                        tu_conifit(), dir, o, rc), 0);
    char *text = tu_slurp(rc);
    assert_non_null(text);
    int status = -1, sent = 0;
    assert_int_equal(sscanf(text, "%d %d", &status, &sent), 2);
    free(text);
    assert_int_equal(status, 0);
    assert_true(sent >= 2); /* it ran through several rounds of both signals */
    assert_int_equal(fit_files(o), NTABLES);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_equals_one_process),
        cmocka_unit_test(test_resume),
        cmocka_unit_test(test_bad_shards),
        cmocka_unit_test(test_merge_refuses_what_is_not_one_whole_study),
        cmocka_unit_test(test_awkward_names_one_form_one_order),
        cmocka_unit_test(test_killed_shard_keeps_finished_tables),
        cmocka_unit_test(test_failed_table_is_a_row),
        cmocka_unit_test(test_one_output_name_refused_in_every_shard),
        cmocka_unit_test(test_options_are_part_of_the_study),
        cmocka_unit_test(test_ignored_signals_stay_ignored),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
