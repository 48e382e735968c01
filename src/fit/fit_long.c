/*
** A long table (more rows than cf_fit_options.subsample_above): stage A's global searches run on
** its subsample, and their results are polished here by Levenberg-Marquardt on every row.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "fit/fit_ctx.h"
#include "fit/lm.h"
#include "fit/lsq.h"

/* The quantities (rho, B, A) at th, the coordinates of cf_fit_lm_run (logits of rho and B in
** their ranges, log A); dq receives d rho/d th0 and d B/d th1. */
static void unpack(const fit_ctx *c, const double th[3], double q[3], double dq[2])
{
    const double s0 = 1 / (1 + exp(-th[0])), s1 = 1 / (1 + exp(-th[1]));
    q[0] = c->rho_lo + (c->rho_hi - c->rho_lo) * s0;
    q[1] = c->b_lo + (c->b_hi - c->b_lo) * s1;
    q[2] = exp(th[2]);
    dq[0] = (c->rho_hi - c->rho_lo) * s0 * (1 - s0);
    dq[1] = (c->b_hi - c->b_lo) * s1 * (1 - s1);
}

/* One pass over every row at th: the sum of squares of the residuals (scaled as cf_fit_lm_run
** scales them, so that the zero model has 1), J^T J and J^T r of their Jacobian in th, without
** storing the Jacobian. CF_LSQ_HUGE_OBJ where the model is not defined. */
static double normal_pass(fit_ctx *c, const double th[3], double jtj[3][3], double jtr[3])
{
    double q[3], dq[2];
    unpack(c, th, q, dq);
    if (!isfinite(q[2]) ||
        cf_ident_canon_many_rho(q[0], q[1], c->n, c->data->x, c->model, c->gt, c->gr) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    const double B = q[1], A = q[2], sc = 1.0 / sqrt(c->ynorm);
    double chi2 = 0;
    memset(jtj, 0, 9 * sizeof(double));
    memset(jtr, 0, 3 * sizeof(double));
    for (size_t i = 0; i < c->n; i++) {
        const double w = sc * c->sw[i];
        const double r = w * (A * c->model[i] - c->data->y[i]);
        const double j[3] = {w * A * c->gr[i] * dq[0],
                             -w * A * c->gt[i] * c->data->x[i] / (B * B) * dq[1],
                             w * A * c->model[i]};
        chi2 += r * r;
        for (int a = 0; a < 3; a++) {
            jtr[a] += j[a] * r;
            for (int b = 0; b <= a; b++)
                jtj[a][b] += j[a] * j[b];
        }
    }
    for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++)
            jtj[a][b] = jtj[b][a];
    c->evals++;
    return isfinite(chi2) ? chi2 : CF_LSQ_HUGE_OBJ;
}

/* Levenberg-Marquardt on every row of a long table from (rho0, B0, A0), as cf_fit_lm_run but
** streaming: each step is one pass over the rows that forms the 3 x 3 normal equations (the
** Jacobian of a million rows is never stored, nor passed over again by the linear algebra), with
** Marquardt's damping scaled by the largest diagonal seen and the same stopping rules. out
** receives the quantities; returns the scaled sum of squares (CF_LSQ_HUGE_OBJ when the start
** has no model). */
static double lm_stream(fit_ctx *c, double rho0, double B0, double A0, double out[3])
{
    double th[3] = {cf_logit((rho0 - c->rho_lo) / (c->rho_hi - c->rho_lo)),
                    cf_logit((B0 - c->b_lo) / (c->b_hi - c->b_lo)), log(A0)};
    double jtj[3][3], jtr[3], tj[3][3], tr[3], diag[3] = {0, 0, 0}, dq[2];
    double chi2 = normal_pass(c, th, jtj, jtr);
    if (!(chi2 < CF_LSQ_HUGE_OBJ))
        return CF_LSQ_HUGE_OBJ;
    const int stall_max = c->stat_tol > 0 ? LM_STALL_LONG : LM_STALL;
    const double stall_rel = c->stat_tol > 0 ? c->stat_tol : LM_STALL_REL;
    double mu = 1e-3;
    int stall = 0;
    for (int it = 0; it < LM_MAX_ITER && mu < 1e16 && chi2 > LM_FLOOR_REL; it++) {
        double m[9], d[3];
        for (int a = 0; a < 3; a++) {
            diag[a] = fmax(diag[a], jtj[a][a]);
            d[a] = -jtr[a];
            for (int b = 0; b < 3; b++)
                m[3 * a + b] = jtj[a][b] + (a == b ? mu * fmax(diag[a], 1e-300) : 0);
        }
        gsl_matrix_view mv = gsl_matrix_view_array(m, 3, 3);
        gsl_vector_view dv = gsl_vector_view_array(d, 3);
        if (gsl_linalg_cholesky_decomp1(&mv.matrix) != GSL_SUCCESS ||
            gsl_linalg_cholesky_svx(&mv.matrix, &dv.vector) != GSL_SUCCESS) {
            mu *= 4;
            continue;
        }
        double tt[3], step = 0, size = 0;
        for (int a = 0; a < 3; a++) {
            tt[a] = th[a] + d[a];
            step = fmax(step, fabs(d[a]));
            size = fmax(size, fabs(th[a]));
        }
        if (step <= 1e-15 * (size + 1e-15))
            break;
        double t2 = normal_pass(c, tt, tj, tr);
        if (!(t2 < chi2)) {
            mu *= 4;
            continue;
        }
        stall = chi2 - t2 <= stall_rel * chi2 ? stall + 1 : 0;
        chi2 = t2;
        memcpy(th, tt, sizeof th);
        memcpy(jtj, tj, sizeof jtj);
        memcpy(jtr, tr, sizeof jtr);
        mu = fmax(mu / 3, 1e-12);
        if (stall >= stall_max)
            break;
    }
    unpack(c, th, out, dq);
    return chi2;
}

/* Stage A's optima on the subsample polished by Levenberg-Marquardt on every row: the best one,
** and up to POLISH_RUNS - 1 others, distinct from it, that the F-test on the subsample cannot tell
** from it (a table that leaves the quantities open has a valley of optima of nearly equal depth,
** and the deepest on every row may lie elsewhere in it); v receives the best on every row. */
#define POLISH_RUNS 3
void cf_fit_stage_a_polish(fit_ctx *c, start4 *found, int nfound, double v[3])
{
    qsort(found, (size_t)nfound, sizeof found[0], cf_fit_cmp_start4);
    const double er = 1e-12 * (c->rho_hi - c->rho_lo), eb = 1e-12 * (c->b_hi - c->b_lo);
    const double dof = (double)c->n - 3;
    const double within = nfound > 0 ? found[0].obj * (1 + cf_lsq_f95(dof) / dof) : 0;
    double best = CF_LSQ_HUGE_OBJ;
    int done = 0;
    for (int i = 0; i < nfound && done < POLISH_RUNS && (i == 0 || found[i].obj <= within); i++) {
        const double *u = found[i].v;
        int same = 0;
        for (int j = 0; j < i && !same; j++)
            same = fabs(found[j].v[0] - u[0]) <= 1e-3 * u[0] &&
                   fabs(found[j].v[1] - u[1]) <= 1e-3 * u[1];
        if (same || !(u[2] > 0 && isfinite(u[2])))
            continue;
        done++;
        double rho = fmin(fmax(u[0], c->rho_lo + er), c->rho_hi - er);
        double B = fmin(fmax(u[1], c->b_lo + eb), c->b_hi - eb), out[3];
        double f = lm_stream(c, rho, B, u[2], out);
        if (f < best) {
            best = f;
            memcpy(v, out, sizeof out);
        }
    }
}

/* The constrained optimum v (found on the subsample) polished on every row: SLSQP on the analytic
** gradient, then COBYLA from its end in short first steps (SLSQP can stop short along an active
** limit; the optimum on every row lies close to the subsample's, and COBYLA's default first step,
** a fraction of the whole range, cost a hundred passes over the rows), then SLSQP again; v keeps
** its value when the polish finds no better point. */
void cf_fit_stage_a_constrained_polish(fit_ctx *c, double v[3])
{
    sub q = {c, -1, 0, 0};
    double x0[2] = {log(v[0]), v[1]}, x[2] = {x0[0], x0[1]};
    double f0 = cf_fit_sub_g0(&q, x0) <= 1e-9 ? cf_fit_sub_f0(&q, x0) : CF_LSQ_HUGE_OBJ;
    double f = cf_fit_sub_solve(c, &q, x, NLOPT_LD_SLSQP);
    q.step = 1e-3;
    f = fmin(f, cf_fit_sub_solve(c, &q, x, NLOPT_LN_COBYLA));
    f = fmin(f, cf_fit_sub_solve(c, &q, x, NLOPT_LD_SLSQP));
    if (f > f0 || !(f < CF_LSQ_HUGE_OBJ))
        memcpy(x, x0, sizeof x);
    v[0] = exp(x[0]);
    v[1] = x[1];
    region r = cf_fit_region_at(c, v[0], v[1]);
    cf_fit_rss_at(c, v[0], v[1], -1, r.A_max, &v[2]);
}
