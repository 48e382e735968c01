/*
** Batch runs split across processes or machines (`conifit fit --shard K/N`) and the merge of
** their summaries (`conifit merge`). Private to src/cli/.
*/
#ifndef CF_CLI_SHARD_H
#define CF_CLI_SHARD_H

#include "base/atomic.h"

/* One table of the shard. */
typedef struct cf_shard_table {
    const char *file;    /* its path, as given */
    char *name;          /* its escaped name, as summaries write it (owned) */
    char *fit;           /* its fit file, DIR/NAME.json (owned) */
    char *why;           /* why it failed in this run (escaped, owned), or NULL */
} cf_shard_table;

typedef struct cf_shard {
    long k, n;           /* this process fits the tables i (0-based, sorted, each path once)
                         ** with i % n == k - 1 */
    int given;           /* --shard was on the command line */
    cf_shard_table *tables; /* this shard's tables, sorted by name (owned) */
    int ntables;
    long total;          /* tables of the whole study (each path once) */
    char study[17];      /* the study's hash (cli_summary.h) */
    char *options;       /* the options of the study, escaped ("-": none) (owned) */
} cf_shard;

/* Removes --shard K/N (or --shard=K/N) from argv (argc updated) into sh. -1 to go on, else the
** exit status of a usage error (2: malformed, or K outside 1..N). */
int cf_cli_shard_take(int *argc, char **argv, cf_shard *sh);

/* With --shard: sorts the tables by escaped name, refuses (2) a study in which two tables would
** write one fit file (in every shard alike), keeps this shard's (sh->tables) and, in *files /
** *nfiles (malloc'd), those of them whose fit file in the folder out is not complete or was
** fitted with other options. options: the study's options, escaped, "-" for none. out must be a
** folder (-o DIR/). -1 to go on, else an exit status. */
int cf_cli_shard_select(cf_shard *sh, const char *out, const char *options, const char ***files,
                        int *nfiles);

/* Appends the table's escaped name and the study's options to the finished fit file of table
** file, not yet in place, as its last members ("shard_table", "shard_options"), so that a rerun
** knows for what and with what it was fitted. CF_E_CANTWRITE (the temporary removed) on
** failure. Thread-safe. */
cf_status cf_cli_shard_stamp(const cf_shard *sh, const char *file, cf_atomic *json,
                             cf_error *err);

/* Records that table file failed in this run, for the reason given. */
void cf_cli_shard_failed(cf_shard *sh, const char *file, const char *reason);

/* Writes out/summary-K-of-N.tsv: one row per table of the shard, read back from its fit file (so
** that a resumed shard writes the same summary), or its failure. Returns an exit status. */
int cf_cli_shard_summary(const cf_shard *sh, const char *out);

void cf_cli_shard_free(cf_shard *sh);

/* DIR/NAME.EXT for the table at path file, as conifit fit -o DIR/ names its outputs (NAME: the
** file name without folder and extension; "stdin" for '-'). */
void cf_cli_path_in_dir(char *dst, size_t cap, const char *dir, const char *file,
                        const char *ext);

/* conifit merge SUMMARY... [-o FILE]: the shards' summaries into the summary one process would
** have written. */
int cf_cli_merge(int argc, char **argv);

#endif
