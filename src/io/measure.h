/*
** Reading measured tables: stress against strain (or stretch), or force against displacement,
** from a CSV file with a header row, into the units conifit works in (MPa, N, mm, s).
**
** Accepted: '#' comment lines (anywhere, also before the header, holding any bytes), a preamble of
** metadata lines before the header row (skipped), CRLF or LF line ends, a UTF-8
** byte-order mark, ',' ';' or TAB delimiters (detected from the header), double-quoted fields,
** an optional `weight` column, an optional `time` column. Units come from the column name
** (`stress_kPa`, `stress [kPa]`, `stress (kPa)`, `displacement_mm`, `force_N`) or from the options;
** a bare `stress` column without a unit is an error unless opt->stress_unit gives one, except in
** files whose '#' comments state the unit (e.g. "stress = ... [kPa]"), which the reader honours.
** The x column is strain (engineering, dimensionless), stretch (converted to strain = stretch - 1),
** or displacement (mm after conversion). Sign convention on input: tension positive; tables in
** compression (negative values) are kept as they are and flagged in `compression`.
*/
#ifndef CF_MEASURE_H
#define CF_MEASURE_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/table.h"

/* Names of the measures a table records (table.h), as messages and reports spell them. */
const char *cf_stress_measure_name(cf_stress_measure m); /* "nominal", "cauchy" */
const char *cf_strain_measure_name(cf_strain_measure m); /* "engineering", "log", "stretch" */
const char *cf_decl_source_name(cf_decl_source s);       /* "assumed", "comment", ... */

/* Parse a measure word (case-insensitive; synonyms: true = cauchy, pk1/piola/engineering =
** nominal for stress; true/hencky/logarithmic = log, lambda = stretch for strain). Return 0 and
** set *m, or -1 for a word they do not know. */
int cf_stress_measure_parse(const char *word, cf_stress_measure *m);
int cf_strain_measure_parse(const char *word, cf_strain_measure *m);

typedef struct cf_measure_options {
    const char *x_col;       /* column name of x (with or without its unit decoration; a number
                             ** from 1 when no column has that name), or NULL: the first column
                             ** named strain/stretch/lambda/displacement/elongation/gamma/
                             ** shear..., else the first column that is not y */
    const char *y_col;       /* column name (or number) of y, or NULL: the first column named
                             ** stress/force/load..., else the first remaining column */
    const char *stress_unit; /* "Pa", "kPa", "MPa", "GPa", "N/mm2", "mmHg"...; NULL: from header */
    const char *force_unit;  /* "N", "mN", "kN", "uN"; NULL: from header */
    const char *length_unit; /* "m", "mm", "um", "cm"; NULL: from header */
    int x_is_stretch;        /* -1: decide from the column name, 0: strain, 1: stretch */
    const char *mode;        /* test mode ("uniaxial", "shear", ...), or NULL: from a '# mode:'
                             ** comment of the file, else uniaxial */
    int stress_measure;      /* -1: from the file (comment, column name; else nominal), or a
                             ** cf_stress_measure that wins over the file */
    int strain_measure;      /* -1: from the file, or a cf_strain_measure */
    size_t header_row;       /* 1-based line of the header row, or 0: the first line with
                             ** content, else the first after a preamble that names known columns
                             ** and is followed by rows of numbers */
    const char *columns;     /* "X,Y" or "X,Y,W": the x, y and weight columns by name or 1-based
                             ** number, and no others (no weight or time found by name); or NULL */
    const char *plane;       /* the plane in the fibre frame (table.h) of shear and biaxial tables
                             ** that state none or another in a '# plane:' comment: "ij" for
                             ** every shear and biaxial table, or a comma list of NAME=ij, NAME a table's file name
                             ** without folder and extension; NULL: from the comment */
} cf_measure_options;

/* Options with everything decided from the file. */
cf_measure_options cf_measure_default_options(void);

/* Fewest data rows a table must have (six design parameters). */
#define CF_MEASURE_MIN_ROWS 6

/* Limits of a table: beyond them it is refused with a message naming the line (CF_E_DATA), so that
** the memory and time a table takes are bounded by these and not only by what a file holds. */
#define CF_MEASURE_MAX_ROWS 1000000           /* data rows */
#define CF_MEASURE_MAX_COLUMNS 1000           /* columns of the header */
#define CF_MEASURE_MAX_LINES 2000000          /* lines in all: rows, comments, blank lines */
#define CF_MEASURE_MAX_BYTES ((size_t)256 << 20) /* file size, 256 MiB */
#define CF_MEASURE_MAX_VALUE 1e100                /* |value| in MPa, N, mm, s or a weight */

/* What a unit measures. */
typedef enum cf_unit_class {
    CF_UNIT_UNKNOWN = 0,
    CF_UNIT_STRESS = 1, /* converted to MPa */
    CF_UNIT_FORCE = 2,  /* converted to N */
    CF_UNIT_LENGTH = 3, /* converted to mm */
    CF_UNIT_TIME = 4,   /* converted to s */
    CF_UNIT_STRAIN = 5  /* dimensionless: "-", "1" or "%" (converted to a plain fraction) */
} cf_unit_class;

/* Looks up a unit name ("kPa", "MPa", "N/mm2", "mN", "um", "%", "mm/mm", ...; letter case is
** ignored except in a leading m or M, so "Mpa" is MPa and "mPa" is not a unit). Returns
** CF_UNIT_UNKNOWN for a name it does not know; otherwise the class, and in *to_conifit (if not
** NULL) the factor that converts a value in that unit to conifit's (MPa, N, mm, s, -). */
cf_unit_class cf_measure_unit(const char *name, double *to_conifit);

/* Reads the table at path ("-": standard input, named "(standard input)" in messages).
** A biaxial table ('# mode: biaxial', or option mode) holds two directions: its first strain and
** stress columns (by name, or option x_col and y_col) are the first direction, the next strain
** and stress columns after them the second, read with the same units and measures; its
** '# ratio: A:B' comment is checked against every row's two strains (1e-9 relative), and the
** rows are stacked as table.h says. Columns
** are separated by ',' ';' TAB or, when the header has none of them, by blanks. A message that
** points at a setting of opt names it "option FIELD" (option stress_unit, option x_col), which a
** front end maps to its own spelling. Errors (nothing allocated is left behind):
**   CF_E_NOINPUT  the file cannot be opened;
**   CF_E_DATA     missing header, unknown unit, a column not found, a non-numeric or non-finite
**                 cell, a short row, fewer than 6 data rows, an empty file, binary content, a
**                 weight <= 0; the message reads "PATH:LINE:COLUMN: what is wrong ('value')". */
cf_status cf_measure_load(const char *path, const cf_measure_options *opt, cf_table *m,
                          cf_error *err);

#endif
