/*
** The double-acting element's and the volume term's joint search through the cell (joint_ctx.h,
** cf_joint_fit_pair): BOBYQA from a grid of starts, kept to stable full lattices, polished by
** Levenberg-Marquardt; both springs placed, the errors of every quantity.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <nlopt.h>

#include "model/cell.h"
#include "model/family.h"
#include "fit/cell_problem.h"
#include "fit/joint_ctx.h"
#include "fit/lsq.h"
#include "fit/tail.h"
#include "fit/tail_cell.h"

/* BOBYQA's curves per start of the double-acting element's (or the volume term's) search */
#define PAIR_MAX_EVALS 1500
/* the pair's starts (at most), and the searches kept to stable lattices from their ends */
#define MAX_PAIR_STARTS 32
#define STABLE_RESTARTS 8
#define STABLE_SAME 1e-3
#define STABLE_BISECT_SEGMENT 12
#define STABLE_MAX_EVALS 500
/* projections to stability: the best distinct unstable ends (within PROJ_WORSE of the best
** objective, PROJ_SAME of the box apart) moved along each stabilising direction in steps of
** PROJ_STEP0 doubling up to PROJ_DOUBLINGS times, the first stable step bisected PROJ_BISECT
** times; the searches kept to stable lattices from the PROJ_RESTARTS best projected points */
#define PROJ_ENDS 3
#define PROJ_WORSE 2.0
#define PROJ_SAME 0.05
#define PROJ_STEP0 0.5
#define PROJ_DOUBLINGS 5
#define PROJ_BISECT 6
#define PROJ_RESTARTS 3
#define PROJ_ROUNDS 2
#define PROJ_DIRS 4
#define PROJ_MAX (PROJ_ENDS * PROJ_DIRS)
/* the last search's rounds (pair_last_search) */
#define LAST_ROUNDS 4
#define LAST_GAIN 1e-3
/* the tailed compression spring's tau (its tail's coils over the cone's) held through the starts
** and the searches kept to stable lattices (its range: joint_ctx.h) */
#define TAU_HELD 1.0

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
        cf_joint_weights_of(exp(z[pv->iq]), c->weight);
    if (pv->it >= 0)
        c->tau = exp(z[pv->it]);
}

/* 1 when the search's point z (pair_set) has both springs buildable and full lattices stable over
** the uniaxial tables. */
static int z_stable(jctx *c, const pvars *pv, const double *z)
{
    pair_set(c, pv, z);
    double A = 0;
    if (c->reach && !(cf_cell_rss(&c->pr, exp(z[0]), z[1], &A) < CF_LSQ_HUGE_OBJ))
        return 0;
    return cf_joint_pair_buildable(c, exp(z[0]), z[1], A) &&
           cf_joint_stable_at(c, exp(z[0]), z[1]);
}

typedef struct pair_obj {
    jctx *c;
    const pvars *pv;
} pair_obj;

/* The search's objective at z. Under the stability wall (c->stab_on) a point below the best stable
** objective so far (stab_best) counts only when its springs are buildable and its lattice stable;
** one that is not is reported mirrored above that best (2 stab_best - f): never lower than a
** point the search keeps, yet close to it near the wall, so BOBYQA's quadratic model stays of the
** objective's size (with a wall of 1e30 the searches stalled on it; src/notes/lattice-fit.md). */
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
        if (!cf_joint_pair_buildable(c, exp(z[0]), z[1], A) ||
            !cf_joint_stable_at(c, exp(z[0]), z[1]))
            return c->stab_best < CF_LSQ_HUGE_OBJ ? 2 * c->stab_best - f : CF_LSQ_HUGE_OBJ;
        c->stab_best = f;
    }
    return f;
}

typedef struct pair_search {
    pvars pv;
    pair_obj o;
    double best, zb[8];
    double ends[MAX_PAIR_STARTS][8], fends[MAX_PAIR_STARTS];
    int nends;
    int starts, stable_ends, restarts; /* what the search tried (cf_joint_result) */
    int projected;                     /* stable points found by projection (cf_joint_result) */
    /* the last search's starting point and each round's end (pair_last_search) */
    double hist[LAST_ROUNDS + 1][8], fhist[LAST_ROUNDS + 1];
    int nhist;
    int tried[MAX_PAIR_STARTS], ntried; /* the ends restarted from */
} pair_search;

/* 1 when end i lies within STABLE_SAME (in every search variable, relative to its box) of an end
** already restarted from. */
static int same_end(const pvars *pv, const pair_search *s, int i)
{
    for (int t = 0; t < s->ntried; t++) {
        int same = 1;
        for (int j = 0; j < pv->n && same; j++)
            same = fabs(s->ends[i][j] - s->ends[s->tried[t]][j]) <=
                   STABLE_SAME * (pv->ub[j] - pv->lb[j]);
        if (same)
            return 1;
    }
    return 0;
}

/* 1 when BOBYQA's end res is a point to keep (converged, or out of curves). */
static int search_ended(nlopt_result res)
{
    return res > 0 || res == NLOPT_ROUNDOFF_LIMITED || res == NLOPT_MAXEVAL_REACHED;
}

/* BOBYQA's initial steps: a twentieth of the solid strains' range (fine: a hundredth), 0.2 in the
** logarithms (fine: 0.05). */
static void pair_steps(const pvars *pv, int fine, double step[8])
{
    for (int j = 0; j < pv->n; j++)
        step[j] = j == 1 || j == pv->ie + 1 ? (fine ? 0.01 : 0.05) * (pv->ub[j] - pv->lb[j])
                  : j == pv->iq             ? cf_joint_q_step(pv->lb[j], pv->ub[j], fine)
                                            : (fine ? 0.05 : 0.2);
}

/* The tailed pair contains the conical pair plain (a tail of no coils): plain's optimum, its tail
** at the search's shortest, replaces the best point when it is lower (and, after a search kept
** to stable lattices, stable), so the last search starts from it. */
static void tail_nest_start(jctx *c, const cf_joint_result *plain, pair_search *s)
{
    const pvars *pv = &s->pv;
    if (!plain || !plain->pair || pv->it < 0 || pv->ie < 0)
        return;
    double z[8] = {0};
    z[0] = log(plain->ident.rho), z[1] = plain->ident.solid;
    z[pv->ie] = log(plain->ext.ident.rho), z[pv->ie + 1] = plain->ext.ident.solid;
    z[pv->ie + 2] = log(plain->ext.ident.scale / plain->ident.scale);
    if (pv->ik >= 0) {
        const double k = cf_joint_nest_kappa_rel(plain);
        z[pv->ik] = log(k > 0 ? k : 1e-5);
    }
    if (pv->iA >= 0)
        z[pv->iA] = log(plain->ident.scale);
    if (pv->iq >= 0)
        z[pv->iq] = log(plain->weight[1] / plain->weight[0]);
    z[pv->it] = log(TAU_LO);
    for (int j = 0; j < pv->n; j++)
        z[j] = isfinite(z[j]) ? fmin(fmax(z[j], pv->lb[j]), pv->ub[j]) : pv->lb[j];
    c->stab_best = CF_LSQ_HUGE_OBJ;
    const double f = pair_objective((unsigned)pv->n, z, NULL, (void *)&s->o);
    if (f < s->best) {
        s->best = f;
        memcpy(s->zb, z, sizeof s->zb);
    }
}

/* Step 2: BOBYQA from every start, the best end into s->best and s->zb and every end kept. The
** starts: the compression spring at plain's quantities (or the middle of the box) and on a coarse
** grid; the extension spring from a near-cylinder (linear) to a strong cone. The pair contains
** the single-sided law (two equal springs): with plain, its optimum is a start too (ge 3), so the
** pair never ends worse than the law it contains. */
static cf_status pair_starts(jctx *c, const cf_joint_result *plain, pair_search *s,
                             cf_error *err)
{
    const pvars *pv = &s->pv;
    const double rc0 = plain ? plain->ident.rho : 0.35;
    const double bc0 = plain ? plain->ident.solid : pv->lb[1] + 0.4 * (pv->ub[1] - pv->lb[1]);
    const double A0 = plain ? plain->ident.scale : 0;
    const double grid_rc[2] = {rc0, 0.1}, grid_re[3] = {0.9, 0.5, 0.15},
                 grid_be[2] = {0.25, 0.7}, grid_k[2] = {0.3, 3.0};
    /* the law this one contains: the single-sided law (two equal springs) for the pair, the
    ** conical pair for the tailed one; its optimum is a start, its kappa too when it has one */
    const int nest = plain && (c->tail ? plain->pair : !plain->pair);
    const int nre = c->pair ? (nest ? 4 : 3) : 1, nbe = c->pair ? 2 : 1,
              nk = pv->ik >= 0 ? 2 : 1;
    const double k_nest = nest && pv->ik >= 0 ? cf_joint_nest_kappa_rel(plain) : 0;
    s->best = CF_LSQ_HUGE_OBJ;
    memset(s->zb, 0, sizeof s->zb);
    s->nends = 0;
    s->starts = s->stable_ends = s->restarts = s->ntried = s->projected = 0;
    c->stab_on = 0;
    for (int gc = 0; gc < 2; gc++)
        for (int ge = 0; ge < nre; ge++)
            for (int gb = 0; gb < nbe; gb++)
                for (int gk = 0; gk < nk; gk++) {
                    double z[8];
                    if (ge == 3 && (gc != 0 || gb != 0 || (k_nest > 0 && gk != 0)))
                        continue;
                    z[0] = log(grid_rc[gc]);
                    z[1] = gc == 0 ? bc0 : pv->lb[1] + 0.3 * (pv->ub[1] - pv->lb[1]);
                    if (pv->ie >= 0 && ge == 3 && plain->pair) {
                        z[pv->ie] = log(plain->ext.ident.rho);
                        z[pv->ie + 1] = plain->ext.ident.solid;
                        z[pv->ie + 2] = log(plain->ext.ident.scale / plain->ident.scale);
                    } else if (pv->ie >= 0 && ge == 3) {
                        z[pv->ie] = z[0], z[pv->ie + 1] = z[1], z[pv->ie + 2] = 0;
                    } else if (pv->ie >= 0) {
                        z[pv->ie] = log(grid_re[ge]);
                        z[pv->ie + 1] = pv->lb[1] + grid_be[gb] * (pv->ub[1] - pv->lb[1]);
                        z[pv->ie + 2] = log(0.5);
                    }
                    if (pv->ik >= 0)
                        z[pv->ik] = log(ge == 3 && k_nest > 0 ? k_nest : grid_k[gk]);
                    if (pv->iA >= 0)
                        z[pv->iA] = log(A0 > 0 ? A0 : 1e-3);
                    if (pv->iq >= 0)
                        z[pv->iq] = log(plain ? plain->weight[1] / plain->weight[0]
                                              : 0.2708 / 0.6085);
                    double step[8];
                    for (int j = 0; j < pv->n; j++)
                        z[j] = fmin(fmax(z[j], pv->lb[j]), pv->ub[j]);
                    pair_steps(pv, 0, step);
                    double f = CF_LSQ_HUGE_OBJ;
                    if (ge == 3) {
                        /* BOBYQA may move a start near a bound before its first evaluation:
                        ** the contained law's optimum counts as it is */
                        const double f0 =
                            pair_objective((unsigned)pv->n, z, NULL, (void *)&s->o);
                        if (f0 < s->best) {
                            s->best = f0;
                            memcpy(s->zb, z, sizeof s->zb);
                        }
                    }
                    s->starts++;
                    nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv->n,
                                                      pv->lb, pv->ub, step, XTOL_REL,
                                                      PAIR_MAX_EVALS, pair_objective,
                                                      (void *)&s->o, z, &f);
                    if (c->pr.oom)
                        return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint "
                                                                "fit's optimiser (NLopt)");
                    const int ok = search_ended(res);
                    if (ok && f < CF_LSQ_HUGE_OBJ && s->nends < MAX_PAIR_STARTS) {
                        memcpy(s->ends[s->nends], z, sizeof z);
                        s->fends[s->nends++] = f;
                    }
                    if (ok && f < s->best) {
                        s->best = f;
                        memcpy(s->zb, z, sizeof s->zb);
                    }
                }
    return CF_OK;
}

/* z0 + t d, held inside the box, into z; 1 when it differs from prev (a step that ends on the
** box's bounds in every direction d moves does not). */
static int proj_point(const pvars *pv, const double *z0, const double *d, double t,
                      const double *prev, double z[8])
{
    int moved = 0;
    memset(z, 0, 8 * sizeof(double));
    for (int j = 0; j < pv->n; j++) {
        z[j] = fmin(fmax(z0[j] + t * d[j], pv->lb[j]), pv->ub[j]);
        moved |= z[j] != prev[j];
    }
    return moved;
}

/* The stable point nearest z0 (whose lattice fails the check) along direction d: steps of
** PROJ_STEP0 doubling until one passes the check, then bisected between it and the last that
** failed. 1 with that point in zp; 0 when no step inside the box passes. */
static int project_stable(jctx *c, const pvars *pv, const double *z0, const double *d,
                          double zp[8])
{
    double z[8], prev[8], lo = 0, hi = -1;
    memcpy(prev, z0, sizeof prev);
    for (int k = 0; k <= PROJ_DOUBLINGS && hi < 0; k++) {
        const double t = PROJ_STEP0 * (double)(1 << k);
        if (!proj_point(pv, z0, d, t, prev, z))
            break;
        memcpy(prev, z, sizeof prev);
        if (z_stable(c, pv, z))
            hi = t;
        else
            lo = t;
    }
    if (hi < 0)
        return 0;
    for (int b = 0; b < PROJ_BISECT; b++) {
        const double mid = 0.5 * (lo + hi);
        proj_point(pv, z0, d, mid, z0, z);
        if (z_stable(c, pv, z))
            hi = mid;
        else
            lo = mid;
    }
    proj_point(pv, z0, d, hi, z0, zp);
    return 1;
}

/* The next end to project: the lowest not yet looked at (seen), within PROJ_WORSE of the best
** objective and PROJ_SAME of the box away from every end already projected; -1 when none. */
static int next_proj_end(const pair_search *s, const double *fends, int *seen, const int *used,
                         int nused)
{
    const pvars *pv = &s->pv;
    for (;;) {
        int pick = -1;
        for (int i = 0; i < s->nends; i++)
            if (!seen[i] && fends[i] <= PROJ_WORSE * s->best &&
                (pick < 0 || fends[i] < fends[pick]))
                pick = i;
        if (pick < 0)
            return -1;
        seen[pick] = 1;
        int same = 0;
        for (int t = 0; t < nused && !same; t++) {
            same = 1;
            for (int j = 0; j < pv->n && same; j++)
                same = fabs(s->ends[pick][j] - s->ends[used[t]][j]) <=
                       PROJ_SAME * (pv->ub[j] - pv->lb[j]);
        }
        if (!same)
            return pick;
    }
}

/* BOBYQA kept to stable lattices (STABLE_MAX_EVALS curves) from z, its end into z and *f; 1 when
** it ended on a point to keep, 0 when not, -1 out of memory. */
static int stable_search(jctx *c, pair_search *s, double z[8], double *f)
{
    const pvars *pv = &s->pv;
    double step[8];
    pair_steps(pv, 0, step);
    c->stab_on = 1;
    c->stab_best = CF_LSQ_HUGE_OBJ;
    s->restarts++;
    *f = CF_LSQ_HUGE_OBJ;
    nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv->n, pv->lb, pv->ub,
                                      step, XTOL_REL, STABLE_MAX_EVALS, pair_objective,
                                      (void *)&s->o, z, f);
    return c->pr.oom ? -1 : search_ended(res);
}

/* One round of pair_project: the next PROJ_ENDS best distinct ends that fail the check (used,
** *nused the ends projected so far), each moved to stability along the directions dirs[nd];
** then the searches kept to stable lattices from the PROJ_RESTARTS lowest projected points, a
** lower end into *sb and zs. Returns the points projected (0: no end left), -1 out of memory. */
static int project_round(jctx *c, pair_search *s, const double *fends, double dirs[PROJ_DIRS][8],
                         int nd, int *seen, int *used, int *nused, double *sb, double zs[8])
{
    const pvars *pv = &s->pv;
    double cand[PROJ_MAX][8], fc[PROJ_MAX];
    int nc = 0;
    c->stab_on = 0;
    for (int k = 0; nd > 0 && k < PROJ_ENDS;) {
        const int i = next_proj_end(s, fends, seen, used, *nused);
        if (i < 0)
            break;
        if (z_stable(c, pv, s->ends[i]))
            continue; /* a stable end: the restarts from stable ends start from it */
        used[(*nused)++] = i, k++;
        for (int d = 0; d < nd; d++)
            if (project_stable(c, pv, s->ends[i], dirs[d], cand[nc])) {
                c->stab_on = 0;
                fc[nc] = pair_objective((unsigned)pv->n, cand[nc], NULL, (void *)&s->o);
                nc += fc[nc] < CF_LSQ_HUGE_OBJ;
            }
    }
    for (int r = 0, n = nc; r < PROJ_RESTARTS; r++) {
        int pick = -1;
        for (int k = 0; k < n; k++)
            if (fc[k] < CF_LSQ_HUGE_OBJ && (pick < 0 || fc[k] < fc[pick]))
                pick = k;
        if (pick < 0)
            break;
        fc[pick] = CF_LSQ_HUGE_OBJ;
        double f;
        const int ok = stable_search(c, s, cand[pick], &f);
        if (ok < 0)
            return -1;
        if (ok && f < *sb) {
            *sb = f;
            memcpy(zs, cand[pick], 8 * sizeof(double));
        }
    }
    return nc;
}

/* Step 3a: the best distinct ends of the starts whose lattices fail the check, each projected to
** stability along the directions that resist the lattice's node-scale modes (issue 42: a stiffer
** extension spring in compression, a smaller kappa in tension): the extension spring's stress
** scale up, kappa down, and both together; with fitted weights also the diagonals' weight up
** (a lattice whose diagonals the search has thinned resists shear and lateral modes with little
** else); then the searches kept to stable lattices from the
** lowest projected points, the best end into *sb and zs. In rounds of PROJ_ENDS ends: another
** round while the last one lowered the best end by more than LAST_GAIN, at most PROJ_ROUNDS.
** fends: the starts' ends' objectives. */
static cf_status pair_project(jctx *c, pair_search *s, const double *fends, double *sb,
                              double zs[8], cf_error *err)
{
    const pvars *pv = &s->pv;
    double dirs[PROJ_DIRS][8] = {{0}};
    int nd = 0, seen[MAX_PAIR_STARTS] = {0}, used[PROJ_ENDS * PROJ_ROUNDS], nused = 0;
    if (pv->ie >= 0)
        dirs[nd++][pv->ie + 2] = 1;
    if (pv->ik >= 0)
        dirs[nd++][pv->ik] = -1;
    if (pv->ie >= 0 && pv->ik >= 0)
        dirs[nd][pv->ie + 2] = 1, dirs[nd++][pv->ik] = -1;
    if (pv->iq >= 0) /* fitted weights: stiffer diagonals (the springs that resist shear) */
        dirs[nd++][pv->iq] = 1;
    for (int round = 0; round < PROJ_ROUNDS; round++) {
        const double before = *sb;
        const int nc = project_round(c, s, fends, dirs, nd, seen, used, &nused, sb, zs);
        if (nc < 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's "
                                                    "optimiser (NLopt)");
        s->projected += nc;
        if (nc == 0 || !(*sb < before * (1 - LAST_GAIN)))
            break;
    }
    return CF_OK;
}

/* Step 3: an optimum whose lattice fails the joint fit's stability check (the verification's,
** cf_joint_lattice_stable): the search again, kept to stable lattices, from the stable point
** nearest the optimum on the segment to each starts' end that is stable, best first (ends within
** STABLE_SAME of one already restarted from are the same end), at most STABLE_RESTARTS. None
** stable: the optimum stays, and the verification reports the loss. c->stab_on says afterwards
** whether the search kept to stable lattices. */
static cf_status pair_keep_stable(jctx *c, pair_search *s, cf_error *err)
{
    const pvars *pv = &s->pv;
    if (!(s->best < CF_LSQ_HUGE_OBJ))
        return CF_OK;
    if (z_stable(c, pv, s->zb)) { /* the later steps keep to stable lattices too */
        s->stable_ends = 1;
        c->stab_on = 1;
        return CF_OK;
    }
    double sb = CF_LSQ_HUGE_OBJ, zs[8] = {0}, fe[MAX_PAIR_STARTS], ftried[STABLE_RESTARTS];
    memcpy(fe, s->fends, sizeof fe);
    cf_status st = pair_project(c, s, fe, &sb, zs, err);
    if (st != CF_OK)
        return st;
    for (int tries = 0; tries < STABLE_RESTARTS; tries++) {
        int pick = -1;
        for (int i = 0; i < s->nends; i++)
            if (s->fends[i] < CF_LSQ_HUGE_OBJ && (pick < 0 || s->fends[i] < s->fends[pick]))
                pick = i;
        if (pick < 0)
            break;
        s->fends[pick] = CF_LSQ_HUGE_OBJ; /* tried */
        if (!z_stable(c, pv, s->ends[pick]) || same_end(pv, s, pick)) {
            tries--;
            continue;
        }
        s->stable_ends++;
        /* an end at the objective of one already restarted from (to 1e-6) is its basin again */
        int twin = 0;
        for (int t = 0; t < s->ntried && !twin; t++)
            twin = fabs(fe[pick] - ftried[t]) <= 1e-6 * ftried[t];
        if (twin) {
            tries--;
            continue;
        }
        ftried[s->ntried] = fe[pick];
        s->tried[s->ntried++] = pick;
        /* from the stable point nearest the optimum on the segment to this end */
        double z[8], f, lo = 0, hi = 1;
        for (int b = 0; b < STABLE_BISECT_SEGMENT; b++) {
            const double mid = 0.5 * (lo + hi);
            for (int j = 0; j < pv->n; j++)
                z[j] = s->zb[j] + mid * (s->ends[pick][j] - s->zb[j]);
            if (z_stable(c, pv, z))
                hi = mid;
            else
                lo = mid;
        }
        for (int j = 0; j < pv->n; j++)
            z[j] = s->zb[j] + hi * (s->ends[pick][j] - s->zb[j]);
        const int ok = stable_search(c, s, z, &f);
        if (ok < 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory in the joint fit's "
                                                    "optimiser (NLopt)");
        if (ok && f < sb) {
            sb = f;
            memcpy(zs, z, sizeof zs);
        }
    }
    c->stab_on = sb < CF_LSQ_HUGE_OBJ;
    if (c->stab_on) {
        s->best = sb;
        memcpy(s->zb, zs, sizeof s->zb);
    }
    return CF_OK;
}

/* Step 4: a last, finer BOBYQA from the best point (under the stability check when step 3 kept
** to stable lattices), started again from its end while a round lowers the objective by more than
** LAST_GAIN (under the stability check BOBYQA's model stalls on the wall of unstable points it
** cannot see; a fresh start rebuilds it), at most LAST_ROUNDS rounds, the coarse steps and the
** fine ones in turn. */
static void pair_last_search(jctx *c, pair_search *s)
{
    const pvars *pv = &s->pv;
    memcpy(s->hist[0], s->zb, sizeof s->hist[0]);
    s->fhist[0] = s->best;
    s->nhist = 1;
    for (int round = 0; round < LAST_ROUNDS && s->best < CF_LSQ_HUGE_OBJ; round++) {
        double z[8], f = CF_LSQ_HUGE_OBJ, step[8];
        memcpy(z, s->zb, sizeof z);
        pair_steps(pv, round % 2 == 0, step);
        c->stab_best = CF_LSQ_HUGE_OBJ;
        nlopt_result res = cf_cell_search(&c->pr, NLOPT_LN_BOBYQA, (unsigned)pv->n, pv->lb,
                                          pv->ub, step, XTOL_REL * 1e-2,
                                          round == 0 ? PAIR_MAX_EVALS : STABLE_MAX_EVALS,
                                          pair_objective, (void *)&s->o, z, &f);
        if (!search_ended(res) || !(f < s->best))
            return;
        const int gain = f < s->best * (1 - LAST_GAIN);
        s->best = f;
        memcpy(s->zb, z, sizeof s->zb);
        memcpy(s->hist[s->nhist], z, sizeof s->hist[0]);
        s->fhist[s->nhist++] = f;
        if (!gain || !c->stab_on)
            return;
    }
}

/* Step 5: the quantities of the search's best point into v (*A the compression stress scale),
** then Levenberg-Marquardt from them over the used quantities, the weights held, its point kept
** when lower (and, after a search kept to stable lattices, stable and buildable). Returns the
** RSS of v, CF_LSQ_HUGE_OBJ when the best point runs no table. */
static double pair_quantities(jctx *c, pair_search *s, const int used[PQ_COUNT],
                              double v[PQ_COUNT], double *A, cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    const pvars *pv = &s->pv;
    c->stab_best = CF_LSQ_HUGE_OBJ;
    if (!(s->best < CF_LSQ_HUGE_OBJ) ||
        !(pair_objective((unsigned)pv->n, s->zb, NULL, (void *)&s->o) < CF_LSQ_HUGE_OBJ)) {
        cf_error_set(err, CF_E_NOCONV, "the joint fit found no %s that runs every table",
                     c->pair ? "double-acting element" : "lattice with a volume term");
        return CF_LSQ_HUGE_OBJ;
    }
    double best = cf_cell_rss(&c->pr, exp(s->zb[0]), s->zb[1], A);
    c->pr.A_fixed = 0;
    memset(v, 0, sizeof(double) * PQ_COUNT);
    v[PQ_RC] = exp(s->zb[0]), v[PQ_BC] = s->zb[1], v[PQ_AC] = *A;
    if (c->tail)
        v[PQ_T] = c->tau;
    cf_law lc;
    const cf_spring pc = cf_joint_compression_member(c, v);
    if (cf_law_init(&lc, &pc, err) != CF_OK)
        return -1;
    v[PQ_K] = *A * cf_joint_curve_kappa(c, &lc);
    if (c->pair)
        v[PQ_RE] = c->ext[0], v[PQ_BE] = c->ext[1], v[PQ_AE] = *A * c->ext[2];
    const double box[4] = {pv->lb[1], pv->ub[1], exp(pv->lb[0]), exp(pv->ub[0])};
    double vp[PQ_COUNT];
    memcpy(vp, v, sizeof vp);
    const int stab = c->stab_on;
    c->stab_on = 0;
    double fp = cf_joint_pair_polish(c, vp, used, box);
    if (stab && fp < best) { /* the polish's point under the search's stability check */
        c->ext[0] = vp[PQ_RE], c->ext[1] = vp[PQ_BE], c->ext[2] = vp[PQ_AE] / vp[PQ_AC];
        if (c->tail)
            c->tau = vp[PQ_T];
        if (opt->volume != CF_VOLUME_POISSON)
            c->kappa_mode = KAPPA_UNIT, c->kappa = vp[PQ_K] / vp[PQ_AC];
        if (!cf_joint_pair_buildable(c, vp[PQ_RC], vp[PQ_BC], vp[PQ_AC]) ||
            !cf_joint_stable_at(c, vp[PQ_RC], vp[PQ_BC]))
            fp = CF_LSQ_HUGE_OBJ;
    }
    if (fp < best) {
        memcpy(v, vp, sizeof vp);
        best = fp;
        *A = v[PQ_AC];
        const cf_spring pp = cf_joint_compression_member(c, v);
        if (cf_law_init(&lc, &pp, err) != CF_OK)
            return -1;
        if (opt->volume == CF_VOLUME_POISSON) {
            c->kappa_mode = KAPPA_NU;
            c->kappa = opt->volume_value;
            v[PQ_K] = *A * cf_joint_curve_kappa(c, &lc);
        }
    }
    return best;
}

/* Steps 5 and 6 from the last search's latest point back (s->hist): the point's quantities
** polished into v and both springs placed into r. A search kept to stable lattices keeps to
** buildable springs too (cf_joint_pair_buildable); one that is not (no stable point found) can
** walk past them: a point whose springs are not both buildable gives way to the one the round
** before ended on; when none is buildable, the latest is kept. Returns the RSS of v as
** pair_quantities does (-1 on an error, *st then set). */
static double pair_finish(jctx *c, const cf_table *reach, pair_search *s,
                          const int used[PQ_COUNT], double v[PQ_COUNT], double *A,
                          cf_joint_result *r, cf_status *st, cf_error *err)
{
    const int mode = c->kappa_mode, stab = c->stab_on;
    const double kappa = c->kappa;
    double best = CF_LSQ_HUGE_OBJ;
    for (int h = s->nhist - 1, last = 0, tries = 0; h >= 0 && !last; h--, tries++) {
        last = h == 0;
        if (tries > 0) { /* the context as the search left it */
            c->kappa_mode = mode, c->stab_on = stab, c->kappa = kappa;
            c->pr.A_fixed = 0;
        }
        memcpy(s->zb, s->hist[h], sizeof s->zb);
        s->best = s->fhist[h];
        best = pair_quantities(c, s, used, v, A, err);
        if (best < 0 || !(best < CF_LSQ_HUGE_OBJ)) {
            *st = best < 0 ? CF_E_INTERNAL : CF_E_NOCONV;
            return -1;
        }
        if ((*st = cf_joint_pair_place(c, reach, v, r, err)) != CF_OK)
            return -1;
        if (r->fit.feasible)
            return best;
        if (last && s->nhist > 1) { /* none buildable: the latest again */
            const int k = s->nhist - 1;
            memcpy(s->hist[0], s->hist[k], sizeof s->hist[0]);
            s->fhist[0] = s->fhist[k];
            h = 1, last = 0, s->nhist = 1;
        }
    }
    return best;
}

/* Step 7: the pair contains the single-sided law plain (two equal springs): a pair infeasible
** where plain is feasible is plain's optimum as two equal springs, what its search ended on kept
** in nested_objective and fit.nested_* (issue 37). v and *best follow. */
static cf_status pair_nest(jctx *c, const cf_table *reach, const cf_joint_result *plain,
                           pair_search *s, double v[PQ_COUNT], double *best, cf_joint_result *r,
                           cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    const pvars *pv = &s->pv;
    if (!(c->pair && !c->tail && plain && !plain->pair && plain->volume == CF_VOLUME_NONE &&
          opt->volume == CF_VOLUME_NONE && plain->fit.feasible && !r->fit.feasible))
        return CF_OK;
    const double lost = *best, lost_rmse = r->fit.rmse;
    const unsigned lost_bits = r->fit.violated | r->ext.violated;
    double zq[8] = {log(plain->ident.rho), plain->ident.solid, 0}, A = 0;
    zq[pv->ie] = zq[0], zq[pv->ie + 1] = zq[1], zq[pv->ie + 2] = 0;
    if (pv->iq >= 0)
        zq[pv->iq] = log(plain->weight[1] / plain->weight[0]);
    pair_set(c, pv, zq);
    *best = cf_cell_rss(&c->pr, plain->ident.rho, plain->ident.solid, &A);
    const double vq[PQ_COUNT] = {plain->ident.rho, plain->ident.solid, A, plain->ident.rho,
                                 plain->ident.solid, A, 0};
    memcpy(v, vq, sizeof vq);
    r->objective = *best;
    r->ident.rho = v[PQ_RC], r->ident.solid = v[PQ_BC], r->ident.scale = A;
    cf_status st = cf_fit_place(reach, opt, c->type, &r->ident, &r->fit, err);
    if (st != CF_OK)
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
    return CF_OK;
}

/* The double-acting element's (and the volume term's) search from plain's quantities and a grid,
** every table through the cell, step after step; both springs placed; the errors of every
** quantity. */
cf_status cf_joint_search_pair(jctx *c, const cf_table *reach, double xmax,
                               const cf_joint_result *plain, cf_joint_result *r, cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    pair_search s;
    cf_status st = cf_joint_pair_box(c, xmax, &s.pv, err);
    if (st != CF_OK)
        return st;
    /* a tailed compression spring: the starts and the searches kept to stable lattices hold tau
    ** at TAU_HELD (the last variable), the last search frees it. With tau free from the start every
    ** end drifts to long tails whose lattices buckle, and the searches kept to stable lattices
    ** then end far above (brain cortex: 0.0183 against 0.0125 with tau held) */
    const pvars full = s.pv;
    if (c->tail) {
        s.pv.n--;
        s.pv.it = -1;
        c->tau = TAU_HELD;
    }
    s.o = (pair_obj){c, &s.pv};
    c->reach = reach;
    if ((st = pair_starts(c, plain, &s, err)) != CF_OK ||
        (st = pair_keep_stable(c, &s, err)) != CF_OK)
        return st;
    if (c->tail) {
        s.pv = full;
        s.zb[full.it] = log(TAU_HELD);
        tail_nest_start(c, plain, &s);
    }
    pair_last_search(c, &s);
    /* the quantities found, polished with the weights held */
    const int used[PQ_COUNT] = {1,       1,       1, c->pair, c->pair, c->pair,
                                opt->volume == CF_VOLUME_FIT, c->tail};
    double v[PQ_COUNT], A = 0;
    const int was_fw = c->fit_weights;
    c->fit_weights = 0;
    double best = pair_finish(c, reach, &s, used, v, &A, r, &st, err);
    if (best < 0)
        return st;
    r->objective = best;
    r->starts = s.starts, r->stable_ends = s.stable_ends, r->restarts = s.restarts;
    r->projected = s.projected;
    r->pair = c->pair;
    r->volume = opt->volume;
    r->volume_modulus_MPa = v[PQ_K];
    r->volume_modulus_se = -1;
    r->nparams = 3 + (c->pair ? 3 : 0) + (opt->volume == CF_VOLUME_FIT ? 1 : 0) + c->tail;
    if ((st = pair_nest(c, reach, plain, &s, v, &best, r, err)) != CF_OK)
        return st;
    /* the small-strain moduli each side, from the cell of the quantities found: a bimodular
    ** lattice's uniaxial compression loads its axial springs' compression sides and its lateral
    ** springs' extension sides (and the reverse in tension), so neither side's E and nu is that
    ** of one spring's k0 alone */
    cf_joint_small_strain_moduli(c, v, r);
    /* the errors of every quantity fitted (the weights held) */
    double se[PQ_COUNT], cov_bt;
    if (cf_joint_pair_errors(c, v, used, best, se, &cov_bt) < 0)
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
    if (c->tail) { /* e_t = tau B: var = B^2 var(tau) + tau^2 var(B) + 2 tau B cov(B, tau) */
        const double B = v[PQ_BC], tau = v[PQ_T];
        const double var = B * B * se[PQ_T] * se[PQ_T] + tau * tau * se[PQ_BC] * se[PQ_BC] +
                           2 * tau * B * cov_bt;
        r->fit.q_se[CF_Q_TAIL] = isfinite(cov_bt) ? (var > 0 ? sqrt(var) : 0) : -1;
        r->fit.interval_ok[CF_Q_TAIL] = 0;
    }
    return CF_OK;
}
