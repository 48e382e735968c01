/*
** What a viscoelastic fit reports: the readable terminal text, the JSON fit file and the plot.
** The fit file keeps the layout of an elastic fit file (fits[] with type, params, derived,
** identifiable; better_type), so that every reader of springs takes it, and adds per fit the
** Prony terms, the dashpot, the moduli, the errors over ramp and hold and the predictions; the
** measured series and the model's curve are kept under "series". Written atomically, doubles to
** 17 significant digits, never a NaN or Inf.
*/
#ifndef CF_VISCOREPORT_H
#define CF_VISCOREPORT_H

#include "conifit/error.h"
#include "fit/fit.h"
#include "io/measure.h"
#include "conifit/output.h"
#include "fit/viscofit.h"

typedef struct cf_visco_report {
    const char *version;       /* conifit version */
    const cf_table *table;     /* the series (t not NULL; must outlive the report) */
    cf_visco_setup setup;      /* where the model was evaluated */
    cf_visco_fit fit;          /* the fit (owned: cf_visco_report_free) */
    int nplaced;               /* design springs placed from the identifiable quantities (1-2) */
    cf_fit_result placed[2];
    int with_timing;           /* 0: wall_time_s written as 0 (reproducible files) */
    const char *title;         /* of the plot; NULL: the table's file name without folder and
                                  extension */
} cf_visco_report;

/* Releases what the report owns. Safe on a zeroed report. */
void cf_visco_report_free(cf_visco_report *r);

/* The readable report (malloc'd; NULL when memory runs out). */
char *cf_visco_report_text(const cf_visco_report *r);

/* Writes the JSON to a temporary file beside path, complete but not in place (the caller commits
** or aborts *out); inputs (NULL-terminated, may be NULL) are refused as targets. */
cf_status cf_visco_report_json_prepare(const cf_visco_report *r, const char *path,
                                       const char *const *inputs, cf_output *out,
                                       cf_error *err);

/* Draws stress against time (data, model, residuals underneath) beside stress against strain,
** with gnuplot, to a temporary .png or .svg beside path (as cf_plot_fit: the caller commits or
** aborts *out). */
cf_status cf_visco_plot(const cf_visco_report *r, const char *path, const char *const *inputs,
                        cf_output *out, cf_error *err);

#endif
