/*
** The identifiable quantities of a fit as the fit files write them: the single table's report
** (report.c) and the joint fit's (jointreport.c). Private to src/report/.
*/
#ifndef CF_REPORT_JSON_H
#define CF_REPORT_JSON_H

#include <jansson.h>

#include "fit/fit.h"

/* {value, stderr | stderr_reason, [interval, interval_reason, interval_limit]} of quantity k
** in conifit's units (MPa, N, mm): a key is present only with a value, never null. */
json_t *cf_report_ident_json(const cf_fit_result *f, int k);

/* {order: names, matrix} of the first n quantities when every correlation is determined, else
** {order, reason}. */
json_t *cf_report_correlation_json(const cf_fit_result *f, const char *const *names, int n);

#endif
