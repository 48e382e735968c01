/*
** The spring type's limits in the space of the identifiable quantities (stress-strain tables, no
** fixed parameter; family.h gives them in closed form): stage A under those limits when its
** optimum lies outside, the limits a result sits on, and a member of the family within them for
** the placement to start from.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_rng.h>
#include <nlopt.h>

#include "fit/fit_ctx.h"
#include "fit/lsq.h"

/* The design limits of options o as the family's space sees them. */
static cf_ident_design design_of(const cf_fit_options *o)
{
    cf_ident_design d = {o->lower[CF_P_N], o->upper[CF_P_N], o->upper[CF_P_G], o->D2_over_H_max,
                         o->index_max, o->rho_min};
    return d;
}

region cf_fit_region_at(const fit_ctx *c, double rho, double B)
{
    region r = {-1.0, INFINITY, 0, 0};
    if (!c->region)
        return r;
    const cf_ident_design d = design_of(c->opt);
    return cf_ident_region_at(&d, c->type, rho, B, c->inside);
}

double cf_fit_ident_limit(const cf_fit_options *opt, cf_spring_type type, double rho, double B,
                          double *A_max, unsigned *bits)
{
    fit_ctx c;
    memset(&c, 0, sizeof c);
    c.opt = opt;
    c.type = type;
    c.region = 1;
    c.inside = REGION_SAFETY;
    for (int k = 0; k < CF_P_COUNT; k++)
        c.region &= !opt->fixed[k];
    region r = cf_fit_region_at(&c, rho, B);
    *A_max = r.A_max;
    if (bits)
        *bits = r.lo_bit | r.hi_bit;
    return r.margin;
}

#define RSS_LANES 4
#if defined(__GNUC__) && !defined(__clang__)
#define RSS_UNROLL _Pragma("GCC unroll 4")
#else
#define RSS_UNROLL
#endif

static double lanes_sum(const double p[RSS_LANES])
{
    return (p[0] + p[1]) + (p[2] + p[3]);
}

/* The weighted RSS of the reduced model at (rho, B) with the load scale A fixed (A_fixed > 0) or
** solved in closed form and clamped to (0, A_max]; *A_out the scale used. With d (not NULL) also
** its partial derivatives at that A: d[0] in log rho, d[1] in B, d[2] in A, from one pass of the
** canonical law with its derivatives. The sum is formed from the residuals themselves, not from
** the expanded square, so that it stays exact on noiseless tables. */
static double rss_core(fit_ctx *c, double rho, double B, double A_fixed, double A_max,
                       double *A_out, double d[3])
{
    *A_out = A_fixed;
    if (!(B > 0) || cf_ident_canon_many_rho(rho, B, c->n, c->data->x, c->model,
                                            d ? c->gt : NULL, d ? c->gr : NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    /* the sums in RSS_LANES partial sums each, added at the end: RSS_LANES chains of additions in
    ** flight instead of one, whose latency was a tenth of a short table's fit */
    const size_t n = c->n;
    const double *sw = c->sw, *x = c->data->x, *y = c->data->y;
    double *m = c->model;
    double pgy[RSS_LANES] = {0}, pgg[RSS_LANES] = {0};
    const size_t whole = n - n % RSS_LANES;
    for (size_t i0 = 0; i0 < n; i0 += RSS_LANES) {
        const size_t lanes = i0 < whole ? RSS_LANES : n - whole;
        RSS_UNROLL
        for (size_t l = 0; l < lanes; l++) {
            const size_t i = i0 + l;
            const double g = sw[i] * m[i];
            m[i] = g;
            pgy[l] += g * sw[i] * y[i];
            pgg[l] += g * g;
        }
    }
    const double sgy = lanes_sum(pgy), sgg = lanes_sum(pgg);
    double A = A_fixed;
    if (!(A > 0)) {
        A = sgg > 0 ? sgy / sgg : 0;
        if (!(A > 0) || !isfinite(A))
            A = 1e-300;
        A = fmin(A, A_max);
    }
    double prs[RSS_LANES] = {0}, psr[RSS_LANES] = {0}, pst[RSS_LANES] = {0},
           psa[RSS_LANES] = {0};
    for (size_t i0 = 0; i0 < n; i0 += RSS_LANES) {
        const size_t lanes = i0 < whole ? RSS_LANES : n - whole;
        if (d) {
            RSS_UNROLL
            for (size_t l = 0; l < lanes; l++) {
                const size_t i = i0 + l;
                const double r = A * m[i] - sw[i] * y[i];
                prs[l] += r * r;
                psr[l] += r * sw[i] * c->gr[i];
                pst[l] += r * sw[i] * c->gt[i] * x[i];
                psa[l] += r * m[i];
            }
        } else {
            RSS_UNROLL
            for (size_t l = 0; l < lanes; l++) {
                const double r = A * m[i0 + l] - sw[i0 + l] * y[i0 + l];
                prs[l] += r * r;
            }
        }
    }
    const double rss = lanes_sum(prs), sr = lanes_sum(psr), st = lanes_sum(pst),
                 sa = lanes_sum(psa);
    c->evals++;
    *A_out = A;
    if (d) {
        d[0] = 2 * A * rho * sr;
        d[1] = -2 * A * st / (B * B);
        d[2] = 2 * sa;
    }
    return isfinite(rss) ? rss : CF_LSQ_HUGE_OBJ;
}

double cf_fit_rss_at(fit_ctx *c, double rho, double B, double A_fixed, double A_max,
                     double *A_out)
{
    return rss_core(c, rho, B, A_fixed, A_max, A_out, NULL);
}

void cf_fit_sub_point(const sub *q, const double *x, double *rho, double *B)
{
    int j = 0;
    *rho = q->fixed == 0 ? q->t : exp(x[j++]);
    *B = q->fixed == 1 ? q->t : x[j];
}

double cf_fit_sub_f0(const sub *q, const double *x)
{
    double rho, B, A;
    cf_fit_sub_point(q, x, &rho, &B);
    region r = cf_fit_region_at(q->c, rho, B);
    return cf_fit_rss_at(q->c, rho, B, q->fixed == 2 ? q->t : -1, r.A_max, &A);
}


/* Central differences for the gradient-based optimiser (SLSQP): the limits' margin, which needs
** no pass over the rows. */
static void sub_grad(const sub *q, double (*f)(const sub *, const double *), unsigned n,
                     const double *x, double *grad)
{
    double xx[2];
    memcpy(xx, x, sizeof(double) * n);
    for (unsigned k = 0; k < n; k++) {
        double h = 1e-7 * fmax(1.0, fabs(x[k]));
        xx[k] = x[k] + h;
        double fp = f(q, xx);
        xx[k] = x[k] - h;
        double fm = f(q, xx);
        xx[k] = x[k];
        grad[k] = (fp - fm) / (2 * h);
    }
}

/* log of the largest load scale the limits admit at x (the clamp of cf_fit_rss_at) */
static double sub_log_amax(const sub *q, const double *x)
{
    double rho, B;
    cf_fit_sub_point(q, x, &rho, &B);
    return log(cf_fit_region_at(q->c, rho, B).A_max);
}

/* The sub-problem's RSS and its analytic gradient in x from one pass over the rows: the load scale
** in closed form is optimal, so the RSS moves with x through rho and B alone, unless it is clamped
** on the limits' largest scale, which then moves it too. */
static double sub_f(unsigned n, const double *x, double *grad, void *data)
{
    const sub *q = data;
    if (!grad)
        return cf_fit_sub_f0(q, x);
    double rho, B, A, d[3];
    cf_fit_sub_point(q, x, &rho, &B);
    region r = cf_fit_region_at(q->c, rho, B);
    const double A_fixed = q->fixed == 2 ? q->t : -1;
    double f = rss_core(q->c, rho, B, A_fixed, r.A_max, &A, d);
    unsigned j = 0;
    if (q->fixed != 0)
        grad[j++] = d[0];
    if (q->fixed != 1)
        grad[j] = d[1];
    if (!(A_fixed > 0) && A >= r.A_max && isfinite(r.A_max)) {
        double da[2];
        sub_grad(q, sub_log_amax, n, x, da);
        for (unsigned k = 0; k < n; k++)
            grad[k] += d[2] * A * da[k];
    }
    for (unsigned k = 0; k < n; k++)
        if (!isfinite(grad[k]))
            grad[k] = 0;
    return f;
}

static double sub_g(unsigned n, const double *x, double *grad, void *data)
{
    const sub *q = data;
    if (grad)
        sub_grad(q, cf_fit_sub_g0, n, x, grad);
    return cf_fit_sub_g0(q, x);
}

double cf_fit_sub_g0(const sub *q, const double *x)
{
    double rho, B;
    cf_fit_sub_point(q, x, &rho, &B);
    region r = cf_fit_region_at(q->c, rho, B);
    double g = r.margin + q->c->inside;
    if (q->fixed == 2 && isfinite(r.A_max))
        g = fmax(g, log(q->t) - log(r.A_max));
    return g;
}

/* Whether no point of the sub-problem meets the type's limits, decided without a pass over the
** rows (0: not known). With rho held: the limits' margin does not grow with B for either type
** (telescoping, the upper index c_hi = min(index_max, D2max rho/(1 - B)) grows with B;
** non-telescoping, the least coil count max(n_min, n_type, 3 (1 - B)/(D2max rho)) falls with it;
** rho_min's margin does not depend on B), so the least margin over B's range is the one at its
** upper end, and when that is above cf_fit_sub_solve's admission (1e-9, and more than rounding
** above it) every search ends outside: it returns CF_LSQ_HUGE_OBJ, as the search would. The
** profile of rho reaches such points where the limits close (bisected to the end's tolerance,
** each point a failed SLSQP and a failed COBYLA run). */
int cf_fit_sub_empty(const sub *q)
{
    const double x[1] = {q->c->b_hi};
    return q->c->region && q->fixed == 0 && cf_fit_sub_g0(q, x) > 1e-9 + 1e-12;
}

/* Minimises the sub-problem from x (in/out); returns its RSS, CF_LSQ_HUGE_OBJ when no point meets
** the limits. */
double cf_fit_sub_solve(fit_ctx *c, sub *q, double *x, nlopt_algorithm alg)
{
    unsigned nv = q->fixed < 0 ? 2u : q->fixed == 2 ? 2u : 1u;
    double lb[2], ub[2];
    unsigned j = 0;
    if (q->fixed != 0) {
        lb[j] = log(c->rho_lo);
        ub[j] = log(c->rho_hi * (1 - 1e-12));
        j++;
    }
    if (q->fixed != 1) {
        lb[j] = c->b_lo;
        ub[j] = c->b_hi;
    }
    for (unsigned k = 0; k < nv; k++)
        x[k] = fmin(fmax(x[k], lb[k]), ub[k]);
    nlopt_opt o = nlopt_create(alg, nv);
    if (!o) {
        c->oom = 1;
        return CF_LSQ_HUGE_OBJ;
    }
    int set_oom = nlopt_set_lower_bounds(o, lb) == NLOPT_OUT_OF_MEMORY;
    set_oom |= nlopt_set_upper_bounds(o, ub) == NLOPT_OUT_OF_MEMORY;
    set_oom |= nlopt_set_min_objective(o, sub_f, q) == NLOPT_OUT_OF_MEMORY;
    if (c->region)
        set_oom |= nlopt_add_inequality_constraint(o, sub_g, q, 0.0) == NLOPT_OUT_OF_MEMORY;
    if (set_oom) {
        c->oom = 1;
        nlopt_destroy(o);
        return CF_LSQ_HUGE_OBJ;
    }
    nlopt_set_xtol_rel(o, 1e-9);
    nlopt_set_maxeval(o, 300);
    if (q->step > 0) {
        double dx[2];
        for (unsigned k = 0; k < nv; k++)
            dx[k] = q->step * (ub[k] - lb[k]);
        nlopt_set_initial_step(o, dx);
    }
    double f = CF_LSQ_HUGE_OBJ;
    nlopt_result r = nlopt_optimize(o, x, &f);
    c->oom |= r == NLOPT_OUT_OF_MEMORY;
    nlopt_destroy(o);
    if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED)
        f = cf_fit_sub_f0(q, x);
    if (c->region && cf_fit_sub_g0(q, x) > 1e-9)
        return CF_LSQ_HUGE_OBJ;
    return f;
}

/* Stage A under the type's limits: used when the optimum over every spring lies outside them.
** The points of stage A's grid that meet the limits, ranked by the RSS with the load scale
** clamped to the type's largest (from each point's fit in closed form: pts, stage A's own when
** this fit ran it, else evaluated here at those points alone, to the same values), then SLSQP
** from the best. */
int cf_fit_stage_a_constrained(fit_ctx *c, double v[3], grid_point *pts)
{
    grid_point own[GRID * GRID];
    grid_point *gp = pts;
    if (!gp) {
        gp = own;
        cf_fit_grid_points(c, gp);
    }
    start grid[GRID * GRID];
    size_t k = 0;
    sub q = {c, -1, 0};
    for (size_t i = 0; i < GRID * GRID; i++) {
        /* the limits at the point, once: its margin (cf_fit_sub_g0's with nothing held) and the
        ** largest scale */
        const region r = cf_fit_region_at(c, gp[i].rho, gp[i].B);
        if (r.margin + c->inside > 0)
            continue;
        if (!gp[i].done)
            cf_fit_grid_value(c, &gp[i]);
        const double A = fmin(gp[i].A, r.A_max);
        grid[k].obj = gp[i].rss + (A - gp[i].A) * (A - gp[i].A) * gp[i].sgg;
        grid[k].rho = gp[i].rho;
        grid[k].B = gp[i].B;
        k++;
    }
    if (k == 0)
        return 0;
    qsort(grid, k, sizeof grid[0], cf_fit_cmp_start);
    /* the starts end once a second one reaches the best point found (to 1e-9 of its RSS and 1e-6
    ** in log rho and B): on the shipped and published tables the later starts then ended there
    ** too or higher, and the six to eight more SLSQP runs were half the cost of this stage */
    double best = CF_LSQ_HUGE_OBJ, bx[2] = {0, 0};
    for (size_t i = 0; i < k && (int)i < c->opt->multistart; i++) {
        double x[2] = {log(grid[i].rho), grid[i].B};
        double f = cf_fit_sub_solve(c, &q, x, NLOPT_LD_SLSQP);
        const int again = best < CF_LSQ_HUGE_OBJ && fabs(f - best) <= 1e-9 * best &&
                          fabs(x[0] - bx[0]) <= 1e-6 && fabs(x[1] - bx[1]) <= 1e-6;
        if (f < best) {
            best = f;
            memcpy(bx, x, sizeof bx);
        }
        if (again)
            break;
    }
    if (!(best < CF_LSQ_HUGE_OBJ))
        return 0;
    v[0] = exp(bx[0]);
    v[1] = bx[1];
    region r = cf_fit_region_at(c, v[0], v[1]);
    cf_fit_rss_at(c, v[0], v[1], -1, r.A_max, &v[2]);
    return 1;
}

/* ---- what the limits mean for a result ------------------------------------------------------- */

/* Limits the quantities v sit on (CF_C_* bits): rho_min, the travel, the type's limits. */
unsigned cf_fit_held_at(const fit_ctx *c, const double v[3])
{
    unsigned h = 0;
    if (v[0] <= fmax(c->rho_lo, c->opt->rho_min) * (1 + 1e-3))
        h |= c->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS;
    if (c->travel_ok && v[1] <= c->b_lo * (1 + 1e-5))
        h |= CF_C_TRAVEL;
    if (c->region) {
        region r = cf_fit_region_at(c, v[0], v[1]);
        if (r.margin > -10 * REGION_SAFETY)
            h |= r.lo_bit | r.hi_bit;
        if (v[2] >= r.A_max * (1 - 10 * REGION_SAFETY))
            h |= CF_C_G_MAX;
    } else if (c->rho_hi < 1 && v[0] >= c->rho_hi * (1 - 1e-4)) {
        h |= CF_C_TYPE;
    }
    return h;
}

/* A member of the family v that meets every limit, for the placement to start from (stress-strain
** tables without fixed parameters): the corner the limits leave open, then a grid over the spring
** index and the coil count for the point closest to the preferred design. 0 when none is found. */
int cf_fit_region_member(fit_ctx *c, const double v[3], double *p)
{
    const double rho = v[0], B = v[1], H = c->opt->H_preferred_mm;
    const double nmin = c->opt->lower[CF_P_N], nmax = c->opt->upper[CF_P_N];
    const double cmax = c->opt->index_max;
    double best = CF_LSQ_HUGE_OBJ;
    int found = 0;
    for (int i = -1; i <= 40; i++)
        for (int j = 0; j <= 40; j++) {
            double cidx, n;
            if (i < 0) { /* the corner of cf_ident_region_at */
                if (j > 0)
                    break;
                if (c->type == CF_TELESCOPING) {
                    cidx = fmax(3.0, 2 * nmin * rho / (1 - rho)) * (1 + 1e-5);
                    n = nmin * (1 + 1e-7);
                } else {
                    cidx = 3.0 * (1 + 1e-7);
                    n = fmax(nmin, fmax(3.0 * (1 - rho) / (2 * rho) * (1 + 1e-6),
                                        3.0 * (1 - B) / (c->opt->D2_over_H_max * rho))) *
                        (1 + 1e-5);
                }
            } else {
                cidx = 3.0 * pow(cmax / 3.0, i / 40.0);
                n = nmin * pow(nmax / nmin, j / 40.0);
            }
            double s = B * H, Lmin = H - s;
            double d = c->type == CF_TELESCOPING ? Lmin : Lmin / n;
            double D1 = cidx * d, FC = v[2] * H * H;
            double q[CF_P_COUNT] = {
                D1, D1 / rho, n, d, 8 * n * D1 * D1 * D1 * FC / (d * d * d * d * s), H};
            cf_spring sp = from_array(q);
            if (!cf_fit_check_at(c, &sp, NULL, NULL))
                continue;
            double a = log(cidx) - c->pref[0], b = log(n) - c->pref[1];
            double score = a * a + b * b;
            if (score < best) {
                best = score;
                memcpy(p, q, sizeof q);
                found = 1;
            }
        }
    return found;
}
