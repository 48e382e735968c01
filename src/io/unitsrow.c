/*
** The units row of a testing machine's export (reader.h): a row directly under the header that
** gives each column's unit, as "(s),(mm),(N)", "[s];[mm];[N]" or "sec,mm,N", taken for the
** columns whose header names no unit.
*/
#include "io/reader.h"
#include "io/columns.h"

#include <stdio.h>
#include <string.h>

/* 1 when a cell is in parentheses or brackets: "(s)", "[mm]". */
static int bracketed(const char *cell)
{
    size_t n = strlen(cell);
    return n >= 2 && ((cell[0] == '(' && cell[n - 1] == ')') ||
                      (cell[0] == '[' && cell[n - 1] == ']'));
}

/* The unit a units-row cell spells, without its brackets and blanks, into out. */
static void cell_unit(const char *cell, char *out, size_t cap)
{
    int b = bracketed(cell);
    cf_csv_trim_copy(out, cap, cell + b, strlen(cell) - 2 * (size_t)b);
}

int cf_units_row_is(reader *r, size_t i, size_t n, char delim)
{
    size_t bad;
    const char *why;
    if (cf_csv_split(r->lines[i].s, n, delim, &r->f, &bad, &why) != 0)
        return 0;
    size_t filled = 0, enclosed = 0, known = 0;
    for (size_t k = 0; k < r->f.count; k++) {
        const char *cell = cf_csv_field(&r->f, k);
        double v;
        if (cell[0] == '\0')
            continue;
        if (cf_csv_number(cell, delim, &v) == CF_CSV_NUM_OK)
            return 0;
        char u[CF_COLUMN_NAME_CAP];
        cell_unit(cell, u, sizeof u);
        filled++;
        enclosed += bracketed(cell);
        known += u[0] != '\0' && cf_unit_find(u) != NULL;
    }
    return filled > 0 && (enclosed == filled || known > 0);
}

/* 1 when column i is one the table reads (x, y, the weight or the time). */
static int column_read(const layout *h, size_t i)
{
    long c = (long)i;
    return c == h->xi || c == h->yi || c == h->wi || c == h->ti;
}

/* Takes the unit of column i from units-row cell u (its text), or refuses it. */
static cf_status take_unit(reader *r, const layout *h, size_t i, const char *u, const char *q,
                           cf_error *err)
{
    cf_column *c = &r->cols[i];
    const cf_unit_def *d = cf_unit_find(u);
    /* a bracket in the header that is no unit qualifies the name, as Instron's "Tensile strain
    ** (Extension)" does: the units row gives the unit */
    int header_unit = c->unit[0] && (cf_unit_find(c->unit) || cf_unit_m_case(c->unit));
    if (!column_read(h, i) && (!d || header_unit))
        return CF_OK; /* a column the table does not read may say anything */
    if (header_unit) {
        const cf_unit_def *hd = cf_unit_find(c->unit);
        if (!hd || (d && hd->cls == d->cls && hd->to_conifit == d->to_conifit))
            return CF_OK; /* the same unit, or a header unit the reader refuses later */
        return cf_csv_error(err, r->path, h->units_line, i + 1,
                            "units row: column '%s' has unit '%s', but its header (line %zu) "
                            "says '%s'; correct one of them ('%s')",
                            c->name, u, h->header_line, c->unit, q);
    }
    if (!d)
        return cf_csv_error(err, r->path, h->units_line, i + 1,
                            "units row: column '%s' has unit '%s', which is not one conifit "
                            "knows (%s) ('%s')", c->name, u, cf_unit_list, q);
    snprintf(c->unit, sizeof c->unit, "%s", u);
    c->unit_from_row = 1;
    return CF_OK;
}

cf_status cf_units_row_read(reader *r, layout *h, cf_error *err)
{
    size_t i = h->hi + 1, n = 0;
    for (; i < r->nlines; i++)
        if (!cf_csv_is_comment(&r->lines[i]) &&
            (n = cf_csv_content_length(r->lines[i].s, r->lines[i].n)) > 0)
            break;
    if (i >= r->nlines || !cf_units_row_is(r, i, n, h->delim))
        return CF_OK;
    const cf_csv_line *l = &r->lines[i];
    h->units_line = l->line;
    char q[256];
    cf_csv_quote(q, sizeof q, l->s, n);
    cf_status st = cf_reader_split(r, l, n, h->delim, err);
    if (st != CF_OK)
        return st;
    size_t cells = r->f.count - (h->trailing && r->f.count > h->ncols);
    if (cells > h->ncols)
        return cf_csv_error(err, r->path, h->units_line, h->ncols + 1,
                            "units row: %zu cells under a header of %zu columns ('%s')", cells,
                            h->ncols, q);
    for (size_t k = 0; k < cells; k++) { /* take_unit does not split: r->f stays this row */
        char u[CF_COLUMN_NAME_CAP];
        cell_unit(cf_csv_field(&r->f, k), u, sizeof u);
        if (u[0] && (st = take_unit(r, h, k, u, q, err)) != CF_OK)
            return st;
    }
    return CF_OK;
}
