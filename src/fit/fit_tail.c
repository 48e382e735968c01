/*
** The fit of the conical-tail law (fit.h, cf_fit_tail_run): the cone's three identifiable quantities
** and the tail's compliance e_t, then a buildable spring of that family placed in closed form.
**
** A table sees the series spring as y = A g(x/B; rho, tau): g the canonical law of a cone of travel
** 1 and solid load 1 with a tail of tau = n_t/n coils per cone coil (law.h), A the load scale and
** B the length scale as for the plain law (family.h), and the tail's compliance e_t = tau B
** (F_C/(k_t H) of a stress-strain table, F_C/k_t in mm of a force table). The search: a grid over
** (rho, B, tau) with A in closed form (the model is linear in it), then Levenberg-Marquardt (GSL,
** central differences) in (logit rho, logit B, log A, log tau) from the best grid points and from
** the plain fit's quantities with a small tail; standard errors from the Jacobian at the optimum.
**
** Placement (closed form, like family.c's region): the spring of free length 1 with spring index 3
** and the fewest coils the type allows (the design that needs the softest wire), its tail closing
** after the cone with a gap per coil 1.5 times the cone's (less where the free length has no room)
** and at 1.6 times the table's largest strain (less where there is no room); then scaled to the preferred free length (every length
** times H keeps the stress-strain law and G).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>

#include "fit/clock.h"
#include "fit/fit_ctx.h"
#include "fit/lm.h"
#include "fit/lsq.h"
#include "fit/profile.h"
#include "fit/tail.h"

#define TAIL_GRID_RHO 10
#define TAIL_GRID_B 12
#define TAIL_GRID_TAU 9
#define TAIL_TAU_LO 1e-4 /* the search's range of tau = n_t/n */
#define TAIL_TAU_HI 1e3
#define TAIL_STARTS 6
#define TAIL_GAP 1.5          /* tail gap per coil over the cone's, where the length allows */
#define TAIL_COILS_MIN 1.0    /* a tail of less than one coil is no tail: the cone gets more
                              ** coils (n >= 1/tau), up to n_max */
#define TAIL_GAP_MAX 10       /* a tail whose gap per coil would exceed ten times the cone's to
                              ** stay open past the table is no wound spring: CF_C_TRAVEL */
#define TAIL_SEARCH_ROWS 1000
#define TAIL_SOLID_RATIO 1.6  /* the whole spring solid at this multiple of the table's largest
                              ** strain, where the length allows (else 1.05): the data do not
                              ** see the tail's solid, and one just past them would be warned of */ /* the grid runs on at most this many rows, evenly spaced */

typedef struct tail_ctx {
    const cf_table *data;
    const cf_fit_options *opt;
    int fd;
    size_t n;
    const double *sw; /* residual weights (lsq.h) */
    double ynorm;
    double *t, *g;    /* scratch: x/B and the canonical law at it */
    double rho_lo, rho_hi, b_lo, b_hi;
    size_t stride;    /* the grid's row stride */
    cf_spring_type type;
    double need;      /* the table's largest strain with the travel margin (stress-strain) */
    long evals;
} tail_ctx;

/* The canonical tailed law: the family's canonical cone (family.c: travel 1, solid load 1) with
** 2 tau tail coils of its wire and a tail travel so long that the data never reach its solid. */
static cf_status tail_canon(double rho, double tau, cf_law *law)
{
    const double n = 2.0, d = 0.5, nt = n * tau, st = tau * (1.0 + 1e6);
    cf_spring p = {rho, 1.0, n, d, 256.0 * rho * rho * rho, 2.0 + nt * d + st};
    p.n_tail = nt;
    p.H_tail_mm = nt * d + st;
    return cf_law_init(law, &p, NULL);
}

/* The canonical law at x[i]/B for the rows i = 0, stride, 2 stride, ... (into c->g, compacted);
** returns how many. */
static size_t canon_rows(tail_ctx *c, const cf_law *canon, double B, size_t stride)
{
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride)
        c->t[m++] = c->data->x[i] / B;
    cf_law_force_many(canon, CF_LAW_CLOSED, m, c->t, c->g, NULL);
    c->evals++;
    return m;
}

/* The weighted RSS with A in closed form (rows by stride); *A_out the load scale. */
static double tail_profile(tail_ctx *c, double rho, double B, double tau, size_t stride,
                           double *A_out)
{
    cf_law canon;
    *A_out = 0;
    if (tail_canon(rho, tau, &canon) != CF_OK)
        return INFINITY;
    canon_rows(c, &canon, B, stride);
    double sgy = 0, sgg = 0, syy = 0;
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride, m++) {
        const double g = c->sw[i] * c->g[m], y = c->sw[i] * c->data->y[i];
        sgy += g * y;
        sgg += g * g;
        syy += y * y;
    }
    const double A = sgg > 0 ? sgy / sgg : 0;
    if (!(A > 0) || !isfinite(A))
        return syy;
    *A_out = A;
    return fmax(syy - A * sgy, 0.0);
}

/* The weighted RSS at a given load scale A (rows by stride). */
static double tail_objective(tail_ctx *c, double rho, double B, double tau, double A,
                             size_t stride)
{
    cf_law canon;
    if (tail_canon(rho, tau, &canon) != CF_OK)
        return INFINITY;
    canon_rows(c, &canon, B, stride);
    double rss = 0;
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += stride, m++) {
        const double r = c->sw[i] * (A * c->g[m] - c->data->y[i]);
        rss += r * r;
    }
    return rss;
}

/* ---- Levenberg-Marquardt in (logit rho, logit B, log A, log tau) ----------------------------- */

typedef struct tail_geom tail_geom;
static double amax_at(const tail_ctx *c, double rho, double B, double tau);

static double sigm(double t) { return 1.0 / (1.0 + exp(-t)); }

/* The fourth coordinate: log tau for a force table; for a stress-strain table the strain at which
** the cone closes, u_C/H = B (1 + tau), as a logit between B and 1 (a spring's whole travel is
** below its free length, so u_C/H < 1). */
static double tau_fd(int fd, double B, double th3)
{
    if (fd)
        return exp(fmin(fmax(th3, log(TAIL_TAU_LO) - 10), log(TAIL_TAU_HI)));
    return (1 - B) * (1 - 1e-9) * sigm(th3) / B;
}

static double th3_fd(int fd, double B, double tau)
{
    if (fd)
        return log(tau);
    return cf_logit(tau * B / ((1 - B) * (1 - 1e-9)));
}

static double tau_of(const tail_ctx *c, double B, double th3)
{
    return tau_fd(c->fd, B, th3);
}

static double th3_of(const tail_ctx *c, double B, double tau)
{
    return th3_fd(c->fd, B, tau);
}

/* The load scale: of a stress-strain table below the largest a spring of the family carries with
** G <= G_max (a logit of A/A_max), of a force table free (log A). */
static void unpack(const tail_ctx *c, const double *th, double v[4])
{
    v[0] = c->rho_lo + (c->rho_hi - c->rho_lo) * sigm(th[0]);
    v[1] = c->b_lo + (c->b_hi - c->b_lo) * sigm(th[1]);
    v[3] = tau_of(c, v[1], th[3]);
    v[2] = c->fd ? exp(th[2]) : amax_at(c, v[0], v[1], v[3]) * sigm(th[2]);
}

/* Weighted residuals at the quantities v = (rho, B, A, tau), scaled by sc; GSL_EDOM where the
** law has no spring. */
static int residuals(tail_ctx *c, const double v[4], double sc, gsl_vector *f)
{
    cf_law canon;
    if (!isfinite(v[2]) || tail_canon(v[0], v[3], &canon) != CF_OK)
        return GSL_EDOM;
    canon_rows(c, &canon, v[1], 1);
    for (size_t i = 0; i < c->n; i++)
        gsl_vector_set(f, i, sc * c->sw[i] * (v[2] * c->g[i] - c->data->y[i]));
    return GSL_SUCCESS;
}

static int resid_at(void *ctx, const double v[4], gsl_vector *f)
{
    return residuals(ctx, v, 1.0, f);
}

/* The weighted residuals of the rows by c->stride, each times sqrt(stride): the subsample's RSS
** stands for the whole table's, so that a long table's profiles cost what its grid costs, not a
** pass over every row per point. With stride 1 they are resid_at's. */
static int resid_stride(void *ctx, const double v[4], gsl_vector *f)
{
    tail_ctx *c = ctx;
    cf_law canon;
    if (!isfinite(v[2]) || tail_canon(v[0], v[3], &canon) != CF_OK)
        return GSL_EDOM;
    canon_rows(c, &canon, v[1], c->stride);
    const double w = sqrt((double)c->stride);
    size_t m = 0;
    for (size_t i = 0; i < c->n; i += c->stride, m++)
        gsl_vector_set(f, m, w * c->sw[i] * (v[2] * c->g[m] - c->data->y[i]));
    return GSL_SUCCESS;
}

static int lm_f(const gsl_vector *th, void *params, gsl_vector *f)
{
    tail_ctx *c = params;
    double v[4];
    unpack(c, th->data, v);
    return residuals(c, v, 1.0 / sqrt(c->ynorm), f);
}

/* One LM run from v0 (rho, B, A, tau); returns the weighted RSS and the optimum in out. */
static double lm_run(tail_ctx *c, const double v0[4], double out[4])
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.fdtype = GSL_MULTIFIT_NLINEAR_CTRDIFF;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.n = c->n;
    fdf.p = 4;
    fdf.params = c;
    double th0[4] = {cf_logit((v0[0] - c->rho_lo) / (c->rho_hi - c->rho_lo)),
                     cf_logit((v0[1] - c->b_lo) / (c->b_hi - c->b_lo)),
                     c->fd ? log(v0[2]) : cf_logit(v0[2] / amax_at(c, v0[0], v0[1], v0[3])),
                     th3_of(c, v0[1], v0[3])};
    int ist;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, th0, &ist);
    if (!w)
        return INFINITY;
    double best = INFINITY;
    if (ist == GSL_SUCCESS) {
        cf_lm_stop stop = {LM_MAX_ITER, 1e-15, 1e-15, 1e-15, LM_STALL, LM_STALL_REL, LM_FLOOR_REL};
        cf_lm_iterate(w, &stop);
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        double chi2;
        gsl_blas_ddot(f, f, &chi2);
        if (isfinite(chi2)) {
            unpack(c, gsl_multifit_nlinear_position(w)->data, out);
            best = chi2 * c->ynorm;
        }
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

typedef struct tail_start {
    double obj, v[4];
} tail_start;

static int cmp_start(const void *a, const void *b)
{
    const double x = ((const tail_start *)a)->obj, y = ((const tail_start *)b)->obj;
    return (x > y) - (x < y);
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

static double amax_at(const tail_ctx *c, double rho, double B, double tau)
{
    return cf_tail_A_max(rho, B, tau, c->type, c->need, c->opt);
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
    res->e_tail = tau * B;
    for (int q = 0; q < 3; q++)
        res->ident_se.v[q] = se[q];
    /* e_t = tau B: var = B^2 var(tau) + tau^2 var(B) + 2 tau B cov(B, tau) */
    if (se[1] > 0 && se[3] > 0 && isfinite(cov_Bt)) {
        const double var = B * B * se[3] * se[3] + tau * tau * se[1] * se[1] + 2 * tau * B * cov_Bt;
        res->e_tail_se = var > 0 ? sqrt(var) : 0;
    } else {
        res->e_tail_se = -1;
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
    if (type == CF_TELESCOPING && rho >= cf_ident_rho_hi(type, opt->index_max) * (1 - 1e-3))
        res->held |= CF_C_TYPE;
    if (res->law.type != type)
        res->violated |= CF_C_TYPE;
    res->feasible = res->violated == 0;
    res->solid_table_strain = fd ? res->law.travel_mm : res->law.travel_mm / res->params.H_mm;
    res->solid_ratio = xmax > 0 ? res->solid_table_strain / xmax : INFINITY;
    return CF_OK;
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
    v[0] = r->k == 0 ? r->fixed : p->rho_lo + (p->rho_hi - p->rho_lo) * sigm(z[0]);
    v[1] = r->k == 1 ? r->fixed : p->b_lo + (prof_b_hi(r) - p->b_lo) * sigm(z[1]);
    v[3] = r->k == 3 ? r->fixed / v[1] : tau_fd(p->fd, v[1], z[3]);
    v[2] = r->k == 2 ? r->fixed : p->fd ? exp(z[2]) : prof_A_max(r, v) * sigm(z[2]);
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

typedef struct prof_ctx {
    const cf_tail_profile *p;
    int oom;
    double stall_rel; /* the statistical tolerance of a profile's search, relative to its RSS */
} prof_ctx;

/* cf_profile's at: x holds (rho, B, A, tau) of the last point within the limit. */
static double prof_at(void *ctx, int k, double u, double limit, double *x)
{
    prof_ctx *pc = ctx;
    const prof_run r = {pc->p, k, exp(u)};
    if (!(prof_b_hi(&r) > pc->p->b_lo))
        return CF_LSQ_HUGE_OBJ;
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
    double f = CF_LSQ_HUGE_OBJ, v[4];
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
                          res->e_tail_se};
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
    prof_ctx pc = {p, 0, 1e-2 * (limit - rss0) / (4 * rss0)};
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
    memcpy(res->e_tail_interval, out[3], sizeof out[3]);
    memcpy(res->e_tail_interval_end, end[3], sizeof end[3]);
    res->e_tail_interval_ok = 1;
    res->e_tail_interval_why = why;
    return 0;
}

/* ---- the fit --------------------------------------------------------------------------------- */

/* The fit's context over table data (its weights and scratch in buf, 3 n doubles): the ranges
** the search takes and the rows its grid and profiles run on. */
static void ctx_init(tail_ctx *c, const cf_table *data, const cf_fit_options *opt,
                     cf_spring_type type, double *buf)
{
    memset(c, 0, sizeof *c);
    c->data = data;
    c->opt = opt;
    c->fd = cf_table_is_force(data);
    c->n = data->count;
    double *sw = buf;
    c->t = buf + c->n;
    c->g = c->t + c->n;
    c->ynorm = cf_lsq_weights(data, opt->relative, sw);
    c->sw = sw;
    const double xmax = cf_lsq_xmax(data);
    c->type = type;
    c->need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    c->rho_lo = fmax(CF_IDENT_RHO_LO, opt->rho_min * (1 - CF_IDENT_RHO_MIN_TOL));
    c->rho_hi = cf_ident_rho_hi(type, opt->index_max);
    /* the cone may close inside the data (the tail carries on); a stress-strain table's cone
    ** travel is below 1 */
    c->b_lo = 1e-3 * xmax;
    c->b_hi = c->fd ? 1e3 * xmax : 1 - 1e-9;
    c->stride = c->n > TAIL_SEARCH_ROWS ? (c->n + TAIL_SEARCH_ROWS - 1) / TAIL_SEARCH_ROWS : 1;
}

/* The weighted RSS of c's profile rows at v (rho, B, A, tau); CF_LSQ_HUGE_OBJ where the law has
** no value. */
static double stride_rss(tail_ctx *c, const double v[4])
{
    const size_t m = (c->n + c->stride - 1) / c->stride;
    gsl_vector *fv = gsl_vector_alloc(m);
    double rss = CF_LSQ_HUGE_OBJ;
    if (fv && resid_stride(c, v, fv) == GSL_SUCCESS) {
        gsl_blas_ddot(fv, fv, &rss);
        rss = isfinite(rss) ? rss : CF_LSQ_HUGE_OBJ;
    }
    gsl_vector_free(fv);
    return rss;
}

static cf_tail_profile profile_of(tail_ctx *c)
{
    const cf_tail_profile tp = {resid_stride, c, (c->n + c->stride - 1) / c->stride, c->ynorm,
                                c->opt, c->type, c->fd, c->need, c->rho_lo, c->rho_hi, c->b_lo,
                                c->b_hi};
    return tp;
}

double cf_tail_profile_at(const cf_table *data, const cf_fit_options *opt,
                          const cf_fit_result *fit, int k, double value, double *limit)
{
    *limit = NAN;
    const size_t n = data->count;
    double *buf = n >= 6 ? malloc(3 * sizeof(double) * n) : NULL;
    if (!buf)
        return NAN;
    tail_ctx c;
    ctx_init(&c, data, opt, fit->type, buf);
    const double B = fit->ident.solid, tau = fit->e_tail / B;
    const double v[4] = {fit->ident.rho, B, fit->ident.scale, tau};
    const double rss = fit->objective, rss0 = stride_rss(&c, v);
    *limit = rss0 + cf_profile_limit_np(n, 4, rss, c.ynorm) - rss;
    const cf_tail_profile tp = profile_of(&c);
    prof_ctx pc = {&tp, 0, 1e-2 * (*limit - rss0) / (4 * rss0)};
    double x[4] = {v[0], v[1], v[2], v[3]};
    const double f = prof_at(&pc, k, log(value), INFINITY, x);
    free(buf);
    return f;
}

cf_status cf_fit_tail_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                          const cf_fit_result *plain, cf_fit_result *res, cf_error *err)
{
    memset(res, 0, sizeof *res);
    const double t0 = cf_clock_s();
    tail_ctx c;
    if (data->count < 6)
        return cf_error_set(err, CF_E_DATA,
                            "the conical-tail law needs at least 6 rows (the table has %zu)",
                            data->count);
    double *buf = malloc(3 * sizeof(double) * data->count);
    if (!buf)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", data->count);
    ctx_init(&c, data, opt, type, buf);
    const double xmax = cf_lsq_xmax(data);

    /* the grid over (rho, B, tau), A in closed form */
    tail_start grid[TAIL_GRID_RHO * TAIL_GRID_B * TAIL_GRID_TAU];
    size_t k = 0;
    for (int i = 0; i < TAIL_GRID_RHO; i++) {
        const double rho = c.rho_lo * pow(c.rho_hi / c.rho_lo, (i + 0.5) / TAIL_GRID_RHO);
        for (int j = 0; j < TAIL_GRID_B; j++) {
            const double Bmax = c.fd ? 5 * xmax : fmin(0.999, 5 * xmax);
            const double B = 0.1 * xmax * pow(Bmax / (0.1 * xmax), (j + 0.5) / TAIL_GRID_B);
            if (!(B > c.b_lo && B < c.b_hi))
                continue;
            for (int l = 0; l < TAIL_GRID_TAU; l++) {
                const double tau = 1e-3 * pow(1e5, (double)l / (TAIL_GRID_TAU - 1));
                if (!c.fd && B * (1 + tau) >= 1)
                    continue;
                double A;
                grid[k].obj = tail_profile(&c, rho, B, tau, c.stride, &A);
                if (!c.fd && A > 0.999 * amax_at(&c, rho, B, tau)) {
                    /* beyond what a spring carries: the profile at the limit */
                    A = 0.999 * amax_at(&c, rho, B, tau);
                    grid[k].obj = tail_objective(&c, rho, B, tau, A, c.stride);
                }
                grid[k].v[0] = rho, grid[k].v[1] = B, grid[k].v[2] = A, grid[k].v[3] = tau;
                if (A > 0)
                    k++;
            }
        }
    }
    qsort(grid, k, sizeof grid[0], cmp_start);
    /* LM from the best grid points and from the plain fit with a small tail */
    double best = INFINITY, v[4] = {0.5, 0.5 * (c.b_lo + c.b_hi), 1, 0.1};
    tail_start starts[TAIL_STARTS + 2];
    int ns = 0;
    for (size_t i = 0; i < k && ns < TAIL_STARTS; i++)
        starts[ns++] = grid[i];
    if (plain && plain->ident.rho > 0 && plain->ident.solid > c.b_lo && plain->ident.solid < c.b_hi) {
        const double taus[2] = {1e-3, 0.1};
        for (int q = 0; q < 2; q++) {
            starts[ns].v[0] = fmin(fmax(plain->ident.rho, c.rho_lo * 1.001), c.rho_hi * 0.999);
            starts[ns].v[1] = plain->ident.solid / (1 + taus[q]);
            starts[ns].v[2] = plain->ident.scale;
            starts[ns].v[3] = taus[q];
            ns++;
        }
    }
    for (int i = 0; i < ns; i++) {
        double out[4];
        if (!c.fd)
            starts[i].v[2] = fmin(starts[i].v[2],
                                  0.999 * amax_at(&c, starts[i].v[0], starts[i].v[1], starts[i].v[3]));
        const double obj = lm_run(&c, starts[i].v, out);
        if (obj < best) {
            best = obj;
            memcpy(v, out, sizeof v);
        }
    }
    if (!isfinite(best)) {
        free(buf);
        return cf_error_set(err, CF_E_DATA, "%s: no conical-tail law fits the table",
                            data->path);
    }
    /* the identifiable quantities, their errors, the spring */
    double se[4], corr[4][4], cov_Bt;
    cf_tail_errors(resid_at, &c, c.n, v, 1e-6, best, se, corr, &cov_Bt);
    cf_status st = cf_tail_result(data, opt, type, v, se, corr, cov_Bt, res, err);
    if (st != CF_OK) {
        free(buf);
        return st;
    }
    /* profile intervals where the errors say nothing, on the grid's rows (every row of a table
    ** of up to TAIL_SEARCH_ROWS), against the whole table's threshold: the rise F s^2 of the
    ** F-test with 1 and N - 4 degrees of freedom */
    const double rss0 = stride_rss(&c, v);
    const cf_tail_profile tp = profile_of(&c);
    const double rise = cf_profile_limit_np(c.n, 4, best, c.ynorm) - best;
    const int pst = cf_tail_intervals(&tp, v, rss0, rss0 + rise, res);
    free(buf);
    if (pst < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the profiles of %zu rows", c.n);
    res->optimizer = "lm";
    res->evaluations = c.evals;
    res->evaluations_full = c.evals;
    res->wall_time_s = cf_clock_s() - t0;
    return CF_OK;
}

cf_status cf_law_family_parse(const char *name, cf_law_family *f, cf_error *err)
{
    static const struct { const char *name; cf_law_family f; } map[] = {
        {"conical", CF_FAMILY_CONICAL}, {"conical-tail", CF_FAMILY_TAIL}, {"auto", CF_FAMILY_AUTO}};
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (name && strcmp(name, map[i].name) == 0) {
            *f = map[i].f;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA,
                        "unknown law '%s' (expected conical, conical-tail or auto)",
                        name ? name : "(null)");
}

const char *cf_law_family_name(cf_law_family f)
{
    switch (f) {
    case CF_FAMILY_CONICAL: return "conical";
    case CF_FAMILY_TAIL: return "conical-tail";
    case CF_FAMILY_AUTO: return "auto";
    }
    return "?";
}
