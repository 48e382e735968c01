/*
** The summary of a sharded study (`conifit fit --shard K/N` writes DIR/summary-K-of-N.tsv,
** `conifit merge` joins them): its text form, read from memory, and the checks that a set of
** shard summaries is the whole of one study. Private to src/cli/; prints nothing.
**
** A summary is
**   # conifit fit summary: shard K/N of T tables; study HHHHHHHHHHHHHHHH; options: OPTIONS
**   table<TAB>telescoping_rmse<TAB>non_telescoping_rmse<TAB>unit<TAB>better_type<TAB>fit_file<TAB>status
** then one row per table of the shard, sorted by table name (byte order of the escaped names),
** status "ok" or "failed: REASON". Table names, options and reasons are escaped by
** cf_summary_escape, so that one name has one form everywhere and any name can be written.
** The study (16 hex digits) is a hash of the options and of every table's escaped name in order
** (cf_summary_study): shards of one study carry one study, and a merge recomputes it from the
** rows it joins.
*/
#ifndef CF_CLI_SUMMARY_H
#define CF_CLI_SUMMARY_H

#include <stddef.h>
#include <stdint.h>

#include "conifit/error.h"

#define CF_SUMMARY_MAGIC "# conifit fit summary: shard "
#define CF_SUMMARY_HEADER                                                                          \
    "table\ttelescoping_rmse\tnon_telescoping_rmse\tunit\tbetter_type\tfit_file\tstatus\n"
#define CF_SUMMARY_FIELDS 7
#define CF_SUMMARY_N_MAX 1000000L     /* the largest N of --shard K/N */
#define CF_SUMMARY_TABLES_MAX 2000000000L

typedef struct cf_summary_row {
    char *table; /* the first field, the table's escaped name (owned) */
    char *line;  /* the whole row, newline included (owned) */
} cf_summary_row;

typedef struct cf_summary {
    long k, n, total;      /* shard K of N, of a study of `total` tables */
    char study[17];        /* 16 lower-case hex digits */
    char *options;         /* escaped options ("-": none) (owned) */
    cf_summary_row *rows;  /* sorted by table */
    size_t nrows, cap;
} cf_summary;

/* The escaped form of the n bytes at s (malloc'd, NULL when out of memory): printable ASCII and
** whole valid UTF-8 sequences of printable characters kept, every other byte (controls, tab,
** newline, DEL, C1 controls, bytes that are not valid UTF-8) and the backslash itself written
** \xNN; with `space` set, the blank too. One-to-one: two different names never share a form. */
char *cf_summary_escape(const char *s, size_t n, int space);

/* The study of a summary: options (escaped) and the tables' escaped names in sorted order, as 16
** hex digits into out[17]. */
void cf_summary_study(const char *options, const char *const *tables, size_t n, char out[17]);

/* Tables of shard k of n when the study has `total`: every n-th from the k-th. */
long cf_summary_share(long k, long n, long total);

/* Reads a summary from text (len bytes; need not end in NUL) into s (zeroed first). CF_E_DATA with
** "name:LINE: what is wrong" when it is not one: a header or row out of form, rows not sorted or
** one table twice, a shard that is not K/N with 1 <= K <= N. CF_E_INTERNAL when out of memory. */
cf_status cf_summary_parse(const char *text, size_t len, const char *name, cf_summary *s,
                           cf_error *err);

/* Checks that the n summaries s (read from the files names) are the N shards of one study, each
** once, complete: one N, one table count, one study and one set of options; no shard twice and
** none missing; each holding exactly its share of rows; their tables, dealt as the shards deal
** them, in the study's order; and the study recomputed from the joined tables equal to the one
** every shard names. Then *rows (malloc'd, pointing into the summaries) holds the study's rows in
** order, *nrows of them. CF_E_DATA naming the file and what is wrong otherwise. */
cf_status cf_summary_join(const cf_summary *s, size_t n, const char *const *names,
                          const cf_summary_row ***rows, size_t *nrows, cf_error *err);

void cf_summary_free(cf_summary *s);

#endif
