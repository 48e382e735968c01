/*
** Least-squares pieces shared by the fitter and the validation (see lsq.h).
*/
#include "fit/lsq.h"

#include <math.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

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

int cf_lsq_covariance(double jtj[3][3], double rss, size_t n, double se[3],
                      double corr[3][3])
{
    se[0] = se[1] = se[2] = -1;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            corr[a][b] = NAN;
    if (n <= 3)
        return 1;
    gsl_matrix *M = gsl_matrix_alloc(3, 3), *E = gsl_matrix_alloc(3, 3);
    gsl_vector *ev = gsl_vector_alloc(3);
    gsl_eigen_symm_workspace *ew = gsl_eigen_symm_alloc(3);
    int rank_def = 0;
    if (!M || !E || !ev || !ew) {
        rank_def = -1;
        goto done;
    }
    /* scale to unit diagonal before inverting (the columns differ by orders of magnitude) */
    double dsc[3];
    for (int a = 0; a < 3; a++) {
        dsc[a] = sqrt(jtj[a][a]);
        if (!(dsc[a] > 0 && isfinite(dsc[a]))) {
            rank_def = 1;
            goto done;
        }
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            gsl_matrix_set(M, a, b, jtj[a][b] / (dsc[a] * dsc[b]));
    gsl_matrix_memcpy(E, M);
    if (gsl_eigen_symm(E, ev, ew) != GSL_SUCCESS) {
        rank_def = 1;
        goto done;
    }
    double emin = gsl_vector_min(ev), emax = gsl_vector_max(ev);
    if (!(emin > 1e-10 * emax)) {
        rank_def = 1;
        goto done;
    }
    if (gsl_linalg_cholesky_decomp1(M) == GSL_SUCCESS &&
        gsl_linalg_cholesky_invert(M) == GSL_SUCCESS) {
        double s2 = rss / (double)(n - 3);
        for (int a = 0; a < 3; a++) {
            double var = s2 * gsl_matrix_get(M, a, a) / (dsc[a] * dsc[a]);
            se[a] = (var >= 0 && isfinite(var)) ? sqrt(var) : -1;
        }
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double q = gsl_matrix_get(M, a, b) /
                           sqrt(gsl_matrix_get(M, a, a) * gsl_matrix_get(M, b, b));
                corr[a][b] = isfinite(q) ? fmax(-1.0, fmin(1.0, q)) : NAN;
            }
    } else {
        rank_def = 1;
    }
done:
    gsl_eigen_symm_free(ew);
    gsl_vector_free(ev);
    gsl_matrix_free(E);
    gsl_matrix_free(M);
    return rank_def;
}
