/*
** The types the stages of the table reader share with one another and with its callers (io/measure.c
** reads a table through csv.c, header.c, unitsrow.c, columns.c, measures.c and biaxial.c): the
** caller's options, what a unit measures, and a column of the header. A header of its own, so
** that every stage depends on these types and none on the reader that uses them.
*/
#ifndef CF_IO_TABLE_TYPES_H
#define CF_IO_TABLE_TYPES_H

#include <stddef.h>

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

/* What a unit measures. */
typedef enum cf_unit_class {
    CF_UNIT_UNKNOWN = 0,
    CF_UNIT_STRESS = 1, /* converted to MPa */
    CF_UNIT_FORCE = 2,  /* converted to N */
    CF_UNIT_LENGTH = 3, /* converted to mm */
    CF_UNIT_TIME = 4,   /* converted to s */
    CF_UNIT_STRAIN = 5  /* dimensionless: "-", "1" or "%" (converted to a plain fraction) */
} cf_unit_class;

/* Longest column name kept (longer names are an error: they are not column names). */
#define CF_COLUMN_NAME_CAP 256

/* A column of the header. */
typedef struct cf_column {
    char name[CF_COLUMN_NAME_CAP]; /* as in the header */
    char base[CF_COLUMN_NAME_CAP]; /* without the unit decoration */
    char unit[CF_COLUMN_NAME_CAP]; /* the decoration ("" when none), or the units row's */
    int unit_from_row;             /* 1 when unit came from the units row under the header */
} cf_column;

#endif
