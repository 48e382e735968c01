/*
** The joint fit of several tables through the lattice (see joint.h).
*/
#include "conifit/joint.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <nlopt.h>

#include "conifit/baseline.h"
#include "conifit/cell.h"
#include "conifit/cell_stability.h"
#include "conifit/family.h"
#include "conifit/msm.h"
#include "fit/cell_problem.h"
#include "fit/clock.h"
#include "fit/lsq.h"
#include "fit/tail.h"
#include "fit/tail_cell.h"

/* BOBYQA: relative step tolerance and curves per start (each a few tens of microseconds). */
#define XTOL_REL 1e-7
#define MAX_EVALS 600
/* Diagonal-to-edge weight ratio searched when the weights are fitted. */
#define Q_LO 0.02
#define Q_HI 5.0
/* relative step of the tailed law's errors' central differences, as its single fit through the
** lattice takes (lattice_tail.c) */
#define TAIL_FD_STEP 1e-4
/* BOBYQA's curves per start of the double-acting element's (or the volume term's) search */
#define PAIR_MAX_EVALS 1500
/* the pair's starts (at most), and the searches kept to stable lattices from their ends */
#define MAX_PAIR_STARTS 32
#define STABLE_RESTARTS 3
#define STABLE_BISECT_SEGMENT 12
#define STABLE_MAX_EVALS 500

typedef struct jctx {
    const cf_table *const *t;
    size_t n;
    const cf_fit_options *opt;
    const cf_validate_setup *lat;
    cf_spring_type type;
    int fit_weights;
    double weight[CF_FAMILY_COUNT]; /* the fixed weights (or the last tried) */
    double *sw[CF_JOINT_MAX];       /* per-row residual weights 1/(s_k sqrt n_k) */
    double *curve[CF_JOINT_MAX];    /* scratch: each table's cell curve at unit scale */
    cf_cell_problem pr;             /* every table's rows in order, with their weights */
    int tail;                       /* 1: the conical-tail law's members, their tail tau */
    double tau;
    double need;                    /* the largest spring strain with the travel margin */
    /* the double-acting element and the volume term (cf_joint_fit_pair) */
    int pair;                       /* 1: every curve's law has the extension spring ext */
    double ext[3];                  /* its rho, s/H and stress scale over the compression one's */
    int kappa_mode;                 /* the cell's kappa: KAPPA_* */
    double kappa;                   /* KAPPA_REL: over the compression spring's k0/H; KAPPA_UNIT:
                                    ** over its stress scale; KAPPA_NU: the declared nu */
    /* the pair's search keeps to lattices stable over the uniaxial tables' ranges: a point that
    ** would lower the best objective of the current start (stab_best) counts only when its full
    ** lattice is stable there (joint_stable_at); stab_on 0: no such check */
    int stab_on;
    double stab_best;
} jctx;

/* How a curve's volume modulus is set (jctx.kappa_mode): none; kappa/(k0/H) of the compression
** spring (the fit's search variable); kappa per unit stress scale (a declared kappa over the
** stress scale held, or the errors' Jacobian); from a declared nu. */
enum { KAPPA_NONE = 0, KAPPA_REL, KAPPA_UNIT, KAPPA_NU };

/* The cell's volume modulus for a curve whose compression law (at stress scale 1) is law. */
static double curve_kappa(const jctx *c, const cf_law *law)
{
    const double k0H = law->k0_N_per_mm / law->p.H_mm; /* H = 1 mm: MPa */
    switch (c->kappa_mode) {
    case KAPPA_REL: return c->kappa * k0H;
    case KAPPA_UNIT: return c->kappa;
    case KAPPA_NU: return fmax(0.0, cf_cubic_kappa_of_nu(c->weight, k0H, c->kappa));
    default: return 0.0;
    }
}

/* Family weights of ratio q (face = body = q edge), scaled to the law's small-strain modulus. */
static void weights_of(double q, double w[CF_FAMILY_COUNT])
{
    double u[CF_FAMILY_COUNT] = {1, q, q};
    double E = cf_cubic_moduli_of(u).E;
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        w[f] = u[f] / E;
}

/* Every table's cell curve at stress scale 1 for (rho, B), the tables one after another. */
static int joint_curve(void *ctx, double rho, double B, double *out)
{
    const jctx *c = ctx;
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = c->tail ? cf_ident_member_tail(&q, c->tau) : cf_ident_member(&q);
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 1;
    cf_law ext;
    if (c->pair) {
        const cf_ident qe = {.rho = c->ext[0], .solid = c->ext[1], .scale = c->ext[2]};
        const cf_spring pe = cf_ident_member(&qe);
        if (cf_law_init(&ext, &pe, NULL) != CF_OK || cf_law_pair(&law, &ext, NULL) != CF_OK)
            return 1;
    }
    cf_cell cell;
    if (cf_cell_init(&cell, &law, c->lat->method == CF_LAW_TABLE ? CF_LAW_CLOSED : c->lat->method,
                     c->weight, NULL) != CF_OK)
        return 1;
    if (c->kappa_mode != KAPPA_NONE)
        cell.volume_modulus_MPa = curve_kappa(c, &law);
    for (size_t k = 0, m = 0; k < c->n; m += c->t[k++]->count)
        if (cf_cell_curve(&cell, c->t[k]->mode, c->t[k]->x, c->t[k]->count, out + m, NULL) !=
            CF_OK)
            return 1;
    return 0;
}

/* The tailed law's cap on the stress scale at (rho, B) and the context's tau (tail_cell.h). */
static double joint_A_max(void *ctx, double rho, double B)
{
    const jctx *c = ctx;
    return cf_tail_cell_A_max(rho, B, c->tau, c->need, c->type, c->opt);
}

/* Objective at z = (ln rho, s/H [, ln q]) with the stress scale in closed form; *A_out. */
static double profile(jctx *c, const double *z, double *A_out)
{
    if (c->fit_weights)
        weights_of(exp(z[2]), c->weight);
    return cf_cell_rss(&c->pr, exp(z[0]), z[1], A_out);
}

static double objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    double A;
    return profile(data, z, &A);
}

int cf_joint_stable(const cf_joint_result *r)
{
    for (size_t k = 0; k < r->ntables && k < CF_JOINT_MAX; k++)
        if (r->tab[k].stability_checked && !r->tab[k].stable_in_range)
            return 0;
    return 1;
}

void cf_joint_free(cf_joint_result *r)
{
    if (!r)
        return;
    for (size_t k = 0; k < CF_JOINT_MAX; k++) {
        free(r->tab[k].lattice_MPa);
        r->tab[k].lattice_MPa = NULL;
    }
}

/* Full-lattice checks of a pair's or a volume term's stability: the lattices of 2 x 2 x 2 (the
** export's) and 3 x 3 x 3 cells (simulate's default), bottom sliding, and the scan's steps and
** bisections over the table's range. */
#define LATTICE_CHECK_SIZES 2
#define STABLE_SCAN_STEPS 32
#define STABLE_BISECT 20

/* 1 when every checked lattice (cfg with n^3 cells, n = 2 .. 1 + sizes) is stable at the homogeneous
** uniaxial state of table strain e that the cell c gives, 0 when one is not (or the state cannot
** be reached), -1 on running out of memory. The homogeneous state is the sliding-bottom
** lattice's equilibrium, so no Newton solve: one factorisation of each tangent, whose negative
** pivots (cf_msm_homogeneous_inertia) are the columns of cells that buckle sideways -- a
** cell-scale mode the homogenised cell's positive-definite tangent does not see. */
static int lattice_stable_at(const cf_cell *c, const cf_msm_config *cfg, double e, int sizes)
{
    cf_cell_state s;
    cf_error e1 = {0};
    if (cf_cell_mode(c, CF_MODE_UNIAXIAL, e, NULL, &s, &e1) != CF_OK)
        return 0;
    for (int n = 2; n < 2 + sizes; n++) {
        cf_msm_config k = *cfg;
        k.lattice.nx = k.lattice.ny = k.lattice.nz = n;
        k.lattice.bottom = CF_BOTTOM_AXIAL;
        long neg = -1;
        cf_error e2 = {0};
        cf_status st = cf_msm_homogeneous_inertia(c->law, CF_LAW_CLOSED, &k, e, s.F[0], &neg,
                                                  &e2);
        if (st == CF_E_INTERNAL)
            return -1;
        if (st != CF_OK || neg != 0)
            return 0;
    }
    return 1;
}

/* Follows the uniaxial state from 0 to reach (table sign) in the full lattices and returns the
** largest |strain| up to which every one stays stable (*lost 1 when that is short of reach), as
** cf_cell_stable_to does for the cell. CF_E_INTERNAL when memory runs out. */
static cf_status lattice_stable_to(const cf_cell *c, const cf_msm_config *cfg, double reach,
                                   double *limit, int *lost, cf_error *err)
{
    *limit = reach;
    *lost = 0;
    double good = 0;
    for (int k = 1; k <= STABLE_SCAN_STEPS; k++) {
        const double e = reach * k / STABLE_SCAN_STEPS;
        int r = lattice_stable_at(c, cfg, e, LATTICE_CHECK_SIZES);
        if (r < 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory in the lattice's stability "
                                                    "check");
        if (r) {
            good = e;
            continue;
        }
        double bad = e;
        for (int b = 0; b < STABLE_BISECT && fabs(bad - good) > 1e-6 * fabs(reach); b++) {
            const double mid = 0.5 * (good + bad);
            r = lattice_stable_at(c, cfg, mid, LATTICE_CHECK_SIZES);
            if (r < 0)
                return cf_error_set(err, CF_E_INTERNAL, "out of memory in the lattice's "
                                                        "stability check");
            if (r)
                good = mid;
            else
                bad = mid;
        }
        *limit = good;
        *lost = 1;
        return CF_OK;
    }
    return CF_OK;
}

/* Strains of a uniaxial table's range at which the search checks the full lattice (the
** verification scans it finely, verify_tables). */
#define SEARCH_STABLE_STEPS 5

/* 1 when the full lattices of the curve's law at (rho, B) (the context's extension spring and
** kappa, at unit stress scale: every force scales alike, so stability does not depend on the
** scale) of 2^3 cells (the more slender, the first to buckle; the verification checks 3^3 too)
** are stable at SEARCH_STABLE_STEPS strains up to each uniaxial table's farthest one. */
static int joint_stable_at(const jctx *c, double rho, double B)
{
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = cf_ident_member(&q);
    cf_law law, ext;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 0;
    if (c->pair) {
        const cf_ident qe = {.rho = c->ext[0], .solid = c->ext[1], .scale = c->ext[2]};
        const cf_spring pe = cf_ident_member(&qe);
        if (cf_law_init(&ext, &pe, NULL) != CF_OK || cf_law_pair(&law, &ext, NULL) != CF_OK)
            return 0;
    }
    cf_cell cell;
    if (cf_cell_init(&cell, &law, CF_LAW_CLOSED, c->weight, NULL) != CF_OK)
        return 0;
    if (c->kappa_mode != KAPPA_NONE)
        cell.volume_modulus_MPa = curve_kappa(c, &law);
    cf_msm_config cfg = c->lat->cfg;
    memcpy(cfg.lattice.weight, c->weight, sizeof c->weight);
    cfg.lattice.volume_modulus_MPa = cell.volume_modulus_MPa;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        if (t->mode != CF_MODE_UNIAXIAL)
            continue;
        double reach = 0;
        for (size_t i = 0; i < t->count; i++)
            if (fabs(t->x[i]) > fabs(reach))
                reach = t->x[i];
        double e[SEARCH_STABLE_STEPS], lat[SEARCH_STABLE_STEPS];
        for (int j = 0; j < SEARCH_STABLE_STEPS; j++) {
            cf_cell_state st;
            e[j] = reach * (j + 1) / SEARCH_STABLE_STEPS;
            if (cf_cell_mode(&cell, CF_MODE_UNIAXIAL, e[j], NULL, &st, NULL) != CF_OK)
                return 0;
            lat[j] = st.F[0];
        }
        cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = 2;
        cfg.lattice.bottom = CF_BOTTOM_AXIAL;
        long neg = -1;
        if (cf_msm_homogeneous_inertias(&law, CF_LAW_CLOSED, &cfg, e, lat, SEARCH_STABLE_STEPS,
                                        &neg, NULL) != CF_OK ||
            neg != 0)
            return 0;
    }
    return 1;
}

/* Each table in the lattice of the placed spring r->fit: the cell, and the full lattice when the
** mode is uniaxial (the verification). */
static cf_status verify_tables(const jctx *c, cf_joint_result *r, cf_error *err)
{
    cf_law law, ext;
    cf_status st = cf_law_init(&law, &r->fit.params, err);
    if (st != CF_OK)
        return st;
    if (r->pair && ((st = cf_law_init(&ext, &r->ext.params, err)) != CF_OK ||
                    (st = cf_law_pair(&law, &ext, err)) != CF_OK))
        return st;
    cf_validate_setup full = *c->lat;
    memcpy(full.cfg.lattice.weight, c->weight, sizeof c->weight);
    full.cfg.lattice.volume_modulus_MPa = r->volume_modulus_MPa;
    cf_cell cell;
    cf_cell_init(&cell, &law, CF_LAW_CLOSED, c->weight, NULL);
    cell.volume_modulus_MPa = r->volume_modulus_MPa;
    const int k_aic = r->nparams ? r->nparams : r->fit.tail ? 4 : 3;
    for (size_t k = 0; k < c->n && st == CF_OK; k++) {
        const cf_table *t = c->t[k];
        cf_joint_table *jt = &r->tab[k];
        if ((st = cf_cell_curve(&cell, t->mode, t->x, t->count, c->curve[k], err)) != CF_OK)
            break;
        jt->cell_rmse = cf_lsq_quality_of(t, c->curve[k]).rmse;
        /* the table's own AIC at the joint law, in the table's unit as a single fit states it */
        double ymax = 0;
        for (size_t i = 0; i < t->count; i++)
            ymax = fmax(ymax, fabs(t->y[i]));
        const double u = t->y_to_file;
        const double rss = jt->cell_rmse * jt->cell_rmse * (double)t->count * u * u;
        jt->aic = cf_baseline_aic(t->count, rss, k_aic, ymax * u);
        jt->by_cell = t->mode != CF_MODE_UNIAXIAL;
        if (jt->by_cell)
            memcpy(jt->lattice_MPa, c->curve[k], t->count * sizeof(double));
        else if ((st = cf_msm_uniaxial(&law, CF_LAW_CLOSED, &full.cfg, t->x, t->count,
                                       jt->lattice_MPa, NULL, err)) != CF_OK)
            break;
        jt->lattice_rmse = cf_lsq_quality_of(t, jt->lattice_MPa).rmse;
        if (r->pair || r->volume_modulus_MPa != 0) { /* stable over the table's whole range? */
            double reach = 0, limit = 0;
            int lost = 1;
            for (size_t i = 0; i < t->count; i++)
                if (fabs(t->x[i]) > fabs(reach))
                    reach = t->x[i];
            if (reach != 0 && cf_cell_stable_to(&cell, t->mode, reach, &limit, &lost, NULL) ==
                                  CF_OK) {
                jt->stability_checked = 1;
                jt->stable_in_range = !lost;
                jt->stable_to = limit;
            }
            /* a uniaxial table: the full lattice too, which can buckle where the cell does not */
            if (jt->stability_checked && t->mode == CF_MODE_UNIAXIAL) {
                double llim = reach;
                int llost = 0;
                if ((st = lattice_stable_to(&cell, &full.cfg, reach, &llim, &llost, err)) !=
                    CF_OK)
                    break;
                jt->lattice_checked = 1;
                if (llost && fabs(llim) < fabs(jt->stable_to))
                    jt->stable_to = llim;
                jt->stable_in_range = jt->stable_in_range && !llost;
            }
        }
        double ss = 0;
        for (size_t i = 0; i < t->count; i++) {
            /* the law's stress at table strain x (tension positive): -F(-x H)/H^2, the odd
            ** law's F(x H)/H^2 to the bit, a pair's extension spring in tension */
            double d = jt->lattice_MPa[i] + cf_fit_model(&law, 0, -t->x[i]);
            ss += d * d;
        }
        jt->law_rmse = t->mode == CF_MODE_UNIAXIAL ? sqrt(ss / (double)t->count) : NAN;
    }
    cf_law_free(&law);
    return st;
}

/* The conical law's search over (rho, s/H [, the weight ratio]) from a grid of starts, every
** table's curve through the cell, and the spring placed from the best; the reach bounds s/H. */
static cf_status search_conical(jctx *c, const cf_table *reach, double xmax, cf_joint_result *r,
                                cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    const int nz = c->fit_weights ? 3 : 2;
    double lb[3] = {log(fmax(CF_IDENT_RHO_LO, opt->rho_min)),
                    xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9), log(Q_LO)};
    double ub[3] = {log(cf_ident_rho_hi(c->type, opt->index_max)), 1 - 1e-9, log(Q_HI)};
    if (!(lb[1] < ub[1]))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    memcpy(c->pr.lb, lb, sizeof c->pr.lb);
    memcpy(c->pr.ub, ub, sizeof c->pr.ub);
    double best = CF_LSQ_HUGE_OBJ, zb[3] = {0, 0, 0};
    const double grid_rho[3] = {0.1, 0.35, 0.7}, grid_e[3] = {0.1, 0.4, 0.8};
    const double q_iso = 0.2708 / 0.6085, grid_q[2] = {q_iso, 1.0};
    for (int gq = 0; gq < (c->fit_weights ? 2 : 1); gq++)
        for (int g = 0; g < 9; g++) {
            double z[3] = {log(grid_rho[g % 3]), lb[1] + grid_e[g / 3] * (ub[1] - lb[1]),
                           log(grid_q[gq])};
            for (int j = 0; j < nz; j++)
                z[j] = fmin(fmax(z[j], lb[j]), ub[j]);
            double step[3] = {0.1, 0.05 * (ub[1] - lb[1]), 0.2}, f = CF_LSQ_HUGE_OBJ;
            nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)nz, lb, ub,
                                              step, XTOL_REL, MAX_EVALS, objective, c, z, &f);
            if (c->pr.oom)
                return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's "
                                                        "optimiser (NLopt)");
            if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED) && f < best) {
                best = f;
                memcpy(zb, z, sizeof zb);
            }
        }
    double A = 0;
    if (!(best < CF_LSQ_HUGE_OBJ) || !(profile(c, zb, &A) < CF_LSQ_HUGE_OBJ) || !(A > 0))
        return cf_error_set(err, CF_E_NOCONV, "the joint fit found no lattice that runs every "
                                              "table");
    r->objective = best;
    r->ident.rho = exp(zb[0]), r->ident.solid = zb[1], r->ident.scale = A;
    cf_status st = cf_fit_place(reach, opt, c->type, &r->ident, &r->fit, err);
    if (st != CF_OK)
        return st;
    /* the uncertainty of the quantities found, the weights (fitted or not) held where they are:
    ** each table's residuals weighted as in the search */
    r->fit.ident = r->ident;
    return cf_cell_uncertainty(&c->pr, &c->pr, &r->fit, err);
}

/* The conical-tail law's search through the cell (tail_cell.h), the weights held at the conical
** law's fit plain, from its quantities; the tailed spring placed in closed form (tail.h) with the
** errors of its four quantities from the joint residuals, and their profile intervals where the
** errors say nothing. */
static cf_status search_tail(jctx *c, const cf_table *reach, double xmax,
                             const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    c->tail = 1;
    c->fit_weights = 0;
    c->need = xmax * (1 + CF_FIT_TRAVEL_MARGIN);
    c->pr.A_max = joint_A_max;
    if (!(c->need < 1))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    double lb[3], ub[3], zb[3] = {0, 0, 0}, A = 0;
    cf_tail_cell_box(c->opt, c->type, xmax, lb, ub);
    const cf_tail_cell tc = {&c->pr, &c->tau};
    const double best = cf_tail_cell_search(&tc, &plain->ident, lb, ub, zb);
    if (c->pr.oom)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's optimiser "
                                                "(NLopt)");
    const double f = best < CF_LSQ_HUGE_OBJ ? cf_tail_cell_profile(&tc, zb, &A) : CF_LSQ_HUGE_OBJ;
    if (!(f < CF_LSQ_HUGE_OBJ) || !(A > 0))
        return cf_error_set(err, CF_E_NOCONV, "the joint fit found no conical-tail law that runs "
                                              "every table");
    double v[4], se[4], corr[4][4], cov_Bt;
    cf_tail_cell_quantities(zb, A, v);
    r->objective = f * c->pr.ynorm;
    cf_tail_errors(cf_tail_cell_residuals, (void *)&tc, c->pr.n, v, TAIL_FD_STEP, r->objective,
                   se, corr, &cov_Bt);
    cf_status st = cf_tail_result(reach, c->opt, c->type, v, se, corr, cov_Bt, &r->fit, err);
    if (st != CF_OK)
        return st;
    r->fit.held |= cf_tail_cell_held(c->opt, lb, ub, zb, c->type);
    /* profile intervals where the errors say nothing, as for one table, on every table's rows */
    if (cf_tail_cell_intervals(&tc, c->opt, c->type, c->need, lb, ub, c->pr.n, r->objective,
                               c->pr.ynorm, v, &r->fit) < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the profiles of %zu rows",
                            c->pr.n);
    r->ident = r->fit.ident;
    return CF_OK;
}

/* The pair's and the volume term's search variables, in order: ln rho, s/H of the compression
** spring; with the pair ln rho, s/H of the extension spring and ln of its stress scale over the
** compression one's; with kappa fitted ln (kappa/(k0/H)); with kappa declared ln of the stress
** scale (held, kappa over it then known); with fitted weights ln q. */
typedef struct pvars {
    int n;                         /* variables */
    int ie, ik, iA, iq;            /* index of the extension's first, kappa's, A's, q's; -1 none */
    double lb[8], ub[8];
} pvars;

/* The quantities the search's z stands for into the context (and the stress scale held, or 0). */
static void pair_set(jctx *c, const pvars *pv, const double *z)
{
    if (pv->ie >= 0)
        c->ext[0] = exp(z[pv->ie]), c->ext[1] = z[pv->ie + 1], c->ext[2] = exp(z[pv->ie + 2]);
    if (pv->ik >= 0)
        c->kappa = exp(z[pv->ik]);
    if (pv->iA >= 0) {
        c->pr.A_fixed = exp(z[pv->iA]);
        c->kappa = c->opt->volume_value / c->pr.A_fixed;
    }
    if (pv->iq >= 0)
        weights_of(exp(z[pv->iq]), c->weight);
}

/* 1 when the search's point z (pair_set) has full lattices stable over the uniaxial tables. */
static int z_stable(jctx *c, const pvars *pv, const double *z)
{
    pair_set(c, pv, z);
    return joint_stable_at(c, exp(z[0]), z[1]);
}

typedef struct pair_obj {
    jctx *c;
    const pvars *pv;
} pair_obj;

static double pair_objective(unsigned nz, const double *z, double *grad, void *data)
{
    (void)nz;
    (void)grad;
    const pair_obj *o = data;
    jctx *c = o->c;
    pair_set(c, o->pv, z);
    double A;
    const double f = cf_cell_rss(&c->pr, exp(z[0]), z[1], &A);
    if (c->stab_on && f < c->stab_best) {
        if (!joint_stable_at(c, exp(z[0]), z[1]))
            return CF_LSQ_HUGE_OBJ;
        c->stab_best = f;
    }
    return f;
}

/* The largest compression stress scale at (rho, B) with the extension spring of the context: the
** smaller of what a spring of the type carries there and what the extension spring carries over
** its share; 0 where either cannot be placed. */
static double pair_A_max(void *ctx, double rho, double B)
{
    const jctx *c = ctx;
    double Ac, Ae = INFINITY;
    if (cf_fit_ident_limit(c->opt, c->type, rho, B, &Ac, NULL) > 0)
        return 0;
    if (c->pair) {
        if (cf_fit_ident_limit(c->opt, c->type, c->ext[0], c->ext[1], &Ae, NULL) > 0)
            return 0;
        Ae /= c->ext[2];
    }
    return fmin(Ac, Ae);
}

/* The seven (at most) quantities v = rho_c, B_c, A_c, rho_e, B_e, A_e, kappa into the context
** for a curve at stress scale 1 (kappa over A_c). */
enum { PQ_RC = 0, PQ_BC, PQ_AC, PQ_RE, PQ_BE, PQ_AE, PQ_K, PQ_COUNT };

static int pair_residuals(jctx *c, const double v[PQ_COUNT], double *g, double *res)
{
    c->ext[0] = v[PQ_RE], c->ext[1] = v[PQ_BE], c->ext[2] = v[PQ_AE] / v[PQ_AC];
    if (c->opt->volume == CF_VOLUME_POISSON) { /* kappa follows the springs */
        c->kappa_mode = KAPPA_NU;
        c->kappa = c->opt->volume_value;
    } else {
        c->kappa_mode = KAPPA_UNIT;
        c->kappa = v[PQ_K] / v[PQ_AC];
    }
    if (joint_curve(c, v[PQ_RC], v[PQ_BC], g) != 0)
        return 1;
    for (size_t i = 0; i < c->pr.n; i++)
        res[i] = c->pr.sw[i] * (v[PQ_AC] * g[i] - c->pr.y[i]);
    return 0;
}

/* 1 when quantity k of v is searched in logarithm (the scales, ratios and kappa), 0 for the solid
** strains. */
static int pq_log(int k)
{
    return k != PQ_BC && k != PQ_BE;
}

/* The weighted RSS at v (the residuals into res), CF_LSQ_HUGE_OBJ where a curve fails, a strain
** leaves [Blo, Bhi], a ratio [rlo, rhi], or the compression spring's scale passes what the pair
** carries there. */
static double pair_rss(jctx *c, const double v[PQ_COUNT], const double box[4], double *g,
                       double *res)
{
    if (v[PQ_BC] < box[0] || v[PQ_BC] > box[1] || v[PQ_RC] < box[2] || v[PQ_RC] > box[3])
        return CF_LSQ_HUGE_OBJ;
    if (c->pair && (v[PQ_BE] < box[0] || v[PQ_BE] > box[1] || v[PQ_RE] < box[2] ||
                    v[PQ_RE] > box[3]))
        return CF_LSQ_HUGE_OBJ;
    if (pair_residuals(c, v, g, res) != 0)
        return CF_LSQ_HUGE_OBJ;
    if (!(v[PQ_AC] <= pair_A_max(c, v[PQ_RC], v[PQ_BC]) * (1 + 1e-12)))
        return CF_LSQ_HUGE_OBJ;
    double ss = 0;
    for (size_t i = 0; i < c->pr.n; i++)
        ss += res[i] * res[i];
    return isfinite(ss) ? ss : CF_LSQ_HUGE_OBJ;
}

/* Levenberg-Marquardt from v over the used quantities (logarithms of the scales and kappa, the
** strains as they are), central-difference Jacobians, inside the search's box: BOBYQA's optimum
** polished to where the residuals stop falling (a noiseless table's quantities to ~1e-8). Returns
** the RSS at v (updated in place). */
static double pair_polish(jctx *c, double v[PQ_COUNT], const int used[PQ_COUNT],
                          const double box[4])
{
    const size_t n = c->pr.n;
    int idx[PQ_COUNT], p = 0;
    for (int k = 0; k < PQ_COUNT; k++)
        if (used[k] && v[k] > 0)
            idx[p++] = k;
    double *g = malloc(sizeof(double) * n), *r0 = malloc(sizeof(double) * n);
    double *rp = malloc(sizeof(double) * n), *rm = malloc(sizeof(double) * n);
    double *J = malloc(sizeof(double) * n * (size_t)(p ? p : 1));
    double f = CF_LSQ_HUGE_OBJ;
    if (g && r0 && rp && rm && J)
        f = pair_rss(c, v, box, g, r0);
    double lambda = 1e-3;
    for (int it = 0; it < 40 && f < CF_LSQ_HUGE_OBJ && f > 0; it++) {
        int bad = 0;
        for (int a = 0; a < p && !bad; a++) {
            const int k = idx[a];
            const double h = 1e-6 * (pq_log(k) ? 1.0 : fabs(v[k]));
            double vp[PQ_COUNT], vm[PQ_COUNT];
            memcpy(vp, v, sizeof vp);
            memcpy(vm, v, sizeof vm);
            vp[k] = pq_log(k) ? v[k] * exp(h) : v[k] + h;
            vm[k] = pq_log(k) ? v[k] * exp(-h) : v[k] - h;
            bad = pair_residuals(c, vp, g, rp) != 0 || pair_residuals(c, vm, g, rm) != 0;
            for (size_t i = 0; i < n && !bad; i++)
                J[i * (size_t)p + (size_t)a] = (rp[i] - rm[i]) / (2 * h);
        }
        c->pr.evals += 2 * p;
        if (bad)
            break;
        double A[PQ_COUNT][PQ_COUNT], b[PQ_COUNT];
        for (int a = 0; a < p; a++) {
            b[a] = 0;
            for (size_t i = 0; i < n; i++)
                b[a] -= J[i * (size_t)p + (size_t)a] * r0[i];
            for (int bb = 0; bb < p; bb++) {
                double d = 0;
                for (size_t i = 0; i < n; i++)
                    d += J[i * (size_t)p + (size_t)a] * J[i * (size_t)p + (size_t)bb];
                A[a][bb] = d;
            }
        }
        int improved = 0;
        for (int tries = 0; tries < 8 && !improved; tries++) {
            /* (J^T J + lambda diag) delta = -J^T r by Gaussian elimination with pivoting */
            double M[PQ_COUNT][PQ_COUNT + 1];
            for (int a = 0; a < p; a++) {
                for (int bb = 0; bb < p; bb++)
                    M[a][bb] = A[a][bb] + (a == bb ? lambda * (A[a][a] > 0 ? A[a][a] : 1) : 0);
                M[a][p] = b[a];
            }
            int singular = 0;
            for (int col = 0; col < p && !singular; col++) {
                int piv = col;
                for (int row = col + 1; row < p; row++)
                    if (fabs(M[row][col]) > fabs(M[piv][col]))
                        piv = row;
                if (!(fabs(M[piv][col]) > 0)) {
                    singular = 1;
                    break;
                }
                for (int q = 0; q <= p; q++) {
                    const double t = M[col][q];
                    M[col][q] = M[piv][q];
                    M[piv][q] = t;
                }
                for (int row = col + 1; row < p; row++) {
                    const double fct = M[row][col] / M[col][col];
                    for (int q = col; q <= p; q++)
                        M[row][q] -= fct * M[col][q];
                }
            }
            double delta[PQ_COUNT];
            for (int a = p - 1; a >= 0 && !singular; a--) {
                double t = M[a][p];
                for (int q = a + 1; q < p; q++)
                    t -= M[a][q] * delta[q];
                delta[a] = t / M[a][a];
            }
            double vt[PQ_COUNT];
            memcpy(vt, v, sizeof vt);
            for (int a = 0; a < p && !singular; a++) {
                const int k = idx[a];
                vt[k] = pq_log(k) ? v[k] * exp(fmax(fmin(delta[a], 1.0), -1.0)) : v[k] + delta[a];
            }
            const double ft = singular ? CF_LSQ_HUGE_OBJ : pair_rss(c, vt, box, g, rp);
            c->pr.evals++;
            if (ft < f) {
                const double drop = (f - ft) / f;
                memcpy(v, vt, sizeof vt);
                memcpy(r0, rp, sizeof(double) * n);
                f = ft;
                lambda = fmax(lambda / 10, 1e-12);
                improved = 1;
                if (drop < 1e-12)
                    it = 40; /* converged */
            } else {
                lambda *= 10;
            }
        }
        if (!improved)
            break;
    }
    free(g);
    free(r0);
    free(rp);
    free(rm);
    free(J);
    return f;
}

/* Standard errors of the used quantities (used[k]) from the central-difference Jacobian of the
** weighted residuals: s^2 (J^T J)^+ with s^2 = rss/(N - p), the pseudo-inverse over the
** eigenvalues of J^T J's unit-diagonal form above 1e-10 of the largest; a quantity with a
** component in the discarded directions is not determined (se -1). 0, or -1 when memory runs out
** or a curve fails. */
static int pair_errors(jctx *c, const double v0[PQ_COUNT], const int used[PQ_COUNT],
                       double rss, double se[PQ_COUNT])
{
    const size_t n = c->pr.n;
    int idx[PQ_COUNT], p = 0;
    for (int k = 0; k < PQ_COUNT; k++) {
        se[k] = -1;
        if (used[k])
            idx[p++] = k;
    }
    double *J = malloc(sizeof(double) * n * (size_t)p), *g = malloc(sizeof(double) * n);
    double *rp = malloc(sizeof(double) * n), *rm = malloc(sizeof(double) * n);
    const int oom = !J || !g || !rp || !rm;
    int bad = oom;
    for (int a = 0; a < p && !bad; a++) {
        double v[PQ_COUNT];
        memcpy(v, v0, sizeof v);
        const double h = TAIL_FD_STEP * fabs(v0[idx[a]]);
        v[idx[a]] = v0[idx[a]] + h;
        bad = pair_residuals(c, v, g, rp);
        v[idx[a]] = v0[idx[a]] - h;
        bad = bad || pair_residuals(c, v, g, rm);
        for (size_t i = 0; i < n && !bad; i++)
            J[i * (size_t)p + (size_t)a] = (rp[i] - rm[i]) / (2 * h);
    }
    c->pr.evals += 2 * p;
    if (!bad && (size_t)p < n) {
        gsl_matrix *M = gsl_matrix_alloc((size_t)p, (size_t)p);
        gsl_matrix *V = gsl_matrix_alloc((size_t)p, (size_t)p);
        gsl_vector *ev = gsl_vector_alloc((size_t)p);
        gsl_eigen_symmv_workspace *ws = gsl_eigen_symmv_alloc((size_t)p);
        double dsc[PQ_COUNT];
        const int oom2 = !M || !V || !ev || !ws;
        bad = oom2;
        for (int a = 0; a < p && !bad; a++) {
            double d = 0;
            for (size_t i = 0; i < n; i++)
                d += J[i * (size_t)p + (size_t)a] * J[i * (size_t)p + (size_t)a];
            dsc[a] = d > 0 ? 1 / sqrt(d) : 0;
        }
        for (int a = 0; a < p && !bad; a++)
            for (int b = 0; b < p; b++) {
                double d = 0;
                for (size_t i = 0; i < n; i++)
                    d += J[i * (size_t)p + (size_t)a] * J[i * (size_t)p + (size_t)b];
                gsl_matrix_set(M, (size_t)a, (size_t)b, d * dsc[a] * dsc[b]);
            }
        if (!bad && gsl_eigen_symmv(M, ev, V, ws) == GSL_SUCCESS) {
            double emax = 0;
            for (int a = 0; a < p; a++)
                emax = fmax(emax, gsl_vector_get(ev, (size_t)a));
            const double s2 = rss / (double)((int)n - p);
            for (int a = 0; a < p; a++) {
                double var = 0, null = 0;
                for (int b = 0; b < p; b++) {
                    const double e = gsl_vector_get(ev, (size_t)b), x = gsl_matrix_get(V, (size_t)a,
                                                                                     (size_t)b);
                    if (e > 1e-10 * emax)
                        var += x * x / e;
                    else
                        null += x * x;
                }
                if (dsc[a] > 0 && null < 1e-6)
                    se[idx[a]] = sqrt(s2 * var) * dsc[a];
            }
        }
        gsl_eigen_symmv_free(ws);
        gsl_vector_free(ev);
        gsl_matrix_free(V);
        gsl_matrix_free(M);
        if (oom2)
            bad = -1;
    }
    free(J);
    free(g);
    free(rp);
    free(rm);
    return oom || bad < 0 ? -1 : bad; /* a curve that failed: every error stays -1 */
}

/* The lattice's small-strain Young's modulus and Poisson's ratio in uniaxial compression and in
** tension (strain -+1e-6, every spring inside its linear region) from the cell of the quantities
** v; NAN where the cell fails. */
static void small_strain_moduli(jctx *c, const double v[PQ_COUNT], cf_joint_result *r)
{
    const cf_ident qc = {.rho = v[PQ_RC], .solid = v[PQ_BC], .scale = v[PQ_AC]};
    const cf_ident qe = {.rho = v[PQ_RE], .solid = v[PQ_BE], .scale = v[PQ_AE]};
    const cf_spring pc = cf_ident_member(&qc), pe = cf_ident_member(&qe);
    cf_law lc, le;
    cf_cell cell;
    r->E_compression_MPa = r->E_extension_MPa = r->nu_compression = r->nu_extension = NAN;
    if (cf_law_init(&lc, &pc, NULL) != CF_OK ||
        (c->pair && (cf_law_init(&le, &pe, NULL) != CF_OK || cf_law_pair(&lc, &le, NULL) != CF_OK)) ||
        cf_cell_init(&cell, &lc, CF_LAW_CLOSED, c->weight, NULL) != CF_OK)
        return;
    cell.volume_modulus_MPa = v[PQ_K];
    for (int side = 0; side < 2; side++) {
        const double e = side ? 1e-6 : -1e-6;
        cf_cell_state s;
        if (cf_cell_mode(&cell, CF_MODE_UNIAXIAL, e, NULL, &s, NULL) != CF_OK)
            continue;
        *(side ? &r->E_extension_MPa : &r->E_compression_MPa) = s.stress_MPa / e;
        *(side ? &r->nu_extension : &r->nu_compression) = (1 - s.free_stretch) / e;
    }
}

/* The double-acting element's (and the volume term's) search from plain's quantities and a grid,
** every table through the cell; both springs placed; the errors of every quantity. */
static cf_status search_pair(jctx *c, const cf_table *reach, double xmax,
                             const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    pvars pv = {.n = 2, .ie = -1, .ik = -1, .iA = -1, .iq = -1};
    pv.lb[0] = log(fmax(CF_IDENT_RHO_LO, opt->rho_min));
    pv.ub[0] = log(cf_ident_rho_hi(c->type, opt->index_max));
    pv.lb[1] = xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    pv.ub[1] = 1 - 1e-9;
    if (!(pv.lb[1] < pv.ub[1]))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    if (c->pair) {
        pv.ie = pv.n;
        pv.lb[pv.n] = pv.lb[0], pv.ub[pv.n++] = pv.ub[0];
        pv.lb[pv.n] = pv.lb[1], pv.ub[pv.n++] = pv.ub[1];
        pv.lb[pv.n] = log(1e-4), pv.ub[pv.n++] = log(1e4);
    }
    if (opt->volume == CF_VOLUME_FIT) {
        pv.ik = pv.n;
        pv.lb[pv.n] = log(1e-5), pv.ub[pv.n++] = log(1e4);
        c->kappa_mode = KAPPA_REL;
    } else if (opt->volume == CF_VOLUME_MODULUS) {
        pv.iA = pv.n;
        pv.lb[pv.n] = log(1e-12), pv.ub[pv.n++] = log(CF_MEASURE_MAX_VALUE);
        c->kappa_mode = KAPPA_UNIT;
    } else if (opt->volume == CF_VOLUME_POISSON) {
        c->kappa_mode = KAPPA_NU;
        c->kappa = opt->volume_value;
    }
    if (c->fit_weights) {
        pv.iq = pv.n;
        pv.lb[pv.n] = log(Q_LO), pv.ub[pv.n++] = log(Q_HI);
    }
    memcpy(c->pr.lb, pv.lb, sizeof c->pr.lb);
    memcpy(c->pr.ub, pv.ub, sizeof c->pr.ub);
    c->pr.A_max = pair_A_max;
    /* the starts: the compression spring at plain's quantities (or the middle of the box) and on
    ** a coarse grid; the extension spring from a near-cylinder (linear) to a strong cone */
    const double rc0 = plain ? plain->ident.rho : 0.35;
    const double bc0 = plain ? plain->ident.solid : pv.lb[1] + 0.4 * (pv.ub[1] - pv.lb[1]);
    const double A0 = plain ? plain->ident.scale : 0;
    const double grid_rc[2] = {rc0, 0.1}, grid_re[3] = {0.9, 0.5, 0.15},
                 grid_be[2] = {0.25, 0.7}, grid_k[2] = {0.3, 3.0};
    /* the pair contains the single-sided law (two equal springs): with plain, its optimum is a
    ** start too (ge 3), so the pair never ends worse than the law it contains */
    const int nre = c->pair ? (plain ? 4 : 3) : 1, nbe = c->pair ? 2 : 1,
              nk = pv.ik >= 0 ? 2 : 1;
    const pair_obj o = {c, &pv};
    double best = CF_LSQ_HUGE_OBJ, zb[8] = {0};
    double ends[MAX_PAIR_STARTS][8], fends[MAX_PAIR_STARTS];
    int nends = 0;
    c->stab_on = 0;
    for (int gc = 0; gc < 2; gc++)
        for (int ge = 0; ge < nre; ge++)
            for (int gb = 0; gb < nbe; gb++)
                for (int gk = 0; gk < nk; gk++) {
                    double z[8];
                    if (ge == 3 && (gc != 0 || gb != 0))
                        continue;
                    z[0] = log(grid_rc[gc]);
                    z[1] = gc == 0 ? bc0 : pv.lb[1] + 0.3 * (pv.ub[1] - pv.lb[1]);
                    if (pv.ie >= 0 && ge == 3) {
                        z[pv.ie] = z[0], z[pv.ie + 1] = z[1], z[pv.ie + 2] = 0;
                    } else if (pv.ie >= 0) {
                        z[pv.ie] = log(grid_re[ge]);
                        z[pv.ie + 1] = pv.lb[1] + grid_be[gb] * (pv.ub[1] - pv.lb[1]);
                        z[pv.ie + 2] = log(0.5);
                    }
                    if (pv.ik >= 0)
                        z[pv.ik] = log(grid_k[gk]);
                    if (pv.iA >= 0)
                        z[pv.iA] = log(A0 > 0 ? A0 : 1e-3);
                    if (pv.iq >= 0)
                        z[pv.iq] = log(plain ? plain->weight[1] / plain->weight[0]
                                             : 0.2708 / 0.6085);
                    double step[8];
                    for (int j = 0; j < pv.n; j++) {
                        z[j] = fmin(fmax(z[j], pv.lb[j]), pv.ub[j]);
                        step[j] = j == 1 || j == pv.ie + 1 ? 0.05 * (pv.ub[j] - pv.lb[j]) : 0.2;
                    }
                    double f = CF_LSQ_HUGE_OBJ;
                    if (ge == 3) {
                        /* BOBYQA may move a start near a bound before its first evaluation:
                        ** the contained law's optimum counts as it is */
                        const double f0 = pair_objective((unsigned)pv.n, z, NULL, (void *)&o);
                        if (f0 < best) {
                            best = f0;
                            memcpy(zb, z, sizeof zb);
                        }
                    }
                    nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv.n,
                                                      pv.lb, pv.ub, step, XTOL_REL,
                                                      PAIR_MAX_EVALS, pair_objective, (void *)&o,
                                                      z, &f);
                    if (c->pr.oom)
                        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint "
                                                                "fit's optimiser (NLopt)");
                    const int ok = res > 0 || res == NLOPT_ROUNDOFF_LIMITED ||
                                   res == NLOPT_MAXEVAL_REACHED;
                    if (ok && f < CF_LSQ_HUGE_OBJ && nends < MAX_PAIR_STARTS) {
                        memcpy(ends[nends], z, sizeof z);
                        fends[nends++] = f;
                    }
                    if (ok && f < best) {
                        best = f;
                        memcpy(zb, z, sizeof zb);
                    }
                }
    /* An optimum whose full lattice buckles inside a uniaxial table's range: the search again,
    ** kept to stable lattices, from the stable point nearest the optimum on the segment to each
    ** of the best (up to STABLE_RESTARTS) starts' ends that are stable. None stable: the optimum
    ** stays, and the verification reports the loss. */
    if (best < CF_LSQ_HUGE_OBJ && !z_stable(c, &pv, zb)) {
        double sb = CF_LSQ_HUGE_OBJ, zs[8] = {0};
        for (int tries = 0; tries < STABLE_RESTARTS; tries++) {
            int pick = -1;
            for (int i = 0; i < nends; i++)
                if (fends[i] < CF_LSQ_HUGE_OBJ && (pick < 0 || fends[i] < fends[pick]))
                    pick = i;
            if (pick < 0)
                break;
            fends[pick] = CF_LSQ_HUGE_OBJ; /* tried */
            if (!z_stable(c, &pv, ends[pick])) {
                tries--;
                continue;
            }
            /* from the stable point nearest the optimum on the segment to this end */
            double z[8], step[8], f = CF_LSQ_HUGE_OBJ, lo = 0, hi = 1;
            for (int b = 0; b < STABLE_BISECT_SEGMENT; b++) {
                const double mid = 0.5 * (lo + hi);
                for (int j = 0; j < pv.n; j++)
                    z[j] = zb[j] + mid * (ends[pick][j] - zb[j]);
                if (z_stable(c, &pv, z))
                    hi = mid;
                else
                    lo = mid;
            }
            for (int j = 0; j < pv.n; j++)
                z[j] = zb[j] + hi * (ends[pick][j] - zb[j]);
            for (int j = 0; j < pv.n; j++)
                step[j] = j == 1 || j == pv.ie + 1 ? 0.05 * (pv.ub[j] - pv.lb[j]) : 0.2;
            c->stab_on = 1;
            c->stab_best = CF_LSQ_HUGE_OBJ;
            nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv.n, pv.lb,
                                              pv.ub, step, XTOL_REL, STABLE_MAX_EVALS,
                                              pair_objective, (void *)&o, z, &f);
            if (c->pr.oom)
                return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's "
                                                        "optimiser (NLopt)");
            if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_MAXEVAL_REACHED) &&
                f < sb) {
                sb = f;
                memcpy(zs, z, sizeof zs);
            }
        }
        c->stab_on = sb < CF_LSQ_HUGE_OBJ;
        if (c->stab_on) {
            best = sb;
            memcpy(zb, zs, sizeof zb);
        }
    }
    /* a last polish from the best start */
    if (best < CF_LSQ_HUGE_OBJ) {
        double z[8], f = CF_LSQ_HUGE_OBJ, step[8];
        memcpy(z, zb, sizeof z);
        for (int j = 0; j < pv.n; j++)
            step[j] = j == 1 || j == pv.ie + 1 ? 0.01 * (pv.ub[j] - pv.lb[j]) : 0.05;
        c->stab_best = CF_LSQ_HUGE_OBJ;
        nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv.n, pv.lb, pv.ub,
                                          step, XTOL_REL * 1e-2, PAIR_MAX_EVALS, pair_objective,
                                          (void *)&o, z, &f);
        if ((res > 0 || res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_MAXEVAL_REACHED) &&
            f < best) {
            best = f;
            memcpy(zb, z, sizeof zb);
        }
    }
    double A = 0;
    c->stab_best = CF_LSQ_HUGE_OBJ;
    if (!(best < CF_LSQ_HUGE_OBJ) || !(pair_objective((unsigned)pv.n, zb, NULL, (void *)&o) <
                                       CF_LSQ_HUGE_OBJ))
        return cf_error_set(err, CF_E_NOCONV, "the joint fit found no %s that runs every table",
                            c->pair ? "double-acting element" : "lattice with a volume term");
    best = cf_cell_rss(&c->pr, exp(zb[0]), zb[1], &A);
    c->pr.A_fixed = 0;
    /* the quantities found */
    double v[PQ_COUNT] = {exp(zb[0]), zb[1], A, 0, 0, 0, 0};
    cf_law lc;
    const cf_ident qc = {.rho = v[PQ_RC], .solid = v[PQ_BC], .scale = 1.0};
    const cf_spring pc = cf_ident_member(&qc);
    if (cf_law_init(&lc, &pc, err) != CF_OK)
        return CF_E_INTERNAL;
    v[PQ_K] = A * curve_kappa(c, &lc);
    if (c->pair)
        v[PQ_RE] = c->ext[0], v[PQ_BE] = c->ext[1], v[PQ_AE] = A * c->ext[2];
    /* Levenberg-Marquardt from BOBYQA's optimum, the weights held */
    int used[PQ_COUNT] = {1, 1, 1, c->pair, c->pair, c->pair, opt->volume == CF_VOLUME_FIT};
    const double box[4] = {pv.lb[1], pv.ub[1], exp(pv.lb[0]), exp(pv.ub[0])};
    const int was_fw = c->fit_weights;
    c->fit_weights = 0;
    {
        double vp[PQ_COUNT];
        memcpy(vp, v, sizeof vp);
        const int stab = c->stab_on;
        c->stab_on = 0;
        double fp = pair_polish(c, vp, used, box);
        if (stab && fp < best) { /* the polish's point under the search's stability check */
            c->ext[0] = vp[PQ_RE], c->ext[1] = vp[PQ_BE], c->ext[2] = vp[PQ_AE] / vp[PQ_AC];
            if (opt->volume != CF_VOLUME_POISSON)
                c->kappa_mode = KAPPA_UNIT, c->kappa = vp[PQ_K] / vp[PQ_AC];
            if (!joint_stable_at(c, vp[PQ_RC], vp[PQ_BC]))
                fp = CF_LSQ_HUGE_OBJ;
        }
        if (fp < best) {
            memcpy(v, vp, sizeof vp);
            best = fp;
            A = v[PQ_AC];
            const cf_ident qp = {.rho = v[PQ_RC], .solid = v[PQ_BC], .scale = 1.0};
            const cf_spring pp = cf_ident_member(&qp);
            if (cf_law_init(&lc, &pp, err) != CF_OK)
                return CF_E_INTERNAL;
            if (opt->volume == CF_VOLUME_POISSON) {
                c->kappa_mode = KAPPA_NU;
                c->kappa = opt->volume_value;
                v[PQ_K] = A * curve_kappa(c, &lc);
            }
        }
    }
    r->objective = best;
    r->pair = c->pair;
    r->volume = opt->volume;
    r->volume_modulus_MPa = v[PQ_K];
    r->volume_modulus_se = -1;
    r->ident.rho = v[PQ_RC], r->ident.solid = v[PQ_BC], r->ident.scale = A;
    r->nparams = 3 + (c->pair ? 3 : 0) + (opt->volume == CF_VOLUME_FIT ? 1 : 0);
    cf_status st = cf_fit_place(reach, opt, c->type, &r->ident, &r->fit, err);
    if (st != CF_OK)
        return st;
    r->fit.ident = r->ident;
    if (c->pair) {
        cf_fit_options oe = *opt;
        oe.fixed[CF_P_H] = 1;
        oe.fixed_value[CF_P_H] = r->fit.params.H_mm;
        const cf_ident qe = {.rho = v[PQ_RE], .solid = v[PQ_BE], .scale = v[PQ_AE]};
        if ((st = cf_fit_place(reach, &oe, c->type, &qe, &r->ext, err)) != CF_OK)
            return st;
        r->ext.ident = qe;
        /* the element is buildable when both springs are: fit.feasible says it for the pair */
        r->fit.feasible = r->fit.feasible && r->ext.feasible;
    }
    /* the pair contains the single-sided law plain (two equal springs): a pair infeasible where
    ** plain is feasible is plain's optimum as two equal springs, what its search ended on kept
    ** in nested_objective and fit.nested_* (issue 37) */
    if (c->pair && plain && !plain->pair && plain->volume == CF_VOLUME_NONE &&
        opt->volume == CF_VOLUME_NONE && plain->fit.feasible && !r->fit.feasible) {
        const double lost = best, lost_rmse = r->fit.rmse;
        const unsigned lost_bits = r->fit.violated | r->ext.violated;
        double zq[8] = {log(plain->ident.rho), plain->ident.solid, 0};
        zq[pv.ie] = zq[0], zq[pv.ie + 1] = zq[1], zq[pv.ie + 2] = 0;
        if (pv.iq >= 0)
            zq[pv.iq] = log(plain->weight[1] / plain->weight[0]);
        pair_set(c, &pv, zq);
        best = cf_cell_rss(&c->pr, plain->ident.rho, plain->ident.solid, &A);
        const double vq[PQ_COUNT] = {plain->ident.rho, plain->ident.solid, A, plain->ident.rho,
                                     plain->ident.solid, A, 0};
        memcpy(v, vq, sizeof v);
        r->objective = best;
        r->ident.rho = v[PQ_RC], r->ident.solid = v[PQ_BC], r->ident.scale = A;
        if ((st = cf_fit_place(reach, opt, c->type, &r->ident, &r->fit, err)) != CF_OK)
            return st;
        r->fit.ident = r->ident;
        cf_fit_options oe = *opt;
        oe.fixed[CF_P_H] = 1;
        oe.fixed_value[CF_P_H] = r->fit.params.H_mm;
        if ((st = cf_fit_place(reach, &oe, c->type, &r->ident, &r->ext, err)) != CF_OK)
            return st;
        r->ext.ident = r->ident;
        r->fit.feasible = r->fit.feasible && r->ext.feasible;
        r->nested_objective = lost;
        r->fit.nested_rmse = lost_rmse;
        r->fit.nested_violated = lost_bits;
    }
    /* the small-strain moduli each side, from the cell of the quantities found: a bimodular
    ** lattice's uniaxial compression loads its axial springs' compression sides and its lateral
    ** springs' extension sides (and the reverse in tension), so neither side's E and nu is that
    ** of one spring's k0 alone */
    small_strain_moduli(c, v, r);
    /* the errors of every quantity fitted (the weights held) */
    double se[PQ_COUNT];
    if (pair_errors(c, v, used, best, se) < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the errors of %zu rows",
                            c->pr.n);
    c->fit_weights = was_fw;
    for (int k = 0; k < 3; k++) {
        r->fit.ident_se.v[k] = se[k];
        r->ext.ident_se.v[k] = c->pair ? se[PQ_RE + k] : -1;
        r->fit.interval_ok[k] = r->ext.interval_ok[k] = 0;
        for (int m = 0; m < 3; m++)
            r->fit.corr[k][m] = r->ext.corr[k][m] = NAN;
    }
    r->volume_modulus_se = opt->volume == CF_VOLUME_FIT ? se[PQ_K] : -1;
    return CF_OK;
}

/* A joint fit, stage after stage: check the tables, the springs' common reach, the search of the
** law (search_conical; search_tail when plain, the conical law's joint fit, is given), then each
** table in the lattice of the placed spring (verify_tables). Kept as one function because the
** stages share the tables' weights, the reach and the result being filled; each stage is marked
** below. */
static cf_status joint_run(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                           const cf_validate_setup *lat, cf_spring_type type,
                           const cf_joint_result *plain, int pair_mode, cf_joint_result *r,
                           cf_error *err)
{
    const double t0 = cf_clock_s();
    memset(r, 0, sizeof *r);
    if (n < 2 || n > CF_JOINT_MAX)
        return cf_error_set(err, CF_E_DATA, "a joint fit takes 2 to %d tables, not %zu",
                            CF_JOINT_MAX, n);
    for (size_t k = 0; k < n; k++)
        if (cf_table_is_force(tables[k]))
            return cf_error_set(err, CF_E_DATA,
                                "%s: a joint fit needs stress-strain tables; a force-displacement "
                                "table's lengths are its own, not strains one lattice shares",
                                tables[k]->path);
    jctx c;
    memset(&c, 0, sizeof c);
    c.t = tables;
    c.n = n;
    c.opt = opt;
    c.lat = lat;
    c.type = type;
    c.fit_weights = lat->cfg.lattice.calibration == CF_CAL_FITTED;
    memcpy(c.weight, plain ? plain->weight : lat->cfg.lattice.weight, sizeof c.weight);
    cf_status st = CF_OK;
    size_t total = 0;
    for (size_t k = 0; k < n; k++)
        total += tables[k]->count;
    double *reach_x = malloc(total * sizeof(double)), *reach_y = malloc(total * sizeof(double));
    double *all_sw = malloc(total * sizeof(double));
    c.pr = (cf_cell_problem){.curve = joint_curve, .ctx = &c, .n = total, .y = reach_y,
                             .sw = all_sw, .opt = opt, .type = type,
                             .g = malloc(total * sizeof(double))};
    if (!reach_x || !reach_y || !all_sw || !c.pr.g) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
        goto out;
    }
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        const cf_table *t = tables[k];
        c.sw[k] = malloc(t->count * sizeof(double));
        c.curve[k] = malloc(t->count * sizeof(double));
        r->tab[k].lattice_MPa = malloc(t->count * sizeof(double));
        if (!c.sw[k] || !c.curve[k] || !r->tab[k].lattice_MPa) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
            goto out;
        }
        double ss = 0;
        for (size_t i = 0; i < t->count; i++)
            ss += t->y[i] * t->y[i];
        double s = sqrt(ss / (double)t->count);
        if (!(s > 0)) {
            st = cf_error_set(err, CF_E_DATA, "%s: every stress is zero", t->path);
            goto out;
        }
        r->tab[k].scale_MPa = s;
        r->tab[k].mode = t->mode;
        r->tab[k].points = t->count;
        for (size_t i = 0; i < t->count; i++) {
            c.sw[k][i] = sqrt((t->w ? t->w[i] : 1.0) / (double)t->count) / s;
            all_sw[m] = c.sw[k][i];
            c.pr.ynorm += (all_sw[m] * t->y[i]) * (all_sw[m] * t->y[i]);
            reach_x[m] = copysign(cf_cell_spring_strain(t->mode, t->x[i]), t->x[i]);
            reach_y[m++] = t->y[i];
        }
    }
    r->ntables = n;
    /* the springs' reach over every table bounds s/H and is what the placement must honour */
    cf_table reach = *tables[0];
    reach.count = total;
    reach.x = reach_x;
    reach.y = reach_y;
    reach.w = NULL;
    reach.t = NULL;
    const double xmax = cf_lsq_xmax(&reach);
    /* the search and the placement */
    c.pair = pair_mode == 1;
    if (pair_mode >= 0) {
        memcpy(c.weight, lat->cfg.lattice.weight, sizeof c.weight);
        if (plain && !c.fit_weights)
            memcpy(c.weight, plain->weight, sizeof c.weight);
        st = search_pair(&c, &reach, xmax, plain, r, err);
    } else {
        st = plain ? search_tail(&c, &reach, xmax, plain, r, err)
                   : search_conical(&c, &reach, xmax, r, err);
    }
    if (st != CF_OK)
        goto out;
    memcpy(r->weight, c.weight, sizeof r->weight);
    r->calibration = lat->cfg.lattice.calibration;
    if (!r->nparams)
        r->nparams = r->fit.tail ? 4 : 3;
    r->aic = cf_baseline_aic(total, r->objective, r->nparams, 1.0);
    /* each table in the lattice of the placed spring */
    st = verify_tables(&c, r, err);
out:
    for (size_t k = 0; k < n && k < CF_JOINT_MAX; k++) {
        free(c.sw[k]);
        free(c.curve[k]);
    }
    free(reach_x);
    free(reach_y);
    free(all_sw);
    free(c.pr.g);
    r->evaluations = c.pr.evals;
    r->wall_time_s = cf_clock_s() - t0;
    if (st != CF_OK)
        cf_joint_free(r);
    return st;
}

cf_status cf_joint_fit(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                       const cf_validate_setup *lat, cf_spring_type type, cf_joint_result *r,
                       cf_error *err)
{
    CF_GSL_GUARD;
    return joint_run(tables, n, opt, lat, type, NULL, -1, r, err);
}

cf_status cf_joint_fit_pair(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, cf_spring_type type, int pair,
                            const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    CF_GSL_GUARD;
    if (opt->volume == CF_VOLUME_POISSON && pair)
        return cf_error_set(err, CF_E_DATA,
                            "--poisson %g: a double-acting element's lattice has one small-strain "
                            "nu in compression and another in tension; declare kappa "
                            "(--volume-modulus) or fit it (--volume fit)",
                            opt->volume_value);
    if (opt->volume == CF_VOLUME_POISSON) {
        const double *w = plain ? plain->weight : lat->cfg.lattice.weight;
        const double nu0 = cf_cubic_moduli_of(w).nu;
        if (!(opt->volume_value >= nu0 * (1 - 1e-12)) || !(opt->volume_value < 0.5))
            return cf_error_set(err, CF_E_DATA,
                                "--poisson %g: the lattice's springs alone give nu = %.4g along "
                                "an axis and the volume term only raises it (up to 0.5)",
                                opt->volume_value, nu0);
    }
    return joint_run(tables, n, opt, lat, type, plain, pair ? 1 : 0, r, err);
}

cf_status cf_joint_fit_tail(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, const cf_joint_result *plain,
                            cf_joint_result *r, cf_error *err)
{
    CF_GSL_GUARD;
    cf_status st = joint_run(tables, n, opt, lat, plain->fit.type, plain, -1, r, err);
    if (st == CF_E_INTERNAL || !(plain->objective >= 0) || !isfinite(plain->objective))
        return st;
    /* the tailed law contains the conical law (tail compliance 0): a search that finds nothing,
    ** ends infeasible where plain is feasible, or ends with a larger weighted objective at the
    ** same feasibility gives plain with no tail (cf_tail_nest for one table) */
    const int found = st == CF_OK;
    if (found && !(plain->fit.feasible && !r->fit.feasible) &&
        !(plain->fit.feasible == r->fit.feasible &&
          !(r->objective <= plain->objective * (1 + 1e-9))))
        return CF_OK;
    cf_joint_result nest = *plain;
    for (size_t k = 0; k < CF_JOINT_MAX; k++)
        nest.tab[k].lattice_MPa = NULL;
    for (size_t k = 0; k < plain->ntables; k++) {
        const size_t m = plain->tab[k].points;
        if (!plain->tab[k].lattice_MPa)
            continue;
        nest.tab[k].lattice_MPa = malloc(m * sizeof(double));
        if (!nest.tab[k].lattice_MPa) {
            cf_joint_free(&nest);
            if (found)
                cf_joint_free(r);
            return cf_error_set(err, CF_E_INTERNAL, "out of memory");
        }
        memcpy(nest.tab[k].lattice_MPa, plain->tab[k].lattice_MPa, m * sizeof(double));
    }
    cf_fit_result *f = &nest.fit;
    f->nested_rmse = found && isfinite(r->fit.rmse) ? r->fit.rmse : 0;
    f->nested_violated = found && !r->fit.feasible ? r->fit.violated : 0;
    nest.nested_objective = found && isfinite(r->objective) ? r->objective : 0;
    f->tail = 1;
    f->e_tail = 0;
    f->e_tail_se = 0;
    f->e_tail_interval_ok = 0;
    f->params.n_tail = 0;
    f->params.H_tail_mm = 0;
    /* the search's cost is the tailed fit's own */
    nest.evaluations = found ? r->evaluations : 0;
    nest.wall_time_s = found ? r->wall_time_s : 0;
    if (found)
        cf_joint_free(r);
    *r = nest;
    if (err)
        memset(err, 0, sizeof *err);
    return CF_OK;
}
