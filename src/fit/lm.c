/*
** The Levenberg-Marquardt of the fits (see lm.h).
*/
#include "fit/lm.h"

#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>

double cf_logit(double p)
{
    p = fmin(fmax(p, 1e-15), 1 - 1e-15);
    return log(p / (1 - p));
}

double cf_logistic(double t)
{
    return 1.0 / (1.0 + exp(-t));
}

gsl_multifit_nlinear_parameters cf_lm_parameters(void)
{
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    fp.trs = gsl_multifit_nlinear_trs_lm;
    fp.scale = gsl_multifit_nlinear_scale_more;
    return fp;
}

gsl_multifit_nlinear_workspace *cf_lm_start(const gsl_multifit_nlinear_parameters *fp,
                                            gsl_multifit_nlinear_fdf *fdf, double *x0,
                                            int *init)
{
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, fp, fdf->n, fdf->p);
    if (!w)
        return NULL;
    gsl_vector_view v = gsl_vector_view_array(x0, fdf->p);
    *init = gsl_multifit_nlinear_init(&v.vector, fdf, w);
    return w;
}

int cf_lm_iterate(gsl_multifit_nlinear_workspace *w, const cf_lm_stop *stop)
{
    gsl_vector *f = gsl_multifit_nlinear_residual(w);
    double prev;
    gsl_blas_ddot(f, f, &prev);
    int stall = 0, out_stall = 0;
    const int win = stop->ceiling > 0 && stop->ceiling_iter > 0 &&
                            stop->ceiling_iter <= CF_LM_CEILING_ITER_MAX
                        ? stop->ceiling_iter
                        : 0;
    double last[CF_LM_CEILING_ITER_MAX]; /* the sums of squares of the last win iterations */
    for (int it = 0; it < stop->max_iter; it++) {
        int info;
        int is = gsl_multifit_nlinear_iterate(w);
        if (is == GSL_ENOMEM)
            return -1;
        if (is != GSL_SUCCESS)
            break;
        if (gsl_multifit_nlinear_test(stop->xtol, stop->gtol, stop->ftol, &info, w) ==
            GSL_SUCCESS)
            break;
        double cur;
        gsl_blas_ddot(f, f, &cur);
        stall = (prev - cur <= stop->stall_rel * prev) ? stall + 1 : 0;
        out_stall = (prev - cur <= stop->outside_rel * prev) ? out_stall + 1 : 0;
        prev = cur;
        if (stall >= stop->stall || cur <= stop->floor)
            break;
        if (stop->outside && out_stall >= stop->outside_stall &&
            stop->outside(gsl_multifit_nlinear_position(w), stop->outside_arg))
            break;
        if (win) {
            if (it >= win && cur > stop->ceiling &&
                last[it % win] - cur <= stop->ceiling_rel * last[it % win])
                break;
            last[it % win] = cur;
        }
    }
    return 0;
}

double cf_lm_minimise(int (*f)(const gsl_vector *x, void *params, gsl_vector *r), void *params,
                      size_t n, size_t p, double *x, const cf_lm_stop *stop)
{
    gsl_multifit_nlinear_fdf fdf = {f, NULL, NULL, n, p, params, 0, 0, 0};
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.fdtype = GSL_MULTIFIT_NLINEAR_CTRDIFF;
    int init = 0;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, x, &init);
    if (!w)
        return INFINITY;
    double ss = INFINITY;
    if (init == GSL_SUCCESS) {
        cf_lm_iterate(w, stop);
        gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &ss);
        memcpy(x, gsl_multifit_nlinear_position(w)->data, p * sizeof *x);
    }
    gsl_multifit_nlinear_free(w);
    return isfinite(ss) ? ss : INFINITY;
}
