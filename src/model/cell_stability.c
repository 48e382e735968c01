/*
** Positive definiteness of the cell's incremental stiffness along a test mode (see
** cell_stability.h).
*/
#include "model/cell_stability.h"
#include "base/gslguard.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_matrix.h>
#include <math.h>
#include <string.h>

/* Steps of the scan from 0 to the reach, and bisections of a step where stability is lost. */
#define SCAN_STEPS 64
#define BISECTIONS 20

/* The six strain increments D (symmetric, unit Frobenius norm). */
static void strain_basis(int a, double D[9])
{
    static const int pair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    memset(D, 0, 9 * sizeof(double));
    const int i = pair[a][0], j = pair[a][1];
    if (i == j) {
        D[3 * i + j] = 1;
    } else {
        D[3 * i + j] = D[3 * j + i] = M_SQRT1_2;
    }
}

static cf_status min_eigen(const double K[36], double *lambda, cf_error *err)
{
    gsl_matrix *m = gsl_matrix_alloc(6, 6);
    gsl_vector *ev = gsl_vector_alloc(6);
    gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(6);
    cf_status st = CF_OK;
    if (!m || !ev || !w) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the cell's eigenvalues");
    } else {
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++)
                gsl_matrix_set(m, a, b, K[6 * a + b]);
        if (gsl_eigen_symm(m, ev, w) != 0)
            st = cf_error_set(err, CF_E_INTERNAL, "the cell's eigenvalues did not converge");
        else
            *lambda = gsl_vector_min(ev);
    }
    gsl_eigen_symm_free(w);
    gsl_vector_free(ev);
    gsl_matrix_free(m);
    return st;
}

cf_status cf_cell_min_stiffness(const cf_cell *c, const double F[9], double *lambda_MPa,
                                cf_error *err)
{
    CF_GSL_GUARD;
    double A[81], dF[6][9], K[36];
    cf_cell_state s;
    cf_status st = cf_cell_tangent(c, F, NULL, &s, A, err);
    if (st != CF_OK)
        return st;
    for (int a = 0; a < 6; a++) {
        double D[9];
        strain_basis(a, D);
        for (int k = 0; k < 3; k++)
            for (int l = 0; l < 3; l++)
                dF[a][3 * k + l] = D[3 * k] * F[l] + D[3 * k + 1] * F[3 + l] + D[3 * k + 2] * F[6 + l];
    }
    for (int a = 0; a < 6; a++)
        for (int b = 0; b < 6; b++) {
            double q = 0;
            for (int p = 0; p < 9; p++)
                for (int r = 0; r < 9; r++)
                    q += dF[a][p] * A[9 * p + r] * dF[b][r];
            K[6 * a + b] = q;
        }
    for (int a = 0; a < 6; a++) /* symmetric up to rounding: average the two halves */
        for (int b = a + 1; b < 6; b++)
            K[6 * a + b] = K[6 * b + a] = 0.5 * (K[6 * a + b] + K[6 * b + a]);
    return min_eigen(K, lambda_MPa, err);
}

/* 1: the state of mode m at strain e exists and is stable; 0: it is not (or cannot be reached);
** CF_E_INTERNAL passes through *st. */
static int stable_at(const cf_cell *c, cf_mode m, double e, cf_status *st, cf_error *err)
{
    cf_cell_state s;
    cf_error e1 = {0};
    double lambda = 0;
    if (cf_cell_mode(c, m, e, NULL, &s, &e1) != CF_OK)
        return 0;
    cf_status r = cf_cell_min_stiffness(c, s.F, &lambda, &e1);
    if (r == CF_E_INTERNAL) {
        *st = r;
        if (err)
            *err = e1;
        return 0;
    }
    return r == CF_OK && lambda > 0;
}

cf_status cf_cell_stable_to(const cf_cell *c, cf_mode m, double reach, double *limit, int *lost,
                            cf_error *err)
{
    CF_GSL_GUARD;
    *limit = reach;
    *lost = 0;
    if (!isfinite(reach))
        return cf_error_set(err, CF_E_DATA, "strain %g: not finite", reach);
    cf_status st = CF_OK;
    double good = 0;
    for (int k = 1; k <= SCAN_STEPS; k++) {
        const double e = reach * k / SCAN_STEPS;
        if (stable_at(c, m, e, &st, err)) {
            good = e;
            continue;
        }
        if (st != CF_OK)
            return st;
        double bad = e;
        for (int b = 0; b < BISECTIONS && fabs(bad - good) > 1e-6 * fabs(reach); b++) {
            const double mid = 0.5 * (good + bad);
            if (stable_at(c, m, mid, &st, err))
                good = mid;
            else if (st != CF_OK)
                return st;
            else
                bad = mid;
        }
        *limit = good;
        *lost = 1;
        return CF_OK;
    }
    return CF_OK;
}
