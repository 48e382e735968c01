/*
** The sentences a fit report states both in its text (report_text.c) and in its JSON fit file
** (report.c). Private to src/report/.
*/
#ifndef CF_REPORT_WORDS_H
#define CF_REPORT_WORDS_H

#include <stddef.h>

#include "report/report_types.h"

/* Appends printf-formatted text to buf (capacity cap, *n bytes used), never past its end. */
void cf_report_append(char *buf, size_t cap, size_t *n, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* note when it says something, else fallback: a reason printed or written is never empty. */
const char *cf_report_why(const char *note, const char *fallback);

/* The index of the tailed law's fourth quantity, its tail compliance e_t, where the two below
** take the quantity k (0, 1, 2 the identifiable quantities). */
#define CF_REPORT_TAIL CF_Q_TAIL

/* Why fit f's profile interval of quantity k was computed and where its ends come from. */
void cf_report_interval_reason(const cf_fit_result *f, int k, char *buf, size_t cap);

/* Quantity k of fit f (times scale, in unit) with its standard error, "value ± se", or its
** profile interval, "value [low, high]*" (the digits that tell the ends from the value). */
void cf_report_ident_cell(const cf_fit_result *f, int k, double scale, const char *unit,
                          char *cell, size_t cap);

/* The one sentence that compares the two types (both fitted, at least one feasible). */
void cf_report_verdict(const cf_fit_report *r, char *buf, size_t cap);

/* Why a conical-tail fit f of report r has no tail (it is the conical optimum it contains:
** fit.h, nested_rmse), in one sentence; "" for any other fit. */
void cf_report_nested(const cf_fit_report *r, const cf_fit_result *f, char *buf, size_t cap);

/* Where table t's stress and strain measures and its mode came from, one phrase each. */
void cf_report_sources(const cf_table *t, char src[3][128]);

/* The strain measure of table t as fitted, in words: "shear strain gamma" in simple shear (the
** amount of shear, of either sign), else the measure's name; *src set to what said so (src[1] of
** cf_report_sources, or the mode for shear). */
const char *cf_report_strain_name(const cf_table *t, char src[3][128]);

/* Why a mode stated for a force-displacement table is not honoured, or NULL when it is (none
** stated, or uniaxial). */
const char *cf_report_mode_dropped(const cf_table *t);

/* What was done to the stress and strain columns, in one sentence ("" when nothing). */
void cf_report_conversion(const cf_table *t, char *buf, size_t cap);

#endif
