/*
** Batch runs split across processes or machines (`conifit fit --shard K/N`) and the merge of
** their summaries (`conifit merge`). Private to src/cli/.
*/
#ifndef CF_CLI_SHARD_H
#define CF_CLI_SHARD_H

typedef struct cf_shard {
    long k, n;           /* this process fits the tables i (0-based, sorted, each path once)
                         ** with i % n == k - 1 */
    int given;           /* --shard was on the command line */
    const char **mine;   /* this shard's tables, sorted (owned) */
    int nmine;
    int total;           /* tables of the whole study (each path once) */
} cf_shard;

/* Removes --shard K/N (or --shard=K/N) from argv (argc updated) into sh. -1 to go on, else the
** exit status of a usage error (2: malformed, or K outside 1..N). */
int cf_cli_shard_take(int *argc, char **argv, cf_shard *sh);

/* With --shard: sorts the tables, keeps this shard's (sh->mine) and, in *files / *nfiles, those
** of them whose fit file in the folder out is not complete yet. out must be a folder (-o DIR/).
** -1 to go on, else an exit status. */
int cf_cli_shard_select(cf_shard *sh, const char *out, const char ***files, int *nfiles);

/* Writes out/summary-K-of-N.tsv: one row per table of the shard, read back from its fit file, so
** that a resumed shard writes the same summary. Returns an exit status. */
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
