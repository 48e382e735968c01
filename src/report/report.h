/*
** What a fit reports: the readable terminal text and the JSON fit file (schema in fitfile.h,
** extended with the identifiable quantities, quality measures and baselines). The JSON is written
** atomically (conifit/output.h) with doubles to 17 significant digits and never a NaN or Inf.
*/
#ifndef CF_REPORT_H
#define CF_REPORT_H

#include <stddef.h>

#include "conifit/error.h"
#include "conifit/output.h"
#include "io/measure.h"
#include "report/report_types.h"

/* Longest warning sentence, and the most a report states. */
#define CF_REPORT_WARNING_LEN 512
#define CF_REPORT_WARNINGS_MAX 12

/* The sentences saying what the model cannot follow in the table (softening, a design limit that
** costs fit quality), at most cap of them into out; returns how many. The text report lists them
** under "Warnings", the fit file as warnings[], the command line on standard error. */
int cf_report_warnings(const cf_fit_report *r, char (*out)[CF_REPORT_WARNING_LEN], int cap);

/* Releases what the report owns (the validations' curves). Safe on a zeroed report. */
void cf_report_free(cf_fit_report *r);

/* Makes r's verdict (above) from its fits; cf_pipeline_fit calls it last. */
void cf_report_settle(cf_fit_report *r);

/* Index of the better fit in r->fits: the feasible one with the lower objective (-1 if none);
** on a tie (cf_report_types_tie) this is the one a command uses, never one the report names. */
int cf_report_better(const cf_fit_report *r);

/* 1 when both types were fitted and the data cannot tell them apart (cf_fit_compare: F-test at
** 95 % on the residual sum of squares, floored at rounding level). */
int cf_report_types_tie(const cf_fit_report *r);

/* 1 when every fit's target is the lattice (each was fitted through it): then the fits' rss,
** rmse, max_abs_error, r2, objective and uncertainty are the lattice's (lattice_fit.h), and so
** are the verdict, the comparison and the better type; 0: the single spring's. */
int cf_report_target_is_lattice(const cf_fit_report *r);

/* AIC of fit i, with RSS in the file's unit (comparable with the baselines' AIC of the report,
** cf_report_baseline_aic in report_baselines.h). */
double cf_report_fit_aic(const cf_fit_report *r, int i);

/* The JSON document as a string (malloc'd; caller frees). NULL when memory runs out. */
char *cf_report_json_string(const cf_fit_report *r);

/* Writes the JSON to a temporary file beside path, complete but not yet in place, held by out
** (conifit/output.h): the caller commits it together with its other outputs, or aborts it.
** CF_E_USAGE when r, path or out is NULL or out still holds a file; other errors as below. */
cf_status cf_report_json_prepare(const cf_fit_report *r, const char *path,
                                 const char *const *inputs, cf_output *out, cf_error *err);

/* Writes the JSON to path atomically; `inputs` (NULL-terminated, may be NULL) are refused as
** targets. CF_E_CANTWRITE on failure (no file left behind). */
cf_status cf_report_json_write(const cf_fit_report *r, const char *path,
                               const char *const *inputs, cf_error *err);

/* The readable report (malloc'd string; caller frees); NULL when memory runs out. */
char *cf_report_text(const cf_fit_report *r);

#endif
