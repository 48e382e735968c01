/*
** The standard errors of the viscoelastic fit: s^2 (J^T J)^-1 from central differences of the
** model at the fitted parameters, quantities held on a limit left out.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>

#include "fit/viscofit_ctx.h"

/* The covariance's quantities are numbered: the identifiable ones (family.h) from 0, then from Q0
** (g_i, tau_i) per branch, the dashpot, and from QK + 2 nb the k_i. */
#define Q0 CF_IDENT_COUNT
#define QK (Q0 + 1)

/* Quantities of the covariance, in the order rho, s/H, F_C/H^2, (g_i, tau_i) per branch, eta:
** the slot of quantity `which` in q, or NULL when it is not fitted or held at a limit. */
static double *se_slot(const ctx *c, const int held[CF_IDENT_COUNT], int which, cf_visco_params *q)
{
    const int nb = q->nbranch;
    if (which < Q0) {
        if (!c->free_el || held[which])
            return NULL;
        return &q->ident.v[which];
    }
    if (which < Q0 + 2 * nb) {
        int i = (which - Q0) / 2;
        return (which - Q0) % 2 == 0 ? &q->g[i] : &q->tau_s[i];
    }
    if (which == Q0 + 2 * nb)
        return c->dash ? &q->eta_MPa_s : NULL;
    return cf_viscofit_strain_term(c, which - QK - 2 * nb) ? &q->k[which - QK - 2 * nb] : NULL;
}

/* One column of the Jacobian: the weighted central difference of the model in quantity `which`,
** its steps kept inside the quantity's domain. 0 when the model cannot be evaluated. */
static int se_column(ctx *c, const cf_visco_params *p, const int held[CF_IDENT_COUNT], int which,
                     gsl_matrix *J, size_t col, double *mp, double *mm)
{
    cf_visco_params q = *p;
    double *slot = se_slot(c, held, which, &q);
    const double v = *slot;
    const int is_g = which >= Q0 && which < Q0 + 2 * p->nbranch && (which - Q0) % 2 == 0;
    double h = SE_STEP * fmax(fabs(v), is_g ? 1e-2 : 1e-300);
    double hp = h, hm = h;
    if (which == CF_IDENT_RHO) { /* keep rho inside (0, 1] */
        hp = fmin(h, 1 - v);
        hm = fmin(h, 0.5 * v);
    } else if (which == CF_IDENT_SOLID) { /* s/H inside (largest strain, 1) */
        hm = fmin(h, 0.5 * (v - c->xmax));
        hp = fmin(h, 0.5 * (1 - v));
    } else if (which >= Q0 && (is_g || which > Q0 + 2 * p->nbranch)) {
        /* a relative modulus or its slope: every g_i(x) >= 0 and their sum below 1 at x = 0 and
        ** at the largest strain x_max (one-sided next to a limit, as the fit may sit on it) */
        const int i = is_g ? (which - Q0) / 2 : which - QK - 2 * p->nbranch;
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
    if (which < Q0)
        res->ident_se.v[which] = se;
    else if (which < Q0 + 2 * nb)
        *((which - Q0) % 2 == 0 ? &res->se_g[(which - Q0) / 2] : &res->se_tau_s[(which - Q0) / 2]) =
            se;
    else if (which == Q0 + 2 * nb)
        res->se_eta_MPa_s = se;
    else
        res->se_k[which - QK - 2 * nb] = se;
}

/* Central-difference Jacobian of the weighted model in the reported quantities at p, and the
** covariance s^2 (J^T W J)^-1. A quantity on a limit (held[]: rho on rho_min, s/H on the
** stability bound, the scale on the design cap) is set by the limit, not by the data: it is held
** here (its error undetermined), or the others' errors would carry its freedom along the limit. */
void cf_viscofit_standard_errors(ctx *c, const cf_visco_params *p,
                                 const int held[CF_IDENT_COUNT], double s2, cf_visco_fit *res)
{
    for (int i = 0; i < CF_IDENT_COUNT; i++)
        res->ident_se.v[i] = -1;
    for (int i = 0; i < CF_PRONY_MAX; i++)
        res->se_g[i] = res->se_tau_s[i] = res->se_k[i] = res->se_g_max[i] = -1;
    res->se_eta_MPa_s = -1;
    const int nq = Q0 + 2 * p->nbranch + 1 + (c->gs ? p->nbranch : 0);
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
        int colof[Q0 + 3 * CF_PRONY_MAX + 1];
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
            const int cg = colof[Q0 + 2 * i], ck = c->gs ? colof[QK + 2 * p->nbranch + i] : -1;
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
