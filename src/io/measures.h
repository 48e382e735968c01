/*
** Stress and strain measures of a table (table.h, measure.h): their names and words
** (cf_stress_measure_name, cf_stress_measure_parse, ...), which reports and the command line use
** too; and, for the table reader, what the file, its column names and the caller's options say,
** reconciled, and the conversion, for the table's test mode, to the engineering strain and
** nominal stress the law models.
*/
#ifndef CF_IO_MEASURES_H
#define CF_IO_MEASURES_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/csv.h"
#include "io/table_types.h"
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

/* 1 when word occurs in s, letter case ignored. */
int cf_measures_contains_ci(const char *s, const char *word);

/* The stress and strain measures of a table: the caller's options, the '# stress:' and
** '# strain:' comments and the names of the x and y columns, reconciled. CF_E_DATA naming the
** line for a declaration of no known measure, two declarations that differ, or a declaration
** that the column's name contradicts when no option settles it. */
cf_status cf_measures_read(const cf_csv_line *comments, size_t ncomments, const char *path,
                           const cf_measure_options *opt, const cf_column *xc, const cf_column *yc,
                           cf_table_measures *out, cf_error *err);

/* Converts t's x to engineering strain and its y to nominal stress, as t->measures says (x is
** already stretch - 1 for a stretch column). CF_E_DATA, naming the file and the measure, for a
** combination that has no meaning (log strain or stretch of simple shear, a Cauchy force, a
** stretch <= 0). */
cf_status cf_measures_convert(cf_table *t, cf_error *err);

#endif
