/*
** The tangent of the lattice solvers (see msm_internal.h): the sparsity pattern of K = -dR/dx over
** the free DOFs, built once from the springs and the cells of the volume term, with the Newton
** driver (mech.h) made on it, and its assembly into the values of the driver's linear solver
** (linsolve.h), which sees only the pattern and the values.
*/
#include "model/msm_tangent.h"
#include "model/msm_internal.h"
#include "model/lattice_cells.h"
#include "model/lattice_hourglass.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A pattern in compressed columns: the column starts p[n + 1], the rows i[p[n]], increasing
** within each column. */
typedef struct ccs {
    const int *p, *i;
} ccs;

/* Index of entry (row, col) in the compressed-column pattern C, or -1. */
static int ccs_index(const ccs *C, long row, long col)
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
static void ccs_index3(const ccs *C, const long rows[3], long col, int out[3])
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

/* Whether the cells carry a tangent of their own: the volume term, the hourglass control or
** fibre groups. */
static int cells_couple(const cf_lattice *lat)
{
    return cf_lattice_has_cells(lat) || lat->cfg.nfibre > 0;
}

/* The pattern: each node couples with itself and the nodes it shares a spring or a cell with (at
** most 26), a 3 x 3 block each. */
enum { MAXADJ = CF_MSM_TANGENT_MAX_ADJ };

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
    /* the volume term, the hourglass control and the fibre groups couple every two nodes of a
    ** cell (a spring does unless its family's weight is 0) */
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    for (size_t c = 0; cells_couple(lat) && c < nc && !bad; c++) {
        uint32_t node[8];
        cf_lattice_cell_nodes(lat, c, node);
        for (int a = 0; a < 8 && !bad; a++)
            for (int b = 0; b < 8 && !bad; b++)
                bad = a != b && adjacent(adj, deg, node[a], node[b]);
    }
    return bad;
}

/* The compressed-column pattern of the free DOFs that adj couples: its n + 1 column starts into
** colp, its rows into *rowi (allocated here). 1 when out of memory. */
static int pattern(const solver *s, const uint32_t *adj, const unsigned char *deg, int *colp,
                   int **rowi)
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
    int *ri = malloc((nnz ? nnz : 1) * sizeof(int));
    if (!(*rowi = ri))
        return 1;
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
                        ri[at++] = (int)row;
                }
            /* rows in increasing order within the column (at most 81: insertion sort) */
            for (int x = colp[col] + 1; x < at; x++) {
                int v = ri[x], y = x - 1;
                for (; y >= colp[col] && ri[y] > v; y--)
                    ri[y + 1] = ri[y];
                ri[y + 1] = v;
            }
        }
    return 0;
}

/* Where each spring's blocks, and each cell's of the volume term, lie in the pattern C. */
static void block_map(solver *s, const ccs *C)
{
    const cf_lattice *lat = s->lat;
    for (size_t q = 0; q < lat->ns; q++) {
        uint32_t i = lat->si[q], j = lat->sj[q];
        const long ri[3] = {s->eq[3 * i], s->eq[3 * i + 1], s->eq[3 * i + 2]};
        const long rj[3] = {s->eq[3 * j], s->eq[3 * j + 1], s->eq[3 * j + 2]};
        int *m = s->map + q * 36;
        for (int b = 0; b < 3; b++) {
            int pos[4][3]; /* block (i, i), (j, j), (i, j), (j, i): rows a of column b */
            ccs_index3(C, ri, ri[b], pos[0]);
            ccs_index3(C, rj, rj[b], pos[1]);
            ccs_index3(C, ri, rj[b], pos[2]);
            ccs_index3(C, rj, ri[b], pos[3]);
            for (int a = 0; a < 3; a++)
                for (int blk = 0; blk < 4; blk++)
                    m[9 * blk + a * 3 + b] = pos[blk][a];
        }
    }
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
                    ccs_index3(C, ra, s->eq[3 * node[b] + k], pos);
                    for (int i = 0; i < 3; i++)
                        s->vmap[((c * 8 + (size_t)a) * 8 + (size_t)b) * 9 + (size_t)(i * 3 + k)] =
                            pos[i];
                }
        }
    }
}

/* The sparsity pattern of the tangent, built once, and the driver with the linear solver of that
** pattern; then for every spring the positions in the values of its four 3 x 3 blocks (ii, jj,
** ij, ji), and the volume term's, so that assembly is a pass of additions. */
cf_status cf_msm_tangent_build(solver *s, const cf_mech_ops *ops, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const size_t n = s->ndof;
    const size_t nn = lat->nn;
    uint32_t *adj = malloc((nn ? nn : 1) * MAXADJ * sizeof(uint32_t));
    unsigned char *deg = calloc(nn ? nn : 1, 1);
    int *colp = malloc((n + 1) * sizeof(int)), *rowi = NULL;
    if (!adj || !deg || !colp || node_adjacency(lat, adj, deg) ||
        pattern(s, adj, deg, colp, &rowi)) {
        free(adj);
        free(deg);
        free(colp);
        free(rowi);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    }
    free(adj);
    free(deg);
    s->nnz = (size_t)colp[n];
    cf_status st = cf_mech_create(&s->mech, n, 0, ops, s, colp, rowi, s->cfg->banded_only, err);
    free(colp);
    free(rowi);
    if (st != CF_OK)
        return st;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    s->map = malloc((lat->ns ? lat->ns : 1) * 36 * sizeof(int));
    if (cells_couple(lat))
        s->vmap = malloc(nc * 8 * 8 * 9 * sizeof(int));
    if (!s->map || (cells_couple(lat) && !s->vmap)) {
        free(s->map);
        free(s->vmap);
        s->map = s->vmap = NULL;
        cf_mech_free(&s->mech); /* built again on the next solve */
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent matrix");
    }
    ccs C;
    cf_linsolve_pattern(s->mech.ls, &C.p, &C.i);
    block_map(s, &C);
    return CF_OK;
}

/* Adds cell c's fibre groups' tangent to blk: the cell's F = sum_a x_a g_a^T (g_a the mean
** gradient of corner a's shape function, (2 xi_a - 1)/(4 H) per axis, as lattice.c's forces use),
** its force on corner a -H^3 P g_a, so K_(a i)(b k) = H^3 sum_jl A_ijkl g_a,j g_b,l with A the
** groups' dP/dF (fibre.h). A spring past solid adds nothing (the residual reports it). */
static void fibre_block(const cf_lattice *lat, size_t c, double blk[8][8][9])
{
    const double H = lat->H_mm, H3 = H * H * H;
    uint32_t node[8];
    double g[8][3], F[9] = {0}, A[81] = {0};
    cf_lattice_cell_nodes(lat, c, node);
    for (int a = 0; a < 8; a++)
        for (int j = 0; j < 3; j++)
            g[a][j] = (2.0 * ((a >> j) & 1) - 1) / (4 * H);
    for (int a = 0; a < 8; a++) {
        const double x[3] = {lat->x[node[a]], lat->y[node[a]], lat->z[node[a]]};
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                F[3 * i + j] += x[i] * g[a][j];
    }
    for (int k = 0; k < lat->cfg.nfibre; k++)
        (void)cf_fibre_add_tangent(&lat->cfg.fibre[k], H, F, A, NULL);
    /* Ag[i][k][a][l] = sum_j A_ijkl g_a,j, then the blocks */
    double Ag[3][3][8][3] = {{{{0}}}};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 8; a++)
                for (int l = 0; l < 3; l++)
                    for (int j = 0; j < 3; j++)
                        Ag[i][k][a][l] += A[27 * i + 9 * j + 3 * k + l] * g[a][j];
    for (int a = 0; a < 8; a++)
        for (int b = 0; b < 8; b++)
            for (int i = 0; i < 3; i++)
                for (int k = 0; k < 3; k++)
                    blk[a][b][i * 3 + k] += H3 * (Ag[i][k][a][0] * g[b][0] +
                                                  Ag[i][k][a][1] * g[b][1] +
                                                  Ag[i][k][a][2] * g[b][2]);
}

/* The cells' tangent added into v: per cell, the volume term's kappa/H^3 g_a g_b^T + kappa (J - 1)
** d2V/dx_a dx_b (W = (kappa/2)(J - 1)^2 H^3, J = V/H^3, g = dV/dx), the fibre groups'
** (fibre_block) and the hourglass control's constant k_h coef(a, b) I (lattice_hourglass.h). In a
** homogeneous state (s->homogeneous) every cell has the first one's J, g, d2V/dx2 and F (they
** depend on the differences of its corners only), so its block is computed once (the same
** operations, so the same values as each cell's own). */
static void cell_tangent(solver *s, double *v)
{
    const cf_lattice *lat = s->lat;
    const double kappa = lat->cfg.volume_modulus_MPa, H = lat->H_mm, V0 = H * H * H;
    const double kh = lat->hg_k_N_per_mm;
    const int fib = lat->cfg.nfibre > 0;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    double hess[8][8][3][3]; /* 4.6 kB */
    double hg[8][8], blk[8][8][9];
    for (int a = 0; a < 8; a++)
        for (int b = 0; b < 8; b++)
            hg[a][b] = kh * cf_hourglass_coef(a, b);
    double g[8][3] = {{0}}, J = 1.0;
    for (size_t c = 0; c < nc; c++) {
        uint32_t node[8];
        const int fresh = c == 0 || !s->homogeneous;
        if (kappa != 0 && fresh)
            J = cf_lattice_cell_volume(lat, c, node, g, hess);
        for (int a = 0; (kappa != 0 || fib) && fresh && a < 8; a++)
            for (int b = 0; b < 8; b++)
                for (int i = 0; i < 3; i++)
                    for (int k = 0; k < 3; k++)
                        blk[a][b][i * 3 + k] = kappa == 0 ? 0.0
                                                          : kappa / V0 * g[a][i] * g[b][k] +
                                                                kappa * (J - 1) * hess[a][b][i][k];
        if (fib && fresh)
            fibre_block(lat, c, blk);
        const int *vm = s->vmap + c * 8 * 8 * 9;
        for (int a = 0; a < 8; a++)
            for (int b = 0; b < 8; b++)
                for (int e = 0; e < 9; e++) {
                    const int at = vm[(a * 8 + b) * 9 + e];
                    if (at < 0)
                        continue;
                    if (kappa != 0 || fib)
                        v[at] += blk[a][b][e];
                    if (e % 4 == 0) /* i == k */
                        v[at] += hg[a][b];
                }
    }
}

/* The tangent K = -dR/dx at the state of the last cf_msm_residual() into v (the pattern of
** cf_msm_tangent_build), unscaled: the matrix of the linear solver (linsolve.h). */
void cf_msm_tangent_fill(void *ctx, double *v)
{
    solver *s = ctx;
    cf_lattice *lat = s->lat;
    memset(v, 0, s->nnz * sizeof(double));
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
    if (cells_couple(lat))
        cell_tangent(s, v);
}
