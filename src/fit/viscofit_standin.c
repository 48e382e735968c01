/*
** Stage A of the viscoelastic fit: the stand-in search. Over a grid of the elastic quantities and
** of time constants, the branches' relative moduli solved by non-negative least squares on
** responses computed once, which gives the Levenberg-Marquardt its starts.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "fit/viscofit_ctx.h"

/* ---- the best starts ------------------------------------------------------------------------- */

static void keep_start(start *best, int nbest, double obj, const cf_visco_params *p)
{
    int pos = nbest;
    while (pos > 0 && obj < best[pos - 1].obj)
        pos--;
    if (pos >= nbest)
        return;
    /* one start per (rho, s/H): replace a worse start of the same grid point */
    for (int i = 0; i < nbest; i++)
        if (best[i].obj < HUGE_VAL && best[i].p.ident.rho == p->ident.rho &&
            best[i].p.ident.solid == p->ident.solid) {
            if (i < pos)
                return;
            memmove(best + i, best + i + 1, (size_t)(nbest - 1 - i) * sizeof *best);
            best[nbest - 1].obj = HUGE_VAL;
            break;
        }
    memmove(best + pos + 1, best + pos, (size_t)(nbest - 1 - pos) * sizeof *best);
    best[pos].obj = obj;
    best[pos].p = *p;
}

/* ---- the stand-in at one grid point: non-negative least squares ------------------------------ */

/* The stand-in at one grid point (rho, s/H) for one set of time constants: the elastic curve E
** (at unit scale, or at the held scale) and the responses of the chosen branches. The stress is
**     A E + sum_i (A g_i) (R_i - E) + c_d rate,
** with R_i branch i's response to E, linear in the unknowns A (unless held or capped), A g_i and
** the dashpot's c_d. With relaxation depending on strain, g_i (1 - |x|/x_max) + g'_i |x|/x_max
** (its values at zero and at the largest strain) takes the place of g_i: the unknowns are A g_i
** and A g'_i, all >= 0 (non-negative least squares), with S_i the response to |x| E. */
typedef struct standin {
    const double *E, *rate;
    const double *xE; /* |x| E (NULL: quasi-linear) */
    const double *basis[2 + 2 * CF_PRONY_MAX];
    double A_fixed;     /* > 0: the scale is held there (a held fit, or the design cap) */
    gsl_matrix *X;      /* weighted design, rows x (2 + 2 CF_PRONY_MAX) */
    gsl_vector *y, *tau, *a, *res;
    /* Every column above is a combination of the few base columns of the grid point (E, the
    ** responses, |x| E and its responses, the rate), so the least squares run in the space of
    ** the weighted base's QR factor: rows = the base's columns (or the points, when fewer), each
    ** vector (E, rate, basis, yw) has that many entries, and tail2 is the part of the weighted
    ** data outside the base, which no combination reaches. */
    size_t rows;
    const double *yw;
    double tail2;
} standin;

enum { NNLS_MAX = 2 + 2 * CF_PRONY_MAX }; /* columns of the stand-in's design */
enum { BASE_MAX = 3 + 2 * GRID_TAU };     /* columns of the base of one grid point */

/* Least squares of y on the columns of X marked in[] (Householder QR in Q, tau, sol, res), into z
** (0 on the other columns); 0 when it fails or gives a non-finite value. */
static int nnls_free_columns(const gsl_matrix *X, const gsl_vector *y, const int *in, gsl_matrix *Q,
                             gsl_vector *tau, gsl_vector *sol, gsl_vector *res, double *z)
{
    const size_t n = X->size1, m = X->size2;
    size_t nf = 0, map[NNLS_MAX];
    for (size_t j = 0; j < m; j++) {
        z[j] = 0;
        if (in[j])
            map[nf++] = j;
    }
    gsl_matrix_view Qv = gsl_matrix_submatrix(Q, 0, 0, n, nf);
    for (size_t k = 0; k < nf; k++) {
        gsl_vector_const_view col = gsl_matrix_const_column(X, map[k]);
        gsl_matrix_set_col(&Qv.matrix, k, &col.vector);
    }
    gsl_vector_view tv = gsl_vector_subvector(tau, 0, nf), sv = gsl_vector_subvector(sol, 0, nf);
    if (gsl_linalg_QR_decomp(&Qv.matrix, &tv.vector) != GSL_SUCCESS ||
        gsl_linalg_QR_lssolve(&Qv.matrix, &tv.vector, y, &sv.vector, res) != GSL_SUCCESS)
        return 0;
    for (size_t k = 0; k < nf; k++)
        if (!isfinite(z[map[k]] = gsl_vector_get(sol, k)))
            return 0;
    return 1;
}

/* Non-negative least squares min |X a - y|, a >= 0 (Lawson and Hanson's active-set method, the
** subproblems on the free columns by Householder QR): for the stand-in with relaxation depending
** on strain, whose unconstrained solutions mostly cancel terms of opposite sign. X is n x m
** (m <= NNLS_MAX), not changed; 0 when a subproblem fails. */
static int nnls(const gsl_matrix *X, const gsl_vector *y, double *a)
{
    const size_t n = X->size1, m = X->size2;
    int in[NNLS_MAX] = {0};
    double w[NNLS_MAX], z[NNLS_MAX];
    gsl_matrix *Q = gsl_matrix_alloc(n, m);
    gsl_vector *tau = gsl_vector_alloc(m), *sol = gsl_vector_alloc(m), *res = gsl_vector_alloc(n);
    int ok = Q && tau && sol && res;
    for (size_t j = 0; j < m; j++)
        a[j] = 0;
    for (int outer = 0; ok && outer < 3 * (int)m; outer++) {
        /* the gradient w = X^T (y - X a), from the residual formed once */
        gsl_vector_memcpy(res, y);
        for (size_t k = 0; k < m; k++)
            if (a[k] != 0) {
                gsl_vector_const_view col = gsl_matrix_const_column(X, k);
                gsl_blas_daxpy(-a[k], &col.vector, res);
            }
        size_t jmax = m;
        for (size_t j = 0; j < m; j++) {
            gsl_vector_const_view col = gsl_matrix_const_column(X, j);
            gsl_blas_ddot(&col.vector, res, &w[j]);
            if (!in[j] && w[j] > 1e-12 && (jmax == m || w[j] > w[jmax]))
                jmax = j;
        }
        if (jmax == m)
            break;
        in[jmax] = 1;
        for (int inner = 0; ok && inner < 3 * (int)m; inner++) {
            if (!(ok = nnls_free_columns(X, y, in, Q, tau, sol, res, z)))
                break;
            double alpha = 2;
            for (size_t j = 0; j < m; j++)
                if (in[j] && z[j] <= 0)
                    alpha = fmin(alpha, a[j] / (a[j] - z[j]));
            if (alpha > 1) { /* every free coefficient positive */
                memcpy(a, z, m * sizeof(double));
                break;
            }
            for (size_t j = 0; j < m; j++) { /* back to the boundary, dropping what reached it */
                a[j] += alpha * (z[j] - a[j]);
                if (in[j] && a[j] <= 1e-300) {
                    in[j] = 0;
                    a[j] = 0;
                }
            }
        }
    }
    if (Q)
        gsl_matrix_free(Q);
    if (tau)
        gsl_vector_free(tau);
    if (sol)
        gsl_vector_free(sol);
    if (res)
        gsl_vector_free(res);
    return ok;
}

/* Weighted linear least squares of the stand-in by Householder QR (GSL): the coefficients in
** a[] in the order of the basis (A first when free). 0 when the design is rank deficient. */
static int standin_solve(standin *s, int m, double *a)
{
    const size_t n = s->rows;
    gsl_matrix_view X = gsl_matrix_submatrix(s->X, 0, 0, n, (size_t)m);
    gsl_vector_view tau = gsl_vector_subvector(s->tau, 0, (size_t)m);
    gsl_vector_view av = gsl_vector_subvector(s->a, 0, (size_t)m);
    gsl_vector_view yv = gsl_vector_subvector(s->y, 0, n);
    gsl_vector_view rv = gsl_vector_subvector(s->res, 0, n);
    const int held = s->A_fixed > 0;
    const int off = held ? 0 : 1;
    if ((size_t)m > n)
        return 0;
    for (size_t k = 0; k < n; k++) {
        gsl_vector_set(&yv.vector, k, s->yw[k] - (held ? s->A_fixed * s->E[k] : 0.0));
        for (int i = 0; i < m; i++) {
            const double *b = i < off ? s->E : s->basis[i - off];
            gsl_matrix_set(&X.matrix, k, (size_t)i, b[k]);
        }
    }
    if (s->xE) /* relaxation growing with strain: every coefficient >= 0 */
        return nnls(&X.matrix, &yv.vector, a);
    if (gsl_linalg_QR_decomp(&X.matrix, &tau.vector) != GSL_SUCCESS)
        return 0;
    double dmax = 0, dmin = HUGE_VAL;
    for (int i = 0; i < m; i++) {
        double r = fabs(gsl_matrix_get(&X.matrix, (size_t)i, (size_t)i));
        dmax = fmax(dmax, r);
        dmin = fmin(dmin, r);
    }
    if (!(dmin > 1e-13 * dmax))
        return 0;
    if (gsl_linalg_QR_lssolve(&X.matrix, &tau.vector, &yv.vector, &av.vector, &rv.vector) !=
        GSL_SUCCESS)
        return 0;
    for (int i = 0; i < m; i++)
        if (!isfinite(a[i] = gsl_vector_get(&av.vector, (size_t)i)))
            return 0;
    return 1;
}

/* The parameters of a stand-in solution, or 0 when they break g_i >= 0, sum g_i < 1, c_d > 0. */
static int standin_params(const ctx *c, const standin *s, const double *a, const int *idx,
                          const double *taus, double rate_factor, cf_visco_params *p)
{
    const int held = s->A_fixed > 0, off = held ? 0 : 1;
    const double A = held ? s->A_fixed : a[0];
    if (!(A > 0))
        return 0;
    double gs = 0, gs1 = 0;
    p->nbranch = c->nb;
    for (int i = 0; i < c->nb; i++) {
        const double g1 = c->gs ? a[off + c->nb + i] / A : 0.0; /* at the largest strain */
        p->g[i] = a[off + i] / A;
        p->k[i] = c->gs ? (g1 - p->g[i]) / c->xmax : 0.0;
        p->tau_s[i] = taus[idx[i]];
        if (!(p->g[i] >= 0) || !(g1 >= 0))
            return 0;
        gs += p->g[i];
        gs1 += g1;
    }
    if (!(gs < 1 - 1e-9) || !(gs1 < 1 - 1e-9))
        return 0;
    if (c->dash) {
        double cd = a[off + c->nb * (1 + c->gs)];
        if (!(cd > 0))
            return 0;
        p->eta_MPa_s = cd * rate_factor; /* MPa s */
    }
    p->ident.scale *= A;
    return 1;
}

/* The weighted, scaled sum of squares of the stand-in solution a. */
static double standin_obj(const ctx *c, const standin *s, int m, const double *a)
{
    const int held = s->A_fixed > 0, off = held ? 0 : 1;
    double sum = s->tail2;
    for (size_t k = 0; k < s->rows; k++) {
        double model = held ? s->A_fixed * s->E[k] : 0.0;
        for (int i = 0; i < m; i++)
            model += a[i] * (i < off ? s->E[k] : s->basis[i - off][k]);
        double r = model - s->yw[k];
        sum += r * r;
    }
    return sum / c->ynorm;
}

/* One combination of time constants (indices idx into taus): solved, the scale capped at A_max
** (then solved again with the scale held there), kept in best when feasible. */
static void standin_combo(ctx *c, standin *s, double *const *R, double *const *S, const int *idx,
                          const double *taus, double rate_factor, double A_max,
                          const cf_visco_params *el, double *tmp, start *best, int nbest)
{
    const int nb = c->nb;
    const size_t n = s->rows;
    for (int i = 0; i < nb; i++) {
        double *b = tmp + (size_t)i * n;
        for (size_t k = 0; k < n; k++)
            b[k] = R[idx[i]][k] - s->E[k];
        s->basis[i] = b;
    }
    for (int i = 0; c->gs && i < nb; i++) {
        double *b0 = tmp + (size_t)i * n, *b1 = tmp + (size_t)(nb + i) * n;
        for (size_t k = 0; k < n; k++) {
            b1[k] = (S[idx[i]][k] - s->xE[k]) / c->xmax;
            b0[k] -= b1[k];
        }
        s->basis[nb + i] = b1;
    }
    if (c->dash)
        s->basis[nb * (1 + c->gs)] = s->rate;
    const double A_held = c->free_el ? 0.0 : 1.0; /* a held curve carries its scale */
    double a[2 + 2 * CF_PRONY_MAX];
    s->A_fixed = A_held;
    int m = (s->A_fixed > 0 ? 0 : 1) + nb * (1 + c->gs) + c->dash;
    if (!standin_solve(s, m, a))
        return;
    if (s->A_fixed == 0 && a[0] > A_max) { /* past the design cap: the scale held there */
        s->A_fixed = A_max;
        m = nb * (1 + c->gs) + c->dash;
        if (!(A_max > 0) || !standin_solve(s, m, a))
            return;
    }
    cf_visco_params p = *el;
    if (standin_params(c, s, a, idx, taus, rate_factor, &p))
        keep_start(best, nbest, standin_obj(c, s, m, a), &p);
}

/* The K columns base[] of a grid point in the space of their weighted QR factor (see standin):
** column j into out + j s->rows, the weighted data into yw (s->rows entries) and s->tail2. With no
** more points than columns (or options.full_standin), the weighted columns themselves. 0 when
** memory runs out or the factorisation fails. */
static int reduce_base(const ctx *c, const double *const *base, size_t K, double *out,
                       double *yw, standin *s)
{
    const size_t n = c->n;
    s->yw = yw;
    s->tail2 = 0;
    if (n <= K || c->o->full_standin) {
        s->rows = n;
        for (size_t k = 0; k < n; k++) {
            for (size_t j = 0; j < K; j++)
                out[j * n + k] = c->sw[k] * base[j][k];
            yw[k] = c->sw[k] * c->d->y[k];
        }
        return 1;
    }
    gsl_matrix *B = gsl_matrix_alloc(n, K);
    gsl_vector *tau = gsl_vector_alloc(K), *y = gsl_vector_alloc(n);
    int ok = B && tau && y;
    for (size_t k = 0; ok && k < n; k++) {
        for (size_t j = 0; j < K; j++)
            gsl_matrix_set(B, k, j, c->sw[k] * base[j][k]);
        gsl_vector_set(y, k, c->sw[k] * c->d->y[k]);
    }
    ok = ok && gsl_linalg_QR_decomp(B, tau) == GSL_SUCCESS &&
         gsl_linalg_QR_QTvec(B, tau, y) == GSL_SUCCESS;
    if (ok) {
        s->rows = K;
        for (size_t j = 0; j < K; j++)
            for (size_t i = 0; i < K; i++)
                out[j * K + i] = i <= j ? gsl_matrix_get(B, i, j) : 0.0;
        for (size_t k = 0; k < n; k++) {
            const double v = gsl_vector_get(y, k);
            if (k < K)
                yw[k] = v;
            else
                s->tail2 += v * v;
        }
    }
    gsl_matrix_free(B); /* GSL's free functions take NULL */
    gsl_vector_free(tau);
    gsl_vector_free(y);
    return ok;
}

/* For one elastic curve E and the Prony responses R[t][k] of every grid time constant, tries
** every set of nb time constants and keeps the best feasible ones in best. */
static void search_taus(ctx *c, const double *E, const double *xE, double *const *R,
                        double *const *S, const double *taus, const double *rate,
                        double rate_factor, double A_max, const cf_visco_params *el, start *best,
                        int nbest)
{
    const int nb = c->nb;
    standin s;
    memset(&s, 0, sizeof s);
    s.X = gsl_matrix_alloc(c->n, 2 + 2 * CF_PRONY_MAX);
    s.y = gsl_vector_alloc(c->n);
    s.res = gsl_vector_alloc(c->n);
    s.tau = gsl_vector_alloc(2 + 2 * CF_PRONY_MAX);
    s.a = gsl_vector_alloc(2 + 2 * CF_PRONY_MAX);
    double *tmp = malloc((size_t)(2 * nb + 1) * c->n * sizeof(double));
    /* the base: E, its responses, with relaxation depending on strain |x| E and its responses,
    ** with a dashpot the rate; every column of every combination is made of them */
    const double *base[BASE_MAX];
    size_t K = 0;
    base[K++] = E;
    for (int i = 0; i < GRID_TAU; i++)
        base[K++] = R[i];
    if (xE) {
        base[K++] = xE;
        for (int i = 0; i < GRID_TAU; i++)
            base[K++] = S[i];
    }
    if (c->dash)
        base[K++] = rate;
    double *red = malloc((K + 1) * c->n * sizeof(double)), *Rr[GRID_TAU], *Sr[GRID_TAU];
    int ready = red && reduce_base(c, base, K, red, red + K * c->n, &s);
    if (ready) {
        size_t j = 0;
        s.E = red + s.rows * j++;
        for (int i = 0; i < GRID_TAU; i++)
            Rr[i] = red + s.rows * j++;
        s.xE = xE ? red + s.rows * j++ : NULL;
        for (int i = 0; xE && i < GRID_TAU; i++)
            Sr[i] = red + s.rows * j++;
        s.rate = c->dash ? red + s.rows * j++ : NULL;
    }
    int idx[CF_PRONY_MAX];
    for (int i = 0; i < nb; i++)
        idx[i] = i;
    while (ready && tmp && s.X && s.y && s.res && s.tau && s.a) {
        standin_combo(c, &s, Rr, Sr, idx, taus, rate_factor, A_max, el, tmp, best, nbest);
        /* next combination of nb indices out of GRID_TAU, increasing */
        int i = nb - 1;
        while (i >= 0 && idx[i] == GRID_TAU - nb + i)
            i--;
        if (i < 0)
            break;
        idx[i]++;
        for (int j = i + 1; j < nb; j++)
            idx[j] = idx[j - 1] + 1;
    }
    free(tmp);
    free(red);
    gsl_matrix_free(s.X);
    gsl_vector_free(s.y);
    gsl_vector_free(s.res);
    gsl_vector_free(s.tau);
    gsl_vector_free(s.a);
}

/* ---- the grid -------------------------------------------------------------------------------- */

/* Static lattice stress (table's sign) of the model's elastic part at every strain of the
** series, and the small-strain ratio of the lattice modulus to the spring's k0/H (the factor
** that maps a spring's dashpot to the lattice's). */
static int elastic_curve(ctx *c, const cf_visco_params *el, double *E, double *lat_factor)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    p.ident = el->ident;
    p.e_tail = el->e_tail; /* a held tailed spring's tail goes with it */
    const double e = p.ident.solid;
    cf_error err = {0};
    c->evals++;
    if (cf_visco_elastic_curve(&p, &c->o->setup, c->d->x, c->n, E, &err) != CF_OK)
        return 0;
    cf_spring sp = cf_visco_member(&p);
    cf_law law;
    double small = -1e-3 * e, s0 = 0;
    if (cf_law_init(&law, &sp, &err) != CF_OK)
        return 0;
    int ok = cf_visco_elastic_curve(&p, &c->o->setup, &small, 1, &s0, &err) == CF_OK;
    *lat_factor = (s0 / small) / (law.k0_N_per_mm / sp.H_mm);
    cf_law_free(&law);
    return ok && *lat_factor > 0;
}

/* Prony responses per unit g of the curve E at every grid time constant:
** h_k = e h_(k-1) + b (E_k - E_(k-1)), relaxed start. */
static void grid_responses(const ctx *c, const double *E, const double *taus, double *const *R)
{
    const double *t = c->d->t_s;
    for (int i = 0; i < GRID_TAU; i++) {
        R[i][0] = 0;
        for (size_t k = 1; k < c->n; k++) {
            double h = t[k] - t[k - 1];
            double ex = exp(-h / taus[i]), b = -expm1(-h / taus[i]) * taus[i] / h;
            R[i][k] = ex * R[i][k - 1] + b * (E[k] - E[k - 1]);
        }
    }
}

/* The grid point (ir, ie) of the stand-in: rho spaced logarithmically from the lower limit, s/H
** quadratically from the smallest allowed at that rho; the held values when held. */
static void grid_point(const ctx *c, int ir, int ie, cf_visco_params *el)
{
    memset(el, 0, sizeof *el);
    if (!c->free_el) {
        el->ident = c->o->elastic;
        el->e_tail = c->o->elastic_e_tail;
        return;
    }
    const double r0 = fmax(c->rho_lo * 1.001, 0.02);
    el->ident.rho = r0 * pow(0.98 / r0, (double)ir / (GRID_RHO - 1));
    const double lo = cf_viscofit_solid_lo(c, el->ident.rho), f = (ie + 1.0) / (GRID_E + 1.0);
    el->ident.solid = lo + (E_HI - lo) * f * f;
    el->ident.scale = 1;
}

/* Stage A: the best starts for nb branches. */
int cf_viscofit_stand_in(ctx *c, start *best, int nbest)
{
    for (int i = 0; i < nbest; i++)
        best[i].obj = HUGE_VAL;
    const size_t n = c->n;
    const double *t = c->d->t_s;
    double dtmin = HUGE_VAL, taus[GRID_TAU];
    for (size_t k = 1; k < n; k++)
        dtmin = fmin(dtmin, t[k] - t[k - 1]);
    const double tlo = 0.5 * dtmin, thi = 2 * (t[n - 1] - t[0]);
    for (int i = 0; i < GRID_TAU; i++)
        taus[i] = tlo * pow(thi / tlo, (double)i / (GRID_TAU - 1));
    double *E = malloc(n * sizeof(double)), *rate = calloc(n, sizeof(double));
    double *xE = malloc(n * sizeof(double));
    double *Rbuf = malloc((size_t)GRID_TAU * 2 * n * sizeof(double)), *R[GRID_TAU], *S[GRID_TAU];
    for (int i = 0; Rbuf && i < GRID_TAU; i++) {
        R[i] = Rbuf + (size_t)i * n;
        S[i] = Rbuf + (size_t)(GRID_TAU + i) * n;
    }
    for (size_t k = 1; rate && k < n; k++)
        rate[k] = (c->d->x[k] - c->d->x[k - 1]) / (t[k] - t[k - 1]);
    const int nrho = c->free_el ? GRID_RHO : 1, ne = c->free_el ? GRID_E : 1;
    for (int ir = 0; E && xE && rate && Rbuf && ir < nrho; ir++)
        for (int ie = 0; ie < ne; ie++) {
            cf_visco_params el;
            grid_point(c, ir, ie, &el);
            double fac = 1;
            if (!elastic_curve(c, &el, E, &fac))
                continue;
            grid_responses(c, E, taus, R);
            if (c->gs) {
                for (size_t k = 0; k < n; k++)
                    xE[k] = fabs(c->d->x[k]) * E[k];
                grid_responses(c, xE, taus, S);
            }
            const double A_max =
                c->free_el ? cf_visco_limits_scale_max(&c->lim, el.ident.rho, el.ident.solid)
                           : INFINITY;
            /* a dashpot eta beside every spring adds about eta * fac * rate to the stress */
            search_taus(c, E, c->gs ? xE : NULL, R, S, taus, rate, 1 / fac, A_max, &el, best,
                        nbest);
        }
    free(E);
    free(xE);
    free(rate);
    free(Rbuf);
    return best[0].obj < HUGE_VAL;
}
