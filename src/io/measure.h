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
#include "io/table_types.h"
#include "model/table.h"

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
