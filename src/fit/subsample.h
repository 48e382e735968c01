/*
** A deterministic subsample of a long table for the global stages of a fit (fit.c, baseline.c):
** the searches that evaluate the model thousands of times run on it, and the local polish that
** follows runs on every row, so that a fit's cost grows linearly in the rows with a small slope.
** Private to the library.
*/
#ifndef CF_FIT_SUBSAMPLE_H
#define CF_FIT_SUBSAMPLE_H

#include <stddef.h>

#include "conifit/error.h"
#include "io/measure.h"

/* Rows kept by cf_subsample (at most). */
#define CF_SUBSAMPLE_ROWS 1000

/* Fills out with at most `rows` (>= 8) rows of t chosen evenly along x: the range of x is cut into
** bins of equal width and each bin that holds rows gives one, the row nearest its centre, with
** weight the sum of the weights of the bin's rows, so that a weighted sum of squares over the
** subsample approximates that over the table. The rows of the smallest and largest x and of the
** largest |y| are always kept (each represents its bin), so the subsample has the table's range
** and scale. The kind of t is kept; one pass over t, memory O(rows). CF_E_INTERNAL when memory
** runs out (out is then empty). Release with cf_table_free. */
cf_status cf_subsample(const cf_table *t, size_t rows, cf_table *out, cf_error *err);

#endif
