/*
** Reading measured tables: stress against strain (or stretch), or force against displacement,
** from a CSV file with a header row, into the units conifit works in (MPa, N, mm, s).
**
** Accepted: '#' comment lines (anywhere, also before the header), CRLF or LF line ends, a UTF-8
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

#include "error.h"

typedef enum cf_measure_kind {
    CF_MEASURE_STRESS_STRAIN = 0,     /* x = engineering strain [-], y = stress [MPa] */
    CF_MEASURE_FORCE_DISPLACEMENT = 1 /* x = displacement [mm], y = force [N] */
} cf_measure_kind;

typedef struct cf_measure_options {
    const char *x_col;       /* column name of x, or NULL to take the first data column */
    const char *y_col;       /* column name of y, or NULL to take the column after x */
    const char *stress_unit; /* "Pa", "kPa", "MPa", "GPa", "N/mm2", "mmHg"...; NULL: from header */
    const char *force_unit;  /* "N", "mN", "kN", "uN"; NULL: from header */
    const char *length_unit; /* "m", "mm", "um", "cm"; NULL: from header */
    int x_is_stretch;        /* -1: decide from the column name, 0: strain, 1: stretch */
} cf_measure_options;

/* Options with everything decided from the file. */
cf_measure_options cf_measure_default_options(void);

typedef struct cf_measure {
    cf_measure_kind kind;
    size_t count;          /* number of data rows */
    double *x;             /* strain [-] or displacement [mm], count values */
    double *y;             /* stress [MPa] or force [N], count values */
    double *w;             /* weights (> 0; 1 when the file has no weight column), count values */
    double *t;             /* time [s] when the file has a time column, else NULL */
    double y_to_file;      /* multiply y by this to get the file's own unit (1000 for kPa) */
    int compression;       /* 1 when the data lie at negative x (compression negative) */
    char path[1024];       /* the file as named by the caller */
    char x_column[64];     /* header name of the x column */
    char y_column[64];     /* header name of the y column */
    char x_unit[16];       /* "-" for strain, "mm" for displacement after conversion */
    char y_unit[16];       /* the file's own unit of y ("kPa", "mN", ...), used in reports */
} cf_measure;

/* Reads the table at path. Errors (nothing allocated is left behind):
**   CF_E_NOINPUT  the file cannot be opened;
**   CF_E_DATA     missing header, unknown unit, a column not found, a non-numeric or non-finite
**                 cell, a short row, fewer than 6 data rows, an empty file, binary content, a
**                 weight <= 0; the message reads "PATH:LINE:COLUMN: what is wrong ('value')". */
cf_status cf_measure_load(const char *path, const cf_measure_options *opt, cf_measure *m,
                          cf_error *err);

/* Releases the arrays of m (safe on a zeroed struct). */
void cf_measure_free(cf_measure *m);

#endif
