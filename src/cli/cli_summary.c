/*
** Summaries of sharded studies (cli_summary.h): escaping, the study's hash, reading one summary
** and joining the shards of a study.
*/
#include <stdlib.h>
#include <string.h>

#include "base/safetext.h"
#include "cli/cli_summary.h"

char *cf_summary_escape(const char *s, size_t n, int space)
{
    char *out = malloc(4 * n + 1);
    if (!out)
        return NULL;
    const unsigned char *u = (const unsigned char *)s;
    size_t w = 0;
    for (size_t i = 0; i < n;) {
        size_t len = u[i] == '\\' || (space && u[i] == ' ') ? 0 : cf_text_char_length(u + i, n - i);
        if (len == 0) {
            static const char hex[] = "0123456789abcdef";
            out[w++] = '\\';
            out[w++] = 'x';
            out[w++] = hex[u[i] >> 4];
            out[w++] = hex[u[i] & 15];
            i++;
        } else {
            memcpy(out + w, u + i, len);
            w += len;
            i += len;
        }
    }
    out[w] = '\0';
    return out;
}

static uint64_t fnv1a(uint64_t h, const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        h = (h ^ (unsigned char)s[i]) * 0x100000001b3ULL;
    return h;
}

void cf_summary_study(const char *options, const char *const *tables, size_t n, char out[17])
{
    static const char tag[] = "conifit study 1\n";
    uint64_t h = fnv1a(0xcbf29ce484222325ULL, tag, sizeof tag - 1);
    h = fnv1a(h, options, strlen(options));
    h = fnv1a(h, "\n", 1);
    for (size_t i = 0; i < n; i++) {
        h = fnv1a(h, tables[i], strlen(tables[i]));
        h = fnv1a(h, "\n", 1); /* never inside an escaped name */
    }
    static const char hex[] = "0123456789abcdef";
    for (int i = 0; i < 16; i++)
        out[i] = hex[(h >> (60 - 4 * i)) & 15];
    out[16] = '\0';
}

long cf_summary_share(long k, long n, long total)
{
    return total / n + (k - 1 < total % n);
}

/* A whole number of 1 to 10 digits at *p, without sign or leading zero, up to max; advances *p.
** -1 when there is none. */
static long number(const char **p, const char *end, long max)
{
    const char *s = *p;
    long v = 0;
    int nd = 0;
    while (s < end && *s >= '0' && *s <= '9' && nd < 11) {
        v = v * 10 + (*s - '0');
        s++;
        nd++;
    }
    if (nd == 0 || nd > 10 || (nd > 1 && **p == '0') || v > max)
        return -1;
    *p = s;
    return v;
}

static int literal(const char **p, const char *end, const char *lit)
{
    size_t n = strlen(lit);
    if ((size_t)(end - *p) < n || memcmp(*p, lit, n) != 0)
        return 0;
    *p += n;
    return 1;
}

/* 1 when [s, end) holds no control character (tab included) and no DEL. */
static int plain(const char *s, const char *end)
{
    for (; s < end; s++)
        if ((unsigned char)*s < 0x20 || *s == 0x7f)
            return 0;
    return 1;
}

/* The header line [p, end) (its newline excluded) into s. */
static int parse_header(const char *p, const char *end, cf_summary *s)
{
    if (!literal(&p, end, CF_SUMMARY_MAGIC) || (s->k = number(&p, end, CF_SUMMARY_N_MAX)) < 1 ||
        !literal(&p, end, "/") || (s->n = number(&p, end, CF_SUMMARY_N_MAX)) < 1 ||
        s->k > s->n || !literal(&p, end, " of ") ||
        (s->total = number(&p, end, CF_SUMMARY_TABLES_MAX)) < 0 ||
        !literal(&p, end, " tables; study "))
        return 0;
    for (int i = 0; i < 16; i++, p++) {
        if (p >= end || !((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'f')))
            return 0;
        s->study[i] = *p;
    }
    s->study[16] = '\0';
    if (!literal(&p, end, "; options: ") || p == end || !plain(p, end))
        return 0;
    s->options = strndup(p, (size_t)(end - p));
    return s->options != NULL ? 1 : -1;
}

/* One row [p, end) (its newline excluded): CF_SUMMARY_FIELDS fields, the first (the table) and
** the last (the status) well-formed. */
static int row_ok(const char *p, const char *end, size_t *key)
{
    const char *f[CF_SUMMARY_FIELDS + 1];
    int nf = 0;
    f[nf++] = p;
    for (const char *c = p; c < end; c++) {
        if (*c == '\t') {
            if (nf == CF_SUMMARY_FIELDS)
                return 0;
            f[nf++] = c + 1;
        } else if ((unsigned char)*c < 0x20 || *c == 0x7f) {
            return 0;
        }
    }
    if (nf != CF_SUMMARY_FIELDS)
        return 0;
    f[nf] = end + 1;
    for (int i = 0; i < nf; i++)
        if (f[i + 1] - 1 == f[i]) /* an empty field */
            return 0;
    const char *status = f[CF_SUMMARY_FIELDS - 1];
    size_t slen = (size_t)(end - status);
    if (!(slen == 2 && memcmp(status, "ok", 2) == 0) &&
        !(slen > 8 && memcmp(status, "failed: ", 8) == 0))
        return 0;
    *key = (size_t)(f[1] - 1 - p);
    return 1;
}

cf_status cf_summary_parse(const char *text, size_t len, const char *name, cf_summary *s,
                           cf_error *err)
{
    memset(s, 0, sizeof *s);
    const char *p = text, *end = text + len;
    size_t ln = 0;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        ln++;
        if (!nl) {
            cf_summary_free(s);
            return cf_error_set(err, CF_E_DATA, "%s:%zu: the last line has no end (a summary cut "
                                "short?)", name, ln);
        }
        if (memchr(p, '\0', (size_t)(nl - p))) {
            cf_summary_free(s);
            return cf_error_set(err, CF_E_DATA, "%s:%zu: a NUL byte: not a summary", name, ln);
        }
        if (ln == 1) {
            int h = parse_header(p, nl, s);
            if (h <= 0) {
                cf_summary_free(s);
                return h < 0 ? cf_error_set(err, CF_E_INTERNAL, "out of memory")
                             : cf_error_set(err, CF_E_DATA, "%s:1: not the first line of a "
                                            "summary of conifit fit --shard K/N (\"%sK/N of T "
                                            "tables; study ...; options: ...\", 1 <= K <= N)",
                                            name, CF_SUMMARY_MAGIC);
            }
        } else if (ln == 2) {
            if ((size_t)(nl + 1 - p) != strlen(CF_SUMMARY_HEADER) ||
                memcmp(p, CF_SUMMARY_HEADER, strlen(CF_SUMMARY_HEADER)) != 0) {
                cf_summary_free(s);
                return cf_error_set(err, CF_E_DATA, "%s:2: not the summary's column header",
                                    name);
            }
        } else {
            size_t key;
            if (!row_ok(p, nl, &key)) {
                cf_summary_free(s);
                return cf_error_set(err, CF_E_DATA, "%s:%zu: not a summary row (%d fields "
                                    "separated by tabs, the last \"ok\" or \"failed: REASON\")",
                                    name, ln, CF_SUMMARY_FIELDS);
            }
            if (s->nrows == s->cap) {
                size_t nc = s->cap ? 2 * s->cap : 64;
                cf_summary_row *r = realloc(s->rows, nc * sizeof *r);
                if (!r) {
                    cf_summary_free(s);
                    return cf_error_set(err, CF_E_INTERNAL, "out of memory");
                }
                s->rows = r;
                s->cap = nc;
            }
            cf_summary_row r = {strndup(p, key), strndup(p, (size_t)(nl + 1 - p))};
            if (!r.table || !r.line) {
                free(r.table);
                free(r.line);
                cf_summary_free(s);
                return cf_error_set(err, CF_E_INTERNAL, "out of memory");
            }
            s->rows[s->nrows++] = r;
            if (s->nrows > 1 && strcmp(s->rows[s->nrows - 2].table, r.table) >= 0) {
                char t[256];
                cf_safe_text(t, sizeof t, r.table, strlen(r.table));
                cf_summary_free(s);
                return cf_error_set(err, CF_E_DATA, "%s:%zu: table %s is out of order or there "
                                    "twice (a summary's rows are sorted by table)", name, ln, t);
            }
        }
        p = nl + 1;
    }
    if (ln < 2) {
        cf_summary_free(s);
        return cf_error_set(err, CF_E_DATA, "%s:%zu: %s: not a summary of conifit fit --shard "
                            "K/N", name, ln ? ln : 1, ln ? "no column header" : "empty");
    }
    return CF_OK;
}

cf_status cf_summary_join(const cf_summary *s, size_t n, const char *const *names,
                          const cf_summary_row ***rows, size_t *nrows, cf_error *err)
{
    *rows = NULL;
    *nrows = 0;
    if (n == 0)
        return cf_error_set(err, CF_E_DATA, "no summary to merge");
    const cf_summary *a = &s[0];
    for (size_t i = 1; i < n; i++) {
        const cf_summary *b = &s[i];
        if (b->n != a->n || b->total != a->total || strcmp(b->study, a->study) != 0 ||
            strcmp(b->options, a->options) != 0)
            return cf_error_set(err, CF_E_DATA, "%s is shard %ld/%ld of a study of %ld tables "
                                "(study %s), %s shard %ld/%ld of %ld tables (study %s)%s: not "
                                "one study", names[i], b->k, b->n, b->total, b->study,
                                names[0], a->k, a->n, a->total, a->study,
                                strcmp(b->options, a->options) ? ", with other options" : "");
        for (size_t j = 0; j < i; j++)
            if (s[j].k == b->k)
                return cf_error_set(err, CF_E_DATA, "%s and %s are both shard %ld/%ld",
                                    names[j], names[i], b->k, b->n);
    }
    if ((long)n != a->n) /* n < N: no shard is there twice, so one is missing */
        for (long k = 1; k <= a->n; k++) {
            int seen = 0;
            for (size_t i = 0; i < n && !seen; i++)
                seen = s[i].k == k;
            if (!seen)
                return cf_error_set(err, CF_E_DATA, "shard %ld/%ld is missing", k, a->n);
        }
    for (size_t i = 0; i < n; i++) {
        long want = cf_summary_share(s[i].k, s[i].n, s[i].total);
        if ((long)s[i].nrows != want)
            return cf_error_set(err, CF_E_DATA, "%s: shard %ld/%ld of a study of %ld tables takes "
                                "%ld of them but has %zu rows: the summary is not whole",
                                names[i], s[i].k, s[i].n, s[i].total, want, s[i].nrows);
    }
    const size_t total = (size_t)a->total;
    const cf_summary_row **all = malloc((total + 1) * sizeof *all);
    const char **tables = malloc((total + 1) * sizeof *tables);
    if (!all || !tables) {
        free(all);
        free(tables);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    }
    /* shard k's j-th row is the study's table (k - 1) + j N */
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < s[i].nrows; j++) {
            size_t at = (size_t)(s[i].k - 1) + j * (size_t)s[i].n;
            all[at] = &s[i].rows[j];
            tables[at] = s[i].rows[j].table;
        }
    for (size_t i = 1; i < total; i++) {
        int c = strcmp(tables[i - 1], tables[i]);
        if (c >= 0) {
            char t[256];
            cf_safe_text(t, sizeof t, tables[i], strlen(tables[i]));
            const size_t ka = (i - 1) % (size_t)a->n + 1, kb = i % (size_t)a->n + 1;
            free(all);
            free(tables);
            if (c == 0)
                return cf_error_set(err, CF_E_DATA, "table %s is in shards %zu/%ld and %zu/%ld",
                                    t, ka, a->n, kb, a->n);
            return cf_error_set(err, CF_E_DATA, "the tables of shards %zu/%ld and %zu/%ld (at "
                                "%s) are not those the split deals to them: not one study", ka,
                                a->n, kb, a->n, t);
        }
    }
    char study[17];
    cf_summary_study(a->options, tables, total, study);
    free(tables);
    if (strcmp(study, a->study) != 0) {
        free(all);
        return cf_error_set(err, CF_E_DATA, "the shards' tables are not study %s's (they make "
                            "study %s): a summary lost or changed rows", a->study, study);
    }
    *rows = all;
    *nrows = total;
    return CF_OK;
}

void cf_summary_free(cf_summary *s)
{
    for (size_t i = 0; i < s->nrows; i++) {
        free(s->rows[i].table);
        free(s->rows[i].line);
    }
    free(s->rows);
    free(s->options);
    memset(s, 0, sizeof *s);
}
