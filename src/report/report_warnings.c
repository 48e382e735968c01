/*
** What the model cannot follow in a table, as sentences the text report, the fit file
** (warnings[]) and the command line's standard error share (report.h, cf_report_warnings).
*/
#include <stdio.h>

#include "conifit/report.h"

/* The table softens: the conical law only stiffens. */
static int softening_warning(const cf_fit_report *r, char *buf, size_t cap)
{
    const cf_softening *s = &r->softening;
    if (!s->found)
        return 0;
    snprintf(buf, cap,
             "the table softens (its curve is concave) from %s %.4g to %.4g, %.0f %% of its "
             "range: the conical law only stiffens with strain and cannot follow that part (it "
             "settles on a compromise through it)",
             cf_table_is_force(r->table) ? "displacement" : "strain", s->from, s->to,
             100 * s->share);
    return 1;
}

int cf_report_warnings(const cf_fit_report *r, char (*out)[CF_REPORT_WARNING_LEN], int cap)
{
    int n = 0;
    if (n < cap)
        n += softening_warning(r, out[n], CF_REPORT_WARNING_LEN);
    return n;
}
