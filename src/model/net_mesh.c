/*
** The tetrahedral mesh's generator of a net (net.h, cf_net_mesh): the mesh's edges as springs and
** their calibration, per tetrahedron the edge stiffnesses whose spring tensor best matches an
** isotropic one, the whole network scaled to the law's shear modulus (body.h).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"
#include "model/net.h"

double cf_body_mu_of_law(const cf_law *law)
{
    return law->k0_N_per_mm / law->p.H_mm / 2.5; /* E0 = k0/H at nu = 1/4 (calibration.h) */
}


/* The six edges of a tetrahedron, as pairs of its corners. */
static const int tet_edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a;
}

static size_t edge_find(const uint64_t *keys, size_t n, uint64_t k)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (keys[mid] < k)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Solves the symmetric positive definite n x n system A x = r (row-major, destroyed) by
** Gaussian elimination; returns 0 when a pivot is not positive. */
static int spd_solve(double *A, double *r, int n)
{
    for (int k = 0; k < n; k++) {
        if (!(A[k * n + k] > 0))
            return 0;
        for (int i = k + 1; i < n; i++) {
            double f = A[i * n + k] / A[k * n + k];
            for (int j = k; j < n; j++)
                A[i * n + j] -= f * A[k * n + j];
            r[i] -= f * r[k];
        }
    }
    for (int k = n - 1; k >= 0; k--) {
        double s = r[k];
        for (int j = k + 1; j < n; j++)
            s -= A[k * n + j] * r[j];
        r[k] = s / A[k * n + k];
    }
    return 1;
}

/* The 15 monomials n_x^a n_y^b n_z^c of degree 4: a fully symmetric fourth-order tensor has one
** component each, appearing 4!/(a! b! c!) times. */
static int mono[15][3];
static double mono_mult[15], mono_iso[15];

static void mono_init(void)
{
    static const double fact[5] = {1, 1, 2, 6, 24};
    int m = 0;
    for (int a = 4; a >= 0; a--)
        for (int bb = 4 - a; bb >= 0; bb--) {
            int c = 4 - a - bb;
            mono[m][0] = a;
            mono[m][1] = bb;
            mono[m][2] = c;
            mono_mult[m] = 24 / (fact[a] * fact[bb] * fact[c]);
            /* mu (d_ij d_kl + d_ik d_jl + d_il d_jk) in units of mu: 3 for iiii, 1 for iijj */
            mono_iso[m] = (a == 4 || bb == 4 || c == 4) ? 3
                          : ((a == 2 || a == 0) && (bb == 2 || bb == 0) && (c == 2 || c == 0)) ? 1
                                                                                               : 0;
            m++;
        }
}

static double ipow(double x, int p)
{
    double r = 1;
    while (p-- > 0)
        r *= x;
    return r;
}

/* The six edge stiffnesses k[6] >= 0 (N/mm, per unit mu) of tetrahedron v whose spring tensor
** (1/V) sum k L^2 n n n n best matches the isotropic tensor of lambda = mu = 1 (weighted least
** squares over the 15 components; edges whose stiffness would be negative are dropped, one at a
** time, the most negative first). */
static void tet_springs(const double *X, const uint32_t *v, double V, double k[6])
{
    double A[15][6], t[15];
    for (int e = 0; e < 6; e++) {
        const double *p = X + 3 * v[tet_edge[e][0]], *q = X + 3 * v[tet_edge[e][1]];
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int m = 0; m < 15; m++)
            A[m][e] = sqrt(mono_mult[m]) * ipow(d[0] / L, mono[m][0]) * ipow(d[1] / L, mono[m][1]) *
                      ipow(d[2] / L, mono[m][2]) * L * L / V;
    }
    for (int m = 0; m < 15; m++)
        t[m] = sqrt(mono_mult[m]) * mono_iso[m];
    int on[6] = {1, 1, 1, 1, 1, 1};
    for (int round = 0; round < 6; round++) {
        int idx[6], n = 0;
        for (int e = 0; e < 6; e++)
            if (on[e])
                idx[n++] = e;
        double N[36], r[6];
        for (int i = 0; i < n; i++) {
            r[i] = 0;
            for (int m = 0; m < 15; m++)
                r[i] += A[m][idx[i]] * t[m];
            for (int j = 0; j < n; j++) {
                double s = 0;
                for (int m = 0; m < 15; m++)
                    s += A[m][idx[i]] * A[m][idx[j]];
                N[i * n + j] = s;
            }
        }
        for (int e = 0; e < 6; e++)
            k[e] = 0;
        if (n == 0 || !spd_solve(N, r, n))
            return;
        int worst = -1;
        for (int i = 0; i < n; i++) {
            k[idx[i]] = r[i];
            if (r[i] < 0 && (worst < 0 || r[i] < k[worst]))
                worst = idx[i];
        }
        if (worst < 0)
            return;
        on[worst] = 0;
    }
}

/* The springs' weights: the stiffnesses of every tetrahedron's matching summed per edge (keys: the
** ns sorted edges), scaled so that the isotropic part of the network's tensor has the law's shear
** modulus, k = w k0 H / L0. 0, or -1 when the matching finds no stiffness. */
static int calibrate(cf_net *n, const cf_mesh *m, const uint64_t *keys, const cf_law *law)
{
    mono_init();
    double Vtot = 0;
    for (size_t t = 0; t < m->nt; t++) {
        double k[6];
        const uint32_t *v = m->tet + 4 * t;
        const double V =
            body_vol6(n->X + 3 * v[0], n->X + 3 * v[1], n->X + 3 * v[2], n->X + 3 * v[3]) / 6;
        tet_springs(n->X, v, V, k);
        Vtot += V;
        for (int e = 0; e < 6; e++)
            n->w[edge_find(keys, n->ns, edge_key(v[tet_edge[e][0]], v[tet_edge[e][1]]))] += k[e];
    }
    /* the isotropic part of the whole network's tensor (1/Vtot) sum k L^2 nnnn: for a fully
    ** symmetric tensor its shear modulus is the full trace over 15 */
    double trace = 0;
    for (size_t s = 0; s < n->ns; s++)
        trace += n->w[s] * n->L0_mm[s] * n->L0_mm[s];
    const double mu = cf_body_mu_of_law(law), mu_net = trace / (15 * Vtot);
    if (!(mu_net > 0) || !(mu > 0))
        return -1;
    const double g = mu / mu_net, H = law->p.H_mm, k0 = law->k0_N_per_mm;
    for (size_t s = 0; s < n->ns; s++)
        n->w[s] *= g * n->L0_mm[s] / (k0 * H); /* k = w k0 H / L0 */
    return 0;
}

cf_status cf_net_mesh(cf_net *n, const cf_mesh *m, const cf_law *law, cf_error *err)
{
    memset(n, 0, sizeof *n);
    n->nn = m->nn;
    n->nc = m->nt;
    n->cell_kind = CF_NET_TET4;
    uint64_t *keys = malloc((m->nt ? 6 * m->nt : 1) * sizeof *keys);
    n->X = malloc(3 * m->nn * sizeof *n->X);
    n->fix = calloc(m->nn, 1);
    n->cell = malloc(4 * m->nt * sizeof *n->cell);
    if (!keys || !n->X || !n->fix || !n->cell)
        goto oom;
    memcpy(n->X, m->X, 3 * m->nn * sizeof *n->X);
    memcpy(n->cell, m->tet, 4 * m->nt * sizeof *n->cell);
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tet + 4 * t;
        for (int e = 0; e < 6; e++)
            keys[6 * t + e] = edge_key(v[tet_edge[e][0]], v[tet_edge[e][1]]);
    }
    qsort(keys, 6 * m->nt, sizeof *keys, cmp_u64);
    size_t ns = 0;
    for (size_t i = 0; i < 6 * m->nt; i++)
        if (i == 0 || keys[i] != keys[ns - 1])
            keys[ns++] = keys[i];
    n->ns = ns;
    n->si = malloc(ns * sizeof *n->si);
    n->sj = malloc(ns * sizeof *n->sj);
    n->L0_mm = malloc(ns * sizeof *n->L0_mm);
    n->w = calloc(ns, sizeof *n->w);
    if (!n->si || !n->sj || !n->L0_mm || !n->w)
        goto oom;
    for (size_t s = 0; s < ns; s++) {
        n->si[s] = (uint32_t)(keys[s] >> 32);
        n->sj[s] = (uint32_t)(keys[s] & 0xffffffffu);
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = n->X[3 * n->sj[s] + k] - n->X[3 * n->si[s] + k];
            d2 += d * d;
        }
        n->L0_mm[s] = sqrt(d2);
    }
    if (calibrate(n, m, keys, law) != 0) {
        free(keys);
        cf_net_free(n);
        return cf_error_set(err, CF_E_DATA, "body: the calibration found no stiffness");
    }
    free(keys);
    return CF_OK;
oom:
    free(keys);
    cf_net_free(n);
    return cf_error_set(err, CF_E_INTERNAL, "out of memory for a body of %zu nodes", m->nn);
}
