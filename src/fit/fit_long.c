/*
** A long table (more rows than cf_fit_options.subsample_above): stage A's global searches run on
** its subsample, and their results are polished here by Levenberg-Marquardt on every row.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit/fit_ctx.h"
#include "fit/lsq.h"

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
        double f = cf_fit_lm_run(c, rho, B, u[2], out);
        if (f < best) {
            best = f;
            memcpy(v, out, sizeof out);
        }
    }
}

/* The constrained optimum v (found on the subsample) polished on every row, as
** cf_fit_stage_a_constrained polishes each of its starts; v keeps its value when the polish finds
** no better point. */
void cf_fit_stage_a_constrained_polish(fit_ctx *c, double v[3])
{
    sub q = {c, -1, 0};
    double x0[2] = {log(v[0]), v[1]}, x[2] = {x0[0], x0[1]};
    double f0 = cf_fit_sub_g0(&q, x0) <= 1e-9 ? cf_fit_sub_f0(&q, x0) : CF_LSQ_HUGE_OBJ;
    double f = cf_fit_sub_solve(c, &q, x, NLOPT_LN_COBYLA);
    f = fmin(f, cf_fit_sub_solve(c, &q, x, NLOPT_LD_SLSQP));
    if (f > f0 || !(f < CF_LSQ_HUGE_OBJ))
        memcpy(x, x0, sizeof x);
    v[0] = exp(x[0]);
    v[1] = x[1];
    region r = cf_fit_region_at(c, v[0], v[1]);
    cf_fit_rss_at(c, v[0], v[1], -1, r.A_max, &v[2]);
}
