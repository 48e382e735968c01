/*
** The double-acting element's quantities as a least-squares problem (joint_ctx.h): the pair's cap
** on the compression stress scale, its residuals, the Levenberg-Marquardt polish of the search's
** optimum, the errors of every quantity, and the lattice's small-strain moduli in tension and in
** compression; both springs placed. Below the search (joint_pair.c), which calls it.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_permutation.h>

#include "model/cell.h"
#include "model/family.h"
#include "fit/cell_problem.h"
#include "fit/joint_ctx.h"
#include "fit/lsq.h"
#include "fit/tail.h"
#include "fit/tail.h"
#include "fit/tail_cell.h"

/* The largest compression stress scale at (rho, B) with the extension spring of the context: the
** smaller of what a spring of the type (with the context's tail tau, when it has one) carries
** there and what the extension spring carries over its share; 0 where either cannot be placed. */
double cf_joint_pair_A_max(void *ctx, double rho, double B)
{
    const jctx *c = ctx;
    double Ac, Ae = INFINITY;
    if (c->tail) {
        if (!((Ac = cf_tail_cell_A_max(rho, B, c->tau, c->need, c->type, c->opt)) > 0))
            return 0;
    } else if (cf_fit_ident_limit(c->opt, c->type, rho, B, &Ac, NULL) > 0)
        return 0;
    if (c->pair) {
        if (cf_fit_ident_limit(c->opt, c->type, c->ext[0], c->ext[1], &Ae, NULL) > 0)
            return 0;
        Ae /= c->ext[2];
    }
    return fmin(Ac, Ae);
}


/* The compression spring of the quantities v at stress scale 1 (tailed when the context is). */
cf_spring cf_joint_compression_member(const jctx *c, const double v[PQ_COUNT])
{
    const cf_ident q = {.rho = v[PQ_RC], .solid = v[PQ_BC], .scale = 1.0};
    return c->tail ? cf_ident_member_tail(&q, v[PQ_T]) : cf_ident_member(&q);
}

static int pair_residuals(jctx *c, const double v[PQ_COUNT], double *g, double *res)
{
    c->ext[0] = v[PQ_RE], c->ext[1] = v[PQ_BE], c->ext[2] = v[PQ_AE] / v[PQ_AC];
    if (c->tail)
        c->tau = v[PQ_T];
    if (c->opt->volume == CF_VOLUME_POISSON) { /* kappa follows the springs */
        c->kappa_mode = KAPPA_NU;
        c->kappa = c->opt->volume_value;
    } else {
        c->kappa_mode = KAPPA_UNIT;
        c->kappa = v[PQ_K] / v[PQ_AC];
    }
    if (cf_joint_curve(c, v[PQ_RC], v[PQ_BC], g) != 0)
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
    if (!(v[PQ_AC] <= cf_joint_pair_A_max(c, v[PQ_RC], v[PQ_BC]) * (1 + 1e-12)))
        return CF_LSQ_HUGE_OBJ;
    if (c->kappa_rel_max > 0) { /* a fitted kappa within its bound (CF_JOINT_NU_MAX) */
        const cf_spring pc = cf_joint_compression_member(c, v);
        cf_law lc;
        if (cf_law_init(&lc, &pc, NULL) != CF_OK ||
            !(v[PQ_K] <= c->kappa_rel_max * v[PQ_AC] * lc.k0_N_per_mm / lc.p.H_mm * (1 + 1e-9)))
            return CF_LSQ_HUGE_OBJ;
    }
    double ss = 0;
    for (size_t i = 0; i < c->pr.n; i++)
        ss += res[i] * res[i];
    return isfinite(ss) ? ss : CF_LSQ_HUGE_OBJ;
}

/* The central-difference Jacobian of the weighted residuals at v over the p quantities idx into
** J (n x p, row-major; g, rp, rm scratch of n); 1 where a curve fails. */
static int pair_jacobian(jctx *c, const double v[PQ_COUNT], const int *idx, int p, double *g,
                         double *rp, double *rm, double *J)
{
    const size_t n = c->pr.n;
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
    return bad;
}

/* The Levenberg-Marquardt step: (A + lambda diag A) delta = b for the p x p normal equations A
** (a zero diagonal entry damped by lambda), by GSL's LU decomposition with partial pivoting. 1
** when the system is singular. */
static int lm_step(double A[PQ_COUNT][PQ_COUNT], const double b[PQ_COUNT], int p,
                   double lambda, double delta[PQ_COUNT])
{
    double M[PQ_COUNT * PQ_COUNT], rhs[PQ_COUNT];
    size_t perm_data[PQ_COUNT];
    for (int a = 0; a < p; a++) {
        for (int bb = 0; bb < p; bb++)
            M[a * p + bb] = A[a][bb] + (a == bb ? lambda * (A[a][a] > 0 ? A[a][a] : 1) : 0);
        rhs[a] = b[a];
    }
    gsl_matrix_view m = gsl_matrix_view_array(M, (size_t)p, (size_t)p);
    gsl_vector_view bv = gsl_vector_view_array(rhs, (size_t)p);
    gsl_vector_view x = gsl_vector_view_array(delta, (size_t)p);
    gsl_permutation perm = {(size_t)p, perm_data};
    int signum;
    if (gsl_linalg_LU_decomp(&m.matrix, &perm, &signum) != GSL_SUCCESS)
        return 1;
    for (int a = 0; a < p; a++) /* a zero pivot: singular (GSL would divide by it) */
        if (!(fabs(M[a * p + a]) > 0))
            return 1;
    return gsl_linalg_LU_solve(&m.matrix, &perm, &bv.vector, &x.vector) != GSL_SUCCESS;
}

/* Levenberg-Marquardt from v over the used quantities (logarithms of the scales and kappa, the
** strains as they are), central-difference Jacobians, inside the search's box: BOBYQA's optimum
** polished to where the residuals stop falling (a noiseless table's quantities to ~1e-8). Returns
** the RSS at v (updated in place). */
double cf_joint_pair_polish(jctx *c, double v[PQ_COUNT], const int used[PQ_COUNT],
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
        if (pair_jacobian(c, v, idx, p, g, rp, rm, J))
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
            double delta[PQ_COUNT];
            const int singular = lm_step(A, b, p, lambda, delta);
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
** component in the discarded directions is not determined (se -1); *cov_bt the covariance of
** the compression spring's B and tau when both are determined (NAN otherwise). 0, or -1 when
** memory runs out or a curve fails. */
int cf_joint_pair_errors(jctx *c, const double v0[PQ_COUNT], const int used[PQ_COUNT],
                       double rss, double se[PQ_COUNT], double *cov_bt)
{
    *cov_bt = NAN;
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
            for (int a = 0; a < p; a++) /* B_c is idx 1; tau, when used, the last */
                if (idx[a] == PQ_T && se[PQ_T] >= 0 && se[PQ_BC] >= 0) {
                    double cv = 0;
                    for (int b = 0; b < p; b++) {
                        const double e = gsl_vector_get(ev, (size_t)b);
                        if (e > 1e-10 * emax)
                            cv += gsl_matrix_get(V, (size_t)a, (size_t)b) *
                                  gsl_matrix_get(V, 1, (size_t)b) / e;
                    }
                    *cov_bt = s2 * cv * dsc[a] * dsc[1];
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
void cf_joint_small_strain_moduli(jctx *c, const double v[PQ_COUNT], cf_joint_result *r)
{
    const cf_ident qc = {.rho = v[PQ_RC], .solid = v[PQ_BC], .scale = v[PQ_AC]};
    const cf_ident qe = {.rho = v[PQ_RE], .solid = v[PQ_BE], .scale = v[PQ_AE]};
    const cf_spring pc = c->tail ? cf_ident_member_tail(&qc, v[PQ_T]) : cf_ident_member(&qc),
                    pe = cf_ident_member(&qe);
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

/* Both springs of the quantities v placed (the extension spring at the compression
** spring's H); the element is buildable when both are (fit.feasible says it for the pair). */
cf_status cf_joint_pair_place(const jctx *c, const cf_table *reach, const double v[PQ_COUNT],
                              cf_joint_result *r, cf_error *err)
{
    r->ident.rho = v[PQ_RC], r->ident.solid = v[PQ_BC], r->ident.scale = v[PQ_AC];
    cf_status st;
    if (c->tail) { /* the tailed spring in closed form (tail.h); its errors follow the search */
        const double vt[4] = {v[PQ_RC], v[PQ_BC], v[PQ_AC], v[PQ_T]}, se[4] = {-1, -1, -1, -1};
        double corr[4][4];
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 4; b++)
                corr[a][b] = NAN;
        st = cf_tail_result(reach, c->opt, c->type, vt, se, corr, NAN, &r->fit, err);
    } else {
        st = cf_fit_place(reach, c->opt, c->type, &r->ident, &r->fit, err);
    }
    if (st != CF_OK)
        return st;
    r->fit.ident = r->ident;
    if (c->pair) {
        cf_fit_options oe = *c->opt;
        oe.fixed[CF_P_H] = 1;
        oe.fixed_value[CF_P_H] = r->fit.params.H_mm;
        const cf_ident qe = {.rho = v[PQ_RE], .solid = v[PQ_BE], .scale = v[PQ_AE]};
        if ((st = cf_fit_place(reach, &oe, c->type, &qe, &r->ext, err)) != CF_OK)
            return st;
        r->ext.ident = qe;
        r->fit.feasible = r->fit.feasible && r->ext.feasible;
    }
    return CF_OK;
}

/* 1 when both springs of the context's law at (rho, B) and compression stress scale A can be
** built (cf_joint_pair_place over c->reach; 1 when the context has no reach). The search does not
** see buildability otherwise, and its searches kept to stable lattices walked to springs that
** cannot be built, the pair then falling back to the law it contains (issue 42). */
int cf_joint_pair_buildable(const jctx *c, double rho, double B, double A)
{
    if (!c->reach)
        return 1;
    if (!(A > 0) || !isfinite(A))
        return 0;
    double v[PQ_COUNT] = {0};
    v[PQ_RC] = rho, v[PQ_BC] = B, v[PQ_AC] = A;
    if (c->tail)
        v[PQ_T] = c->tau;
    if (c->pair)
        v[PQ_RE] = c->ext[0], v[PQ_BE] = c->ext[1], v[PQ_AE] = A * c->ext[2];
    cf_joint_result r;
    memset(&r, 0, sizeof r);
    cf_error e = {0};
    return cf_joint_pair_place(c, c->reach, v, &r, &e) == CF_OK && r.fit.feasible;
}

/* The fitted kappa of the law a search contains (plain) over its compression spring's k0/H (the
** search's variable, KAPPA_REL); 0 when it has none. */
double cf_joint_nest_kappa_rel(const cf_joint_result *plain)
{
    if (plain->volume != CF_VOLUME_FIT || !(plain->volume_modulus_MPa > 0) ||
        !(plain->ident.scale > 0))
        return 0;
    const cf_ident q1 = {.rho = plain->ident.rho, .solid = plain->ident.solid, .scale = 1.0};
    const cf_spring p1 = cf_ident_member(&q1);
    cf_law l1;
    if (cf_law_init(&l1, &p1, NULL) != CF_OK)
        return 0;
    return plain->volume_modulus_MPa / (plain->ident.scale * l1.k0_N_per_mm / l1.p.H_mm);
}

/* Step 1 of the pair's search (joint_pair.c): its variables and their box (pvars) into the
** context's problem; the volume term's mode. */
cf_status cf_joint_pair_box(jctx *c, double xmax, pvars *pv, cf_error *err)
{
    const cf_fit_options *opt = c->opt;
    *pv = (pvars){.n = 2, .ie = -1, .ik = -1, .iA = -1, .iq = -1, .it = -1};
    pv->lb[0] = log(fmax(CF_IDENT_RHO_LO, opt->rho_min));
    pv->ub[0] = log(cf_ident_rho_hi(c->type, opt->index_max));
    pv->lb[1] = xmax * (1 + CF_FIT_TRAVEL_MARGIN) * (1 + 1e-9);
    pv->ub[1] = 1 - 1e-9;
    if (!(pv->lb[1] < pv->ub[1]))
        return cf_error_set(err, CF_E_DATA, "the springs must reach a strain of %g: no spring "
                                            "does", xmax);
    if (c->pair) {
        pv->ie = pv->n;
        pv->lb[pv->n] = pv->lb[0], pv->ub[pv->n++] = pv->ub[0];
        pv->lb[pv->n] = pv->lb[1], pv->ub[pv->n++] = pv->ub[1];
        pv->lb[pv->n] = log(1e-4), pv->ub[pv->n++] = log(1e4);
    }
    if (opt->volume == CF_VOLUME_FIT) {
        pv->ik = pv->n;
        /* kappa/(k0/H) at most the one of nu CF_JOINT_NU_MAX (the weights as they start) */
        const double kmax = cf_cubic_kappa_of_nu(c->weight, 1.0, CF_JOINT_NU_MAX);
        pv->lb[pv->n] = log(1e-5), pv->ub[pv->n++] = log(fmin(1e4, fmax(kmax, 1e-4)));
        c->kappa_rel_max = exp(pv->ub[pv->n - 1]);
        c->kappa_mode = KAPPA_REL;
    } else if (opt->volume == CF_VOLUME_MODULUS) {
        pv->iA = pv->n;
        pv->lb[pv->n] = log(1e-12), pv->ub[pv->n++] = log(CF_MEASURE_MAX_VALUE);
        c->kappa_mode = KAPPA_UNIT;
    } else if (opt->volume == CF_VOLUME_POISSON) {
        c->kappa_mode = KAPPA_NU;
        c->kappa = opt->volume_value;
    }
    if (c->fit_weights) {
        pv->iq = pv->n;
        cf_joint_q_box(opt, &pv->lb[pv->n], &pv->ub[pv->n]);
        pv->n++;
    }
    if (c->tail) {
        pv->it = pv->n;
        pv->lb[pv->n] = log(TAU_LO), pv->ub[pv->n++] = log(TAU_HI);
    }
    memcpy(c->pr.lb, pv->lb, sizeof c->pr.lb);
    memcpy(c->pr.ub, pv->ub, sizeof c->pr.ub);
    c->pr.A_max = cf_joint_pair_A_max;
    return CF_OK;
}
