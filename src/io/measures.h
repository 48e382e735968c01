/*
** Stress and strain measures of a table (measure.h): the '# stress:' and '# strain:'
** declarations, the measures that column names state, how the file, its columns and the caller's
** options are reconciled, and the conversion, for the table's test mode, to the engineering strain
** and nominal stress the law models. Private to the table reader.
*/
#ifndef CF_IO_MEASURES_H
#define CF_IO_MEASURES_H

#include <stddef.h>

#include "conifit/error.h"
#include "conifit/measure.h"
#include "io/columns.h"
#include "io/csv.h"

/* What a declaration declares. */
enum { CF_DECL_STRESS = 0, CF_DECL_STRAIN = 1, CF_DECL_KINDS = 2 };

/* Names of the values of each kind, in the order of their enums. */
extern const char *const cf_measures_names[CF_DECL_KINDS][3];

/* One comment line (without its '#'): 1 when it is a declaration "stress: WORD" or "strain: WORD"
** (key case-insensitive, at the start of the comment), with *kind and the word copied to word
** (at most cap - 1 characters); 0 otherwise. (The '# mode:' comment is read with the mode.) */
int cf_measures_declaration(const char *s, size_t n, int *kind, char *word, size_t cap);

/* 1 when word occurs in s, letter case ignored. */
int cf_measures_contains_ci(const char *s, const char *word);

/* The measure a column's name states, or -1: y names true_stress, cauchy..., nominal_stress,
** pk1...; x names log_strain, true_strain, hencky..., stretch, lambda, engineering_strain. */
int cf_measures_stress_of_column(const char *name);
int cf_measures_strain_of_column(const char *name);

/* What the file says about one quantity: from a declaration (line > 0) and/or a column (-1: it
** says nothing). */
typedef struct cf_measures_said {
    int declared;       /* value of the declaration, -1: none */
    size_t line;        /* its line */
    int column;         /* value stated by the column's name, -1: none */
} cf_measures_said;

/* Decides one quantity: the option (>= 0) wins over the file; a declaration and a column name
** that disagree are an error (CF_E_DATA naming the file, the line and the column); nothing said
** gives fallback, marked assumed. `what` names the quantity in messages ("stress measure"),
** names[] the values. */
cf_status cf_measures_decide(const char *path, const char *column, const char *what,
                             const char *const *names, int option, const cf_measures_said *said,
                             int fallback, int *value, cf_decl_source *from, size_t *line,
                             int *overridden, int *file_value, cf_error *err);

/* The stress and strain measures of a table: the caller's options, the '# stress:' and
** '# strain:' comments and the names of the x and y columns, reconciled (a declaration that
** names no measure, or two that disagree, is an error naming the comment's line). */
cf_status cf_measures_read(const cf_csv_line *comments, size_t ncomments, const char *path,
                           const cf_measure_options *opt, const cf_column *xc, const cf_column *yc,
                           cf_table_measures *out, cf_error *err);

/* Converts t's x to engineering strain and its y to nominal stress, as t->measures says (x is
** already stretch - 1 for a stretch column). CF_E_DATA, naming the file and the measure, for a
** combination that has no meaning (log strain or stretch of simple shear, a Cauchy force, a
** stretch <= 0). */
cf_status cf_measures_convert(cf_table *t, cf_error *err);

#endif
