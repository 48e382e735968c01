/*
** Column names and units, for the table reader (io/measure.c): the catalogue of units (a unit's
** class and factor, cf_measure_unit, which the command line and the prediction use too), a header
** name split into its name and its unit decoration, which names mark x, y, a weight or a time, and
** what the file's '#' comments state (a column's unit, the test mode).
*/
#ifndef CF_IO_COLUMNS_H
#define CF_IO_COLUMNS_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/csv.h"
#include "io/table_types.h"
#include "model/mode.h"

/* A unit as a file may spell it: its class and the factor to conifit's units. */
typedef struct cf_unit_def {
    const char *name;
    cf_unit_class cls;
    double to_conifit;
    const char *canon; /* spelling used in reports */
} cf_unit_def;

/* Looks up a unit name ("kPa", "MPa", "N/mm2", "mN", "um", "%", "mm/mm", ...; letter case is
** ignored except in a leading m or M, so "Mpa" is MPa and "mPa" is not a unit). Returns
** CF_UNIT_UNKNOWN for a name it does not know; otherwise the class, and in *to_conifit (if not
** NULL) the factor that converts a value in that unit to conifit's (MPa, N, mm, s, -). */
cf_unit_class cf_measure_unit(const char *name, double *to_conifit);

/* The unit spelled name, or NULL: letter case is ignored except for a leading m or M (milli or
** metre against mega), so "Mpa" and "kpa" are found and "mPa" is not MPa. */
const cf_unit_def *cf_unit_find(const char *name);

/* The known unit that name spells but for the case of a leading m or M ("mPa", "MN"), which
** cf_unit_find does not take; NULL when there is none. For messages that name both readings. */
const cf_unit_def *cf_unit_m_case(const char *name);

/* The known units by class, for messages. */
extern const char cf_unit_list[];

/* Splits a header name into base and unit: "stress [kPa]", "stress (kPa)", "stress_kPa". A
** suffix after the last '_' is a unit only when it is one (so "true_strain" stays a name) or
** looks like one written in the wrong case ("stress_kpa", reported as an unknown unit). */
void cf_column_parse(cf_column *c, const char *name);

/* 1 when a base name starts like that of an x column: strain, stretch, lambda, displacement,
** elongation, gamma, shear, log_strain, true_strain, hencky or the letter lambda (letter case
** ignored). */
int cf_column_is_x(const char *b);

/* What a base name says its column holds: CF_UNIT_STRESS when it contains "stress" or starts
** with "cauchy", CF_UNIT_FORCE when it starts with "load" or contains "force", else
** CF_UNIT_UNKNOWN (letter case ignored). */
cf_unit_class cf_column_y_class(const char *b);

/* 1 when a base name starts with stress, force, load, cauchy or true_stress (letter case
** ignored). */
int cf_column_is_y(const char *b);

/* 1 for the base names weight and weights, and time and t (letter case ignored). */
int cf_column_is_weight(const char *b);
int cf_column_is_time(const char *b);

/* The unit the '#' comments state for the column with base name `name`, of one of the nwant
** classes in want: first a comment naming the column with a bracketed unit after it, else a list
** of units for "(x, y)" at place `which` (0: x, 1: y); NULL when no comment states one. */
const cf_unit_def *cf_comment_unit(const cf_csv_line *comments, size_t ncomments,
                                   const char *name, int which, const cf_unit_class *want,
                                   size_t nwant);

/* Finds the comment "mode: NAME" (spaces allowed around the words; text after NAME ignored) and
** parses NAME. Returns CF_OK with *found = 0 when no comment states a mode. */
cf_status cf_comment_mode(const cf_csv_line *comments, size_t ncomments, const char *path,
                          cf_mode *mode, int *found, cf_error *err);

#endif
