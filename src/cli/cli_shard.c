/*
** `conifit fit --shard K/N` and `conifit merge` (cli_shard.h). A study's tables are sorted by
** path and dealt out: shard K of N takes the (K-1)-th, (K-1+N)-th, ... table, so that N processes
** given the same list fit every table once, wherever they run. Each table's fit file lands in
** the output folder; a table whose fit file is already there and complete (fit files are written
** atomically, and the file names its table) is not fitted again, so a killed shard is resumed by
** running it again. Each shard writes DIR/summary-K-of-N.tsv, read back from the fit files; merge
** checks that every shard of one split is present once and writes the summary one process
** (--shard 1/1) would have written.
*/
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic.h"
#include "base/input.h"
#include "base/safetext.h"
#include "cli/cli.h"
#include "cli/cli_shard.h"
#include "conifit/fitfile.h"

#define SUMMARY_MAGIC "# conifit fit summary: shard "
#define SUMMARY_HEADER "table\ttelescoping_rmse\tnon_telescoping_rmse\tunit\tbetter_type\tfit_file\n"
#define ROW_MAX 12288

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

static int by_path(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
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

/* 1 when the fit file of table is in dir, loads, and names that table. */
static int complete(const char *dir, const char *table)
{
    char path[4200];
    cf_cli_path_in_dir(path, sizeof path, dir, table, ".json");
    cf_fitted_spring fs;
    cf_error err = {0};
    for (int t = 0; t < 2; t++)
        if (cf_fitfile_load(path, cf_spring_type_name((cf_spring_type)t), &fs, &err) == CF_OK)
            return !fs.data_file[0] || strcmp(fs.data_file, table) == 0;
    return 0;
}

int cf_cli_shard_select(cf_shard *sh, const char *out, const char ***files, int *nfiles)
{
    if (!out || cf_cli_is_stdio(out) || !cf_cli_is_dir_target(out))
        return cf_cli_usage_error("fit", "--shard writes one fit file per table: give a folder, "
                                         "-o DIR/");
    for (int i = 0; i < *nfiles; i++)
        if (cf_cli_is_stdio((*files)[i]))
            return cf_cli_usage_error("fit", "--shard reads tables from files, not standard "
                                             "input");
    const char **all = malloc(((size_t)*nfiles + 1) * sizeof *all);
    sh->mine = malloc(((size_t)*nfiles + 1) * sizeof *sh->mine);
    const char **todo = malloc(((size_t)*nfiles + 1) * sizeof *todo);
    if (!all || !sh->mine || !todo) {
        free(all);
        free(todo);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    memcpy(all, *files, (size_t)*nfiles * sizeof *all);
    qsort(all, (size_t)*nfiles, sizeof *all, by_path);
    int ntodo = 0, distinct = 0;
    sh->nmine = 0;
    for (int i = 0; i < *nfiles; i++) {
        if (i > 0 && strcmp(all[i], all[i - 1]) == 0)
            continue; /* a table named twice is fitted once */
        if (distinct++ % sh->n != sh->k - 1)
            continue;
        sh->mine[sh->nmine++] = all[i];
        if (!complete(out, all[i]))
            todo[ntodo++] = all[i];
    }
    sh->mine[sh->nmine] = NULL; /* the inputs a summary must not overwrite */
    sh->total = distinct;
    free(all);
    *files = todo;
    *nfiles = ntodo;
    return -1;
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
    if (fs.y_unit[0])
        cf_safe_text(unit, ucap, fs.y_unit, strlen(fs.y_unit));
}

int cf_cli_shard_summary(const cf_shard *sh, const char *out)
{
    char path[4200], name[64];
    snprintf(name, sizeof name, "summary-%ld-of-%ld.tsv", sh->k, sh->n);
    size_t dl = strlen(out);
    snprintf(path, sizeof path, "%s%s%s", out, (dl && out[dl - 1] == '/') ? "" : "/", name);
    cf_cli_out o;
    cf_error err = {0};
    if (cf_cli_out_open(&o, path, sh->mine, &err) != CF_OK)
        return cf_cli_fail(&err);
    fprintf(o.fp, SUMMARY_MAGIC "%ld/%ld of %d tables\n" SUMMARY_HEADER, sh->k, sh->n, sh->total);
    for (int i = 0; i < sh->nmine; i++) {
        char fit[4200], cell[2][40], unit[64] = "-", better[32] = "-", table[4200], fitname[4200];
        cf_cli_path_in_dir(fit, sizeof fit, out, sh->mine[i], ".json");
        for (int t = 0; t < 2; t++)
            rmse_cell(fit, t, cell[t], sizeof cell[t], unit, sizeof unit);
        cf_fitted_spring fs;
        if (cf_fitfile_load(fit, NULL, &fs, &err) == CF_OK)
            snprintf(better, sizeof better, "%s", cf_spring_type_name(fs.type));
        cf_safe_text(table, sizeof table, sh->mine[i], strlen(sh->mine[i]));
        const char *base = strrchr(fit, '/'); /* the name alone: shards may write elsewhere */
        base = base ? base + 1 : fit;
        cf_safe_text(fitname, sizeof fitname, base, strlen(base));
        fprintf(o.fp, "%s\t%s\t%s\t%s\t%s\t%s\n", table, cell[0], cell[1], unit, better, fitname);
    }
    if (cf_cli_out_close(&o, &err) != CF_OK)
        return cf_cli_fail(&err);
    return CF_EXIT_OK;
}

void cf_cli_shard_free(cf_shard *sh)
{
    free(sh->mine);
    sh->mine = NULL;
}

/* ---- conifit merge ---- */

static const char merge_help[] =
    "usage: conifit merge SUMMARY.tsv... [-o FILE]\n"
    "Merges the summaries that `conifit fit --shard K/N -o DIR/` writes (DIR/summary-K-of-N.tsv)\n"
    "into the summary of the whole study, as one process (--shard 1/1) writes it: rows sorted by\n"
    "table. Refused (exit 65) unless the files are the N shards of one split, each once, with\n"
    "every table once. After --, every argument is a summary, even one whose name starts with\n"
    "'-'.\n\n"
    "  -o, --output FILE  the merged summary (atomically); default, or '-': standard output\n";

typedef struct row {
    char *text; /* the whole line, newline included */
    size_t key; /* length of its first field (the table) */
} row;

static int by_row(const void *a, const void *b)
{
    const row *x = a, *y = b;
    size_t n = x->key < y->key ? x->key : y->key;
    int c = memcmp(x->text, y->text, n);
    return c ? c : (x->key > y->key) - (x->key < y->key);
}

/* Reads one shard's summary into rows (appended; *nrows updated), its K, N and table count. */
static int read_summary(const char *path, long *k, long *n, long *total, row **rows,
                        size_t *nrows, size_t *cap)
{
    cf_error err = {0};
    FILE *f = cf_input_open(path, "shard summary", &err); /* a folder: 66, as for any input */
    if (!f)
        return cf_cli_fail(&err);
    char line[ROW_MAX];
    int rc = -1;
    if (!fgets(line, sizeof line, f) || sscanf(line, SUMMARY_MAGIC "%ld/%ld of %ld tables", k, n,
                                                total) != 3)
        rc = cf_error_set(&err, CF_E_DATA, "%s:1: not a summary of conifit fit --shard", path);
    else if (!fgets(line, sizeof line, f) || strcmp(line, SUMMARY_HEADER) != 0)
        rc = cf_error_set(&err, CF_E_DATA, "%s:2: not the summary's column header", path);
    for (size_t ln = 3; rc == -1 && fgets(line, sizeof line, f); ln++) {
        char *tab = strchr(line, '\t');
        size_t len = strlen(line);
        if (!tab || len == 0 || line[len - 1] != '\n') {
            rc = cf_error_set(&err, CF_E_DATA, "%s:%zu: not a summary row", path, ln);
            break;
        }
        if (*nrows == *cap) {
            size_t nc = *cap ? 2 * *cap : 64;
            row *r = realloc(*rows, nc * sizeof *r);
            if (!r) {
                rc = cf_error_set(&err, CF_E_INTERNAL, "out of memory");
                break;
            }
            *rows = r;
            *cap = nc;
        }
        char *copy = strdup(line);
        if (!copy) {
            rc = cf_error_set(&err, CF_E_INTERNAL, "out of memory");
            break;
        }
        (*rows)[(*nrows)++] = (row){copy, (size_t)(tab - line)};
    }
    fclose(f);
    return rc == -1 ? -1 : cf_cli_fail(&err);
}

/* The shards must be 1..N of one N and one study, each once, and the rows every table once. */
static int check_split(const char *const *paths, const long *ks, int nfiles, long n, long total,
                       const row *rows, size_t nrows)
{
    cf_error err = {0};
    for (int i = 0; i < nfiles; i++)
        for (int j = 0; j < i; j++)
            if (ks[i] == ks[j]) {
                cf_error_set(&err, CF_E_DATA, "%s and %s are both shard %ld/%ld", paths[j],
                             paths[i], ks[i], n);
                return cf_cli_fail(&err);
            }
    if (nfiles != n) {
        for (long k = 1; k <= n; k++) {
            int seen = 0;
            for (int i = 0; i < nfiles; i++)
                seen |= ks[i] == k;
            if (!seen) {
                cf_error_set(&err, CF_E_DATA, "shard %ld/%ld is missing", k, n);
                return cf_cli_fail(&err);
            }
        }
    }
    for (size_t i = 1; i < nrows; i++)
        if (by_row(&rows[i - 1], &rows[i]) == 0) {
            char t[512];
            cf_error_set(&err, CF_E_DATA, "table %s is in two shards",
                         cf_safe_text(t, sizeof t, rows[i].text, rows[i].key));
            return cf_cli_fail(&err);
        }
    if ((long)nrows > total) {
        cf_error_set(&err, CF_E_DATA, "%zu rows for a study of %ld tables", nrows, total);
        return cf_cli_fail(&err);
    }
    return -1;
}

int cf_cli_merge(int argc, char **argv)
{
    const char *out = NULL;
    const char **paths = calloc((size_t)argc + 1, sizeof *paths);
    long *ks = calloc((size_t)argc + 1, sizeof *ks);
    int nfiles = 0, rc = -1;
    if (!paths || !ks) {
        free(paths);
        free(ks);
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
    row *rows = NULL;
    size_t nrows = 0, cap = 0;
    long n = 0, total = 0;
    for (int i = 0; i < nfiles && rc == -1; i++) {
        long ni, ti;
        rc = read_summary(paths[i], &ks[i], &ni, &ti, &rows, &nrows, &cap);
        if (rc == -1 && i > 0 && (ni != n || ti != total)) {
            cf_error err = {0};
            cf_error_set(&err, CF_E_DATA, "%s is shard %ld/%ld of %ld tables, %s one of %ld/%ld "
                         "tables: not one split", paths[i], ks[i], ni, ti, paths[0], n, total);
            rc = cf_cli_fail(&err);
        }
        n = ni;
        total = ti;
    }
    if (rows)
        qsort(rows, nrows, sizeof *rows, by_row);
    if (rc == -1)
        rc = check_split(paths, ks, nfiles, n, total, rows, nrows);
    if (rc == -1) {
        cf_cli_out o;
        cf_error err = {0};
        if (cf_cli_out_open(&o, out, paths, &err) != CF_OK) {
            rc = cf_cli_fail(&err);
        } else {
            fprintf(o.fp, SUMMARY_MAGIC "1/1 of %ld tables\n" SUMMARY_HEADER, total);
            for (size_t i = 0; i < nrows; i++)
                fputs(rows[i].text, o.fp);
            rc = cf_cli_out_close(&o, &err) == CF_OK ? CF_EXIT_OK : cf_cli_fail(&err);
        }
    }
    for (size_t i = 0; i < nrows; i++)
        free(rows[i].text);
    free(rows);
    free(paths);
    free(ks);
    return rc;
}
