/*
** Solvers for the mass-spring lattice (see msm.h): Newton equilibria with a sparse tangent solved
** by GMRES, implicit quasi-static viscous steps, explicit symplectic dynamics, and the uniaxial
** validation curve.
*/
#include "conifit/msm.h"
#include "model/lattice_step.h"
#include "model/sparse_chol.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_spblas.h>
#include <gsl/gsl_splinalg.h>
#include <gsl/gsl_spmatrix.h>
#include <gsl/gsl_vector.h>

/* GMRES: residual relative to the right-hand side. The Newton update only needs a few digits more
** than the Newton tolerance asks of the residual, and Newton's own iteration removes the rest. */
#define GMRES_TOL 1e-13
#define GMRES_MAX_RESTARTS 200
#define GMRES_ACCEPT 1e-6
/* Linear solves: sparse Cholesky (CHOLMOD, L D L^T when the tangent is indefinite) first, accepted
** when its relative residual is below BAND_ACCEPT; if it fails, banded LDL^T (when the band fits
** in BAND_MAX_ENTRIES doubles), else dense LU up to DENSE_MAX_DOF free DOFs (a 7x7x7 lattice has
** ~1500), else GMRES. */
#define BAND_ACCEPT 1e-10
#define CHOL_REFINE 2
#define BAND_MAX_ENTRIES 5e7
#define DENSE_MAX_DOF 1200
/* A spring may come this close to solid (fraction of the travel) in a Newton step; beyond it the
** step is shortened. Past it the law's stiffness grows like (s - u)^(-1/2) and Newton stalls. */
#define SOLID_MARGIN (1.0 - 1e-9)
/* Chord iterations (the uniaxial curve): a direction from the last factored tangent is kept while
** each step cuts the residual at least by CHORD_RATE without shortening; otherwise the next
** direction refactors. */
#define CHORD_RATE 0.25
/* Bisections of a load increment (or time step) before a solve is declared non-converged. */
#define MAX_BISECT 12
/* Stability scan of the uniaxial lattice: steps up to STABILITY_REACH of the solid strain, then
** bisections between the last stable strain and the first unstable one (resolution
** REACH / STEPS / 2^BISECT of the solid strain, about 1e-5). */
#define STABILITY_REACH 0.995
#define STABILITY_STEPS 32
#define STABILITY_BISECT 11
/* Safety factor on the explicit stable step. */
#define DT_SAFETY 0.9

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

cf_msm_config cf_msm_default(void)
{
    cf_msm_config c;
    c.lattice = cf_lattice_default();
    c.newton_rtol = 1e-11;
    c.newton_max_iter = 50;
    c.dt_s = 0;
    c.quasi_substeps = 10;
    c.banded_only = 0;
    c.progress = NULL;
    c.progress_ctx = NULL;
    return c;
}

/* ---- workspace ------------------------------------------------------------------------------- */

typedef struct solver {
    cf_lattice *lat;
    const cf_msm_effects *fx;
    const cf_msm_config *cfg;
    cf_msm_drive drive;
    size_t ndof;              /* free DOFs */
    long *eq;                 /* node*3+axis -> equation or -1 */
    double *R, *D, *dx;       /* residual, Jacobi scale, update (ndof) */
    double *xsave;            /* 3 nn positions for backtracking */
    double *Tx0, *kx, *Lprev; /* quasi-static extras per spring (NULL when static) */
    double *sigm;             /* Maxwell branch stress per spring, MPa (NULL when off) */
    double *hq;               /* Prony branch forces, N per unit weight, compression positive:
                                 branch i of spring q at hq[q * prony_count + i] (NULL when off) */
    double *Fprev;            /* law force of every spring at the start of the step, N */
    double qlv_scale;         /* step's law-force factor minus 1 (Prony terms; 0 when off) */
    double qlv_slope;         /* its growth per unit |strain| of the spring (0: quasi-linear) */
    double *tmp;              /* per-spring scratch */
    gsl_spmatrix *C;          /* tangent, compressed columns, pattern built once */
    int *map, *diag;          /* spring block -> C->data index; DOF -> its diagonal index */
    size_t band;              /* half-bandwidth of C (largest |row - col|) */
    gsl_matrix *AB;           /* banded LDL^T workspace, ndof x (band + 1); NULL until used */
    cf_sparse_chol *chol;     /* sparse factorisation of C (pattern analysed once); NULL until used */
    int chol_failed;          /* 1: the sparse factorisation could not be set up; not retried */
    long neg_pivots;          /* negative pivots of the last factored tangent, -1 unknown */
    int chord;                /* reuse factorisations across iterations and load steps (below) */
    int chol_ready;           /* s->chol holds the factors of C, scaled by s->D, for a chord step */
    int refactor;             /* the next direction needs a fresh tangent */
    double load;              /* current drive value: strain or stress, MPa */
    int extras;               /* quasi-static extras active */
    cf_msm_stats *st;
} solver;

/* The step's law-force factor minus 1 on spring q at its current strain (qlv_scale + qlv_slope
** |u| / H), and its derivative with respect to the law compression u. */
static inline double qlv_factor(const solver *s, size_t q, double *d_du)
{
    const cf_lattice *lat = s->lat;
    if (s->qlv_slope == 0) {
        if (d_du)
            *d_du = 0;
        return s->qlv_scale;
    }
    if (d_du)
        *d_du = s->qlv_slope * copysign(1.0, lat->u_mm[q]) / lat->H_mm;
    return s->qlv_scale + s->qlv_slope * fabs(lat->u_mm[q]) / lat->H_mm;
}

/* Prony term i's relative modulus at a spring's |strain| e: g_i + k_i e. */
static inline double prony_g_at(const cf_msm_effects *fx, int i, double abs_e)
{
    return fx->prony_k[i] != 0 ? fx->prony_g[i] + fx->prony_k[i] * abs_e : fx->prony_g[i];
}

static void cf_msm_solver_free(solver *s)
{
    free(s->eq);
    free(s->R);
    free(s->D);
    free(s->dx);
    free(s->xsave);
    free(s->Tx0);
    free(s->kx);
    free(s->Lprev);
    free(s->sigm);
    free(s->hq);
    free(s->Fprev);
    free(s->tmp);
    free(s->map);
    free(s->diag);
    if (s->C)
        gsl_spmatrix_free(s->C);
    if (s->AB)
        gsl_matrix_free(s->AB);
    cf_sparse_chol_free(s->chol);
}

static int is_prescribed(const solver *s, size_t node, int axis)
{
    const cf_lattice *lat = s->lat;
    if (lat->fix[node] & (1 << axis))
        return 1;
    if (axis == 2 && s->drive == CF_DRIVE_DISPLACEMENT && lat->Z[node] >= lat->height_mm * 0.9999999)
        return 1;
    return 0;
}

static cf_status cf_msm_solver_init(solver *s, cf_lattice *lat, const cf_msm_effects *fx,
                                    const cf_msm_config *cfg, cf_msm_drive drive,
                                    cf_msm_stats *st, cf_error *err)
{
    memset(s, 0, sizeof *s);
    s->lat = lat;
    s->fx = fx;
    s->cfg = cfg;
    s->drive = drive;
    s->st = st;
    s->neg_pivots = -1;
    if (st)
        st->neg_pivots_max = -1;
    s->eq = malloc(3 * lat->nn * sizeof(long));
    s->xsave = malloc(3 * lat->nn * sizeof(double));
    s->tmp = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    if (!s->eq || !s->xsave || !s->tmp)
        goto oom;
    size_t n = 0;
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++)
            s->eq[3 * p + a] = is_prescribed(s, p, a) ? -1 : (long)n++;
    s->ndof = n;
    s->R = calloc(n ? n : 1, sizeof(double));
    s->D = calloc(n ? n : 1, sizeof(double));
    s->dx = calloc(n ? n : 1, sizeof(double));
    if (!s->R || !s->D || !s->dx)
        goto oom;
    if (fx && (fx->eta_MPa_s > 0 || fx->maxwell_E_MPa > 0 || fx->prony_count > 0)) {
        s->Tx0 = calloc(lat->ns, sizeof(double));
        s->kx = calloc(lat->ns, sizeof(double));
        s->Lprev = calloc(lat->ns, sizeof(double));
        if (!s->Tx0 || !s->kx || !s->Lprev)
            goto oom;
    }
    if (fx && fx->maxwell_E_MPa > 0 && !(s->sigm = calloc(lat->ns, sizeof(double))))
        goto oom;
    if (fx && fx->prony_count > 0 &&
        (!(s->hq = calloc(lat->ns * (size_t)fx->prony_count, sizeof(double))) ||
         !(s->Fprev = calloc(lat->ns, sizeof(double)))))
        goto oom;
    return CF_OK;
oom:
    cf_msm_solver_free(s);
    return cf_error_set(err, CF_E_INTERNAL, "out of memory for the lattice solver");
}

static double *coord(cf_lattice *lat, int a)
{
    return a == 0 ? lat->x : a == 1 ? lat->y : lat->z;
}

static double *force(cf_lattice *lat, int a)
{
    return a == 0 ? lat->fx : a == 1 ? lat->fy : lat->fz;
}

/* Places the top face for a displacement drive at compressive strain e. */
static void cf_msm_place_top(cf_lattice *lat, double e)
{
    for (size_t t = 0; t < lat->ntop; t++) {
        uint32_t p = lat->top[t];
        lat->z[p] = lat->Z[p] - e * lat->height_mm;
    }
}

/* External loads: force drive on the top face, gravity on every node. */
static void cf_msm_add_external(solver *s)
{
    cf_lattice *lat = s->lat;
    if (s->drive == CF_DRIVE_FORCE) {
        double per = s->load * lat->H_mm * lat->H_mm; /* N per unit share */
        for (size_t t = 0; t < lat->ntop; t++)
            lat->fz[lat->top[t]] -= per * lat->top_share[t];
    }
    if (s->fx && s->fx->gravity_mm_per_s2 != 0)
        for (size_t p = 0; p < lat->nn; p++)
            lat->fz[p] -= lat->mass_t[p] * s->fx->gravity_mm_per_s2;
}

/* Forces at the current positions (kernel + quasi-static extras + loads) and the residual on the
** free DOFs. Returns max |u|/travel; *rnorm the infinity norm, *fscale the force scale. */
static double cf_msm_residual(solver *s, double *rnorm, double *fscale)
{
    cf_lattice *lat = s->lat;
    double um = cf_lattice_forces(lat);
    if (s->extras) {
        for (size_t q = 0; q < lat->ns; q++)
            s->tmp[q] = s->Tx0[q] + s->kx[q] * (lat->L_mm[q] - s->Lprev[q]) -
                        qlv_factor(s, q, NULL) * lat->w[q] * lat->F_N[q];
        cf_lattice_add_tensions(lat, s->tmp);
    }
    cf_msm_add_external(s);
    double rn = 0, fs = 0;
    for (size_t q = 0; q < lat->ns; q++)
        fs = fmax(fs, fabs(lat->T_N[q]));
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++) {
            long e = s->eq[3 * p + a];
            if (e < 0)
                continue;
            s->R[e] = force(lat, a)[p];
            rn = fmax(rn, fabs(s->R[e]));
        }
    *rnorm = rn;
    *fscale = fs;
    return um;
}

/* Index of entry (row, col) in the compressed-column matrix C, or -1 (rows within a column are
** not sorted by GSL's compression; a column holds at most 81 entries). */
static int ccs_index(const gsl_spmatrix *C, long row, long col)
{
    if (row < 0 || col < 0)
        return -1;
    for (int k = C->p[col]; k < C->p[col + 1]; k++)
        if (C->i[k] == row)
            return k;
    return -1;
}

/* The sparsity pattern of the tangent, built once: for every spring the positions in C->data of
** its four 3 x 3 blocks (ii, jj, ij, ji), so that assembly is a pass of additions. */
static cf_status build_pattern(solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const size_t n = s->ndof;
    /* The pattern by hand: each node couples with itself and the nodes it shares a spring with
    ** (at most 26), a 3 x 3 block each. GSL's triplet tree and its compression are not used: they
    ** crash on their own allocation failures (gsl_spmatrix_set, gsl_spmatrix_ccs); a compressed
    ** matrix allocated directly fails cleanly. */
    enum { MAXADJ = 27 };
    const size_t nn = lat->nn;
    uint32_t *adj = malloc((nn ? nn : 1) * MAXADJ * sizeof(uint32_t));
    unsigned char *deg = calloc(nn ? nn : 1, 1);
    int *colp = malloc((n + 1) * sizeof(int));
    if (!adj || !deg || !colp) {
        free(adj);
        free(deg);
        free(colp);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    }
    for (size_t p = 0; p < nn; p++) {
        adj[p * MAXADJ] = (uint32_t)p;
        deg[p] = 1;
    }
    int bad = 0;
    for (size_t q = 0; q < lat->ns && !bad; q++) {
        uint32_t ends[2] = {lat->si[q], lat->sj[q]};
        for (int e = 0; e < 2; e++) {
            uint32_t a = ends[e], b = ends[1 - e];
            int have = 0;
            for (int k = 0; k < deg[a] && !have; k++)
                have = adj[a * MAXADJ + k] == b;
            if (!have) {
                if (deg[a] == MAXADJ) {
                    bad = 1;
                    break;
                }
                adj[a * MAXADJ + deg[a]++] = b;
            }
        }
    }
    /* the column of free DOF e = eq[3 p + a] holds the free DOFs of the nodes adjacent to p */
    size_t nnz = 0;
    for (size_t e = 0; e <= n; e++)
        colp[e] = 0;
    for (size_t p = 0; p < nn && !bad; p++) {
        size_t rows = 0;
        for (int k = 0; k < deg[p]; k++)
            for (int b = 0; b < 3; b++)
                rows += s->eq[3 * (size_t)adj[p * MAXADJ + k] + b] >= 0;
        for (int a = 0; a < 3; a++)
            if (s->eq[3 * p + a] >= 0)
                colp[s->eq[3 * p + a] + 1] = (int)rows;
    }
    for (size_t e = 0; e < n; e++)
        colp[e + 1] += colp[e];
    nnz = (size_t)colp[n];
    gsl_spmatrix *C = bad ? NULL
                          : gsl_spmatrix_alloc_nzmax(n ? n : 1, n ? n : 1, nnz ? nnz : 1,
                                                     GSL_SPMATRIX_CSC);
    if (C) {
        for (size_t e = 0; e <= n; e++)
            C->p[e] = colp[e];
        for (size_t p = 0; p < nn; p++)
            for (int a = 0; a < 3; a++) {
                long col = s->eq[3 * p + a];
                if (col < 0)
                    continue;
                int at = colp[col];
                for (int k = 0; k < deg[p]; k++)
                    for (int b = 0; b < 3; b++) {
                        long row = s->eq[3 * (size_t)adj[p * MAXADJ + k] + b];
                        if (row >= 0)
                            C->i[at++] = (int)row;
                    }
                /* rows in increasing order within the column (at most 81: insertion sort) */
                for (int x = colp[col] + 1; x < at; x++) {
                    int v = C->i[x], y = x - 1;
                    for (; y >= colp[col] && C->i[y] > v; y--)
                        C->i[y + 1] = C->i[y];
                    C->i[y + 1] = v;
                }
            }
        memset(C->data, 0, (nnz ? nnz : 1) * sizeof(double));
        C->nz = nnz;
    }
    free(adj);
    free(deg);
    free(colp);
    s->C = C;
    s->map = malloc((lat->ns ? lat->ns : 1) * 36 * sizeof(int));
    s->diag = malloc((n ? n : 1) * sizeof(int));
    if (!s->C || !s->map || !s->diag)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    for (size_t q = 0; q < lat->ns; q++) {
        uint32_t i = lat->si[q], j = lat->sj[q];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                long ia = s->eq[3 * i + a], ib = s->eq[3 * i + b];
                long ja = s->eq[3 * j + a], jb = s->eq[3 * j + b];
                int *m = s->map + q * 36 + a * 3 + b;
                m[0] = ccs_index(s->C, ia, ib);
                m[9] = ccs_index(s->C, ja, jb);
                m[18] = ccs_index(s->C, ia, jb);
                m[27] = ccs_index(s->C, ja, ib);
            }
    }
    for (size_t e = 0; e < n; e++)
        s->diag[e] = ccs_index(s->C, (long)e, (long)e);
    s->band = 0;
    for (size_t col = 0; col < n; col++)
        for (int k = s->C->p[col]; k < s->C->p[col + 1]; k++) {
            size_t row = (size_t)s->C->i[k];
            size_t off = row > col ? row - col : col - row;
            if (off > s->band)
                s->band = off;
        }
    return CF_OK;
}

/* Adds the inertia of the tangent just solved (s->neg_pivots, -1 unknown) to the statistics. */
static void note_inertia(solver *s)
{
    const long neg = s->neg_pivots;
    if (!s->st || neg < 0)
        return;
    if (neg > 0)
        s->st->indefinite_tangents++;
    if (neg > s->st->neg_pivots_max)
        s->st->neg_pivots_max = neg;
}

/* Sparse Cholesky of the scaled tangent (sparse_chol.h): the pattern is analysed once with a
** fill-reducing ordering, so a factorisation costs far less than the band's n b^2 on lattices of
** more than a few cells a side, and an indefinite tangent is factored as L D L^T with its negative
** pivots counted. Accepted when the residual is small. Returns 1 when s->dx holds the update;
** sets *fatal for an out-of-memory that no fallback would survive. */
static int cf_linsolve_chord(solver *s, int *fatal, cf_error *err);

static int chol_direction(solver *s, int *fatal, cf_error *err)
{
    const size_t n = s->ndof;
    gsl_spmatrix *C = s->C;
    *fatal = 0;
    s->chol_ready = 0;
    if (s->chol_failed || n == 0)
        return 0;
    cf_error lerr = {0};
    if (!s->chol && cf_sparse_chol_create(&s->chol, n, C->p, C->i, &lerr) != CF_OK) {
        s->chol_failed = 1;
        return 0;
    }
    cf_chol_info info;
    cf_status st = cf_sparse_chol_factor(s->chol, C->data, &info, &lerr);
    if (st == CF_E_INTERNAL) {
        *fatal = 1;
        cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
        return 0;
    }
    if (st != CF_OK)
        return 0;
    s->neg_pivots = info.neg_pivots; /* the inertia holds even when the solve is refused */
    int ok = cf_linsolve_chord(s, fatal, err);
    s->chol_ready = ok;
    if (ok && s->st)
        s->st->linear_iters++;
    return ok;
}

/* The update from the factors in s->chol (of C as it was factored, scaled by s->D): solved,
** accepted when its residual against C is small. Returns 1 when s->dx holds it. */
static int cf_linsolve_chord(solver *s, int *fatal, cf_error *err)
{
    const size_t n = s->ndof;
    gsl_spmatrix *C = s->C;
    cf_error lerr = {0};
    double *rhs = malloc(4 * n * sizeof(double));
    if (!rhs) {
        *fatal = 1;
        cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent solve");
        return 0;
    }
    double *xv = rhs + n, *r = rhs + 2 * n, *dv = rhs + 3 * n;
    for (size_t e = 0; e < n; e++)
        rhs[e] = s->R[e] / s->D[e];
    int ok = cf_sparse_chol_solve(s->chol, rhs, xv, &lerr) == CF_OK;
    /* residual check, || rhs - C x || against || rhs ||, with up to CHOL_REFINE steps of
    ** iterative refinement (an indefinite tangent near a singular one may need them) */
    gsl_vector_view xw = gsl_vector_view_array(xv, n), rw = gsl_vector_view_array(r, n);
    gsl_vector_const_view bw = gsl_vector_const_view_array(rhs, n);
    const double bn = gsl_blas_dnrm2(&bw.vector);
    for (int k = 0; ok; k++) {
        memcpy(r, rhs, n * sizeof(double));
        ok = gsl_spblas_dgemv(CblasNoTrans, -1.0, C, &xw.vector, 1.0, &rw.vector) == GSL_SUCCESS;
        if (!ok || gsl_blas_dnrm2(&rw.vector) <= BAND_ACCEPT * bn)
            break;
        ok = k < CHOL_REFINE && cf_sparse_chol_solve(s->chol, r, dv, &lerr) == CF_OK;
        for (size_t e = 0; ok && e < n; e++)
            xv[e] += dv[e];
    }
    for (size_t e = 0; ok && e < n; e++) {
        double v = xv[e] / s->D[e];
        ok = isfinite(v);
        s->dx[e] = v;
    }
    free(rhs);
    return ok;
}

/* The scaled tangent is symmetric and, with the nodes numbered layer by layer, banded (half-
** bandwidth about 3 (nx + 1)(ny + 1)): a banded LDL^T (GSL) costs n b^2 instead of n^3/3. It does
** not pivot, so the solve is accepted only when its residual is small; otherwise the caller falls
** back to dense LU or GMRES. Returns 1 when s->dx holds the update. */
static int band_direction(solver *s)
{
    const size_t n = s->ndof, b = s->band;
    const gsl_spmatrix *C = s->C;
    if (b + 1 > n || (double)n * (double)(b + 1) > BAND_MAX_ENTRIES)
        return 0;
    if (!s->AB && !(s->AB = gsl_matrix_alloc(n, b + 1)))
        return 0;
    gsl_matrix_set_zero(s->AB);
    for (size_t col = 0; col < n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++) {
            size_t row = (size_t)C->i[k];
            if (row >= col)
                gsl_matrix_set(s->AB, col, row - col, C->data[k]); /* AB(j, i - j) = A(i, j) */
        }
    gsl_vector *rhs = gsl_vector_alloc(n), *xv = gsl_vector_alloc(n), *r = gsl_vector_alloc(n);
    int ok = rhs && xv && r;
    if (ok) {
        for (size_t e = 0; e < n; e++)
            gsl_vector_set(rhs, e, s->R[e] / s->D[e]);
        ok = gsl_linalg_ldlt_band_decomp(s->AB) == GSL_SUCCESS &&
             gsl_linalg_ldlt_band_solve(s->AB, rhs, xv) == GSL_SUCCESS;
    }
    long neg = 0; /* the inertia from D, the first column of the decomposed band */
    for (size_t e = 0; ok && e < n; e++)
        neg += gsl_matrix_get(s->AB, e, 0) < 0;
    if (ok) { /* residual check: r = rhs - C x */
        gsl_vector_memcpy(r, rhs);
        ok = gsl_spblas_dgemv(CblasNoTrans, -1.0, C, xv, 1.0, r) == GSL_SUCCESS &&
             gsl_blas_dnrm2(r) <= BAND_ACCEPT * gsl_blas_dnrm2(rhs);
    }
    for (size_t e = 0; ok && e < n; e++) {
        double v = gsl_vector_get(xv, e) / s->D[e];
        ok = isfinite(v);
        s->dx[e] = v;
    }
    if (ok) {
        s->neg_pivots = neg;
        if (s->st)
            s->st->linear_iters++;
    }
    gsl_vector_free(rhs);
    gsl_vector_free(xv);
    gsl_vector_free(r);
    return ok;
}

/* Small systems are solved directly: LU with partial pivoting (GSL) of the scaled tangent costs
** well under a millisecond for the few hundred DOFs of a validation lattice, where restarted GMRES
** took several (measured on the 3x3x3 hysteresis scene: 18 s before, see the README). */
static cf_status dense_direction(solver *s, cf_error *err)
{
    const size_t n = s->ndof;
    const gsl_spmatrix *C = s->C;
    gsl_matrix *A = gsl_matrix_calloc(n, n);
    gsl_permutation *perm = gsl_permutation_alloc(n);
    gsl_vector *b = gsl_vector_alloc(n), *xv = gsl_vector_alloc(n);
    cf_status st = CF_OK;
    int sign;
    if (!A || !perm || !b || !xv) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the lattice tangent (%zu DOFs)",
                          n);
        goto done;
    }
    for (size_t col = 0; col < n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            gsl_matrix_set(A, (size_t)C->i[k], col, C->data[k]);
    for (size_t e = 0; e < n; e++)
        gsl_vector_set(b, e, s->R[e] / s->D[e]);
    if (gsl_linalg_LU_decomp(A, perm, &sign) != GSL_SUCCESS ||
        gsl_linalg_LU_solve(A, perm, b, xv) != GSL_SUCCESS) {
        st = cf_error_set(err, CF_E_NOCONV, "the lattice tangent is singular (%zu DOFs)", n);
        goto done;
    }
    for (size_t e = 0; e < n; e++) {
        double v = gsl_vector_get(xv, e) / s->D[e];
        if (!isfinite(v)) {
            st = cf_error_set(err, CF_E_NOCONV, "the lattice tangent is singular (%zu DOFs)", n);
            goto done;
        }
        s->dx[e] = v;
    }
    if (s->st)
        s->st->linear_iters++;
done:
    gsl_matrix_free(A);
    gsl_permutation_free(perm);
    gsl_vector_free(b);
    gsl_vector_free(xv);
    return st;
}

/* Assembles the tangent K = -dR/dx at the state of the last cf_msm_residual(), solves K dx = R
** (sparse Cholesky, else banded LDL^T, dense LU for small systems, GMRES) with symmetric Jacobi scaling
** (a congruence: the inertia is that of K). Kept as one function (~85 lines): assembly, scaling,
** the solver cascade and the acceptance test share the scaled system and its workspaces. */
static cf_status tangent_solve(solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const size_t n = s->ndof;
    if (!s->C && build_pattern(s, err) != CF_OK)
        return CF_E_INTERNAL;
    gsl_spmatrix *C = s->C;
    memset(C->data, 0, (size_t)C->p[n] * sizeof(double));
    for (size_t q = 0; q < lat->ns; q++) {
        uint32_t i = lat->si[q], j = lat->sj[q];
        double L = lat->L_mm[q];
        double nv[3] = {(lat->x[j] - lat->x[i]) / L, (lat->y[j] - lat->y[i]) / L,
                        (lat->z[j] - lat->z[i]) / L};
        double kt = lat->w[q] * lat->a[q] * lat->k_N_per_mm[q];
        if (s->extras) {
            double dq, qf = qlv_factor(s, q, &dq);
            kt = kt * (1 + qf) + s->kx[q] + dq * lat->w[q] * lat->a[q] * lat->F_N[q];
        }
        double g = lat->T_N[q] / L;
        const int *m = s->map + q * 36;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double B = (kt - g) * nv[a] * nv[b] + (a == b ? g : 0.0);
                int k = a * 3 + b;
                if (m[k] >= 0)
                    C->data[m[k]] += B;
                if (m[k + 9] >= 0)
                    C->data[m[k + 9]] += B;
                if (m[k + 18] >= 0)
                    C->data[m[k + 18]] -= B;
                if (m[k + 27] >= 0)
                    C->data[m[k + 27]] -= B;
            }
    }
    /* Symmetric Jacobi scaling: K' = D^-1 K D^-1 with D = sqrt|diag|. */
    for (size_t e = 0; e < n; e++) {
        double d = C->data[s->diag[e]];
        s->D[e] = (d != 0 && isfinite(d)) ? sqrt(fabs(d)) : 1.0;
    }
    for (size_t col = 0; col < n; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            C->data[k] /= s->D[C->i[k]] * s->D[col];
    int fatal = 0;
    s->neg_pivots = -1;
    if (!s->cfg->banded_only && chol_direction(s, &fatal, err))
        return CF_OK;

    if (fatal)
        return CF_E_INTERNAL;
    if (band_direction(s))
        return CF_OK;
    if (n <= DENSE_MAX_DOF)
        return dense_direction(s, err);
    gsl_vector *b = gsl_vector_alloc(n), *xv = gsl_vector_calloc(n);
    size_t restart = n < 150 ? n : 150;
    gsl_splinalg_itersolve *w = gsl_splinalg_itersolve_alloc(gsl_splinalg_itersolve_gmres, n,
                                                              restart);
    cf_status st = CF_OK;
    if (!b || !xv || !w) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for GMRES");
        goto done;
    }
    for (size_t e = 0; e < n; e++)
        gsl_vector_set(b, e, s->R[e] / s->D[e]);
    int status = GSL_CONTINUE;
    for (int it = 0; it < GMRES_MAX_RESTARTS && status == GSL_CONTINUE; it++) {
        status = gsl_splinalg_itersolve_iterate(C, b, GMRES_TOL, xv, w);
        if (s->st)
            s->st->linear_iters++;
    }
    /* Stagnation near rounding is accepted when the update is still accurate to a few digits:
    ** Newton corrects the rest (inexact Newton). */
    if (status != GSL_SUCCESS && gsl_splinalg_itersolve_normr(w) <= GMRES_ACCEPT * gsl_blas_dnrm2(b))
        status = GSL_SUCCESS;
    if (status != GSL_SUCCESS) {
        st = cf_error_set(err, CF_E_NOCONV,
                          "GMRES did not converge on the lattice tangent (residual %.3g)",
                          gsl_splinalg_itersolve_normr(w));
        goto done;
    }
    for (size_t e = 0; e < n; e++)
        s->dx[e] = gsl_vector_get(xv, e) / s->D[e];
done:
    gsl_splinalg_itersolve_free(w);
    gsl_vector_free(b);
    gsl_vector_free(xv);
    return st;
}

static cf_status cf_linsolve_direction(solver *s, cf_error *err)
{
    cf_status st = tangent_solve(s, err);
    note_inertia(s);
    return st;
}

static void save_positions(solver *s)
{
    cf_lattice *lat = s->lat;
    memcpy(s->xsave, lat->x, lat->nn * sizeof(double));
    memcpy(s->xsave + lat->nn, lat->y, lat->nn * sizeof(double));
    memcpy(s->xsave + 2 * lat->nn, lat->z, lat->nn * sizeof(double));
}

static void restore_positions(solver *s)
{
    cf_lattice *lat = s->lat;
    memcpy(lat->x, s->xsave, lat->nn * sizeof(double));
    memcpy(lat->y, s->xsave + lat->nn, lat->nn * sizeof(double));
    memcpy(lat->z, s->xsave + 2 * lat->nn, lat->nn * sizeof(double));
}

/* Newton from the current positions (prescribed DOFs already placed). On failure the positions
** are put back where they started. Kept as one function (~105 lines): the force floor, the choice
** between a chord step and a fresh tangent, the line search and the retry with a fresh tangent all
** read and update the same iteration state (residual norms, the factorisation's age). */
static cf_status cf_msm_newton(solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    double *start = malloc(3 * lat->nn * sizeof(double));
    if (!start)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    memcpy(start, lat->x, lat->nn * sizeof(double));
    memcpy(start + lat->nn, lat->y, lat->nn * sizeof(double));
    memcpy(start + 2 * lat->nn, lat->z, lat->nn * sizeof(double));
    if (s->st)
        s->st->solves++;
    double rn, fs;
    double um = cf_msm_residual(s, &rn, &fs);
    /* Floor of the force scale: a small fraction of the solid load times the largest spring
    ** weight (forces scale with it, and so does their rounding), so that an unloaded lattice is
    ** converged at once whatever its weights (a diagonal weight of 1e4 left 7e-13 N of rounding
    ** against a floor of 1e-12 F_C). */
    double wmax = 1, dash = 0;
    for (size_t q = 0; q < lat->ns; q++)
        wmax = fmax(wmax, lat->w[q]);
    /* ... and, in an implicit step with dashpots or Maxwell branches, above the rounding of their
    ** forces kx (L - Lprev) (kx grows as 1/dt: 1000 substeps of a 1 s ramp left 1.9e-8 N of it).
    ** A length is known only to the rounding of the coordinates it is formed from, eps times the
    ** largest |coordinate| of the lattice, not of the length: so the scale of those terms is kx
    ** times that coordinate (a row of 1000 cells stalled at 1.9 times a floor taken from kx L). */
    if (s->extras && s->kx) {
        double xmax = 0;
        for (size_t p = 0; p < lat->nn; p++)
            xmax = fmax(xmax, fmax(fabs(lat->x[p]), fmax(fabs(lat->y[p]), fabs(lat->z[p]))));
        for (size_t q = 0; q < lat->ns; q++)
            dash = fmax(dash, s->kx[q] * fmax(lat->L_mm[q], xmax));
    }
    const double floor_f = 1e-12 * lat->law->F_C_N * wmax + 1e-13 * dash;
    cf_status st = CF_E_NOCONV;
    for (int it = 0; it <= s->cfg->newton_max_iter; it++) {
        if (um < SOLID_MARGIN && rn <= s->cfg->newton_rtol * fs + floor_f) {
            st = CF_OK;
            break;
        }
        if (it == s->cfg->newton_max_iter)
            break;
        if (s->st)
            s->st->newton_iters++;
        cf_error lerr = {0};
        /* a chord step: the last factored tangent, while it still converges fast */
        const int chord = s->chord && s->chol_ready && !s->refactor;
        if (chord) {
            int fatal = 0;
            if (!cf_linsolve_chord(s, &fatal, &lerr)) {
                if (fatal) {
                    memcpy(lat->x, start, lat->nn * sizeof(double));
                    memcpy(lat->y, start + lat->nn, lat->nn * sizeof(double));
                    memcpy(lat->z, start + 2 * lat->nn, lat->nn * sizeof(double));
                    free(start);
                    return cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
                }
                s->refactor = 1;
                continue;
            }
            if (s->st)
                s->st->chord_iters++;
        } else if (cf_linsolve_direction(s, &lerr) != CF_OK) {
            if (lerr.status == CF_E_INTERNAL) { /* out of memory: not a matter of step size */
                memcpy(lat->x, start, lat->nn * sizeof(double));
                memcpy(lat->y, start + lat->nn, lat->nn * sizeof(double));
                memcpy(lat->z, start + 2 * lat->nn, lat->nn * sizeof(double));
                free(start);
                return cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
            }
            break;
        } else
            s->refactor = 0;
        save_positions(s);
        double alpha = 1, rn0 = rn;
        int ok = 0;
        for (int h = 0; h < 40; h++) {
            for (size_t p = 0; p < lat->nn; p++)
                for (int a = 0; a < 3; a++) {
                    long e = s->eq[3 * p + a];
                    if (e >= 0)
                        coord(lat, a)[p] = s->xsave[a * lat->nn + p] + alpha * s->dx[e];
                }
            um = cf_msm_residual(s, &rn, &fs);
            if (um < SOLID_MARGIN && isfinite(rn) && (rn < (1 - 1e-4 * alpha) * rn0 || h >= 30)) {
                ok = 1;
                break;
            }
            alpha *= 0.5;
        }
        if (!ok) {
            restore_positions(s);
            if (!chord)
                break;
            um = cf_msm_residual(s, &rn, &fs); /* a stale tangent: try again with a fresh one */
            s->refactor = 1;
            continue;
        }
        if (chord && (alpha < 1 || rn > CHORD_RATE * rn0))
            s->refactor = 1;
    }
    if (s->st && um > s->st->max_u_over_travel && st == CF_OK)
        s->st->max_u_over_travel = um;
    if (st != CF_OK) {
        memcpy(lat->x, start, lat->nn * sizeof(double));
        memcpy(lat->y, start + lat->nn, lat->nn * sizeof(double));
        memcpy(lat->z, start + 2 * lat->nn, lat->nn * sizeof(double));
        cf_error_set(err, CF_E_NOCONV,
                     "lattice equilibrium not found at %s %.6g (residual %.3g N, max spring "
                     "compression %.6g of travel)",
                     s->drive == CF_DRIVE_DISPLACEMENT ? "strain" : "stress_MPa", s->load, rn, um);
    }
    free(start);
    return st;
}

/* Moves the free z of every node by the affine part of a strain increment de (a predictor that
** puts the interior where a uniform lattice would be). */
static void predict(solver *s, double de)
{
    cf_lattice *lat = s->lat;
    for (size_t p = 0; p < lat->nn; p++)
        if (s->eq[3 * p + 2] >= 0)
            lat->z[p] -= de * lat->Z[p];
}

/* Static equilibrium from drive value v0 (the current state) to v1; splits the increment in two
** when a direct solve fails. */
static cf_status static_seg(solver *s, double v0, double v1, int depth, cf_error *err)
{
    s->load = v1;
    int disp = s->drive == CF_DRIVE_DISPLACEMENT;
    if (disp) {
        cf_msm_place_top(s->lat, v1);
        predict(s, v1 - v0);
    }
    cf_status st = cf_msm_newton(s, err);
    if (st == CF_OK)
        return st;
    s->load = v0;
    if (disp) {
        cf_msm_place_top(s->lat, v0);
        predict(s, v0 - v1);
    }
    if (st != CF_E_NOCONV || depth >= MAX_BISECT)
        return st;
    double mid = 0.5 * (v0 + v1);
    st = static_seg(s, v0, mid, depth + 1, err);
    if (st != CF_OK)
        return st;
    return static_seg(s, mid, v1, depth + 1, err);
}

static cf_status cf_msm_static_to(solver *s, double v, cf_error *err)
{
    return static_seg(s, s->load, v, 0, err);
}

/* Compressive nominal stress (MPa) at the current state from the node forces of the last
** residual/kernel call: the reaction the top platen provides. */
static double cf_msm_top_stress(const cf_lattice *lat)
{
    double r = 0;
    for (size_t t = 0; t < lat->ntop; t++)
        r += lat->fz[lat->top[t]];
    return r / lat->area_mm2;
}

/* Node force evaluation for reporting the reaction of a displacement drive. */
static double cf_msm_reported_stress(solver *s)
{
    if (s->drive == CF_DRIVE_FORCE)
        return s->load;
    double rn, fs;
    cf_msm_residual(s, &rn, &fs);
    return cf_msm_top_stress(s->lat);
}

double cf_msm_path_value(const cf_msm_path *p, double t)
{
    if (t <= p->t_s[0])
        return p->value[0];
    for (size_t i = 1; i < p->count; i++)
        if (t <= p->t_s[i]) {
            double h = p->t_s[i] - p->t_s[i - 1];
            double f = h > 0 ? (t - p->t_s[i - 1]) / h : 1.0;
            return p->value[i - 1] + f * (p->value[i] - p->value[i - 1]);
        }
    return p->value[p->count - 1];
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
static cf_status cf_msm_relaxed_share_check(const solver *s, cf_error *err)
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
static cf_status cf_msm_quasi_advance(solver *s, const cf_msm_path *p, double t0, double t1,
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

/* ---- explicit dynamics ---------------------------------------------------------------------- */

double cf_msm_stable_step(cf_lattice *lat, const cf_msm_effects *fx)
{
    cf_lattice_forces(lat);
    double kmax = 0, cmax = 0;
    double H2 = lat->H_mm * lat->H_mm;
    double branch = fx->maxwell_E_MPa > 0 ? fx->maxwell_E_MPa : 0.0;
    for (size_t q = 0; q < lat->ns; q++) {
        double k = lat->w[q] * lat->a[q] * lat->k_N_per_mm[q] + fabs(lat->T_N[q]) / lat->L_mm[q] +
                   lat->w[q] * H2 * branch / lat->L0_mm[q];
        kmax = fmax(kmax, k);
        cmax = fmax(cmax, lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q]);
    }
    /* Gershgorin: omega^2 <= 2 * degree * k_max / m_min. */
    double deg = lat->max_degree > 0 ? lat->max_degree : 1;
    double om2 = 2 * deg * kmax / lat->m_min_t;
    if (!(om2 > 0))
        return INFINITY;
    double om = sqrt(om2);
    double zeta = deg * cmax / (lat->m_min_t * om); /* c_node / (2 m omega), c_node <= 2 deg c */
    return 2.0 / om * (sqrt(1 + zeta * zeta) - zeta);
}

typedef struct dyn {
    double *vx, *vy, *vz, *Ld, *Tt;
    int fused;                /* elastic springs only: the fused step of lattice_step.h */
    cf_lattice_stepper step;  /* its state (when fused) */
} dyn;

/* One symplectic Euler step of length h ending at drive value v1 (rate for prescribed DOFs). */
static void dyn_step(solver *s, dyn *d, double h, double v1, double rate)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    const size_t ns = lat->ns, nn = lat->nn;
    if (d->fused) {
        /* node forces are zero here (cleared by the last advance or before the interval) */
        cf_lattice_stepper_forces(&d->step);
        cf_msm_add_external(s);
        cf_lattice_stepper_advance(&d->step, h, d->vx, d->vy, d->vz);
        goto drive;
    }
    lat->with_stiffness = 0; /* an explicit step needs forces only */
    cf_lattice_forces(lat);
    lat->with_stiffness = 1;
    double H2 = lat->H_mm * lat->H_mm;
    if (fx->eta_MPa_s > 0 || s->sigm) {
        /* Rate of change of every spring length. */
        for (size_t q = 0; q < ns; q++) {
            uint32_t i = lat->si[q], j = lat->sj[q];
            d->Ld[q] = ((lat->x[j] - lat->x[i]) * (d->vx[j] - d->vx[i]) +
                        (lat->y[j] - lat->y[i]) * (d->vy[j] - d->vy[i]) +
                        (lat->z[j] - lat->z[i]) * (d->vz[j] - d->vz[i])) /
                       lat->L_mm[q];
        }
        memset(d->Tt, 0, ns * sizeof(double));
        if (fx->eta_MPa_s > 0)
            for (size_t q = 0; q < ns; q++)
                d->Tt[q] += lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q] * d->Ld[q];
        if (s->sigm) {
            double E1 = exp(-h / fx->maxwell_tau_s);
            double mc = fx->maxwell_E_MPa * fx->maxwell_tau_s * (-expm1(-h / fx->maxwell_tau_s));
            for (size_t q = 0; q < ns; q++) {
                d->Tt[q] += lat->w[q] * H2 * s->sigm[q];
                s->sigm[q] = s->sigm[q] * E1 + mc * d->Ld[q] / lat->L0_mm[q];
            }
        }
        cf_lattice_add_tensions(lat, d->Tt);
    }
    cf_msm_add_external(s);
    double *v[3] = {d->vx, d->vy, d->vz};
    for (int a = 0; a < 3; a++) {
        double *x = coord(lat, a), *f = force(lat, a), *va = v[a];
        for (size_t p = 0; p < nn; p++) {
            if (s->eq[3 * p + a] < 0)
                continue;
            va[p] += h * f[p] / lat->mass_t[p];
            x[p] += h * va[p];
        }
    }
drive:
    if (s->drive == CF_DRIVE_DISPLACEMENT) {
        cf_msm_place_top(lat, v1);
        for (size_t t = 0; t < lat->ntop; t++)
            d->vz[lat->top[t]] = -rate * lat->height_mm;
    }
    if (s->st)
        s->st->steps++;
}

static double cf_msm_kinetic(const cf_lattice *lat, const dyn *d)
{
    double e = 0;
    for (size_t p = 0; p < lat->nn; p++)
        e += 0.5 * lat->mass_t[p] * (d->vx[p] * d->vx[p] + d->vy[p] * d->vy[p] + d->vz[p] * d->vz[p]);
    return e;
}

/* Total energy for a constant load: kinetic + elastic + gravity - work potential of the load. */
static double cf_msm_total_energy(solver *s, const dyn *d)
{
    cf_lattice *lat = s->lat;
    double e = cf_msm_kinetic(lat, d) + cf_lattice_elastic_energy(lat);
    if (s->fx->gravity_mm_per_s2 != 0)
        for (size_t p = 0; p < lat->nn; p++)
            e += lat->mass_t[p] * s->fx->gravity_mm_per_s2 * (lat->z[p] - lat->Z[p]);
    if (s->drive == CF_DRIVE_FORCE)
        for (size_t t = 0; t < lat->ntop; t++) {
            uint32_t p = lat->top[t];
            e += s->load * lat->H_mm * lat->H_mm * lat->top_share[t] * (lat->z[p] - lat->Z[p]);
        }
    return e;
}

/* ---- runner ---------------------------------------------------------------------------------- */

static cf_status check_path(const cf_msm_path *p, const double *ts, size_t ns, cf_error *err)
{
    if (p->count < 1 || !p->t_s || !p->value)
        return cf_error_set(err, CF_E_DATA, "loading path is empty");
    for (size_t i = 0; i < p->count; i++) {
        if (!isfinite(p->t_s[i]) || !isfinite(p->value[i]))
            return cf_error_set(err, CF_E_DATA, "loading path point %zu is not finite", i);
        if (i > 0 && !(p->t_s[i] >= p->t_s[i - 1]))
            return cf_error_set(err, CF_E_DATA,
                                "loading path time %.6g s at point %zu goes backwards", p->t_s[i],
                                i);
    }
    for (size_t k = 0; k < ns; k++)
        if (!isfinite(ts[k]) || (k > 0 && ts[k] < ts[k - 1]))
            return cf_error_set(err, CF_E_DATA, "sample time %zu = %g is not increasing", k,
                                ts[k]);
    return CF_OK;
}

/* The run's effects and path are ones it can follow: CF_E_DATA naming what is not. */
static cf_status check_run(const cf_msm_effects *fx, const cf_msm_path *path,
                           const double *sample_t_s, size_t nsamples, cf_error *err)
{
    cf_status rc = check_path(path, sample_t_s, nsamples, err);
    if (rc != CF_OK)
        return rc;
    if (fx->maxwell_E_MPa > 0 && !(fx->maxwell_tau_s > 0 && isfinite(fx->maxwell_tau_s)))
        return cf_error_set(err, CF_E_DATA, "maxwell tau_s = %g: must be finite and > 0",
                            fx->maxwell_tau_s);
    if ((rc = cf_msm_prony_check(fx, err)) != CF_OK)
        return rc;
    if (fx->prony_count > 0 && fx->inertia)
        return cf_error_set(err, CF_E_DATA, "Prony terms are solved quasi-statically: they do not "
                            "combine with inertia");
    return CF_OK;
}

static void cf_msm_dyn_free(dyn *d)
{
    free(d->vx);
    free(d->vy);
    free(d->vz);
    free(d->Ld);
    free(d->Tt);
    if (d->fused)
        cf_lattice_stepper_free(&d->step);
}

/* The dynamic state (velocities at rest) of an explicit run; the fused step when the springs are
** elastic only. */
static cf_status cf_msm_dyn_init(dyn *d, solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    d->vx = calloc(lat->nn, sizeof(double));
    d->vy = calloc(lat->nn, sizeof(double));
    d->vz = calloc(lat->nn, sizeof(double));
    d->Ld = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    d->Tt = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    if (!d->vx || !d->vy || !d->vz || !d->Ld || !d->Tt)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the dynamic state");
    d->fused = !(s->fx->eta_MPa_s > 0) && !s->sigm;
    cf_status rc = CF_OK;
    if (d->fused && (rc = cf_lattice_stepper_init(&d->step, lat, s->eq, err)) != CF_OK)
        d->fused = 0;
    return rc;
}

/* Explicit steps from t to tk, each within the stable step (and cfg->dt_s when set). */
static cf_status cf_msm_explicit_interval(solver *s, dyn *d, const cf_msm_path *path,
                                          double t, double tk, cf_msm_stats *st, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    double stab = DT_SAFETY * cf_msm_stable_step(lat, fx);
    double want = s->cfg->dt_s > 0 ? s->cfg->dt_s : stab;
    if (want > stab) {
        want = stab;
        st->substepped++;
    }
    double n = ceil((tk - t) / want - 1e-9);
    if (n > 1e12)
        return cf_error_set(err, CF_E_DATA, "stable step %.3g s is too small for %.3g s", want,
                            tk - t);
    double h = (tk - t) / n;
    if (st->dt_used_min_s == 0 || h < st->dt_used_min_s)
        st->dt_used_min_s = h;
    for (double m = 1; m <= n; m++) {
        double tb = t + m * h;
        double vb = cf_msm_path_value(path, tb);
        double rate = (vb - cf_msm_path_value(path, tb - h)) / h;
        s->load = vb;
        if (m == 1 && d->fused) { /* the fused step adds onto zeroed node forces */
            memset(lat->fx, 0, lat->nn * sizeof(double));
            memset(lat->fy, 0, lat->nn * sizeof(double));
            memset(lat->fz, 0, lat->nn * sizeof(double));
        }
        dyn_step(s, d, h, vb, rate);
    }
    double um = cf_lattice_forces(lat);
    st->max_u_over_travel = fmax(st->max_u_over_travel, um);
    if (um >= 1)
        return cf_error_set(err, CF_E_NOCONV,
                            "a spring reached solid length at t = %.6g s (strain %.6g): the load "
                            "is more than the lattice can carry",
                            tk, cf_lattice_top_strain(lat));
    return CF_OK;
}

/* From time t to sample k at tk, drive value vk: a static equilibrium, implicit quasi-static
** steps, or explicit steps, as the effects ask. */
static cf_status advance_to(solver *s, dyn *d, const cf_msm_path *path, double t, double tk,
                            double vk, size_t k, cf_msm_stats *st, cf_error *err)
{
    const cf_msm_effects *fx = s->fx;
    const int timed = fx->inertia || fx->eta_MPa_s > 0 || fx->maxwell_E_MPa > 0 ||
                      fx->prony_count > 0;
    if (!timed)
        return cf_msm_static_to(s, vk, err);
    if (fx->inertia)
        return tk > t ? cf_msm_explicit_interval(s, d, path, t, tk, st, err) : CF_OK;
    if (tk > t) {
        int n = s->cfg->quasi_substeps > 0 ? s->cfg->quasi_substeps : 1;
        if (s->cfg->dt_s > 0)
            n = (int)fmin(1e9, ceil((tk - t) / s->cfg->dt_s - 1e-9));
        return cf_msm_quasi_advance(s, path, t, tk, n > 0 ? n : 1, 0, err);
    }
    if (k > 0)
        return CF_OK;
    /* The state at the first sample is at rest: the Maxwell and Prony branches are relaxed, so
    ** the springs carry g_inf times the law. */
    if (fx->prony_count > 0) {
        double gsum = 0;
        for (int i = 0; i < fx->prony_count; i++)
            gsum += fx->prony_g[i];
        double ksum = 0;
        for (int i = 0; i < fx->prony_count; i++)
            ksum += fx->prony_k[i];
        s->qlv_scale = -gsum;
        s->qlv_slope = -ksum;
        s->extras = 1;
    }
    cf_status rc = cf_msm_static_to(s, vk, err);
    return rc == CF_OK ? cf_msm_relaxed_share_check(s, err) : rc;
}

/* The compressive stress at the top of the current state (drive value vk). */
static double sample_stress(solver *s, dyn *d, const cf_msm_path *path, double vk)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    if (fx->inertia && (fx->eta_MPa_s > 0 || s->sigm) && path->drive == CF_DRIVE_DISPLACEMENT) {
        /* Reaction including the dashpots at the current velocities. */
        cf_lattice_forces(lat);
        double H2 = lat->H_mm * lat->H_mm;
        for (size_t q = 0; q < lat->ns; q++) {
            uint32_t i = lat->si[q], j = lat->sj[q];
            d->Ld[q] = ((lat->x[j] - lat->x[i]) * (d->vx[j] - d->vx[i]) +
                        (lat->y[j] - lat->y[i]) * (d->vy[j] - d->vy[i]) +
                        (lat->z[j] - lat->z[i]) * (d->vz[j] - d->vz[i])) /
                       lat->L_mm[q];
            d->Tt[q] = lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q] * d->Ld[q] +
                       (s->sigm ? lat->w[q] * H2 * s->sigm[q] : 0.0);
        }
        cf_lattice_add_tensions(lat, d->Tt);
        cf_msm_add_external(s);
        return path->drive == CF_DRIVE_FORCE ? vk : cf_msm_top_stress(lat);
    }
    if (s->extras) {
        /* Quasi-static: the reaction of the last step includes its viscous forces. */
        double rn, fsc;
        cf_msm_residual(s, &rn, &fsc);
        return path->drive == CF_DRIVE_FORCE ? vk : cf_msm_top_stress(lat);
    }
    return cf_msm_reported_stress(s);
}

/* The run is one time loop: each sample is reached (advance_to), reported (sample_stress) and
** checked finite; the solver is set up once for the effects asked for. */
cf_status cf_msm_run(cf_lattice *lat, const cf_msm_effects *fxin, const cf_msm_config *cfg,
                     const cf_msm_path *path, const double *sample_t_s, size_t nsamples,
                     cf_msm_sample *out, size_t *done, cf_msm_stats *stats, cf_error *err)
{
    cf_msm_effects none = {0};
    const cf_msm_effects *fx = fxin ? fxin : &none;
    cf_msm_stats local = {0};
    cf_msm_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    if (done)
        *done = 0;
    cf_status rc = check_run(fx, path, sample_t_s, nsamples, err);
    if (rc != CF_OK)
        return rc;
    solver s;
    if ((rc = cf_msm_solver_init(&s, lat, fx, cfg, path->drive, st, err)) != CF_OK)
        return rc;
    dyn d = {0};
    if (fx->inertia && (rc = cf_msm_dyn_init(&d, &s, err)) != CF_OK)
        goto end;
    s.load = 0;
    double t = nsamples ? fmin(sample_t_s[0], path->t_s[0]) : 0;
    if (fx->inertia) {
        st->dt_stable_s = cf_msm_stable_step(lat, fx);
        if (cfg->dt_s > 0 && cfg->dt_s > st->dt_stable_s) {
            rc = cf_error_set(err, CF_E_DATA,
                              "integrator.dt_s = %g s is above the stable explicit step %.6g s "
                              "(stiffest spring, lightest mass); use a smaller step or 0 (auto)",
                              cfg->dt_s, st->dt_stable_s);
            goto end;
        }
        s.load = cf_msm_path_value(path, t);
        if (path->drive == CF_DRIVE_DISPLACEMENT)
            cf_msm_place_top(lat, s.load);
    }
    double E0 = fx->inertia ? cf_msm_total_energy(&s, &d) : 0, Escale = 0, dE = 0;
    for (size_t k = 0; k < nsamples; k++) {
        double tk = sample_t_s[k], vk = cf_msm_path_value(path, tk);
        if ((rc = advance_to(&s, &d, path, t, tk, vk, k, st, err)) != CF_OK)
            goto end;
        t = tk;
        s.load = vk;
        out[k].t_s = tk;
        out[k].strain = cf_lattice_top_strain(lat);
        out[k].stress_MPa = sample_stress(&s, &d, path, vk);
        out[k].kinetic_mJ = fx->inertia ? cf_msm_kinetic(lat, &d) : 0.0;
        out[k].neg_pivots = fx->inertia ? -1 : s.neg_pivots;
        if (!isfinite(out[k].strain) || !isfinite(out[k].stress_MPa) ||
            !isfinite(out[k].kinetic_mJ)) {
            rc = cf_error_set(err, CF_E_INTERNAL,
                              "the simulation became non-finite at t = %.6g s (energy or "
                              "displacement); the time step is too large for this scene",
                              tk);
            goto end;
        }
        if (fx->inertia && fx->eta_MPa_s == 0 && !s.sigm) {
            /* Drift relative to the largest kinetic energy seen: the energy the load exchanges. */
            dE = fmax(dE, fabs(cf_msm_total_energy(&s, &d) - E0));
            Escale = fmax(Escale, out[k].kinetic_mJ);
            st->max_energy_drift = Escale > 0 ? dE / Escale : 0.0;
        }
        if (done)
            *done = k + 1;
        if (cfg->progress)
            cfg->progress(cfg->progress_ctx, k + 1, nsamples, tk);
    }
end:
    cf_msm_dyn_free(&d);
    cf_msm_solver_free(&s);
    return rc;
}

/* ---- the uniaxial validation curve ----------------------------------------------------------- */

typedef struct keyed {
    double key;
    size_t i;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    double x = ((const keyed *)a)->key, y = ((const keyed *)b)->key;
    return (x > y) - (x < y);
}

cf_status cf_msm_uniaxial(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                          const double *strain, size_t count, double *stress_MPa,
                          cf_msm_stats *stats, cf_error *err)
{
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    cf_msm_stats local = {0};
    cf_msm_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    for (size_t i = 0; i < count; i++)
        if (!isfinite(strain[i]))
            return cf_error_set(err, CF_E_DATA, "strain[%zu] = %g is not finite", i, strain[i]);
    cf_lattice lat;
    cf_status rc = cf_lattice_create(&lat, law, m, &cfg.lattice, err);
    if (rc != CF_OK)
        return rc;
    keyed *idx = malloc((count ? count : 1) * sizeof(keyed));
    if (!idx) {
        cf_lattice_free(&lat);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < count; i++) {
        idx[i].key = fabs(strain[i]);
        idx[i].i = i;
    }
    qsort(idx, count, sizeof(keyed), cmp_keyed);
    solver s;
    if ((rc = cf_msm_solver_init(&s, &lat, NULL, &cfg, CF_DRIVE_DISPLACEMENT, st, err)) != CF_OK) {
        free(idx);
        cf_lattice_free(&lat);
        return rc;
    }
    s.chord = 1; /* only the curve is reported, not the inertia of each state */
    /* Two passes from the reference state: compression (table strain < 0), then tension. */
    for (int pass = 0; pass < 2 && rc == CF_OK; pass++) {
        cf_lattice_reset(&lat);
        s.load = 0;
        s.refactor = 1;
        for (size_t r = 0; r < count && rc == CF_OK; r++) {
            size_t i = idx[r].i;
            double e = -strain[i]; /* compressive-positive */
            if ((pass == 0) != (e > 0))
                continue;
            if (e == 0) {
                stress_MPa[i] = 0;
                continue;
            }
            if (fabs(e) * lat.H_mm >= lat.travel_mm) {
                rc = cf_error_set(err, CF_E_DATA,
                                  "strain %.6g is at or beyond the spring's solid strain %.6g",
                                  strain[i], lat.travel_mm / lat.H_mm);
                break;
            }
            rc = cf_msm_static_to(&s, e, err);
            if (rc == CF_OK)
                stress_MPa[i] = -cf_msm_reported_stress(&s);
        }
    }
    if (rc == CF_OK)
        for (size_t i = 0; i < count; i++)
            if (!isfinite(stress_MPa[i]))
                rc = cf_error_set(err, CF_E_INTERNAL, "non-finite lattice stress at strain %g",
                                  strain[i]);
    cf_msm_solver_free(&s);
    free(idx);
    cf_lattice_free(&lat);
    return rc;
}

/* ---- the stability limit of the uniaxial lattice --------------------------------------------- */

/* Negative pivots of the tangent at the current state (a converged equilibrium): assembled and
** factored once more, the update discarded. -1 when no factorisation reports its inertia; *oom
** set when memory ran out (then the count means nothing). */
static long inertia_here(solver *s, int *oom)
{
    double rn, fs;
    cf_msm_residual(s, &rn, &fs);
    s->neg_pivots = -1;
    cf_error e = {0};
    if (cf_linsolve_direction(s, &e) == CF_E_INTERNAL || e.status == CF_E_INTERNAL)
        *oom = 1;
    return s->neg_pivots;
}

/* The static lattice of cfg built from law and its displacement-driven solver (no effects). */
static cf_status static_open(const cf_law *law, cf_law_method m, const cf_msm_config *cfg,
                             cf_lattice *lat, solver *s, cf_msm_stats *st, cf_error *err)
{
    cf_status rc = cf_lattice_create(lat, law, m, &cfg->lattice, err);
    if (rc != CF_OK)
        return rc;
    if ((rc = cf_msm_solver_init(s, lat, NULL, cfg, CF_DRIVE_DISPLACEMENT, st, err)) != CF_OK)
        cf_lattice_free(lat);
    return rc;
}

cf_status cf_msm_stability_limit(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                                 int side, double *limit, cf_error *err)
{
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    *limit = 0;
    cf_lattice lat;
    cf_msm_stats st = {0};
    solver s;
    cf_status rc = static_open(law, m, &cfg, &lat, &s, &st, err);
    if (rc != CF_OK)
        return rc;
    double *keep = malloc(3 * lat.nn * sizeof(double));
    if (!keep) {
        rc = cf_error_set(err, CF_E_INTERNAL, "out of memory");
        goto done;
    }
    /* compressive-positive drive: a table strain of sign `side` is -side times it */
    const double dir = side < 0 ? 1.0 : -1.0, top = STABILITY_REACH * lat.travel_mm / lat.H_mm;
    double stable = 0;
    s.load = 0;
    for (int k = 1; k <= STABILITY_STEPS; k++) {
        double e = top * k / STABILITY_STEPS;
        memcpy(keep, lat.x, lat.nn * sizeof(double));
        memcpy(keep + lat.nn, lat.y, lat.nn * sizeof(double));
        memcpy(keep + 2 * lat.nn, lat.z, lat.nn * sizeof(double));
        cf_error e1 = {0};
        int oom = 0;
        int lost = cf_msm_static_to(&s, dir * e, &e1) != CF_OK || inertia_here(&s, &oom) > 0;
        if (oom || e1.status == CF_E_INTERNAL) { /* not a loss of stability: memory */
            rc = cf_error_set(err, CF_E_INTERNAL, "out of memory in the stability scan");
            goto done;
        }
        if (!lost) {
            stable = e;
            continue;
        }
        /* Bisect between the last stable strain and this one, each solve from the stable state. */
        double hi = e;
        for (int b = 0; b < STABILITY_BISECT; b++) {
            double mid = 0.5 * (stable + hi);
            memcpy(lat.x, keep, lat.nn * sizeof(double));
            memcpy(lat.y, keep + lat.nn, lat.nn * sizeof(double));
            memcpy(lat.z, keep + 2 * lat.nn, lat.nn * sizeof(double));
            s.load = dir * stable;
            cf_msm_place_top(&lat, s.load);
            cf_error e2 = {0};
            int ok2 = cf_msm_static_to(&s, dir * mid, &e2) == CF_OK && inertia_here(&s, &oom) == 0;
            if (oom || e2.status == CF_E_INTERNAL) {
                rc = cf_error_set(err, CF_E_INTERNAL, "out of memory in the stability scan");
                goto done;
            }
            if (ok2) {
                stable = mid;
                memcpy(keep, lat.x, lat.nn * sizeof(double));
                memcpy(keep + lat.nn, lat.y, lat.nn * sizeof(double));
                memcpy(keep + 2 * lat.nn, lat.z, lat.nn * sizeof(double));
            } else {
                hi = mid;
            }
        }
        *limit = -dir * 0.5 * (stable + hi);
        break;
    }
done:
    free(keep);
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
    return rc;
}

/* ---- stability of a homogeneous state -------------------------------------------------------- */

cf_status cf_msm_homogeneous_inertia(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                                     double strain, double lateral, long *neg, cf_error *err)
{
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    /* the banded LDL^T (GSL): its D gives the inertia, and unlike the sparse factorisations it
    ** may run on any thread (MUMPS may not) */
    cfg.banded_only = 1;
    *neg = -1;
    if (!isfinite(strain) || !isfinite(lateral) || !(lateral > 0))
        return cf_error_set(err, CF_E_DATA, "strain %g, lateral stretch %g: not a deformation",
                            strain, lateral);
    if (cfg.lattice.bottom != CF_BOTTOM_AXIAL)
        return cf_error_set(err, CF_E_DATA, "a clamped bottom holds the lattice's base: its "
                            "uniaxial state is never homogeneous");
    cf_lattice lat;
    cf_msm_stats st = {0};
    solver s;
    cf_status rc = static_open(law, m, &cfg, &lat, &s, &st, err);
    if (rc != CF_OK)
        return rc;
    /* F = diag(a, a, 1 + strain) about the pinned corner (the origin) */
    for (size_t p = 0; p < lat.nn; p++) {
        lat.x[p] = lateral * lat.X[p];
        lat.y[p] = lateral * lat.Y[p];
        lat.z[p] = (1 + strain) * lat.Z[p];
    }
    s.load = -strain;
    double rn, fs;
    double um = cf_msm_residual(&s, &rn, &fs);
    if (!(um < 1))
        rc = cf_error_set(err, CF_E_DATA, "strain %g: a spring of the lattice passes solid",
                          strain);
    else if (!(rn <= 1e-7 * fs))
        rc = cf_error_set(err, CF_E_DATA,
                          "strain %g, lateral stretch %.17g: not an equilibrium of this lattice "
                          "(residual %.3g of the largest tension; a clamped bottom is never "
                          "homogeneous)",
                          strain, lateral, rn / fs);
    else {
        /* a right-hand side of ones, whose solution is discarded, so that the factorisation's
        ** residual check means something at an equilibrium (R = 0) */
        for (size_t k = 0; k < s.ndof; k++)
            s.R[k] = 1.0;
        cf_error e = {0};
        (void)cf_linsolve_direction(&s, &e);
        *neg = s.neg_pivots;
        if (*neg < 0)
            rc = cf_error_set(err, CF_E_NOCONV, "strain %g: no factorisation of the tangent "
                              "reported its inertia", strain);
    }
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
    return rc;
}
