/*
** What a biaxial or a fibre-frame table states beyond its columns (biaxial.c): the ratio of a
** biaxial test's strains ('# ratio: A:B') and the plane of a test in the fibre frame
** ('# plane: ij', or the caller's option plane). Used by the reader (measure.c).
*/
#ifndef CF_IO_BIAXIAL_H
#define CF_IO_BIAXIAL_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/csv.h"
#include "io/reader.h"
#include "io/table_types.h"
#include "model/table.h"

/* The '# ratio: A:B' comment (A, B > 0 finite; spaces allowed; text after B ignored) into
** m->ratio and m->ratio_line. CF_E_DATA naming the file, line and column for a value that is not
** two positive numbers, and naming the file when a biaxial table has no such comment. */
cf_status cf_comment_ratio(const cf_csv_line *comments, size_t ncomments, const char *path,
                           cf_table *m, cf_error *err);

/* 0 when text (n bytes) is a plane "ij": two different letters of f, s, n; -1 otherwise. */
int cf_plane_parse(const char *text, size_t n, char plane[3]);

/* The plane of m: the entry of planes (the caller's option: "ij" for every table, or a comma
** list of NAME=ij, NAME the table's file name without folder and extension) for m, else its
** '# plane: ij' comment, else none. A plane for every table leaves the tables of other modes
** alone. CF_E_DATA (naming the file and line, or the option) for a plane that is not two of f,
** s, n, or a plane named for a table (NAME=ij, or its comment) whose mode is neither shear nor
** biaxial. */
cf_status cf_table_plane(const cf_csv_line *comments, size_t ncomments, const char *planes,
                         cf_table *m, cf_error *err);

/* What a first reading of a table adds from its comments (the reader r and layout h alive): the
** plane (cf_table_plane), and for a biaxial table its ratio (cf_comment_ratio) and its second
** direction's columns as "X,Y" (1-based numbers) into pair: the first strain and the first stress
** column after the first direction's. CF_E_DATA naming the file (and header line) for a biaxial
** table on standard input (read twice) or without a second pair. pair "" for other tables. */
cf_status cf_biaxial_frame(const reader *r, const layout *h, const cf_measure_options *opt,
                           cf_table *m, char *pair, size_t cap, cf_error *err);

/* Appends b's rows (the second direction, read with pair's columns; its rows' lines in lines) to
** m's (table.h: m->second, m->count doubled, x2/y2 names), after checking that they are the same
** load steps at m's ratio (1e-9 relative; CF_E_DATA naming the file, line and column), in the
** same unit and measures. CF_E_INTERNAL when memory runs out. */
cf_status cf_biaxial_stack(cf_table *m, const cf_table *b, const size_t *lines, const char *pair,
                           cf_error *err);

#endif
