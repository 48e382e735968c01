/*
** The conical-tail law's pieces that its fits share (tail.h): the standard errors of the four
** identifiable quantities from a residual function, the closed-form placement of a buildable
** tailed spring and the fit result it fills, and the profile intervals of the four quantities.
** fit_tail.c fits the law to the spring, lattice_tail.c and joint.c through the cell; each calls
** these with its own residuals.
**
** Placement (closed form, like family.c's region): the spring of free length 1 with spring index 3
** and the fewest coils the type allows (the design that needs the softest wire), its tail closing
** after the cone with a gap per coil 1.5 times the cone's (less where the free length has no room)
** and at 1.6 times the table's largest strain (less where there is no room); then scaled to the
** preferred free length (every length times H keeps the stress-strain law and G).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>

#include "fit/fit_ctx.h"
#include "fit/lm.h"
#include "fit/lsq.h"
#include "fit/profile.h"
#include "fit/tail.h"

#define TAIL_GAP 1.5          /* tail gap per coil over the cone's, where the length allows */
#define TAIL_COILS_MIN 1.0    /* a tail of less than one coil is no tail: the cone gets more
                              ** coils (n >= 1/tau), up to n_max */
#define TAIL_GAP_MAX 10       /* a tail whose gap per coil would exceed ten times the cone's to
                              ** stay open past the table is no wound spring: CF_C_TRAVEL */
#define TAIL_SOLID_RATIO 1.6  /* the whole spring solid at this multiple of the table's largest
                              ** strain, where the length allows (else 1.05): the data do not
                              ** see the tail's solid, and one just past them would be warned of */

typedef struct tail_geom tail_geom;

double cf_tail_tau(int fd, double B, double th3)
{
    if (fd)
        return exp(fmin(fmax(th3, log(TAIL_TAU_LO) - 10), log(TAIL_TAU_HI)));
    return (1 - B) * (1 - 1e-9) * cf_logistic(th3) / B;
}

double cf_tail_coord(int fd, double B, double tau)
{
    if (fd)
        return log(tau);
    return cf_logit(tau * B / ((1 - B) * (1 - 1e-9)));
}

double cf_tail_tau_max(const cf_fit_options *o)
{
    const double nmin = fmax(o->lower[CF_P_N], 1.0), cap = o->upper[CF_P_N] / nmin;
    return cap > 0 && cap < TAIL_TAU_HI ? cap : TAIL_TAU_HI;
}

/* ---- standard errors ------------------------------------------------------------------------- */

void cf_tail_errors(cf_tail_residuals res, void *ctx, size_t n, const double v[4], double h_rel,
                    double rss, double se[4], double corr[4][4], double *cov_Bt)
{
    for (int k = 0; k < 4; k++) {
        se[k] = -1;
        for (int j = 0; j < 4; j++)
            corr[k][j] = NAN;
    }
    *cov_Bt = NAN;
    if (n <= 4)
        return;
    gsl_matrix *J = gsl_matrix_alloc(n, 4), *JtJ = gsl_matrix_alloc(4, 4);
    gsl_vector *fp = gsl_vector_alloc(n), *fm = gsl_vector_alloc(n);
    gsl_permutation *perm = gsl_permutation_alloc(4);
    gsl_matrix *cov = gsl_matrix_alloc(4, 4);
    int ok = J && JtJ && fp && fm && perm && cov;
    for (int k = 0; ok && k < 4; k++) {
        double vp[4], vm[4];
        memcpy(vp, v, sizeof vp);
        memcpy(vm, v, sizeof vm);
        const double h = h_rel * fabs(v[k]);
        vp[k] += h;
        vm[k] -= h;
        if (k == 0) /* rho stays within (0, 1] */
            vp[0] = fmin(vp[0], 1.0);
        const double dk = vp[k] - vm[k];
        ok = res(ctx, vp, fp) == GSL_SUCCESS && res(ctx, vm, fm) == GSL_SUCCESS;
        for (size_t i = 0; ok && i < n; i++)
            gsl_matrix_set(J, i, k, (gsl_vector_get(fp, i) - gsl_vector_get(fm, i)) / dk);
    }
    int sign;
    if (ok && gsl_blas_dgemm(CblasTrans, CblasNoTrans, 1.0, J, J, 0.0, JtJ) == GSL_SUCCESS &&
        gsl_linalg_LU_decomp(JtJ, perm, &sign) == GSL_SUCCESS &&
        fabs(gsl_linalg_LU_det(JtJ, sign)) > 0 &&
        gsl_linalg_LU_invert(JtJ, perm, cov) == GSL_SUCCESS) {
        const double s2 = rss / (double)(n - 4);
        for (int k = 0; k < 4; k++) {
            const double var = s2 * gsl_matrix_get(cov, k, k);
            se[k] = var >= 0 && isfinite(var) ? sqrt(var) : -1;
        }
        for (int k = 0; k < 4; k++)
            for (int j = 0; j < 4; j++)
                if (se[k] > 0 && se[j] > 0)
                    corr[k][j] = s2 * gsl_matrix_get(cov, k, j) / (se[k] * se[j]);
        *cov_Bt = s2 * gsl_matrix_get(cov, 1, 3);
    }
    gsl_matrix_free(J);
    gsl_matrix_free(JtJ);
    gsl_vector_free(fp);
    gsl_vector_free(fm);
    gsl_permutation_free(perm);
    gsl_matrix_free(cov);
}

/* ---- placement ------------------------------------------------------------------------------- */

/* The geometry of the placed spring at free length 1 (stress-strain form) for (rho, B, tau): its
** coils, spring index, wire, the tail's travel, and the CF_C_* bits it cannot meet. */
struct tail_geom {
    double n, c, dw, st;
    unsigned violated;
};

/* The tail's extra travel beyond the cone's gap (s_t = tau B + extra at H = 1): the least that
** keeps the tail closing after the cone and the whole spring solid past the table's largest
** strain need (0 when even that leaves no room: then CF_C_TRAVEL), and the preferred, a gap per
** coil TAIL_GAP times the cone's and the solid at TAIL_SOLID_RATIO times the table's strain. */
static double tail_extra(double B, double tau, double need, int preferred)
{
    if (preferred)
        return fmax((TAIL_GAP - 1) * tau * B,
                    fmin(need * TAIL_SOLID_RATIO - B * (1 + tau), (TAIL_GAP_MAX - 1) * tau * B));
    return fmax(1e-3 * tau * B, need * (1 + 1e-9) - B * (1 + tau));
}

static tail_geom tail_geometry(double rho, double B, double tau, cf_spring_type type,
                               double extra, const cf_fit_options *o)
{
    tail_geom g = {0, 0, 0, 0, 0};
    /* the room left for the solid lengths, 1 - u_C/H - extra, must stay positive */
    const double free_len = 1.0 - B * (1 + tau);
    if (!(extra < 0.999 * free_len)) {
        g.violated |= CF_C_TRAVEL;
        extra = 0.5 * free_len;
    }
    g.st = tau * B + extra;
    const double room = free_len - extra, cmin = 3.0;
    if (type == CF_NON_TELESCOPING) {
        /* the cone's and the tail's solid lengths n d (1 + tau) fill the room; c = 3 and the
        ** fewest coils the type and D2 <= D2_max H allow need the softest wire */
        g.c = cmin;
        const double n_type = cmin * (1 - rho) / (2 * rho) * (1 + 1e-6);
        const double n_D = cmin * room / ((1 + tau) * rho * o->D2_over_H_max);
        g.n = fmax(fmax(2.0, TAIL_COILS_MIN / tau), fmax(n_type, n_D));
        if (g.n > o->upper[CF_P_N])
            g.violated |= CF_C_COILS_MAX;
        g.dw = room / (g.n * (1 + tau));
    } else {
        /* the cone's solid length d and the tail's tau n d, with n = 2 (more when the tail would
        ** have less than a coil) */
        g.n = fmax(2.0, TAIL_COILS_MIN / tau);
        if (g.n > o->upper[CF_P_N])
            g.violated |= CF_C_COILS_MAX;
        g.dw = room / (1 + tau * g.n);
        const double c_type = 2 * g.n * rho / (1 - rho);
        const double c_D = o->D2_over_H_max * rho / g.dw;
        g.c = fmax(cmin, c_type * (1 + 1e-6)); /* strictly telescoping after rounding */
        if (g.c > fmin(o->index_max, c_D))
            g.violated |= g.c > c_D ? CF_C_D2_H : CF_C_INDEX_MAX;
    }
    /* the tail's coils are wound coils like the cone's: the same most */
    if (tau * g.n > o->upper[CF_P_N] * (1 + 1e-9))
        g.violated |= CF_C_COILS_MAX;
    return g;
}

/* The largest stress scale F_C/H^2 a spring of that geometry carries with G <= G_max:
** A = G d^4 s/(8 n D1^3) at H = 1 = G d B/(8 n c^3). */
static double tail_A_max(const tail_geom *g, double B, const cf_fit_options *o)
{
    return o->upper[CF_P_G] * g->dw * B / (8 * g->n * g->c * g->c * g->c);
}

/* A spring of the family (rho, B, A, tau) of a stress-strain table, of the given type, of free
** length H_mm, whose whole travel exceeds the strain need (the table's largest, with the margin);
** the CF_C_* bits of the limits it cannot meet go to *violated. */
static cf_spring tail_place(double rho, double B, double A, double tau, cf_spring_type type,
                            double need, double H_mm, const cf_fit_options *o,
                            unsigned *violated)
{
    /* the preferred tail where the wire allows it, else shorter, down to the least */
    const double lo = tail_extra(B, tau, need, 0), hi = fmax(tail_extra(B, tau, need, 1), lo);
    static const double share[] = {1, 0.5, 0.25, 0.1, 0};
    tail_geom g;
    double G = 0;
    for (size_t k = 0; k < sizeof share / sizeof share[0]; k++) {
        g = tail_geometry(rho, B, tau, type, lo + (hi - lo) * share[k], o);
        G = 8 * g.n * g.c * g.c * g.c * A / (g.dw * B);
        if (!(G > o->upper[CF_P_G] * (1 + 1e-9)) && !(g.violated & CF_C_TRAVEL))
            break;
    }
    *violated = g.violated;
    if (lo > (TAIL_GAP_MAX - 1) * tau * B * (1 + 1e-9))
        *violated |= CF_C_TRAVEL;
    if (G > o->upper[CF_P_G] * (1 + 1e-9))
        *violated |= CF_C_G_MAX;
    const double D1 = g.c * g.dw;
    cf_spring p = {D1 * H_mm, D1 / rho * H_mm, g.n, g.dw * H_mm, G, H_mm};
    p.n_tail = tau * g.n;
    p.H_tail_mm = (g.st + tau * g.n * g.dw) * H_mm;
    return p;
}

double cf_tail_A_max(double rho, double B, double tau, cf_spring_type type, double need,
                     const cf_fit_options *o)
{
    const tail_geom g = tail_geometry(rho, B, tau, type, tail_extra(B, tau, need, 0), o);
    const double a = tail_A_max(&g, B, o);
    return a > 0 && isfinite(a) ? a : 1e-300;
}

cf_status cf_tail_result(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                         const double v[4], const double se[4], double corr[4][4], double cov_Bt,
                         cf_fit_result *res, cf_error *err)
{
    const int fd = cf_table_is_force(data);
    const size_t n = data->count;
    const double xmax = cf_lsq_xmax(data);
    const double rho = v[0], B = v[1], A = v[2], tau = v[3];
    res->type = type;
    res->tail = 1;
    res->ident.rho = rho;
    res->ident.solid = B;
    res->ident.scale = A;
    res->q[CF_Q_TAIL] = tau * B;
    for (int q = 0; q < 3; q++)
        res->ident_se.v[q] = se[q];
    /* e_t = tau B: var = B^2 var(tau) + tau^2 var(B) + 2 tau B cov(B, tau) */
    if (se[1] > 0 && se[3] > 0 && isfinite(cov_Bt)) {
        const double var = B * B * se[3] * se[3] + tau * tau * se[1] * se[1] + 2 * tau * B * cov_Bt;
        res->q_se[CF_Q_TAIL] = var > 0 ? sqrt(var) : 0;
    } else {
        res->q_se[CF_Q_TAIL] = -1;
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            res->corr[a][b] = corr[a][b];
    /* place: a stress-strain table at the preferred free length; a force table at a free length
    ** that gives its cone travel a strain of 1/(2 (1 + tau)) */
    const double H = fd ? 2 * B * (1 + tau) : opt->H_preferred_mm;
    const double Bs = fd ? B / H : B, As = fd ? A / (H * H) : A;
    const double need = (fd ? xmax / H : xmax) * (1 + CF_FIT_TRAVEL_MARGIN);
    unsigned placed_bad;
    res->params = tail_place(rho, Bs, As, tau, type, need, H, opt, &placed_bad);
    cf_error le = {0};
    if (cf_law_init(&res->law, &res->params, &le) != CF_OK)
        return cf_error_set(err, CF_E_INTERNAL,
                            "placing the conical-tail spring (rho %g B %g A %g tau %g): %s", rho,
                            B, A, tau, le.msg);
    double *buf = malloc(2 * sizeof(double) * (n ? n : 1));
    if (!buf)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", n);
    double *sw = buf, *model = buf + n;
    const double ynorm = cf_lsq_weights(data, opt->relative, sw);
    cf_fit_model_many(&res->law, fd, n, data->x, model);
    cf_lsq_quality q = cf_lsq_quality_of(data, model);
    res->rss = q.rss;
    res->rmse = q.rmse;
    res->max_abs_error = q.max_abs_error;
    res->r2 = q.r2;
    double obj = 0;
    for (size_t i = 0; i < n; i++) {
        const double r = sw[i] * (model[i] - data->y[i]);
        obj += r * r;
    }
    free(buf);
    res->objective = obj;
    res->objective_zero = ynorm;
    res->feasible = cf_fit_check(&res->params, type, data, opt, &res->active, &res->violated);
    /* the plain check sees the cone alone: the whole travel is the law's */
    res->violated &= ~(unsigned)CF_C_TRAVEL;
    res->active &= ~(unsigned)CF_C_TRAVEL;
    const double umax = (fd ? xmax : xmax * res->params.H_mm) * (1 + CF_FIT_TRAVEL_MARGIN);
    if (!(res->law.travel_mm > umax))
        res->violated |= CF_C_TRAVEL;
    res->violated |= placed_bad;
    /* what holds the quantities: the wire's G_max (A on its largest), rho_min, the type's rho */
    const double rho_lo = fmax(CF_IDENT_RHO_LO, opt->rho_min * (1 - CF_IDENT_RHO_MIN_TOL));
    if (!fd && A >= (1 - 1e-3) * cf_tail_A_max(rho, B, tau, type, need, opt))
        res->held |= CF_C_G_MAX;
    if (rho <= rho_lo * (1 + 1e-3) && opt->rho_min > CF_IDENT_RHO_LO)
        res->held |= CF_C_RHO_MIN;
    if (tau >= cf_tail_tau_max(opt) * (1 - 1e-3) && cf_tail_tau_max(opt) < TAIL_TAU_HI)
        res->held |= CF_C_COILS_MAX; /* the tail's coils at n_max */
    if (type == CF_TELESCOPING && rho >= cf_ident_rho_hi(type, opt->index_max) * (1 - 1e-3))
        res->held |= CF_C_TYPE;
    if (res->law.type != type)
        res->violated |= CF_C_TYPE;
    res->feasible = res->violated == 0;
    res->solid_table_strain = fd ? res->law.travel_mm : res->law.travel_mm / res->params.H_mm;
    res->solid_ratio = xmax > 0 ? res->solid_table_strain / xmax : INFINITY;
    return CF_OK;
}

int cf_tail_nest(const cf_fit_result *plain, cf_fit_result *tail)
{
    if (!plain || plain->tail || !(plain->objective >= 0) || !isfinite(plain->objective))
        return 0;
    const int loses = (plain->feasible && !tail->feasible) ||
                      (plain->feasible == tail->feasible &&
                       !(tail->objective <= plain->objective * (1 + 1e-9)));
    if (!loses)
        return 0;
    const long evals = tail->evaluations, full = tail->evaluations_full;
    const double wall = tail->wall_time_s;
    /* what the tailed search ended on, for the report */
    const unsigned lost = tail->feasible ? 0 : tail->violated;
    const double lost_rmse = isfinite(tail->rmse) && isfinite(tail->objective) ? tail->rmse : 0;
    *tail = *plain;
    tail->nested_rmse = lost_rmse;
    tail->nested_violated = lost;
    tail->tail = 1;
    tail->q[CF_Q_TAIL] = 0;
    tail->q_se[CF_Q_TAIL] = 0;
    tail->interval_ok[CF_Q_TAIL] = 0;
    tail->params.n_tail = 0;
    tail->params.H_tail_mm = 0;
    /* the search's cost is the tailed fit's own */
    tail->evaluations = evals;
    tail->evaluations_full = full;
    tail->wall_time_s = wall;
    return 1;
}

/* ---- profile intervals ---------------------------------------------------------------------- */

/* The profile of one quantity k of (rho, B, A, e_t) held at `fixed`: Levenberg-Marquardt over the
** other three, in the fit's own coordinates (logit rho, logit B, the load scale as a logit of its
** cap or its log, the cone's closing strain as a logit or log tau), so that every point it tries
** is a spring the fit could have found. */
typedef struct prof_run {
    const cf_tail_profile *p;
    int k;
    double fixed;
} prof_run;

/* The largest B of the profile: with e_t held, the cone closes at B + e_t, below the free length
** of a stress-strain table. */
static double prof_b_hi(const prof_run *r)
{
    if (r->k == 3 && !r->p->fd)
        return fmin(r->p->b_hi, (1 - r->fixed) * (1 - 1e-9));
    return r->p->b_hi;
}

static double prof_A_max(const prof_run *r, const double v[4])
{
    return cf_tail_A_max(v[0], v[1], v[3], r->p->type, r->p->need, r->p->opt);
}

static void prof_unpack(const prof_run *r, const double *th, double v[4])
{
    const cf_tail_profile *p = r->p;
    double z[4];
    for (int i = 0, j = 0; i < 4; i++)
        z[i] = i == r->k ? 0 : th[j++];
    v[0] = r->k == 0 ? r->fixed : p->rho_lo + (p->rho_hi - p->rho_lo) * cf_logistic(z[0]);
    v[1] = r->k == 1 ? r->fixed : p->b_lo + (prof_b_hi(r) - p->b_lo) * cf_logistic(z[1]);
    v[3] = r->k == 3 ? r->fixed / v[1]
                     : fmin(cf_tail_tau(p->fd, v[1], z[3]), cf_tail_tau_max(p->opt));
    v[2] = r->k == 2 ? r->fixed : p->fd ? exp(z[2]) : prof_A_max(r, v) * cf_logistic(z[2]);
}

/* A logit kept 1e-9 inside its ends: a start on a bound has no slope there, and a start with every
** coordinate on one (a fit held by its limits) would give Levenberg-Marquardt a Jacobian of rank
** zero. */
static double logit_in(double p)
{
    return cf_logit(fmin(fmax(p, 1e-9), 1 - 1e-9));
}

static void prof_pack(const prof_run *r, const double v[4], double th[3])
{
    const cf_tail_profile *p = r->p;
    const double z[4] = {logit_in((v[0] - p->rho_lo) / (p->rho_hi - p->rho_lo)),
                         logit_in((v[1] - p->b_lo) / (prof_b_hi(r) - p->b_lo)),
                         p->fd ? log(v[2]) : logit_in(v[2] / prof_A_max(r, v)),
                         p->fd ? log(v[3]) : logit_in(v[3] * v[1] / ((1 - v[1]) * (1 - 1e-9)))};
    for (int i = 0, j = 0; i < 4; i++)
        if (i != r->k)
            th[j++] = z[i];
}

/* How far a stress-strain table's held load scale is past the cap where the other three now are
** (log units; 0 inside). Only the profile of A can leave the cap: the others keep A below it. */
static double prof_excess(const prof_run *r, const double v[4])
{
    if (r->k != 2 || r->p->fd)
        return 0;
    return fmax(0.0, log(v[2] / prof_A_max(r, v)));
}

/* The residuals, scaled as the fit's LM scales them; past the cap every residual grows by a steep
** factor, so that Levenberg-Marquardt turns back from a step there as from any step that raises
** the sum of squares and settles on the cap (its penalised value is then at most the true
** profile's: an interval too wide by a hair, never too narrow). */
static int prof_f(const gsl_vector *th, void *params, gsl_vector *f)
{
    const prof_run *r = params;
    double v[4];
    prof_unpack(r, th->data, v);
    int st = r->p->res(r->p->ctx, v, f);
    if (st != GSL_SUCCESS)
        return st;
    gsl_vector_scale(f, (1 + 1e4 * prof_excess(r, v)) / sqrt(r->p->ynorm));
    return GSL_SUCCESS;
}

/* A profile search's statistical tolerance relative to its RSS: a hundredth of the way from the
** fit's RSS rss0 to the threshold limit, shared by the four quantities. */
static double prof_stall(double rss0, double limit)
{
    return 1e-2 * (limit - rss0) / (4 * rss0);
}

typedef struct prof_ctx {
    const cf_tail_profile *p;
    int oom;
    double stall_rel; /* the statistical tolerance of a profile's search, relative to its RSS */
} prof_ctx;

/* The profile's search of run r from the point x, (rho, B, A, tau), with r's quantity held: the
** RSS it reaches, and in v the point. */
static double prof_search(prof_ctx *pc, const prof_run *rp, const double *x, double v[4])
{
    const prof_run r = *rp;
    const int k = r.k;
    double v0[4] = {x[0], x[1], x[2], x[3]};
    if (k == 3)
        v0[3] = r.fixed / v0[1];
    else
        v0[k] = r.fixed;
    /* forward differences: the Jacobian only steers the steps (the RSS decides), and a point
    ** costs 4 evaluations of the law per step instead of 7 */
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.fdtype = GSL_MULTIFIT_NLINEAR_FWDIFF;
    /* the SVD solves the steps: a profile far out can leave all three coordinates without effect
    ** (each on a bound of its logit, or a cell curve that no longer moves), a Jacobian of rank zero
    ** that the default QR solver reports through GSL's error handler (an abort unless the caller
    ** turned it off) where the SVD takes the zero step and the search ends */
    fp.solver = gsl_multifit_nlinear_solver_svd;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = prof_f;
    fdf.n = pc->p->m;
    fdf.p = 3;
    fdf.params = (void *)&r;
    double th0[3];
    prof_pack(&r, v0, th0);
    int ist;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, th0, &ist);
    if (!w) {
        pc->oom = 1;
        return CF_LSQ_HUGE_OBJ;
    }
    double f = CF_LSQ_HUGE_OBJ;
    v[0] = v[1] = v[2] = v[3] = NAN;
    if (ist == GSL_SUCCESS) {
        /* stop once two steps in a row lower the RSS by less than a hundredth of the residual
        ** variance (the fit's own statistical tolerance, fit.md): the ends are then placed
        ** within a few thousandths of the threshold's rise, far inside their 1 % tolerance;
        ** GSL's own tests at the parameters' rounding level */
        cf_lm_stop stop = {LM_MAX_ITER, 1e-10, 1e-12, 1e-12, 2, pc->stall_rel, LM_FLOOR_REL};
        if (cf_lm_iterate(w, &stop) < 0)
            pc->oom = 1;
        gsl_vector *res = gsl_multifit_nlinear_residual(w);
        double chi2;
        gsl_blas_ddot(res, res, &chi2);
        prof_unpack(&r, gsl_multifit_nlinear_position(w)->data, v);
        if (isfinite(chi2) && isfinite(v[0] + v[1] + v[2] + v[3]))
            f = fmin(chi2 * pc->p->ynorm, CF_LSQ_HUGE_OBJ);
    }
    gsl_multifit_nlinear_free(w);
    return f;
}

/* cf_profile's at: x holds (rho, B, A, tau) of the last point within the limit, where the search
** starts; where it ends above the limit, again from each of the fit's other optima (p->alt). */
static double prof_at(void *ctx, int k, double u, double limit, double *x)
{
    prof_ctx *pc = ctx;
    const prof_run r = {pc->p, k, exp(u)};
    if (!(prof_b_hi(&r) > pc->p->b_lo))
        return CF_LSQ_HUGE_OBJ;
    double v[4];
    double f = prof_search(pc, &r, x, v);
    for (int a = 0; a < pc->p->nalt && !(f <= limit) && !pc->oom; a++) {
        double w[4];
        const double g = prof_search(pc, &r, pc->p->alt[a], w);
        if (g < f) {
            f = g;
            memcpy(v, w, sizeof v);
        }
    }
    if (f <= limit)
        memcpy(x, v, sizeof v);
    return f;
}

/* Where a profile has no admissible point: the wire's G_max for the load scale of a stress-strain
** table, the search's bounds otherwise. */
static unsigned prof_closed(void *ctx, int k, double u, const double *x)
{
    const prof_ctx *pc = ctx;
    (void)u;
    (void)x;
    return k == 2 && !pc->p->fd ? CF_C_G_MAX : CF_C_BOUNDS;
}

/* The start of every profile: the fit itself, (rho, B, A, tau) from (rho, B, A, e_t). */
static void prof_start(void *ctx, int k, const double *q, double *x)
{
    (void)ctx;
    (void)k;
    x[0] = q[0];
    x[1] = q[1];
    x[2] = q[2];
    x[3] = q[3] / q[1];
}

int cf_tail_intervals(const cf_tail_profile *p, const double v[4], double rss0, double limit,
                      cf_fit_result *res)
{
    const double q[4] = {v[0], v[1], v[2], v[3] * v[1]};
    const double se[4] = {res->ident_se.v[0], res->ident_se.v[1], res->ident_se.v[2],
                          res->q_se[CF_Q_TAIL]};
    /* the range of each quantity: the search's box; e_t below the free length's share past the
    ** smallest cone travel (a stress-strain table) or the largest tail the search takes */
    const double et_lo = TAIL_TAU_LO * p->b_lo,
                 et_hi = p->fd ? TAIL_TAU_HI * p->b_hi : (1 - p->b_lo) * (1 - 1e-9);
    const double lo[4] = {p->rho_lo, p->b_lo, 0, et_lo}, hi[4] = {p->rho_hi, p->b_hi, INFINITY,
                                                                  et_hi};
    int singular = 0;
    for (int k = 0; k < 4; k++)
        singular = singular || !(se[k] >= 0);
    const unsigned why = res->held | (singular ? CF_FIT_RANK_DEFICIENT : 0);
    /* the plain law's rule (profile.h, cf_profile_needed), over the four: a standard error
    ** larger than half its value is one whose Wald interval reaches below zero */
    int need = why != 0;
    for (int k = 0; k < 4; k++)
        need = need || q[k] - 1.96 * se[k] < lo[k] || q[k] + 1.96 * se[k] > hi[k];
    for (int k = 0; k < 4; k++)
        need = need && q[k] > 0 && isfinite(q[k]);
    if (!need || p->m <= 4 || !(rss0 < CF_LSQ_HUGE_OBJ) || !(limit > rss0))
        return 0;
    /* the residual variance from the threshold's rise F(0.95; 1, N - 4) s^2, F about 4 */
    prof_ctx pc = {p, 0, prof_stall(rss0, limit)};
    const cf_profile pr = {
        .ctx = &pc,
        .lo = {log(p->rho_lo), log(p->b_lo), -INFINITY, log(et_lo)},
        .hi = {log(p->rho_hi * (1 - 1e-12)), log(p->b_hi), log(CF_MEASURE_MAX_VALUE), log(et_hi)},
        .lo_bit = {p->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS, CF_C_BOUNDS,
                   0, CF_C_BOUNDS},
        .hi_bit = {p->type == CF_TELESCOPING ? CF_C_TYPE : CF_C_DIAMETERS, CF_C_BOUNDS,
                   CF_C_BOUNDS, CF_C_BOUNDS},
        .at = prof_at,
        .closed = prof_closed,
        .with_rss0 = 1,
        .rss0 = rss0,
        .start = prof_start};
    double out[4][2];
    unsigned end[4][2];
    for (int k = 0; k < 4 && !pc.oom; k++)
        cf_profile_interval(&pr, k, q, limit, se[k], out[k], end[k]);
    for (int k = 0; k < 4; k++)
        for (int e = 0; e < 2; e++)
            if (!isfinite(out[k][e]))
                pc.oom |= 2; /* never reported: a non-finite end */
    if (pc.oom)
        return pc.oom & 1 ? -1 : 0;
    for (int k = 0; k < 3; k++) {
        memcpy(res->interval[k], out[k], sizeof out[k]);
        memcpy(res->interval_end[k], end[k], sizeof end[k]);
        res->interval_ok[k] = 1;
        res->interval_why[k] = why;
    }
    memcpy(res->interval[CF_Q_TAIL], out[3], sizeof out[3]);
    memcpy(res->interval_end[CF_Q_TAIL], end[3], sizeof end[3]);
    res->interval_ok[CF_Q_TAIL] = 1;
    res->interval_why[CF_Q_TAIL] = why;
    return 0;
}

double cf_tail_profile_point(const cf_tail_profile *p, int k, double value, double rss0,
                             double limit, double x[4])
{
    prof_ctx pc = {p, 0, prof_stall(rss0, limit)};
    return prof_at(&pc, k, log(value), limit, x);
}
