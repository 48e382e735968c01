/*
** Reading measured tables (measure.h), in stages: the file's text, the header and which columns
** are x, y, a weight and a time, their units, the rows converted into MPa / N / mm / s, and the
** test mode; each stage refuses a table with one precise message. Columns in messages count
** fields from 1. The stages use the lexer (io/csv.c), the units and column names
** (io/columns.c) and the stress and strain measures (io/measures.c); what they fill is a
** cf_table (model/table.c).
*/
#include "io/measure.h"

#include "base/input.h"
#include "io/biaxial.h"
#include "io/columns.h"
#include "io/csv.h"
#include "io/measures.h"
#include "io/reader.h"
#include "model/mode.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

cf_measure_options cf_measure_default_options(void)
{
    cf_measure_options o = {NULL, NULL, NULL, NULL, NULL, -1, NULL, -1, -1, 0, NULL, NULL};
    return o;
}

/* ---- the text -------------------------------------------------------------------------------- */

static void reader_free(reader *r)
{
    free(r->text);
    free(r->lines);
    free(r->comments);
    free(r->cols);
    cf_csv_fields_free(&r->f);
    free(r->x);
    free(r->y);
    free(r->w);
    free(r->t);
    free(r->row_line);
}


static cf_status read_all(reader *r, cf_error *err)
{
    const int from_stdin = strcmp(r->path, "-") == 0; /* "-": standard input */
    FILE *fp = from_stdin ? stdin : cf_input_open(r->path, "table", err);
    if (!fp)
        return CF_E_NOINPUT;
    if (from_stdin)
        r->path = "(standard input)";
    size_t cap = 1 << 16;
    r->text = malloc(cap);
    if (!r->text) {
        if (!from_stdin)
            fclose(fp);
        return cf_reader_out_of_memory(err, r->path);
    }
    for (;;) {
        if (r->size > CF_MEASURE_MAX_BYTES) {
            if (!from_stdin)
                fclose(fp);
            return cf_error_set(err, CF_E_DATA, "%s:1:1: file larger than %zu bytes (256 MiB): not "
                                "a measured table", r->path, CF_MEASURE_MAX_BYTES);
        }
        if (r->size == cap) {
            /* one byte past the limit is enough to tell a file that is too large */
            size_t ncap = 2 * cap < CF_MEASURE_MAX_BYTES + 1 ? 2 * cap : CF_MEASURE_MAX_BYTES + 1;
            char *t = realloc(r->text, ncap);
            if (!t) {
                if (!from_stdin)
                    fclose(fp);
                return cf_reader_out_of_memory(err, r->path);
            }
            r->text = t;
            cap = ncap;
        }
        size_t got = fread(r->text + r->size, 1, cap - r->size, fp);
        r->size += got;
        if (got == 0)
            break;
    }
    int bad = ferror(fp);
    int saved = errno;
    if (!from_stdin)
        fclose(fp);
    if (bad)
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot read: %s", r->path,
                            strerror(saved ? saved : EIO));
    return CF_OK;
}

/* A spreadsheet is not a text table: say so, and what to do, instead of reporting its first
** binary byte. .xlsx and .ods are ZIP containers ("PK\3\4"), .xls an OLE2 compound file. */
static cf_status spreadsheet_check(const reader *r, cf_error *err)
{
    static const unsigned char zip[4] = {'P', 'K', 3, 4};
    static const unsigned char ole[8] = {0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1};
    const char *what = NULL;
    if (r->size >= 4 && memcmp(r->text, zip, 4) == 0)
        what = "a ZIP container, as .xlsx and .ods spreadsheets are";
    else if (r->size >= 8 && memcmp(r->text, ole, 8) == 0)
        what = "an OLE2 compound file, as .xls spreadsheets are";
    if (!what)
        return CF_OK;
    return cf_error_set(err, CF_E_DATA,
                        "%s:1:1: this file is %s, not a text table: save the sheet as CSV "
                        "(comma-separated values) in the spreadsheet program and fit that file",
                        r->path, what);
}

/* Cuts the text into lines (LF or CRLF), after a UTF-8 byte-order mark. */
static cf_status cut_lines(reader *r, cf_error *err)
{
    const char *s = r->text, *end = r->text + r->size;
    if (r->size >= 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0)
        s += 3;
    size_t cap = 0;
    for (size_t line = 1; s < end; line++) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        const char *e = nl ? nl : end;
        size_t n = (size_t)(e - s);
        if (n > 0 && s[n - 1] == '\r')
            n--;
        if (r->nlines == CF_MEASURE_MAX_LINES)
            return cf_error_set(err, CF_E_DATA, "%s:%zu:1: more than %d lines: not a measured "
                                "table (at most %d data rows)", r->path, line,
                                CF_MEASURE_MAX_LINES, CF_MEASURE_MAX_ROWS);
        if (r->nlines == cap) {
            cap = cap ? 2 * cap : 256;
            cf_csv_line *l = realloc(r->lines, cap * sizeof *l);
            if (!l)
                return cf_reader_out_of_memory(err, r->path);
            r->lines = l;
        }
        r->lines[r->nlines++] = (cf_csv_line){s, n, line};
        s = nl ? nl + 1 : end;
    }
    return CF_OK;
}

/* Collects the comment lines (which may hold any bytes: a degree sign in a Windows code page). */
static cf_status scan_comments(reader *r, cf_error *err)
{
    r->comments = malloc((r->nlines ? r->nlines : 1) * sizeof *r->comments);
    if (!r->comments)
        return cf_reader_out_of_memory(err, r->path);
    for (size_t i = 0; i < r->nlines; i++) {
        const cf_csv_line *l = &r->lines[i];
        if (cf_csv_is_comment(l)) {
            const char *h = memchr(l->s, '#', l->n);
            r->comments[r->ncomments++] = (cf_csv_line){h + 1, l->n - (size_t)(h + 1 - l->s),
                                                      l->line};
        }
    }
    return CF_OK;
}

/* Checks the header and every line after it for binary content, up to a comment: only what is
** read as the table must be text (a preamble before the header and comments may hold any bytes). */
static cf_status check_text(const reader *r, const layout *h, cf_error *err)
{
    for (size_t i = h->hi; i < r->nlines; i++) {
        const cf_csv_line *l = &r->lines[i];
        if (cf_csv_is_comment(l))
            continue;
        size_t n = cf_csv_content_length(l->s, l->n);
        size_t b = cf_csv_bad_byte((const unsigned char *)l->s, n);
        if (b < n) {
            char q[256];
            cf_csv_quote(q, sizeof q, l->s, l->n);
            unsigned char c = (unsigned char)l->s[b];
            return cf_csv_error(err, r->path, l->line, b + 1,
                                "%s: byte 0x%02X is not text (the column counts bytes here) ('%s')",
                                c == '\r' ? "carriage return inside a line" : "binary content", c,
                                q);
        }
    }
    return CF_OK;
}


/* ---- the header and its columns -------------------------------------------------------------- */

/* ---- units ----------------------------------------------------------------------------------- */

/* The units decided: the y unit, the measures, and the factors to conifit's units. */
typedef struct scaling {
    const cf_unit_def *yu;
    cf_table_measures meas;
    int stretch;           /* x is a stretch: strain = x - 1 */
    double xscale, yscale, tscale;
} scaling;

/* Why text (quoted as q) is no unit, for a message: a unit that differs from a known one only in
** a leading m or M names both readings; anything else lists the known units. */
static void unit_refusal(char *out, size_t cap, const char *text, const char *q)
{
    const cf_unit_def *near = cf_unit_m_case(text);
    if (near)
        snprintf(out, cap, "unit '%s' is ambiguous: a leading m is milli (or metre) and M is "
                 "mega, and the known unit is '%s', not '%s'; write '%s' if that is meant", q,
                 near->name, q, near->name);
    else
        snprintf(out, cap, "unknown unit '%s' (known units; letter case is ignored except in a "
                 "leading m or M: %s)", q, cf_unit_list);
}

/* Resolves the unit of column c: the option if given, else its decoration, else a '#' comment.
** Returns CF_OK with *u NULL when no unit is stated anywhere. */
static cf_status column_unit(const reader *r, size_t header_line, size_t ci, const char *option,
                             const char *option_flag, int which, const cf_unit_class *want,
                             size_t nwant, const cf_unit_def **u, cf_error *err)
{
    const cf_column *c = &r->cols[ci];
    const char *text = option ? option : (c->unit[0] ? c->unit : NULL);
    *u = NULL;
    if (text) {
        const cf_unit_def *d = cf_unit_find(text);
        char q[256], why[512];
        cf_csv_quote(q, sizeof q, text, strlen(text));
        if (!d) {
            unit_refusal(why, sizeof why, text, q);
            if (option)
                return cf_error_set(err, CF_E_DATA, "%s: %s %s", r->path, option_flag, why);
            return cf_csv_error(err, r->path, header_line, ci + 1, "column '%s': %s ('%s')",
                                c->name, why, q);
        }
        for (size_t k = 0; k < nwant; k++)
            if (d->cls == want[k]) {
                *u = d;
                return CF_OK;
            }
        if (option)
            return cf_error_set(err, CF_E_DATA, "%s: %s '%s' is not a unit for column '%s'",
                                r->path, option_flag, q, c->name);
        return cf_csv_error(err, r->path, header_line, ci + 1,
                            "column '%s': unit '%s' does not fit this column ('%s')", c->name, q,
                            c->name);
    }
    *u = cf_comment_unit(r->comments, r->ncomments, c->base, which, want, nwant);
    return CF_OK;
}

/* The unit of y, which decides between stress-strain and force-displacement (m->kind). */
static cf_status y_unit(const reader *r, const cf_measure_options *opt, const layout *h,
                        cf_table *m, scaling *u, cf_error *err)
{
    const cf_column *yc = &r->cols[h->yi];
    cf_unit_class yname = cf_column_y_class(yc->base);
    const char *yopt = NULL, *yflag = "option stress_unit";
    cf_unit_class ywant[2] = {CF_UNIT_STRESS, CF_UNIT_FORCE};
    size_t nywant = 2;
    if (yname == CF_UNIT_STRESS) {
        yopt = opt->stress_unit;
        nywant = 1;
    } else if (yname == CF_UNIT_FORCE) {
        yopt = opt->force_unit;
        yflag = "option force_unit";
        ywant[0] = CF_UNIT_FORCE;
        nywant = 1;
    } else if (opt->stress_unit) {
        yopt = opt->stress_unit;
    } else if (opt->force_unit) {
        yopt = opt->force_unit;
        yflag = "option force_unit";
    }
    cf_status st = column_unit(r, h->header_line, (size_t)h->yi, yopt, yflag, 1, ywant, nywant,
                               &u->yu, err);
    if (st)
        return st;
    if (!u->yu) {
        const char *hint = yname == CF_UNIT_FORCE
                               ? "force_N or force [mN], or set option force_unit"
                               : "stress_kPa or stress [kPa], or set option stress_unit (option "
                                 "force_unit for a force)";
        return cf_csv_error(err, r->path, h->header_line, (size_t)h->yi + 1,
                            "column '%s' has no unit: name it like %s ('%s')", yc->name, hint,
                            yc->name);
    }
    m->kind =
        u->yu->cls == CF_UNIT_STRESS ? CF_TABLE_STRESS_STRAIN : CF_TABLE_FORCE_DISPLACEMENT;
    u->yscale = u->yu->to_conifit;
    return CF_OK;
}

/* 1 when a column's name without unit says it holds percent: "strain percent", "strain%",
** "percent_strain" (so that such a column is never read as plain strain). */
static int names_percent(const char *base)
{
    return strchr(base, '%') != NULL || cf_measures_contains_ci(base, "percent");
}

/* The unit of x: a strain or stretch against a stress, a length against a force. */
static cf_status x_unit(const reader *r, const cf_measure_options *opt, const layout *h,
                        const cf_table *m, scaling *u, cf_error *err)
{
    const char *path = r->path;
    const cf_column *xc = &r->cols[h->xi];
    const cf_unit_def *xu = NULL;
    u->xscale = 1.0;
    if (m->kind == CF_TABLE_STRESS_STRAIN) {
        cf_unit_class xw[1] = {CF_UNIT_STRAIN};
        if (xc->unit[0]) {
            const cf_unit_def *d = cf_unit_find(xc->unit);
            if (!d && cf_unit_m_case(xc->unit)) {
                char q[256], why[512];
                cf_csv_quote(q, sizeof q, xc->unit, strlen(xc->unit));
                unit_refusal(why, sizeof why, xc->unit, q);
                return cf_csv_error(err, path, h->header_line, (size_t)h->xi + 1,
                                    "column '%s': %s ('%s')", xc->name, why, q);
            }
            if (!d || d->cls != CF_UNIT_STRAIN)
                return cf_csv_error(err, path, h->header_line, (size_t)h->xi + 1,
                                    "column '%s' has unit '%s' but y is a stress, so x must be a "
                                    "dimensionless strain or stretch ('-', 'mm/mm' or '%%') "
                                    "('%s')",
                                    xc->name, xc->unit, xc->name);
            xu = d;
        } else if (names_percent(xc->base))
            xu = cf_unit_find("%");
        else
            xu = cf_comment_unit(r->comments, r->ncomments, xc->base, 0, xw, 1);
        if (xu)
            u->xscale = xu->to_conifit;
        if (u->stretch && u->xscale != 1.0)
            return cf_csv_error(err, path, h->header_line, (size_t)h->xi + 1,
                                "stretch column '%s' cannot be in '%%' ('%s')", xc->name, xc->name);
        return CF_OK;
    }
    cf_unit_class xw[1] = {CF_UNIT_LENGTH};
    if (u->stretch)
        return cf_csv_error(err, path, h->header_line, (size_t)h->xi + 1,
                            "column '%s' is a stretch but y is a force; give a displacement "
                            "column or a stress ('%s')", xc->name, xc->name);
    cf_status st = column_unit(r, h->header_line, (size_t)h->xi, opt->length_unit,
                               "option length_unit", 0, xw, 1, &xu, err);
    if (st)
        return st;
    if (!xu)
        return cf_csv_error(err, path, h->header_line, (size_t)h->xi + 1,
                            "column '%s' has no length unit (y is a force): name it like "
                            "displacement_mm, or set option length_unit ('%s')", xc->name,
                            xc->name);
    u->xscale = xu->to_conifit;
    return CF_OK;
}

/* The unit of the time column, if there is one. */
static cf_status t_unit(const reader *r, const layout *h, scaling *u, cf_error *err)
{
    u->tscale = 1.0;
    if (h->ti < 0)
        return CF_OK;
    const cf_unit_def *tu = NULL;
    cf_unit_class tw[1] = {CF_UNIT_TIME};
    cf_status st = column_unit(r, h->header_line, (size_t)h->ti, NULL, "", 2, tw, 1, &tu, err);
    if (st)
        return st;
    if (!tu)
        return cf_csv_error(err, r->path, h->header_line, (size_t)h->ti + 1,
                            "time column '%s' has no unit: name it like time_s or time [s] "
                            "(s, ms, min, h)",
                            r->cols[h->ti].name);
    u->tscale = tu->to_conifit;
    return CF_OK;
}

/* Units: y first (it decides the kind of table), the measures, then x and the time. */
static cf_status decide_units(const reader *r, const cf_measure_options *opt, const layout *h,
                              cf_table *m, scaling *u, cf_error *err)
{
    cf_status st = y_unit(r, opt, h, m, u, err);
    if (st == CF_OK)
        st = cf_measures_read(r->comments, r->ncomments, r->path, opt, &r->cols[h->xi],
                              &r->cols[h->yi], &u->meas, err);
    if (st != CF_OK)
        return st;
    u->stretch = u->meas.strain == CF_STRAIN_STRETCH;
    if ((st = x_unit(r, opt, h, m, u, err)) != CF_OK)
        return st;
    return t_unit(r, h, u, err);
}

/* ---- rows ------------------------------------------------------------------------------------ */

static int push_row(reader *r, double x, double y, double w, double t, size_t line)
{
    if (r->count == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 64;
        size_t *rl = realloc(r->row_line, cap * sizeof *rl);
        if (!rl)
            return -1;
        r->row_line = rl;
        double *a[4] = {r->x, r->y, r->w, r->t};
        for (int k = 0; k < 4; k++) {
            double *p = realloc(a[k], cap * sizeof *p);
            if (!p)
                return -1;
            a[k] = p;
            if (k == 0)
                r->x = p;
            else if (k == 1)
                r->y = p;
            else if (k == 2)
                r->w = p;
            else
                r->t = p;
        }
        r->cap = cap;
    }
    r->x[r->count] = x;
    r->y[r->count] = y;
    r->w[r->count] = w;
    r->t[r->count] = t;
    r->row_line[r->count] = line;
    r->count++;
    return 0;
}

/* The field count of a row (split into r->f) against the header's. */
static cf_status check_row_width(const reader *r, const cf_csv_line *l, const layout *h,
                                 const char *q, cf_error *err)
{
    const size_t nf = r->f.count, want = h->ncols + (size_t)h->trailing;
    if (nf < want)
        return cf_csv_error(err, r->path, l->line, nf + 1,
                            "short row: %zu fields where the header has %zu%s ('%s')", nf, want,
                            h->trailing ? " (the header ends with a delimiter, so must every row)"
                                      : "",
                          q);
    if (nf > want) {
        char fq[128];
        cf_csv_quote(fq, sizeof fq, cf_csv_field(&r->f, want), strlen(cf_csv_field(&r->f, want)));
        return cf_csv_error(err, r->path, l->line, want + 1,
                            "long row: %zu fields where the header has %zu (extra '%s') ('%s')", nf,
                            want, fq, q);
    }
    if (h->trailing && cf_csv_field(&r->f, h->ncols)[0])
        return cf_csv_error(err, r->path, l->line, h->ncols + 1,
                            "a value in the unnamed last column (the header ends with a "
                            "delimiter) ('%s')", cf_csv_field(&r->f, h->ncols));
    return CF_OK;
}

/* The x, y, weight and time cells of a row (split into r->f) as numbers, v[4]. */
static cf_status row_numbers(const reader *r, const cf_csv_line *l, const layout *h, double v[4],
                             cf_error *err)
{
    const long idx[4] = {h->xi, h->yi, h->wi, h->ti};
    for (int k = 0; k < 4; k++) {
        if (idx[k] < 0)
            continue;
        const char *cell = cf_csv_field(&r->f, (size_t)idx[k]);
        cf_csv_num nr = cf_csv_number(cell, h->delim, &v[k]);
        if (nr != CF_CSV_NUM_OK) {
            char cq[128];
            cf_csv_quote(cq, sizeof cq, cell, strlen(cell));
            const char *what = nr == CF_CSV_NUM_EMPTY        ? "empty cell"
                               : nr == CF_CSV_NUM_NOT_FINITE ? "not a finite number"
                                                      : "not a number";
            return cf_csv_error(err, r->path, l->line, (size_t)idx[k] + 1, "column '%s': %s ('%s')",
                                r->cols[idx[k]].name, what, cq);
        }
    }
    if (h->wi >= 0 && !(v[2] > 0.0))
        return cf_csv_error(err, r->path, l->line, (size_t)h->wi + 1,
                            "column '%s': a weight must be > 0 ('%s')", r->cols[h->wi].name,
                            cf_csv_field(&r->f, (size_t)h->wi));
    return CF_OK;
}

/* One data row (line l, n characters of content): checked, converted and appended. *skip = 1
** for a row of empty cells, which counts as blank. *tprev is the time of the row before. */
static cf_status read_row(reader *r, const cf_csv_line *l, size_t n, const layout *h,
                          const scaling *u, double *tprev, int *skip, cf_error *err)
{
    const char *path = r->path;
    cf_status st = cf_reader_split(r, l, n, h->delim, err);
    if (st != CF_OK)
        return st;
    *skip = 1;
    for (size_t k = 0; k < r->f.count; k++)
        if (cf_csv_field(&r->f, k)[0])
            *skip = 0;
    if (*skip)
        return CF_OK;
    char q[256];
    cf_csv_quote(q, sizeof q, l->s, n);
    double v[4] = {0.0, 0.0, 1.0, 0.0};
    if ((st = check_row_width(r, l, h, q, err)) != CF_OK ||
        (st = row_numbers(r, l, h, v, err)) != CF_OK)
        return st;
    double x = u->stretch ? v[0] - 1.0 : v[0] * u->xscale;
    double y = v[1] * u->yscale, t = v[3] * u->tscale;
    if (!isfinite(x) || !isfinite(y) || !isfinite(t))
        return cf_csv_error(err, path, l->line, (size_t)h->xi + 1,
                            "value out of range after unit conversion ('%s')", q);
    /* finite, but so large that sums of squares over the table (RMSE, R^2, the fit's
    ** objective) would overflow: refused, so that no derived number can be Inf or NaN */
    if (fabs(x) > CF_MEASURE_MAX_VALUE || fabs(y) > CF_MEASURE_MAX_VALUE ||
        fabs(v[2]) > CF_MEASURE_MAX_VALUE || fabs(t) > CF_MEASURE_MAX_VALUE) {
        size_t col = fabs(x) > CF_MEASURE_MAX_VALUE      ? (size_t)h->xi
                     : fabs(y) > CF_MEASURE_MAX_VALUE    ? (size_t)h->yi
                     : fabs(v[2]) > CF_MEASURE_MAX_VALUE ? (size_t)h->wi
                                                         : (size_t)h->ti;
        return cf_csv_error(err, path, l->line, col + 1,
                            "column '%s': magnitude above %g in conifit's units (MPa, N, mm, s): "
                            "sums over the table would overflow ('%s')",
                            r->cols[col].name, CF_MEASURE_MAX_VALUE, q);
    }
    if (r->count == CF_MEASURE_MAX_ROWS)
        return cf_csv_error(err, path, l->line, 1,
                            "more than %d data rows: a table may have at most %d (thin it, or "
                            "fit a part of it)", CF_MEASURE_MAX_ROWS, CF_MEASURE_MAX_ROWS);
    if (h->ti >= 0 && r->count > 0 && !(t > *tprev))
        return cf_csv_error(err, path, l->line, (size_t)h->ti + 1,
                            "column '%s': time %.17g s does not increase (the row before has "
                            "%.17g s) ('%s')",
                            r->cols[h->ti].name, t, *tprev, cf_csv_field(&r->f, (size_t)h->ti));
    *tprev = t;
    if (push_row(r, x, y, v[2], t, l->line) != 0)
        return cf_reader_out_of_memory(err, path);
    return CF_OK;
}

/* Rows: every line after the header that is not a comment or blank. */
static cf_status read_rows(reader *r, const layout *h, const scaling *u, cf_error *err)
{
    size_t last_line = h->header_line;
    double tprev = 0;
    for (size_t li = h->hi + 1; li < r->nlines; li++) {
        const cf_csv_line *l = &r->lines[li];
        if (cf_csv_is_comment(l))
            continue;
        size_t n = cf_csv_content_length(l->s, l->n);
        if (n == 0 || l->line == h->units_line)
            continue;
        int skip = 0;
        cf_status st = read_row(r, l, n, h, u, &tprev, &skip, err);
        if (st != CF_OK)
            return st;
        if (!skip)
            last_line = l->line;
    }
    if (r->count < CF_MEASURE_MIN_ROWS)
        return cf_csv_error(err, r->path, last_line, 1,
                            "only %zu data rows; a fit needs at least %d ('%zu rows')", r->count,
                            CF_MEASURE_MIN_ROWS, r->count);
    return CF_OK;
}

/* ---- the table ------------------------------------------------------------------------------- */

/* The test mode: the option wins over the file's comment. */
static cf_status decide_mode(const reader *r, const cf_measure_options *opt, cf_table *m,
                             cf_error *err)
{
    m->mode = CF_MODE_UNIAXIAL;
    m->mode_stated = 0;
    if (!opt->mode)
        return cf_comment_mode(r->comments, r->ncomments, r->path, &m->mode, &m->mode_stated, err);
    cf_error me = {0};
    if (cf_mode_parse(opt->mode, &m->mode, &me) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: --mode %s: expected %s", r->path, opt->mode,
                            cf_mode_list());
    m->mode_stated = 1;
    return CF_OK;
}

/* Appends one line to m->notes (cut to fit). */
static void add_note(cf_table *m, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void add_note(cf_table *m, const char *fmt, ...)
{
    size_t o = strlen(m->notes);
    if (o > 0 && o + 1 < sizeof m->notes)
        m->notes[o++] = '\n', m->notes[o] = '\0';
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->notes + o, sizeof m->notes - o, fmt, ap);
    va_end(ap);
}

/* A unit taken from the units row, or a unit decoration read in another letter case ("Mpa" as
** MPa), is said. */
static void note_unit_case(cf_table *m, const cf_column *c, size_t units_line)
{
    const cf_unit_def *d = c->unit[0] ? cf_unit_find(c->unit) : NULL;
    if (d && c->unit_from_row)
        add_note(m, "column '%s': unit '%s' read from the units row under the header (line %zu)",
                 c->name, c->unit, units_line);
    else if (d && strcmp(d->name, c->unit) != 0)
        add_note(m, "column '%s': unit '%s' read as %s", c->name, c->unit, d->canon);
}

/* Strain that looks like stretch: where the stress is smallest (zero, unloaded), an engineering
** strain near 1 means 100 % strain at rest, which no specimen has; a stretch column has 1 there. */
#define STRETCH_LIKE_TOL 0.05
/* "Where the stress is least" is a row at rest when that stress is within this fraction of the
** largest (a measured zero carries noise). */
#define STRETCH_LIKE_REST 0.01

/* The notes of a table (table.h): a skipped preamble, units taken from the units row or read in
** another case (x, y and the time), and a strain column whose values look like stretch (unless
** an option said what the column holds). */
static void table_notes(const layout *h, const reader *r, cf_table *m)
{
    if (h->preamble)
        add_note(m, "lines 1 to %zu before the header row (line %zu) were skipped as a preamble",
                 h->header_line - 1, h->header_line);
    note_unit_case(m, &r->cols[h->xi], h->units_line);
    note_unit_case(m, &r->cols[h->yi], h->units_line);
    if (h->ti >= 0)
        note_unit_case(m, &r->cols[h->ti], h->units_line);
    if (m->kind != CF_TABLE_STRESS_STRAIN || m->measures.strain != CF_STRAIN_ENGINEERING ||
        m->measures.strain_from == CF_DECL_OPTION || m->count == 0)
        return;
    size_t at = 0;
    double ymax = 0.0;
    for (size_t i = 0; i < m->count; i++) {
        ymax = fmax(ymax, fabs(m->y[i]));
        if (fabs(m->y[i]) < fabs(m->y[at]))
            at = i;
    }
    if (fabs(m->x[at] - 1.0) <= STRETCH_LIKE_TOL && fabs(m->y[at]) <= STRETCH_LIKE_REST * ymax)
        add_note(m, "column '%s' holds strain %.6g where the stress is least (%.6g %s, row %zu): "
                 "strain 1 at rest looks like stretch; if the column is stretch, name it "
                 "stretch or give option strain_measure stretch",
                 m->x_column, m->x[at], m->y[at] * m->y_to_file, m->y_unit, at + 1);
}

/* Hands the rows and what is known of them over to m (the reader keeps no rows). */
static void hand_over(reader *r, const layout *h, const scaling *u, cf_table *m)
{
    int neg = 0, pos = 0;
    for (size_t i = 0; i < r->count; i++) {
        neg |= r->x[i] < 0.0;
        pos |= r->x[i] > 0.0;
    }
    m->count = r->count;
    m->x = r->x;
    m->y = r->y;
    m->w = r->w;
    if (h->ti >= 0)
        m->t = r->t;
    else
        free(r->t);
    r->x = r->y = r->w = r->t = NULL;
    m->y_to_file = 1.0 / u->yscale;
    m->compression = neg && !pos;
    m->x_from_stretch = u->stretch;
    cf_csv_utf8_copy(m->path, sizeof m->path, r->path);
    cf_csv_utf8_copy(m->x_column, sizeof m->x_column, r->cols[h->xi].name);
    cf_csv_utf8_copy(m->y_column, sizeof m->y_column, r->cols[h->yi].name);
    snprintf(m->x_unit, sizeof m->x_unit, "%s",
             m->kind == CF_TABLE_STRESS_STRAIN ? "-" : "mm");
    snprintf(m->y_unit, sizeof m->y_unit, "%s", u->yu->canon);
    m->measures = u->meas;
    table_notes(h, r, m);
}

/* Reading a table is one pass through its stages in order: the text, the header, which columns,
** their units, the rows, the test mode; every stage reads what the ones before decided (in the
** reader, the layout and the scaling), and every refusal releases everything at one exit, so no
** error path can leak or leave a half-filled table. A first reading (pair not NULL) also takes
** the plane and, for a biaxial table, its ratio and its second pair of columns; a second reading
** (lines not NULL) hands back the line of every row. */
static cf_status load(const char *path, const cf_measure_options *opt_in, cf_table *m,
                      char *pair, size_t cap, size_t **lines, cf_error *err)
{
    cf_measure_options opt = opt_in ? *opt_in : cf_measure_default_options();
    reader r;
    layout h;
    scaling u;
    memset(&r, 0, sizeof r);
    memset(&h, 0, sizeof h);
    memset(&u, 0, sizeof u);
    memset(m, 0, sizeof *m);
    if (!path)
        return cf_error_set(err, CF_E_NOINPUT, "no input file named");
    r.path = path; /* read_all names standard input "(standard input)" */
    cf_status st;
    if ((st = read_all(&r, err)) != CF_OK || (st = spreadsheet_check(&r, err)) != CF_OK ||
        (st = cut_lines(&r, err)) != CF_OK || (st = scan_comments(&r, err)) != CF_OK ||
        (st = cf_header_find(&r, &opt, &h, err)) != CF_OK ||
        (st = check_text(&r, &h, err)) != CF_OK || (st = cf_header_read(&r, &h, err)) != CF_OK ||
        (st = cf_header_choose_columns(&r, &opt, &h, err)) != CF_OK ||
        (st = cf_units_row_read(&r, &h, err)) != CF_OK ||
        (st = decide_units(&r, &opt, &h, m, &u, err)) != CF_OK ||
        (st = read_rows(&r, &h, &u, err)) != CF_OK ||
        (st = decide_mode(&r, &opt, m, err)) != CF_OK) {
        reader_free(&r);
        memset(m, 0, sizeof *m);
        return st;
    }
    hand_over(&r, &h, &u, m);
    if (pair && (st = cf_biaxial_frame(&r, &h, &opt, m, pair, cap, err)) != CF_OK) {
        reader_free(&r);
        cf_table_free(m);
        memset(m, 0, sizeof *m);
        return st;
    }
    if (lines) {
        *lines = r.row_line;
        r.row_line = NULL;
    }
    reader_free(&r);
    if ((st = cf_measures_convert(m, err)) != CF_OK) {
        cf_table_free(m);
        memset(m, 0, sizeof *m);
        return st;
    }
    cf_error_clear(err);
    return CF_OK;
}

cf_status cf_measure_load(const char *path, const cf_measure_options *opt, cf_table *m,
                          cf_error *err)
{
    char pair[48] = "";
    cf_status st = load(path, opt, m, pair, sizeof pair, NULL, err);
    if (st != CF_OK || m->mode != CF_MODE_BIAXIAL)
        return st;
    cf_measure_options o = opt ? *opt : cf_measure_default_options();
    o.columns = pair;
    o.x_col = o.y_col = NULL;
    o.mode = "biaxial";
    cf_table b;
    size_t *lines = NULL;
    if ((st = load(path, &o, &b, NULL, 0, &lines, err)) == CF_OK)
        st = cf_biaxial_stack(m, &b, lines, pair, err);
    free(lines);
    cf_table_free(&b);
    if (st != CF_OK) {
        cf_table_free(m);
        memset(m, 0, sizeof *m);
        return st;
    }
    cf_error_clear(err);
    return CF_OK;
}
