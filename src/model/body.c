/*
** Tissue bodies (body.h): the springs on the edges of a tetrahedral mesh and their calibration,
** the volume term, and the static probe solve (Newton's method on the sparse tangent).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conifit/body.h"
#include "model/sparse_chol.h"

void cf_body_free(cf_body *b)
{
    if (!b)
        return;
    free(b->X);
    free(b->x);
    free(b->fix);
    free(b->tet);
    free(b->V0);
    free(b->si);
    free(b->sj);
    free(b->L0);
    free(b->c);
    memset(b, 0, sizeof *b);
}

double cf_body_mu_of_law(const cf_law *law)
{
    return law->k0_N_per_mm / law->p.H_mm / 2.5; /* E0 = k0/H at nu = 1/4 (calibration.h) */
}

double cf_body_kappa_for_nu(double mu_MPa, double nu)
{
    return mu_MPa * (4 * nu - 1) / (1 - 2 * nu);
}

static double vol6(const double *a, const double *b, const double *c, const double *d)
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
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

cf_status cf_body_create(cf_body *b, const cf_mesh *m, const cf_law *law, cf_law_method method,
                         double kappa_MPa, cf_error *err)
{
    memset(b, 0, sizeof *b);
    if (!isfinite(kappa_MPa) || kappa_MPa < 0)
        return cf_error_set(err, CF_E_DATA, "body: volume modulus %g MPa: must be finite and >= 0",
                            kappa_MPa);
    b->law = law;
    b->method = method;
    b->nn = m->nn;
    b->nt = m->nt;
    uint64_t *keys = malloc(6 * m->nt * sizeof *keys);
    b->X = malloc(3 * m->nn * sizeof *b->X);
    b->x = malloc(3 * m->nn * sizeof *b->x);
    b->fix = calloc(m->nn, 1);
    b->tet = malloc(4 * m->nt * sizeof *b->tet);
    b->V0 = malloc(m->nt * sizeof *b->V0);
    if (!keys || !b->X || !b->x || !b->fix || !b->tet || !b->V0)
        goto oom;
    memcpy(b->X, m->X, 3 * m->nn * sizeof *b->X);
    memcpy(b->x, m->X, 3 * m->nn * sizeof *b->x);
    memcpy(b->tet, m->tet, 4 * m->nt * sizeof *b->tet);
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tet + 4 * t;
        b->V0[t] = vol6(b->X + 3 * v[0], b->X + 3 * v[1], b->X + 3 * v[2], b->X + 3 * v[3]) / 6;
        for (int e = 0; e < 6; e++)
            keys[6 * t + e] = edge_key(v[tet_edge[e][0]], v[tet_edge[e][1]]);
    }
    qsort(keys, 6 * m->nt, sizeof *keys, cmp_u64);
    size_t ns = 0;
    for (size_t i = 0; i < 6 * m->nt; i++)
        if (i == 0 || keys[i] != keys[ns - 1])
            keys[ns++] = keys[i];
    b->ns = ns;
    b->si = malloc(ns * sizeof *b->si);
    b->sj = malloc(ns * sizeof *b->sj);
    b->L0 = malloc(ns * sizeof *b->L0);
    b->c = calloc(ns, sizeof *b->c);
    if (!b->si || !b->sj || !b->L0 || !b->c)
        goto oom;
    double Lsum = 0;
    for (size_t s = 0; s < ns; s++) {
        b->si[s] = (uint32_t)(keys[s] >> 32);
        b->sj[s] = (uint32_t)(keys[s] & 0xffffffffu);
        double d2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = b->X[3 * b->sj[s] + k] - b->X[3 * b->si[s] + k];
            d2 += d * d;
        }
        b->L0[s] = sqrt(d2);
        Lsum += b->L0[s];
    }
    b->mean_edge_mm = Lsum / (double)ns;
    /* per-tetrahedron matching (stiffnesses per unit mu collected in c for now) */
    mono_init();
    double Vtot = 0;
    for (size_t t = 0; t < m->nt; t++) {
        double k[6];
        const uint32_t *v = m->tet + 4 * t;
        tet_springs(b->X, v, b->V0[t], k);
        Vtot += b->V0[t];
        for (int e = 0; e < 6; e++)
            b->c[edge_find(keys, ns, edge_key(v[tet_edge[e][0]], v[tet_edge[e][1]]))] += k[e];
    }
    /* the isotropic part of the whole network's tensor (1/Vtot) sum k L^2 nnnn: for a fully
    ** symmetric tensor its shear modulus is the full trace over 15 */
    double trace = 0;
    for (size_t s = 0; s < ns; s++)
        trace += b->c[s] * b->L0[s] * b->L0[s];
    const double mu = cf_body_mu_of_law(law), mu_net = trace / (15 * Vtot);
    if (!(mu_net > 0) || !(mu > 0))
        goto bad;
    const double g = mu / mu_net, H = law->p.H_mm, k0 = law->k0_N_per_mm;
    for (size_t s = 0; s < ns; s++)
        b->c[s] *= g * b->L0[s] / (k0 * H); /* k = c k0 H / L0 */
    b->mu_MPa = mu;
    b->kappa_MPa = kappa_MPa;
    const double lam = mu + kappa_MPa;
    b->E_MPa = mu * (3 * lam + 2 * mu) / (lam + mu);
    b->nu = lam / (2 * (lam + mu));
    free(keys);
    return CF_OK;
bad:
    free(keys);
    cf_body_free(b);
    return cf_error_set(err, CF_E_DATA, "body: the calibration found no stiffness");
oom:
    free(keys);
    cf_body_free(b);
    return cf_error_set(err, CF_E_INTERNAL, "out of memory for a body of %zu nodes", m->nn);
}

/* A spring's length, unit axis (from i to j) and law compression at positions x. */
static double spring_geom(const cf_body *b, const double *x, size_t s, double n[3], double *u)
{
    const double *p = x + 3 * b->si[s], *q = x + 3 * b->sj[s];
    double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++)
        n[k] = d[k] / L;
    *u = b->law->p.H_mm * (b->L0[s] - L) / b->L0[s];
    return L;
}

double cf_body_measure(const cf_body *b, cf_body_state *st, double *max_u_over_travel)
{
    double umax = 0, minJ = INFINITY;
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u;
        double L = spring_geom(b, b->x, s, n, &u);
        umax = fmax(umax, fabs(u) / b->law->travel_mm);
        if (st) {
            st->strain[s] = (L - b->L0[s]) / b->L0[s];
            st->solid[s] = fabs(u) >= b->law->travel_mm;
        }
    }
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        double J = vol6(b->x + 3 * v[0], b->x + 3 * v[1], b->x + 3 * v[2], b->x + 3 * v[3]) /
                   (6 * b->V0[t]);
        if (st)
            st->J[t] = J;
        minJ = fmin(minJ, J);
    }
    if (max_u_over_travel)
        *max_u_over_travel = umax;
    return minJ;
}

/* Penetration of the node at p into the probe whose reference point is at c, and the unit
** direction in which the probe pushes it. With signed = 0: 0 when the node is outside. With
** signed = 1 (a node of the active set): the signed depth along that direction, negative when the
** node has left the probe's surface. */
static double penetration(const cf_probe *pr, const double *c, const double *p, double nrm[3],
                          int sgn)
{
    double r[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    if (pr->shape == CF_PROBE_SPHERE) {
        double d = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if ((!sgn && !(d < pr->radius_mm)) || d == 0)
            return 0;
        for (int k = 0; k < 3; k++)
            nrm[k] = r[k] / d;
        return pr->radius_mm - d;
    }
    double s = r[0] * pr->dir[0] + r[1] * pr->dir[1] + r[2] * pr->dir[2];
    for (int k = 0; k < 3; k++)
        nrm[k] = pr->dir[k];
    if (sgn)
        return -s;
    if (!(s < 0))
        return 0;
    double rad2 = 0;
    for (int k = 0; k < 3; k++) {
        double q = r[k] - s * pr->dir[k];
        rad2 += q * q;
    }
    if (!(rad2 < pr->radius_mm * pr->radius_mm))
        return 0;
    return -s;
}

long cf_body_probe_inside(const cf_body *b, const cf_probe *probe)
{
    double nrm[3];
    for (size_t i = 0; i < b->nn; i++)
        if (penetration(probe, probe->center_mm, b->X + 3 * i, nrm, 0) > 0)
            return (long)i;
    return -1;
}

/* The sparse pattern of the tangent: 3 x 3 blocks for every node with itself and with every node
** it shares a spring with (a tetrahedron's four nodes are all joined by springs). */
typedef struct pattern {
    size_t n;              /* 3 nn */
    int *colptr, *rowidx;
    double *val;
    size_t *pos_ii;        /* per node: offset of its own block in its column */
    size_t *pos_ij, *pos_ji; /* per spring: block (si row, sj col) and (sj row, si col) */
} pattern;

static void pattern_free(pattern *P)
{
    free(P->colptr);
    free(P->rowidx);
    free(P->val);
    free(P->pos_ii);
    free(P->pos_ij);
    free(P->pos_ji);
}

static int pattern_build(const cf_body *b, pattern *P)
{
    memset(P, 0, sizeof *P);
    const size_t nn = b->nn;
    size_t *deg = calloc(nn + 1, sizeof *deg), *fillp = NULL;
    P->n = 3 * nn;
    P->colptr = malloc((3 * nn + 1) * sizeof *P->colptr);
    P->pos_ii = malloc(nn * sizeof *P->pos_ii);
    P->pos_ij = malloc(b->ns * sizeof *P->pos_ij);
    P->pos_ji = malloc(b->ns * sizeof *P->pos_ji);
    if (!deg || !P->colptr || !P->pos_ii || !P->pos_ij || !P->pos_ji)
        goto fail;
    for (size_t s = 0; s < b->ns; s++) {
        deg[b->si[s]]++;
        deg[b->sj[s]]++;
    }
    /* column 3j + c holds 3 (deg_j + 1) rows: node j's block first, then its neighbours' */
    size_t nnz = 0;
    P->colptr[0] = 0;
    for (size_t j = 0; j < nn; j++)
        for (int c = 0; c < 3; c++) {
            nnz += 3 * (deg[j] + 1);
            if (nnz > 2147483647u)
                goto fail;
            P->colptr[3 * j + c + 1] = (int)nnz;
        }
    P->rowidx = malloc(nnz * sizeof *P->rowidx);
    P->val = malloc(nnz * sizeof *P->val);
    fillp = calloc(nn, sizeof *fillp); /* blocks placed so far in each node's columns */
    if (!P->rowidx || !P->val || !fillp)
        goto fail;
    for (size_t j = 0; j < nn; j++) {
        P->pos_ii[j] = 0;
        for (int c = 0; c < 3; c++)
            for (int a = 0; a < 3; a++)
                P->rowidx[P->colptr[3 * j + c] + a] = (int)(3 * j + a);
        fillp[j] = 1;
    }
    for (size_t s = 0; s < b->ns; s++) {
        size_t i = b->si[s], j = b->sj[s];
        size_t bj = fillp[j]++, bi = fillp[i]++;
        P->pos_ij[s] = bj; /* row node i in column node j */
        P->pos_ji[s] = bi;
        for (int c = 0; c < 3; c++)
            for (int a = 0; a < 3; a++) {
                P->rowidx[P->colptr[3 * j + c] + 3 * bj + a] = (int)(3 * i + a);
                P->rowidx[P->colptr[3 * i + c] + 3 * bi + a] = (int)(3 * j + a);
            }
    }
    free(deg);
    free(fillp);
    return 1;
fail:
    free(deg);
    free(fillp);
    pattern_free(P);
    return 0;
}

/* Adds the 3 x 3 block B (row-major) to block `blk` of node col's columns. */
static void add_block(pattern *P, size_t col, size_t blk, const double B[9])
{
    for (int c = 0; c < 3; c++) {
        double *v = P->val + P->colptr[3 * col + c] + 3 * blk;
        for (int a = 0; a < 3; a++)
            v[a] += B[3 * a + c];
    }
}

/* Energy gradient g (3 nn) and, when P is not NULL, the tangent at positions x; contact forces of
** the probe at c added (as -f to g) with their tangent. Returns the reaction along the probe's
** direction and the number of nodes in contact. */
static double assemble(const cf_body *b, const double *x, const cf_probe *pr, const double *c,
                       double kp, const uint8_t *active, double *g, pattern *P, int *contacts)
{
    const cf_law *law = b->law;
    const double H = law->p.H_mm;
    memset(g, 0, 3 * b->nn * sizeof *g);
    if (P)
        memset(P->val, 0, (size_t)P->colptr[P->n] * sizeof *P->val);
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u, k;
        double L = spring_geom(b, x, s, n, &u);
        double F = cf_law_force(law, b->method, u, &k, NULL);
        double T = -b->c[s] * F; /* tension */
        size_t i = b->si[s], j = b->sj[s];
        for (int a = 0; a < 3; a++) {
            g[3 * i + a] -= T * n[a];
            g[3 * j + a] += T * n[a];
        }
        if (!P)
            continue;
        double kax = b->c[s] * k * H / b->L0[s], geo = T / L, B[9], Bn[9];
        for (int a = 0; a < 3; a++)
            for (int q = 0; q < 3; q++) {
                B[3 * a + q] = (kax - geo) * n[a] * n[q] + (a == q ? geo : 0);
                Bn[3 * a + q] = -B[3 * a + q];
            }
        add_block(P, i, P->pos_ii[i], B);
        add_block(P, j, P->pos_ii[j], B);
        add_block(P, j, P->pos_ij[s], Bn);
        add_block(P, i, P->pos_ji[s], Bn);
    }
    if (b->kappa_MPa > 0)
        for (size_t t = 0; t < b->nt; t++) {
            const uint32_t *v = b->tet + 4 * t;
            const double *p0 = x + 3 * v[0];
            double e[3][3], dV[4][3];
            for (int m = 0; m < 3; m++)
                for (int a = 0; a < 3; a++)
                    e[m][a] = x[3 * v[m + 1] + a] - p0[a];
            for (int m = 0; m < 3; m++) {
                const double *p = e[(m + 1) % 3], *q = e[(m + 2) % 3];
                dV[m + 1][0] = (p[1] * q[2] - p[2] * q[1]) / 6;
                dV[m + 1][1] = (p[2] * q[0] - p[0] * q[2]) / 6;
                dV[m + 1][2] = (p[0] * q[1] - p[1] * q[0]) / 6;
            }
            for (int a = 0; a < 3; a++)
                dV[0][a] = -(dV[1][a] + dV[2][a] + dV[3][a]);
            double V = e[0][0] * dV[1][0] + e[0][1] * dV[1][1] + e[0][2] * dV[1][2];
            double J = V / b->V0[t], f = b->kappa_MPa * (J - 1);
            for (int m = 0; m < 4; m++)
                for (int a = 0; a < 3; a++)
                    g[3 * v[m] + a] += f * dV[m][a];
            if (!P)
                continue;
            /* the Gauss-Newton part kappa/V0 dV dV^T (the term in (J - 1) d2V is left out:
            ** Newton then converges linearly where J is far from 1, still to the same state) */
            const double kk = b->kappa_MPa / b->V0[t];
            for (int m = 0; m < 4; m++)
                for (int q = 0; q < 4; q++) {
                    double B[9];
                    for (int a = 0; a < 3; a++)
                        for (int r = 0; r < 3; r++)
                            B[3 * a + r] = kk * dV[m][a] * dV[q][r];
                    size_t col = v[q], row = v[m], blk = SIZE_MAX;
                    if (row == col) {
                        blk = P->pos_ii[col];
                    } else {
                        /* the block of the spring between row and col */
                        int *ri = P->rowidx + P->colptr[3 * col];
                        size_t nb = (size_t)(P->colptr[3 * col + 1] - P->colptr[3 * col]) / 3;
                        for (size_t k2 = 1; k2 < nb; k2++)
                            if ((size_t)ri[3 * k2] == 3 * row) {
                                blk = k2;
                                break;
                            }
                    }
                    if (blk != SIZE_MAX)
                        add_block(P, col, blk, B);
                }
        }
    double force = 0;
    int nc = 0;
    if (pr && c && active)
        for (size_t i = 0; i < b->nn; i++) {
            if (!active[i])
                continue;
            double nrm[3], d = penetration(pr, c, x + 3 * i, nrm, 1);
            nc++;
            for (int a = 0; a < 3; a++)
                g[3 * i + a] -= kp * d * nrm[a];
            force += kp * d * (nrm[0] * pr->dir[0] + nrm[1] * pr->dir[1] + nrm[2] * pr->dir[2]);
            if (!P)
                continue;
            double B[9], curv = 0;
            if (pr->shape == CF_PROBE_SPHERE)
                curv = d / fmax(pr->radius_mm - d, 1e-12 * pr->radius_mm); /* (R - r)/r: the normal turns as the node moves */
            for (int a = 0; a < 3; a++)
                for (int q = 0; q < 3; q++)
                    B[3 * a + q] = kp * ((1 + curv) * nrm[a] * nrm[q] - (a == q ? curv : 0));
            add_block(P, i, P->pos_ii[i], B);
        }
    if (contacts)
        *contacts = nc;
    return force;
}

/* Zeroes the rows and columns of fixed components (diagonal 1) and their gradient entries. */
static void apply_fixed(const cf_body *b, pattern *P, double *g)
{
    for (size_t j = 0; j < b->nn; j++) {
        for (int c = 0; c < 3; c++) {
            int *ri = P->rowidx + P->colptr[3 * j + c];
            double *v = P->val + P->colptr[3 * j + c];
            size_t len = (size_t)(P->colptr[3 * j + c + 1] - P->colptr[3 * j + c]);
            const int colfix = (b->fix[j] >> c) & 1;
            for (size_t k = 0; k < len; k++) {
                size_t row = (size_t)ri[k];
                if (colfix || ((b->fix[row / 3] >> (row % 3)) & 1))
                    v[k] = (row == 3 * j + (size_t)c) ? 1 : 0;
            }
            if (colfix)
                g[3 * j + c] = 0;
        }
    }
}

void cf_body_internal_force(const cf_body *b, double *g)
{
    assemble(b, b->x, NULL, NULL, 0, NULL, g, NULL, NULL);
}

/* 1 when positions x invert no tetrahedron and take no spring to solid. */
static int admissible(const cf_body *b, const double *x)
{
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u;
        spring_geom(b, x, s, n, &u);
        if (!(fabs(u) < b->law->travel_mm))
            return 0;
    }
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        if (!(vol6(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3]) > 0))
            return 0;
    }
    return 1;
}

static double norm_inf(const double *v, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    return m;
}

cf_status cf_body_solve(cf_body *b, const cf_probe *probe, double depth_mm,
                        double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : 1e4 * b->E_MPa * b->mean_edge_mm;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    pattern P;
    if (!pattern_build(b, &P))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    double *g = malloc(n * sizeof *g), *dx = malloc(n * sizeof *dx), *xt = malloc(n * sizeof *xt);
    uint8_t *active = malloc(b->nn);
    cf_sparse_chol *ch = NULL;
    cf_status st = CF_OK;
    if (!g || !dx || !xt || !active) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
        goto end;
    }
    if ((st = cf_sparse_chol_create(&ch, n, P.colptr, P.rowidx, err)) != CF_OK)
        goto end;
    /* Active set: Newton's method with the set of nodes in contact held (each held node pushed
    ** back by the penalty in proportion to its signed depth), then the set replaced by the nodes
    ** inside the probe, until it no longer changes (penalty contact with a set that changes
    ** inside Newton's iteration cycles between states). */
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it = 0, contacts = 0, rounds;
    double force = 0;
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        active[i] = b->fix[i] != CF_BODY_FIX_ALL && penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
    }
    for (rounds = 0; rounds < 100; rounds++) {
        int conv = 0;
        for (int k = 0; k < 100 && !conv; k++, it++) {
            force = assemble(b, b->x, probe, c, kp, active, g, &P, &contacts);
            apply_fixed(b, &P, g);
            double r = norm_inf(g, n);
            if (r <= 1e-10 * fscale) {
                conv = 1;
                break;
            }
            if ((st = cf_sparse_chol_factor(ch, P.val, NULL, err)) != CF_OK ||
                (st = cf_sparse_chol_solve(ch, g, dx, err)) != CF_OK)
                goto end;
            double alpha = 1;
            int ok = 0;
            for (int bt = 0; bt < 40 && !ok; bt++, alpha *= 0.5) {
                for (size_t i = 0; i < n; i++)
                    xt[i] = b->x[i] - alpha * dx[i];
                ok = admissible(b, xt);
            }
            if (!ok) {
                st = cf_error_set(err, CF_E_NOCONV,
                                  "body: at probe depth %g mm every Newton step would invert a "
                                  "tetrahedron or take a spring to solid",
                                  depth_mm);
                goto end;
            }
            memcpy(b->x, xt, n * sizeof *xt);
            if (2 * alpha * norm_inf(dx, n) <= 1e-14 * b->mean_edge_mm)
                conv = 1;
        }
        if (!conv) {
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: Newton's method did not converge at probe depth %g mm",
                              depth_mm);
            goto end;
        }
        int changed = 0;
        for (size_t i = 0; i < b->nn; i++) {
            double nrm[3];
            uint8_t in = b->fix[i] != CF_BODY_FIX_ALL && penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
            changed += in != active[i];
            active[i] = in;
        }
        if (!changed)
            break;
    }
    if (rounds == 100) {
        st = cf_error_set(err, CF_E_NOCONV,
                          "body: the contact set did not settle at probe depth %g mm", depth_mm);
        goto end;
    }
    force = assemble(b, b->x, probe, c, kp, active, g, NULL, &contacts);
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    cf_sparse_chol_free(ch);
    pattern_free(&P);
    free(g);
    free(dx);
    free(xt);
    free(active);
    return st;
}
