/*
** The joint fit's full-lattice stability (the lattices of 2^3 and 3^3 cells with a sliding bottom
** at the homogeneous state the cell gives) and each table's verification in the lattice of the
** placed spring (joint_ctx.h).
*/
#include <math.h>
#include <string.h>

#include "fit/baseline.h"
#include "model/cell.h"
#include "model/cell_stability.h"
#include "model/family.h"
#include "model/msm.h"
#include "fit/joint_ctx.h"
#include "fit/lsq.h"

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
int cf_joint_stable_at(const jctx *c, double rho, double B)
{
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = c->tail ? cf_ident_member_tail(&q, c->tau) : cf_ident_member(&q);
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
        cell.volume_modulus_MPa = cf_joint_curve_kappa(c, &law);
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
cf_status cf_joint_verify_tables(const jctx *c, cf_joint_result *r, cf_error *err)
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
        { /* stable over the table's whole range? (every law: the odd law's lattice can buckle
          ** at the cell's scale too) */
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
