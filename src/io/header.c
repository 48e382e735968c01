/*
** The header row of a measurement table (reader.h): where it is, its delimiter and column names,
** and which columns are x, y, a weight and a time.
*/
#include "io/reader.h"
#include "io/columns.h"
#include "io/measure.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Lines after the first one with content that are searched for the header row of a table with a
** preamble (the metadata lines of a testing machine's export: a few dozen at most). */
#define PREAMBLE_MAX_LINES 256

/* The first line at index >= i with content (not a comment, not blank), with its content length
** in *n; r->nlines when there is none. */
static size_t next_content(const reader *r, size_t i, size_t *n)
{
    for (; i < r->nlines; i++) {
        if (cf_csv_is_comment(&r->lines[i]))
            continue;
        if ((*n = cf_csv_content_length(r->lines[i].s, r->lines[i].n)) > 0)
            return i;
    }
    return r->nlines;
}

/* How many fields of line i (n bytes of content) split at delim are numbers; -1 when every field
** is empty (a row that the reader skips), 0 when the line does not split. */
static int numbers_in(reader *r, size_t i, size_t n, char delim)
{
    size_t bad;
    const char *why;
    if (cf_csv_split(r->lines[i].s, n, delim, &r->f, &bad, &why) != 0)
        return 0;
    int numbers = 0, filled = 0;
    for (size_t k = 0; k < r->f.count; k++) {
        double v;
        const char *cell = cf_csv_field(&r->f, k);
        filled |= cell[0] != '\0';
        numbers += cf_csv_number(cell, delim, &v) == CF_CSV_NUM_OK;
    }
    return filled ? numbers : -1;
}

/* 1 when line i (n bytes of content), taken as a header, is followed by a data row: the next line
** with a cell that is not empty holds at least two numbers. */
static int rows_follow(reader *r, size_t i, size_t n)
{
    char delim = cf_csv_delimiter(r->lines[i].s, n);
    if (!delim)
        return 0;
    size_t k = i + 1, kn = 0, empty = 0;
    int numbers = 0;
    size_t under = next_content(r, k, &kn);
    if (under < r->nlines && cf_units_row_is(r, under, kn, delim))
        k = under + 1; /* the rows start after a units row */
    /* rows of empty cells are skipped, as the reader skips them, but no more than a preamble's
    ** worth, so that searching a preamble stays linear in the file */
    while ((k = next_content(r, k, &kn)) < r->nlines &&
           (numbers = numbers_in(r, k, kn, delim)) < 0 && empty++ < PREAMBLE_MAX_LINES)
        k++;
    return k < r->nlines && numbers >= 2;
}

/* 1 when line i (n bytes of content) names known columns: two fields at least, one of them the
** name of an x or a y column (strain, stretch, displacement, stress, force, load, ...). */
static int names_columns(reader *r, size_t i, size_t n)
{
    size_t bad;
    const char *why;
    char delim = cf_csv_delimiter(r->lines[i].s, n);
    if (!delim || cf_csv_split(r->lines[i].s, n, delim, &r->f, &bad, &why) != 0 || r->f.count < 2)
        return 0;
    for (size_t k = 0; k < r->f.count; k++) {
        cf_column c;
        cf_column_parse(&c, cf_csv_field(&r->f, k));
        if (cf_column_is_x(c.base) || cf_column_y_class(c.base) != CF_UNIT_UNKNOWN)
            return 1;
    }
    return 0;
}

/* The header row the option names (a 1-based line of the file). */
static cf_status header_at(const reader *r, size_t line, layout *h, cf_error *err)
{
    if (line > r->nlines)
        return cf_csv_error(err, r->path, r->nlines ? r->nlines : 1, 1,
                            "option header_row %zu: the file has %zu lines ('%zu')", line,
                            r->nlines, line);
    const cf_csv_line *l = &r->lines[line - 1];
    h->hi = line - 1;
    h->hn = cf_csv_is_comment(l) ? 0 : cf_csv_content_length(l->s, l->n);
    if (h->hn > 0)
        return CF_OK;
    char q[256];
    cf_csv_quote(q, sizeof q, l->s, l->n);
    return cf_csv_error(err, r->path, line, 1,
                        "option header_row %zu: line %zu is %s, not a header row ('%s')", line,
                        line, cf_csv_is_comment(l) ? "a comment" : "blank", q);
}

/* A table whose first line with content is not followed by rows of numbers: a preamble (lines
** before the header row, as testing machines write; its first line may name a known column, as
** "Strain rate,0.01 /s" does). The header is the first line after it that names known columns and
** is followed by rows; when none does, the first line stays the header, and when that names no
** known column either, h->no_header_at is the line before the first row of numbers (the one that
** should have named the columns). */
static void skip_preamble(reader *r, layout *h, int first_names_columns)
{
    size_t first = h->hi, n = 0, prev = first;
    for (size_t i = next_content(r, first + 1, &n), seen = 0;
         i < r->nlines && seen < PREAMBLE_MAX_LINES; i = next_content(r, i + 1, &n), seen++) {
        if (names_columns(r, i, n) && rows_follow(r, i, n)) {
            h->hi = i;
            h->hn = n;
            h->preamble = 1;
            h->no_header_at = 0;
            return;
        }
        char delim = cf_csv_delimiter(r->lines[i].s, n);
        if (!first_names_columns && !h->no_header_at && prev != first &&
            numbers_in(r, i, n, delim ? delim : ',') >= 2) {
            h->no_header_at = r->lines[prev].line;
            h->numbers_at = r->lines[i].line;
        }
        prev = i;
    }
}

/* The header row: the line the option names; else the first line with content, unless that is
** followed by no rows of numbers: then the first line after a preamble that names known columns
** and is followed by rows, if there is one. */
cf_status cf_header_find(reader *r, const cf_measure_options *opt, layout *h, cf_error *err)
{
    const char *path = r->path;
    if (opt->header_row > 0)
        return header_at(r, opt->header_row, h, err);
    h->hi = next_content(r, 0, &h->hn);
    if (h->hi < r->nlines) {
        if (!rows_follow(r, h->hi, h->hn))
            skip_preamble(r, h, names_columns(r, h->hi, h->hn));
        return CF_OK;
    }
    if (r->size == 0)
        return cf_csv_error(err, path, 1, 1, "empty file: no header and no data (0 bytes)");
    return cf_csv_error(err, path, r->nlines ? r->lines[r->nlines - 1].line : 1, 1,
                        "no header row and no data: only comments and blank lines (%zu bytes)",
                        r->size);
}

/* The header's delimiter and column names (r->cols). */
cf_status cf_header_read(reader *r, layout *h, cf_error *err)
{
    const char *path = r->path;
    const cf_csv_line *hl = &r->lines[h->hi];
    h->header_line = hl->line;
    cf_csv_quote(h->hq, sizeof h->hq, hl->s, h->hn);
    if (h->no_header_at) {
        const cf_csv_line *nl = &r->lines[h->no_header_at - 1];
        char q[256];
        cf_csv_quote(q, sizeof q, nl->s, cf_csv_content_length(nl->s, nl->n));
        return cf_csv_error(err, path, h->no_header_at, 1,
                            "no header row: the rows of numbers start at line %zu, and neither "
                            "this line before them nor any line above names a known column "
                            "(strain, stretch, displacement, stress, force, load, ...); name the "
                            "columns, or give the header's line with option header_row and the "
                            "columns with option columns ('%s')",
                            h->numbers_at, q);
    }
    h->delim = cf_csv_delimiter(hl->s, h->hn);
    if (!h->delim)
        return cf_csv_error(err, path, h->header_line, 1,
                            "the header has a single column; expected at least x and y separated "
                            "by ',' ';' TAB or blanks ('%s')", h->hq);
    cf_status st = cf_reader_split(r, hl, h->hn, h->delim, err);
    if (st != CF_OK)
        return st;
    size_t ncols = r->f.count;
    h->trailing = 0;
    if (ncols > 1 && cf_csv_field(&r->f, ncols - 1)[0] == '\0') {
        h->trailing = 1;
        ncols--;
    }
    if (ncols > CF_MEASURE_MAX_COLUMNS)
        return cf_csv_error(err, path, h->header_line, CF_MEASURE_MAX_COLUMNS + 1,
                            "the header has %zu columns; a table may have at most %d ('%s')", ncols,
                            CF_MEASURE_MAX_COLUMNS, h->hq);
    r->cols = calloc(ncols, sizeof *r->cols);
    if (!r->cols)
        return cf_reader_out_of_memory(err, path);
    r->ncols = h->ncols = ncols;
    size_t numeric = 0;
    for (size_t i = 0; i < ncols; i++) {
        const char *name = cf_csv_field(&r->f, i);
        double v;
        if (name[0] == '\0')
            return cf_csv_error(err, path, h->header_line, i + 1, "column %zu has no name ('%s')",
                                i + 1, h->hq);
        if (strlen(name) >= CF_COLUMN_NAME_CAP)
            return cf_csv_error(err, path, h->header_line, i + 1,
                                "column name too long ('%.60s...')", name);
        if (cf_csv_number(name, h->delim, &v) == CF_CSV_NUM_OK)
            numeric++;
        cf_column_parse(&r->cols[i], name);
    }
    if (numeric == ncols)
        return cf_csv_error(err, path, h->header_line, 1,
                            "missing header: the first row holds numbers, not column names ('%s')",
                            h->hq);
    return CF_OK;
}

/* Finds a column by name (the full header name or its base, case-insensitive), else by its
** number from 1; -1 when there is none. */
static long find_column(const reader *r, const char *name)
{
    for (size_t i = 0; i < r->ncols; i++)
        if (strcasecmp(r->cols[i].name, name) == 0)
            return (long)i;
    for (size_t i = 0; i < r->ncols; i++)
        if (strcasecmp(r->cols[i].base, name) == 0)
            return (long)i;
    /* no column of that name: a column number, from 1 */
    char *end;
    errno = 0;
    unsigned long k = name[0] >= '1' && name[0] <= '9' ? strtoul(name, &end, 10) : 0;
    if (k >= 1 && k <= r->ncols && errno == 0 && *end == '\0')
        return (long)k - 1;
    return -1;
}

static cf_status column_not_found(const reader *r, size_t header_line, const char *what,
                                  const char *name, cf_error *err)
{
    char list[256];
    size_t o = 0;
    list[0] = '\0';
    for (size_t i = 0; i < r->ncols && o + 4 < sizeof list; i++)
        o += (size_t)snprintf(list + o, sizeof list - o, "%s%s", i ? ", " : "", r->cols[i].name);
    char q[256];
    cf_csv_quote(q, sizeof q, name, strlen(name));
    return cf_csv_error(err, r->path, header_line, 1,
                        "no %s column named '%s' (the header has: %s)", what, q, list);
}

/* Which columns: x, y, weight, time (the options name x and y, else their names tell). */
/* The columns option "X,Y" or "X,Y,W": x, y and the weight, by name or number, and no others. */
static cf_status picked_columns(const reader *r, const char *list, layout *h, cf_error *err)
{
    static const char *const what[3] = {"x", "y", "weight"};
    long idx[3] = {-1, -1, -1};
    const char *s = list;
    size_t k = 0;
    for (; k < 3 && *s; k++) {
        const char *e = strchr(s, ',');
        size_t n = e ? (size_t)(e - s) : strlen(s);
        char name[CF_COLUMN_NAME_CAP];
        cf_csv_trim_copy(name, sizeof name, s, n);
        if (name[0] == '\0')
            break;
        if ((idx[k] = find_column(r, name)) < 0)
            return column_not_found(r, h->header_line, what[k], name, err);
        for (size_t j = 0; j < k; j++)
            if (idx[j] == idx[k])
                return cf_csv_error(err, r->path, h->header_line, (size_t)idx[k] + 1,
                                    "option columns '%s': the %s and the %s are one column ('%s')",
                                    list, what[j], what[k], r->cols[idx[k]].name);
        s = e ? e + 1 : s + n;
        if (e && !*s)
            s = e; /* a comma at the end: an empty name */
    }
    if (k < 2 || *s)
        return cf_error_set(err, CF_E_DATA, "%s: option columns '%s': expected X,Y or X,Y,W "
                            "(names or numbers from 1 of the x, y and weight columns)",
                            r->path, list);
    h->xi = idx[0];
    h->yi = idx[1];
    h->wi = idx[2];
    h->ti = -1;
    return CF_OK;
}

cf_status cf_header_choose_columns(const reader *r, const cf_measure_options *opt, layout *h,
                                   cf_error *err)
{
    const size_t ncols = h->ncols;
    long xi = -1, yi = -1, wi = -1, ti = -1;
    if (opt->columns)
        return picked_columns(r, opt->columns, h, err);
    for (size_t i = 0; i < ncols; i++) {
        if (wi < 0 && cf_column_is_weight(r->cols[i].base))
            wi = (long)i;
        if (ti < 0 && cf_column_is_time(r->cols[i].base))
            ti = (long)i;
    }
    if (opt->x_col && (xi = find_column(r, opt->x_col)) < 0)
        return column_not_found(r, h->header_line, "x", opt->x_col, err);
    if (opt->y_col && (yi = find_column(r, opt->y_col)) < 0)
        return column_not_found(r, h->header_line, "y", opt->y_col, err);
    for (int pass = 0; pass < 2 && yi < 0; pass++)
        for (size_t i = 0; i < ncols && yi < 0; i++)
            if ((long)i != xi &&
                (pass == 0 ? cf_column_is_y(r->cols[i].base)
                           : cf_column_y_class(r->cols[i].base) != CF_UNIT_UNKNOWN))
                yi = (long)i;
    for (size_t i = 0; i < ncols && xi < 0; i++)
        if ((long)i != yi && cf_column_is_x(r->cols[i].base))
            xi = (long)i;
    for (size_t i = 0; i < ncols && (xi < 0 || yi < 0); i++) {
        if ((long)i == xi || (long)i == yi || (long)i == wi || (long)i == ti)
            continue;
        if (xi < 0)
            xi = (long)i;
        else
            yi = (long)i;
    }
    if (xi < 0 || yi < 0 || xi == yi)
        return cf_csv_error(err, r->path, h->header_line, 1,
                            "cannot tell which columns are x and y; name them (strain, stress_kPa, "
                            "...) or set option x_col and option y_col ('%s')", h->hq);
    h->xi = xi;
    h->yi = yi;
    h->wi = wi == xi || wi == yi ? -1 : wi;
    h->ti = ti == xi || ti == yi ? -1 : ti;
    return CF_OK;
}
