/*
** The stages of the table reader (io/measure.c, io/header.c), private to it: what the reader holds
** while it reads a table, and what the header row decided.
*/
#ifndef CF_IO_READER_H
#define CF_IO_READER_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/csv.h"
#include "io/table_types.h"

typedef struct reader {
    const char *path;
    char *text;
    size_t size;
    cf_csv_line *lines; /* every line of the file */
    size_t nlines;
    cf_csv_line *comments; /* the '#' lines, without the '#' */
    size_t ncomments;
    cf_column *cols;
    size_t ncols;
    cf_csv_fields f;
    double *x, *y, *w, *t;
    size_t *row_line;   /* each row's line in the file */
    size_t count, cap;
} reader;

/* What the header decided, for the stages after it: where it is, its delimiter, its columns and
** which of them are x, y, the weight and the time (-1: none). */
typedef struct layout {
    size_t hi, hn;         /* index of the header in r->lines, its content length */
    size_t header_line;    /* its line number */
    char hq[256];          /* the header quoted, for messages */
    char delim;
    size_t ncols;
    int trailing;          /* the header ends with a delimiter: so must every row */
    long xi, yi, wi, ti;
    int preamble;          /* 1: lines before the header row (a preamble) were skipped */
    size_t no_header_at;   /* a preamble without a header: the line that should name the columns */
    size_t numbers_at;     /* and the first row of numbers after it */
    size_t units_line;     /* line number of the units row under the header; 0 when none */
} layout;

/* CF_E_INTERNAL: memory ran out reading the table at path. */
cf_status cf_reader_out_of_memory(cf_error *err, const char *path);

/* Splits line l (its first n bytes) at delim into r->f; CF_E_DATA naming the line and column
** for a quoting error. */
cf_status cf_reader_split(reader *r, const cf_csv_line *l, size_t n, char delim, cf_error *err);

/* The header row (h->hi, h->hn): the line opt->header_row names; else the first line with content,
** or, when that is followed by no rows of numbers, the first line after such a preamble that names
** known columns and is followed by rows (h->preamble: lines were skipped). When none is found and
** the first line names no known column, h->no_header_at is set for cf_header_read to refuse. */
cf_status cf_header_find(reader *r, const cf_measure_options *opt, layout *h, cf_error *err);

/* The header's delimiter and column names (r->cols, h->ncols); CF_E_DATA for a header of one
** column, an unnamed or overlong column, or a row of numbers. */
cf_status cf_header_read(reader *r, layout *h, cf_error *err);

/* 1 when line i (n bytes of content) split at delim is a units row: no cell a number, and every
** filled cell in brackets ("(s)", "[mm]") or one of them a known unit ("sec,mm,N"). Splits into
** r->f. */
int cf_units_row_is(reader *r, size_t i, size_t n, char delim);

/* The units row directly under the header, when there is one (h->units_line): each unit is taken
** for its column when the header names none, or only a bracketed word that is no unit
** ("Tensile strain (Extension)") (cf_column.unit_from_row); CF_E_DATA naming the line
** and column for a unit that contradicts the header's or that conifit does not know in a column
** the table reads. Runs after the columns are chosen. */
cf_status cf_units_row_read(reader *r, layout *h, cf_error *err);

/* Which columns are x, y, the weight and the time: the options name x and y, else the names
** tell. */
cf_status cf_header_choose_columns(const reader *r, const cf_measure_options *opt, layout *h,
                                   cf_error *err);

#endif
