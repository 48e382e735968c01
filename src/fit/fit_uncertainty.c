/*
** The uncertainty of a fit's identifiable quantities: standard errors and correlation (stage A's
** Jacobian), and profile-likelihood intervals where those say nothing (a quantity on a limit, a
** rank-deficient Jacobian, a Wald interval crossing the quantity's range).
*/
#include <math.h>
#include <string.h>

#include "conifit/measure.h"
#include "fit/fit_ctx.h"
#include "fit/lsq.h"

/* F(0.95; 1, N - 3) times the residual variance (floored at rounding level): the rise of the
** weighted RSS that the noise can explain, for one quantity. */
static double rss_threshold(const fit_ctx *c, double rss)
{
    double dof = (double)c->n - 3;
    double s2 = fmax(rss / dof, 1e-24 * c->ynorm / (double)c->n);
    return cf_lsq_f95(dof) * s2;
}

/* The profile of quantity q->fixed at log value u: the RSS minimised over the other quantities
** from xin; xin moves to the minimiser when the RSS is within limit. */
static double profile_at(fit_ctx *c, sub *q, double u, double limit, double *xin)
{
    double x[2] = {xin[0], xin[1]};
    q->t = exp(u);
    double f = cf_fit_sub_solve(c, q, x, NLOPT_LN_COBYLA);
    if (f <= limit)
        memcpy(xin, x, sizeof x);
    return f;
}

/* One end of the profile interval of quantity k (dir = -1 low, +1 high), in log units from the
** value v[k]; res receives the end and the bit of the bound it reached. */
static void profile_end(fit_ctx *c, int k, const double v[3], double limit, int dir, double h,
                        cf_fit_result *res)
{
    /* the range of each quantity, in log units */
    double lo[3] = {log(c->rho_lo), log(c->b_lo), -INFINITY};
    /* the stress scale has no upper limit of its own: its profile stops at the largest value a
    ** table may hold (an outlier of 1e20 kPa walked it to exp(710) = inf) */
    double hi[3] = {log(c->rho_hi * (1 - 1e-12)), log(c->b_hi), log(CF_MEASURE_MAX_VALUE)};
    unsigned lo_bit[3] = {c->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS,
                          c->travel_ok ? CF_C_TRAVEL : CF_C_BOUNDS, 0};
    unsigned hi_bit[3] = {(c->type == CF_TELESCOPING && !c->region) ? CF_C_TYPE : CF_C_DIAMETERS,
                          CF_C_BOUNDS, CF_C_BOUNDS};
    sub q = {c, k, 0};
    double x0[2], xin[2];
    int j = 0;
    if (k != 0)
        x0[j++] = log(v[0]);
    if (k != 1)
        x0[j] = v[1];
    memcpy(xin, x0, sizeof x0);
    double u_in = log(v[k]), u_out = NAN;
    unsigned end_bit = 0;
    int done = 0, infeasible = 0;
    for (int it = 0; it < 60 && !done; it++, h *= 2) {
        double u = u_in + dir * h;
        int at_bound = 0;
        if (dir < 0 && u <= lo[k]) {
            u = lo[k];
            at_bound = 1;
        } else if (dir > 0 && u >= hi[k]) {
            u = hi[k];
            at_bound = 1;
        }
        double f = profile_at(c, &q, u, limit, xin);
        if (f <= limit) {
            u_in = u;
            if (at_bound) {
                end_bit = dir < 0 ? lo_bit[k] : hi_bit[k];
                done = 1;
            }
        } else {
            u_out = u;
            infeasible = f >= CF_LSQ_HUGE_OBJ;
            done = 2;
        }
    }
    if (done == 2) {
        /* to 1e-4 in log units (times |log v|) or 1 % of the end's distance from the value,
        ** whichever is finer: the first alone returned the value itself for every interval
        ** narrower than that (a precise table, a long one, collapsed to [value, value]) */
        const double u0 = log(v[k]);
        for (int it = 0; it < 60 && fabs(u_out - u_in) > fmax(fmin(1e-4 * fmax(1.0, fabs(u_in)),
                                                                   1e-2 * fabs(u_out - u0)),
                                                              1e-15);
             it++) {
            double u = 0.5 * (u_in + u_out);
            double f = profile_at(c, &q, u, limit, xin);
            if (f <= limit) {
                u_in = u;
            } else {
                u_out = u;
                infeasible = f >= CF_LSQ_HUGE_OBJ;
            }
        }
        if (infeasible) { /* the end is where the type's limits close, not the threshold */
            double rho, B;
            cf_fit_sub_point(&q, xin, &rho, &B);
            region r = cf_fit_region_at(c, k == 0 ? exp(u_in) : rho, k == 1 ? exp(u_in) : B);
            end_bit = k == 2 ? CF_C_G_MAX : r.lo_bit | r.hi_bit;
        }
    }
    /* exp(log(v)) may differ from v in the last bit: the interval always holds the value */
    res->interval[k][dir < 0 ? 0 : 1] = dir < 0 ? fmin(exp(u_in), v[k]) : fmax(exp(u_in), v[k]);
    res->interval_end[k][dir < 0 ? 0 : 1] = end_bit;
}

/* Standard errors s^2 (J^T W J)^-1 of (rho, B, A) at v, the correlation matrix, and whether the
** Jacobian is numerically rank-deficient (smallest eigenvalue of the unit-diagonal J^T W J below
** 1e-10 of the largest): then no standard error is given. */
void cf_fit_uncertainty(fit_ctx *c, fit_ctx *g, cf_fit_result *res, unsigned held_a)
{
    const double *v = res->ident.v;
    int rank_def = cf_fit_stage_a_errors(c, v, res->ident_se.v, res->corr);
    res->held = held_a | cf_fit_held_at(c, v) | (c->fd || c->region ? 0u : res->active);
    unsigned why = res->held | (rank_def ? CF_FIT_RANK_DEFICIENT : 0);
    /* a Wald interval that would cross the range of a quantity is no interval either */
    double lo[3] = {c->rho_lo, c->b_lo, 0}, hi[3] = {c->rho_hi, c->b_hi, INFINITY};
    int need = why != 0;
    for (int k = 0; k < 3; k++)
        need = need || res->ident_se.v[k] < 0 || v[k] - 1.96 * res->ident_se.v[k] < lo[k] ||
               v[k] + 1.96 * res->ident_se.v[k] > hi[k];
    if (!need || c->n <= 3)
        return;
    /* The profiles run up to the limits themselves: the searches' REGION_SAFETY is for the
    ** placement, and a polish that ends on a limit (rho on rho_min, A on G_max) uses it up, which
    ** left no admissible point near the fit and every interval at [value, value]. A reported
    ** point past a limit by rounding is admitted; one past it by more stays outside. */
    region r = cf_fit_region_at(c, v[0], v[1]);
    const double room = fmin(-r.margin, log(r.A_max / (1 - REGION_SAFETY)) - log(v[2]));
    g->inside = fmax(fmin(0.0, room), -1e-9);
    r = cf_fit_region_at(g, v[0], v[1]);
    double A;
    double rss0 = g == c ? fmin(res->objective, cf_fit_rss_at(c, v[0], v[1], -1, r.A_max, &A))
                         : cf_fit_rss_at(g, v[0], v[1], -1, r.A_max, &A);
    double limit = rss0 + rss_threshold(c, rss0);
    for (int k = 0; k < 3; k++) {
        double h = res->ident_se.v[k] > 0 ? fmin(0.5 * res->ident_se.v[k] / v[k], 0.1) : 0.01;
        h = fmax(h, 1e-13);
        profile_end(g, k, v, limit, -1, h, res);
        profile_end(g, k, v, limit, +1, h, res);
        res->interval_ok[k] = 1;
        res->interval_why[k] = why;
    }
    g->inside = REGION_SAFETY;
}
