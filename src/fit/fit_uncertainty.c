/*
** The uncertainty of a fit's identifiable quantities: standard errors and correlation (stage A's
** Jacobian), and profile-likelihood intervals where those say nothing (a quantity on a limit, a
** rank-deficient Jacobian, a Wald interval crossing the quantity's range).
*/
#include <math.h>
#include <string.h>

#include "io/measure.h"
#include "fit/fit_ctx.h"
#include "fit/lsq.h"
#include "fit/profile.h"
#include "fit/profile.h"

/* How far inside the type's limits (their margin, log units) SLSQP's end must lie for COBYLA to
** start from it. */
#define PROFILE_CLEAR 1e-3

/* Whether SLSQP's end x of sub-problem q is a minimum COBYLA may start from: clear of the type's
** limits (on a limit SLSQP stops short, and COBYLA's steps along the constraint do better from
** the profile's previous point) and not where the law is linear over the whole table (every row
** at or below the transition, cf_ident_canon_transition: there the RSS is constant along a
** valley in which SLSQP stops anywhere, and COBYLA's wider steps from the previous point leave
** it). */
static int slsqp_end_trusted(const fit_ctx *c, const sub *q, const double *x)
{
    double rho, B;
    cf_fit_sub_point(q, x, &rho, &B);
    return cf_fit_sub_g0(q, x) < -PROFILE_CLEAR &&
           !(c->xmax <= B * cf_ident_canon_transition(rho));
}

/* The profile of quantity k at log value u: the RSS minimised over the other quantities from
** xin; xin moves to the minimiser when the RSS is within limit. SLSQP on the analytic gradient
** first; where it ends above the limit, COBYLA decides: from SLSQP's end where that can be trusted
** as a minimum (slsqp_end_trusted), where from the previous point it only crawled back to the
** same RSS (up to its 300 evaluations each at the stress scale's lower end of the 100-row
** benchmark table, a third of that fit); from the previous point elsewhere. Neither runs where no
** point meets the limits at all (cf_fit_sub_empty), whose answer they could only confirm. */
static double profile_at(void *ctx, int k, double u, double limit, double *xin)
{
    fit_ctx *c = ctx;
    sub q = {c, k, 0};
    double x[2] = {xin[0], xin[1]};
    q.t = exp(u);
    if (cf_fit_sub_empty(&q))
        return CF_LSQ_HUGE_OBJ;
    double f = cf_fit_sub_solve(c, &q, x, NLOPT_LD_SLSQP);
    if (!(f <= limit)) {
        const double *from = slsqp_end_trusted(c, &q, x) ? x : xin;
        double y[2] = {from[0], from[1]};
        double g = cf_fit_sub_solve(c, &q, y, NLOPT_LN_COBYLA);
        if (g < f) {
            f = g;
            memcpy(x, y, sizeof x);
        }
    }
    if (f <= limit)
        memcpy(xin, x, sizeof x);
    return f;
}

/* The limit that closes where the profile of quantity k has no admissible point at xin. */
static unsigned profile_closed(void *ctx, int k, double u, const double *xin)
{
    fit_ctx *c = ctx;
    sub q = {c, k, 0};
    double rho, B;
    q.t = exp(u);
    cf_fit_sub_point(&q, xin, &rho, &B);
    region r = cf_fit_region_at(c, k == 0 ? exp(u) : rho, k == 1 ? exp(u) : B);
    return k == 2 ? CF_C_G_MAX : r.lo_bit | r.hi_bit;
}

/* Standard errors s^2 (J^T W J)^-1 of (rho, B, A) at v, the correlation matrix, and whether the
** Jacobian is numerically rank-deficient (smallest eigenvalue of the unit-diagonal J^T W J below
** 1e-10 of the largest): then no standard error is given. */
void cf_fit_uncertainty(fit_ctx *c, fit_ctx *g, cf_fit_result *res, unsigned held_a)
{
    const double *v = res->ident.v;
    double corr[3][3];
    int rank_def = cf_fit_stage_a_errors(c, v, res->ident_se.v, corr);
    cf_fit_corr3(res, corr);
    res->held = held_a | cf_fit_held_at(c, v) | (c->fd || c->region ? 0u : res->active);
    unsigned why = res->held | (rank_def ? CF_FIT_RANK_DEFICIENT : 0);
    /* a Wald interval that would cross the range of a quantity is no interval either */
    double lo[3] = {c->rho_lo, c->b_lo, 0}, hi[3] = {c->rho_hi, c->b_hi, INFINITY};
    if (!cf_profile_needed(res, lo, hi, why) || c->n <= 3)
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
    /* the range of each quantity, in log units; the stress scale has no upper limit of its own:
    ** its profile stops at the largest value a table may hold (an outlier of 1e20 kPa walked it
    ** to exp(710) = inf) */
    const cf_profile p = {
        .ctx = g,
        .lo = {log(g->rho_lo), log(g->b_lo), -INFINITY},
        .hi = {log(g->rho_hi * (1 - 1e-12)), log(g->b_hi), log(CF_MEASURE_MAX_VALUE)},
        .lo_bit = {g->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS,
                   g->travel_ok ? CF_C_TRAVEL : CF_C_BOUNDS, 0},
        .hi_bit = {(g->type == CF_TELESCOPING && !g->region) ? CF_C_TYPE : CF_C_DIAMETERS,
                   CF_C_BOUNDS, CF_C_BOUNDS},
        .at = profile_at,
        .closed = profile_closed,
        .with_rss0 = 1,
        .rss0 = rss0};
    cf_profile_intervals(&p, v, cf_profile_limit(c->n, rss0, c->ynorm), why, res);
    g->inside = REGION_SAFETY;
}
