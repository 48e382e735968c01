/*
** A measured table in conifit's units (MPa, N, mm, s): the one type that goes from the reader
** (measure.h) through the fit, the validation, the report and the plots. Its x column holds
** engineering strain or displacement, its y column nominal stress or force; the stress and
** strain measures record what the source said and what was converted to reach them.
*/
#ifndef CF_TABLE_H
#define CF_TABLE_H

#include <stddef.h>

#include "model/cell.h"
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

/* A measured table in conifit's units. The reader fills every field; a table built in code
** (cf_table_from_arrays) has the fields that function names, no time column, the uniaxial mode
** (not stated) and zeroed measures (nominal stress, engineering strain, assumed). */
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
    /* A biaxial table (mode CF_MODE_BIAXIAL) holds both loaded directions as one table: rows
    ** 0 .. second - 1 are the first direction (its strain in x, its stress in y), rows second ..
    ** count - 1 the second direction at the same load steps (its own strain and stress), so
    ** count = 2 * second; ratio[0]:ratio[1] is the ratio of the strains (first:second, as its
    ** '# ratio:' comment states it, on line ratio_line), each row's strain along the other
    ** direction being its own times ratio[1]/ratio[0] or ratio[0]/ratio[1]. second 0 and ratio
    ** 0 for every other table. */
    size_t second;
    double ratio[2];
    size_t ratio_line;
    char x2_column[64];    /* header names of the second direction's strain and stress */
    char y2_column[64];
    /* Where the test lies in a fibre frame (f fibre, s sheet, n sheet-normal), from a
    ** '# plane:' comment or the caller's option: a shear table's "ij" (i the normal of the
    ** sheared face, j the direction of shear, as Sommer et al. 2015 name their modes), a biaxial
    ** table's "ij" (the axes of its first and second direction); "" when not stated. */
    char plane[3];
    size_t plane_line;     /* the comment's line, 0 when from an option or not stated */
    cf_table_measures measures; /* stress and strain measures as read; x and y hold engineering
                           ** strain and nominal stress after conversion */
    char notes[768];       /* what the reader noticed and a front end should show: one note a
                           ** line (a skipped preamble, a unit taken from the units row under the
                           ** header or read in another letter case, a strain column that looks
                           ** like stretch); "" when none. The reports keep them (notes[]). */
} cf_table;

/* A table of count points copied from x, y and w (w NULL: every weight 1), for data made in
** code (tests, benchmarks, other front ends): the units are conifit's (x_unit "-" or "mm", y_unit
** "MPa" or "N", y_to_file 1), the path "(table in memory)", the column names "x" and "y", and the
** compression flag set as the reader sets it. CF_E_INTERNAL when memory runs out. */
cf_status cf_table_from_arrays(cf_table_kind kind, size_t count, const double *x, const double *y,
                               const double *w, cf_table *m, cf_error *err);

/* Row i of a biaxial table: the strain along the other in-plane direction per unit of the row's
** own (ratio[1]/ratio[0] in the first direction, ratio[0]/ratio[1] in the second); 1 for every
** row of any other table. */
double cf_table_biaxial_k(const cf_table *m, size_t i);

/* The homogenised cell's stress (MPa, table sign) at every row of m in m's mode: a biaxial
** table's rows each along their own direction with the other at the ratio (cell.h: the cubic
** cell's x stands for either direction). Stops at the first failure, as cf_cell_curve. */
cf_status cf_table_cell_curve(const cf_cell *c, const cf_table *m, double *out, cf_error *err);

/* 1 for a force-displacement table, 0 for stress-strain. */
int cf_table_is_force(const cf_table *m);

/* The table's file name without folder and extension into out (cap bytes, cut to fit): the
** default title of its plots. */
void cf_table_name(const cf_table *m, char *out, size_t cap);

/* Releases the arrays of m (safe on a zeroed struct). */
void cf_table_free(cf_table *m);

#endif
