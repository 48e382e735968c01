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
#include "conifit/fit.h"
#include "conifit/viscofit.h"

typedef struct cf_visco_report {
    const char *version;       /* conifit version */
    const char *data_file;     /* the table as named by the user */
    const char *t_column, *x_column, *y_column, *y_unit; /* header names, the file's stress unit */
    double y_to_file;          /* multiply MPa by this for the file's unit */
    int compression;           /* 1: the table is compression-negative */
    const cf_visco_data *data; /* the series (conifit's units) */
    const cf_visco_fit *fit;   /* the fit */
    const cf_visco_setup *setup; /* where it was evaluated */
    int nplaced;               /* design springs placed from the identifiable quantities (1-2) */
    cf_fit_result placed[2];
    int with_timing;           /* 0: wall_time_s written as 0 (reproducible files) */
} cf_visco_report;

/* The readable report (malloc'd; NULL when memory runs out). */
char *cf_visco_report_text(const cf_visco_report *r);

/* The JSON fit file as a string (malloc'd; NULL when memory runs out). */
char *cf_visco_report_json_string(const cf_visco_report *r);

/* Writes the JSON atomically to path; inputs (NULL-terminated, may be NULL) are refused as
** targets. CF_E_CANTWRITE on failure (nothing left behind). */
cf_status cf_visco_report_json_write(const cf_visco_report *r, const char *path,
                                     const char *const *inputs, cf_error *err);

/* Draws stress against time (data, model, residuals underneath) beside stress against strain,
** with gnuplot, to a .png or .svg (errors as cf_plot_write). */
cf_status cf_visco_plot_write(const cf_visco_report *r, const char *path,
                              const char *const *inputs, cf_error *err);

#endif
