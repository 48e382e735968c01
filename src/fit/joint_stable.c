/*
** The joint fit's full-lattice stability (the lattices of 2^3 and 3^3 cells with a sliding bottom
** at the homogeneous state the cell gives) and each table's verification in the lattice of the
** placed spring (joint_ctx.h).
*/
#include <math.h>
#include <string.h>

#include "fit/baseline.h"
#include "model/cell.h"
#include "model/cell_elliptic.h"
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

/* The one stability check of a joint fit, which the search applies to every point it would keep
** and the verification to the placed springs (so a point the search keeps passes the final check,
** and no other does): for each table, the cell's incremental stiffness positive definite and, for
** a uniaxial table, the full lattices of 2^3 and 3^3 cells with a sliding bottom free of negative
** pivots, at CHECK_STEPS strains evenly from 0 to CF_JOINT_STABLE_MARGIN times the table's
** farthest strain. The farthest strain is checked first (where a lattice fitted at the edge of
** stability buckles first, so the check fails fast). 1 stable, 0 not, -1 out of memory. */
#define CHECK_STEPS 8

/* The table's farthest strain (table sign), 0 for an empty table. */
static double table_reach(const cf_table *t)
{
    double reach = 0;
    for (size_t i = 0; i < t->count; i++)
        if (fabs(t->x[i]) > fabs(reach))
            reach = t->x[i];
    return reach;
}

/* The cell for scanning table t along its mode: a biaxial table's path with its larger strain
** along x (k <= 1), so the scan to the table's farthest strain covers both directions' rows (the
** cubic cell is the same along x and y); the cell itself for every other table. */
static cf_cell scan_cell(const cf_cell *cell, const cf_table *t)
{
    cf_cell c = *cell;
    const double k = cf_table_biaxial_k(t, 0);
    c.biaxial_k = k <= 1 ? k : 1 / k;
    return c;
}

/* The uniaxial states of table t at the check's strains e (the farthest first) and their lateral
** stretches lat; 0 when one cannot be reached. */
static int check_states(const cf_cell *cell, const cf_table *t, double e[CHECK_STEPS],
                        double lat[CHECK_STEPS], double F[CHECK_STEPS][9])
{
    const double reach = table_reach(t) * CF_JOINT_STABLE_MARGIN;
    const cf_cell scan = scan_cell(cell, t);
    for (int j = 0; j < CHECK_STEPS; j++) {
        cf_cell_state st;
        e[j] = reach * (CHECK_STEPS - j) / CHECK_STEPS;
        if (cf_cell_mode(&scan, t->mode, e[j], NULL, &st, NULL) != CF_OK)
            return 0;
        lat[j] = st.F[0];
        memcpy(F[j], st.F, sizeof F[j]);
    }
    return 1;
}

/* The cell's part of the check for table t (check_states' F): its incremental stiffness positive
** definite at every strain. 1 stable, 0 not, -1 out of memory. */
static int cell_part(const cf_cell *cell, double F[CHECK_STEPS][9])
{
    for (int j = 0; j < CHECK_STEPS; j++) {
        double lambda = 0;
        cf_status s = cf_cell_min_stiffness(cell, F[j], &lambda, NULL);
        if (s == CF_E_INTERNAL)
            return -1;
        if (s != CF_OK || !(lambda > 0))
            return 0;
    }
    return 1;
}

/* The lattice of n^3 cells (bottom sliding) at the count homogeneous states (e, lat): free of
** negative pivots at every one. One lattice and one tangent pattern serve all the uniaxial tables'
** strains (cf_msm_homogeneous_inertias stops at the first state with a negative pivot). 1 stable,
** 0 not, -1 out of memory. */
static int lattice_part(const cf_cell *cell, const cf_msm_config *cfg, int n, const double *e,
                        const double *lat, size_t count)
{
    if (count == 0)
        return 1;
    cf_msm_config k = *cfg;
    k.lattice.nx = k.lattice.ny = k.lattice.nz = n;
    k.lattice.bottom = CF_BOTTOM_AXIAL;
    long neg = -1;
    cf_status s = cf_msm_homogeneous_inertias(cell->law, CF_LAW_CLOSED, &k, e, lat, count, &neg,
                                              NULL);
    if (s == CF_E_INTERNAL)
        return -1;
    return s == CF_OK && neg == 0;
}

/* The check on the n tables, part after part over all of them (the 2^3 lattice, the most slender
** and the first to buckle, then the cell, then the 3^3 lattice), so a point that fails usually
** fails at the first part; the verdict is the same in any order. Each lattice part takes the
** uniaxial tables' strains in table order, each table's farthest first. */
static int tables_stable(const cf_cell *cell, const cf_msm_config *cfg, const cf_table *const *t,
                         size_t n)
{
    double e[CF_JOINT_MAX][CHECK_STEPS], lat[CF_JOINT_MAX][CHECK_STEPS];
    double F[CF_JOINT_MAX][CHECK_STEPS][9];
    double ue[CF_JOINT_MAX * CHECK_STEPS] = {0}, ulat[CF_JOINT_MAX * CHECK_STEPS] = {0};
    size_t nu = 0;
    for (size_t k = 0; k < n && k < CF_JOINT_MAX; k++) {
        if (table_reach(t[k]) == 0)
            continue;
        if (!check_states(cell, t[k], e[k], lat[k], F[k]))
            return 0;
        if (t[k]->mode != CF_MODE_UNIAXIAL)
            continue;
        memcpy(ue + nu, e[k], sizeof e[k]);
        memcpy(ulat + nu, lat[k], sizeof lat[k]);
        nu += CHECK_STEPS;
    }
    int r = lattice_part(cell, cfg, 2, ue, ulat, nu);
    for (size_t k = 0; r == 1 && k < n && k < CF_JOINT_MAX; k++)
        if (table_reach(t[k]) != 0)
            r = cell_part(cell, F[k]);
    return r == 1 ? lattice_part(cell, cfg, 3, ue, ulat, nu) : r;
}

static int table_stable(const cf_cell *cell, const cf_msm_config *cfg, const cf_table *t)
{
    return tables_stable(cell, cfg, &t, 1);
}

int cf_joint_lattice_stable(const cf_law *law, const double weight[CF_FAMILY_COUNT],
                            double kappa_MPa, const cf_validate_setup *lat,
                            const cf_table *const *t, size_t n)
{
    cf_cell cell;
    if (cf_cell_init(&cell, law, CF_LAW_CLOSED, weight, NULL) != CF_OK)
        return 0;
    cell.volume_modulus_MPa = kappa_MPa;
    cf_msm_config cfg = lat->cfg;
    memcpy(cfg.lattice.weight, weight, sizeof cfg.lattice.weight);
    cfg.lattice.volume_modulus_MPa = kappa_MPa;
    return tables_stable(&cell, &cfg, t, n);
}

/* 1 when the lattice of the curve's law at (rho, B) (the context's extension spring and kappa, at
** unit stress scale: every force scales alike, so stability does not depend on the scale) passes
** the joint fit's stability check (cf_joint_lattice_stable) on every table. */
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
    const double kappa = c->kappa_mode != KAPPA_NONE ? cf_joint_curve_kappa(c, &law) : 0.0;
    return cf_joint_lattice_stable(&law, c->weight, kappa, c->lat, c->t, c->n) == 1;
}

/* Table t's stability verdict for the lattice of cell (cfg its full lattice) into jt: the joint
** fit's one check (table_stable, the search's) says whether it is stable to the margin; where it
** is not, the scans (the cell's, cf_cell_stable_to, and the full lattices', lattice_stable_to)
** say from which strain on, and whether the lattice is unstable at rest already (the first strain
** of the check, a CHECK_STEPS-th of the range, is then unstable too, and the scans end at 0). */
static cf_status table_verdict(const cf_cell *cell, const cf_msm_config *cfg, const cf_table *t,
                               cf_joint_table *jt, cf_error *err)
{
    const double reach = table_reach(t) * CF_JOINT_STABLE_MARGIN;
    if (reach == 0)
        return CF_OK;
    const int r = table_stable(cell, cfg, t);
    if (r < 0)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the lattice's stability check");
    jt->stability_checked = 1;
    jt->lattice_checked = t->mode == CF_MODE_UNIAXIAL;
    jt->stable_in_range = r;
    jt->stable_to = reach;
    if (r)
        return CF_OK;
    double limit = reach;
    int lost = 0;
    const cf_cell scan = scan_cell(cell, t);
    if (cf_cell_stable_to(&scan, t->mode, reach, &limit, &lost, NULL) == CF_OK && lost)
        jt->stable_to = limit;
    if (t->mode == CF_MODE_UNIAXIAL) {
        double llim = reach;
        int llost = 0;
        cf_status st = lattice_stable_to(cell, cfg, reach, &llim, &llost, err);
        if (st != CF_OK)
            return st;
        if (llost && fabs(llim) < fabs(jt->stable_to))
            jt->stable_to = llim;
    }
    jt->unstable_at_rest = fabs(jt->stable_to) < 1e-3 * fabs(reach);
    return CF_OK;
}

/* Table t's strong-ellipticity verdict for the homogenised cell into jt (cf_cell_elliptic_to over
** the stability check's range, CF_JOINT_STABLE_MARGIN x the farthest strain). */
static void table_elliptic(const cf_cell *cell, const cf_table *t, cf_joint_table *jt)
{
    const double reach = table_reach(t) * CF_JOINT_STABLE_MARGIN;
    if (reach == 0)
        return;
    double limit = reach;
    int lost = 0;
    const cf_cell scan = scan_cell(cell, t);
    if (cf_cell_elliptic_to(&scan, t->mode, reach, &limit, &lost, jt->elliptic_n, NULL) != CF_OK)
        return;
    jt->elliptic_checked = 1;
    jt->elliptic_in_range = !lost;
    jt->elliptic_to = limit;
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
        if ((st = cf_table_cell_curve(&cell, t, c->curve[k], err)) != CF_OK)
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
        if ((st = table_verdict(&cell, &full.cfg, t, jt, err)) != CF_OK)
            break;
        table_elliptic(&cell, t, jt);
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
