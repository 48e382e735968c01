/*
** Profile-likelihood intervals over any residual function (see profile.h).
*/
#include "fit/profile.h"

#include <math.h>
#include <string.h>

#include "fit/lsq.h"

/* F(0.95; 1, N - 3) times the residual variance (floored at rounding level): the rise of the
** weighted RSS that the noise can explain, for one quantity. */
double cf_profile_limit(size_t n, double rss, double ynorm)
{
    return cf_profile_limit_np(n, 3, rss, ynorm);
}

double cf_profile_limit_np(size_t n, int np, double rss, double ynorm)
{
    double dof = (double)n - np;
    double s2 = fmax(rss / dof, 1e-24 * ynorm / (double)n);
    return rss + cf_lsq_f95(dof) * s2;
}

/* The rise of the profile f above the fitted RSS, as its square root: near the value the profile
** is a parabola in u, so this is nearly linear in u and a straight line through two of its points
** lands close to the end (on the RSS itself false position crept to the end from one side, and
** every point outside the interval costs a second search: measured, 8 to 16 points an end). NAN
** without rss0 or beyond the searches' admissible set. */
static double rise(const cf_profile *p, double f)
{
    if (!p->with_rss0 || !(f < CF_LSQ_HUGE_OBJ) || !isfinite(f))
        return NAN;
    return sqrt(fmax(f - p->rss0, 0.0));
}

/* A bracket of one end of a profile interval, in log units: u_in inside (its profile f_in at or
** below the limit), u_out outside (f_out above it; NAN until one is found). */
typedef struct end_bracket {
    double u_in, u_out, f_in, f_out;
    int infeasible; /* f_out is the searches' "no admissible point" value */
} end_bracket;

/* Steps from the value outwards (dir) by h, doubling while the profile stays within the limit,
** until a point outside is found (returns 2) or the quantity's bound is reached inside (returns
** 1, *end_bit its bit), at most 60 steps (returns 0). */
static int end_walk(const cf_profile *p, int k, double limit, int dir, double h, double *xin,
                    end_bracket *b, unsigned *end_bit)
{
    for (int it = 0; it < 60; it++) {
        double u = b->u_in + dir * h;
        int at_bound = 0;
        if (dir < 0 && u <= p->lo[k]) {
            u = p->lo[k];
            at_bound = 1;
        } else if (dir > 0 && u >= p->hi[k]) {
            u = p->hi[k];
            at_bound = 1;
        }
        double f = p->at(p->ctx, k, u, limit, xin);
        if (f > limit) {
            b->u_out = u;
            b->f_out = f;
            b->infeasible = f >= CF_LSQ_HUGE_OBJ;
            return 2;
        }
        b->u_in = u;
        b->f_in = f;
        if (at_bound) {
            *end_bit = dir < 0 ? p->lo_bit[k] : p->hi_bit[k];
            return 1;
        }
        h *= 2;
    }
    return 0;
}

/* Shrinks bracket b of the end to 1e-4 in log units (times |log v|) or 1 % of the end's distance
** from the value u0, whichever is finer: the first alone returned the value itself for every
** interval narrower than that (a precise table, a long one, collapsed to [value, value]). The
** bracket shrinks by false position where both ends have a value. Where the fitted RSS is known,
** on the square root of the profile's rise (the Illinois rule against creeping from one side,
** bisection after four steps in a row on the same side), each point kept 0.9 of the tolerance
** inside the bracket: an estimate that close to one side is tried that far from it, and either
** outcome closes the bracket there. Otherwise on the RSS itself (bisection after two steps on the
** same side), each point half the tolerance inside. */
static void end_refine(const cf_profile *p, int k, double limit, double u0, double *xin,
                       end_bracket *b)
{
    const double r_lim = rise(p, limit);
    int same = 0, last = 0;
    double r_in = rise(p, b->f_in), r_out = rise(p, b->f_out);
    for (int it = 0; it < 60; it++) {
        const double tol =
            fmax(fmin(1e-4 * fmax(1.0, fabs(b->u_in)), 1e-2 * fabs(b->u_out - u0)), 1e-15);
        const double w = b->u_out - b->u_in;
        if (!(fabs(w) > tol))
            break;
        double t = 0.5;
        if (p->with_rss0 && r_out > r_in && r_lim >= r_in && same < 4) {
            t = (r_lim - r_in) / (r_out - r_in);
            const double tt = 0.9 * tol / fabs(w);
            if (t < tt)
                t = tt;
            else if (t > 1 - tt)
                t = 1 - tt;
        } else if (!p->with_rss0 && isfinite(b->f_in) && b->f_out < CF_LSQ_HUGE_OBJ &&
                   b->f_out > b->f_in && same < 2) {
            t = fmin(fmax((limit - b->f_in) / (b->f_out - b->f_in), 0.5 * tol / fabs(w)),
                     1 - 0.5 * tol / fabs(w));
        }
        double u = b->u_in + t * w;
        double f = p->at(p->ctx, k, u, limit, xin);
        const int side = f <= limit ? 1 : 2;
        same = side == last ? same + 1 : 1;
        last = side;
        if (t == 0.5)
            same = 0;
        if (f <= limit) {
            b->u_in = u;
            b->f_in = f;
            r_in = rise(p, f);
            /* the Illinois rule: an end kept twice in a row has its rise drawn halfway towards
            ** the threshold, so that the next line falls beyond the end */
            if (same >= 2)
                r_out = r_lim + 0.5 * (r_out - r_lim);
        } else {
            b->u_out = u;
            b->f_out = f;
            r_out = rise(p, f);
            b->infeasible = f >= CF_LSQ_HUGE_OBJ;
            if (same >= 2)
                r_in = r_lim - 0.5 * (r_lim - r_in);
        }
    }
}

/* One end of the profile interval of quantity k (dir = -1 low, +1 high), in log units from the
** value v[k]; *out receives the end and *out_bit the bit of the bound it reached. */
static void profile_end(const cf_profile *p, int k, const double *v, double limit, int dir,
                        double h, double *out, unsigned *out_bit)
{
    double xin[CF_PROFILE_X] = {0};
    int j = 0;
    if (p->start) {
        p->start(p->ctx, k, v, xin);
    } else {
        if (k != 0)
            xin[j++] = log(v[0]);
        if (k != 1)
            xin[j] = v[1];
    }
    const double u0 = log(v[k]);
    end_bracket b = {u0, NAN, p->with_rss0 ? p->rss0 : NAN, NAN, 0};
    unsigned end_bit = 0;
    if (end_walk(p, k, limit, dir, h, xin, &b, &end_bit) == 2) {
        end_refine(p, k, limit, u0, xin, &b);
        if (b.infeasible) /* the end is where the type's limits close, not the threshold */
            end_bit = p->closed(p->ctx, k, b.u_in, xin);
    }
    /* exp(log(v)) may differ from v in the last bit: the interval always holds the value */
    *out = dir < 0 ? fmin(exp(b.u_in), v[k]) : fmax(exp(b.u_in), v[k]);
    *out_bit = end_bit;
}

void cf_profile_interval(const cf_profile *p, int k, const double *v, double limit, double se,
                         double out[2], unsigned end[2])
{
    double h = se > 0 ? fmin(0.5 * se / v[k], 0.1) : 0.01;
    h = fmax(h, 1e-13);
    profile_end(p, k, v, limit, -1, h, &out[0], &end[0]);
    profile_end(p, k, v, limit, +1, h, &out[1], &end[1]);
}

void cf_profile_intervals(const cf_profile *p, const double v[3], double limit, unsigned why,
                          cf_fit_result *res)
{
    for (int k = 0; k < 3; k++) {
        cf_profile_interval(p, k, v, limit, res->ident_se.v[k], res->interval[k],
                            res->interval_end[k]);
        res->interval_ok[k] = 1;
        res->interval_why[k] = why;
    }
}

int cf_profile_needed(const cf_fit_result *res, const double lo[3], const double hi[3],
                      unsigned why)
{
    const double *v = res->ident.v;
    int need = why != 0;
    for (int k = 0; k < 3; k++)
        need = need || res->ident_se.v[k] < 0 || v[k] - 1.96 * res->ident_se.v[k] < lo[k] ||
               v[k] + 1.96 * res->ident_se.v[k] > hi[k];
    return need;
}

void cf_fit_corr3(cf_fit_result *res, double corr[3][3])
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            res->corr[a][b] = corr[a][b];
}
