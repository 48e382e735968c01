/*
** Least-squares pieces shared by the fitter and the validation (see lsq.h).
*/
#include "fit/lsq.h"

#include <math.h>

#include <gsl/gsl_cdf.h>

double cf_lsq_weights(const cf_table *t, int relative, double *sw)
{
    double ymax = 0, norm = 0;
    for (size_t i = 0; i < t->count; i++)
        ymax = fmax(ymax, fabs(t->y[i]));
    for (size_t i = 0; i < t->count; i++) {
        double sc = relative ? fmax(fabs(t->y[i]), CF_LSQ_REL_FLOOR * ymax) : 1.0;
        sw[i] = sqrt(t->w ? t->w[i] : 1.0) / sc;
        norm += (sw[i] * t->y[i]) * (sw[i] * t->y[i]);
    }
    return norm;
}

cf_lsq_quality cf_lsq_quality_of(const cf_table *t, const double *model)
{
    cf_lsq_quality q = {0, 0, 0, 0};
    if (t->count == 0)
        return q;
    double ym = 0, syy = 0;
    for (size_t i = 0; i < t->count; i++)
        ym += t->y[i];
    ym /= (double)t->count;
    for (size_t i = 0; i < t->count; i++) {
        double r = model[i] - t->y[i];
        q.rss += r * r;
        q.max_abs_error = fmax(q.max_abs_error, fabs(r));
        syy += (t->y[i] - ym) * (t->y[i] - ym);
    }
    q.rmse = sqrt(q.rss / (double)t->count);
    q.r2 = syy > 0 ? 1 - q.rss / syy : 0;
    return q;
}

double cf_lsq_xmax(const cf_table *t)
{
    double m = 0;
    for (size_t i = 0; i < t->count; i++)
        m = fmax(m, fabs(t->x[i]));
    return m;
}

double cf_lsq_f95(double dof)
{
    double f = gsl_cdf_fdist_Pinv(0.95, 1.0, dof);
    if (isfinite(f) && f > 0)
        return f;
    double t = gsl_cdf_tdist_Pinv(0.975, dof);
    return t * t;
}
