/*
** The Holzapfel-Ogden law and its joint fit (holzapfel.h).
*/
#include "fit/holzapfel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>

#include "fit/lm.h"

/* The invariants I1, I4f, I4s, I8fs of C = F^T F, and f = F f0, s = F s0. */
typedef struct ho_state {
    double I1, I4f, I4s, I8;
    double f[3], s[3];
} ho_state;

static ho_state state_of(const double F[9])
{
    ho_state h;
    h.I1 = 0;
    for (int k = 0; k < 9; k++)
        h.I1 += F[k] * F[k];
    for (int i = 0; i < 3; i++) {
        h.f[i] = F[3 * i];
        h.s[i] = F[3 * i + 1];
    }
    h.I4f = h.f[0] * h.f[0] + h.f[1] * h.f[1] + h.f[2] * h.f[2];
    h.I4s = h.s[0] * h.s[0] + h.s[1] * h.s[1] + h.s[2] * h.s[2];
    h.I8 = h.f[0] * h.s[0] + h.f[1] * h.s[1] + h.f[2] * h.s[2];
    return h;
}

/* a/(2b) (exp(b x) - 1), its limit a x / 2 at b = 0. */
static double exp_term(double a, double b, double x)
{
    return b != 0 ? a / (2 * b) * expm1(b * x) : a * x / 2;
}

double cf_ho_energy(const double p[CF_HO_NP], const double F[9])
{
    const ho_state h = state_of(F);
    double W = exp_term(p[0], p[1], h.I1 - 3);
    if (h.I4f > 1)
        W += exp_term(p[2], p[3], (h.I4f - 1) * (h.I4f - 1));
    if (h.I4s > 1)
        W += exp_term(p[4], p[5], (h.I4s - 1) * (h.I4s - 1));
    return W + exp_term(p[6], p[7], h.I8 * h.I8);
}

void cf_ho_sigma_bar(const double p[CF_HO_NP], const double F[9], double s[9])
{
    const ho_state h = state_of(F);
    const double W1 = 0.5 * p[0] * exp(p[1] * (h.I1 - 3));
    const double ef = h.I4f - 1, es = h.I4s - 1;
    const double W4f = ef > 0 ? p[2] * ef * exp(p[3] * ef * ef) : 0;
    const double W4s = es > 0 ? p[4] * es * exp(p[5] * es * es) : 0;
    const double W8 = p[6] * h.I8 * exp(p[7] * h.I8 * h.I8);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double B = 0;
            for (int k = 0; k < 3; k++)
                B += F[3 * i + k] * F[3 * j + k];
            s[3 * i + j] = 2 * W1 * B + 2 * W4f * h.f[i] * h.f[j] + 2 * W4s * h.s[i] * h.s[j] +
                           W8 * (h.f[i] * h.s[j] + h.s[i] * h.f[j]);
        }
}

static int axis_of(char c)
{
    return c == 'f' ? 0 : c == 's' ? 1 : c == 'n' ? 2 : -1;
}

int cf_ho_axes(const cf_table *t, char cross, int axes[2])
{
    if (t->mode != CF_MODE_SHEAR && t->mode != CF_MODE_BIAXIAL)
        return -1;
    if (t->plane[0]) {
        axes[0] = axis_of(t->plane[0]);
        axes[1] = axis_of(t->plane[1]);
    } else if (t->mode == CF_MODE_BIAXIAL) {
        axes[0] = 0;
        axes[1] = axis_of(cross);
    } else
        return -1;
    return axes[0] >= 0 && axes[1] >= 0 && axes[0] != axes[1] ? 0 : -1;
}

double cf_ho_row_stress(const double p[CF_HO_NP], const cf_table *t, size_t i,
                        const int axes[2])
{
    double F[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, s[9];
    const double e = t->x[i];
    if (t->mode == CF_MODE_SHEAR) {
        F[3 * axes[1] + axes[0]] = e; /* F = I + gamma e_j e_i */
        cf_ho_sigma_bar(p, F, s);
        return s[3 * axes[0] + axes[1]];
    }
    const int d = i < t->second ? 0 : 1, pa = axes[d], qa = axes[1 - d], ra = 3 - pa - qa;
    const double lp = 1 + e, lq = 1 + cf_table_biaxial_k(t, i) * e;
    F[4 * pa] = lp;
    F[4 * qa] = lq;
    F[4 * ra] = 1 / (lp * lq);
    cf_ho_sigma_bar(p, F, s);
    return (s[4 * pa] - s[4 * ra]) / lp;
}

int cf_ho_unfit(const cf_table *const *t, size_t n, char *buf, size_t cap)
{
    buf[0] = '\0';
    for (size_t k = 0; k < n; k++) {
        int ax[2];
        if (cf_ho_axes(t[k], 's', ax) == 0)
            continue;
        if (t[k]->mode == CF_MODE_SHEAR)
            snprintf(buf, cap, "%.400s: a shear table states no plane in the fibre frame (a "
                     "'# plane: ij' comment, or the plane option: --plane)", t[k]->path);
        else
            snprintf(buf, cap, "%.400s: a %s table has no form of the law here (biaxial and "
                     "simple-shear tables only)", t[k]->path, cf_mode_name(t[k]->mode));
        return 1;
    }
    return 0;
}

/* ---- the joint fit -------------------------------------------------------------------------- */

/* The fit's tables, their weights and axes, and the form. */
typedef struct ho_ctx {
    const cf_table *const *t;
    size_t n, rows;
    int axes[CF_HO_MAX_TABLES][2];
    double scale[CF_HO_MAX_TABLES]; /* 1 / (RMS stress sqrt(rows)) */
    cf_ho_form form;
    int np;
} ho_ctx;

/* Parameters from the fitted logs (clamped so that no exponential overflows). */
static void params_of(const ho_ctx *c, const double *th, double p[CF_HO_NP])
{
    static const int ti[4] = {0, 1, 2, 3};
    for (int k = 0; k < CF_HO_NP; k++)
        p[k] = k % 2 ? 1.0 : 0.0; /* the terms not fitted: a = 0 */
    for (int k = 0; k < c->np; k++) {
        const int at = c->form == CF_HO_TI ? ti[k] : k;
        p[at] = exp(fmin(fmax(th[k], -40.0), 6.5));
    }
}

static int residuals(const gsl_vector *x, void *arg, gsl_vector *f)
{
    const ho_ctx *c = arg;
    double p[CF_HO_NP];
    params_of(c, x->data, p);
    size_t m = 0;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        for (size_t i = 0; i < t->count; i++) {
            const double w = sqrt(t->w ? t->w[i] : 1.0) * c->scale[k];
            const double r = w * (cf_ho_row_stress(p, t, i, c->axes[k]) - t->y[i]);
            gsl_vector_set(f, m++, isfinite(r) ? r : 1e10);
        }
    }
    return GSL_SUCCESS;
}

/* LM from th (np logs) to its end; the sum of squares there, th moved to it. */
static double run_lm(ho_ctx *c, double *th)
{
    const cf_lm_stop stop = {.max_iter = 400, .xtol = 1e-15, .gtol = 1e-15, .ftol = 0,
                             .stall = 25, .stall_rel = 1e-14, .floor = 1e-28};
    return cf_lm_minimise(residuals, c, c->rows, (size_t)c->np, th, &stop);
}

/* The tables' axes and weights into c; CF_E_DATA naming a table without axes. */
static cf_status setup(ho_ctx *c, const cf_table *const *t, size_t n, cf_ho_form form,
                       char cross, double *amp, cf_error *err)
{
    if (n < 1 || n > CF_HO_MAX_TABLES)
        return cf_error_set(err, CF_E_DATA, "a Holzapfel-Ogden fit takes 1 to %d tables, not %zu",
                            CF_HO_MAX_TABLES, n);
    memset(c, 0, sizeof *c);
    c->t = t;
    c->n = n;
    c->form = form;
    c->np = form == CF_HO_TI ? 4 : CF_HO_NP;
    *amp = 0;
    for (size_t k = 0; k < n; k++) {
        char why[CF_ERROR_MSG_LEN];
        if (cf_ho_axes(t[k], cross, c->axes[k]) != 0) {
            cf_ho_unfit(t + k, 1, why, sizeof why);
            return cf_error_set(err, CF_E_DATA, "%s", why);
        }
        double ss = 0;
        for (size_t i = 0; i < t[k]->count; i++)
            ss += t[k]->y[i] * t[k]->y[i];
        const double rms = sqrt(ss / (double)t[k]->count);
        if (!(rms > 0))
            return cf_error_set(err, CF_E_DATA, "%s: every stress is zero: no scale to weigh "
                                "its residuals by", t[k]->path);
        c->scale[k] = 1 / (rms * sqrt((double)t[k]->count));
        c->rows += t[k]->count;
        *amp = fmax(*amp, rms);
    }
    return CF_OK;
}

cf_status cf_ho_fit_joint(const cf_table *const *t, size_t n, cf_ho_form form, char cross,
                          const cf_ho_fit *from, cf_ho_fit *r, cf_error *err)
{
    ho_ctx c;
    double amp = 0, best = INFINITY, th_best[CF_HO_NP] = {0};
    cf_status st = setup(&c, t, n, form, cross, &amp, err);
    if (st != CF_OK)
        return st;
    memset(r, 0, sizeof *r);
    /* starts: every a at 0.05 or 0.5 of the largest RMS stress, every b at 2 or 10 (the TI
    ** form's four on a full grid; the full form's a_s, a_fs besides at 0.1 or 1 of the others) */
    const int nstarts = form == CF_HO_TI ? 16 : 8;
    for (int s = 0; s <= nstarts; s++) {
        double th[CF_HO_NP];
        if (s == nstarts) { /* the given fit's parameters, the terms it lacks small */
            if (!from)
                break;
            for (int k = 0; k < c.np; k++) {
                const double v = from->p[k];
                th[k] = log(v > 0 ? v : k % 2 ? 1.0 : 1e-3 * amp);
            }
        } else
            for (int k = 0; k < c.np; k++) {
                const int bit = form == CF_HO_TI ? (s >> k) & 1 : k % 2 ? (s >> 1) & 1 : s & 1;
                const double side = form == CF_HO_FULL && k >= 4 && !(k % 2) && (s >> 2)
                                        ? 0.1
                                        : 1.0;
                th[k] = log(k % 2 ? (bit ? 10.0 : 2.0) : (bit ? 0.5 : 0.05) * amp * side);
            }
        const double ss = run_lm(&c, th);
        r->starts++;
        if (ss < best) {
            best = ss;
            memcpy(th_best, th, sizeof th_best);
        }
    }
    if (!isfinite(best))
        return cf_error_set(err, CF_E_NOCONV, "the Holzapfel-Ogden fit found no parameters with "
                            "a finite objective on the %zu tables", n);
    r->form = form;
    r->cross = cross;
    r->nparams = c.np;
    r->ntables = n;
    r->objective = best;
    params_of(&c, th_best, r->p);
    for (size_t k = 0; k < n; k++) {
        double ss = 0;
        for (size_t i = 0; i < t[k]->count; i++) {
            const double d = cf_ho_row_stress(r->p, t[k], i, c.axes[k]) - t[k]->y[i];
            ss += d * d;
        }
        r->rmse_MPa[k] = sqrt(ss / (double)t[k]->count);
    }
    return CF_OK;
}
