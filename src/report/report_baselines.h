/*
** How a fit report states its baselines (baseline.h), in the text (report_text.c) and in the fit
** file's baselines[] (report.c): the coefficients with their names and units, and their AIC.
** Private to src/report/ (and its tests).
*/
#ifndef CF_REPORT_BASELINES_H
#define CF_REPORT_BASELINES_H

#include <stddef.h>
#include <stdio.h>

#include <jansson.h>

#include "report/report_types.h"

/* Baseline k's coefficients as "C1 = 0.1, C2 = 2, C3 = -3 kPa" (values in the file's unit; the
** unit after each run of coefficients in it). */
void cf_report_baseline_coefficients(const cf_fit_report *r, int k, char *buf, size_t cap);

/* AIC of baseline k of r, with RSS in the file's unit (comparable with cf_report_fit_aic). */
double cf_report_baseline_aic(const cf_fit_report *r, int k);

/* Baseline k as the fit file's object: model, formula (the Yeoh and Ogden ones with their
** form, the table's mode), parameters and, when fitted, coefficients, rmse and aic; when not,
** reason. NULL when memory runs out. */
json_t *cf_report_baseline_json(const cf_fit_report *r, int k);

/* The joint report's Holzapfel-Ogden baselines (r->ho, r->ho_why) as text into o, beside the
** weighted objective of the lattice r->fits[better] (cf_joint_better; none when out of range);
** nothing when no table is biaxial. */
void cf_report_ho_text(FILE *o, const cf_joint_report *r, int better);

/* The same as the fit file's object (NULL when they were not fitted or memory runs out). */
json_t *cf_report_ho_json(const cf_joint_report *r);

#endif
