/*
** Fitting the time-dependent model to a measured time series (see viscofit.h).
*/
#include "conifit/viscofit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

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
#define LM_MAX_ITER 150
#define LM_STALL 6
#define LM_STALL_REL 1e-10
#define LM_FLOOR_REL 1e-28
/* g_i = e^a_i / (1 + sum e^a_j): a_i is kept above this (g_i ~ 1e-13, a branch switched off). */
#define A_LO -30.0
/* Relative step of the central differences for the standard errors. */
#define SE_STEP 1e-5

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double logit(double p)
{
    p = fmin(fmax(p, 1e-15), 1 - 1e-15);
    return log(p / (1 - p));
}

static double expit(double z)
{
    return z >= 0 ? 1 / (1 + exp(-z)) : exp(z) / (1 + exp(z));
}

cf_visco_fit_options cf_visco_fit_default_options(void)
{
    cf_visco_fit_options o;
    memset(&o, 0, sizeof o);
    o.setup = cf_visco_default();
    o.rho_min = CF_FIT_RHO_MIN_DEFAULT;
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
    size_t np;          /* LM parameters */
    double *sw;         /* residual weights */
    double ynorm;       /* weighted sum of y^2 */
    double ymax, xmax;
    double e_lo;        /* lower bound of s/H */
    double rho_lo;      /* lower bound of rho (the fitter's rho_min) */
    double *m;          /* model curve scratch (n) */
    cf_visco_series series;
    long evals;
} ctx;

/* LM coordinates -> model parameters; the stress scale is 1 (profiled) or the held one, the
** dashpot relative to it. */
static cf_visco_params unpack(const ctx *c, const double *z)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    size_t j = 0;
    if (c->free_el) {
        p.rho = c->rho_lo + (RHO_HI - c->rho_lo) * expit(z[j++]);
        p.solid_strain = c->e_lo + (E_HI - c->e_lo) * expit(z[j++]);
        p.stress_scale_MPa = 1.0;
    } else {
        p.rho = c->o->elastic[0];
        p.solid_strain = c->o->elastic[1];
        p.stress_scale_MPa = c->o->elastic[2];
    }
    p.nbranch = c->nb;
    double sum = 1, ea[CF_PRONY_MAX];
    for (int i = 0; i < c->nb; i++) {
        p.tau_s[i] = exp(z[j++]);
        ea[i] = exp(fmax(z[j++], A_LO));
        sum += ea[i];
    }
    for (int i = 0; i < c->nb; i++)
        p.g[i] = ea[i] / sum;
    p.eta_MPa_s = c->dash ? exp(z[j++]) * p.stress_scale_MPa : 0.0;
    return p;
}

static void pack(const ctx *c, const cf_visco_params *p, double *z)
{
    size_t j = 0;
    if (c->free_el) {
        z[j++] = logit((p->rho - c->rho_lo) / (RHO_HI - c->rho_lo));
        z[j++] = logit((p->solid_strain - c->e_lo) / (E_HI - c->e_lo));
    }
    double ginf = 1;
    for (int i = 0; i < c->nb; i++)
        ginf -= p->g[i];
    ginf = fmax(ginf, 1e-12);
    for (int i = 0; i < c->nb; i++) {
        z[j++] = log(p->tau_s[i]);
        z[j++] = p->g[i] > 0 ? fmax(log(p->g[i] / ginf), A_LO) : A_LO;
    }
    if (c->dash)
        z[j++] = log(fmax(p->eta_MPa_s / p->stress_scale_MPa, 1e-300));
}

/* The model at p into c->m; returns 0 on failure. */
static int curve(ctx *c, const cf_visco_params *p)
{
    cf_error e = {0};
    c->evals++;
    return cf_visco_curve(p, &c->o->setup, &c->series, c->m, NULL, &e) == CF_OK;
}

/* The best stress scale for the curve in c->m (weighted least squares), or the held one. */
static double profile_scale(const ctx *c)
{
    if (!c->free_el)
        return 1.0; /* the curve already carries the held scale */
    double gy = 0, gg = 0;
    for (size_t k = 0; k < c->n; k++) {
        double w = c->sw[k] * c->sw[k];
        gy += w * c->m[k] * c->d->y[k];
        gg += w * c->m[k] * c->m[k];
    }
    double A = gg > 0 ? gy / gg : 0;
    return isfinite(A) && A > 0 ? A : 0;
}

static int lm_f(const gsl_vector *zv, void *data, gsl_vector *f)
{
    ctx *c = data;
    cf_visco_params p = unpack(c, zv->data);
    double A = 0;
    int ok = curve(c, &p) && (A = profile_scale(c)) > 0;
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
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    fp.trs = gsl_multifit_nlinear_trs_lm;
    fp.scale = gsl_multifit_nlinear_scale_more;
    fp.h_df = 1e-7;
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, c->n, c->np);
    if (!w)
        return HUGE_VAL;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.df = NULL; /* forward differences */
    fdf.n = c->n;
    fdf.p = c->np;
    fdf.params = c;
    gsl_vector_view x0 = gsl_vector_view_array(z, c->np);
    double best = HUGE_VAL;
    if (gsl_multifit_nlinear_init(&x0.vector, &fdf, w) == GSL_SUCCESS) {
        gsl_vector *f = gsl_multifit_nlinear_residual(w);
        double prev;
        gsl_blas_ddot(f, f, &prev);
        int stall = 0;
        for (int it = 0; it < LM_MAX_ITER; it++) {
            int info;
            if (gsl_multifit_nlinear_iterate(w) != GSL_SUCCESS)
                break;
            if (gsl_multifit_nlinear_test(1e-14, 1e-14, 0, &info, w) == GSL_SUCCESS)
                break;
            double cur;
            gsl_blas_ddot(f, f, &cur);
            stall = (prev - cur <= LM_STALL_REL * prev) ? stall + 1 : 0;
            prev = cur;
            if (stall >= LM_STALL || cur <= LM_FLOOR_REL)
                break;
        }
        gsl_blas_ddot(f, f, &best);
        memcpy(z, gsl_multifit_nlinear_position(w)->data, c->np * sizeof(double));
        if (!isfinite(best))
            best = HUGE_VAL;
    }
    gsl_multifit_nlinear_free(w);
    return best;
}

/* ---- stage A: the stand-in search ------------------------------------------------------------ */

/* Solves the m x m system G a = b (Gaussian elimination with partial pivoting); 0 if singular. */
static int small_solve(int m, double *G, double *b, double *a)
{
    for (int i = 0; i < m; i++) {
        int piv = i;
        for (int r = i + 1; r < m; r++)
            if (fabs(G[r * m + i]) > fabs(G[piv * m + i]))
                piv = r;
        if (!(fabs(G[piv * m + i]) > 1e-300))
            return 0;
        if (piv != i) {
            for (int k = 0; k < m; k++) {
                double t = G[i * m + k];
                G[i * m + k] = G[piv * m + k];
                G[piv * m + k] = t;
            }
            double t = b[i];
            b[i] = b[piv];
            b[piv] = t;
        }
        for (int r = i + 1; r < m; r++) {
            double f = G[r * m + i] / G[i * m + i];
            for (int k = i; k < m; k++)
                G[r * m + k] -= f * G[i * m + k];
            b[r] -= f * b[i];
        }
    }
    for (int i = m - 1; i >= 0; i--) {
        double s = b[i];
        for (int k = i + 1; k < m; k++)
            s -= G[i * m + k] * a[k];
        a[i] = s / G[i * m + i];
        if (!isfinite(a[i]))
            return 0;
    }
    return 1;
}

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
        if (best[i].obj < HUGE_VAL && best[i].p.rho == p->rho &&
            best[i].p.solid_strain == p->solid_strain) {
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

/* For one elastic curve E (unit or held scale) and the Prony responses R[t][k] of every grid time
** constant, tries every set of nb time constants and keeps the best feasible ones in best. */
static void search_taus(ctx *c, const double *E, double *const *R, const double *taus,
                        const double *rate, double rate_factor, const cf_visco_params *el,
                        start *best, int nbest)
{
    const int nb = c->nb, held = !c->free_el;
    const int m = (held ? 0 : 1) + nb + c->dash; /* unknowns: A, A g_i, dashpot */
    int idx[CF_PRONY_MAX];
    for (int i = 0; i < nb; i++)
        idx[i] = i;
    const double *basis[2 + CF_PRONY_MAX];
    double *tmp = malloc((size_t)(nb + 1) * c->n * sizeof(double));
    if (!tmp)
        return;
    for (;;) {
        /* basis: E (when the scale is free), R_i - E (coefficient A g_i), the rate */
        int nbas = 0;
        if (!held)
            basis[nbas++] = E;
        for (int i = 0; i < nb; i++) {
            double *b = tmp + (size_t)i * c->n;
            for (size_t k = 0; k < c->n; k++)
                b[k] = R[idx[i]][k] - E[k];
            basis[nbas++] = b;
        }
        if (c->dash)
            basis[nbas++] = rate;
        double G[(2 + CF_PRONY_MAX) * (2 + CF_PRONY_MAX)], rhs[2 + CF_PRONY_MAX],
            a[2 + CF_PRONY_MAX];
        for (int i = 0; i < m; i++) {
            rhs[i] = 0;
            for (int j = 0; j < m; j++)
                G[i * m + j] = 0;
        }
        for (size_t k = 0; k < c->n; k++) {
            double w = c->sw[k] * c->sw[k];
            double yk = c->d->y[k] - (held ? E[k] : 0.0);
            for (int i = 0; i < m; i++) {
                rhs[i] += w * basis[i][k] * yk;
                for (int j = 0; j <= i; j++)
                    G[i * m + j] += w * basis[i][k] * basis[j][k];
            }
        }
        for (int i = 0; i < m; i++)
            for (int j = i + 1; j < m; j++)
                G[i * m + j] = G[j * m + i];
        if (small_solve(m, G, rhs, a)) {
            double A = held ? 1.0 : a[0], gs = 0;
            int ok = A > 0;
            cf_visco_params p = *el;
            p.nbranch = nb;
            for (int i = 0; i < nb && ok; i++) {
                p.g[i] = a[(held ? 0 : 1) + i] / A;
                p.tau_s[i] = taus[idx[i]];
                ok = p.g[i] >= 0;
                gs += p.g[i];
            }
            ok = ok && gs < 1 - 1e-9;
            if (c->dash) {
                double cd = a[m - 1];
                ok = ok && cd > 0;
                p.eta_MPa_s = cd * rate_factor; /* MPa s */
            }
            if (ok) {
                double sum = 0;
                for (size_t k = 0; k < c->n; k++) {
                    double model = held ? E[k] : 0.0;
                    for (int i = 0; i < m; i++)
                        model += a[i] * basis[i][k];
                    double r = c->sw[k] * (model - c->d->y[k]);
                    sum += r * r;
                }
                if (!held)
                    p.stress_scale_MPa *= A;
                keep_start(best, nbest, sum / c->ynorm, &p);
            }
        }
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
}

/* Static lattice stress (table's sign) of the model's elastic part at every strain of the
** series, and the small-strain ratio of the lattice modulus to the spring's k0/H (the factor
** that maps a spring's dashpot to the lattice's). */
static int elastic_curve(ctx *c, double rho, double e, double A, double *E, double *lat_factor)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    p.rho = rho;
    p.solid_strain = e;
    p.stress_scale_MPa = A;
    cf_error err = {0};
    c->evals++;
    if (cf_visco_elastic_curve(&p, &c->o->setup, c->d->x, c->n, E, &err) != CF_OK)
        return 0;
    if (!lat_factor)
        return 1;
    cf_spring sp = cf_spring_member(rho, e, A);
    cf_law law;
    double small = -1e-3 * e, s0 = 0;
    if (cf_law_init(&law, &sp, &err) != CF_OK ||
        cf_visco_elastic_curve(&p, &c->o->setup, &small, 1, &s0, &err) != CF_OK)
        return 0;
    *lat_factor = (s0 / small) / (law.k0_N_per_mm / sp.H_mm);
    cf_law_free(&law);
    return *lat_factor > 0;
}

/* Stage A: the best starts for nb branches. */
static int stand_in(ctx *c, start *best, int nbest)
{
    for (int i = 0; i < nbest; i++)
        best[i].obj = HUGE_VAL;
    const size_t n = c->n;
    const double *t = c->d->t_s;
    double dtmin = HUGE_VAL;
    for (size_t k = 1; k < n; k++)
        dtmin = fmin(dtmin, t[k] - t[k - 1]);
    const double span = t[n - 1] - t[0];
    double taus[GRID_TAU];
    const double tlo = 0.5 * dtmin, thi = 2 * span;
    for (int i = 0; i < GRID_TAU; i++)
        taus[i] = tlo * pow(thi / tlo, (double)i / (GRID_TAU - 1));
    double *E = malloc(n * sizeof(double)), *rate = calloc(n, sizeof(double));
    double *Rbuf = malloc((size_t)GRID_TAU * n * sizeof(double));
    double *R[GRID_TAU];
    if (!E || !rate || !Rbuf) {
        free(E);
        free(rate);
        free(Rbuf);
        return 0;
    }
    for (int i = 0; i < GRID_TAU; i++)
        R[i] = Rbuf + (size_t)i * n;
    for (size_t k = 1; k < n; k++)
        rate[k] = (c->d->x[k] - c->d->x[k - 1]) / (t[k] - t[k - 1]);
    int nrho = c->free_el ? GRID_RHO : 1, ne = c->free_el ? GRID_E : 1;
    for (int ir = 0; ir < nrho; ir++)
        for (int ie = 0; ie < ne; ie++) {
            double rho, e, A;
            if (c->free_el) {
                const double r0 = fmax(c->rho_lo * 1.001, 0.02);
                rho = r0 * pow(0.98 / r0, (double)ir / (GRID_RHO - 1));
                double f = (ie + 1.0) / (GRID_E + 1.0);
                e = c->e_lo + (E_HI - c->e_lo) * f * f;
                A = 1;
            } else {
                rho = c->o->elastic[0];
                e = c->o->elastic[1];
                A = c->o->elastic[2];
            }
            double fac = 1;
            if (!elastic_curve(c, rho, e, A, E, &fac))
                continue;
            /* Prony responses per unit g: h_k = e h_(k-1) + b (E_k - E_(k-1)), relaxed start */
            for (int i = 0; i < GRID_TAU; i++) {
                R[i][0] = 0;
                for (size_t k = 1; k < n; k++) {
                    double h = t[k] - t[k - 1];
                    double ex = exp(-h / taus[i]), b = -expm1(-h / taus[i]) * taus[i] / h;
                    R[i][k] = ex * R[i][k - 1] + b * (E[k] - E[k - 1]);
                }
            }
            cf_visco_params el;
            memset(&el, 0, sizeof el);
            el.rho = rho;
            el.solid_strain = e;
            el.stress_scale_MPa = A;
            /* a dashpot eta beside every spring adds about eta * fac * rate to the stress */
            search_taus(c, E, R, taus, rate, 1 / fac, &el, best, nbest);
        }
    free(E);
    free(rate);
    free(Rbuf);
    return best[0].obj < HUGE_VAL;
}

/* ---- standard errors ------------------------------------------------------------------------- */

/* Central-difference Jacobian of the weighted model in the reported quantities at p, and the
** covariance s^2 (J^T J)^-1. Fills the standard errors of res. */
static void standard_errors(ctx *c, const cf_visco_params *p, double s2, cf_visco_fit *res)
{
    for (int i = 0; i < 3; i++)
        res->se_ident[i] = -1;
    for (int i = 0; i < CF_PRONY_MAX; i++)
        res->se_g[i] = res->se_tau_s[i] = -1;
    res->se_eta_MPa_s = -1;
    /* parameter list: rho, s/H, scale (free elastic), g_i, tau_i, eta */
    const int nb = p->nbranch;
    /* rho on its lower bound is set by the limit, not by the data: it is held here (its error
    ** undetermined), or the others' errors would carry its freedom along the bound */
    const int rho_held = !c->free_el || p->rho <= c->rho_lo * (1 + 1e-4);
    res->rho_at_limit = c->free_el && rho_held;
    const size_t k = (size_t)((c->free_el ? 3 : 0) - (c->free_el && rho_held) + 2 * nb +
                              (c->dash ? 1 : 0));
    if (k == 0 || c->n <= k)
        return;
    gsl_matrix *J = gsl_matrix_alloc(c->n, k), *cov = gsl_matrix_alloc(k, k);
    double *mp = malloc(c->n * sizeof(double)), *mm = malloc(c->n * sizeof(double));
    if (!J || !cov || !mp || !mm)
        goto out;
    size_t col = 0;
    int ok = 1;
    for (int which = 0; ok && which < 3 + 2 * nb + 1; which++) {
        double *slot = NULL;
        cf_visco_params q = *p;
        if (which < 3) {
            if (!c->free_el || (which == 0 && rho_held))
                continue;
            slot = which == 0 ? &q.rho : which == 1 ? &q.solid_strain : &q.stress_scale_MPa;
        } else if (which < 3 + 2 * nb) {
            int i = (which - 3) / 2;
            slot = (which - 3) % 2 == 0 ? &q.g[i] : &q.tau_s[i];
        } else {
            if (!c->dash)
                continue;
            slot = &q.eta_MPa_s;
        }
        const double v = *slot;
        const int is_g = which >= 3 && which < 3 + 2 * nb && (which - 3) % 2 == 0;
        double h = SE_STEP * fmax(fabs(v), is_g ? 1e-2 : 1e-300);
        double hp = h, hm = h;
        if (which == 0) { /* keep rho inside (0, 1] */
            hp = fmin(h, 1 - v);
            hm = fmin(h, 0.5 * v);
        } else if (which == 1) { /* s/H inside (largest strain, 1) */
            hm = fmin(h, 0.5 * (v - c->xmax));
            hp = fmin(h, 0.5 * (1 - v));
        } else if (is_g) {
            hm = fmin(h, v); /* g >= 0 */
        }
        if (!(hp > 0) && !(hm > 0)) {
            ok = 0;
            break;
        }
        cf_error e = {0};
        *slot = v + hp;
        ok = cf_visco_curve(&q, &c->o->setup, &c->series, mp, NULL, &e) == CF_OK;
        *slot = v - hm;
        ok = ok && cf_visco_curve(&q, &c->o->setup, &c->series, mm, NULL, &e) == CF_OK;
        c->evals += 2;
        for (size_t r = 0; ok && r < c->n; r++)
            gsl_matrix_set(J, r, col, c->sw[r] * (mp[r] - mm[r]) / (hp + hm));
        col++;
    }
    if (ok && gsl_multifit_nlinear_covar(J, 1e-13, cov) == GSL_SUCCESS) {
        col = 0;
        for (int which = 0; which < 3 + 2 * nb + 1; which++) {
            if ((which < 3 && !c->free_el) || (which == 0 && rho_held) ||
                (which == 3 + 2 * nb && !c->dash))
                continue;
            double var = s2 * gsl_matrix_get(cov, col, col);
            double se = var > 0 && isfinite(var) ? sqrt(var) : -1;
            if (which < 3)
                res->se_ident[which] = se;
            else if (which < 3 + 2 * nb) {
                int i = (which - 3) / 2;
                if ((which - 3) % 2 == 0)
                    res->se_g[i] = se;
                else
                    res->se_tau_s[i] = se;
            } else
                res->se_eta_MPa_s = se;
            col++;
        }
    }
out:
    gsl_matrix_free(J);
    gsl_matrix_free(cov);
    free(mp);
    free(mm);
}

/* ---- one branch count ------------------------------------------------------------------------ */

/* Fits nb branches; fills p (actual scale and dashpot) and returns the weighted scaled sum of
** squares (HUGE_VAL when nothing could be evaluated). */
static double fit_nb(ctx *c, int nb, cf_visco_params *pout)
{
    c->nb = nb;
    c->np = (size_t)((c->free_el ? 2 : 0) + 2 * nb + (c->dash ? 1 : 0));
    start best[LM_STARTS];
    if (!stand_in(c, best, LM_STARTS)) {
        /* no feasible stand-in: equal branches spread over the series */
        best[0].obj = 1;
        memset(&best[0].p, 0, sizeof best[0].p);
        best[0].p.rho = c->free_el ? 0.3 : c->o->elastic[0];
        best[0].p.solid_strain = c->free_el ? 0.5 * (c->e_lo + E_HI) : c->o->elastic[1];
        best[0].p.stress_scale_MPa = c->free_el ? 1 : c->o->elastic[2];
        best[0].p.nbranch = nb;
        double span = c->d->t_s[c->n - 1] - c->d->t_s[0];
        for (int i = 0; i < nb; i++) {
            best[0].p.g[i] = 0.5 / nb;
            best[0].p.tau_s[i] = span * pow(10, -(double)(nb - i));
        }
        best[0].p.eta_MPa_s = c->dash ? 1e-3 : 0;
    }
    double bestobj = HUGE_VAL;
    double *z = malloc(c->np * sizeof(double)), *zbest = malloc(c->np * sizeof(double));
    if (!z || !zbest) {
        free(z);
        free(zbest);
        return HUGE_VAL;
    }
    for (int s = 0; s < LM_STARTS; s++) {
        if (!(best[s].obj < HUGE_VAL))
            continue;
        cf_visco_params p0 = best[s].p;
        if (c->dash && !(p0.eta_MPa_s > 0))
            p0.eta_MPa_s = 1e-6 * p0.stress_scale_MPa;
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
            double A = profile_scale(c);
            p.stress_scale_MPa = A;
            p.eta_MPa_s *= A;
        }
        *pout = p;
    }
    free(z);
    free(zbest);
    return bestobj;
}

/* ---- predictions ----------------------------------------------------------------------------- */

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
    const double sgn = d->x[kp] < 0 ? -1.0 : 1.0; /* table's sign of the loading */
    enum { PER = 200 };
    double ts[2 * PER + 1];
    cf_msm_sample smp[2 * PER + 1];
    cf_error e = {0};
    /* one load-unload cycle to the largest strain at the series' loading rate */
    {
        double pt[3] = {0, tload, 2 * tload}, pv[3] = {0, fabs(d->x[kp]), 0};
        cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 3, pt, pv};
        for (int k = 0; k <= 2 * PER; k++)
            ts[k] = 2 * tload * k / (2.0 * PER);
        if (cf_visco_run(p, s, &path, ts, 2 * PER + 1, smp, &e) == CF_OK) {
            double area = 0, work = 0;
            for (int k = 1; k <= 2 * PER; k++) {
                double dA = 0.5 * (smp[k].stress_MPa + smp[k - 1].stress_MPa) *
                            (smp[k].strain - smp[k - 1].strain);
                area += dA;
                if (k <= PER)
                    work += dA;
            }
            out->hysteresis_done = 1;
            out->cycle_strain = d->x[kp];
            out->cycle_period_s = 2 * tload;
            out->loop_area_MPa = area;
            out->loading_work_MPa = work;
        } else {
            snprintf(out->note, sizeof out->note, "hysteresis: %.480s", e.msg);
        }
    }
    /* creep under the series' final stress, applied in the loading time and held */
    {
        double sc = fabs(d->y[n - 1]);
        double pt[3] = {0, tload, tload + thold}, pv[3] = {0, sc, sc};
        cf_msm_path path = {CF_DRIVE_FORCE, 3, pt, pv};
        for (int k = 0; k <= 2 * PER; k++)
            ts[k] = k <= PER ? tload * k / PER : tload + thold * (k - PER) / PER;
        cf_error ce = {0};
        if (sc > 0 && cf_visco_run(p, s, &path, ts, 2 * PER + 1, smp, &ce) == CF_OK) {
            out->creep_done = 1;
            out->creep_stress_MPa = sgn * sc;
            out->creep_ramp_s = tload;
            out->creep_hold_s = thold;
            out->creep_strain_ramp = sgn * smp[PER].strain;
            out->creep_strain_end = sgn * smp[2 * PER].strain;
        } else if (!out->note[0]) {
            snprintf(out->note, sizeof out->note, "creep: %.480s",
                     sc > 0 ? ce.msg : "the series ends at zero stress");
        }
    }
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

cf_status cf_visco_fit_run(const cf_visco_data *d, const cf_visco_fit_options *o,
                           cf_visco_fit *res, cf_error *err)
{
    const double t0 = now_s();
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
    memset(&c, 0, sizeof c);
    c.d = d;
    c.o = o;
    c.n = n;
    c.free_el = !o->hold_elastic;
    c.dash = o->dashpot != 0;
    c.series.count = n;
    c.series.t_s = d->t_s;
    c.series.strain = d->x;
    for (size_t k = 0; k < n; k++) {
        c.ymax = fmax(c.ymax, fabs(d->y[k]));
        c.xmax = fmax(c.xmax, fabs(d->x[k]));
    }
    c.e_lo = c.xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    c.rho_lo = o->rho_min > 0 && o->rho_min < RHO_HI ? o->rho_min : 1e-3;
    if (o->hold_elastic) {
        const double *el = o->elastic;
        if (!(el[0] > 0 && el[0] <= 1) || !(el[1] > c.xmax && el[1] < 1) || !(el[2] > 0) ||
            !isfinite(el[2])) {
            cf_visco_fit_free(res);
            return cf_error_set(err, CF_E_DATA,
                                "the held elastic fit (rho %g, s/H %g, F_C/H^2 %g MPa) cannot "
                                "carry this series: its solid strain must exceed the largest "
                                "strain %g",
                                el[0], el[1], el[2], c.xmax);
        }
    }
    if (!(c.e_lo < E_HI)) {
        cf_visco_fit_free(res);
        return cf_error_set(err, CF_E_DATA,
                            "largest strain %g: no conical spring reaches it", c.xmax);
    }
    c.sw = malloc(n * sizeof(double));
    c.m = malloc(n * sizeof(double));
    if (!c.sw || !c.m) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu points", n);
        goto out;
    }
    for (size_t k = 0; k < n; k++) {
        double sc = o->relative ? fmax(fabs(d->y[k]), REL_FLOOR * c.ymax) : 1.0;
        c.sw[k] = sqrt(d->w ? d->w[k] : 1.0) / sc;
        c.ynorm += (c.sw[k] * d->y[k]) * (c.sw[k] * d->y[k]);
    }
    if (!(c.ynorm > 0)) {
        st = cf_error_set(err, CF_E_DATA, "every stress of the series is zero");
        goto out;
    }
    /* Branch counts: the one asked for, or 1..4 by AIC. */
    int nlo = o->nbranch ? o->nbranch : 1, nhi = o->nbranch ? o->nbranch : CF_VISCO_AIC_MAX;
    double best_aic = HUGE_VAL;
    cf_visco_params bestp;
    memset(&bestp, 0, sizeof bestp);
    res->chosen_by_aic = o->nbranch == 0;
    for (int nb = nlo; nb <= nhi; nb++) {
        cf_visco_params p;
        if (!(fit_nb(&c, nb, &p) < HUGE_VAL))
            continue;
        cf_error e = {0};
        if (cf_visco_curve(&p, &o->setup, &c.series, c.m, NULL, &e) != CF_OK)
            continue;
        c.evals++;
        double rss = 0;
        for (size_t k = 0; k < n; k++)
            rss += (c.m[k] - d->y[k]) * (c.m[k] - d->y[k]);
        int kpar = (c.free_el ? 3 : 0) + 2 * nb + c.dash;
        double aic = (double)n * log(fmax(rss, 1e-300) / (double)n) + 2.0 * kpar;
        if (nb - 1 < CF_VISCO_AIC_MAX)
            res->aic_by_n[nb - 1] = aic;
        if (aic < best_aic) {
            best_aic = aic;
            bestp = p;
        }
    }
    if (!(best_aic < HUGE_VAL)) {
        st = cf_error_set(err, CF_E_NOCONV,
                          "no viscoelastic model could be evaluated along this series");
        goto out;
    }
    /* The reported model, its curve and its quality. */
    {
        cf_error e = {0};
        c.nb = bestp.nbranch;
        if ((st = cf_visco_curve(&bestp, &o->setup, &c.series, res->model_MPa, NULL, &e)) !=
            CF_OK) {
            st = cf_error_set(err, st, "%s", e.msg);
            goto out;
        }
        c.evals++;
        res->p = bestp;
        res->dashpot = c.dash;
        res->held_elastic = !c.free_el;
        res->count = n;
        res->k = (c.free_el ? 3 : 0) + 2 * bestp.nbranch + c.dash;
        double ssr = 0, ssh = 0, mean = 0, sst = 0, wrss = 0;
        for (size_t k = 0; k < n; k++)
            mean += d->y[k] / (double)n;
        for (size_t k = 0; k < n; k++) {
            double r = res->model_MPa[k] - d->y[k];
            res->rss += r * r;
            wrss += (c.sw[k] * r) * (c.sw[k] * r);
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
        double s2 = (double)n > res->k ? wrss / ((double)n - res->k) : 0;
        standard_errors(&c, &bestp, s2, res);
        /* small-strain moduli of the lattice */
        double Eel[1], small = -1e-3 * bestp.solid_strain;
        if (cf_visco_elastic_curve(&bestp, &o->setup, &small, 1, Eel, &e) == CF_OK) {
            double ginf = 1;
            for (int i = 0; i < bestp.nbranch; i++)
                ginf -= bestp.g[i];
            res->E_inst_MPa = Eel[0] / small;
            res->E_eq_MPa = ginf * res->E_inst_MPa;
        }
        cf_visco_predictions(&bestp, &o->setup, d, &res->pred);
    }
out:
    res->evaluations = c.evals;
    res->wall_time_s = now_s() - t0;
    free(c.sw);
    free(c.m);
    if (st != CF_OK)
        cf_visco_fit_free(res);
    return st;
}
