/*
** Fitting the time-dependent model to a measured time series (see viscofit.h).
*/
#include "conifit/viscofit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "conifit/msm.h"
#include "fit/clock.h"
#include "fit/lm.h"
#include "fit/lsq.h"
#include "fit/viscolimits.h"

/* Bounds of rho and of the solid strain (the largest strain must stay CF_FIT_TRAVEL_MARGIN
** short of solid, as in the elastic fit). */
#define RHO_HI (1 - 1e-6)
#define E_HI 0.999
/* Relative residual floor (--relative), as in the elastic fit. */
#define REL_FLOOR 1e-3
/* Grid of the stand-in search: rho, s/H, time constants. */
#define GRID_RHO 9
#define GRID_E 9
#define GRID_TAU 12
/* Starts of the Levenberg-Marquardt stage per branch count, and its limits. */
#define LM_STARTS 2
#define LM_STARTS_STRAIN 6
#define LM_MAX_ITER 150
#define LM_STALL 6
#define LM_STALL_REL 1e-10
#define LM_FLOOR_REL 1e-28
/* g_i = e^a_i / (1 + sum e^a_j): a_i is kept above this (g_i ~ 1e-13, a branch switched off). */
#define A_LO -30.0
/* Relative step of the central differences for the standard errors. */
#define SE_STEP 1e-5

static double expit(double z)
{
    return z >= 0 ? 1 / (1 + exp(-z)) : exp(z) / (1 + exp(z));
}

cf_visco_fit_options cf_visco_fit_default_options(void)
{
    cf_visco_fit_options o;
    memset(&o, 0, sizeof o);
    o.setup = cf_visco_default();
    /* the axial calibration: its diagonals carry as much as its edges, which keeps the lattice
    ** stable further in compression than the isotropic one (README) */
    o.setup.cfg.lattice.calibration = CF_CAL_AXIAL;
    cf_calibration_weights(CF_CAL_AXIAL, o.setup.cfg.lattice.weight, NULL);
    o.rho_min = CF_FIT_RHO_MIN_DEFAULT;
    o.stable_cells = 1;
    o.limit_types = (1u << CF_TELESCOPING) | (1u << CF_NON_TELESCOPING);
    return o;
}

/* ---- the series ------------------------------------------------------------------------------ */

cf_status cf_visco_data_check(const cf_visco_data *d, unsigned char *is_hold, cf_error *err)
{
    const size_t n = d->count;
    if (n < 6)
        return cf_error_set(err, CF_E_DATA, "a time series needs at least 6 points, not %zu", n);
    double xmax = 0;
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(d->t_s[k]) || !isfinite(d->x[k]) || !isfinite(d->y[k]))
            return cf_error_set(err, CF_E_DATA, "point %zu of the series is not finite", k + 1);
        if (k > 0 && !(d->t_s[k] > d->t_s[k - 1]))
            return cf_error_set(err, CF_E_DATA,
                                "point %zu: time %.17g s is not after the previous %.17g s", k + 1,
                                d->t_s[k], d->t_s[k - 1]);
        xmax = fmax(xmax, fabs(d->x[k]));
    }
    if (!(xmax > 0))
        return cf_error_set(err, CF_E_DATA,
                            "the strain never changes (all %zu points at strain 0): a time series "
                            "needs a loading history",
                            n);
    const double tol = 1e-9 * xmax;
    size_t holds = 0, reversals = 0;
    int dir = 0;
    for (size_t k = 0; k < n; k++) {
        int hold = k > 0 && fabs(d->x[k] - d->x[k - 1]) <= tol && fabs(d->x[k]) > tol;
        if (is_hold)
            is_hold[k] = (unsigned char)hold;
        holds += (size_t)hold;
        if (k > 0 && fabs(d->x[k] - d->x[k - 1]) > tol) {
            int nd = d->x[k] > d->x[k - 1] ? 1 : -1;
            reversals += (size_t)(dir != 0 && nd != dir);
            dir = nd;
        }
    }
    if (holds == 0 && reversals == 0)
        return cf_error_set(err, CF_E_DATA,
                            "the series has neither a hold (constant nonzero strain) nor a "
                            "reversal of the strain: a single ramp does not separate the elastic "
                            "from the viscous response");
    return CF_OK;
}

/* ---- fit state ------------------------------------------------------------------------------- */

typedef struct ctx {
    const cf_visco_data *d;
    const cf_visco_fit_options *o;
    size_t n;
    int nb;             /* branches */
    int free_el;        /* 1: rho and s/H are fitted (and the scale profiled) */
    int dash;           /* 1: dashpot fitted */
    int gs;             /* 1: growth of the relative moduli with strain (k_i) fitted */
    unsigned smask;     /* with gs: bit i set when term i's k_i is fitted (else held at 0) */
    size_t np;          /* LM parameters */
    double *sw;         /* residual weights */
    double ynorm;       /* weighted sum of y^2 */
    double ymax, xmax;
    double xlo, xhi;    /* most compressive (<= 0) and most tensile (>= 0) strain */
    double e_lo;        /* lower bound of s/H (the travel margin; stability: see lim) */
    double rho_lo;      /* lower bound of rho (the fitter's rho_min) */
    cf_visco_limits lim;/* design cap of the scale and stability bound of s/H */
    double *m;          /* model curve scratch (n) */
    cf_visco_series series;
    long evals;
    int oom;            /* 1 when an allocation failed in a solver or a model curve: the fit
                        ** ends with an error instead of going on without that start or point */
} ctx;

/* The smallest s/H allowed at rho: above the travel margin and the lattice's stability bound. */
static double solid_lo(const ctx *c, double rho)
{
    return cf_visco_limits_solid_min(&c->lim, rho);
}

/* 1 when term i's relative modulus is fitted as changing with strain. */
static int strain_term(const ctx *c, int i)
{
    return c->gs && (c->smask >> i & 1u);
}

/* The k_i fitted. */
static int strain_terms(const ctx *c)
{
    int m = 0;
    for (int i = 0; i < c->nb; i++)
        m += strain_term(c, i);
    return m;
}

/* LM coordinates -> model parameters; the stress scale is 1 (profiled) or the held one, the
** dashpot relative to it. */
static cf_visco_params unpack(const ctx *c, const double *z)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    size_t j = 0;
    if (c->free_el) {
        p.ident.rho = c->rho_lo + (RHO_HI - c->rho_lo) * expit(z[j++]);
        const double lo = solid_lo(c, p.ident.rho);
        p.ident.solid = lo + (E_HI - lo) * expit(z[j++]);
        p.ident.scale = 1.0;
    } else {
        p.ident = c->o->elastic;
    }
    p.nbranch = c->nb;
    /* the moduli at zero strain (g_i) are shares of a softmax: >= 0 and summing below 1; the
    ** terms changing with strain share at the series' largest strain (g_i + k_i x_max) what the
    ** constant terms leave there, by a second softmax: linear in |strain|, every modulus stays
    ** >= 0 and their sum below 1 at every strain the series reaches */
    double sum = 1, sumb = 1, ea[CF_PRONY_MAX], eb[CF_PRONY_MAX];
    for (int i = 0; i < c->nb; i++) {
        p.tau_s[i] = exp(z[j++]);
        ea[i] = exp(fmax(z[j++], A_LO));
        eb[i] = strain_term(c, i) ? exp(fmax(z[j++], A_LO)) : 0.0;
        sum += ea[i];
        sumb += eb[i];
    }
    double left = 1; /* what the constant terms leave at the largest strain */
    for (int i = 0; i < c->nb; i++) {
        p.g[i] = ea[i] / sum;
        if (!strain_term(c, i))
            left -= p.g[i];
    }
    for (int i = 0; i < c->nb; i++)
        p.k[i] = strain_term(c, i) ? (left * eb[i] / sumb - p.g[i]) / c->xmax : 0.0;
    p.eta_MPa_s = c->dash ? exp(z[j++]) * p.ident.scale : 0.0;
    return p;
}

static void pack(const ctx *c, const cf_visco_params *p, double *z)
{
    size_t j = 0;
    if (c->free_el) {
        const double lo = solid_lo(c, p->ident.rho);
        z[j++] = cf_logit((p->ident.rho - c->rho_lo) / (RHO_HI - c->rho_lo));
        z[j++] = cf_logit((p->ident.solid - lo) / (E_HI - lo));
    }
    double ginf = 1, left = 1, gb[CF_PRONY_MAX];
    for (int i = 0; i < c->nb; i++) {
        ginf -= p->g[i];
        gb[i] = strain_term(c, i) ? p->g[i] + p->k[i] * c->xmax : 0.0;
        if (!strain_term(c, i))
            left -= p->g[i];
    }
    left = fmax(left, 1e-12);
    double ginfb = 1;
    for (int i = 0; i < c->nb; i++)
        ginfb -= gb[i] / left;
    ginf = fmax(ginf, 1e-12);
    ginfb = fmax(ginfb, 1e-12);
    for (int i = 0; i < c->nb; i++) {
        z[j++] = log(p->tau_s[i]);
        z[j++] = p->g[i] > 0 ? fmax(log(p->g[i] / ginf), A_LO) : A_LO;
        if (strain_term(c, i))
            z[j++] = gb[i] > 0 ? fmax(log(gb[i] / left / ginfb), A_LO) : A_LO;
    }
    if (c->dash)
        z[j++] = log(fmax(p->eta_MPa_s / p->ident.scale, 1e-300));
}

/* The model at p into c->m; returns 0 on failure. */
static int curve(ctx *c, const cf_visco_params *p)
{
    cf_error e = {0};
    c->evals++;
    cf_status st = cf_visco_curve(p, &c->o->setup, &c->series, c->m, NULL, &e);
    if (st == CF_E_INTERNAL && strstr(e.msg, "out of memory"))
        c->oom = 1; /* not a bad point: the curve was never computed */
    return st == CF_OK;
}

/* The best stress scale for the curve in c->m at unit scale (weighted least squares), capped at
** the largest a spring within the design limits carries at (rho, s/H); 1 for a held scale (the
** curve already carries it). 0 when no positive scale fits. */
static double profile_scale(const ctx *c, double rho, double B)
{
    if (!c->free_el)
        return 1.0;
    double gy = 0, gg = 0;
    for (size_t k = 0; k < c->n; k++) {
        double w = c->sw[k] * c->sw[k];
        gy += w * c->m[k] * c->d->y[k];
        gg += w * c->m[k] * c->m[k];
    }
    double A = gg > 0 ? gy / gg : 0;
    A = fmin(A, cf_visco_limits_scale_max(&c->lim, rho, B));
    return isfinite(A) && A > 0 ? A : 0;
}

static int lm_f(const gsl_vector *zv, void *data, gsl_vector *f)
{
    ctx *c = data;
    cf_visco_params p = unpack(c, zv->data);
    double A = 0;
    int ok = curve(c, &p) && (A = profile_scale(c, p.ident.rho, p.ident.solid)) > 0;
    const double s = 1 / sqrt(c->ynorm);
    for (size_t k = 0; k < c->n; k++) {
        double r = ok ? c->sw[k] * (A * c->m[k] - c->d->y[k])
                      : c->sw[k] * 10 * (fabs(c->d->y[k]) + c->ymax);
        gsl_vector_set(f, k, isfinite(r) ? r * s : 1e10);
    }
    return GSL_SUCCESS;
}

/* Levenberg-Marquardt from z (in place); returns the scaled sum of squares. */
static double lm_run(ctx *c, double *z)
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.h_df = 1e-7;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.df = NULL; /* forward differences */
    fdf.n = c->n;
    fdf.p = c->np;
    fdf.params = c;
    int init;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, z, &init);
    if (!w) {
        c->oom = 1;
        return HUGE_VAL;
    }
    double best = HUGE_VAL;
    if (init == GSL_SUCCESS) {
        static const cf_lm_stop stop = {LM_MAX_ITER, 1e-14, 1e-14, 0,
                                        LM_STALL,    LM_STALL_REL, LM_FLOOR_REL};
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        if (cf_lm_iterate(w, &stop) == 0)
            gsl_blas_ddot(f, f, &best);
        else
            c->oom = 1;
        memcpy(z, gsl_multifit_nlinear_position(w)->data, c->np * sizeof(double));
        if (!isfinite(best))
            best = HUGE_VAL;
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

/* ---- stage A: the stand-in search ------------------------------------------------------------ */

typedef struct start {
    double obj;
    cf_visco_params p;
} start;

static void keep_start(start *best, int nbest, double obj, const cf_visco_params *p)
{
    int pos = nbest;
    while (pos > 0 && obj < best[pos - 1].obj)
        pos--;
    if (pos >= nbest)
        return;
    /* one start per (rho, s/H): replace a worse start of the same grid point */
    for (int i = 0; i < nbest; i++)
        if (best[i].obj < HUGE_VAL && best[i].p.ident.rho == p->ident.rho &&
            best[i].p.ident.solid == p->ident.solid) {
            if (i < pos)
                return;
            memmove(best + i, best + i + 1, (size_t)(nbest - 1 - i) * sizeof *best);
            best[nbest - 1].obj = HUGE_VAL;
            break;
        }
    memmove(best + pos + 1, best + pos, (size_t)(nbest - 1 - pos) * sizeof *best);
    best[pos].obj = obj;
    best[pos].p = *p;
}

/* The stand-in at one grid point (rho, s/H) for one set of time constants: the elastic curve E
** (at unit scale, or at the held scale) and the responses of the chosen branches. The stress is
**     A E + sum_i (A g_i) (R_i - E) + c_d rate,
** with R_i branch i's response to E, linear in the unknowns A (unless held or capped), A g_i and
** the dashpot's c_d. With relaxation depending on strain, g_i (1 - |x|/x_max) + g'_i |x|/x_max
** (its values at zero and at the largest strain) takes the place of g_i: the unknowns are A g_i
** and A g'_i, all >= 0 (non-negative least squares), with S_i the response to |x| E. */
typedef struct standin {
    const double *E, *rate;
    const double *xE; /* |x| E (NULL: quasi-linear) */
    const double *basis[2 + 2 * CF_PRONY_MAX];
    double A_fixed;     /* > 0: the scale is held there (a held fit, or the design cap) */
    gsl_matrix *X;      /* weighted design, n x (2 + 2 CF_PRONY_MAX) */
    gsl_vector *y, *tau, *a, *res;
} standin;

enum { NNLS_MAX = 2 + 2 * CF_PRONY_MAX }; /* columns of the stand-in's design */

/* Least squares of y on the columns of X marked in[] (Householder QR in Q, tau, sol, res), into z
** (0 on the other columns); 0 when it fails or gives a non-finite value. */
static int nnls_free_columns(const gsl_matrix *X, const gsl_vector *y, const int *in, gsl_matrix *Q,
                             gsl_vector *tau, gsl_vector *sol, gsl_vector *res, double *z)
{
    const size_t n = X->size1, m = X->size2;
    size_t nf = 0, map[NNLS_MAX];
    for (size_t j = 0; j < m; j++) {
        z[j] = 0;
        if (in[j])
            map[nf++] = j;
    }
    gsl_matrix_view Qv = gsl_matrix_submatrix(Q, 0, 0, n, nf);
    for (size_t k = 0; k < nf; k++) {
        gsl_vector_const_view col = gsl_matrix_const_column(X, map[k]);
        gsl_matrix_set_col(&Qv.matrix, k, &col.vector);
    }
    gsl_vector_view tv = gsl_vector_subvector(tau, 0, nf), sv = gsl_vector_subvector(sol, 0, nf);
    if (gsl_linalg_QR_decomp(&Qv.matrix, &tv.vector) != GSL_SUCCESS ||
        gsl_linalg_QR_lssolve(&Qv.matrix, &tv.vector, y, &sv.vector, res) != GSL_SUCCESS)
        return 0;
    for (size_t k = 0; k < nf; k++)
        if (!isfinite(z[map[k]] = gsl_vector_get(sol, k)))
            return 0;
    return 1;
}

/* Non-negative least squares min |X a - y|, a >= 0 (Lawson and Hanson's active-set method, the
** subproblems on the free columns by Householder QR): for the stand-in with relaxation depending
** on strain, whose unconstrained solutions mostly cancel terms of opposite sign. X is n x m
** (m <= NNLS_MAX), not changed; 0 when a subproblem fails. */
static int nnls(const gsl_matrix *X, const gsl_vector *y, double *a)
{
    const size_t n = X->size1, m = X->size2;
    int in[NNLS_MAX] = {0};
    double w[NNLS_MAX], z[NNLS_MAX];
    gsl_matrix *Q = gsl_matrix_alloc(n, m);
    gsl_vector *tau = gsl_vector_alloc(m), *sol = gsl_vector_alloc(m), *res = gsl_vector_alloc(n);
    int ok = Q && tau && sol && res;
    for (size_t j = 0; j < m; j++)
        a[j] = 0;
    for (int outer = 0; ok && outer < 3 * (int)m; outer++) {
        /* the gradient w = X^T (y - X a), from the residual formed once */
        gsl_vector_memcpy(res, y);
        for (size_t k = 0; k < m; k++)
            if (a[k] != 0) {
                gsl_vector_const_view col = gsl_matrix_const_column(X, k);
                gsl_blas_daxpy(-a[k], &col.vector, res);
            }
        size_t jmax = m;
        for (size_t j = 0; j < m; j++) {
            gsl_vector_const_view col = gsl_matrix_const_column(X, j);
            gsl_blas_ddot(&col.vector, res, &w[j]);
            if (!in[j] && w[j] > 1e-12 && (jmax == m || w[j] > w[jmax]))
                jmax = j;
        }
        if (jmax == m)
            break;
        in[jmax] = 1;
        for (int inner = 0; ok && inner < 3 * (int)m; inner++) {
            if (!(ok = nnls_free_columns(X, y, in, Q, tau, sol, res, z)))
                break;
            double alpha = 2;
            for (size_t j = 0; j < m; j++)
                if (in[j] && z[j] <= 0)
                    alpha = fmin(alpha, a[j] / (a[j] - z[j]));
            if (alpha > 1) { /* every free coefficient positive */
                memcpy(a, z, m * sizeof(double));
                break;
            }
            for (size_t j = 0; j < m; j++) { /* back to the boundary, dropping what reached it */
                a[j] += alpha * (z[j] - a[j]);
                if (in[j] && a[j] <= 1e-300) {
                    in[j] = 0;
                    a[j] = 0;
                }
            }
        }
    }
    if (Q)
        gsl_matrix_free(Q);
    if (tau)
        gsl_vector_free(tau);
    if (sol)
        gsl_vector_free(sol);
    if (res)
        gsl_vector_free(res);
    return ok;
}

/* Weighted linear least squares of the stand-in by Householder QR (GSL): the coefficients in
** a[] in the order of the basis (A first when free). 0 when the design is rank deficient. */
static int standin_solve(const ctx *c, standin *s, int m, double *a)
{
    const size_t n = c->n;
    gsl_matrix_view X = gsl_matrix_submatrix(s->X, 0, 0, n, (size_t)m);
    gsl_vector_view tau = gsl_vector_subvector(s->tau, 0, (size_t)m);
    gsl_vector_view av = gsl_vector_subvector(s->a, 0, (size_t)m);
    const int held = s->A_fixed > 0;
    const int off = held ? 0 : 1;
    if ((size_t)m > n)
        return 0;
    for (size_t k = 0; k < n; k++) {
        gsl_vector_set(s->y, k, c->sw[k] * (c->d->y[k] - (held ? s->A_fixed * s->E[k] : 0.0)));
        for (int i = 0; i < m; i++) {
            const double *b = i < off ? s->E : s->basis[i - off];
            gsl_matrix_set(&X.matrix, k, (size_t)i, c->sw[k] * b[k]);
        }
    }
    if (s->xE) /* relaxation growing with strain: every coefficient >= 0 */
        return nnls(&X.matrix, s->y, a);
    if (gsl_linalg_QR_decomp(&X.matrix, &tau.vector) != GSL_SUCCESS)
        return 0;
    double dmax = 0, dmin = HUGE_VAL;
    for (int i = 0; i < m; i++) {
        double r = fabs(gsl_matrix_get(&X.matrix, (size_t)i, (size_t)i));
        dmax = fmax(dmax, r);
        dmin = fmin(dmin, r);
    }
    if (!(dmin > 1e-13 * dmax))
        return 0;
    if (gsl_linalg_QR_lssolve(&X.matrix, &tau.vector, s->y, &av.vector, s->res) != GSL_SUCCESS)
        return 0;
    for (int i = 0; i < m; i++)
        if (!isfinite(a[i] = gsl_vector_get(&av.vector, (size_t)i)))
            return 0;
    return 1;
}

/* The parameters of a stand-in solution, or 0 when they break g_i >= 0, sum g_i < 1, c_d > 0. */
static int standin_params(const ctx *c, const standin *s, const double *a, const int *idx,
                          const double *taus, double rate_factor, cf_visco_params *p)
{
    const int held = s->A_fixed > 0, off = held ? 0 : 1;
    const double A = held ? s->A_fixed : a[0];
    if (!(A > 0))
        return 0;
    double gs = 0, gs1 = 0;
    p->nbranch = c->nb;
    for (int i = 0; i < c->nb; i++) {
        const double g1 = c->gs ? a[off + c->nb + i] / A : 0.0; /* at the largest strain */
        p->g[i] = a[off + i] / A;
        p->k[i] = c->gs ? (g1 - p->g[i]) / c->xmax : 0.0;
        p->tau_s[i] = taus[idx[i]];
        if (!(p->g[i] >= 0) || !(g1 >= 0))
            return 0;
        gs += p->g[i];
        gs1 += g1;
    }
    if (!(gs < 1 - 1e-9) || !(gs1 < 1 - 1e-9))
        return 0;
    if (c->dash) {
        double cd = a[off + c->nb * (1 + c->gs)];
        if (!(cd > 0))
            return 0;
        p->eta_MPa_s = cd * rate_factor; /* MPa s */
    }
    p->ident.scale *= A;
    return 1;
}

/* The weighted, scaled sum of squares of the stand-in solution a. */
static double standin_obj(const ctx *c, const standin *s, int m, const double *a)
{
    const int held = s->A_fixed > 0, off = held ? 0 : 1;
    double sum = 0;
    for (size_t k = 0; k < c->n; k++) {
        double model = held ? s->A_fixed * s->E[k] : 0.0;
        for (int i = 0; i < m; i++)
            model += a[i] * (i < off ? s->E[k] : s->basis[i - off][k]);
        double r = c->sw[k] * (model - c->d->y[k]);
        sum += r * r;
    }
    return sum / c->ynorm;
}

/* One combination of time constants (indices idx into taus): solved, the scale capped at A_max
** (then solved again with the scale held there), kept in best when feasible. */
static void standin_combo(ctx *c, standin *s, double *const *R, double *const *S, const int *idx,
                          const double *taus, double rate_factor, double A_max,
                          const cf_visco_params *el, double *tmp, start *best, int nbest)
{
    const int nb = c->nb;
    for (int i = 0; i < nb; i++) {
        double *b = tmp + (size_t)i * c->n;
        for (size_t k = 0; k < c->n; k++)
            b[k] = R[idx[i]][k] - s->E[k];
        s->basis[i] = b;
    }
    for (int i = 0; c->gs && i < nb; i++) {
        double *b0 = tmp + (size_t)i * c->n, *b1 = tmp + (size_t)(nb + i) * c->n;
        for (size_t k = 0; k < c->n; k++) {
            b1[k] = (S[idx[i]][k] - s->xE[k]) / c->xmax;
            b0[k] -= b1[k];
        }
        s->basis[nb + i] = b1;
    }
    if (c->dash)
        s->basis[nb * (1 + c->gs)] = s->rate;
    const double A_held = c->free_el ? 0.0 : 1.0; /* a held curve carries its scale */
    double a[2 + 2 * CF_PRONY_MAX];
    s->A_fixed = A_held;
    int m = (s->A_fixed > 0 ? 0 : 1) + nb * (1 + c->gs) + c->dash;
    if (!standin_solve(c, s, m, a))
        return;
    if (s->A_fixed == 0 && a[0] > A_max) { /* past the design cap: the scale held there */
        s->A_fixed = A_max;
        m = nb * (1 + c->gs) + c->dash;
        if (!(A_max > 0) || !standin_solve(c, s, m, a))
            return;
    }
    cf_visco_params p = *el;
    if (standin_params(c, s, a, idx, taus, rate_factor, &p))
        keep_start(best, nbest, standin_obj(c, s, m, a), &p);
}

/* For one elastic curve E and the Prony responses R[t][k] of every grid time constant, tries
** every set of nb time constants and keeps the best feasible ones in best. */
static void search_taus(ctx *c, const double *E, const double *xE, double *const *R,
                        double *const *S, const double *taus, const double *rate,
                        double rate_factor, double A_max, const cf_visco_params *el, start *best,
                        int nbest)
{
    const int nb = c->nb;
    standin s;
    memset(&s, 0, sizeof s);
    s.E = E;
    s.xE = xE;
    s.rate = rate;
    s.X = gsl_matrix_alloc(c->n, 2 + 2 * CF_PRONY_MAX);
    s.y = gsl_vector_alloc(c->n);
    s.res = gsl_vector_alloc(c->n);
    s.tau = gsl_vector_alloc(2 + 2 * CF_PRONY_MAX);
    s.a = gsl_vector_alloc(2 + 2 * CF_PRONY_MAX);
    double *tmp = malloc((size_t)(2 * nb + 1) * c->n * sizeof(double));
    int idx[CF_PRONY_MAX];
    for (int i = 0; i < nb; i++)
        idx[i] = i;
    while (tmp && s.X && s.y && s.res && s.tau && s.a) {
        standin_combo(c, &s, R, S, idx, taus, rate_factor, A_max, el, tmp, best, nbest);
        /* next combination of nb indices out of GRID_TAU, increasing */
        int i = nb - 1;
        while (i >= 0 && idx[i] == GRID_TAU - nb + i)
            i--;
        if (i < 0)
            break;
        idx[i]++;
        for (int j = i + 1; j < nb; j++)
            idx[j] = idx[j - 1] + 1;
    }
    free(tmp);
    gsl_matrix_free(s.X);
    gsl_vector_free(s.y);
    gsl_vector_free(s.res);
    gsl_vector_free(s.tau);
    gsl_vector_free(s.a);
}

/* Static lattice stress (table's sign) of the model's elastic part at every strain of the
** series, and the small-strain ratio of the lattice modulus to the spring's k0/H (the factor
** that maps a spring's dashpot to the lattice's). */
static int elastic_curve(ctx *c, double rho, double e, double A, double *E, double *lat_factor)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    p.ident.rho = rho;
    p.ident.solid = e;
    p.ident.scale = A;
    cf_error err = {0};
    c->evals++;
    if (cf_visco_elastic_curve(&p, &c->o->setup, c->d->x, c->n, E, &err) != CF_OK)
        return 0;
    cf_spring sp = cf_ident_member(&p.ident);
    cf_law law;
    double small = -1e-3 * e, s0 = 0;
    if (cf_law_init(&law, &sp, &err) != CF_OK)
        return 0;
    int ok = cf_visco_elastic_curve(&p, &c->o->setup, &small, 1, &s0, &err) == CF_OK;
    *lat_factor = (s0 / small) / (law.k0_N_per_mm / sp.H_mm);
    cf_law_free(&law);
    return ok && *lat_factor > 0;
}

/* Prony responses per unit g of the curve E at every grid time constant:
** h_k = e h_(k-1) + b (E_k - E_(k-1)), relaxed start. */
static void grid_responses(const ctx *c, const double *E, const double *taus, double *const *R)
{
    const double *t = c->d->t_s;
    for (int i = 0; i < GRID_TAU; i++) {
        R[i][0] = 0;
        for (size_t k = 1; k < c->n; k++) {
            double h = t[k] - t[k - 1];
            double ex = exp(-h / taus[i]), b = -expm1(-h / taus[i]) * taus[i] / h;
            R[i][k] = ex * R[i][k - 1] + b * (E[k] - E[k - 1]);
        }
    }
}

/* The grid point (ir, ie) of the stand-in: rho spaced logarithmically from the lower limit, s/H
** quadratically from the smallest allowed at that rho; the held values when held. */
static void grid_point(const ctx *c, int ir, int ie, cf_visco_params *el)
{
    memset(el, 0, sizeof *el);
    if (!c->free_el) {
        el->ident = c->o->elastic;
        return;
    }
    const double r0 = fmax(c->rho_lo * 1.001, 0.02);
    el->ident.rho = r0 * pow(0.98 / r0, (double)ir / (GRID_RHO - 1));
    const double lo = solid_lo(c, el->ident.rho), f = (ie + 1.0) / (GRID_E + 1.0);
    el->ident.solid = lo + (E_HI - lo) * f * f;
    el->ident.scale = 1;
}

/* Stage A: the best starts for nb branches. */
static int stand_in(ctx *c, start *best, int nbest)
{
    for (int i = 0; i < nbest; i++)
        best[i].obj = HUGE_VAL;
    const size_t n = c->n;
    const double *t = c->d->t_s;
    double dtmin = HUGE_VAL, taus[GRID_TAU];
    for (size_t k = 1; k < n; k++)
        dtmin = fmin(dtmin, t[k] - t[k - 1]);
    const double tlo = 0.5 * dtmin, thi = 2 * (t[n - 1] - t[0]);
    for (int i = 0; i < GRID_TAU; i++)
        taus[i] = tlo * pow(thi / tlo, (double)i / (GRID_TAU - 1));
    double *E = malloc(n * sizeof(double)), *rate = calloc(n, sizeof(double));
    double *xE = malloc(n * sizeof(double));
    double *Rbuf = malloc((size_t)GRID_TAU * 2 * n * sizeof(double)), *R[GRID_TAU], *S[GRID_TAU];
    for (int i = 0; Rbuf && i < GRID_TAU; i++) {
        R[i] = Rbuf + (size_t)i * n;
        S[i] = Rbuf + (size_t)(GRID_TAU + i) * n;
    }
    for (size_t k = 1; rate && k < n; k++)
        rate[k] = (c->d->x[k] - c->d->x[k - 1]) / (t[k] - t[k - 1]);
    const int nrho = c->free_el ? GRID_RHO : 1, ne = c->free_el ? GRID_E : 1;
    for (int ir = 0; E && xE && rate && Rbuf && ir < nrho; ir++)
        for (int ie = 0; ie < ne; ie++) {
            cf_visco_params el;
            grid_point(c, ir, ie, &el);
            double fac = 1;
            if (!elastic_curve(c, el.ident.rho, el.ident.solid, el.ident.scale, E, &fac))
                continue;
            grid_responses(c, E, taus, R);
            if (c->gs) {
                for (size_t k = 0; k < n; k++)
                    xE[k] = fabs(c->d->x[k]) * E[k];
                grid_responses(c, xE, taus, S);
            }
            const double A_max = c->free_el
                                     ? cf_visco_limits_scale_max(&c->lim, el.ident.rho, el.ident.solid)
                                     : INFINITY;
            /* a dashpot eta beside every spring adds about eta * fac * rate to the stress */
            search_taus(c, E, c->gs ? xE : NULL, R, S, taus, rate, 1 / fac, A_max, &el, best,
                        nbest);
        }
    free(E);
    free(xE);
    free(rate);
    free(Rbuf);
    return best[0].obj < HUGE_VAL;
}

/* ---- standard errors ------------------------------------------------------------------------- */

/* Quantities of the covariance, in the order rho, s/H, F_C/H^2, (g_i, tau_i) per branch, eta:
** the slot of quantity `which` in q, or NULL when it is not fitted or held at a limit. */
static double *se_slot(const ctx *c, const int held[3], int which, cf_visco_params *q)
{
    const int nb = q->nbranch;
    if (which < 3) {
        if (!c->free_el || held[which])
            return NULL;
        return &q->ident.v[which];
    }
    if (which < 3 + 2 * nb) {
        int i = (which - 3) / 2;
        return (which - 3) % 2 == 0 ? &q->g[i] : &q->tau_s[i];
    }
    if (which == 3 + 2 * nb)
        return c->dash ? &q->eta_MPa_s : NULL;
    return strain_term(c, which - 4 - 2 * nb) ? &q->k[which - 4 - 2 * nb] : NULL;
}

/* One column of the Jacobian: the weighted central difference of the model in quantity `which`,
** its steps kept inside the quantity's domain. 0 when the model cannot be evaluated. */
static int se_column(ctx *c, const cf_visco_params *p, const int held[3], int which,
                     gsl_matrix *J, size_t col, double *mp, double *mm)
{
    cf_visco_params q = *p;
    double *slot = se_slot(c, held, which, &q);
    const double v = *slot;
    const int is_g = which >= 3 && which < 3 + 2 * p->nbranch && (which - 3) % 2 == 0;
    double h = SE_STEP * fmax(fabs(v), is_g ? 1e-2 : 1e-300);
    double hp = h, hm = h;
    if (which == 0) { /* keep rho inside (0, 1] */
        hp = fmin(h, 1 - v);
        hm = fmin(h, 0.5 * v);
    } else if (which == 1) { /* s/H inside (largest strain, 1) */
        hm = fmin(h, 0.5 * (v - c->xmax));
        hp = fmin(h, 0.5 * (1 - v));
    } else if (which >= 3 && (is_g || which > 3 + 2 * p->nbranch)) {
        /* a relative modulus or its slope: every g_i(x) >= 0 and their sum below 1 at x = 0 and
        ** at the largest strain x_max (one-sided next to a limit, as the fit may sit on it) */
        const int i = is_g ? (which - 3) / 2 : which - 4 - 2 * p->nbranch;
        double sum0 = 0, sum1 = 0;
        for (int j = 0; j < p->nbranch; j++) {
            sum0 += p->g[j];
            sum1 += p->g[j] + p->k[j] * c->xmax;
        }
        const double room0 = fmax(1 - sum0, 0), room1 = fmax(1 - sum1, 0);
        const double g1 = fmax(p->g[i] + p->k[i] * c->xmax, 0);
        if (is_g) {
            hp = fmin(h, 0.5 * fmin(room0, room1));
            hm = fmin(h, fmin(v, g1));
        } else {
            hp = fmin(h, 0.5 * room1 / c->xmax);
            hm = fmin(h, g1 / c->xmax);
        }
    }
    if (!(hp > 0) && !(hm > 0))
        return 0;
    cf_error e = {0};
    *slot = v + hp;
    cf_status st = cf_visco_curve(&q, &c->o->setup, &c->series, mp, NULL, &e);
    *slot = v - hm;
    if (st == CF_OK)
        st = cf_visco_curve(&q, &c->o->setup, &c->series, mm, NULL, &e);
    if (st == CF_E_INTERNAL && strstr(e.msg, "out of memory"))
        c->oom = 1; /* not an undetermined error: the column was never computed */
    const int ok = st == CF_OK;
    c->evals += 2;
    for (size_t r = 0; ok && r < c->n; r++)
        gsl_matrix_set(J, r, col, c->sw[r] * (mp[r] - mm[r]) / (hp + hm));
    return ok;
}

/* Stores the standard error se of quantity `which` in res. */
static void se_store(int which, int nb, double se, cf_visco_fit *res)
{
    if (which < 3)
        res->ident_se.v[which] = se;
    else if (which < 3 + 2 * nb)
        *((which - 3) % 2 == 0 ? &res->se_g[(which - 3) / 2] : &res->se_tau_s[(which - 3) / 2]) =
            se;
    else if (which == 3 + 2 * nb)
        res->se_eta_MPa_s = se;
    else
        res->se_k[which - 4 - 2 * nb] = se;
}

/* Central-difference Jacobian of the weighted model in the reported quantities at p, and the
** covariance s^2 (J^T W J)^-1. A quantity on a limit (held[]: rho on rho_min, s/H on the
** stability bound, the scale on the design cap) is set by the limit, not by the data: it is held
** here (its error undetermined), or the others' errors would carry its freedom along the limit. */
static void standard_errors(ctx *c, const cf_visco_params *p, const int held[3], double s2,
                            cf_visco_fit *res)
{
    for (int i = 0; i < 3; i++)
        res->ident_se.v[i] = -1;
    for (int i = 0; i < CF_PRONY_MAX; i++)
        res->se_g[i] = res->se_tau_s[i] = res->se_k[i] = res->se_g_max[i] = -1;
    res->se_eta_MPa_s = -1;
    const int nq = 3 + 2 * p->nbranch + 1 + (c->gs ? p->nbranch : 0);
    cf_visco_params q = *p;
    size_t k = 0;
    for (int which = 0; which < nq; which++)
        k += se_slot(c, held, which, &q) != NULL;
    if (k == 0 || c->n <= k)
        return;
    gsl_matrix *J = gsl_matrix_alloc(c->n, k), *cov = gsl_matrix_alloc(k, k);
    double *mp = malloc(c->n * sizeof(double)), *mm = malloc(c->n * sizeof(double));
    int ok = J && cov && mp && mm;
    c->oom |= !ok;
    size_t col = 0;
    for (int which = 0; ok && which < nq; which++)
        if (se_slot(c, held, which, &q))
            ok = se_column(c, p, held, which, J, col++, mp, mm);
    const int cs = ok ? gsl_multifit_nlinear_covar(J, 1e-13, cov) : GSL_FAILURE;
    c->oom |= cs == GSL_ENOMEM;
    if (cs == GSL_SUCCESS) {
        int colof[3 + 3 * CF_PRONY_MAX + 1];
        col = 0;
        for (int which = 0; which < nq; which++) {
            colof[which] = -1;
            if (!se_slot(c, held, which, &q))
                continue;
            double var = s2 * gsl_matrix_get(cov, col, col);
            se_store(which, p->nbranch, var > 0 && isfinite(var) ? sqrt(var) : -1, res);
            colof[which] = (int)col++;
        }
        /* each term's modulus at the largest strain, g_i + k_i x_max: its variance with the
        ** covariance of g_i and k_i */
        for (int i = 0; i < p->nbranch; i++) {
            const int cg = colof[3 + 2 * i], ck = c->gs ? colof[4 + 2 * p->nbranch + i] : -1;
            if (cg < 0 || ck < 0) {
                res->se_g_max[i] = cg < 0 ? -1 : res->se_g[i];
                continue;
            }
            const double x = c->xmax;
            double var = s2 * (gsl_matrix_get(cov, cg, cg) + x * x * gsl_matrix_get(cov, ck, ck) +
                               2 * x * gsl_matrix_get(cov, cg, ck));
            res->se_g_max[i] = var > 0 && isfinite(var) ? sqrt(var) : -1;
        }
    }
    if (J)
        gsl_matrix_free(J);
    if (cov)
        gsl_matrix_free(cov);
    free(mp);
    free(mm);
}

/* ---- one branch count ------------------------------------------------------------------------ */

/* The start when the stand-in found none: equal branches spread over the series. */
static void default_start(const ctx *c, int nb, start *s)
{
    s->obj = 1;
    memset(&s->p, 0, sizeof s->p);
    s->p.ident.rho = c->free_el ? 0.3 : c->o->elastic.rho;
    s->p.ident.solid = c->free_el ? 0.5 * (solid_lo(c, 0.3) + E_HI) : c->o->elastic.solid;
    s->p.ident.scale = c->free_el ? 1 : c->o->elastic.scale;
    s->p.nbranch = nb;
    double span = c->d->t_s[c->n - 1] - c->d->t_s[0];
    for (int i = 0; i < nb; i++) {
        s->p.g[i] = 0.5 / nb;
        s->p.tau_s[i] = span * pow(10, -(double)(nb - i));
    }
    s->p.eta_MPa_s = c->dash ? 1e-3 : 0;
}

/* Fits nb branches from the stand-in's starts and, when given, from `from` as well; fills p
** (actual scale and dashpot) and returns the weighted scaled sum of squares (HUGE_VAL when
** nothing could be evaluated). */
static double fit_nb(ctx *c, int nb, const cf_visco_params *from, cf_visco_params *pout)
{
    c->nb = nb;
    c->np = (size_t)((c->free_el ? 2 : 0) + 2 * nb + strain_terms(c) + (c->dash ? 1 : 0));
    /* relaxation depending on strain trades more freely against the elastic curve: more starts */
    const int nstarts = c->gs ? LM_STARTS_STRAIN : LM_STARTS;
    start best[LM_STARTS_STRAIN + 1];
    if (!stand_in(c, best + 1, nstarts))
        default_start(c, nb, &best[1]);
    best[0].obj = from ? 0.0 : HUGE_VAL;
    if (from)
        best[0].p = *from;
    double bestobj = HUGE_VAL;
    double *z = malloc(c->np * sizeof(double)), *zbest = malloc(c->np * sizeof(double));
    c->oom |= !z || !zbest;
    for (int s = 0; z && zbest && !c->oom && s <= nstarts; s++) {
        if (!(best[s].obj < HUGE_VAL))
            continue;
        cf_visco_params p0 = best[s].p;
        if (c->dash && !(p0.eta_MPa_s > 0))
            p0.eta_MPa_s = 1e-6 * p0.ident.scale;
        pack(c, &p0, z);
        double obj = lm_run(c, z);
        if (obj < bestobj) {
            bestobj = obj;
            memcpy(zbest, z, c->np * sizeof(double));
        }
    }
    if (bestobj < HUGE_VAL) {
        cf_visco_params p = unpack(c, zbest);
        if (c->free_el && curve(c, &p)) {
            double A = profile_scale(c, p.ident.rho, p.ident.solid);
            p.ident.scale = A;
            p.eta_MPa_s *= A;
        }
        *pout = p;
    }
    free(z);
    free(zbest);
    return bestobj;
}

/* ---- predictions ----------------------------------------------------------------------------- */

enum { PRED_PER = 200 }; /* samples per half of a predicted history */

/* One load-unload cycle to the series' largest strain at its loading rate: loop area and loading
** work. */
static void predict_cycle(const cf_visco_params *p, const cf_visco_setup *s, double xpeak,
                          double tload, cf_visco_predict *out)
{
    double ts[2 * PRED_PER + 1];
    cf_msm_sample smp[2 * PRED_PER + 1];
    cf_error e = {0};
    double pt[3] = {0, tload, 2 * tload}, pv[3] = {0, fabs(xpeak), 0};
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 3, pt, pv};
    for (int k = 0; k <= 2 * PRED_PER; k++)
        ts[k] = 2 * tload * k / (2.0 * PRED_PER);
    if (cf_visco_run(p, s, &path, ts, 2 * PRED_PER + 1, smp, &e) != CF_OK) {
        snprintf(out->note, sizeof out->note, "hysteresis: %.480s", e.msg);
        return;
    }
    double area = 0, work = 0;
    for (int k = 1; k <= 2 * PRED_PER; k++) {
        double dA = 0.5 * (smp[k].stress_MPa + smp[k - 1].stress_MPa) *
                    (smp[k].strain - smp[k - 1].strain);
        area += dA;
        if (k <= PRED_PER)
            work += dA;
    }
    out->hysteresis_done = 1;
    out->cycle_strain = xpeak;
    out->cycle_period_s = 2 * tload;
    out->loop_area_MPa = area;
    out->loading_work_MPa = work;
}

/* Creep under the stress sc (MPa, magnitude) applied in tload and held for thold; sgn is the
** table's sign of the loading. */
static void predict_creep(const cf_visco_params *p, const cf_visco_setup *s, double sc,
                          double sgn, double tload, double thold, cf_visco_predict *out)
{
    double ts[2 * PRED_PER + 1];
    cf_msm_sample smp[2 * PRED_PER + 1];
    double pt[3] = {0, tload, tload + thold}, pv[3] = {0, sc, sc};
    cf_msm_path path = {CF_DRIVE_FORCE, 3, pt, pv};
    for (int k = 0; k <= 2 * PRED_PER; k++)
        ts[k] = k <= PRED_PER ? tload * k / PRED_PER : tload + thold * (k - PRED_PER) / PRED_PER;
    cf_error ce = {0};
    if (sc > 0 && cf_visco_run(p, s, &path, ts, 2 * PRED_PER + 1, smp, &ce) == CF_OK) {
        out->creep_done = 1;
        out->creep_stress_MPa = sgn * sc;
        out->creep_ramp_s = tload;
        out->creep_hold_s = thold;
        out->creep_strain_ramp = sgn * smp[PRED_PER].strain;
        out->creep_strain_end = sgn * smp[2 * PRED_PER].strain;
    } else if (!out->note[0]) {
        snprintf(out->note, sizeof out->note, "creep: %.480s",
                 sc > 0 ? ce.msg : "the series ends at zero stress");
    }
}

void cf_visco_predictions(const cf_visco_params *p, const cf_visco_setup *s,
                          const cf_visco_data *d, cf_visco_predict *out)
{
    memset(out, 0, sizeof *out);
    const size_t n = d->count;
    /* the largest strain, when it is first reached, and the loading time from the last zero */
    size_t kp = 0;
    for (size_t k = 0; k < n; k++)
        if (fabs(d->x[k]) > fabs(d->x[kp]))
            kp = k;
    size_t k0 = 0;
    for (size_t k = 0; k < kp; k++)
        if (d->x[k] == 0)
            k0 = k;
    double tload = d->t_s[kp] - d->t_s[k0];
    double thold = d->t_s[n - 1] - d->t_s[kp];
    if (!(tload > 0))
        tload = 1;
    if (!(thold > 0))
        thold = tload;
    predict_cycle(p, s, d->x[kp], tload, out);
    predict_creep(p, s, fabs(d->y[n - 1]), d->x[kp] < 0 ? -1.0 : 1.0, tload, thold, out);
}

/* ---- the fit --------------------------------------------------------------------------------- */

void cf_visco_fit_free(cf_visco_fit *r)
{
    if (!r)
        return;
    free(r->model_MPa);
    free(r->is_hold);
    r->model_MPa = NULL;
    r->is_hold = NULL;
}

/* Where the static elastic lattice of stable_cells^3 cells of the spring (rho, s/H, F_C/H^2)
** first loses stability (table's sign), by the scan of cf_msm_stability_limit on each side the
** series reaches: a side where it does so within the series first, else the side of the
** series' largest strain. 0 when it stays stable to 0.995 of solid or cannot be scanned. */
static double stability_limit(const ctx *c, double rho, double B, double A)
{
    const cf_ident q = {.rho = rho, .solid = B, .scale = A};
    cf_spring sp = cf_ident_member(&q);
    cf_law law;
    cf_error e = {0};
    cf_msm_config cfg = c->o->setup.cfg;
    cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = c->o->stable_cells;
    if (cf_law_init(&law, &sp, &e) != CF_OK)
        return 0;
    const double reach[2] = {c->xlo, c->xhi};
    double lim[2] = {0, 0};
    for (int side = 0; side < 2; side++)
        if (reach[side] == 0 ||
            cf_msm_stability_limit(&law, c->o->setup.method, &cfg, side ? 1 : -1, &lim[side],
                                   &e) != CF_OK)
            lim[side] = 0;
    cf_law_free(&law);
    for (int side = 0; side < 2; side++)
        if (lim[side] != 0 && fabs(lim[side]) <= fabs(reach[side]))
            return lim[side];
    return lim[-c->xlo >= c->xhi ? 0 : 1];
}

/* Checks the options against the series and fills the fit state (weights, bounds, limits). */
static cf_status fit_setup(ctx *c, const cf_visco_data *d, const cf_visco_fit_options *o,
                           cf_error *err)
{
    const size_t n = d->count;
    memset(c, 0, sizeof *c);
    c->d = d;
    c->o = o;
    c->n = n;
    c->free_el = !o->hold_elastic;
    c->dash = o->dashpot != 0;
    c->series.count = n;
    c->series.t_s = d->t_s;
    c->series.strain = d->x;
    for (size_t k = 0; k < n; k++) {
        c->ymax = fmax(c->ymax, fabs(d->y[k]));
        c->xmax = fmax(c->xmax, fabs(d->x[k]));
        c->xlo = fmin(c->xlo, d->x[k]);
        c->xhi = fmax(c->xhi, d->x[k]);
    }
    c->e_lo = c->xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    c->rho_lo = o->rho_min > 0 && o->rho_min < RHO_HI ? o->rho_min : 1e-3;
    const double *el = o->elastic.v;
    if (o->hold_elastic && (!(el[0] > 0 && el[0] <= 1) || !(el[1] > c->xmax && el[1] < 1) ||
                            !(el[2] > 0) || !isfinite(el[2])))
        return cf_error_set(err, CF_E_DATA,
                            "the held elastic fit (rho %g, s/H %g, F_C/H^2 %g MPa) cannot carry "
                            "this series: its solid strain must exceed the largest strain %g",
                            el[0], el[1], el[2], c->xmax);
    if (!(c->e_lo < E_HI))
        return cf_error_set(err, CF_E_DATA, "largest strain %g: no conical spring reaches it",
                            c->xmax);
    c->sw = malloc(n * sizeof(double));
    c->m = malloc(n * sizeof(double));
    if (!c->sw || !c->m)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", n);
    for (size_t k = 0; k < n; k++) {
        double sc = o->relative ? fmax(fabs(d->y[k]), REL_FLOOR * c->ymax) : 1.0;
        c->sw[k] = sqrt(d->w ? d->w[k] : 1.0) / sc;
        c->ynorm += (c->sw[k] * d->y[k]) * (c->sw[k] * d->y[k]);
    }
    if (!(c->ynorm > 0))
        return cf_error_set(err, CF_E_DATA, "every stress of the series is zero");
    cf_visco_limits_init(&c->lim, o->limits, o->limit_types, c->free_el ? o->stable_cells : 0,
                         &o->setup, c->xlo, c->xhi, c->rho_lo, RHO_HI, c->e_lo, E_HI);
    if (c->lim.unstable_everywhere)
        return cf_error_set(err, CF_E_DATA,
                            "no conical spring (rho %g to 1, solid strain to %g) gives a lattice "
                            "of %d^3 cells that stays stable to the series' largest strain %g",
                            c->rho_lo, E_HI, o->stable_cells, c->xmax);
    if (o->hold_elastic && o->stable_cells > 0) {
        /* the held spring is not fitted, so its lattice is checked as the fitted one is kept:
        ** stable at the series' largest strain, or refused */
        cf_visco_limits held = c->lim;
        held.cells = o->stable_cells;
        if (!cf_visco_limits_stable(&held, el[0], el[1])) {
            double at = stability_limit(c, el[0], el[1], el[2]);
            char where[96] = "is not stable at that strain";
            if (at != 0)
                snprintf(where, sizeof where, "loses stability at strain %.6g", at);
            return cf_error_set(err, CF_E_DATA,
                                "the held elastic fit (rho %g, s/H %g, F_C/H^2 %g MPa): the "
                                "lattice of %d^3 cells of its spring %s, within the series' "
                                "strains %g to %g (held there it buckles); fit the elastic "
                                "part with the series instead (without --elastic)",
                                el[0], el[1], el[2], o->stable_cells, where, c->xlo, c->xhi);
        }
    }
    return CF_OK;
}

/* Which limits the fitted elastic quantities sit on (rho_min, the stability bound of s/H, the
** design cap of F_C/H^2): held there, their standard errors are not determined. */
static void limits_held(const ctx *c, const cf_visco_params *p, int held[3])
{
    held[0] = held[1] = held[2] = 0;
    if (!c->free_el)
        return;
    held[0] = p->ident.rho <= c->rho_lo * (1 + 1e-4);
    held[1] = c->lim.cells > 0 && solid_lo(c, p->ident.rho) > c->e_lo &&
              p->ident.solid <= solid_lo(c, p->ident.rho) * (1 + 1e-6);
    held[2] = p->ident.scale >=
              cf_visco_limits_scale_max(&c->lim, p->ident.rho, p->ident.solid) * (1 - 1e-9);
}

/* The limits of the fitted elastic quantities, and where the elastic lattice of the fitted (or
** held) spring loses stability. */
static void fit_limits(const ctx *c, const cf_visco_params *p, cf_visco_fit *res, int held[3])
{
    res->stable_to_strain = 0;
    if (c->o->stable_cells > 0)
        res->stable_to_strain = stability_limit(c, p->ident.rho, p->ident.solid, p->ident.scale);
    limits_held(c, p, held);
    res->rho_at_limit = held[0];
    res->at_stability_limit = held[1];
    res->at_design_limit = held[2];
}

/* 1 when a positive quantity v is larger than its standard error se (se > 0: determined). */
static int resolved(double v, double se)
{
    return se > 0 && se < v;
}

/* Whether the series determines the time-dependent quantities of candidate p, whose weighted
** residual variance is s2: the Jacobian has full rank in them, and each tau_i, each term's
** relative modulus at the largest strain (g_i + k_i x_max), each fitted k_i (its size) and the
** dashpot is larger than its standard error. A term the series cannot pin down (tau_i -> 0 or
** far past the series, a g_i of 0 with its tau_i free, two terms trading one for the other)
** fails it; AIC assumes a regular model and would reward such a fit's extra parameters. The
** errors are computed at s2 = 1 and scaled, so that a noiseless series (s2 -> 0) passes.
** *loose gets the terms whose k_i is fitted but not larger than its error. */
static int prony_identified(ctx *c, const cf_visco_params *p, double s2, unsigned *loose)
{
    int held[3];
    cf_visco_fit se;
    memset(&se, 0, sizeof se);
    limits_held(c, p, held);
    standard_errors(c, p, held, 1.0, &se);
    const double s = sqrt(s2);
    *loose = 0;
    int ok = !c->dash || resolved(p->eta_MPa_s, s * se.se_eta_MPa_s);
    for (int i = 0; i < p->nbranch; i++) {
        ok = ok && resolved(p->tau_s[i], s * se.se_tau_s[i]) &&
             resolved(p->g[i] + p->k[i] * c->xmax, s * se.se_g_max[i]);
        if (strain_term(c, i) && !resolved(fabs(p->k[i]), s * se.se_k[i])) {
            ok = 0;
            *loose |= 1u << i;
        }
    }
    return ok;
}

/* Candidate a is preferred to b: determined terms first, then the lower AIC. */
static int preferred(int ident_a, double aic_a, int ident_b, double aic_b)
{
    return ident_a != ident_b ? ident_a > ident_b : aic_a < aic_b;
}

/* One candidate: nb terms with c->gs and c->smask, started also from `from` when given. 1 when
** fitted (its AIC, whether the series determines it and its loose k_i in *aic, *ident, *loose),
** 0 when no model could be evaluated, -1 when memory ran out. */
static int candidate(ctx *c, int nb, const cf_visco_params *from, cf_visco_params *p, double *aic,
                     int *ident, unsigned *loose)
{
    if (!(fit_nb(c, nb, from, p) < HUGE_VAL) || !curve(c, p))
        return c->oom ? -1 : 0;
    double rss = 0, wrss = 0;
    for (size_t k = 0; k < c->n; k++) {
        const double r = c->m[k] - c->d->y[k];
        rss += r * r;
        wrss += c->sw[k] * c->sw[k] * r * r;
    }
    const int kpar = (c->free_el ? 3 : 0) + 2 * nb + strain_terms(c) + c->dash;
    *aic = (double)c->n * log(fmax(rss, 1e-300) / (double)c->n) + 2.0 * kpar;
    const double s2 = (double)c->n > kpar ? wrss / ((double)c->n - kpar) : 0;
    *ident = prony_identified(c, p, s2, loose);
    return c->oom ? -1 : 1;
}

/* Fits the branch counts asked for (or 1..CF_VISCO_AIC_MAX), quasi-linear, depending on strain or
** both, and keeps in *best the candidate whose terms the data determine with the lowest AIC (the
** lowest AIC of all when none is determined); every candidate's AIC in res->by_n. A candidate
** depending on strain whose k_i are not all determined is fitted again with those terms constant
** in strain (backward elimination, while some terms stay strain-dependent), and the preferred of
** the two kept. c->gs and c->smask are left at the kept candidate's. */
static cf_status fit_counts(ctx *c, cf_visco_fit *res, cf_visco_params *best, cf_error *err)
{
    const cf_visco_fit_options *o = c->o;
    const int nlo = o->nbranch ? o->nbranch : 1, nhi = o->nbranch ? o->nbranch : CF_VISCO_AIC_MAX;
    double best_aic = HUGE_VAL;
    int best_ident = 0, best_gs = 0;
    unsigned best_mask = 0;
    memset(best, 0, sizeof *best);
    res->chosen_by_aic = o->nbranch == 0 || o->relaxation == CF_RELAX_AUTO;
    const int gslo = o->relaxation == CF_RELAX_STRAIN, gshi = o->relaxation != CF_RELAX_QLV;
    for (int v = 0; v < (nhi - nlo + 1) * (gshi - gslo + 1); v++) {
        const int nb = nlo + v / (gshi - gslo + 1);
        c->gs = gslo + v % (gshi - gslo + 1);
        c->smask = (1u << nb) - 1;
        cf_visco_params p, q;
        double aic = HUGE_VAL, aq;
        int ident = 0, iq, fitted = 0, st;
        unsigned lq, mask = c->smask;
        cf_visco_params from;
        const cf_visco_params *fp = NULL;
        while ((st = candidate(c, nb, fp, &q, &aq, &iq, &lq)) != 0) {
            if (st < 0)
                return cf_error_set(err, CF_E_INTERNAL,
                                    "out of memory in the viscoelastic fit of %d Prony term%s",
                                    nb, nb == 1 ? "" : "s");
            if (!fitted || preferred(iq, aq, ident, aic)) {
                p = q;
                aic = aq;
                ident = iq;
                mask = c->smask;
            }
            fitted = 1;
            /* again without the loose k_i, while some stay */
            if (iq || !lq || (c->smask & ~lq) == 0 || c->smask != mask)
                break;
            c->smask &= ~lq;
            from = q; /* the loose terms held at their modulus halfway along the strain */
            for (int i = 0; i < nb; i++)
                if (lq >> i & 1u) {
                    from.g[i] += 0.5 * from.k[i] * c->xmax;
                    from.k[i] = 0;
                }
            fp = &from;
        }
        if (!fitted)
            continue;
        c->smask = mask;
        if (nb - 1 < CF_VISCO_AIC_MAX)
            res->by_n[nb - 1][c->gs] =
                (cf_visco_candidate){1, aic, ident, c->gs ? strain_terms(c) : 0};
        if (best_aic == HUGE_VAL || preferred(ident, aic, best_ident, best_aic)) {
            best_aic = aic;
            best_ident = ident;
            best_gs = c->gs;
            best_mask = c->smask;
            *best = p;
        }
    }
    if (!(best_aic < HUGE_VAL))
        return cf_error_set(err, CF_E_NOCONV,
                            "no viscoelastic model could be evaluated along this series");
    res->identified = best_ident;
    c->gs = best_gs;
    c->smask = best_mask;
    c->nb = best->nbranch;
    return CF_OK;
}

/* The quality of the model curve in res->model_MPa: RSS, RMSE overall, on ramps and in holds,
** R^2, AIC; returns the weighted RSS. */
static double fit_quality(const ctx *c, cf_visco_fit *res)
{
    const cf_visco_data *d = c->d;
    const size_t n = c->n;
    double ssr = 0, ssh = 0, mean = 0, sst = 0, wrss = 0;
    for (size_t k = 0; k < n; k++)
        mean += d->y[k] / (double)n;
    for (size_t k = 0; k < n; k++) {
        double r = res->model_MPa[k] - d->y[k];
        res->rss += r * r;
        wrss += (c->sw[k] * r) * (c->sw[k] * r);
        sst += (d->y[k] - mean) * (d->y[k] - mean);
        res->max_abs_error = fmax(res->max_abs_error, fabs(r));
        if (res->is_hold[k]) {
            ssh += r * r;
            res->n_hold++;
        } else {
            ssr += r * r;
            res->n_ramp++;
        }
    }
    res->rmse = sqrt(res->rss / (double)n);
    res->rmse_ramp = res->n_ramp ? sqrt(ssr / (double)res->n_ramp) : -1;
    res->rmse_hold = res->n_hold ? sqrt(ssh / (double)res->n_hold) : -1;
    res->r2 = sst > 0 ? 1 - res->rss / sst : 0;
    res->aic = (double)n * log(fmax(res->rss, 1e-300) / (double)n) + 2.0 * res->k;
    return wrss;
}

/* The reported model: its curve, quality, standard errors, moduli and predictions. */
static cf_status fit_report(ctx *c, const cf_visco_params *bestp, cf_visco_fit *res,
                            cf_error *err)
{
    const cf_visco_fit_options *o = c->o;
    cf_error e = {0};
    cf_status st;
    c->nb = bestp->nbranch;
    if ((st = cf_visco_curve(bestp, &o->setup, &c->series, res->model_MPa, NULL, &e)) != CF_OK)
        return cf_error_set(err, st, "%s", e.msg);
    c->evals++;
    res->p = *bestp;
    res->dashpot = c->dash;
    res->held_elastic = !c->free_el;
    res->count = c->n;
    res->strain_relaxation = c->gs; /* and c->smask: those of the kept candidate */
    res->strain_mask = c->gs ? c->smask & ((1u << bestp->nbranch) - 1) : 0;
    res->x_max = c->xmax;
    res->k = (c->free_el ? 3 : 0) + 2 * bestp->nbranch + strain_terms(c) + c->dash;
    double wrss = fit_quality(c, res);
    double s2 = (double)c->n > res->k ? wrss / ((double)c->n - res->k) : 0;
    int held[3];
    fit_limits(c, bestp, res, held);
    standard_errors(c, bestp, held, s2, res);
    if (c->oom)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the standard errors of the "
                                                "viscoelastic fit");
    /* small-strain moduli of the lattice */
    double Eel[1], small = -1e-3 * bestp->ident.solid;
    if (cf_visco_elastic_curve(bestp, &o->setup, &small, 1, Eel, &e) == CF_OK) {
        double ginf = 1;
        for (int i = 0; i < bestp->nbranch; i++)
            ginf -= bestp->g[i];
        res->E_inst_MPa = Eel[0] / small;
        res->E_eq_MPa = ginf * res->E_inst_MPa;
    }
    cf_visco_predictions(bestp, &o->setup, c->d, &res->pred);
    return CF_OK;
}

cf_status cf_visco_fit_run(const cf_visco_data *d, const cf_visco_fit_options *o,
                           cf_visco_fit *res, cf_error *err)
{
    const double t0 = cf_clock_s();
    memset(res, 0, sizeof *res);
    const size_t n = d->count;
    if (o->nbranch < 0 || o->nbranch > CF_PRONY_MAX)
        return cf_error_set(err, CF_E_DATA, "--branches %d: must be between 1 and %d",
                            o->nbranch, CF_PRONY_MAX);
    res->is_hold = malloc(n ? n : 1);
    res->model_MPa = malloc((n ? n : 1) * sizeof(double));
    if (!res->is_hold || !res->model_MPa) {
        cf_visco_fit_free(res);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", n);
    }
    cf_status st = cf_visco_data_check(d, res->is_hold, err);
    if (st != CF_OK) {
        cf_visco_fit_free(res);
        return st;
    }
    ctx c;
    cf_visco_params bestp;
    if ((st = fit_setup(&c, d, o, err)) == CF_OK && (st = fit_counts(&c, res, &bestp, err)) == CF_OK)
        st = fit_report(&c, &bestp, res, err);
    if (st == CF_OK && c.oom)
        st = cf_error_set(err, CF_E_INTERNAL,
                          "out of memory in the viscoelastic fit's errors and predictions");
    res->evaluations = c.evals;
    res->wall_time_s = cf_clock_s() - t0;
    free(c.sw);
    free(c.m);
    cf_visco_limits_free(&c.lim);
    if (st != CF_OK)
        cf_visco_fit_free(res);
    return st;
}
