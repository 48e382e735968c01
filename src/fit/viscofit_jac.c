/*
** The Jacobian of the viscoelastic fit's Levenberg-Marquardt (see viscofit_ctx.h). Every column
** by forward differences costs one model run per parameter, which is most of a time-series fit;
** between two such Jacobians, Broyden's rank-one update carries the last one along the step
** taken, from the residuals the step already computed (no model run). A fresh Jacobian by
** differences is taken every LM_JAC_REUSE accepted steps, and after a step whose first trial
** was refused (the updated Jacobian no longer predicted the model well enough).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "fit/viscofit_ctx.h"

struct lm_jac {
    size_t n, p;
    double *x, *f;   /* the last point the residuals were computed at, and those residuals */
    double *xj, *fj; /* the point of the Jacobian held, and its residuals */
    double *J;       /* the Jacobian held, n x p, by rows */
    double *keep;    /* the residuals at x while the differences evaluate other points */
    gsl_vector *work;
    int have;        /* 1 once J holds a Jacobian */
    int since_fd;    /* updates since the last Jacobian by differences */
    int fcalls;      /* residual evaluations since the last Jacobian */
    gsl_multifit_nlinear_fdf *fdf;
    double h_df;
};

void cf_viscofit_jac_free(struct lm_jac *j)
{
    if (!j)
        return;
    free(j->x);
    if (j->work)
        gsl_vector_free(j->work);
    free(j);
}

struct lm_jac *cf_viscofit_jac_alloc(size_t n, size_t p, gsl_multifit_nlinear_fdf *fdf,
                                     double h_df)
{
    struct lm_jac *j = calloc(1, sizeof *j);
    if (!j)
        return NULL;
    j->n = n;
    j->p = p;
    j->fdf = fdf;
    j->h_df = h_df;
    j->x = malloc((2 * p + 3 * n + n * p) * sizeof(double));
    j->work = gsl_vector_alloc(n);
    if (!j->x || !j->work) {
        cf_viscofit_jac_free(j);
        return NULL;
    }
    j->xj = j->x + p;
    j->f = j->xj + p;
    j->fj = j->f + n;
    j->keep = j->fj + n;
    j->J = j->keep + n;
    return j;
}

void cf_viscofit_jac_record(struct lm_jac *j, const double *x, const double *f)
{
    if (!j)
        return;
    memcpy(j->x, x, j->p * sizeof(double));
    memcpy(j->f, f, j->n * sizeof(double));
    j->fcalls++;
}

/* Broyden's update of the Jacobian held from its point xj to x, where the residuals are f. 0
** when the step is too small to carry it. */
static int broyden(struct lm_jac *j, const double *x, const double *f)
{
    double s[64], ss = 0;
    if (j->p > 64)
        return 0;
    for (size_t c = 0; c < j->p; c++) {
        s[c] = x[c] - j->xj[c];
        ss += s[c] * s[c];
    }
    if (!(ss > 0) || !isfinite(ss))
        return 0;
    for (size_t k = 0; k < j->n; k++) {
        double *row = j->J + k * j->p, pred = 0;
        for (size_t c = 0; c < j->p; c++)
            pred += row[c] * s[c];
        const double d = (f[k] - j->fj[k] - pred) / ss;
        for (size_t c = 0; c < j->p; c++)
            row[c] += d * s[c];
    }
    return 1;
}

int cf_viscofit_jac_df(const gsl_vector *xv, void *data, gsl_matrix *Jm)
{
    ctx *c = data;
    struct lm_jac *j = c->jac;
    const double *x = xv->data;
    /* the residuals at x: those of the trial just accepted, else computed */
    if (memcmp(x, j->x, j->p * sizeof(double)) != 0) {
        gsl_vector_view fv = gsl_vector_view_array(j->f, j->n);
        j->fdf->f(xv, data, &fv.vector);
        memcpy(j->x, x, j->p * sizeof(double));
    }
    int fresh = !j->have || j->since_fd + 1 >= LM_JAC_REUSE || j->fcalls > 1 ||
                !broyden(j, x, j->f);
    if (fresh) {
        memcpy(j->keep, j->f, j->n * sizeof(double));
        gsl_vector_view fv = gsl_vector_view_array(j->keep, j->n);
        gsl_matrix_view Jv = gsl_matrix_view_array(j->J, j->n, j->p);
        int st = gsl_multifit_nlinear_df(j->h_df, GSL_MULTIFIT_NLINEAR_FWDIFF, xv, NULL, j->fdf,
                                         &fv.vector, &Jv.matrix, j->work);
        if (st != GSL_SUCCESS)
            return st;
        memcpy(j->f, j->keep, j->n * sizeof(double)); /* the differences ran elsewhere */
        memcpy(j->x, x, j->p * sizeof(double));
        j->since_fd = 0;
    } else {
        j->since_fd++;
    }
    memcpy(j->xj, x, j->p * sizeof(double));
    memcpy(j->fj, j->f, j->n * sizeof(double));
    j->have = 1;
    j->fcalls = 0;
    gsl_matrix_const_view Jv = gsl_matrix_const_view_array(j->J, j->n, j->p);
    gsl_matrix_memcpy(Jm, &Jv.matrix);
    return GSL_SUCCESS;
}
