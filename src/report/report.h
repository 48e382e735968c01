/*
** What a fit reports: the readable terminal text and the JSON fit file (schema in fitfile.h,
** extended with the identifiable quantities, quality measures and baselines). The JSON is written
** atomically (conifit/output.h) with doubles to 17 significant digits and never a NaN or Inf.
*/
#ifndef CF_REPORT_H
#define CF_REPORT_H

#include <stddef.h>

#include "fit/baseline.h"
#include "conifit/error.h"
#include "fit/fit.h"
#include "io/measure.h"
#include "conifit/output.h"
#include "fit/softening.h"
#include "check/validate.h"

/* One table and its fits, as the report sees it (cf_pipeline_fit fills it). Values of the fits
** are in conifit's units (MPa or N); table->y_to_file converts them to the file's own unit for
** display and JSON. */
/* The law kinds fitted to one type (cf_fit_options.law conical-tail or auto, or the kinds a
** caller lists in cf_fit_options.kinds): each one's fit and AIC (n ln(RSS_w/n) + 2 k, k the
** kind's number of quantities, lawkind.h, on the weighted residuals), and the one kept in fits[]:
** the feasible one of lowest AIC, the conical law where no other is feasible and lower, or the
** one kind asked for. */
typedef struct cf_law_choice {
    int ran;                                /* 1: more than one kind was fitted */
    int n;                                  /* kinds fitted: cand[0] the conical law, then the
                                            ** others in the order asked */
    cf_fit_result cand[CF_LAW_KINDS_MAX];  /* their fits (cand[chosen] is fits[]'s) */
    double aic[CF_LAW_KINDS_MAX];
    int chosen;                             /* index of the one kept */
    int asked;                              /* 1: kept because it alone was asked for */
} cf_law_choice;

typedef struct cf_fit_report {
    const char *version;        /* conifit version */
    const cf_table *table;      /* the table fitted (not owned; outlives the report) */
    const char *title;          /* the figure's title; NULL: the table's name (its file name
                                ** without folder and extension) */
    cf_fit_options fit_options; /* the options the fits ran with (their limits are reported) */
    double ymax;                /* largest |y| in MPa or N */
    int nfits;                  /* 1 or 2 */
    cf_fit_result fits[2];
    cf_baseline baselines[CF_BASE_COUNT];
    int with_timing;            /* 0: write wall_time_s as 0 (for reproducible files) */
    int validate;               /* 1: each fit was run in the lattice (val[i]) */
    cf_validation val[2];       /* lattice validation of fits[i] (MPa; freed by cf_report_free) */
    int through_msm;            /* 1: each fit was refined through the lattice (thr[i]) */
    cf_through_msm thr[2];      /* what that cost and gained (MPa) */
    cf_softening softening;     /* where the table softens, which the law cannot follow */
    cf_limit_cost limit_cost[2]; /* what the limits holding fits[i] cost (checked when held) */
    cf_law_kind law;          /* the law kind asked for (fit.h) */
    cf_law_choice law_choice[2]; /* for fits[i], both laws (ran = 0 with the conical law alone) */
    /* The verdict on the two types, made once when the fit is made (cf_pipeline_fit) and read by
    ** every part of the report: with two fits cf_fit_compare's; with one, better 0 when its
    ** spring is feasible, else -1 (tie 0). */
    cf_fit_verdict verdict;
} cf_fit_report;

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

/* AIC of fit i, with RSS in the file's unit (comparable with the baselines' AIC of the report). */
double cf_report_fit_aic(const cf_fit_report *r, int i);
double cf_report_baseline_aic(const cf_fit_report *r, int k);

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
