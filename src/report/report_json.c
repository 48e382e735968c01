/*
** The identifiable quantities of a fit in its fit file: value, standard error or interval, and
** their correlation (see report_json.h).
*/
#include "report/report_json.h"
#include "fit/lawkind.h"

#include <math.h>

#include "io/fitfile_json.h"
#include "report/report_words.h"

#define num cf_json_number

/* Why a fit has no standard errors (and no correlation matrix), in words. */
static const char *stderr_reason(const cf_fit_result *f)
{
    const int nq = cf_fit_kind_of(f)->nq;
    for (int k = 0; k < nq; k++)
        if (f->interval_ok[k] && (f->interval_why[k] & CF_FIT_RANK_DEFICIENT))
            return nq == 3 ? "not determined: the Jacobian of the three quantities is "
                             "numerically rank-deficient (see interval)"
                 : nq == 4 ? "not determined: the Jacobian of the four quantities is singular "
                             "(see interval)"
                           : "not determined: the Jacobian of the fitted quantities is singular "
                             "(see interval)";
    return "not determined: the linearised covariance s^2 (J^T W J)^-1 could not be formed";
}

/* {value, stderr | stderr_reason, [interval, interval_reason]} in conifit's units (MPa, N, mm):
** a key is present only with a value, never null. */
/* o's interval, interval_reason and interval_limit for quantity k (report_words.h: k < 3 or
** CF_REPORT_TAIL), its interval [lo, hi] whose ends reached the limits end[2] (0: the data's). */
static void interval_json(json_t *o, const cf_fit_result *f, int k, const double iv[2],
                          const unsigned end[2])
{
    char why[512];
    cf_report_interval_reason(f, k, why, sizeof why);
    json_object_set_new(o, "interval", json_pack("[o, o]", num(iv[0]), num(iv[1])));
    json_object_set_new(o, "interval_reason", json_string(why));
    /* an end that is a limit, not the data's: the interval is one-sided there */
    json_t *lim = json_object();
    for (int e = 0; e < 2; e++) {
        unsigned b = end[e];
        if (b && lim)
            json_object_set_new(lim, e ? "upper" : "lower",
                                json_string(cf_fit_constraint_name(b & (0u - b))));
    }
    if (lim && json_object_size(lim) > 0)
        json_object_set_new(o, "interval_limit", lim);
    else
        json_decref(lim);
}

json_t *cf_report_ident_json(const cf_fit_result *f, int k)
{
    double se = f->q_se[k];
    json_t *o = json_pack("{s:o}", "value", num(f->q[k]));
    if (!o)
        return NULL;
    if (se >= 0)
        json_object_set_new(o, "stderr", num(se));
    else
        json_object_set_new(o, "stderr_reason",
                            json_string(k < CF_IDENT_COUNT ? stderr_reason(f)
                                                           : "the Jacobian of the fitted "
                                                             "quantities is singular"));
    if (cf_fit_kind_of(f) != &cf_law_conical_row && se > fabs(f->q[k]))
        json_object_set_new(o, "determined", json_false());
    if (f->interval_ok[k])
        interval_json(o, f, k, f->interval[k], f->interval_end[k]);
    return o;
}

/* {order, matrix} of the first n quantities (names) when every correlation is determined, else
** {order, reason}. */
json_t *cf_report_correlation_json(const cf_fit_result *f, const char *const *names, int n)
{
    json_t *order = json_array();
    for (int a = 0; a < n; a++)
        json_array_append_new(order, json_string(names[a]));
    json_t *o = json_pack("{s:o}", "order", order);
    int ok = 1;
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++)
            ok = ok && isfinite(f->corr[a][b]);
    if (!o)
        return NULL;
    if (!ok) {
        json_object_set_new(o, "reason", json_string(stderr_reason(f)));
        return o;
    }
    json_t *m = json_array();
    for (int a = 0; a < n; a++) {
        json_t *row = json_array();
        for (int b = 0; b < n; b++)
            json_array_append_new(row, num(f->corr[a][b]));
        json_array_append_new(m, row);
    }
    json_object_set_new(o, "matrix", m);
    return o;
}
