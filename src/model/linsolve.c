/*
** The linear solves of Newton's method on the lattice (see linsolve.h): the sparsity pattern of the
** tangent, its assembly, and the cascade sparse Cholesky or L D L^T (CHOLMOD, MUMPS:
** sparse_chol.h), banded LDL^T, dense LU, GMRES.
*/
#include "model/msm_internal.h"
#include "model/lattice_cells.h"

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
/* Linear solves: sparse Cholesky (CHOLMOD, L D L^T by MUMPS when the tangent is indefinite) first,
** accepted when its relative residual is below BAND_ACCEPT after at most CHOL_REFINE steps of
** refinement; if it fails, banded LDL^T (when the band fits in CF_LINSOLVE_BAND_MAX_ENTRIES
** doubles), else dense LU up to CF_LINSOLVE_DENSE_MAX_DOF free DOFs, else GMRES (linsolve.h). */
#define BAND_ACCEPT 1e-10
#define CHOL_REFINE 2

/* ---- the pattern of the tangent -------------------------------------------------------------- */

/* Index of entry (row, col) in the compressed-column matrix C, or -1 (rows within a column are
** not sorted by GSL's compression; a column holds at most 81 entries). */
static int ccs_index(const gsl_spmatrix *C, long row, long col)
{
    if (row < 0 || col < 0)
        return -1;
    /* the rows of a column are in increasing order (pattern_matrix): binary search */
    int lo = C->p[col], hi = C->p[col + 1];
    while (lo < hi) {
        const int mid = lo + (hi - lo) / 2;
        if (C->i[mid] < row)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < C->p[col + 1] && C->i[lo] == row ? lo : -1;
}

/* The positions in column col of a node's three DOFs rows[0..2] (-1 where fixed): one binary
** search, then the next free rows by a short scan forward (a node's free DOFs are numbered in
** increasing order, so they follow one another in the column); a full search where the scan does
** not find one. */
static void ccs_index3(const gsl_spmatrix *C, const long rows[3], long col, int out[3])
{
    int at = -1;
    for (int r = 0; r < 3; r++) {
        out[r] = -1;
        if (rows[r] < 0 || col < 0)
            continue;
        if (at >= 0) {
            int x = at + 1;
            while (x < C->p[col + 1] && C->i[x] < rows[r])
                x++;
            out[r] = x < C->p[col + 1] && C->i[x] == rows[r] ? x : ccs_index(C, rows[r], col);
        } else {
            out[r] = ccs_index(C, rows[r], col);
        }
        if (out[r] >= 0)
            at = out[r];
    }
}

/* The pattern by hand: each node couples with itself and the nodes it shares a spring with (at
** most 26), a 3 x 3 block each. GSL's triplet tree and its compression are not used: they crash on
** their own allocation failures (gsl_spmatrix_set, gsl_spmatrix_ccs); a compressed matrix
** allocated directly fails cleanly. */
enum { MAXADJ = CF_LINSOLVE_MAX_ADJ };

/* Adds b to a's adjacent nodes unless there: 0, or 1 when a has MAXADJ already. */
static int adjacent(uint32_t *adj, unsigned char *deg, uint32_t a, uint32_t b)
{
    for (int k = 0; k < deg[a]; k++)
        if (adj[a * MAXADJ + k] == b)
            return 0;
    if (deg[a] == MAXADJ)
        return 1;
    adj[a * MAXADJ + deg[a]++] = b;
    return 0;
}

/* The nodes each node shares a spring with, itself first: adj[p * MAXADJ + k] for k < deg[p].
** Returns 1 when a node has more than MAXADJ (the pattern cannot hold it). */
static int node_adjacency(const cf_lattice *lat, uint32_t *adj, unsigned char *deg)
{
    const size_t nn = lat->nn;
    for (size_t p = 0; p < nn; p++) {
        adj[p * MAXADJ] = (uint32_t)p;
        deg[p] = 1;
    }
    int bad = 0;
    for (size_t q = 0; q < lat->ns && !bad; q++) {
        uint32_t ends[2] = {lat->si[q], lat->sj[q]};
        for (int e = 0; e < 2 && !bad; e++)
            bad = adjacent(adj, deg, ends[e], ends[1 - e]);
    }
    /* the volume term couples every two nodes of a cell (a spring does unless its family's
    ** weight is 0) */
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    for (size_t c = 0; lat->cfg.volume_modulus_MPa != 0 && c < nc && !bad; c++) {
        uint32_t node[8];
        cf_lattice_cell_nodes(lat, c, node);
        for (int a = 0; a < 8 && !bad; a++)
            for (int b = 0; b < 8 && !bad; b++)
                bad = a != b && adjacent(adj, deg, node[a], node[b]);
    }
    return bad;
}

/* The compressed-column matrix of the free DOFs with the pattern of adj (values zero), colp its
** n + 1 column starts (scratch); NULL when out of memory. */
static gsl_spmatrix *pattern_matrix(const solver *s, const uint32_t *adj, const unsigned char *deg,
                                    int *colp)
{
    const size_t n = s->ndof, nn = s->lat->nn;
    /* the column of free DOF e = eq[3 p + a] holds the free DOFs of the nodes adjacent to p */
    size_t nnz = 0;
    for (size_t e = 0; e <= n; e++)
        colp[e] = 0;
    for (size_t p = 0; p < nn; p++) {
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
    gsl_spmatrix *C = gsl_spmatrix_alloc_nzmax(n ? n : 1, n ? n : 1, nnz ? nnz : 1,
                                               GSL_SPMATRIX_CSC);
    if (!C)
        return NULL;
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
    return C;
}

/* Where each spring's blocks, each DOF's diagonal entry lie in s->C, and its half-bandwidth. */
static void block_map(solver *s)
{
    const cf_lattice *lat = s->lat;
    const size_t n = s->ndof;
    for (size_t q = 0; q < lat->ns; q++) {
        uint32_t i = lat->si[q], j = lat->sj[q];
        const long ri[3] = {s->eq[3 * i], s->eq[3 * i + 1], s->eq[3 * i + 2]};
        const long rj[3] = {s->eq[3 * j], s->eq[3 * j + 1], s->eq[3 * j + 2]};
        int *m = s->map + q * 36;
        for (int b = 0; b < 3; b++) {
            int pos[4][3]; /* block (i, i), (j, j), (i, j), (j, i): rows a of column b */
            ccs_index3(s->C, ri, ri[b], pos[0]);
            ccs_index3(s->C, rj, rj[b], pos[1]);
            ccs_index3(s->C, ri, rj[b], pos[2]);
            ccs_index3(s->C, rj, ri[b], pos[3]);
            for (int a = 0; a < 3; a++)
                for (int blk = 0; blk < 4; blk++)
                    m[9 * blk + a * 3 + b] = pos[blk][a];
        }
    }
    for (size_t e = 0; e < n; e++)
        s->diag[e] = ccs_index(s->C, (long)e, (long)e);
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    for (size_t c = 0; s->vmap && c < nc; c++) {
        uint32_t node[8];
        cf_lattice_cell_nodes(lat, c, node);
        for (int a = 0; a < 8; a++) {
            const long ra[3] = {s->eq[3 * node[a]], s->eq[3 * node[a] + 1],
                                s->eq[3 * node[a] + 2]};
            for (int b = 0; b < 8; b++)
                for (int k = 0; k < 3; k++) {
                    int pos[3];
                    ccs_index3(s->C, ra, s->eq[3 * node[b] + k], pos);
                    for (int i = 0; i < 3; i++)
                        s->vmap[((c * 8 + (size_t)a) * 8 + (size_t)b) * 9 + (size_t)(i * 3 + k)] =
                            pos[i];
                }
        }
    }
    s->band = 0;
    for (size_t col = 0; col < n; col++)
        for (int k = s->C->p[col]; k < s->C->p[col + 1]; k++) {
            size_t row = (size_t)s->C->i[k];
            size_t off = row > col ? row - col : col - row;
            if (off > s->band)
                s->band = off;
        }
}

/* The sparsity pattern of the tangent, built once: for every spring the positions in C->data of
** its four 3 x 3 blocks (ii, jj, ij, ji), so that assembly is a pass of additions. */
static cf_status build_pattern(solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const size_t n = s->ndof;
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
    int bad = node_adjacency(lat, adj, deg);
    gsl_spmatrix *C = bad ? NULL : pattern_matrix(s, adj, deg, colp);
    free(adj);
    free(deg);
    free(colp);
    s->C = C;
    s->map = malloc((lat->ns ? lat->ns : 1) * 36 * sizeof(int));
    s->diag = malloc((n ? n : 1) * sizeof(int));
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    if (lat->cfg.volume_modulus_MPa != 0)
        s->vmap = malloc(nc * 8 * 8 * 9 * sizeof(int));
    if (!s->C || !s->map || !s->diag || (lat->cfg.volume_modulus_MPa != 0 && !s->vmap))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    block_map(s);
    return CF_OK;
}

/* ---- the factorisations ---------------------------------------------------------------------- */

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
static int chol_direction(solver *s, int *fatal, cf_error *err)
{
    const size_t n = s->ndof;
    gsl_spmatrix *C = s->C;
    *fatal = 0;
    s->chol_ready = 0;
    if (s->chol_failed || n == 0)
        return 0;
    cf_error lerr = {0};
    if (!s->chol) {
        cf_status cs = cf_sparse_chol_create(&s->chol, n, C->p, C->i, &lerr);
        if (cs == CF_E_INTERNAL) { /* out of memory: a fallback would only run out later */
            *fatal = 1;
            cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
            return 0;
        }
        if (cs != CF_OK) {
            s->chol_failed = 1;
            return 0;
        }
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
int cf_linsolve_chord(solver *s, int *fatal, cf_error *err)
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
    if (b + 1 > n || (double)n * (double)(b + 1) > CF_LINSOLVE_BAND_MAX_ENTRIES)
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
** took several (measured on the 3x3x3 hysteresis scene: 18 s before; src/notes/performance.md). */
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

/* ---- assembly and the cascade ---------------------------------------------------------------- */

/* The volume term's tangent added into v: per cell, kappa/H^3 g_a g_b^T + kappa (J - 1) d2V/dx_a
** dx_b (W = (kappa/2)(J - 1)^2 H^3, J = V/H^3, g = dV/dx). */
static void volume_tangent(solver *s, double *v)
{
    const cf_lattice *lat = s->lat;
    const double kappa = lat->cfg.volume_modulus_MPa, H = lat->H_mm, V0 = H * H * H;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    double hess[8][8][3][3]; /* 4.6 kB */
    for (size_t c = 0; c < nc; c++) {
        uint32_t node[8];
        double g[8][3];
        const double J = cf_lattice_cell_volume(lat, c, node, g, hess);
        for (int a = 0; a < 8; a++)
            for (int b = 0; b < 8; b++)
                for (int i = 0; i < 3; i++)
                    for (int k = 0; k < 3; k++) {
                        const int at =
                            s->vmap[((c * 8 + (size_t)a) * 8 + (size_t)b) * 9 + (size_t)(i * 3 + k)];
                        if (at >= 0)
                            v[at] += kappa / V0 * g[a][i] * g[b][k] +
                                     kappa * (J - 1) * hess[a][b][i][k];
                    }
    }
}

/* Adds the tangent K = -dR/dx at the state of the last cf_msm_residual() into v (C's pattern,
** zeroed first), unscaled. */
static void assemble_values(solver *s, double *v)
{
    cf_lattice *lat = s->lat;
    memset(v, 0, (size_t)s->C->p[s->ndof] * sizeof(double));
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
                    v[m[k]] += B;
                if (m[k + 9] >= 0)
                    v[m[k + 9]] += B;
                if (m[k + 18] >= 0)
                    v[m[k + 18]] -= B;
                if (m[k + 27] >= 0)
                    v[m[k + 27]] -= B;
            }
    }
    if (lat->cfg.volume_modulus_MPa != 0)
        volume_tangent(s, v);
}

/* v <- D^-1 v D^-1 with D = s->D (C's pattern). */
static void scale_values(const solver *s, double *v)
{
    const gsl_spmatrix *C = s->C;
    for (size_t col = 0; col < s->ndof; col++)
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            v[k] /= s->D[C->i[k]] * s->D[col];
}

/* Assembles the tangent at the state of the last cf_msm_residual() into s->C (its pattern built on
** first use) and scales it symmetrically, K' = D^-1 K D^-1 with D = sqrt|diag| in s->D (a
** congruence: the inertia is that of K). */
static cf_status assemble(solver *s, cf_error *err)
{
    const size_t n = s->ndof;
    if (!s->C && build_pattern(s, err) != CF_OK)
        return CF_E_INTERNAL;
    gsl_spmatrix *C = s->C;
    assemble_values(s, C->data);
    for (size_t e = 0; e < n; e++) {
        double d = C->data[s->diag[e]];
        s->D[e] = (d != 0 && isfinite(d)) ? sqrt(fabs(d)) : 1.0;
    }
    scale_values(s, C->data);
    return CF_OK;
}

void cf_linsolve_tangent_scaled(solver *s, double *v)
{
    assemble_values(s, v);
    scale_values(s, v);
}

/* Restarted GMRES on the scaled tangent: the last resort of the cascade, for a system above
** CF_LINSOLVE_DENSE_MAX_DOF free DOFs that neither the sparse nor the banded factorisation solved. */
static cf_status gmres_direction(solver *s, cf_error *err)
{
    const size_t n = s->ndof;
    gsl_spmatrix *C = s->C;
    gsl_vector *b = gsl_vector_alloc(n), *xv = gsl_vector_calloc(n);
    size_t restart = n < CF_LINSOLVE_GMRES_RESTART ? n : CF_LINSOLVE_GMRES_RESTART;
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

/* Assembles and scales the tangent, then solves K dx = R for the Newton update: sparse Cholesky
** or L D L^T (unless cfg->banded_only), else banded LDL^T, dense LU for small systems, GMRES. */
static cf_status tangent_solve(solver *s, cf_error *err)
{
    if (assemble(s, err) != CF_OK)
        return CF_E_INTERNAL;
    int fatal = 0;
    s->neg_pivots = -1;
    if (!s->cfg->banded_only && chol_direction(s, &fatal, err))
        return CF_OK;

    if (fatal)
        return CF_E_INTERNAL;
    if (band_direction(s))
        return CF_OK;
    if (s->ndof <= CF_LINSOLVE_DENSE_MAX_DOF)
        return dense_direction(s, err);
    return gmres_direction(s, err);
}

cf_status cf_linsolve_direction(solver *s, cf_error *err)
{
    cf_status st = tangent_solve(s, err);
    note_inertia(s);
    return st;
}
