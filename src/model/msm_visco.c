/*
** Implicit quasi-static steps of the lattice with dashpots, Maxwell branches and Prony terms (see
** msm.h), and the checks of the Prony terms.
*/
#include "model/msm_internal.h"

#include <math.h>

cf_status cf_msm_prony_check(const cf_msm_effects *fx, cf_error *err)
{
    if (fx->prony_count < 0 || fx->prony_count > CF_PRONY_MAX)
        return cf_error_set(err, CF_E_DATA, "%d Prony terms: at most %d", fx->prony_count,
                            CF_PRONY_MAX);
    double sum = 0;
    for (int i = 0; i < fx->prony_count; i++) {
        double g = fx->prony_g[i], tau = fx->prony_tau_s[i];
        if (!(g >= 0) || !isfinite(g))
            return cf_error_set(err, CF_E_DATA, "Prony term %d: g = %g must be finite and >= 0",
                                i + 1, g);
        if (!(tau > 0) || !isfinite(tau))
            return cf_error_set(err, CF_E_DATA,
                                "Prony term %d: tau_s = %g must be finite and > 0", i + 1, tau);
        sum += g;
    }
    if (!(sum < 1))
        return cf_error_set(err, CF_E_DATA,
                            "Prony terms: the relative moduli sum to %.17g; the sum must be below "
                            "1 (g_inf = 1 - sum g > 0)",
                            sum);
    for (int i = 0; i < fx->prony_count; i++)
        if (!isfinite(fx->prony_k[i]))
            return cf_error_set(err, CF_E_DATA, "Prony term %d: g_per_strain = %g must be finite",
                                i + 1, fx->prony_k[i]);
    return CF_OK;
}

/* Prony term i's relative modulus at a spring's |strain| e: g_i + k_i e. */
static inline double prony_g_at(const cf_msm_effects *fx, int i, double abs_e)
{
    return fx->prony_k[i] != 0 ? fx->prony_g[i] + fx->prony_k[i] * abs_e : fx->prony_g[i];
}

/* ---- quasi-static viscous steps ------------------------------------------------------------- */

int cf_msm_prony_depends_on_strain(const cf_msm_effects *fx)
{
    for (int i = 0; i < fx->prony_count; i++)
        if (fx->prony_k[i] != 0)
            return 1;
    return 0;
}

cf_status cf_msm_prony_at_strain(const cf_msm_effects *fx, double e, cf_error *err)
{
    double sum = 0;
    for (int i = 0; i < fx->prony_count; i++) {
        const double g = prony_g_at(fx, i, e);
        if (!(g >= 0))
            return cf_error_set(err, CF_E_DATA,
                                "Prony term %d: at strain %.6g of a spring its relative modulus "
                                "g + g_per_strain |strain| is %.6g; it must stay >= 0",
                                i + 1, e, g);
        sum += g;
    }
    if (!(sum < 1))
        return cf_error_set(err, CF_E_DATA,
                            "Prony terms: at strain %.6g of a spring the relative moduli sum to "
                            "%.6g (g + g_per_strain |strain|); the sum must stay below 1",
                            e, sum);
    return CF_OK;
}

/* With relaxation that depends on strain, every spring's moduli at the converged state: past their
** bounds the relaxed spring would push back the wrong way. */
cf_status cf_msm_relaxed_share_check(const solver *s, cf_error *err)
{
    const cf_msm_effects *fx = s->fx;
    const int any = fx && cf_msm_prony_depends_on_strain(fx);
    cf_status st = CF_OK;
    for (size_t q = 0; any && st == CF_OK && q < s->lat->ns; q++)
        st = cf_msm_prony_at_strain(fx, fabs(s->lat->u_mm[q]) / s->lat->H_mm, err);
    return st;
}

/* One implicit step of length h to drive value v: dashpots by backward Euler, Maxwell branches by
** their exact exponential update at a constant strain rate over the step. */
static cf_status quasi_step(solver *s, double h, double v, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    double H2 = lat->H_mm * lat->H_mm;
    double E1 = 1, mcoef = 0;
    if (fx->maxwell_E_MPa > 0) {
        E1 = exp(-h / fx->maxwell_tau_s);
        mcoef = fx->maxwell_E_MPa * fx->maxwell_tau_s * (-expm1(-h / fx->maxwell_tau_s)) / h;
    }
    double visc = fx->eta_MPa_s / h + mcoef; /* MPa per unit strain */
    /* Prony terms: with F linear in time over the step, h_i(t + h) = e_i h_i(t) +
    ** g_i b_i (F(t + h) - F(t)), e_i = exp(-h/tau_i), b_i = tau_i (1 - e_i)/h; so the spring
    ** force w ((1 - sum g) F + sum h_i) at the end of the step is w (alpha F(t + h) + c) with
    ** alpha = 1 - sum g_i (1 - b_i) and c = sum (e_i h_i - g_i b_i F(t)). */
    const int np = fx->prony_count;
    double pe[CF_PRONY_MAX], pb[CF_PRONY_MAX], alpha = 1, slope = 0;
    for (int i = 0; i < np; i++) {
        pe[i] = exp(-h / fx->prony_tau_s[i]);
        pb[i] = -expm1(-h / fx->prony_tau_s[i]) * fx->prony_tau_s[i] / h;
        alpha -= fx->prony_g[i] * (1 - pb[i]);
        slope -= fx->prony_k[i] * (1 - pb[i]);
    }
    cf_lattice_forces(lat); /* lengths at the start of the step */
    for (size_t q = 0; q < lat->ns; q++) {
        s->Lprev[q] = lat->L_mm[q];
        s->Tx0[q] = s->sigm ? lat->w[q] * H2 * s->sigm[q] * E1 : 0.0;
        s->kx[q] = lat->w[q] * H2 * visc / lat->L0_mm[q];
        if (np > 0) {
            double c = 0;
            const double e = fabs(lat->u_mm[q]) / lat->H_mm;
            s->Fprev[q] = lat->F_N[q];
            for (int i = 0; i < np; i++)
                c += pe[i] * s->hq[q * np + i] - prony_g_at(fx, i, e) * pb[i] * lat->F_N[q];
            s->Tx0[q] -= lat->w[q] * c;
        }
    }
    s->qlv_scale = alpha - 1;
    s->qlv_slope = slope;
    s->extras = 1;
    double v0 = s->load;
    s->load = v;
    if (s->drive == CF_DRIVE_DISPLACEMENT)
        cf_msm_place_top(lat, v);
    cf_status st = cf_msm_newton(s, err);
    if (st != CF_OK) {
        s->load = v0;
        if (s->drive == CF_DRIVE_DISPLACEMENT)
            cf_msm_place_top(lat, v0);
        return st;
    }
    if ((st = cf_msm_relaxed_share_check(s, err)) != CF_OK)
        return st;
    if (s->sigm)
        for (size_t q = 0; q < lat->ns; q++)
            s->sigm[q] = s->sigm[q] * E1 + mcoef * (lat->L_mm[q] - s->Lprev[q]) / lat->L0_mm[q];
    for (size_t q = 0; np > 0 && q < lat->ns; q++) { /* F_N: the converged state */
        /* |strain| at the start of the step, from its length there */
        const double e0 = fabs((lat->L0_mm[q] - s->Lprev[q]) * lat->a[q]) / lat->H_mm;
        const double e1 = fabs(lat->u_mm[q]) / lat->H_mm;
        for (int i = 0; i < np; i++)
            s->hq[q * np + i] =
                pe[i] * s->hq[q * np + i] +
                (fx->prony_k[i] == 0
                     ? fx->prony_g[i] * pb[i] * (lat->F_N[q] - s->Fprev[q])
                     : pb[i] * (prony_g_at(fx, i, e1) * lat->F_N[q] -
                                prony_g_at(fx, i, e0) * s->Fprev[q]));
    }
    if (s->st)
        s->st->steps++;
    return CF_OK;
}

/* Advances from t0 to t1 (the path's drive) in n implicit steps, halving on failure. */
cf_status cf_msm_quasi_advance(solver *s, const cf_msm_path *p, double t0, double t1,
                               int n, int depth, cf_error *err)
{
    double h = (t1 - t0) / n;
    for (int k = 1; k <= n; k++) {
        double ta = t0 + (k - 1) * h, tb = t0 + k * h;
        cf_status st = quasi_step(s, h, cf_msm_path_value(p, tb), err);
        if (st == CF_E_NOCONV && depth < MAX_BISECT)
            st = cf_msm_quasi_advance(s, p, ta, tb, 2, depth + 1, err);
        if (st != CF_OK)
            return st;
        if (s->st && (s->st->dt_used_min_s == 0 || h < s->st->dt_used_min_s))
            s->st->dt_used_min_s = h;
    }
    return CF_OK;
}
