/*
** Least squares in the identifiable quantities through the lattice (see cell_problem.h).
*/
#include "fit/cell_problem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <nlopt.h>

#include "model/family.h"
#include "fit/lsq.h"
#include "fit/profile.h"

/* A profile's local search: relative step tolerance and curves per point. */
#define PROFILE_XTOL 1e-6
#define PROFILE_EVALS 200
/* Relative step of the central differences of the Jacobian: the cell's curves are solved to
** rounding level, so 1e-4 leaves about 8 digits in each derivative. */
#define FD_STEP 1e-4

cf_status cf_cell_problem_init(cf_cell_problem *p, const cf_table *d, const cf_fit_options *opt,
                               cf_spring_type type,
                               int (*curve)(void *ctx, double rho, double B, double *out),
                               double (*A_max)(void *ctx, double rho, double B), void *ctx,
                               cf_error *err)
{
    const size_t n = d->count ? d->count : 1;
    double *sw = malloc(sizeof(double) * n);
    *p = (cf_cell_problem){.curve = curve, .A_max = A_max, .ctx = ctx, .n = d->count, .y = d->y,
                           .sw = sw, .opt = opt, .type = type, .g = malloc(sizeof(double) * n)};
    if (!sw || !p->g)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", d->count);
    p->ynorm = cf_lsq_weights(d, opt->relative, sw);
    return CF_OK;
}

void cf_cell_problem_free(cf_cell_problem *p)
{
    free((double *)p->sw);
    free(p->g);
    p->sw = NULL;
    p->g = NULL;
}

double cf_cell_rss(cf_cell_problem *p, double rho, double B, double *A_out)
{
    p->evals++;
    *A_out = 0;
    double A_max;
    if (p->A_max) {
        if (!((A_max = p->A_max(p->ctx, rho, B)) > 0))
            return CF_LSQ_HUGE_OBJ;
    } else if (cf_fit_ident_limit(p->opt, p->type, rho, B, &A_max, NULL) > 0) {
        return CF_LSQ_HUGE_OBJ;
    }
    if (p->A_fixed > 0 && p->A_fixed > A_max * (1 + 1e-9))
        return CF_LSQ_HUGE_OBJ;
    if (p->curve(p->ctx, rho, B, p->g) != 0)
        return CF_LSQ_HUGE_OBJ;
    double A = p->A_fixed;
    if (!(A > 0)) {
        double gy = 0, gg = 0;
        for (size_t i = 0; i < p->n; i++) {
            double w = p->sw[i] * p->sw[i];
            gy += w * p->g[i] * p->y[i];
            gg += w * p->g[i] * p->g[i];
        }
        A = fmin(gy / gg, A_max);
    }
    if (!(A > 0) || !isfinite(A))
        return CF_LSQ_HUGE_OBJ;
    double sum = 0;
    for (size_t i = 0; i < p->n; i++) {
        double r = p->sw[i] * (A * p->g[i] - p->y[i]);
        sum += r * r;
    }
    *A_out = A;
    return isfinite(sum) ? sum : CF_LSQ_HUGE_OBJ;
}

nlopt_result cf_cell_search(cf_cell_problem *p, nlopt_algorithm alg, unsigned n, const double *lb,
                            const double *ub, const double *step, double xtol, int maxeval,
                            nlopt_func f, void *data, double *z, double *fz)
{
    *fz = CF_LSQ_HUGE_OBJ;
    nlopt_opt o = nlopt_create(alg, n);
    int oom = !o;
    if (o) {
        oom |= nlopt_set_lower_bounds(o, lb) == NLOPT_OUT_OF_MEMORY;
        oom |= nlopt_set_upper_bounds(o, ub) == NLOPT_OUT_OF_MEMORY;
        oom |= nlopt_set_min_objective(o, f, data) == NLOPT_OUT_OF_MEMORY;
        oom |= nlopt_set_initial_step(o, step) == NLOPT_OUT_OF_MEMORY;
        nlopt_set_xtol_rel(o, xtol);
        nlopt_set_maxeval(o, maxeval);
    }
    nlopt_result r = oom ? NLOPT_OUT_OF_MEMORY : nlopt_optimize(o, z, fz);
    nlopt_destroy(o);
    p->oom |= r == NLOPT_OUT_OF_MEMORY;
    return r;
}

/* The profile's objective: x = (log rho, B) without the quantity held (k_held in the context). */
typedef struct prof_ctx {
    cf_cell_problem *p;
    int k;
    double held; /* the held quantity's value */
} prof_ctx;

static double prof_objective(unsigned nx, const double *x, double *grad, void *data)
{
    (void)nx;
    (void)grad;
    prof_ctx *q = data;
    double rho = q->k == 0 ? q->held : exp(x[0]);
    double B = q->k == 1 ? q->held : q->k == 0 ? x[0] : x[1];
    double A;
    return cf_cell_rss(q->p, rho, B, &A);
}

/* The profile of quantity k at exp(u): the RSS minimised over the other quantities from x (one
** of log rho, B by COBYLA; both by BOBYQA when the stress scale is held). */
static double profile_at(void *ctx, int k, double u, double limit, double *x)
{
    cf_cell_problem *p = ctx;
    prof_ctx q = {p, k, exp(u)};
    unsigned nx = k == 2 ? 2 : 1;
    double lb[2], ub[2], z[2] = {x[0], x[1]};
    for (unsigned j = 0; j < nx; j++) {
        int dim = k == 0 ? 1 : (int)j; /* which of (log rho, B) x[j] is */
        lb[j] = p->lb[dim];
        ub[j] = p->ub[dim];
        z[j] = fmin(fmax(z[j], lb[j]), ub[j]);
    }
    p->A_fixed = k == 2 ? exp(u) : 0;
    double f = CF_LSQ_HUGE_OBJ, step[2] = {0.05, 0.02 * (p->ub[1] - p->lb[1])};
    if (k == 0)
        step[0] = step[1];
    nlopt_result res = cf_cell_search(p, nx == 2 ? NLOPT_LN_BOBYQA : NLOPT_LN_COBYLA, nx, lb, ub,
                                      step, PROFILE_XTOL, PROFILE_EVALS, prof_objective, &q, z,
                                      &f);
    if (res < 0 && f < CF_LSQ_HUGE_OBJ)
        f = prof_objective(nx, z, NULL, &q);
    p->A_fixed = 0;
    if (f <= limit)
        memcpy(x, z, sizeof z);
    return f;
}

/* Where the profile of k has no admissible point past its last one (exp(u), x): the stress
** scale's cap, or the type's limits whose edge is there (the bounds when none is known). */
static unsigned profile_closed(void *ctx, int k, double u, const double *x)
{
    const cf_cell_problem *p = ctx;
    if (k == 2)
        return CF_C_G_MAX;
    double rho = k == 0 ? exp(u) : exp(x[0]), B = k == 1 ? exp(u) : x[0], A_max;
    unsigned bits = 0;
    cf_fit_ident_limit(p->opt, p->type, rho, B, &A_max, &bits);
    return bits ? bits : CF_C_BOUNDS;
}

/* The limits the quantities v sit on: the search box and the stress scale's cap. */
static unsigned held_at(const cf_cell_problem *p, const double v[3])
{
    unsigned held = 0;
    const double tol = 1e-6;
    if (log(v[0]) <= p->lb[0] + tol)
        held |= p->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS;
    if (log(v[0]) >= p->ub[0] - tol)
        held |= p->type == CF_TELESCOPING ? CF_C_TYPE : CF_C_DIAMETERS;
    if (v[1] <= p->lb[1] * (1 + tol))
        held |= CF_C_TRAVEL;
    double A_max;
    unsigned edge = 0;
    const double margin = cf_fit_ident_limit(p->opt, p->type, v[0], v[1], &A_max, &edge);
    if (margin <= 0 && v[2] >= A_max * (1 - tol))
        held |= CF_C_G_MAX;
    /* on the edge of the region where a spring of the type can be placed (log units): the
    ** limits that draw that edge hold the fit, as a box bound would */
    if (margin <= 0 && margin >= -tol)
        held |= edge;
    return held;
}

/* J^T W J of the model A g(rho, B) at v by central differences in rho and B (one-sided where a
** step would leave the search box) and the weighted RSS there; 0, or nonzero when a curve fails. */
static int normal_matrix(cf_cell_problem *p, const double v[3], double *gp, double *gm,
                         double jtj[3][3], double *rss)
{
    double *d[2] = {gp, gm}, *col[3];
    double *g0 = malloc(sizeof(double) * p->n), *dr = malloc(sizeof(double) * p->n),
           *dB = malloc(sizeof(double) * p->n);
    int bad = !g0 || !dr || !dB || p->curve(p->ctx, v[0], v[1], g0) != 0;
    col[0] = dr, col[1] = dB, col[2] = g0;
    for (int j = 0; j < 2 && !bad; j++) {
        double lo = j == 0 ? exp(p->lb[0]) : p->lb[1], hi = j == 0 ? exp(p->ub[0]) : p->ub[1];
        double qp = fmin(v[j] * (1 + FD_STEP), hi), qm = fmax(v[j] * (1 - FD_STEP), lo);
        for (int s = 0; s < 2 && !bad; s++) {
            double q = s ? qm : qp;
            bad = p->curve(p->ctx, j == 0 ? q : v[0], j == 1 ? q : v[1], d[s]) != 0;
        }
        for (size_t i = 0; i < p->n && !bad; i++)
            col[j][i] = v[2] * (gp[i] - gm[i]) / (qp - qm);
    }
    p->evals += 5;
    *rss = 0;
    memset(jtj, 0, 9 * sizeof(double));
    for (size_t i = 0; i < p->n && !bad; i++) {
        double w = p->sw[i] * p->sw[i], r = p->sw[i] * (v[2] * g0[i] - p->y[i]);
        *rss += r * r;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                jtj[a][b] += w * col[a][i] * col[b][i];
    }
    int oom = !g0 || !dr || !dB;
    free(g0);
    free(dr);
    free(dB);
    return oom ? -1 : bad;
}

cf_status cf_cell_uncertainty(cf_cell_problem *p, cf_cell_problem *prof, cf_fit_result *res,
                              cf_error *err)
{
    const double *v = res->ident.v;
    for (int k = 0; k < 3; k++) {
        res->ident_se.v[k] = -1;
        res->interval_ok[k] = 0;
        for (int m = 0; m < 3; m++)
            res->corr[k][m] = NAN;
    }
    double *gp = malloc(sizeof(double) * p->n), *gm = malloc(sizeof(double) * p->n);
    double jtj[3][3], rss = 0;
    int bad = !gp || !gm ? -1 : normal_matrix(p, v, gp, gm, jtj, &rss);
    free(gp);
    free(gm);
    int rank_def = 1;
    double corr[3][3];
    if (bad == 0) {
        rank_def = cf_lsq_covariance(jtj, rss, p->n, res->ident_se.v, corr);
        cf_fit_corr3(res, corr);
    }
    if (bad < 0 || rank_def < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the errors of %zu rows",
                            p->n);
    res->held = held_at(p, v);
    unsigned why = res->held | (rank_def ? CF_FIT_RANK_DEFICIENT : 0);
    const double lo[3] = {exp(p->lb[0]), p->lb[1], 0}, hi[3] = {exp(p->ub[0]), p->ub[1],
                                                                INFINITY};
    if (!cf_profile_needed(res, lo, hi, why) || prof->n <= 3)
        return CF_OK;
    prof->A_fixed = v[2];
    double A, rss0 = cf_cell_rss(prof, v[0], v[1], &A);
    prof->A_fixed = 0;
    if (!(rss0 < CF_LSQ_HUGE_OBJ))
        return CF_OK;
    const cf_profile pr = {
        .ctx = prof,
        .lo = {prof->lb[0], log(prof->lb[1]), -INFINITY},
        .hi = {prof->ub[0], log(prof->ub[1]), log(CF_MEASURE_MAX_VALUE)},
        .lo_bit = {p->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS, CF_C_TRAVEL,
                   0},
        .hi_bit = {p->type == CF_TELESCOPING ? CF_C_TYPE : CF_C_DIAMETERS, CF_C_BOUNDS,
                   CF_C_BOUNDS},
        .at = profile_at,
        .closed = profile_closed};
    cf_profile_intervals(&pr, v, cf_profile_limit(prof->n, rss0, prof->ynorm), why, res);
    if (prof->oom)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in a profile's optimiser (NLopt)");
    return CF_OK;
}
