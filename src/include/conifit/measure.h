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

#include "conifit/cell.h"
#include "conifit/error.h"

typedef enum cf_table_kind {
    CF_TABLE_STRESS_STRAIN = 0,     /* x = engineering strain [-], y = stress [MPa] */
    CF_TABLE_FORCE_DISPLACEMENT = 1 /* x = displacement [mm], y = force [N] */
} cf_table_kind;

/* What the y column measures in a stress-strain table. Conversion: a Cauchy (true) stress sigma
** becomes the nominal (first Piola-Kirchhoff) stress P the law models under incompressibility
** (J = 1), for the table's test mode (cf_mode, cell.h): uniaxial, planar and equibiaxial
** P = sigma / lambda along the loading axis (lambda = 1 + strain); simple shear P = sigma (the
** shear face keeps its area); confined compression P = sigma (the lateral stretches are 1). */
typedef enum cf_stress_measure {
    CF_STRESS_NOMINAL = 0, /* force over undeformed area (first Piola-Kirchhoff) */
    CF_STRESS_CAUCHY = 1   /* force over deformed area (true stress) */
} cf_stress_measure;

/* What the x column measures: engineering strain (stretch - 1, or the amount of shear), the
** logarithmic (true, Hencky) strain ln(stretch), or the stretch itself. */
typedef enum cf_strain_measure {
    CF_STRAIN_ENGINEERING = 0,
    CF_STRAIN_LOG = 1,
    CF_STRAIN_STRETCH = 2
} cf_strain_measure;

/* Where a measure came from. */
typedef enum cf_decl_source {
    CF_DECL_ASSUMED = 0, /* nothing said: the default was assumed (and is reported as such) */
    CF_DECL_COMMENT = 1, /* a '# stress:' or '# strain:' comment */
    CF_DECL_COLUMN = 2,  /* the column's name (true_stress, cauchy, log_strain, lambda, ...) */
    CF_DECL_OPTION = 3   /* the caller's option (it wins over the file; see *_overridden) */
} cf_decl_source;

/* The measures of a table as read and what was done with them. */
typedef struct cf_table_measures {
    cf_stress_measure stress;   /* as the file (or option) gives it, before conversion */
    cf_strain_measure strain;
    cf_decl_source stress_from, strain_from;
    size_t stress_line, strain_line; /* the comment's line (CF_DECL_COMMENT), else 0 */
    int stress_overridden;      /* 1: an option replaced a different declaration in the file, */
    int strain_overridden;      /* which *_file then holds (its line in *_line when a comment) */
    int stress_file, strain_file;
    int stress_converted;       /* 1: y was converted from Cauchy to nominal */
    int strain_converted;       /* 1: x was converted from log strain or stretch to engineering */
} cf_table_measures;

const char *cf_stress_measure_name(cf_stress_measure m); /* "nominal", "cauchy" */
const char *cf_strain_measure_name(cf_strain_measure m); /* "engineering", "log", "stretch" */
const char *cf_decl_source_name(cf_decl_source s);       /* "assumed", "comment", ... */

/* Parse a measure word (case-insensitive; synonyms: true = cauchy, pk1/piola/engineering =
** nominal for stress; true/hencky/logarithmic = log, lambda = stretch for strain). Return 0 and
** set *m, or -1 for a word they do not know. */
int cf_stress_measure_parse(const char *word, cf_stress_measure *m);
int cf_strain_measure_parse(const char *word, cf_strain_measure *m);

typedef struct cf_measure_options {
    const char *x_col;       /* column name of x (with or without its unit decoration), or NULL:
                             ** the first column named strain/stretch/lambda/displacement/
                             ** elongation/gamma/shear..., else the first column that is not y */
    const char *y_col;       /* column name of y, or NULL: the first column named stress/force/
                             ** load..., else the first remaining column */
    const char *stress_unit; /* "Pa", "kPa", "MPa", "GPa", "N/mm2", "mmHg"...; NULL: from header */
    const char *force_unit;  /* "N", "mN", "kN", "uN"; NULL: from header */
    const char *length_unit; /* "m", "mm", "um", "cm"; NULL: from header */
    int x_is_stretch;        /* -1: decide from the column name, 0: strain, 1: stretch */
    const char *mode;        /* test mode ("uniaxial", "shear", ...), or NULL: from a '# mode:'
                             ** comment of the file, else uniaxial */
    int stress_measure;      /* -1: from the file (comment, column name; else nominal), or a
                             ** cf_stress_measure that wins over the file */
    int strain_measure;      /* -1: from the file, or a cf_strain_measure */
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

/* Looks up a unit name (case-sensitive: "kPa", "MPa", "N/mm2", "mN", "um", "%", ...). Returns
** CF_UNIT_UNKNOWN for a name it does not know; otherwise the class, and in *to_conifit (if not
** NULL) the factor that converts a value in that unit to conifit's (MPa, N, mm, s, -). */
cf_unit_class cf_measure_unit(const char *name, double *to_conifit);

/* A measured table in conifit's units: the one type that goes from the reader through the fit,
** the validation, the report and the plots. The reader fills every field; a table built in code
** (cf_table_from_arrays) has kind, count, x, y, w, y_to_file = 1 and empty names. */
typedef struct cf_table {
    cf_table_kind kind;
    size_t count;          /* number of data rows */
    double *x;             /* strain [-] or displacement [mm], count values */
    double *y;             /* stress [MPa] or force [N], count values */
    double *w;             /* weights (> 0; 1 when the file has no weight column), count values */
    double *t;             /* time [s] when the file has a time column, else NULL */
    double y_to_file;      /* multiply y by this to get the file's own unit (1000 for kPa) */
    int compression;       /* 1 when the data lie at negative x (compression negative): some
                           ** x < 0 and none > 0 */
    int x_from_stretch;    /* 1 when the x column held stretch, converted to strain = stretch - 1 */
    char path[1024];       /* the file as named by the caller */
    char x_column[64];     /* header name of the x column */
    char y_column[64];     /* header name of the y column */
    char x_unit[16];       /* "-" for strain, "mm" for displacement after conversion */
    char y_unit[16];       /* the file's own unit of y ("kPa", "mN", ...), used in reports */
    cf_mode mode;          /* test mode (cell.h): the option, else a '# mode: NAME' comment, else
                           ** uniaxial */
    int mode_stated;       /* 1 when the option or the file named the mode */
    cf_table_measures measures; /* stress and strain measures as read; x and y hold engineering
                           ** strain and nominal stress after conversion */
} cf_table;

/* Reads the table at path ("-": standard input, named "(standard input)" in messages). Columns
** are separated by ',' ';' TAB or, when the header has none of them, by blanks. A message that
** points at a setting of opt names it "option FIELD" (option stress_unit, option x_col), which a
** front end maps to its own spelling. Errors (nothing allocated is left behind):
**   CF_E_NOINPUT  the file cannot be opened;
**   CF_E_DATA     missing header, unknown unit, a column not found, a non-numeric or non-finite
**                 cell, a short row, fewer than 6 data rows, an empty file, binary content, a
**                 weight <= 0; the message reads "PATH:LINE:COLUMN: what is wrong ('value')". */
cf_status cf_measure_load(const char *path, const cf_measure_options *opt, cf_table *m,
                          cf_error *err);

/* A table of count points copied from x, y and w (w NULL: every weight 1), for data made in
** code (tests, benchmarks, other front ends): the units are conifit's, y_unit "MPa" or "N",
** path and column names "x" and "y". CF_E_INTERNAL when memory runs out. */
cf_status cf_table_from_arrays(cf_table_kind kind, size_t count, const double *x, const double *y,
                               const double *w, cf_table *m, cf_error *err);

/* 1 for a force-displacement table, 0 for stress-strain. */
int cf_table_is_force(const cf_table *m);

/* The table's file name without folder and extension into out (cap bytes, cut to fit): the
** default title of its plots. */
void cf_table_name(const cf_table *m, char *out, size_t cap);

/* Releases the arrays of m (safe on a zeroed struct). */
void cf_table_free(cf_table *m);

#endif
