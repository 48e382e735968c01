/*
** `conifit fit --shard K/N` and `conifit merge` (cli_shard.h). A study's tables are sorted by
** their escaped names (cli_summary.h) and dealt out: shard K of N takes the (K-1)-th, (K-1+N)-th,
** ... table, so that N processes given the same list fit every table once, wherever they run.
** Each table's fit file lands in the output folder as soon as it is fitted, stamped with the
** options of the study; a table whose fit file is already there, complete (fit files are written
** atomically) and fitted with the same options is not fitted again, so a killed shard is resumed
** by running it again, and a rerun with other options fits every table again. A table that
** fails leaves no fit file and a "failed: REASON" row; a rerun tries it again. Each shard writes
** DIR/summary-K-of-N.tsv; merge checks that the summaries are the whole of one study and writes
** the summary one process (--shard 1/1) would have written.
*/
#define _GNU_SOURCE /* O_CLOEXEC */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>

#include "base/atomic.h"
#include "base/input.h"
#include "base/safetext.h"
#include "cli/cli.h"
#include "cli/cli_shard.h"
#include "cli/cli_summary.h"
#include "io/fitfile.h"

static int parse_kn(const char *v, long *k, long *n)
{
    char *end;
    errno = 0;
    *k = strtol(v, &end, 10);
    if (end == v || *end != '/' || errno)
        return -1;
    const char *s = end + 1;
    *n = strtol(s, &end, 10);
    if (end == s || *end || errno)
        return -1;
    return 0;
}

int cf_cli_shard_take(int *argc, char **argv, cf_shard *sh)
{
    memset(sh, 0, sizeof *sh);
    int w = 1;
    for (int i = 1; i < *argc; i++) {
        const char *v = NULL;
        if (strcmp(argv[i], "--") == 0) { /* operands from here on */
            while (i < *argc)
                argv[w++] = argv[i++];
            break;
        }
        if (strcmp(argv[i], "--shard") == 0) {
            if (i + 1 >= *argc)
                return cf_cli_usage_error("fit", "--shard needs K/N (this process's share, 1..N, "
                                                 "of N)");
            v = argv[++i];
        } else if (strncmp(argv[i], "--shard=", 8) == 0) {
            v = argv[i] + 8;
        } else {
            argv[w++] = argv[i];
            continue;
        }
        if (sh->given)
            return cf_cli_usage_error("fit", "--shard given twice (%ld/%ld, then '%s'): a "
                                             "process fits one share",
                                      sh->k, sh->n, v);
        if (parse_kn(v, &sh->k, &sh->n) != 0)
            return cf_cli_usage_error("fit", "--shard '%s': expected K/N, two whole numbers", v);
        if (sh->n < 1 || sh->n > 1000000 || sh->k < 1 || sh->k > sh->n)
            return cf_cli_usage_error("fit", "--shard %ld/%ld: K must lie in 1..N and N in "
                                             "1..1000000", sh->k, sh->n);
        sh->given = 1;
    }
    *argc = w;
    argv[w] = NULL;
    return -1;
}

/* The table's name as summaries write it (cli_summary.h); sorted by this everywhere. */
static int by_name(const void *a, const void *b)
{
    const cf_shard_table *x = a, *y = b;
    return strcmp(x->name, y->name);
}

static int by_output(const void *a, const void *b)
{
    const cf_shard_table *x = *(const cf_shard_table *const *)a,
                         *y = *(const cf_shard_table *const *)b;
    return strcmp(x->fit, y->fit);
}

void cf_cli_path_in_dir(char *dst, size_t cap, const char *dir, const char *file, const char *ext)
{
    if (strcmp(file, "-") == 0)
        file = "stdin"; /* a table read from standard input */
    const char *base = strrchr(file, '/');
    base = base ? base + 1 : file;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot && dot != base)
        n = (size_t)(dot - base);
    size_t dl = strlen(dir);
    snprintf(dst, cap, "%s%s%.*s%s", dir, (dl && dir[dl - 1] == '/') ? "" : "/", (int)n, base,
             ext);
}

/* s (escaped: printable, UTF-8) as a JSON string's contents at t; returns the end. */
static char *json_text(char *t, const char *s)
{
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            *t++ = '\\';
        *t++ = *s;
    }
    return t;
}

/* What the fit file of table `name` (escaped) in this study ends with: the table and the options
** it was fitted with, as its last members (cf_cli_shard_stamp). malloc'd. */
static char *stamp_tail(const char *name, const char *options)
{
    char *t = malloc(2 * (strlen(name) + strlen(options)) + 64);
    if (!t)
        return NULL;
    char *w = t + sprintf(t, ",\n  \"shard_table\": \"");
    w = json_text(w, name);
    w += sprintf(w, "\",\n  \"shard_options\": \"");
    w = json_text(w, options);
    strcpy(w, "\"\n}\n");
    return t;
}

/* 1 when the fit file at path loads and was fitted for this table with this study's options (it
** ends with the table's tail). */
static int complete(const char *path, const char *name, const char *options)
{
    cf_fitted_spring fs;
    cf_error err = {0};
    int ok = 0;
    for (int t = 0; t < 2 && !ok; t++)
        ok = cf_fitfile_load(path, cf_spring_type_name((cf_spring_type)t), &fs, &err) == CF_OK;
    char *tail = ok ? stamp_tail(name, options) : NULL;
    if (!tail)
        return 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    const size_t tl = strlen(tail);
    char *buf = malloc(tl + 1);
    ok = buf && fseek(f, -(long)tl, SEEK_END) == 0 && fread(buf, 1, tl, f) == tl &&
         memcmp(buf, tail, tl) == 0;
    free(buf);
    free(tail);
    fclose(f);
    return ok;
}

cf_status cf_cli_shard_stamp(const cf_shard *sh, const char *file, cf_atomic *json,
                             cf_error *err)
{
    if (!json->tmp[0])
        return cf_error_set(err, CF_E_INTERNAL, "%s: no fit file to stamp", json->path);
    cf_status st = cf_atomic_finish(json, err);
    if (st != CF_OK)
        return st;
    cf_shard_table key = {.name = cf_summary_escape(file, strlen(file), 0)};
    const cf_shard_table *t =
        key.name ? bsearch(&key, sh->tables, (size_t)sh->ntables, sizeof key, by_name) : NULL;
    free(key.name);
    char *tail = t ? stamp_tail(t->name, sh->options) : NULL;
    if (!tail) {
        cf_atomic_abort(json);
        return cf_error_set(err, CF_E_INTERNAL, "%s: %s", json->path,
                            t ? "out of memory" : "not a table of the shard");
    }
    int fd = open(json->tmp, O_RDWR | O_CLOEXEC);
    char end[64];
    struct stat s;
    off_t at = -1;
    if (fd >= 0 && fstat(fd, &s) == 0) {
        off_t from = s.st_size > (off_t)sizeof end ? s.st_size - (off_t)sizeof end : 0;
        ssize_t got = pread(fd, end, (size_t)(s.st_size - from), from);
        for (ssize_t i = got - 1; i >= 0 && at < 0; i--)
            if (end[i] == '}')
                at = from + i;
            else if (end[i] != '\n' && end[i] != ' ')
                break;
    }
    const size_t tl = strlen(tail);
    int ok = at > 0 && ftruncate(fd, at) == 0 && pwrite(fd, tail, tl, at) == (ssize_t)tl;
    free(tail);
    if (fd >= 0 && close(fd) != 0)
        ok = 0;
    if (!ok) {
        cf_atomic_abort(json);
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: %s", json->path,
                            at > 0 ? strerror(errno) : "the fit file does not end in '}'");
    }
    return CF_OK;
}

int cf_cli_shard_select(cf_shard *sh, const char *out, const char *options, const char ***files,
                        int *nfiles)
{
    if (!out || cf_cli_is_stdio(out) || !cf_cli_is_dir_target(out))
        return cf_cli_usage_error("fit", "--shard writes one fit file per table: give a folder, "
                                         "-o DIR/");
    for (int i = 0; i < *nfiles; i++)
        if (cf_cli_is_stdio((*files)[i]))
            return cf_cli_usage_error("fit", "--shard reads tables from files, not standard "
                                             "input");
    const size_t nf = (size_t)*nfiles;
    cf_shard_table *all = calloc(nf + 1, sizeof *all);
    cf_shard_table **byout = calloc(nf + 1, sizeof *byout);
    const char **names = calloc(nf + 1, sizeof *names);
    const char **todo = calloc(nf + 1, sizeof *todo);
    sh->tables = calloc(nf + 1, sizeof *sh->tables);
    sh->options = strdup(options);
    int rc = -1;
    for (size_t i = 0; i < nf && all; i++) {
        const char *f = (*files)[i];
        all[i].file = f;
        all[i].name = cf_summary_escape(f, strlen(f), 0);
        all[i].fit = malloc(strlen(out) + strlen(f) + 8);
        if (!all[i].name || !all[i].fit)
            break;
        cf_cli_path_in_dir(all[i].fit, strlen(out) + strlen(f) + 8, out, f, ".json");
    }
    for (size_t i = 0; rc < 0 && i < nf; i++)
        if (!all || !all[i].name || !all[i].fit)
            rc = -2;
    if (rc < 0 && (!byout || !names || !todo || !sh->tables || !sh->options))
        rc = -2;
    if (rc == -2) {
        fprintf(stderr, "conifit: out of memory\n");
        rc = CF_EXIT_SOFTWARE;
    }
    size_t distinct = 0;
    if (rc < 0) {
        qsort(all, nf, sizeof *all, by_name);
        for (size_t i = 0; i < nf; i++) {
            if (distinct > 0 && strcmp(all[i].name, all[distinct - 1].name) == 0) {
                free(all[i].name); /* a table named twice is fitted once */
                free(all[i].fit);
                continue;
            }
            all[distinct++] = all[i];
        }
        for (size_t i = 0; i < distinct; i++) {
            byout[i] = &all[i];
            names[i] = all[i].name;
        }
        /* two tables of the study with one output name: refused in every shard alike */
        qsort(byout, distinct, sizeof *byout, by_output);
        for (size_t i = 1; i < distinct && rc < 0; i++)
            if (strcmp(byout[i - 1]->fit, byout[i]->fit) == 0)
                rc = cf_cli_usage_error("fit", "tables %s and %s of the study would both be "
                                               "written to %s; give them different names",
                                        byout[i - 1]->name, byout[i]->name, byout[i]->fit);
    }
    if (rc < 0) {
        cf_summary_study(options, names, distinct, sh->study);
        int ntodo = 0;
        sh->ntables = 0;
        for (size_t i = 0; i < distinct; i++) {
            if (i % (size_t)sh->n != (size_t)(sh->k - 1))
                continue;
            sh->tables[sh->ntables++] = all[i];
            all[i].name = all[i].fit = NULL; /* the shard's now */
            if (!complete(sh->tables[sh->ntables - 1].fit, sh->tables[sh->ntables - 1].name,
                          options))
                todo[ntodo++] = all[i].file;
        }
        sh->total = (long)distinct;
        *files = todo;
        *nfiles = ntodo;
        todo = NULL;
    }
    for (size_t i = 0; all && i < distinct; i++) {
        free(all[i].name);
        free(all[i].fit);
    }
    free(all);
    free(byout);
    free(names);
    free(todo);
    return rc;
}

void cf_cli_shard_failed(cf_shard *sh, const char *file, const char *reason)
{
    for (int i = 0; i < sh->ntables; i++)
        if (sh->tables[i].file == file || strcmp(sh->tables[i].file, file) == 0) {
            free(sh->tables[i].why);
            sh->tables[i].why = cf_summary_escape(reason, strlen(reason), 0);
            return;
        }
}

/* The cell of one type: its RMSE in the table's unit, or "-" when the file has no such fit. */
static void rmse_cell(const char *path, int type, char *cell, size_t cap, char *unit, size_t ucap)
{
    cf_fitted_spring fs;
    cf_error err = {0};
    snprintf(cell, cap, "-");
    if (cf_fitfile_load(path, cf_spring_type_name((cf_spring_type)type), &fs, &err) != CF_OK ||
        fs.type != (cf_spring_type)type)
        return;
    if (fs.rmse == fs.rmse)
        snprintf(cell, cap, "%.10g", fs.rmse);
    if (fs.y_unit[0]) {
        char *u = cf_summary_escape(fs.y_unit, strlen(fs.y_unit), 0);
        if (u)
            snprintf(unit, ucap, "%s", u);
        free(u);
    }
}

/* The better type as the fit file says it: its better_type, "tie" when its comparison is a tie,
** "none" when it compared two types and neither has a spring, "-" when it compared none. */
static void better_cell(const char *path, char *cell, size_t cap)
{
    snprintf(cell, cap, "-");
    json_error_t je;
    json_t *root = json_load_file(path, 0, &je);
    if (!root)
        return;
    const char *b = json_string_value(json_object_get(root, "better_type"));
    json_t *cmp = json_object_get(root, "comparison");
    if (b)
        cf_safe_text(cell, cap, b, strlen(b));
    else if (json_is_true(json_object_get(cmp, "tie")))
        snprintf(cell, cap, "tie");
    else if (json_is_object(cmp))
        snprintf(cell, cap, "none");
    json_decref(root);
}

int cf_cli_shard_summary(const cf_shard *sh, const char *out)
{
    char path[4200], name[64];
    snprintf(name, sizeof name, "summary-%ld-of-%ld.tsv", sh->k, sh->n);
    size_t dl = strlen(out);
    snprintf(path, sizeof path, "%s%s%s", out, (dl && out[dl - 1] == '/') ? "" : "/", name);
    const char **inputs = calloc((size_t)sh->ntables + 1, sizeof *inputs);
    if (!inputs) {
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    for (int i = 0; i < sh->ntables; i++)
        inputs[i] = sh->tables[i].file; /* the inputs a summary must not overwrite */
    cf_cli_out o;
    cf_error err = {0};
    cf_status st = cf_cli_out_open(&o, path, inputs, &err);
    free(inputs);
    if (st != CF_OK)
        return cf_cli_fail(&err);
    fprintf(o.fp, CF_SUMMARY_MAGIC "%ld/%ld of %ld tables; study %s; options: %s\n"
                  CF_SUMMARY_HEADER, sh->k, sh->n, sh->total, sh->study, sh->options);
    for (int i = 0; i < sh->ntables; i++) {
        const cf_shard_table *t = &sh->tables[i];
        char cell[2][40], unit[64] = "-", better[32] = "-";
        for (int k = 0; k < 2; k++)
            rmse_cell(t->fit, k, cell[k], sizeof cell[k], unit, sizeof unit);
        if (!t->why)
            better_cell(t->fit, better, sizeof better);
        const char *base = strrchr(t->fit, '/'); /* the name alone: shards may write elsewhere */
        base = base ? base + 1 : t->fit;
        char *fitname = cf_summary_escape(base, strlen(base), 0);
        if (t->why) /* failed in this run: it has no fit file of this study */
            fprintf(o.fp, "%s\t-\t-\t-\t-\t%s\tfailed: %s\n", t->name, fitname ? fitname : "-",
                    t->why);
        else
            fprintf(o.fp, "%s\t%s\t%s\t%s\t%s\t%s\tok\n", t->name, cell[0], cell[1], unit, better,
                    fitname ? fitname : "-");
        free(fitname);
    }
    if (cf_cli_out_close(&o, &err) != CF_OK)
        return cf_cli_fail(&err);
    return CF_EXIT_OK;
}

void cf_cli_shard_free(cf_shard *sh)
{
    for (int i = 0; sh->tables && i < sh->ntables; i++) {
        free(sh->tables[i].name);
        free(sh->tables[i].fit);
        free(sh->tables[i].why);
    }
    free(sh->tables);
    free(sh->options);
    sh->tables = NULL;
    sh->options = NULL;
    sh->ntables = 0;
}

/* ---- conifit merge ---- */

static const char merge_help[] =
    "usage: conifit merge SUMMARY.tsv... [-o FILE]\n"
    "Merges the summaries that `conifit fit --shard K/N -o DIR/` writes (DIR/summary-K-of-N.tsv)\n"
    "into the summary of the whole study, as one process (--shard 1/1) writes it: rows sorted by\n"
    "table. Refused (exit 65, naming the file and what is wrong) unless the files are the N\n"
    "shards of one study (one table count, study and options), each once, each holding its whole\n"
    "share, and their rows the tables each shard takes; a FIFO or device is refused unread, a\n"
    "folder is a missing input (exit 66). After --, every argument is a summary, even one whose\n"
    "name starts with '-'.\n\n"
    "  -o, --output FILE  the merged summary (atomically); default, or '-': standard output\n";

/* Reads one shard's summary into s: a regular file (a FIFO or device would block or never end),
** parsed by cf_summary_parse. -1 to go on, else an exit status (its message printed). */
static int read_summary(const char *path, cf_summary *s)
{
    cf_error err = {0};
    memset(s, 0, sizeof *s);
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        cf_error_set(&err, CF_E_NOINPUT, "%s: cannot open: %s", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return cf_cli_fail(&err);
    }
    if (S_ISDIR(st.st_mode)) {
        close(fd);
        cf_error_set(&err, CF_E_NOINPUT, "%s: is a folder, not a summary (give its "
                     "summary-K-of-N.tsv files)", path);
        return cf_cli_fail(&err);
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        cf_error_set(&err, CF_E_DATA, "%s: is %s, not a regular file: not a summary", path,
                     cf_file_kind(st.st_mode));
        return cf_cli_fail(&err);
    }
    size_t cap = (size_t)st.st_size + 1, len = 0;
    char *text = malloc(cap);
    for (ssize_t got = 1; text && got > 0;) {
        if (len == cap) {
            char *t = realloc(text, 2 * cap);
            if (!t) {
                free(text);
                text = NULL;
                break;
            }
            text = t;
            cap *= 2;
        }
        got = read(fd, text + len, cap - len);
        if (got < 0 && errno == EINTR)
            got = 1;
        else if (got < 0) {
            cf_error_set(&err, CF_E_NOINPUT, "%s: cannot read: %s", path, strerror(errno));
            free(text);
            close(fd);
            return cf_cli_fail(&err);
        } else
            len += (size_t)got;
    }
    close(fd);
    if (!text) {
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    cf_status rc = cf_summary_parse(text, len, path, s, &err);
    free(text);
    return rc == CF_OK ? -1 : cf_cli_fail(&err);
}

int cf_cli_merge(int argc, char **argv)
{
    const char *out = NULL;
    const char **paths = calloc((size_t)argc + 1, sizeof *paths);
    cf_summary *sums = calloc((size_t)argc + 1, sizeof *sums);
    int nfiles = 0, rc = -1;
    if (!paths || !sums) {
        free(paths);
        free(sums);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    for (int i = 1; i < argc && rc == -1; i++) {
        if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            fputs(merge_help, stdout);
            rc = CF_EXIT_OK;
        } else if (strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--output") == 0) {
            if (i + 1 >= argc)
                rc = cf_cli_usage_error("merge", "%s needs a file name", argv[i]);
            else
                out = argv[++i];
        } else if (strcmp(argv[i], "--") == 0) { /* summaries from here on, whatever their name */
            while (++i < argc)
                paths[nfiles++] = argv[i];
        } else if (argv[i][0] == '-' && argv[i][1]) {
            rc = cf_cli_usage_error("merge", "unknown option '%s'", argv[i]);
        } else {
            paths[nfiles++] = argv[i];
        }
    }
    if (rc == -1 && nfiles == 0)
        rc = cf_cli_usage_error("merge", "no summary given");
    int nread = 0;
    for (; nread < nfiles && rc == -1; nread++)
        rc = read_summary(paths[nread], &sums[nread]);
    const cf_summary_row **rows = NULL;
    size_t nrows = 0;
    cf_error err = {0};
    if (rc == -1 && cf_summary_join(sums, (size_t)nfiles, paths, &rows, &nrows, &err) != CF_OK)
        rc = cf_cli_fail(&err);
    if (rc == -1) {
        cf_cli_out o;
        if (cf_cli_out_open(&o, out, paths, &err) != CF_OK) {
            rc = cf_cli_fail(&err);
        } else {
            fprintf(o.fp, CF_SUMMARY_MAGIC "1/1 of %ld tables; study %s; options: %s\n"
                          CF_SUMMARY_HEADER, sums[0].total, sums[0].study, sums[0].options);
            for (size_t i = 0; i < nrows; i++)
                fputs(rows[i]->line, o.fp);
            rc = cf_cli_out_close(&o, &err) == CF_OK ? CF_EXIT_OK : cf_cli_fail(&err);
        }
    }
    size_t failed = 0;
    for (size_t i = 0; rc == CF_EXIT_OK && i < nrows; i++)
        failed += strstr(rows[i]->line, "\tfailed: ") != NULL;
    if (failed)
        fprintf(stderr, "conifit merge: note: %zu of %zu tables failed (their rows say why); run "
                        "their shards again to try them again\n", failed, nrows);
    free(rows);
    for (int i = 0; i < nread; i++)
        cf_summary_free(&sums[i]);
    free(paths);
    free(sums);
    return rc;
}
