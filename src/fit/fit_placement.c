/*
** Stages B and C of the fit (see fit.h): NLopt over the free design parameters in log variables,
** placing one spring of the family stage A found (equality constraints on the three quantities,
** a preferred design as objective) and polishing it on the weighted least-squares objective under
** the design constraints.
*/
#include <math.h>
#include <string.h>

#include <nlopt.h>

#include "fit/fit_ctx.h"
#include "fit/lsq.h"

void cf_fit_full_params(const fit_ctx *c, const double *z, double *p)
{
    memcpy(p, c->base, sizeof c->base);
    for (int k = 0; k < c->nfree; k++)
        p[c->free_idx[k]] = exp(z[k]);
}

/* Weighted objective of the six-parameter model, normalised by that of the zero model. */
double cf_fit_objective6(fit_ctx *c, const double *p)
{
    cf_spring s = from_array(p);
    cf_law law;
    if (cf_law_init(&law, &s, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    cf_fit_model_many(&law, c->fd, c->n, c->data->x, c->model);
    double sum = 0;
    for (size_t i = 0; i < c->n; i++) {
        double r = c->sw[i] * (c->model[i] - c->data->y[i]);
        sum += r * r;
    }
    c->evals++;
    return isfinite(sum) ? sum / c->ynorm : CF_LSQ_HUGE_OBJ;
}

/* Central-difference gradient of a scalar function of z. */

static void fd_grad(fit_ctx *c, zfun f, int which, const double *z, double *grad)
{
    double zz[CF_P_COUNT];
    memcpy(zz, z, sizeof(double) * (size_t)c->nfree);
    for (int k = 0; k < c->nfree; k++) {
        double h = 1e-6 * fmax(1.0, fabs(z[k]));
        zz[k] = z[k] + h;
        double fp = f(c, zz, which);
        zz[k] = z[k] - h;
        double fm = f(c, zz, which);
        zz[k] = z[k];
        grad[k] = (fp - fm) / (2 * h);
    }
}

double cf_fit_z_objective(fit_ctx *c, const double *z, int which)
{
    (void)which;
    double p[CF_P_COUNT];
    cf_fit_full_params(c, z, p);
    return cf_fit_objective6(c, p);
}

/* log(ident(p)) - log(target): the equality constraints of placement */
static double z_equality(fit_ctx *c, const double *z, int which)
{
    double p[CF_P_COUNT];
    cf_fit_full_params(c, z, p);
    cf_spring sp = from_array(p);
    const cf_ident id = cf_ident_of_type(&sp, c->type, c->fd);
    double v = id.v[which] > 0 ? log(id.v[which]) - log(c->target[which]) : 50.0;
    return isfinite(v) ? v : 50.0;
}

/* Preference of placement: a practical spring index, a handful of coils, the preferred H. */
static double z_preference(fit_ctx *c, const double *z, int which)
{
    (void)which;
    double p[CF_P_COUNT];
    cf_fit_full_params(c, z, p);
    double a = log(p[CF_P_D1] / p[CF_P_D]) - c->pref[0];
    double b = log(p[CF_P_N]) - c->pref[1];
    double h = log(p[CF_P_H]) - c->pref[2];
    return a * a + b * b + h * h;
}

/* The gradient of cf_fit_z_objective from one pass over the rows: the model sees the spring only
** through its family (rho, the length scale B, the load scale A), so the gradient is that of the
** reduced model in (rho, B, A), from the canonical law's derivatives, times the family's
** derivatives in z, by central differences that need no rows. 0 (grad untouched) where the family
** is not defined, or where the geometry is not of the type being fitted: there the family jumps
** across the type's boundary, and the search outside the type's limits keeps the differences of
** the objective itself (measured: the analytic gradient there led a fit that no spring of the type
** can meet to another infeasible spring, of H = 356 mm and the largest G). */
static int objective_grad(fit_ctx *c, const double *z, double *grad)
{
    double p[CF_P_COUNT], zz[CF_P_COUNT];
    cf_fit_full_params(c, z, p);
    cf_spring sp = from_array(p);
    cf_law law;
    if (cf_law_init(&law, &sp, NULL) != CF_OK || law.type != c->type)
        return 0;
    const cf_ident id = cf_ident_of_type(&sp, c->type, c->fd);
    const double rho = id.v[0], B = id.v[1], A = id.v[2];
    if (!(rho > 0 && B > 0 && A > 0 && isfinite(A) && isfinite(B)) ||
        cf_ident_canon_many_rho(rho, B, c->n, c->data->x, c->model, c->gt, c->gr) != CF_OK)
        return 0;
    double sr = 0, st = 0, sa = 0;
    for (size_t i = 0; i < c->n; i++) {
        double r = c->sw[i] * c->sw[i] * (A * c->model[i] - c->data->y[i]);
        sa += r * c->model[i];
        sr += r * c->gr[i];
        st += r * c->gt[i] * c->data->x[i];
    }
    c->evals++;
    const double dv[3] = {2 * A * sr / c->ynorm, -2 * A * st / (B * B * c->ynorm),
                          2 * sa / c->ynorm};
    memcpy(zz, z, sizeof(double) * (size_t)c->nfree);
    for (int k = 0; k < c->nfree; k++) {
        double h = 1e-6 * fmax(1.0, fabs(z[k])), q[CF_P_COUNT];
        cf_ident v[2];
        for (int side = 0; side < 2; side++) {
            zz[k] = z[k] + (side ? -h : h);
            cf_fit_full_params(c, zz, q);
            sp = from_array(q);
            v[side] = cf_ident_of_type(&sp, c->type, c->fd);
        }
        zz[k] = z[k];
        double g = 0;
        for (int j = 0; j < 3; j++)
            g += dv[j] * (v[0].v[j] - v[1].v[j]) / (2 * h);
        if (!isfinite(g))
            return 0;
        grad[k] = g;
    }
    return 1;
}

typedef struct nl_thunk {
    fit_ctx *c;
    zfun f;
    int which;
} nl_thunk;

static double nl_func(unsigned n, const double *z, double *grad, void *data)
{
    (void)n;
    nl_thunk *t = data;
    if (grad && !(t->f == cf_fit_z_objective && objective_grad(t->c, z, grad)))
        fd_grad(t->c, t->f, t->which, z, grad);
    return t->f(t->c, z, t->which);
}

/* The design constraints as one vector (the travel one left out when it cannot be met), with
** their central-difference gradients: one evaluation of all of them per point. */
static void nl_constraints(unsigned m, double *result, unsigned n, const double *z, double *grad,
                           void *data)
{
    fit_ctx *c = data;
    double p[CF_P_COUNT], g[NCON], zz[CF_P_COUNT];
    const int skip = c->travel_ok ? -1 : CON_TRAVEL;
    cf_fit_full_params(c, z, p);
    cf_fit_constraint_values(p, c->type, c->xmax, c->fd, c->opt, g);
    for (int k = 0, i = 0; k < NCON && i < (int)m; k++)
        if (k != skip)
            result[i++] = g[k] + SAFETY;
    if (!grad)
        return;
    memcpy(zz, z, sizeof(double) * n);
    for (unsigned v = 0; v < n; v++) {
        double h = 1e-6 * fmax(1.0, fabs(z[v])), gp[NCON], gm[NCON];
        zz[v] = z[v] + h;
        cf_fit_full_params(c, zz, p);
        cf_fit_constraint_values(p, c->type, c->xmax, c->fd, c->opt, gp);
        zz[v] = z[v] - h;
        cf_fit_full_params(c, zz, p);
        cf_fit_constraint_values(p, c->type, c->xmax, c->fd, c->opt, gm);
        zz[v] = z[v];
        for (int k = 0, i = 0; k < NCON && i < (int)m; k++)
            if (k != skip)
                grad[(size_t)(i++) * n + v] = (gp[k] - gm[k]) / (2 * h);
    }
}

nlopt_algorithm cf_fit_algorithm_of(cf_fit_optimizer o)
{
    switch (o) {
    case CF_OPT_COBYLA: return NLOPT_LN_COBYLA;
    case CF_OPT_MMA: return NLOPT_LD_MMA;
    case CF_OPT_SLSQP: break;
    }
    return NLOPT_LD_SLSQP;
}

/* Runs NLopt with the free variables z (in/out); objective `obj`, the six inequality constraints
** (the travel one left out when it cannot be met), optionally the three placement equalities. */
void cf_fit_nl_run(fit_ctx *c, nlopt_algorithm alg, zfun obj, int equalities, double *z,
                   int maxeval)
{
    unsigned nf = (unsigned)c->nfree;
    if (nf == 0)
        return;
    nlopt_opt o = nlopt_create(alg, nf);
    if (!o) {
        c->oom = 1;
        return;
    }
    double lb[CF_P_COUNT], ub[CF_P_COUNT];
    for (int k = 0; k < c->nfree; k++) {
        lb[k] = log(c->opt->lower[c->free_idx[k]]);
        ub[k] = log(c->opt->upper[c->free_idx[k]]);
        z[k] = fmin(fmax(z[k], lb[k]), ub[k]);
    }
    int set_oom = nlopt_set_lower_bounds(o, lb) == NLOPT_OUT_OF_MEMORY;
    set_oom |= nlopt_set_upper_bounds(o, ub) == NLOPT_OUT_OF_MEMORY;
    nl_thunk to = {c, obj, 0}, te[3];
    set_oom |= nlopt_set_min_objective(o, nl_func, &to) == NLOPT_OUT_OF_MEMORY;
    const double ctol[NCON] = {0};
    set_oom |= nlopt_add_inequality_mconstraint(o, c->travel_ok ? NCON : NCON - 1, nl_constraints,
                                                c, ctol) == NLOPT_OUT_OF_MEMORY;
    if (equalities)
        for (int k = 0; k < 3; k++) {
            te[k] = (nl_thunk){c, z_equality, k};
            set_oom |=
                nlopt_add_equality_constraint(o, nl_func, &te[k], 1e-12) == NLOPT_OUT_OF_MEMORY;
        }
    if (set_oom) {
        c->oom = 1;
        nlopt_destroy(o);
        return;
    }
    nlopt_set_xtol_rel(o, c->opt->xtol_rel);
    nlopt_set_ftol_abs(o, 1e-16);
    if (c->stat_tol > 0)
        nlopt_set_ftol_rel(o, c->stat_tol);
    if (obj == cf_fit_z_objective) /* a fit at rounding level cannot be polished further */
        nlopt_set_stopval(o, LM_FLOOR_REL);
    nlopt_set_maxeval(o, maxeval);
    double f;
    double zs[CF_P_COUNT];
    memcpy(zs, z, sizeof(double) * nf);
    nlopt_result r = nlopt_optimize(o, z, &f);
    c->oom |= r == NLOPT_OUT_OF_MEMORY;
    int bad = r < 0 && r != NLOPT_ROUNDOFF_LIMITED;
    for (int k = 0; k < c->nfree; k++)
        bad = bad || !isfinite(z[k]);
    if (bad)
        memcpy(z, zs, sizeof(double) * nf); /* keep the start rather than a broken point */
    nlopt_destroy(o);
}

/* An analytic member of the family: preferred index (moved into the type's feasible range),
** a few coils, the preferred free length, G from the load scale. Fixed values override. */
static void analytic_member(const fit_ctx *c, const double v[3], double *p)
{
    const double rho = v[0], cmax = c->opt->index_max;
    double cidx = exp(c->pref[0]), n = exp(c->pref[1]);
    double lim = (1 - rho) / (2 * rho); /* telescoping <=> n <= c lim */
    if (c->type == CF_TELESCOPING) {
        if (cidx * lim < 2)
            cidx = fmin(cmax, 2.0 / fmax(lim, 1e-300) * (1 + 1e-6));
        n = fmax(2.0, fmin(n, cidx * lim * (1 - 1e-6)));
    } else if (n <= cidx * lim) {
        n = cidx * lim * 1.05 + 1e-3;
    }
    double H, s;
    if (c->fd) {
        s = v[1];
        H = fmax(c->opt->H_preferred_mm, 2 * s);
    } else {
        H = c->opt->H_preferred_mm;
        s = v[1] * H;
    }
    double Lmin = H - s;
    double d = c->type == CF_TELESCOPING ? Lmin : Lmin / n;
    double D1 = cidx * d, D2 = D1 / rho;
    double FC = c->fd ? v[2] : v[2] * H * H;
    double G = cf_ident_G_of_FC(FC, n, D1, d, s);
    const double q[CF_P_COUNT] = {D1, D2, n, d, G, H};
    for (int k = 0; k < CF_P_COUNT; k++)
        p[k] = c->opt->fixed[k] ? c->opt->fixed_value[k] : q[k];
}

/* SLSQP meets the equality constraints to its tolerance only; where D2, H and G are free they
** are set from the identifiable quantities in closed form so that the spring reproduces them to
** rounding. Kept only when the constraints still hold. */
static void snap_to_family(fit_ctx *c, double *p, double *z)
{
    double q[CF_P_COUNT];
    memcpy(q, p, sizeof q);
    const double *v = c->target;
    const int *fx = c->opt->fixed;
    if (!fx[CF_P_D2])
        q[CF_P_D2] = q[CF_P_D1] / v[0];
    double Lmin = lmin_of(q, c->type);
    if (!fx[CF_P_H])
        q[CF_P_H] = c->fd ? Lmin + v[1] : Lmin / (1 - v[1]);
    double s = q[CF_P_H] - Lmin;
    if (!fx[CF_P_G] && s > 0) {
        double FC = c->fd ? v[2] : v[2] * q[CF_P_H] * q[CF_P_H];
        double D1 = q[CF_P_D1], d = q[CF_P_D];
        q[CF_P_G] = cf_ident_G_of_FC(FC, q[CF_P_N], D1, d, s);
    }
    cf_spring sp = from_array(q);
    if (!cf_fit_check_at(c, &sp, NULL, NULL))
        return;
    memcpy(p, q, sizeof q);
    for (int k = 0; k < c->nfree; k++)
        z[k] = log(p[c->free_idx[k]]);
}

/* Stage B: places a spring of the family with identifiable quantities v (p, z out). */
void cf_fit_stage_b(fit_ctx *c, const double v[3], double *p, double *z)
{
    memcpy(c->target, v, sizeof c->target);
    if (!(c->region && cf_fit_region_member(c, v, p)))
        analytic_member(c, v, p);
    for (int k = 0; k < c->nfree; k++)
        z[k] = log(p[c->free_idx[k]]);
    double p0[CF_P_COUNT], z0[CF_P_COUNT];
    memcpy(p0, p, sizeof p0);
    memcpy(z0, z, sizeof z0);
    cf_spring sp = from_array(p0);
    int feas0 = cf_fit_check_at(c, &sp, NULL, NULL);
    cf_fit_nl_run(c, NLOPT_LD_SLSQP, z_preference, 1, z, 2000);
    cf_fit_full_params(c, z, p);
    snap_to_family(c, p, z);
    sp = from_array(p);
    if (feas0 && !cf_fit_check_at(c, &sp, NULL, NULL)) {
        memcpy(p, p0, sizeof p0); /* keep the feasible start rather than a worse point */
        memcpy(z, z0, sizeof z0);
    }
}
