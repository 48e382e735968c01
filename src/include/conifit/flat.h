/*
** Flat calls: the common paths of the library behind arguments of plain C types (numbers,
** strings, arrays), for callers that cannot use conifit's structures, such as a foreign-function
** interface (the Python module src/python/conifit.py uses these alone). Each returns a cf_status
** and, on failure, leaves a message in err (err may be NULL); NULL or malformed arguments are
** refused with CF_E_USAGE or CF_E_DATA, never a crash. Text and arrays handed back are malloc'd:
** release them with cf_flat_free.
*/
#ifndef CF_FLAT_H
#define CF_FLAT_H

#include <stddef.h>

#include "conifit/error.h"

/* The force F_N[i] (N) and, when k_N_per_mm is not NULL, the tangent stiffness (N/mm) at each of
** count compressions u_mm[i] (mm, > 0 shortens) of the spring spring[0..5] = D1 (mm), D2 (mm), n,
** d (mm), G (MPa), H (mm), with the evaluator named by method ("exact", "closed",
** "closed+newton", "table"; NULL: "closed"). A displacement that is not a finite number is refused
** (CF_E_DATA naming its index), as is a spring cf_law_init refuses. */
cf_status cf_flat_force(const double spring[6], const char *method, size_t count,
                        const double *u_mm, double *F_N, double *k_N_per_mm, cf_error *err);

/* The same for a spring with a cylindrical tail: spring[0..7] = D1, D2, n, d, G, H, n_tail and
** H_tail (mm); n_tail = H_tail = 0 is the plain spring of cf_flat_force. */
cf_status cf_flat_force_tail(const double spring[8], const char *method, size_t count,
                             const double *u_mm, double *F_N, double *k_N_per_mm, cf_error *err);

/* Fits the stress-strain (or force-displacement) table at table_path as `conifit fit` does: the
** types named by type ("telescoping", "non-telescoping", "both"; NULL: both), run in the default
** lattice when validate is 1. *json receives the fit file's text (the document conifit fit -o
** writes). A time series (a table with a time column) is refused: conifit fit handles those. */
cf_status cf_flat_fit(const char *table_path, const char *type, int validate, char **json,
                      cf_error *err);

/* Runs the scene at scene_path (a scene file, as conifit simulate reads it), refused with CF_E_DATA
** when its estimated memory, steps or work exceed conifit simulate's default budget. Lattice
** scenes only: a scene with a tissue body (key 'body') is refused with CF_E_USAGE, a message
** saying so (conifit simulate runs it).
** *samples receives *count rows of CF_FLAT_SAMPLE_COLUMNS numbers, the columns of conifit
** simulate's CSV: time (s), compressive strain, compressive nominal stress (kPa), kinetic energy (mJ), one spring's
** F(strain H)/H^2 (kPa), stable (1 up to the first sample whose tangent had a negative pivot,
** 0 from there on, -1 in explicit dynamics) and the lateral stretch (the width along x over the
** rest width). */
enum { CF_FLAT_SAMPLE_COLUMNS = 7 };
cf_status cf_flat_simulate(const char *scene_path, double **samples, size_t *count,
                           cf_error *err);

/* Writes the spring of the fit file (or exported spring) at fit_path, of the type named by type
** (NULL: the better fit), in the format named by format (as conifit export --format), with table
** tolerance tol (fraction of F_C; 0: the default) into *text. A double-acting element is written
** whole (its table's u < 0 side the extension spring's), as conifit export writes it. */
cf_status cf_flat_export(const char *fit_path, const char *type, const char *format, double tol,
                         char **text, cf_error *err);

/* Releases what a flat call handed back; NULL is ignored. */
void cf_flat_free(void *p);

#endif
