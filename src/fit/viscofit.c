/*
** Fitting the time-dependent model to a measured time series (see viscofit.h): the options, the
** check of the series, the fit of one branch count from the stand-in's starts, and the driver
** (the choice of the branch count, the limits, the quality and the report). The working state
** and the Levenberg-Marquardt are in viscofit_state.c, the stand-in search that starts it in
** viscofit_standin.c, the standard errors in viscofit_se.c, the predictions in
** viscofit_predict.c.
*/
#include "fit/viscofit.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/msm.h"
#include "fit/clock.h"
#include "fit/viscofit_ctx.h"

cf_visco_fit_options cf_visco_fit_default_options(void)
{
    cf_visco_fit_options o;
    memset(&o, 0, sizeof o);
    o.setup = cf_visco_default();
    /* the axial calibration: its diagonals carry as much as its edges, which keeps the lattice
    ** stable further in compression than the isotropic one (src/notes/time-series.md) */
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

/* ---- one branch count ------------------------------------------------------------------------ */

/* 1 when the fit has used its model runs: what is left is not started (and the fit says so). */
static int out_of_evaluations(ctx *c)
{
    if (c->evals >= c->max_evals)
        c->bound_hit = 1;
    return c->bound_hit;
}

/* The start when the stand-in found none: equal branches spread over the series. */
static void default_start(const ctx *c, int nb, start *s)
{
    s->obj = 1;
    memset(&s->p, 0, sizeof s->p);
    s->p.ident.rho = c->free_el ? 0.3 : c->o->elastic.rho;
    s->p.ident.solid =
        c->free_el ? 0.5 * (cf_viscofit_solid_lo(c, 0.3) + E_HI) : c->o->elastic.solid;
    s->p.ident.scale = c->free_el ? 1 : c->o->elastic.scale;
    s->p.e_tail = c->free_el ? 0 : c->o->elastic_e_tail;
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
    c->np = (size_t)((c->free_el ? 2 : 0) + 2 * nb + cf_viscofit_strain_terms(c) +
                     (c->dash ? 1 : 0));
    /* relaxation depending on strain trades more freely against the elastic curve: more starts */
    const int nstarts = c->gs ? LM_STARTS_STRAIN : LM_STARTS;
    start best[LM_STARTS_STRAIN + 1];
    if (!cf_viscofit_stand_in(c, best + 1, nstarts))
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
        if (bestobj < HUGE_VAL && out_of_evaluations(c))
            break; /* one start fitted at least, so the candidate has a model */
        cf_visco_params p0 = best[s].p;
        if (c->dash && !(p0.eta_MPa_s > 0))
            p0.eta_MPa_s = 1e-6 * p0.ident.scale;
        cf_viscofit_pack(c, &p0, z);
        double obj = cf_viscofit_lm_run(c, z, bestobj);
        if (obj < bestobj) {
            bestobj = obj;
            memcpy(zbest, z, c->np * sizeof(double));
        }
    }
    if (bestobj < HUGE_VAL) {
        cf_visco_params p = cf_viscofit_unpack(c, zbest);
        if (c->free_el && cf_viscofit_curve(c, &p)) {
            double A = cf_viscofit_profile_scale(c, p.ident.rho, p.ident.solid);
            p.ident.scale = A;
            p.eta_MPa_s *= A;
        }
        *pout = p;
    }
    free(z);
    free(zbest);
    return bestobj;
}

/* ---- set-up and the limits of the elastic quantities ----------------------------------------- */

void cf_visco_fit_free(cf_visco_fit *r)
{
    if (!r)
        return;
    free(r->model_MPa);
    free(r->is_hold);
    r->model_MPa = NULL;
    r->is_hold = NULL;
}

/* Where the static elastic lattice of stable_cells^3 cells of the spring (rho, s/H, F_C/H^2, and
** the tail's compliance e_t, 0 without a tail) first loses stability (table's sign), by the scan
** of cf_msm_stability_limit on each side the series reaches: a side where it does so within the
** series first, else the side of the series' largest strain. 0 when it stays stable to 0.995 of
** solid or cannot be scanned. */
static double stability_limit(const ctx *c, double rho, double B, double A, double e_tail)
{
    cf_visco_params q;
    memset(&q, 0, sizeof q);
    q.ident = (cf_ident){.rho = rho, .solid = B, .scale = A};
    q.e_tail = e_tail;
    cf_spring sp = cf_visco_member(&q);
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
    c->max_evals = o->max_evaluations > 0 ? o->max_evaluations : CF_VISCO_EVAL_MAX;
    const double *el = o->elastic.v, et = o->elastic_e_tail;
    if (!o->hold_elastic && et != 0)
        return cf_error_set(err, CF_E_DATA,
                            "tail compliance %g: a tail is carried only by a held elastic part "
                            "(the fitted one is the conical law)",
                            et);
    if (o->hold_elastic && et != 0) {
        /* the tailed spring: the cone may close within the series (its third, linear region is
        ** the point of the tail); the model's member (cf_ident_member_tail) is solid only near
        ** its free length, which the series must stay short of */
        const double whole = 1 - CF_IDENT_TAIL_SOLIDS * (1 - el[1] - et);
        if (!(el[0] > 0 && el[0] <= 1) || !(el[1] > 0 && el[1] < 1) || !(el[2] > 0) ||
            !isfinite(el[2]) || !(et > 0) || !isfinite(et) || !(el[1] + et < 1) ||
            !(c->xmax < whole))
            return cf_error_set(err, CF_E_DATA,
                                "the held elastic fit (rho %g, s/H %g, F_C/H^2 %g MPa, tail "
                                "compliance %g) cannot carry this series: its cone must close "
                                "(at s/H + e_t) below the free length and the spring stay short "
                                "of solid at the largest strain %g",
                                el[0], el[1], el[2], et, c->xmax);
    } else if (o->hold_elastic &&
               (!(el[0] > 0 && el[0] <= 1) || !(el[1] > c->xmax && el[1] < 1) ||
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
        /* the limits' grid is the conical law's: a tailed spring is scanned itself */
        const double at_tail = et != 0 ? stability_limit(c, el[0], el[1], el[2], et) : 0;
        if (et != 0 ? at_tail != 0 && at_tail >= c->xlo && at_tail <= c->xhi
                    : !cf_visco_limits_stable(&held, el[0], el[1])) {
            double at = et != 0 ? at_tail : stability_limit(c, el[0], el[1], el[2], 0);
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
static void limits_held(const ctx *c, const cf_visco_params *p, int held[CF_IDENT_COUNT])
{
    held[CF_IDENT_RHO] = held[CF_IDENT_SOLID] = held[CF_IDENT_SCALE] = 0;
    if (!c->free_el)
        return;
    held[CF_IDENT_RHO] = p->ident.rho <= c->rho_lo * (1 + 1e-4);
    held[CF_IDENT_SOLID] = c->lim.cells > 0 && cf_viscofit_solid_lo(c, p->ident.rho) > c->e_lo &&
              p->ident.solid <= cf_viscofit_solid_lo(c, p->ident.rho) * (1 + 1e-6);
    held[CF_IDENT_SCALE] = p->ident.scale >=
              cf_visco_limits_scale_max(&c->lim, p->ident.rho, p->ident.solid) * (1 - 1e-9);
}

/* The limits of the fitted elastic quantities, and where the elastic lattice of the fitted (or
** held) spring loses stability. */
static void fit_limits(const ctx *c, const cf_visco_params *p, cf_visco_fit *res,
                       int held[CF_IDENT_COUNT])
{
    res->stable_to_strain = 0;
    if (c->o->stable_cells > 0)
        res->stable_to_strain =
            stability_limit(c, p->ident.rho, p->ident.solid, p->ident.scale, p->e_tail);
    limits_held(c, p, held);
    res->rho_at_limit = held[CF_IDENT_RHO];
    res->at_stability_limit = held[CF_IDENT_SOLID];
    res->at_design_limit = held[CF_IDENT_SCALE];
}

/* ---- the choice of the branch count ---------------------------------------------------------- */

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
** fails it, as does a strain term whose modulus at zero strain sits on its floor; AIC assumes a regular model and would reward such a fit's extra parameters. The
** errors are computed at s2 = 1 and scaled, so that a noiseless series (s2 -> 0) passes.
** *loose gets the terms whose k_i is fitted but not larger than its error. */
/* The fitted elastic quantities (rho, s/H, F_C/H^2) whose standard error (se at s2 = 1, times s)
** is larger than the range the quantity can take: rho and s/H lie in (0, 1], so an error above 1
** says nothing of them; the stress scale is positive, so an error above its own value. A bit per
** quantity (CF_IDENT_*); held quantities are not fitted and never fail. */
static unsigned elastic_unresolved(const ctx *c, const cf_visco_params *p, const int *held,
                                   const cf_visco_fit *se, double s)
{
    unsigned bad = 0;
    if (!c->free_el)
        return 0;
    for (int k = 0; k < CF_IDENT_COUNT; k++) {
        const double e = s * se->ident_se.v[k], range = k == CF_IDENT_SCALE ? p->ident.v[k] : 1.0;
        if (!held[k] && se->ident_se.v[k] > 0 && !(e <= range))
            bad |= 1u << k;
    }
    return bad;
}

static int prony_identified(ctx *c, const cf_visco_params *p, double s2, unsigned *loose,
                            unsigned *elastic)
{
    int held[CF_IDENT_COUNT];
    cf_visco_fit se;
    memset(&se, 0, sizeof se);
    limits_held(c, p, held);
    cf_viscofit_standard_errors(c, p, held, 1.0, &se);
    const double s = sqrt(s2);
    *loose = 0;
    *elastic = elastic_unresolved(c, p, held, &se, s);
    int ok = !*elastic && (!c->dash || resolved(p->eta_MPa_s, s * se.se_eta_MPa_s));
    for (int i = 0; i < p->nbranch; i++) {
        ok = ok && resolved(p->tau_s[i], s * se.se_tau_s[i]) &&
             resolved(p->g[i] + p->k[i] * c->xmax, s * se.se_g_max[i]);
        if (cf_viscofit_strain_term(c, i) && !resolved(fabs(p->k[i]), s * se.se_k[i])) {
            ok = 0;
            *loose |= 1u << i;
        }
        /* a modulus at zero strain held at its floor (its log-share at A_LO): the optimum is on
        ** a bound, where the linearised errors say nothing (they swing with the last digits of
        ** the search) and AIC's regular-model premise fails */
        if (cf_viscofit_strain_term(c, i) && p->g[i] <= 2 * exp(A_LO))
            ok = 0;
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
                     int *ident, unsigned *loose, unsigned *elastic)
{
    if (!(fit_nb(c, nb, from, p) < HUGE_VAL) || !cf_viscofit_curve(c, p))
        return c->oom ? -1 : 0;
    double rss = 0, wrss = 0;
    for (size_t k = 0; k < c->n; k++) {
        const double r = c->m[k] - c->d->y[k];
        rss += r * r;
        wrss += c->sw[k] * c->sw[k] * r * r;
    }
    const int kpar = (c->free_el ? 3 : 0) + 2 * nb + cf_viscofit_strain_terms(c) + c->dash;
    *aic = (double)c->n * log(fmax(rss, 1e-300) / (double)c->n) + 2.0 * kpar;
    const double s2 = (double)c->n > kpar ? wrss / ((double)c->n - kpar) : 0;
    *ident = prony_identified(c, p, s2, loose, elastic);
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
    unsigned best_mask = 0, best_el = 0;
    memset(best, 0, sizeof *best);
    res->chosen_by_aic = o->nbranch == 0 || o->relaxation == CF_RELAX_AUTO;
    const int gslo = o->relaxation == CF_RELAX_STRAIN, gshi = o->relaxation != CF_RELAX_QLV;
    for (int v = 0; v < (nhi - nlo + 1) * (gshi - gslo + 1); v++) {
        const int nb = nlo + v / (gshi - gslo + 1);
        if (best_aic < HUGE_VAL && out_of_evaluations(c))
            break; /* the candidates left are not fitted (res->evaluation_bound_reached) */
        c->gs = gslo + v % (gshi - gslo + 1);
        c->smask = (1u << nb) - 1;
        cf_visco_params p, q;
        double aic = HUGE_VAL, aq;
        int ident = 0, iq, fitted = 0, st;
        unsigned lq, mask = c->smask, eq = 0, el = 0;
        cf_visco_params from;
        const cf_visco_params *fp = NULL;
        while ((st = candidate(c, nb, fp, &q, &aq, &iq, &lq, &eq)) != 0) {
            if (st < 0)
                return cf_error_set(err, CF_E_INTERNAL,
                                    "out of memory in the viscoelastic fit of %d Prony term%s",
                                    nb, nb == 1 ? "" : "s");
            if (!fitted || preferred(iq, aq, ident, aic)) {
                p = q;
                aic = aq;
                ident = iq;
                el = eq;
                mask = c->smask;
            }
            fitted = 1;
            /* again without the loose k_i, while some stay */
            if (iq || !lq || (c->smask & ~lq) == 0 || c->smask != mask || out_of_evaluations(c))
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
                (cf_visco_candidate){1, aic, ident, c->gs ? cf_viscofit_strain_terms(c) : 0, el};
        if (best_aic == HUGE_VAL || preferred(ident, aic, best_ident, best_aic)) {
            best_aic = aic;
            best_ident = ident;
            best_gs = c->gs;
            best_mask = c->smask;
            best_el = el;
            *best = p;
        }
    }
    if (!(best_aic < HUGE_VAL))
        return cf_error_set(err, CF_E_NOCONV,
                            "no viscoelastic model could be evaluated along this series");
    res->identified = best_ident;
    res->elastic_unresolved = best_el;
    c->gs = best_gs;
    c->smask = best_mask;
    c->nb = best->nbranch;
    return CF_OK;
}

/* ---- the reported model ---------------------------------------------------------------------- */

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
    res->k = (c->free_el ? 3 : 0) + 2 * bestp->nbranch + cf_viscofit_strain_terms(c) + c->dash;
    double wrss = fit_quality(c, res);
    double s2 = (double)c->n > res->k ? wrss / ((double)c->n - res->k) : 0;
    int held[CF_IDENT_COUNT];
    fit_limits(c, bestp, res, held);
    cf_viscofit_standard_errors(c, bestp, held, s2, res);
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
    CF_GSL_GUARD;
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
    res->evaluation_bound_reached = c.bound_hit;
    res->wall_time_s = cf_clock_s() - t0;
    free(c.sw);
    free(c.m);
    cf_visco_limits_free(&c.lim);
    if (st != CF_OK)
        cf_visco_fit_free(res);
    return st;
}
