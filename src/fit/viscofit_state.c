/*
** The viscoelastic fit's working state (see viscofit_ctx.h): the map between the model's
** parameters and the optimiser's free coordinates, the model curve with the stress scale in
** closed form, and the Levenberg-Marquardt over the coordinates.
*/
#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "fit/lm.h"
#include "fit/viscofit_ctx.h"

static double expit(double z)
{
    return z >= 0 ? 1 / (1 + exp(-z)) : exp(z) / (1 + exp(z));
}

/* The smallest s/H allowed at rho: above the travel margin and the lattice's stability bound. */
double cf_viscofit_solid_lo(const ctx *c, double rho)
{
    return cf_visco_limits_solid_min(&c->lim, rho);
}

/* 1 when term i's relative modulus is fitted as changing with strain. */
int cf_viscofit_strain_term(const ctx *c, int i)
{
    return c->gs && (c->smask >> i & 1u);
}

/* The k_i fitted. */
int cf_viscofit_strain_terms(const ctx *c)
{
    int m = 0;
    for (int i = 0; i < c->nb; i++)
        m += cf_viscofit_strain_term(c, i);
    return m;
}

/* LM coordinates -> model parameters; the stress scale is 1 (profiled) or the held one, the
** dashpot relative to it. */
cf_visco_params cf_viscofit_unpack(const ctx *c, const double *z)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    size_t j = 0;
    if (c->free_el) {
        p.ident.rho = c->rho_lo + (RHO_HI - c->rho_lo) * expit(z[j++]);
        const double lo = cf_viscofit_solid_lo(c, p.ident.rho);
        p.ident.solid = lo + (E_HI - lo) * expit(z[j++]);
        p.ident.scale = 1.0;
    } else {
        p.ident = c->o->elastic;
        p.e_tail = c->o->elastic_e_tail;
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
        eb[i] = cf_viscofit_strain_term(c, i) ? exp(fmax(z[j++], A_LO)) : 0.0;
        sum += ea[i];
        sumb += eb[i];
    }
    double left = 1; /* what the constant terms leave at the largest strain */
    for (int i = 0; i < c->nb; i++) {
        p.g[i] = ea[i] / sum;
        if (!cf_viscofit_strain_term(c, i))
            left -= p.g[i];
    }
    for (int i = 0; i < c->nb; i++)
        p.k[i] = cf_viscofit_strain_term(c, i) ? (left * eb[i] / sumb - p.g[i]) / c->xmax : 0.0;
    p.eta_MPa_s = c->dash ? exp(z[j++]) * p.ident.scale : 0.0;
    return p;
}

void cf_viscofit_pack(const ctx *c, const cf_visco_params *p, double *z)
{
    size_t j = 0;
    if (c->free_el) {
        const double lo = cf_viscofit_solid_lo(c, p->ident.rho);
        z[j++] = cf_logit((p->ident.rho - c->rho_lo) / (RHO_HI - c->rho_lo));
        z[j++] = cf_logit((p->ident.solid - lo) / (E_HI - lo));
    }
    double ginf = 1, left = 1, gb[CF_PRONY_MAX];
    for (int i = 0; i < c->nb; i++) {
        ginf -= p->g[i];
        gb[i] = cf_viscofit_strain_term(c, i) ? p->g[i] + p->k[i] * c->xmax : 0.0;
        if (!cf_viscofit_strain_term(c, i))
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
        if (cf_viscofit_strain_term(c, i))
            z[j++] = gb[i] > 0 ? fmax(log(gb[i] / left / ginfb), A_LO) : A_LO;
    }
    if (c->dash)
        z[j++] = log(fmax(p->eta_MPa_s / p->ident.scale, 1e-300));
}

/* The model at p into c->m; returns 0 on failure. */
int cf_viscofit_curve(ctx *c, const cf_visco_params *p)
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
double cf_viscofit_profile_scale(const ctx *c, double rho, double B)
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
    cf_visco_params p = cf_viscofit_unpack(c, zv->data);
    double A = 0;
    int ok = cf_viscofit_curve(c, &p) &&
             (A = cf_viscofit_profile_scale(c, p.ident.rho, p.ident.solid)) > 0;
    const double s = 1 / sqrt(c->ynorm);
    for (size_t k = 0; k < c->n; k++) {
        double r = ok ? c->sw[k] * (A * c->m[k] - c->d->y[k])
                      : c->sw[k] * 10 * (fabs(c->d->y[k]) + c->ymax);
        gsl_vector_set(f, k, isfinite(r) ? r * s : 1e10);
    }
    cf_viscofit_jac_record(c->jac, zv->data, f->data);
    return GSL_SUCCESS;
}

/* Levenberg-Marquardt from z (in place); returns the scaled sum of squares. Its Jacobian by
** forward differences at every step (options.full_jacobian), or by default every few steps and
** carried by Broyden's update in between (viscofit_jac.c). beat (HUGE_VAL: none) is the sum of
** squares an earlier start reached: a run settling well above it stops early (LM_BEAT_*), and
** what it returns is then above beat. */
double cf_viscofit_lm_run(ctx *c, double *z, double beat)
{
    gsl_multifit_nlinear_parameters fp = cf_lm_parameters();
    fp.h_df = 1e-7;
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = lm_f;
    fdf.df = NULL; /* forward differences at every step */
    fdf.n = c->n;
    fdf.p = c->np;
    fdf.params = c;
    c->jac = NULL;
    if (!c->o->full_jacobian) { /* differences now and then, Broyden's update in between */
        if (!(c->jac = cf_viscofit_jac_alloc(c->n, c->np, &fdf, fp.h_df))) {
            c->oom = 1;
            return HUGE_VAL;
        }
        fdf.df = cf_viscofit_jac_df;
    }
    int init;
    gsl_multifit_nlinear_workspace *w = cf_lm_start(&fp, &fdf, z, &init);
    if (!w) {
        cf_viscofit_jac_free(c->jac);
        c->jac = NULL;
        c->oom = 1;
        return HUGE_VAL;
    }
    double best = HUGE_VAL;
    if (init == GSL_SUCCESS) {
        const cf_lm_stop stop = {LM_MAX_ITER,
                                 1e-14,
                                 1e-14,
                                 0,
                                 LM_STALL,
                                 LM_STALL_REL,
                                 LM_FLOOR_REL,
                                 beat < HUGE_VAL ? LM_BEAT_FACTOR * beat : 0,
                                 LM_BEAT_ITER,
                                 LM_BEAT_REL};
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
    cf_viscofit_jac_free(c->jac);
    c->jac = NULL;
    return best;
}
