/*
** libFuzzer harness: the summaries `conifit merge` reads (cli_summary.c). The input holds up to
** four summaries separated by NUL bytes (a summary never holds one); each is read, and when all
** are summaries they are joined as a merge joins them, with every check of a whole study.
*/
#include "fuzz.h"

#include <string.h>

#include "cli/cli_summary.h"

#define PARTS 4

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    cf_summary s[PARTS];
    const char *names[PARTS] = {"a.tsv", "b.tsv", "c.tsv", "d.tsv"};
    size_t n = 0, at = 0;
    int ok = 1;
    while (ok && n < PARTS) {
        const uint8_t *nul = memchr(data + at, 0, size - at);
        size_t len = nul ? (size_t)(nul - (data + at)) : size - at;
        cf_error err = {0};
        ok = cf_summary_parse((const char *)data + at, len, names[n], &s[n], &err) == CF_OK;
        n += ok;
        if (!nul)
            break;
        at += len + 1;
    }
    if (ok && n > 0) {
        const cf_summary_row **rows;
        size_t nrows;
        cf_error err = {0};
        if (cf_summary_join(s, n, names, &rows, &nrows, &err) == CF_OK) {
            for (size_t i = 0; i < nrows; i++) /* every row the join returns is a row read */
                if (!rows[i] || !rows[i]->line || rows[i]->line[strlen(rows[i]->line) - 1] != '\n')
                    abort();
            free(rows);
        }
    }
    for (size_t i = 0; i < n; i++)
        cf_summary_free(&s[i]);
    return 0;
}
