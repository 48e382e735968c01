/*
** Fitting a table, behind an opaque handle: the call behind `conifit fit TABLE` for a program.
** A stress-strain or force-displacement table (a file conifit fit reads) goes in; the handle
** holds its fits, one per spring type, which the accessors below read, and writes the fit file
** (the document `conifit fit TABLE -o FILE` writes) through an output handle (conifit/output.h).
**
**   cf_tablefit_options o = cf_tablefit_default_options();
**   cf_tablefit *f = NULL;
**   if (cf_tablefit_run("tissue.csv", &o, &f, &err) == CF_OK) {
**       int i = cf_tablefit_better(f);
**       printf("rho = %g\n", cf_tablefit_quantity(f, i, "rho", NULL));
**       ... cf_tablefit_prepare(f, "tissue.json", out, &err), then cf_output_commit(out, &err)
**   }
**   cf_tablefit_free(f);
**
** Units: the spring in mm and MPa (conifit/spring.h); the identifiable quantities in conifit's
** units (stress in MPa, force in N, as cf_tablefit_quantity_unit names them), the RMSE in the
** table's own unit (cf_tablefit_y_unit), as the fit file writes them. One handle belongs to one
** thread at a time; handles are independent.
*/
#ifndef CF_TABLEFIT_H
#define CF_TABLEFIT_H

#include "conifit/error.h"
#include "conifit/output.h"
#include "conifit/spring.h"

typedef struct cf_tablefit cf_tablefit;

/* Spring types to fit, as bits of cf_tablefit_options.types. */
enum {
    CF_TABLEFIT_TELESCOPING = 1 << CF_TELESCOPING,
    CF_TABLEFIT_NON_TELESCOPING = 1 << CF_NON_TELESCOPING,
    CF_TABLEFIT_BOTH = CF_TABLEFIT_TELESCOPING | CF_TABLEFIT_NON_TELESCOPING
};

typedef struct cf_tablefit_options {
    unsigned types;   /* CF_TABLEFIT_* bits (default both) */
    const char *law;  /* the law kind, as conifit fit --law names it ("conical", "conical-tail",
                      ** "auto"); NULL: the default, the conical law. "double-acting" (an
                      ** element fitted through the lattice, conifit fit's joint fit) is
                      ** refused: CF_E_DATA with conifit fit's message when the table cannot
                      ** determine both springs, CF_E_USAGE when it can */
    int validate;     /* 1: run each fit in the default lattice (conifit fit --validate) */
    int with_timing;  /* 0 (default): wall times written as 0, so fit files are reproducible */
} cf_tablefit_options;

/* Both types, the conical law, no validation, no timing. */
cf_tablefit_options cf_tablefit_default_options(void);

/* Reads the table at table_path and fits it with opt (NULL: the defaults); *out receives the
** handle (release with cf_tablefit_free), NULL on failure. A time series (a table with a time
** column) is refused with CF_E_DATA: conifit fit fits those. Errors as conifit fit's: the file,
** line, column or key and the value; CF_E_USAGE for a NULL path or out, or an unknown law or
** type bit. */
cf_status cf_tablefit_run(const char *table_path, const cf_tablefit_options *opt,
                          cf_tablefit **out, cf_error *err);

/* The number of fits (one per type fitted: 1 or 2); 0 for NULL. */
int cf_tablefit_count(const cf_tablefit *f);

/* Index of the better fit (the feasible one of lower objective), -1 if neither is feasible. */
int cf_tablefit_better(const cf_tablefit *f);

/* Fit i's spring type (CF_SPRING_TYPE_NONE for a bad i, never a type), and its spring (NULL for
** a bad i). */
cf_spring_type cf_tablefit_type(const cf_tablefit *f, int i);
const cf_spring *cf_tablefit_spring(const cf_tablefit *f, int i);

/* Fit i's law kind ("conical", "conical-tail", ...; NULL for a bad i). */
const char *cf_tablefit_law(const cf_tablefit *f, int i);

/* Fit i's root mean square residual in the table's own unit; NaN for a bad i. */
double cf_tablefit_rmse(const cf_tablefit *f, int i);

/* The table's own unit of stress or force ("kPa", "N", ...). */
const char *cf_tablefit_y_unit(const cf_tablefit *f);

/* The identifiable quantities of fit i: how many, and the fit-file key of the k-th ("rho",
** "solid_strain", "stress_scale_MPa", ...; NULL for a bad i or k). */
int cf_tablefit_quantity_count(const cf_tablefit *f, int i);
const char *cf_tablefit_quantity_key(const cf_tablefit *f, int i, int k);

/* The unit of the quantity called key ("" dimensionless, "mm", "MPa", "N"); NULL when fit i has
** no such quantity. */
const char *cf_tablefit_quantity_unit(const cf_tablefit *f, int i, const char *key);

/* The value of the quantity of fit i called key, and (when se is not NULL) its standard error,
** -1 when the fit could not determine it. NaN (and *se = -1) when fit i has no such quantity. */
double cf_tablefit_quantity(const cf_tablefit *f, int i, const char *key, double *se);

/* Writes the fit file of every fit to path as a complete temporary beside it, held by out: the
** caller commits it (cf_output_commit) or aborts it. The table itself is refused as the target.
** CF_E_USAGE when f, path or out is NULL or out still holds a file; CF_E_CANTWRITE otherwise. */
cf_status cf_tablefit_prepare(const cf_tablefit *f, const char *path, cf_output *out,
                              cf_error *err);

/* Releases the handle; NULL is ignored. */
void cf_tablefit_free(cf_tablefit *f);

#endif
