/*
** The fitter: three identifiable quantities first (global grid + Levenberg-Marquardt, GSL), then
** one spring of that family placed under the design constraints (NLopt SLSQP with equality
** constraints), then a constrained local polish on the six design parameters (NLopt). See fit.h.
*/
#include "conifit/fit.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_vector.h>
#include <nlopt.h>

#include "fit/clock.h"
#include "fit/lsq.h"
#include "fit/subsample.h"

/* Constraint tolerances (constraints are in log units, i.e. relative): a constraint counts as
** violated beyond FEAS_TOL and active within ACTIVE_TOL of its limit. The optimisers see the
** constraints shifted by SAFETY so that their solutions land on the feasible side. */
#define FEAS_TOL 1e-9
#define ACTIVE_TOL 1e-6
#define SAFETY 1e-10
/* Grid of the global stage: GRID x GRID cells over (rho, length scale). */
#define GRID 28

const char *cf_fit_optimizer_name(cf_fit_optimizer o)
{
    switch (o) {
    case CF_OPT_SLSQP: return "slsqp";
    case CF_OPT_COBYLA: return "cobyla";
    case CF_OPT_MMA: return "mma";
    }
    return "?";
}

cf_status cf_fit_optimizer_parse(const char *name, cf_fit_optimizer *o, cf_error *err)
{
    for (int i = 0; i <= CF_OPT_MMA; i++)
        if (strcmp(name, cf_fit_optimizer_name((cf_fit_optimizer)i)) == 0) {
            *o = (cf_fit_optimizer)i;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA, "unknown optimizer '%s' (expected slsqp, cobyla or mma)",
                        name);
}

const char *cf_fit_constraint_name(unsigned bit)
{
    switch (bit) {
    case CF_C_INDEX_MIN: return "index_min";
    case CF_C_INDEX_MAX: return "index_max";
    case CF_C_COILS: return "coils_min";
    case CF_C_DIAMETERS: return "D2_ge_D1";
    case CF_C_TRAVEL: return "travel";
    case CF_C_TYPE: return "type";
    case CF_C_BOUNDS: return "bounds";
    case CF_C_RHO_MIN: return "rho_min";
    case CF_C_COILS_MAX: return "coils_max";
    case CF_C_G_MAX: return "G_max";
    case CF_C_D2_H: return "D2_max_H";
    }
    return "?";
}

cf_fit_options cf_fit_default_options(void)
{
    cf_fit_options o;
    memset(&o, 0, sizeof o);
    /* Bounds from the spring description (spring.h); the constraints, not the bounds, shape
    ** the fit. */
    for (int k = 0; k < CF_P_COUNT; k++) {
        o.lower[k] = cf_spring_param_info(k)->lower;
        o.upper[k] = cf_spring_param_info(k)->upper;
    }
    o.upper[CF_P_N] = CF_FIT_COILS_MAX_DEFAULT;
    o.upper[CF_P_G] = CF_FIT_G_MAX_DEFAULT;
    o.rho_min = CF_FIT_RHO_MIN_DEFAULT;
    o.D2_over_H_max = CF_FIT_D2_OVER_H_MAX_DEFAULT;
    o.index_max = CF_FIT_INDEX_MAX_DEFAULT;
    o.optimizer = CF_OPT_SLSQP;
    o.xtol_rel = 1e-12;
    o.seed = 1;
    o.multistart = 8;
    o.H_preferred_mm = 10.0;
    o.subsample_above = CF_FIT_SUBSAMPLE_ABOVE;
    return o;
}

/* ---- small helpers --------------------------------------------------------------------------- */

/* The fit's random numbers: GSL's mt19937 (the generator conifit uses everywhere), one stream
** per use, seeded from the fit's seed, local to one call (no shared state between threads). */
static gsl_rng *seeded_rng(unsigned long seed, unsigned long stream)
{
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    if (r)
        gsl_rng_set(r, seed * 4u + stream);
    return r;
}

/* A uniform number in [0, 1); 0.5 (the cell's centre) when no generator could be made. */
static double jitter(gsl_rng *r)
{
    return r ? gsl_rng_uniform(r) : 0.5;
}

static double sigmoid(double t) { return 1.0 / (1.0 + exp(-t)); }
static double logit(double p)
{
    p = fmin(fmax(p, 1e-15), 1 - 1e-15);
    return log(p / (1 - p));
}

double cf_fit_model(const cf_law *law, int force_displacement, double x)
{
    if (force_displacement)
        return cf_law_force(law, CF_LAW_CLOSED, x, NULL, NULL);
    const double H = law->p.H_mm;
    return cf_law_force(law, CF_LAW_CLOSED, x * H, NULL, NULL) / (H * H);
}

/* Solid length of a spring of the given type (the type being fitted, not the one its geometry
** has; the type constraint makes the two agree). */
static double lmin_of(const double *p, cf_spring_type type)
{
    return type == CF_TELESCOPING ? p[CF_P_D] : p[CF_P_N] * p[CF_P_D];
}

static void to_array(const cf_spring *s, double *p)
{
    p[CF_P_D1] = s->D1_mm;
    p[CF_P_D2] = s->D2_mm;
    p[CF_P_N] = s->n;
    p[CF_P_D] = s->d_mm;
    p[CF_P_G] = s->G_MPa;
    p[CF_P_H] = s->H_mm;
}

static cf_spring from_array(const double *p)
{
    cf_spring s = {p[CF_P_D1], p[CF_P_D2], p[CF_P_N], p[CF_P_D], p[CF_P_G], p[CF_P_H]};
    return s;
}

/* ---- the data as the fit sees it ------------------------------------------------------------- */

typedef struct fit_ctx {
    const cf_table *data;
    const cf_fit_options *opt;
    cf_spring_type type;
    int fd;
    size_t n;
    double *sw;     /* sqrt(w_i)/scale_i: residual i is sw_i (model_i - y_i) */
    double *model;  /* scratch: the model at each point (same allocation as sw) */
    double xmax;    /* largest |x|: strain [-] or displacement [mm] */
    double ynorm;   /* sum of (sw_i y_i)^2: objective of the zero model */
    int travel_ok;  /* 0 when no spring can reach xmax (strain >= 1) */
    int region;     /* 1: the type's placeable set of (rho, B, A) is known in closed form
                    ** (stress-strain table, no fixed parameter; see region_at) */
    double inside;  /* how far inside those limits (log units) a sub-problem's points keep:
                    ** REGION_SAFETY for the searches, less for the profiles (uncertainty) */
    /* stage A bounds on (rho, length scale) */
    double rho_lo, rho_hi, b_lo, b_hi;
    long evals;
    /* stage B/C: free parameters */
    int nfree;
    int free_idx[CF_P_COUNT];
    double base[CF_P_COUNT]; /* values of the fixed parameters */
    /* stage B targets */
    double target[3];
    double pref[3]; /* preferred log c, log n, log H */
    int oom;        /* 1 when an allocation of GSL or NLopt failed: the fit ends with an error */
} fit_ctx;

/* The canonical law g(t) = F/F_C at t = u/s and its derivatives dg/dt and dg/drho, analytic:
** region 1: g = h(rho) t, h = 4 rho^3/((1 + rho)(1 + rho^2));
** region 2: g = y^3 with y^4 - 4 c y + 3 = 0, c = (1 - |t|)/rho + |t|, so dy/dc = y/(y^3 - c)
** and dc/drho = -(1 - |t|)/rho^2; past solid g = +-1 with zero derivatives. */
static double canon_eval(const cf_law *canon, double t, double *dg_dt, double *dg_drho)
{
    int flags = 0;
    double k;
    double g = cf_law_force(canon, CF_LAW_CLOSED, t, &k, &flags);
    const double rho = canon->rho, a = fabs(t), sg = t < 0 ? -1.0 : 1.0;
    *dg_dt = k;
    if (flags & CF_LAW_SOLID) {
        *dg_drho = 0;
    } else if (flags & CF_LAW_LINEAR) {
        double h = 4 * rho * rho * rho / ((1 + rho) * (1 + rho * rho));
        *dg_drho = t * h * (3 / rho - 1 / (1 + rho) - 2 * rho / (1 + rho * rho));
    } else {
        double y = cbrt(fabs(g));
        double c = (1 - a) / rho + a;
        double den = y * y * y - c;
        *dg_drho = den < 0 ? sg * 3 * y * y * (y / den) * (-(1 - a) / (rho * rho)) : 0.0;
    }
    return g;
}

/* Weighted objective of the reduced model with the load scale A solved in closed form. */
static double reduced_profile(fit_ctx *c, double rho, double B, double *A_out)
{
    cf_law canon;
    if (cf_ident_canon_law(rho, &canon) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    double sgy = 0, sgg = 0, syy = 0;
    for (size_t i = 0; i < c->n; i++) {
        double g = c->sw[i] * cf_ident_reduced(&canon, 1.0, B, c->data->x[i], NULL);
        double y = c->sw[i] * c->data->y[i];
        sgy += g * y;
        sgg += g * g;
        syy += y * y;
    }
    c->evals++;
    double A = sgg > 0 ? sgy / sgg : 0;
    if (!(A > 0) || !isfinite(A)) {
        *A_out = 1e-300;
        return syy;
    }
    *A_out = A;
    return fmax(syy - A * sgy, 0.0);
}

/* ---- stage A: Levenberg-Marquardt on the three identifiable quantities ----------------------- */

static void unpack3(const fit_ctx *c, const gsl_vector *th, double *rho, double *B, double *A)
{
    *rho = c->rho_lo + (c->rho_hi - c->rho_lo) * sigmoid(gsl_vector_get(th, 0));
    *B = c->b_lo + (c->b_hi - c->b_lo) * sigmoid(gsl_vector_get(th, 1));
    *A = exp(gsl_vector_get(th, 2));
}

static int lm_f(const gsl_vector *th, void *params, gsl_vector *f)
{
    fit_ctx *c = params;
    double rho, B, A;
    unpack3(c, th, &rho, &B, &A);
    cf_law canon;
    if (!isfinite(A) || cf_ident_canon_law(rho, &canon) != CF_OK)
        return GSL_EDOM;
    /* residuals scaled so that the zero model has |f| = 1: GSL's gradient test is absolute
    ** below |f| = 1, which would stop early on tables in MPa of tissue (tiny numbers) */
    const double sc = 1.0 / sqrt(c->ynorm);
    for (size_t i = 0; i < c->n; i++)
        gsl_vector_set(f, i, sc * c->sw[i] *
                                 (cf_ident_reduced(&canon, A, B, c->data->x[i], NULL) - c->data->y[i]));
    c->evals++;
    return GSL_SUCCESS;
}

/* Analytic Jacobian of lm_f in the transformed variables. */
static int lm_df(const gsl_vector *th, void *params, gsl_matrix *J)
{
    fit_ctx *c = params;
    double rho, B, A;
    unpack3(c, th, &rho, &B, &A);
    cf_law canon;
    if (!isfinite(A) || cf_ident_canon_law(rho, &canon) != CF_OK)
        return GSL_EDOM;
    const double s0 = sigmoid(gsl_vector_get(th, 0)), s1 = sigmoid(gsl_vector_get(th, 1));
    const double drho = (c->rho_hi - c->rho_lo) * s0 * (1 - s0);
    const double dB = (c->b_hi - c->b_lo) * s1 * (1 - s1);
    const double sc = 1.0 / sqrt(c->ynorm);
    for (size_t i = 0; i < c->n; i++) {
        double t = c->data->x[i] / B, gt, gr;
        double g = canon_eval(&canon, t, &gt, &gr);
        double w = sc * c->sw[i];
        gsl_matrix_set(J, i, 0, w * A * gr * drho);
        gsl_matrix_set(J, i, 1, w * (-A * gt * t / B) * dB);
        gsl_matrix_set(J, i, 2, w * A * g);
    }
    c->evals++;
    return GSL_SUCCESS;
}

/* Levenberg-Marquardt limits: iterations, and the stagnation rule (cf_lsq_lm_stop). */
#define LM_MAX_ITER 300
#define LM_STALL 8
#define LM_STALL_REL 1e-9
/* ... and once the residual is at rounding level (relative residual norm 1e-13): on a noiseless
** table the sum of squares then only jitters, and no step can improve the fit. */
#define LM_FLOOR_REL 1e-26

static double lm_run(fit_ctx *c, double rho0, double B0, double A0, double out[3])
{
    const size_t p = 3;
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    fp.trs = gsl_multifit_nlinear_trs_lm;
    fp.scale = gsl_multifit_nlinear_scale_more;
    fp.fdtype = GSL_MULTIFIT_NLINEAR_CTRDIFF;
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, c->n, p);
    if (!w) {
        c->oom = 1;
        return CF_LSQ_HUGE_OBJ;
    }
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.df = lm_df;
    fdf.n = c->n;
    fdf.p = p;
    fdf.params = c;
    double th0[3] = {logit((rho0 - c->rho_lo) / (c->rho_hi - c->rho_lo)),
                     logit((B0 - c->b_lo) / (c->b_hi - c->b_lo)), log(A0)};
    gsl_vector_view x0 = gsl_vector_view_array(th0, 3);
    double best = CF_LSQ_HUGE_OBJ;
    int ist = gsl_multifit_nlinear_init(&x0.vector, &fdf, w);
    if (ist == GSL_ENOMEM)
        c->oom = 1;
    if (ist == GSL_SUCCESS) {
        /* an optimum on a bound of rho or of the length scale lies at infinity in the logit
        ** coordinates: the stall rule stops there (residuals are scaled by 1/sqrt(ynorm)) */
        static const cf_lsq_lm_stop stop = {LM_MAX_ITER, 1e-15, 1e-15, 1e-15,
                                            LM_STALL,    LM_STALL_REL, LM_FLOOR_REL};
        if (cf_lsq_lm_iterate(w, &stop) != 0)
            c->oom = 1;
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        double chi2;
        gsl_blas_ddot(f, f, &chi2);
        if (isfinite(chi2)) {
            unpack3(c, gsl_multifit_nlinear_position(w), &out[0], &out[1], &out[2]);
            best = chi2;
        }
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

/* The paper's two-point start: the maximum point gives the solid strain and the load scale,
** the transition point (last point on the initial line within 5 %) gives rho = (F_T/F_C)^(1/3). */
static void two_point_start(const fit_ctx *c, double *rho, double *B, double *A)
{
    const double *x = c->data->x, *y = c->data->y;
    size_t imax = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(x[i]) > fabs(x[imax]))
            imax = i;
    /* initial slope from the points in the first tenth of the range */
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(x[i]) <= 0.1 * c->xmax) {
            sxy += x[i] * y[i];
            sxx += x[i] * x[i];
        }
    double k = sxx > 0 ? sxy / sxx : y[imax] / x[imax];
    double yT = 0;
    for (size_t i = 0; i < c->n; i++)
        if (fabs(y[i] - k * x[i]) <= 0.05 * fabs(y[i]) && fabs(y[i]) > yT)
            yT = fabs(y[i]);
    double ymax = fabs(y[imax]);
    double r = (yT > 0 && ymax > 0) ? cbrt(fmin(yT / ymax, 1.0)) : 0.5;
    *rho = fmin(fmax(r, c->rho_lo + 1e-9 * (c->rho_hi - c->rho_lo)), c->rho_hi);
    *B = fmin(fmax(c->travel_ok ? c->xmax * (1 + 2 * CF_FIT_TRAVEL_MARGIN) : 0.5 * c->b_hi,
                   c->b_lo + 1e-6 * (c->b_hi - c->b_lo)),
              c->b_hi - 1e-6 * (c->b_hi - c->b_lo));
    *A = ymax > 0 ? ymax : 1.0;
}

typedef struct start {
    double obj, rho, B;
} start;

/* A result of stage A's Levenberg-Marquardt runs (at most 1 + multistart of them are kept). */
typedef struct start4 {
    double obj, v[3];
} start4;
#define STAGE_A_RUNS 64

static void record(start4 *found, int *nfound, double obj, const double v[3])
{
    if (found && obj < CF_LSQ_HUGE_OBJ && *nfound < STAGE_A_RUNS) {
        found[*nfound].obj = obj;
        memcpy(found[*nfound].v, v, sizeof found[0].v);
        (*nfound)++;
    }
}

static int cmp_start4(const void *a, const void *b)
{
    double x = ((const start4 *)a)->obj, y = ((const start4 *)b)->obj;
    return (x > y) - (x < y);
}

static int cmp_start(const void *a, const void *b)
{
    double x = ((const start *)a)->obj, y = ((const start *)b)->obj;
    return (x > y) - (x < y);
}

/* Global stage over (rho, B) with A in closed form, then LM from the best starts. Each LM
** result (objective, rho, B, A) goes to found[] when found is not NULL (at most
** STAGE_A_RUNS, counted in *nfound). */
static double stage_a(fit_ctx *c, double best3[3], start4 *found, int *nfound)
{
    gsl_rng *rng = seeded_rng(c->opt->seed, 1);
    c->oom |= !rng;
    start grid[GRID * GRID];
    size_t k = 0;
    for (int i = 0; i < GRID; i++) {
        /* rho: half the grid log-spaced from CF_IDENT_RHO_LO, half approaching rho_hi geometrically
        ** (resolves nearly cylindrical springs) */
        double ti = (i + jitter(rng)) / GRID;
        double rho = (i % 2 == 0)
                         ? c->rho_lo * pow(c->rho_hi / c->rho_lo, ti)
                         : c->rho_hi - (c->rho_hi - c->rho_lo) * pow(1e-7, ti);
        for (int j = 0; j < GRID; j++) {
            double tj = (j + jitter(rng)) / GRID;
            double B = (j % 2 == 0) ? c->b_lo + (c->b_hi - c->b_lo) * tj * tj
                                    : c->b_lo + (c->b_hi - c->b_lo) * pow(1e-7, 1 - tj);
            double A;
            grid[k].obj = reduced_profile(c, rho, B, &A);
            grid[k].rho = rho;
            grid[k].B = B;
            k++;
        }
    }
    gsl_rng_free(rng);
    qsort(grid, k, sizeof grid[0], cmp_start);
    double best = CF_LSQ_HUGE_OBJ;
    double r, B, A, out[3];
    two_point_start(c, &r, &B, &A);
    reduced_profile(c, r, B, &A);
    best = lm_run(c, r, B, A, best3);
    record(found, nfound, best, best3);
    int used = 0;
    for (size_t i = 0; i < k && used < c->opt->multistart; i++) {
        /* skip starts that lie next to one already used */
        int near = 0;
        for (size_t j = 0; j < i && !near; j++)
            near = fabs(grid[j].rho - grid[i].rho) < 0.02 && fabs(grid[j].B - grid[i].B) <
                                                                  0.02 * (c->b_hi - c->b_lo);
        if (near && i > 0)
            continue;
        used++;
        reduced_profile(c, grid[i].rho, grid[i].B, &A);
        double v = lm_run(c, grid[i].rho, grid[i].B, A, out);
        record(found, nfound, v, out);
        if (v < best) {
            best = v;
            memcpy(best3, out, sizeof out);
        }
    }
    return best;
}

/* Standard errors of (rho, B, A) at a solution: s^2 (J^T J)^-1 with the analytic Jacobian of the
** weighted residuals (canon_eval); the correlation matrix (NAN where not determined). Returns 1
** when J^T J is numerically singular (then the errors stay -1). */
static int stage_a_errors(fit_ctx *c, const double v[3], double se[3], double corr[3][3])
{
    se[0] = se[1] = se[2] = -1;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            corr[a][b] = NAN;
    const double rho = v[0], B = v[1], A = v[2];
    cf_law lc;
    if (cf_ident_canon_law(rho, &lc) != CF_OK || c->n <= 3)
        return 0;
    gsl_matrix *JtJ = gsl_matrix_calloc(3, 3), *E = gsl_matrix_alloc(3, 3);
    gsl_vector *ev = gsl_vector_alloc(3);
    gsl_eigen_symm_workspace *ew = gsl_eigen_symm_alloc(3);
    int rank_def = 0;
    if (!JtJ || !E || !ev || !ew) {
        c->oom = 1;
        goto done;
    }
    double rss = 0;
    for (size_t i = 0; i < c->n; i++) {
        double x = c->data->x[i], gt, gr;
        double g = canon_eval(&lc, x / B, &gt, &gr);
        double m = A * g;
        double row[3] = {A * gr, -A * gt * x / (B * B), g};
        double r = c->sw[i] * (m - c->data->y[i]);
        rss += r * r;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                *gsl_matrix_ptr(JtJ, a, b) += c->sw[i] * c->sw[i] * row[a] * row[b];
    }
    c->evals += 3;
    /* scale to unit diagonal before inverting (the columns differ by orders of magnitude) */
    double dsc[3];
    for (int a = 0; a < 3; a++) {
        dsc[a] = sqrt(gsl_matrix_get(JtJ, a, a));
        if (!(dsc[a] > 0 && isfinite(dsc[a]))) {
            rank_def = 1;
            goto done;
        }
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            *gsl_matrix_ptr(JtJ, a, b) /= dsc[a] * dsc[b];
    gsl_matrix_memcpy(E, JtJ);
    if (gsl_eigen_symm(E, ev, ew) != GSL_SUCCESS) {
        rank_def = 1;
        goto done;
    }
    double emin = gsl_vector_min(ev), emax = gsl_vector_max(ev);
    if (!(emin > 1e-10 * emax)) {
        rank_def = 1;
        goto done;
    }
    if (gsl_linalg_cholesky_decomp1(JtJ) == GSL_SUCCESS &&
        gsl_linalg_cholesky_invert(JtJ) == GSL_SUCCESS) {
        double s2 = rss / (double)(c->n - 3);
        for (int a = 0; a < 3; a++) {
            double var = s2 * gsl_matrix_get(JtJ, a, a) / (dsc[a] * dsc[a]);
            se[a] = (var >= 0 && isfinite(var)) ? sqrt(var) : -1;
        }
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double q = gsl_matrix_get(JtJ, a, b) /
                           sqrt(gsl_matrix_get(JtJ, a, a) * gsl_matrix_get(JtJ, b, b));
                corr[a][b] = isfinite(q) ? fmax(-1.0, fmin(1.0, q)) : NAN;
            }
    } else {
        rank_def = 1;
    }
done:
    gsl_eigen_symm_free(ew);
    gsl_vector_free(ev);
    gsl_matrix_free(E);
    gsl_matrix_free(JtJ);
    return rank_def;
}

/* ---- constraints (shared by stages B, C and the check) --------------------------------------- */

/* Number of inequality constraints of the design, and the CF_C_* bit of each. */
#define NCON 8
static const unsigned con_bit[NCON] = {CF_C_INDEX_MIN, CF_C_INDEX_MAX, CF_C_COILS, CF_C_DIAMETERS,
                                       CF_C_TRAVEL,    CF_C_TYPE,      CF_C_RHO_MIN, CF_C_D2_H};
#define CON_TRAVEL 4

/* Constraint values g_k <= 0 when satisfied, in log (relative) units, in the order of con_bit. */
static void constraint_values(const double *p, cf_spring_type type, double xmax, int fd,
                              const cf_fit_options *opt, double g[NCON])
{
    double c = p[CF_P_D1] / p[CF_P_D];
    g[0] = log(3.0) - log(c);
    g[1] = log(c) - log(opt->index_max);
    g[2] = log(2.0) - log(p[CF_P_N]);
    g[3] = log(p[CF_P_D1]) - log(p[CF_P_D2]);
    double s = p[CF_P_H] - lmin_of(p, type);
    double umax = (fd ? xmax : xmax * p[CF_P_H]) * (1 + CF_FIT_TRAVEL_MARGIN);
    g[4] = s > 0 ? log(umax) - log(s) : 50.0;
    double step = (p[CF_P_D2] - p[CF_P_D1]) / 2, nd = p[CF_P_N] * p[CF_P_D];
    g[5] = type == CF_TELESCOPING ? (nd - step) / p[CF_P_D2] : (step - nd) / p[CF_P_D2] + 1e-12;
    g[6] = log(opt->rho_min * (1 - CF_IDENT_RHO_MIN_TOL)) - log(p[CF_P_D1] / p[CF_P_D2]);
    g[7] = log(p[CF_P_D2]) - log(opt->D2_over_H_max * p[CF_P_H]);
    for (int k = 0; k < NCON; k++)
        if (!isfinite(g[k]))
            g[k] = 50.0;
}

/* cf_fit_check for a table whose largest |x| is xmax (fd: force-displacement). */
static int check_spring(const cf_spring *sp, cf_spring_type type, double xmax, int fd,
                        const cf_fit_options *opt, unsigned *active, unsigned *violated)
{
    double p[CF_P_COUNT], g[NCON];
    to_array(sp, p);
    unsigned act = 0, vio = 0;
    constraint_values(p, type, xmax, fd, opt, g);
    for (int k = 0; k < NCON; k++) {
        if (g[k] > FEAS_TOL)
            vio |= con_bit[k];
        if (g[k] > -ACTIVE_TOL)
            act |= con_bit[k];
    }
    /* the geometry must be of the type fitted, judged by the law itself */
    cf_law law;
    if (cf_law_init(&law, sp, NULL) != CF_OK || law.type != type)
        vio |= CF_C_TYPE;
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (opt->fixed[k]) {
            if (fabs(p[k] - opt->fixed_value[k]) > 1e-12 * fabs(opt->fixed_value[k]))
                vio |= CF_C_BOUNDS;
            continue;
        }
        /* the upper bounds of n and G are named; the other bounds are the wide defaults */
        unsigned ub = k == CF_P_N ? CF_C_COILS_MAX : k == CF_P_G ? CF_C_G_MAX : CF_C_BOUNDS;
        if (p[k] < opt->lower[k] * (1 - 1e-12))
            vio |= CF_C_BOUNDS;
        if (p[k] > opt->upper[k] * (1 + 1e-12))
            vio |= ub;
        if (p[k] <= opt->lower[k] * (1 + ACTIVE_TOL))
            act |= k == CF_P_N ? CF_C_COILS : CF_C_BOUNDS;
        if (p[k] >= opt->upper[k] * (1 - ACTIVE_TOL))
            act |= ub;
    }
    if (active)
        *active = act;
    if (violated)
        *violated = vio;
    return vio == 0;
}

int cf_fit_check(const cf_spring *sp, cf_spring_type type, const cf_table *data,
                 const cf_fit_options *opt, unsigned *active, unsigned *violated)
{
    return check_spring(sp, type, cf_lsq_xmax(data), cf_table_is_force(data), opt, active,
                        violated);
}

/* The check at the fit's own table, without a pass over it. */
static int check_at(const fit_ctx *c, const cf_spring *sp, unsigned *active, unsigned *violated)
{
    return check_spring(sp, c->type, c->xmax, c->fd, c->opt, active, violated);
}

/* ---- stages B and C: NLopt over the free design parameters (log variables) ------------------- */

static void full_params(const fit_ctx *c, const double *z, double *p)
{
    memcpy(p, c->base, sizeof c->base);
    for (int k = 0; k < c->nfree; k++)
        p[c->free_idx[k]] = exp(z[k]);
}

/* Weighted objective of the six-parameter model, normalised by that of the zero model. */
static double objective6(fit_ctx *c, const double *p)
{
    cf_spring s = from_array(p);
    cf_law law;
    if (cf_law_init(&law, &s, NULL) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    double sum = 0;
    for (size_t i = 0; i < c->n; i++) {
        double r = c->sw[i] * (cf_fit_model(&law, c->fd, c->data->x[i]) - c->data->y[i]);
        sum += r * r;
    }
    c->evals++;
    return isfinite(sum) ? sum / c->ynorm : CF_LSQ_HUGE_OBJ;
}

/* Central-difference gradient of a scalar function of z. */
typedef double (*zfun)(fit_ctx *c, const double *z, int which);

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

static double z_objective(fit_ctx *c, const double *z, int which)
{
    (void)which;
    double p[CF_P_COUNT];
    full_params(c, z, p);
    return objective6(c, p);
}

static double z_constraint(fit_ctx *c, const double *z, int which)
{
    double p[CF_P_COUNT], g[NCON];
    full_params(c, z, p);
    constraint_values(p, c->type, c->xmax, c->fd, c->opt, g);
    return g[which] + SAFETY;
}

/* log(ident(p)) - log(target): the equality constraints of placement */
static double z_equality(fit_ctx *c, const double *z, int which)
{
    double p[CF_P_COUNT];
    full_params(c, z, p);
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
    full_params(c, z, p);
    double a = log(p[CF_P_D1] / p[CF_P_D]) - c->pref[0];
    double b = log(p[CF_P_N]) - c->pref[1];
    double h = log(p[CF_P_H]) - c->pref[2];
    return a * a + b * b + h * h;
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
    if (grad)
        fd_grad(t->c, t->f, t->which, z, grad);
    return t->f(t->c, z, t->which);
}

static nlopt_algorithm algorithm_of(cf_fit_optimizer o)
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
static void nl_run(fit_ctx *c, nlopt_algorithm alg, zfun obj, int equalities, double *z,
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
    nl_thunk to = {c, obj, 0}, tc[NCON], te[3];
    set_oom |= nlopt_set_min_objective(o, nl_func, &to) == NLOPT_OUT_OF_MEMORY;
    for (int k = 0; k < NCON; k++) {
        tc[k] = (nl_thunk){c, z_constraint, k};
        if (k == CON_TRAVEL && !c->travel_ok)
            continue;
        set_oom |= nlopt_add_inequality_constraint(o, nl_func, &tc[k], 0.0) == NLOPT_OUT_OF_MEMORY;
    }
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
    if (obj == z_objective) /* a fit at rounding level cannot be polished further */
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
    if (!check_at(c, &sp, NULL, NULL))
        return;
    memcpy(p, q, sizeof q);
    for (int k = 0; k < c->nfree; k++)
        z[k] = log(p[c->free_idx[k]]);
}

/* ---- the type's limits in the space of the identifiable quantities --------------------------- */

/* For a stress-strain table with no fixed parameter the design limits reduce to closed-form
** limits on (rho, B = s/H, A = F_C/H^2), because H is a pure scale (family.h,
** cf_ident_region_at). REGION_SAFETY keeps solutions that far inside, so that placement finds
** them. */
#define REGION_SAFETY 1e-4

typedef cf_ident_region region;

/* The design limits of options o as the family's space sees them. */
static cf_ident_design design_of(const cf_fit_options *o)
{
    cf_ident_design d = {o->lower[CF_P_N], o->upper[CF_P_N], o->upper[CF_P_G], o->D2_over_H_max,
                         o->index_max, o->rho_min};
    return d;
}

static region region_at(const fit_ctx *c, double rho, double B)
{
    region r = {-1.0, INFINITY, 0, 0};
    if (!c->region)
        return r;
    const cf_ident_design d = design_of(c->opt);
    return cf_ident_region_at(&d, c->type, rho, B, c->inside);
}

double cf_fit_ident_limit(const cf_fit_options *opt, cf_spring_type type, double rho, double B,
                          double *A_max)
{
    fit_ctx c;
    memset(&c, 0, sizeof c);
    c.opt = opt;
    c.type = type;
    c.region = 1;
    c.inside = REGION_SAFETY;
    for (int k = 0; k < CF_P_COUNT; k++)
        c.region &= !opt->fixed[k];
    region r = region_at(&c, rho, B);
    *A_max = r.A_max;
    return r.margin;
}

/* Weighted residual sum of squares of the reduced model at (rho, B) with the load scale A fixed
** (A_fixed > 0) or solved in closed form and clamped to (0, A_max]; *A_out the scale used.
** The sum is formed from the residuals themselves, not from the expanded square, so that it
** stays exact on noiseless tables. */
static double rss_at(fit_ctx *c, double rho, double B, double A_fixed, double A_max,
                     double *A_out)
{
    cf_law canon;
    *A_out = A_fixed;
    if (!(B > 0) || cf_ident_canon_law(rho, &canon) != CF_OK)
        return CF_LSQ_HUGE_OBJ;
    double sgy = 0, sgg = 0;
    for (size_t i = 0; i < c->n; i++) {
        double g = c->sw[i] * cf_ident_reduced(&canon, 1.0, B, c->data->x[i], NULL);
        c->model[i] = g;
        sgy += g * c->sw[i] * c->data->y[i];
        sgg += g * g;
    }
    double A = A_fixed;
    if (!(A > 0)) {
        A = sgg > 0 ? sgy / sgg : 0;
        if (!(A > 0) || !isfinite(A))
            A = 1e-300;
        A = fmin(A, A_max);
    }
    double rss = 0;
    for (size_t i = 0; i < c->n; i++) {
        double r = A * c->model[i] - c->sw[i] * c->data->y[i];
        rss += r * r;
    }
    c->evals++;
    *A_out = A;
    return isfinite(rss) ? rss : CF_LSQ_HUGE_OBJ;
}

/* A sub-problem over (log rho, B) with one quantity held (fixed = 0 rho, 1 B, 2 A; -1 none) and
** the type's limits as constraints: the constrained fit (fixed = -1) and the profiles. */
typedef struct sub {
    fit_ctx *c;
    int fixed;
    double t;
} sub;

static void sub_point(const sub *q, const double *x, double *rho, double *B)
{
    int j = 0;
    *rho = q->fixed == 0 ? q->t : exp(x[j++]);
    *B = q->fixed == 1 ? q->t : x[j];
}

static double sub_f0(const sub *q, const double *x)
{
    double rho, B, A;
    sub_point(q, x, &rho, &B);
    region r = region_at(q->c, rho, B);
    return rss_at(q->c, rho, B, q->fixed == 2 ? q->t : -1, r.A_max, &A);
}

static double sub_g0(const sub *q, const double *x);

/* Central differences for the gradient-based optimiser (SLSQP). */
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

static double sub_f(unsigned n, const double *x, double *grad, void *data)
{
    const sub *q = data;
    if (grad)
        sub_grad(q, sub_f0, n, x, grad);
    return sub_f0(q, x);
}

static double sub_g(unsigned n, const double *x, double *grad, void *data)
{
    const sub *q = data;
    if (grad)
        sub_grad(q, sub_g0, n, x, grad);
    return sub_g0(q, x);
}

static double sub_g0(const sub *q, const double *x)
{
    double rho, B;
    sub_point(q, x, &rho, &B);
    region r = region_at(q->c, rho, B);
    double g = r.margin + q->c->inside;
    if (q->fixed == 2 && isfinite(r.A_max))
        g = fmax(g, log(q->t) - log(r.A_max));
    return g;
}

/* Minimises the sub-problem from x (in/out); returns its RSS, CF_LSQ_HUGE_OBJ when no point meets the
** limits. */
static double sub_solve(fit_ctx *c, sub *q, double *x, nlopt_algorithm alg)
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
    double f = CF_LSQ_HUGE_OBJ;
    nlopt_result r = nlopt_optimize(o, x, &f);
    c->oom |= r == NLOPT_OUT_OF_MEMORY;
    nlopt_destroy(o);
    if (r < 0 && r != NLOPT_ROUNDOFF_LIMITED)
        f = sub_f0(q, x);
    if (c->region && sub_g0(q, x) > 1e-9)
        return CF_LSQ_HUGE_OBJ;
    return f;
}

/* Stage A under the type's limits: used when the optimum over every spring lies outside them.
** Seeded grid over (rho, B) as in stage_a, feasible points only, then COBYLA from the best. */
static int stage_a_constrained(fit_ctx *c, double v[3])
{
    gsl_rng *rng = seeded_rng(c->opt->seed, 3);
    c->oom |= !rng;
    start grid[GRID * GRID];
    size_t k = 0;
    sub q = {c, -1, 0};
    for (int i = 0; i < GRID; i++) {
        double ti = (i + jitter(rng)) / GRID;
        double rho = c->rho_lo * pow(c->rho_hi / c->rho_lo, ti);
        for (int j = 0; j < GRID; j++) {
            double tj = (j + jitter(rng)) / GRID;
            double B = c->b_lo + (c->b_hi - c->b_lo) * tj;
            double x[2] = {log(rho), B};
            if (sub_g0(&q, x) > 0)
                continue;
            grid[k].obj = sub_f0(&q, x);
            grid[k].rho = rho;
            grid[k].B = B;
            k++;
        }
    }
    gsl_rng_free(rng);
    if (k == 0)
        return 0;
    qsort(grid, k, sizeof grid[0], cmp_start);
    double best = CF_LSQ_HUGE_OBJ, bx[2] = {0, 0};
    for (size_t i = 0; i < k && (int)i < c->opt->multistart; i++) {
        double x[2] = {log(grid[i].rho), grid[i].B};
        double f = sub_solve(c, &q, x, NLOPT_LN_COBYLA);
        double f2 = sub_solve(c, &q, x, NLOPT_LD_SLSQP);
        f = fmin(f, f2);
        if (f < best) {
            best = f;
            memcpy(bx, x, sizeof bx);
        }
    }
    if (!(best < CF_LSQ_HUGE_OBJ))
        return 0;
    v[0] = exp(bx[0]);
    v[1] = bx[1];
    region r = region_at(c, v[0], v[1]);
    rss_at(c, v[0], v[1], -1, r.A_max, &v[2]);
    return 1;
}

/* ---- a long table: the global stages on its subsample, then a polish on every row ------------ */

/* Stage A's optima on the subsample polished by Levenberg-Marquardt on every row: the best one,
** and up to POLISH_RUNS - 1 others, distinct from it, that the F-test on the subsample cannot tell
** from it (a table that leaves the quantities open has a valley of optima of nearly equal depth,
** and the deepest on every row may lie elsewhere in it); v receives the best on every row. */
#define POLISH_RUNS 3
static void stage_a_polish(fit_ctx *c, start4 *found, int nfound, double v[3])
{
    qsort(found, (size_t)nfound, sizeof found[0], cmp_start4);
    const double er = 1e-12 * (c->rho_hi - c->rho_lo), eb = 1e-12 * (c->b_hi - c->b_lo);
    const double dof = (double)c->n - 3, within = nfound > 0 ? found[0].obj * (1 + cf_lsq_f95(dof) / dof) : 0;
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
        double f = lm_run(c, rho, B, u[2], out);
        if (f < best) {
            best = f;
            memcpy(v, out, sizeof out);
        }
    }
}

/* The constrained optimum v (found on the subsample) polished on every row, as stage_a_constrained
** polishes each of its starts; v keeps its value when the polish finds no better point. */
static void stage_a_constrained_polish(fit_ctx *c, double v[3])
{
    sub q = {c, -1, 0};
    double x0[2] = {log(v[0]), v[1]}, x[2] = {x0[0], x0[1]};
    double f0 = sub_g0(&q, x0) <= 1e-9 ? sub_f0(&q, x0) : CF_LSQ_HUGE_OBJ;
    double f = sub_solve(c, &q, x, NLOPT_LN_COBYLA);
    f = fmin(f, sub_solve(c, &q, x, NLOPT_LD_SLSQP));
    if (f > f0 || !(f < CF_LSQ_HUGE_OBJ))
        memcpy(x, x0, sizeof x);
    v[0] = exp(x[0]);
    v[1] = x[1];
    region r = region_at(c, v[0], v[1]);
    rss_at(c, v[0], v[1], -1, r.A_max, &v[2]);
}

/* Limits the quantities v sit on (CF_C_* bits): rho_min, the travel, the type's limits. */
static unsigned held_at(const fit_ctx *c, const double v[3])
{
    unsigned h = 0;
    if (v[0] <= fmax(c->rho_lo, c->opt->rho_min) * (1 + 1e-3))
        h |= c->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS;
    if (c->travel_ok && v[1] <= c->b_lo * (1 + 1e-5))
        h |= CF_C_TRAVEL;
    if (c->region) {
        region r = region_at(c, v[0], v[1]);
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
static int region_member(fit_ctx *c, const double v[3], double *p)
{
    const double rho = v[0], B = v[1], H = c->opt->H_preferred_mm;
    const double nmin = c->opt->lower[CF_P_N], nmax = c->opt->upper[CF_P_N];
    const double cmax = c->opt->index_max;
    double best = CF_LSQ_HUGE_OBJ;
    int found = 0;
    for (int i = -1; i <= 40; i++)
        for (int j = 0; j <= 40; j++) {
            double cidx, n;
            if (i < 0) { /* the corner of region_at */
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
            double q[CF_P_COUNT] = {D1, D1 / rho, n, d, 8 * n * D1 * D1 * D1 * FC / (d * d * d * d * s),
                                    H};
            cf_spring sp = from_array(q);
            if (!check_at(c, &sp, NULL, NULL))
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

/* ---- uncertainty: standard errors, correlation, profile-likelihood intervals ----------------- */

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
    double f = sub_solve(c, q, x, NLOPT_LN_COBYLA);
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
    double hi[3] = {log(c->rho_hi * (1 - 1e-12)), log(c->b_hi), INFINITY};
    unsigned lo_bit[3] = {c->opt->rho_min > CF_IDENT_RHO_LO ? CF_C_RHO_MIN : CF_C_BOUNDS,
                          c->travel_ok ? CF_C_TRAVEL : CF_C_BOUNDS, 0};
    unsigned hi_bit[3] = {(c->type == CF_TELESCOPING && !c->region) ? CF_C_TYPE : CF_C_DIAMETERS,
                          CF_C_BOUNDS, 0};
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
            sub_point(&q, xin, &rho, &B);
            region r = region_at(c, k == 0 ? exp(u_in) : rho, k == 1 ? exp(u_in) : B);
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
static void uncertainty(fit_ctx *c, fit_ctx *g, cf_fit_result *res, unsigned held_a)
{
    const double *v = res->ident.v;
    int rank_def = stage_a_errors(c, v, res->ident_se.v, res->corr);
    res->held = held_a | held_at(c, v) | (c->fd || c->region ? 0u : res->active);
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
    region r = region_at(c, v[0], v[1]);
    const double room = fmin(-r.margin, log(r.A_max / (1 - REGION_SAFETY)) - log(v[2]));
    g->inside = fmax(fmin(0.0, room), -1e-9);
    r = region_at(g, v[0], v[1]);
    double A;
    double rss0 = g == c ? fmin(res->objective, rss_at(c, v[0], v[1], -1, r.A_max, &A))
                         : rss_at(g, v[0], v[1], -1, r.A_max, &A);
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

/* ---- the driver ------------------------------------------------------------------------------ */

static cf_status check_data(const cf_table *d, cf_error *err)
{
    if (d->count < 4)
        return cf_error_set(err, CF_E_DATA, "%zu data points: a fit needs at least 4", d->count);
    double ymax = 0, xmax = 0;
    for (size_t i = 0; i < d->count; i++) {
        if (!isfinite(d->x[i]) || !isfinite(d->y[i]))
            return cf_error_set(err, CF_E_DATA, "data point %zu is not finite (%g, %g)", i + 1,
                                d->x[i], d->y[i]);
        if (d->w && !(d->w[i] > 0 && isfinite(d->w[i])))
            return cf_error_set(err, CF_E_DATA, "weight of data point %zu is %g (must be > 0)",
                                i + 1, d->w[i]);
        ymax = fmax(ymax, fabs(d->y[i]));
        xmax = fmax(xmax, fabs(d->x[i]));
    }
    if (!(ymax > 0) || !(xmax > 0))
        return cf_error_set(err, CF_E_DATA, "every %s value is zero: nothing to fit",
                            !(ymax > 0) ? "y" : "x");
    return CF_OK;
}

static cf_status check_options(const cf_fit_options *o, cf_error *err)
{
    if (!(o->index_max >= 3 && o->index_max <= CF_FIT_INDEX_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA,
                            "index_max = %g: the largest spring index must lie in [3, %g]",
                            o->index_max, CF_FIT_INDEX_MAX_LIMIT);
    if (!(o->rho_min >= CF_FIT_RHO_MIN_LIMIT))
        return cf_error_set(err, CF_E_DATA, "rho_min = %g: at least %g", o->rho_min,
                            CF_FIT_RHO_MIN_LIMIT);
    if (!(o->upper[CF_P_N] <= CF_FIT_COILS_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "upper bound of n = %g: at most %g coils",
                            o->upper[CF_P_N], CF_FIT_COILS_MAX_LIMIT);
    if (!(o->upper[CF_P_G] <= CF_FIT_G_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "upper bound of G = %g MPa: at most %g MPa",
                            o->upper[CF_P_G], CF_FIT_G_MAX_LIMIT);
    if (!(o->D2_over_H_max <= CF_FIT_D2_OVER_H_MAX_LIMIT))
        return cf_error_set(err, CF_E_DATA, "D2/H limit = %g: at most %g", o->D2_over_H_max,
                            CF_FIT_D2_OVER_H_MAX_LIMIT);
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (!(o->lower[k] > 0 && o->lower[k] <= o->upper[k] && isfinite(o->upper[k])))
            return cf_error_set(err, CF_E_DATA, "bounds of %s: %g .. %g are not 0 < lo <= hi",
                                cf_spring_param_info(k)->name, o->lower[k], o->upper[k]);
        if (o->fixed[k] && !(o->fixed_value[k] > 0 && isfinite(o->fixed_value[k])))
            return cf_error_set(err, CF_E_DATA, "fixed %s = %g must be a positive number",
                                cf_spring_param_info(k)->name, o->fixed_value[k]);
    }
    if (!(o->rho_min > 0 && o->rho_min < 1))
        return cf_error_set(err, CF_E_DATA,
                            "rho_min = %g: the smallest diameter ratio D1/D2 must lie in (0, 1)",
                            o->rho_min);
    if (!(o->D2_over_H_max > 0) || !isfinite(o->D2_over_H_max))
        return cf_error_set(err, CF_E_DATA, "D2/H limit = %g must be a positive number",
                            o->D2_over_H_max);
    if (o->upper[CF_P_N] < 2)
        return cf_error_set(err, CF_E_DATA, "upper bound of n = %g: a conical spring needs n >= 2",
                            o->upper[CF_P_N]);
    if (o->fixed[CF_P_N] && o->fixed_value[CF_P_N] < 2)
        return cf_error_set(err, CF_E_DATA, "fixed n = %g: a conical spring needs n >= 2",
                            o->fixed_value[CF_P_N]);
    if (o->multistart < 1)
        return cf_error_set(err, CF_E_DATA, "multistart = %d must be >= 1", o->multistart);
    return CF_OK;
}

static void summarise(fit_ctx *c, const double *p, cf_fit_result *res)
{
    res->params = from_array(p);
    cf_law_init(&res->law, &res->params, NULL);
    res->ident = cf_ident_of_type(&res->params, c->type, c->fd);
    for (size_t i = 0; i < c->n; i++)
        c->model[i] = cf_fit_model(&res->law, c->fd, c->data->x[i]);
    cf_lsq_quality q = cf_lsq_quality_of(c->data, c->model);
    res->rss = q.rss;
    res->rmse = q.rmse;
    res->max_abs_error = q.max_abs_error;
    res->r2 = q.r2;
    res->objective = objective6(c, p) * c->ynorm;
    res->feasible = check_at(c, &res->params, &res->active, &res->violated);
    res->objective_zero = c->ynorm;
    res->solid_ratio = c->xmax > 0 ? res->ident.solid / c->xmax : INFINITY;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            res->corr[a][b] = NAN;
}

/* Checks data and options and prepares the context shared by every stage (c->sw is malloc'd). */
static cf_status ctx_setup(fit_ctx *c, const cf_table *data, const cf_fit_options *opt,
                           cf_spring_type type, cf_error *err)
{
    memset(c, 0, sizeof *c);
    cf_status st = check_data(data, err);
    if (st != CF_OK || (st = check_options(opt, err)) != CF_OK)
        return st;
    c->data = data;
    c->opt = opt;
    c->type = type;
    c->inside = REGION_SAFETY;
    c->fd = cf_table_is_force(data);
    c->n = data->count;
    /* one block: the residual weights, then the model's values at the points (summarise, and
    ** scratch for rss_at) */
    c->sw = malloc(2 * sizeof(double) * c->n);
    if (!c->sw)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", c->n);
    c->model = c->sw + c->n;
    c->ynorm = cf_lsq_weights(data, opt->relative, c->sw);
    c->xmax = cf_lsq_xmax(data);
    int nfixed = 0;
    for (int k = 0; k < CF_P_COUNT; k++)
        nfixed += opt->fixed[k] != 0;
    c->region = !c->fd && nfixed == 0;
    /* Stage A bounds. Both types search the same range of rho when the type's own limits are
    ** known in closed form (they are then imposed as constraints, region_at), so that both report
    ** the same quantities wherever neither type's limits bind; rho_min is one of those limits and
    ** stage A searches a little below it, so that an optimum on rho_min lies inside its range.
    ** Otherwise (lsq.h) telescoping stops at rho <= index_max/(index_max + 4). */
    c->rho_lo = fmax(CF_IDENT_RHO_LO, opt->rho_min * (c->region ? 0.9 : 1 - CF_IDENT_RHO_MIN_TOL));
    c->rho_hi = c->region ? 1.0 : cf_ident_rho_hi(type, opt->index_max);
    if (c->rho_hi <= c->rho_lo * (1 + 1e-9))
        return cf_error_set(err, CF_E_DATA,
                            "rho_min = %g leaves no diameter ratio a %s spring can have (at most "
                            "%g with index_max = %g)",
                            opt->rho_min, cf_spring_type_name(type), c->rho_hi, opt->index_max);
    double need = c->xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    if (c->fd) {
        c->travel_ok = 1;
        c->b_lo = need;
        c->b_hi = 1e3 * need;
    } else {
        c->travel_ok = need < 1 - 1e-9;
        c->b_lo = c->travel_ok ? need : 1e-6;
        c->b_hi = 1 - 1e-9;
    }
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (opt->fixed[k])
            c->base[k] = opt->fixed_value[k];
        else
            c->free_idx[c->nfree++] = k;
    }
    c->pref[0] = log(sqrt(3.0 * opt->index_max));
    c->pref[1] = log(4.0);
    c->pref[2] = log(opt->fixed[CF_P_H] ? opt->fixed_value[CF_P_H] : opt->H_preferred_mm);
    return CF_OK;
}

/* Stage B: places a spring of the family with identifiable quantities v (p, z out). */
static void place(fit_ctx *c, const double v[3], double *p, double *z)
{
    memcpy(c->target, v, sizeof c->target);
    if (!(c->region && region_member(c, v, p)))
        analytic_member(c, v, p);
    for (int k = 0; k < c->nfree; k++)
        z[k] = log(p[c->free_idx[k]]);
    double p0[CF_P_COUNT], z0[CF_P_COUNT];
    memcpy(p0, p, sizeof p0);
    memcpy(z0, z, sizeof z0);
    cf_spring sp = from_array(p0);
    int feas0 = check_at(c, &sp, NULL, NULL);
    nl_run(c, NLOPT_LD_SLSQP, z_preference, 1, z, 2000);
    full_params(c, z, p);
    snap_to_family(c, p, z);
    sp = from_array(p);
    if (feas0 && !check_at(c, &sp, NULL, NULL)) {
        memcpy(p, p0, sizeof p0); /* keep the feasible start rather than a worse point */
        memcpy(z, z0, sizeof z0);
    }
}

static void ctx_free(fit_ctx *c)
{
    free(c->sw);
}

cf_status cf_fit_place(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                       const cf_ident *ident, cf_fit_result *res, cf_error *err)
{
    const double t0 = cf_clock_s();
    fit_ctx c;
    cf_status st = ctx_setup(&c, data, opt, type, err);
    if (st != CF_OK) {
        ctx_free(&c);
        return st;
    }
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        if (!(ident->v[k] > 0) || !isfinite(ident->v[k])) {
            ctx_free(&c);
            return cf_error_set(err, CF_E_DATA, "identifiable quantity %d = %g must be positive",
                                k, ident->v[k]);
        }
    double p[CF_P_COUNT], z[CF_P_COUNT];
    place(&c, ident->v, p, z);
    memset(res, 0, sizeof *res);
    res->type = type;
    summarise(&c, p, res);
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        res->ident_se.v[k] = -1;
    res->optimizer = "placement";
    res->evaluations = res->evaluations_full = c.evals;
    const int oom = c.oom;
    ctx_free(&c);
    if (oom)
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the %s placement's solver (NLopt)",
                            cf_spring_type_name(type));
    res->wall_time_s = cf_clock_s() - t0;
    return CF_OK;
}

/* The fit of one spring type: stage A (the identifiable quantities), B (placement of a spring),
** C (polish on the real objective) and the errors, as marked below. Kept as one function (~120
** lines) because the stages hand the same working point, subsample and result along; A, B and
** the errors are calls of their own, C's loop over starts keeps the best candidate inline. */
cf_status cf_fit_run(const cf_table *data, const cf_fit_options *opt, cf_spring_type type,
                     cf_fit_result *res, cf_error *err)
{
    const double t0 = cf_clock_s();
    memset(res, 0, sizeof *res);
    fit_ctx c, sc;
    memset(&sc, 0, sizeof sc);
    cf_table subt;
    memset(&subt, 0, sizeof subt);
    cf_status st = ctx_setup(&c, data, opt, type, err);
    /* A long table: the global searches see its subsample (g), the polish every row (c). */
    const int long_table = st == CF_OK && opt->subsample_above > 0 && c.n > opt->subsample_above;
    if (long_table && (st = cf_subsample(data, CF_SUBSAMPLE_ROWS, &subt, err)) == CF_OK)
        st = ctx_setup(&sc, &subt, opt, type, err);
    if (st != CF_OK) {
        ctx_free(&c);
        ctx_free(&sc);
        cf_table_free(&subt);
        return st;
    }
    fit_ctx *g = long_table ? &sc : &c;
    /* Stage A: the identifiable quantities, over every spring, then under the type's limits when
    ** the optimum lies outside them. */
    double v[3] = {0.5, 0.5 * (c.b_lo + c.b_hi), 1.0};
    start4 found[STAGE_A_RUNS];
    int nfound = 0;
    stage_a(g, v, long_table ? found : NULL, &nfound);
    if (long_table)
        stage_a_polish(&c, found, nfound, v);
    unsigned held_a = 0; /* the limits that keep the type from stage A's optimum */
    if (c.region) {
        region r = region_at(&c, v[0], v[1]);
        int out = r.margin > 0, over = v[2] > r.A_max / (1 - REGION_SAFETY);
        if (out || over) {
            held_a = (out ? r.lo_bit | r.hi_bit : 0u) | (over ? (unsigned)CF_C_G_MAX : 0u);
            if (stage_a_constrained(g, v)) {
                if (long_table)
                    stage_a_constrained_polish(&c, v);
                held_a |= held_at(&c, v);
            }
        }
    }
    /* Stage B: place a spring of the family. */
    double p[CF_P_COUNT], z[CF_P_COUNT];
    place(&c, v, p, z);
    double best_obj = objective6(&c, p);
    double best_p[CF_P_COUNT];
    memcpy(best_p, p, sizeof p);
    unsigned act, vio;
    cf_spring sp = from_array(p);
    int best_feas = check_at(&c, &sp, &act, &vio);
    /* Stage C: local polish on the real objective; with fixed parameters the family may be out
    ** of reach, so then also from seeded starts around the placement. A long table polishes its
    ** starts on the subsample and the best of them on every row; without fixed parameters on a
    ** stress-strain table (c.region) the six parameters reach the model only through the three
    ** quantities that stage A fitted on every row, so the polish there can move the objective by
    ** rounding only (1e-14 of it on the shipped tables) and a long table skips its full pass. */
    gsl_rng *rng = seeded_rng(opt->seed, 2);
    c.oom |= !rng;
    int starts = 1;
    for (int k = 0; k < CF_P_COUNT; k++)
        if (opt->fixed[k])
            starts = opt->multistart;
    const nlopt_algorithm alg = algorithm_of(opt->optimizer);
    double cand_z[CF_P_COUNT], cand_obj = CF_LSQ_HUGE_OBJ;
    int cand_feas = 0, have_cand = 0;
    for (int s = 0; s < starts; s++) {
        double zz[CF_P_COUNT];
        for (int k = 0; k < c.nfree; k++)
            zz[k] = z[k] + (s == 0 ? 0.0 : 0.5 * (jitter(rng) - 0.5));
        nl_run(g, alg, z_objective, 0, zz, 3000);
        double q[CF_P_COUNT];
        full_params(&c, zz, q);
        sp = from_array(q);
        int feas = check_at(&c, &sp, &act, &vio);
        double o = objective6(g, q);
        if (long_table) {
            if (!have_cand || (feas && !cand_feas) || (feas == cand_feas && o < cand_obj)) {
                have_cand = 1;
                cand_obj = o;
                cand_feas = feas;
                memcpy(cand_z, zz, sizeof zz);
            }
        } else if ((feas && !best_feas) || (feas == best_feas && o < best_obj)) {
            best_obj = o;
            best_feas = feas;
            memcpy(best_p, q, sizeof q);
        }
    }
    gsl_rng_free(rng);
    if (have_cand) {
        if (!c.region || held_a)
            nl_run(&c, alg, z_objective, 0, cand_z, 3000);
        double q[CF_P_COUNT];
        full_params(&c, cand_z, q);
        sp = from_array(q);
        int feas = check_at(&c, &sp, &act, &vio);
        double o = objective6(&c, q);
        if ((feas && !best_feas) || (feas == best_feas && o < best_obj)) {
            best_obj = o;
            best_feas = feas;
            memcpy(best_p, q, sizeof q);
        }
    }
    res->type = type;
    summarise(&c, best_p, res);
    /* Errors, correlation and, where the data leave a quantity open, its profile interval: at
    ** the reported spring's quantities. */
    uncertainty(&c, g, res, held_a);
    res->optimizer = cf_fit_optimizer_name(opt->optimizer);
    res->evaluations = c.evals + sc.evals;
    res->evaluations_full = c.evals;
    const int oom = c.oom || sc.oom;
    ctx_free(&c);
    ctx_free(&sc);
    cf_table_free(&subt);
    res->wall_time_s = cf_clock_s() - t0;
    if (oom) /* a stage ran short: its result is not the fit's */
        return cf_error_set(err, CF_E_INTERNAL,
                            "out of memory in the %s fit's solvers (GSL, NLopt)",
                            cf_spring_type_name(type));
    return CF_OK;
}

cf_fit_verdict cf_fit_compare(const cf_fit_result *a, const cf_fit_result *b, size_t points)
{
    cf_fit_verdict v = {0, -1, NAN, NAN, 0};
    const cf_fit_result *f[2] = {a, b};
    if (a->feasible && b->feasible)
        v.better = b->objective < a->objective ? 1 : 0;
    else if (a->feasible || b->feasible)
        v.better = a->feasible ? 0 : 1;
    else
        return v;
    const cf_fit_result *w = f[1 - v.better], *g = f[v.better];
    if (!w->feasible) { /* no contest: the other type has no spring inside its limits */
        v.held = w->violated;
        return v;
    }
    double dof = points > 3 ? (double)points - 3 : 1;
    double s2 = fmax(g->objective / dof, 1e-24 * g->objective_zero / (double)points);
    v.delta_rss = w->objective - g->objective;
    v.threshold = cf_lsq_f95(dof) * s2;
    v.tie = v.delta_rss <= v.threshold;
    v.held = w->held & ~g->held;
    if (!v.held)
        v.held = w->held;
    return v;
}
