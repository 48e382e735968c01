/*
** Tissue bodies (body.h): the springs on the edges of a tetrahedral mesh and their calibration,
** the volume term, and the static probe solve (Newton's method on the sparse tangent).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "conifit/body.h"
#include "model/sparse_chol.h"

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

/* The sparse pattern of the tangent in 3 x 3 blocks: column node j holds the blocks of the nodes
** in nb[nbp[j] .. nbp[j + 1]) (sorted, j among them): the nodes of the tetrahedra around j (its
** springs' other ends), and with a volume term those of the tetrahedra around each of these (the
** nodal volume couples every pair of nodes around one node). */
typedef struct pattern {
    size_t n;              /* 3 nn */
    int *colptr, *rowidx;
    double *val;
    size_t *nbp;           /* nn + 1 */
    uint32_t *nb;
    size_t *tp;            /* tetrahedra around each node: tl[tp[a] .. tp[a + 1]) */
    uint32_t *tl;
    /* block indices found once (a search per block at every assembly cost more than the rest):
    ** per spring (i, j): (i in i), (j in j), (i in j), (j in i); per tetrahedron: (row m in
    ** column q) for its 16 corner pairs; per node a with a volume term: its ring (the nodes of
    ** the tetrahedra around it, in the order the assembly meets them) and the blocks of every
    ** pair of ring nodes */
    uint32_t *sblk, *tblk;
    size_t *rp;            /* nn + 1: ring of a in rn[rp[a] .. rp[a + 1]) */
    uint32_t *rn;
    size_t *bp;            /* nn + 1: blocks of a's ring pairs in rblk[bp[a] ..), row-major */
    uint32_t *rblk;
} pattern;

static void pattern_free(pattern *P)
{
    free(P->colptr);
    free(P->rowidx);
    free(P->val);
    free(P->nbp);
    free(P->nb);
    free(P->tp);
    free(P->tl);
    free(P->sblk);
    free(P->tblk);
    free(P->rp);
    free(P->rn);
    free(P->bp);
    free(P->rblk);
}

/* Block index of row node i in column node j's columns (i must be in the pattern). */
static size_t blk_of(const pattern *P, size_t j, size_t i)
{
    size_t lo = P->nbp[j], hi = P->nbp[j + 1];
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (P->nb[mid] < i)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo - P->nbp[j];
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The block indices of pattern.sblk, tblk and the rings (see pattern); mark is nn scratch. */
static int pattern_blocks(const cf_body *b, pattern *P, uint32_t *mark)
{
    const size_t nn = b->nn, nt = b->nt;
    P->sblk = malloc(4 * b->ns * sizeof *P->sblk);
    P->tblk = malloc(16 * nt * sizeof *P->tblk);
    if (!P->sblk || !P->tblk)
        return 0;
    for (size_t s = 0; s < b->ns; s++) {
        size_t i = b->si[s], j = b->sj[s];
        P->sblk[4 * s] = (uint32_t)blk_of(P, i, i);
        P->sblk[4 * s + 1] = (uint32_t)blk_of(P, j, j);
        P->sblk[4 * s + 2] = (uint32_t)blk_of(P, j, i);
        P->sblk[4 * s + 3] = (uint32_t)blk_of(P, i, j);
    }
    for (size_t t = 0; t < nt; t++)
        for (int m = 0; m < 4; m++)
            for (int q = 0; q < 4; q++)
                P->tblk[16 * t + 4 * (size_t)m + (size_t)q] =
                    (uint32_t)blk_of(P, b->tet[4 * t + q], b->tet[4 * t + m]);
    if (!(b->kappa_MPa > 0))
        return 1;
    P->rp = malloc((nn + 1) * sizeof *P->rp);
    P->bp = malloc((nn + 1) * sizeof *P->bp);
    if (!P->rp || !P->bp)
        return 0;
    for (size_t a = 0; a < nn; a++)
        mark[a] = UINT32_MAX;
    /* ring sizes first */
    size_t nr_all = 0, nb_all = 0;
    for (size_t a = 0; a < nn; a++) {
        size_t nr = 0;
        for (size_t k = P->tp[a]; k < P->tp[a + 1]; k++)
            for (int m = 0; m < 4; m++) {
                uint32_t q = b->tet[4 * P->tl[k] + m];
                if (mark[q] != (uint32_t)a) {
                    mark[q] = (uint32_t)a;
                    nr++;
                }
            }
        P->rp[a] = nr_all;
        P->bp[a] = nb_all;
        nr_all += nr;
        nb_all += nr * nr;
    }
    P->rp[nn] = nr_all;
    P->bp[nn] = nb_all;
    P->rn = malloc((nr_all ? nr_all : 1) * sizeof *P->rn);
    P->rblk = malloc((nb_all ? nb_all : 1) * sizeof *P->rblk);
    if (!P->rn || !P->rblk)
        return 0;
    for (size_t a = 0; a < nn; a++)
        mark[a] = UINT32_MAX;
    for (size_t a = 0; a < nn; a++) {
        size_t nr = 0;
        uint32_t *ring = P->rn + P->rp[a];
        for (size_t k = P->tp[a]; k < P->tp[a + 1]; k++)
            for (int m = 0; m < 4; m++) {
                uint32_t q = b->tet[4 * P->tl[k] + m];
                if (mark[q] != (uint32_t)(nn + a)) { /* other marks than the sizing pass's */
                    mark[q] = (uint32_t)(nn + a);
                    ring[nr++] = q;
                }
            }
        for (size_t rq = 0; rq < nr; rq++)
            for (size_t cq = 0; cq < nr; cq++)
                P->rblk[P->bp[a] + rq * nr + cq] = (uint32_t)blk_of(P, ring[cq], ring[rq]);
    }
    return 1;
}

static int pattern_build(const cf_body *b, pattern *P)
{
    memset(P, 0, sizeof *P);
    const size_t nn = b->nn, nt = b->nt;
    const int two = b->kappa_MPa > 0;
    P->n = 3 * nn;
    P->tp = calloc(nn + 1, sizeof *P->tp);
    P->tl = malloc(4 * nt * sizeof *P->tl);
    P->nbp = malloc((nn + 1) * sizeof *P->nbp);
    uint32_t *mark = malloc(nn * sizeof *mark), *list = NULL;
    size_t cap = 0, nnb = 0;
    if (!P->tp || !P->tl || !P->nbp || !mark)
        goto fail;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 4; k++)
            P->tp[b->tet[4 * t + k] + 1]++;
    for (size_t a = 0; a < nn; a++)
        P->tp[a + 1] += P->tp[a];
    size_t *fill = malloc(nn * sizeof *fill);
    if (!fill)
        goto fail;
    memcpy(fill, P->tp, nn * sizeof *fill);
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 4; k++)
            P->tl[fill[b->tet[4 * t + k]]++] = (uint32_t)t;
    free(fill);
    for (size_t a = 0; a < nn; a++)
        mark[a] = UINT32_MAX;
    /* the neighbours of each node: its ring, or the rings of its ring's nodes */
    P->nbp[0] = 0;
    for (size_t j = 0; j < nn; j++) {
        size_t start = nnb;
#define ADD_NODE(q)                                                                                 \
    do {                                                                                            \
        uint32_t q_ = (q);                                                                          \
        if (mark[q_] != (uint32_t)j) {                                                              \
            mark[q_] = (uint32_t)j;                                                                 \
            if (nnb == cap) {                                                                       \
                size_t nc = cap ? 2 * cap : 64 * nn + 64;                                           \
                uint32_t *nl = realloc(list, nc * sizeof *nl);                                      \
                if (!nl)                                                                            \
                    goto fail;                                                                      \
                list = nl;                                                                          \
                cap = nc;                                                                           \
            }                                                                                       \
            list[nnb++] = q_;                                                                       \
        }                                                                                           \
    } while (0)
        ADD_NODE((uint32_t)j);
        for (size_t k = P->tp[j]; k < P->tp[j + 1]; k++)
            for (int c = 0; c < 4; c++) {
                uint32_t a = b->tet[4 * P->tl[k] + c];
                ADD_NODE(a);
                if (two)
                    for (size_t k2 = P->tp[a]; k2 < P->tp[a + 1]; k2++)
                        for (int c2 = 0; c2 < 4; c2++)
                            ADD_NODE(b->tet[4 * P->tl[k2] + c2]);
            }
#undef ADD_NODE
        qsort(list + start, nnb - start, sizeof *list, cmp_u32);
        P->nbp[j + 1] = nnb;
    }
    P->nb = list;
    list = NULL;
    if (9 * nnb > 2147483647u)
        goto fail;
    P->colptr = malloc((3 * nn + 1) * sizeof *P->colptr);
    P->rowidx = malloc(9 * nnb * sizeof *P->rowidx);
    P->val = malloc(9 * nnb * sizeof *P->val);
    if (!P->colptr || !P->rowidx || !P->val)
        goto fail;
    size_t nnz = 0;
    P->colptr[0] = 0;
    for (size_t j = 0; j < nn; j++)
        for (int c = 0; c < 3; c++) {
            for (size_t k = P->nbp[j]; k < P->nbp[j + 1]; k++)
                for (int a = 0; a < 3; a++)
                    P->rowidx[nnz++] = (int)(3 * P->nb[k] + (size_t)a);
            P->colptr[3 * j + c + 1] = (int)nnz;
        }
    if (!pattern_blocks(b, P, mark))
        goto fail;
    free(mark);
    return 1;
fail:
    free(mark);
    free(list);
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

/* The volume of tetrahedron t at positions x and its gradient dV[4][3]. */
static double tet_dV(const cf_body *b, const double *x, size_t t, double dV[4][3])
{
    const uint32_t *v = b->tet + 4 * t;
    const double *p0 = x + 3 * v[0];
    double e[3][3];
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
    return e[0][0] * dV[1][0] + e[0][1] * dV[1][1] + e[0][2] * dV[1][2];
}

/* Adds f times the second derivative of tetrahedron t's volume to the tangent. With the edges
** e_m = x_m - x_0 (m = 1, 2, 3) and V = e_1 . (e_2 x e_3)/6, the block of e_a and e_b for (a, b, c)
** in cyclic order is -[e_c]x / 6 ([v]x the matrix of v x), its transpose for the reverse order,
** zero for a = b; node 0 enters through every edge with the sign minus. */
static void volume_hessian(const cf_body *b, const double *x, size_t t, double f, pattern *P)
{
    const uint32_t *v = b->tet + 4 * t;
    double e[3][3], He[3][3][9], Hx[4][4][9];
    for (int m = 0; m < 3; m++)
        for (int a = 0; a < 3; a++)
            e[m][a] = x[3 * v[m + 1] + a] - x[3 * v[0] + a];
    memset(He, 0, sizeof He);
    for (int a = 0; a < 3; a++) {
        int bb = (a + 1) % 3, c = (a + 2) % 3;
        const double *w = e[c];
        /* -[w]x / 6 = (1/6) [[0, w2, -w1], [-w2, 0, w0], [w1, -w0, 0]] */
        double M[9] = {0, w[2] / 6, -w[1] / 6, -w[2] / 6, 0, w[0] / 6, w[1] / 6, -w[0] / 6, 0};
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 3; q++) {
                He[a][bb][3 * r + q] = M[3 * r + q];
                He[bb][a][3 * q + r] = M[3 * r + q];
            }
    }
    memset(Hx, 0, sizeof Hx);
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 9; k++) {
                double h = He[a][c][k];
                Hx[a + 1][c + 1][k] += h;
                Hx[0][c + 1][k] -= h;
                Hx[a + 1][0][k] -= h;
                Hx[0][0][k] += h;
            }
    for (int m = 0; m < 4; m++)
        for (int q = 0; q < 4; q++) {
            if (m == q)
                continue; /* the diagonal blocks are zero */
            double B[9];
            for (int k = 0; k < 9; k++)
                B[k] = f * Hx[m][q][k];
            add_block(P, v[q], P->tblk[16 * t + 4 * (size_t)m + (size_t)q], B);
        }
}

/* The volume term, averaged over nodes: each node a owns a quarter of the volume of every
** tetrahedron around it, V_a and V0_a, and stores V0_a (kappa/2)(J_a - 1)^2 with J_a = V_a/V0_a
** (the average nodal pressure tetrahedron of Bonet & Burton 1998, Commun Numer Meth Engng
** 14:437-449: one volume constraint per node instead of per element, which keeps linear
** tetrahedra from locking as nu approaches 1/2). Adds its gradient to g and, when P is not NULL,
** its tangent sum_a (kappa/V0_a) dV_a dV_a^T + sum_t f_t d2V_t, f_t = (kappa/4) sum over the
** tetrahedron's nodes of (J_a - 1). Returns 0 when memory runs out. */
static int volume_term(const cf_body *b, const double *x, double *g, pattern *P)
{
    const size_t nn = b->nn, nt = b->nt;
    double *Vn = calloc(nn, sizeof *Vn), *V0n = calloc(nn, sizeof *V0n);
    double *dVall = malloc(12 * nt * sizeof *dVall), *w = NULL;
    uint32_t *loc = NULL, *ring = NULL;
    int ok = 0;
    if (!Vn || !V0n || !dVall)
        goto end;
    for (size_t t = 0; t < nt; t++) {
        double(*dV)[3] = (double(*)[3])(dVall + 12 * t);
        double V = tet_dV(b, x, t, dV);
        for (int k = 0; k < 4; k++) {
            Vn[b->tet[4 * t + k]] += V / 4;
            V0n[b->tet[4 * t + k]] += b->V0[t] / 4;
        }
    }
    for (size_t t = 0; t < nt; t++) {
        double(*dV)[3] = (double(*)[3])(dVall + 12 * t);
        double f = 0;
        for (int k = 0; k < 4; k++) {
            size_t a = b->tet[4 * t + k];
            f += b->kappa_MPa * (Vn[a] / V0n[a] - 1) / 4;
        }
        for (int m = 0; m < 4; m++)
            for (int a = 0; a < 3; a++)
                g[3 * b->tet[4 * t + m] + a] += f * dV[m][a];
        if (P && f != 0)
            volume_hessian(b, x, t, f, P);
    }
    if (P) {
        loc = malloc(nn * sizeof *loc);
        size_t maxring = 1;
        for (size_t a = 0; a < nn; a++)
            maxring = P->rp[a + 1] - P->rp[a] > maxring ? P->rp[a + 1] - P->rp[a] : maxring;
        w = malloc(3 * maxring * sizeof *w);
        if (!loc || !w)
            goto end;
        for (size_t a = 0; a < nn; a++) {
            const size_t nr = P->rp[a + 1] - P->rp[a];
            ring = P->rn + P->rp[a];
            for (size_t q = 0; q < nr; q++) {
                loc[ring[q]] = (uint32_t)q;
                w[3 * q] = w[3 * q + 1] = w[3 * q + 2] = 0;
            }
            for (size_t k = P->tp[a]; k < P->tp[a + 1]; k++) {
                size_t t = P->tl[k];
                const double *dV = dVall + 12 * t;
                for (int m = 0; m < 4; m++) {
                    uint32_t q = loc[b->tet[4 * t + m]];
                    for (int c = 0; c < 3; c++)
                        w[3 * q + c] += dV[3 * m + c] / 4;
                }
            }
            const double kk = b->kappa_MPa / V0n[a];
            const uint32_t *blk = P->rblk + P->bp[a];
            for (size_t rq = 0; rq < nr; rq++)
                for (size_t cq = 0; cq < nr; cq++) {
                    double B[9];
                    for (int r = 0; r < 3; r++)
                        for (int c = 0; c < 3; c++)
                            B[3 * r + c] = kk * w[3 * rq + r] * w[3 * cq + c];
                    add_block(P, ring[cq], blk[rq * nr + cq], B);
                }
        }
    }
    ok = 1;
end:
    free(Vn);
    free(V0n);
    free(dVall);
    free(w);
    free(loc);
    return ok;
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
        add_block(P, i, P->sblk[4 * s], B);
        add_block(P, j, P->sblk[4 * s + 1], B);
        add_block(P, j, P->sblk[4 * s + 2], Bn);
        add_block(P, i, P->sblk[4 * s + 3], Bn);
    }
    if (b->kappa_MPa > 0 && !volume_term(b, x, g, P))
        return NAN;
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
            add_block(P, i, blk_of(P, i, i), B);
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
            if (!P) {
                if ((b->fix[j] >> c) & 1)
                    g[3 * j + c] = 0;
                continue;
            }
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

cf_status cf_body_internal_force(const cf_body *b, double *g, cf_error *err)
{
    if (isnan(assemble(b, b->x, NULL, NULL, 0, NULL, g, NULL, NULL)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
    return CF_OK;
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

/* What the solves of a body keep between calls: the pattern and the analysed factorisation of its
** tangent, the last factors (reused as chord steps while they converge fast enough), and work
** vectors. */
typedef struct body_work {
    pattern P;
    cf_sparse_chol *ch;
    double *g, *dx, *xt;
    uint8_t *active;
    int factored;       /* ch holds the factors of a tangent of this body */
    /* the haptic loop (cf_body_haptic_step): the factors of the tangent without contact, taken
    ** once, and per node that has touched the probe the three columns of its inverse at that
    ** node (slot[i] + 1 indexes Z, 0 = none yet) */
    cf_sparse_chol *hch;
    int hfactored;
    uint8_t *hactive;
    uint32_t *slot;
    double *Z;          /* 9 nn per slot: columns 3 nn each */
    size_t nslot, capslot;
    double *hy, *hrhs;
} body_work;

static void work_free(body_work *w)
{
    if (!w)
        return;
    cf_sparse_chol_free(w->ch);
    cf_sparse_chol_free(w->hch);
    free(w->hactive);
    free(w->slot);
    free(w->Z);
    free(w->hy);
    free(w->hrhs);
    pattern_free(&w->P);
    free(w->g);
    free(w->dx);
    free(w->xt);
    free(w->active);
    free(w);
}

void cf_body_free(cf_body *b)
{
    if (!b)
        return;
    work_free(b->work);
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

static cf_status work_get(cf_body *b, body_work **out, cf_error *err)
{
    if (b->work) {
        *out = b->work;
        return CF_OK;
    }
    const size_t n = 3 * b->nn;
    body_work *w = calloc(1, sizeof *w);
    if (!w || !pattern_build(b, &w->P)) {
        free(w);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    }
    w->g = malloc(n * sizeof *w->g);
    w->dx = malloc(n * sizeof *w->dx);
    w->xt = malloc(n * sizeof *w->xt);
    w->active = malloc(b->nn);
    cf_status st = CF_OK;
    if (!w->g || !w->dx || !w->xt || !w->active)
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the tangent of %zu nodes", b->nn);
    else
        st = cf_sparse_chol_create(&w->ch, n, w->P.colptr, w->P.rowidx, err);
    if (st != CF_OK) {
        work_free(w);
        return st;
    }
    b->work = w;
    *out = w;
    return CF_OK;
}

cf_status cf_body_solve(cf_body *b, const cf_probe *probe, double depth_mm,
                        double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : 1e4 * b->E_MPa * b->mean_edge_mm;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    pattern *P = &w->P;
    double *g = w->g, *dx = w->dx, *xt = w->xt;
    uint8_t *active = w->active;
    /* Active set: Newton's method with the set of nodes in contact held (each held node pushed
    ** back by the penalty in proportion to its signed depth), then the set replaced by the nodes
    ** inside the probe, until it no longer changes (penalty contact with a set that changes
    ** inside Newton's iteration cycles between states). Within a set, the factors of an earlier
    ** tangent serve as long as each step reduces the residual to a quarter (chord steps: the
    ** next update of a probe moving slowly reuses the last factors); otherwise, and whenever the
    ** set changes, the tangent is assembled and factored afresh. */
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it = 0, contacts = 0, rounds, fresh = 0;
    double force = 0;
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = b->fix[i] != CF_BODY_FIX_ALL && penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
        fresh |= in != active[i];
        active[i] = in;
    }
    fresh |= !w->factored;
    for (rounds = 0; rounds < 100; rounds++) {
        int conv = 0;
        double rprev = INFINITY;
        for (int k = 0; k < 200 && !conv; k++, it++) {
            force = assemble(b, b->x, probe, c, kp, active, g, fresh ? P : NULL, &contacts);
            if (isnan(force)) {
                st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's tangent");
                goto end;
            }
            apply_fixed(b, fresh ? P : NULL, g);
            double r = norm_inf(g, n);
            if (r <= 1e-8 * fscale) {
                conv = 1;
                break;
            }
            if (!fresh && !(r <= 0.25 * rprev)) {
                /* the old factors no longer converge fast: take the tangent here */
                fresh = 1;
                rprev = INFINITY;
                k--;
                it--;
                continue;
            }
            if (fresh) {
                w->factored = 0;
                if ((st = cf_sparse_chol_factor(w->ch, P->val, NULL, err)) != CF_OK)
                    goto end;
                w->factored = 1;
            }
            if ((st = cf_sparse_chol_solve(w->ch, g, dx, err)) != CF_OK)
                goto end;
            for (size_t i = 0; i < b->nn; i++) /* held components never move (old factors */
                for (int a = 0; a < 3; a++)    /* may have been made with other ones held) */
                    if ((b->fix[i] >> a) & 1)
                        dx[3 * i + (size_t)a] = 0;
            fresh = 0;
            rprev = r;
            double alpha = 2;
            int ok = 0;
            for (int bt = 0; bt < 40 && !ok; bt++) {
                alpha *= 0.5;
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
            if (alpha < 0.99)
                fresh = 1; /* a shortened step: take the tangent where it landed */
            if (alpha * norm_inf(dx, n) <= 1e-14 * b->mean_edge_mm)
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
            /* a node at a punch's rim can slide out past the radius and back in as the set
            ** changes; after ten rounds a node in the set stays while it is still pushed */
            if (rounds >= 10 && active[i] && penetration(probe, c, b->x + 3 * i, nrm, 1) > 0)
                in = 1;
            changed += in != active[i];
            active[i] = in;
        }
        if (!changed)
            break;
        fresh = 1;
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
    return st;
}

/* The three columns of the inverse of the contact-free tangent at node i (held components zero),
** computed at its first contact and kept (*out). */
static cf_status haptic_columns(body_work *w, size_t nn, size_t i, const double **out,
                                cf_error *err)
{
    const size_t n = 3 * nn;
    cf_status st;
    if (w->slot[i]) {
        *out = w->Z + (size_t)(w->slot[i] - 1) * 3 * n;
        return CF_OK;
    }
    if (w->nslot == w->capslot) {
        size_t cap = w->capslot ? 2 * w->capslot : 16;
        double *Z = realloc(w->Z, cap * 3 * n * sizeof *Z);
        if (!Z)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop's columns");
        w->Z = Z;
        w->capslot = cap;
    }
    double *col = w->Z + w->nslot * 3 * n;
    for (int a = 0; a < 3; a++) {
        memset(w->hrhs, 0, n * sizeof *w->hrhs);
        w->hrhs[3 * i + (size_t)a] = 1;
        if ((st = cf_sparse_chol_solve(w->hch, w->hrhs, col + (size_t)a * n, err)) != CF_OK)
            return st;
    }
    w->slot[i] = (uint32_t)++w->nslot;
    *out = col;
    return CF_OK;
}

/* Solves (K0 + U U^T) dx = g by Woodbury's identity: K0 the factored contact-free tangent, U one
** column sqrt(kp) n_i (at node i's components, held ones zero) per node in contact. m nodes in
** list[], their normals in nv[3 m]; M is m x m work space, rhs m. */
static cf_status haptic_solve(cf_body *b, body_work *w, double kp, const size_t *list,
                              const double *nv, size_t m, double *M, double *rhs, double *dx,
                              cf_error *err)
{
    const size_t n = 3 * b->nn;
    cf_status st = cf_sparse_chol_solve(w->hch, w->g, dx, err);
    if (st != CF_OK || m == 0)
        return st;
    const double sk = sqrt(kp);
    /* v_k = K0^-1 u_k is sqrt(kp) Z_k n_k; M = I + U^T K0^-1 U; rhs = U^T y */
    for (size_t k = 0; k < m; k++) {
        const double *Zk = NULL;
        if ((st = haptic_columns(w, b->nn, list[k], &Zk, err)) != CF_OK)
            return st;
        const size_t ik = list[k];
        rhs[k] = 0;
        for (int a = 0; a < 3; a++)
            rhs[k] += sk * nv[3 * k + a] * dx[3 * ik + (size_t)a];
        for (size_t q = 0; q < m; q++) {
            const size_t iq = list[q];
            double s = 0;
            for (int a = 0; a < 3; a++)     /* row of node iq, component a */
                for (int c = 0; c < 3; c++) /* column c of node ik */
                    s += nv[3 * q + a] * Zk[(size_t)c * n + 3 * iq + (size_t)a] * nv[3 * k + c];
            M[q * m + k] = kp * s + (q == k);
        }
    }
    /* M is symmetric positive definite: Cholesky in place, then rhs = M^-1 rhs */
    for (size_t j = 0; j < m; j++) {
        double d = M[j * m + j];
        for (size_t k = 0; k < j; k++)
            d -= M[j * m + k] * M[j * m + k];
        if (!(d > 0))
            return cf_error_set(err, CF_E_NOCONV, "body: the haptic loop's contact matrix is "
                                                  "not positive definite");
        d = sqrt(d);
        M[j * m + j] = d;
        for (size_t i = j + 1; i < m; i++) {
            double s = M[i * m + j];
            for (size_t k = 0; k < j; k++)
                s -= M[i * m + k] * M[j * m + k];
            M[i * m + j] = s / d;
        }
    }
    for (size_t i = 0; i < m; i++) {
        double s = rhs[i];
        for (size_t k = 0; k < i; k++)
            s -= M[i * m + k] * rhs[k];
        rhs[i] = s / M[i * m + i];
    }
    for (size_t i = m; i-- > 0;) {
        double s = rhs[i];
        for (size_t k = i + 1; k < m; k++)
            s -= M[k * m + i] * rhs[k];
        rhs[i] = s / M[i * m + i];
    }
    for (size_t k = 0; k < m; k++) {
        const double *Zk = w->Z + (size_t)(w->slot[list[k]] - 1) * 3 * n;
        for (int c = 0; c < 3; c++) {
            const double f = sk * nv[3 * k + c] * rhs[k];
            if (f == 0)
                continue;
            const double *z = Zk + (size_t)c * n;
            for (size_t r = 0; r < n; r++)
                dx[r] -= f * z[r];
        }
    }
    return CF_OK;
}

cf_status cf_body_haptic_step(cf_body *b, const cf_probe *probe, double depth_mm,
                              double penalty_N_per_mm, int max_iters, cf_body_step *out,
                              cf_error *err)
{
    const size_t n = 3 * b->nn, nn = b->nn;
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : 1e4 * b->E_MPa * b->mean_edge_mm;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    if (!w->hch) {
        w->hactive = calloc(nn, 1);
        w->slot = calloc(nn, sizeof *w->slot);
        w->hy = malloc(n * sizeof *w->hy);
        w->hrhs = malloc(n * sizeof *w->hrhs);
        if (!w->hactive || !w->slot || !w->hy || !w->hrhs)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        if ((st = cf_sparse_chol_create(&w->hch, n, w->P.colptr, w->P.rowidx, err)) != CF_OK)
            return st;
    }
    if (!w->hfactored) {
        /* the contact-free tangent where the body is now, factored once */
        if (isnan(assemble(b, b->x, NULL, NULL, 0, NULL, w->g, &w->P, NULL)))
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's tangent");
        apply_fixed(b, &w->P, w->g);
        if ((st = cf_sparse_chol_factor(w->hch, w->P.val, NULL, err)) != CF_OK)
            return st;
        w->factored = 0; /* the Newton solver's factors were of the same values: refactor */
        w->hfactored = 1;
        w->nslot = 0;
        memset(w->slot, 0, nn * sizeof *w->slot);
    }
    size_t *list = NULL, cap = 0;
    double *nv = NULL, *M = NULL, *rhs = NULL;
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it = 0, contacts = 0;
    double force = 0, r = INFINITY;
    size_t m = 0;
    for (it = 0; it < max_iters; it++) {
        /* the contact set where the body is at the update's start: nodes inside the probe, and
        ** nodes of the last set still pushed; held through the update's iterations (a node the
        ** step leaves just outside a curved probe, by its slip along the surface, would otherwise
        ** drop out and spring back every other iteration), its normals renewed */
        for (size_t k = 0; it > 0 && k < m; k++) {
            penetration(probe, c, b->x + 3 * list[k], nv + 3 * k, 1);
            for (int a = 0; a < 3; a++)
                if ((b->fix[list[k]] >> a) & 1)
                    nv[3 * k + (size_t)a] = 0;
        }
        for (size_t i = 0; it == 0 && i < nn; i++) {
            double nrm[3];
            uint8_t in = b->fix[i] != CF_BODY_FIX_ALL &&
                         (penetration(probe, c, b->x + 3 * i, nrm, 0) > 0 ||
                          (w->hactive[i] && penetration(probe, c, b->x + 3 * i, nrm, 1) > 0));
            w->hactive[i] = in;
            if (!in)
                continue;
            if (m == cap) {
                cap = cap ? 2 * cap : 16;
                size_t *l2 = realloc(list, cap * sizeof *l2);
                double *n2 = l2 ? realloc(nv, 3 * cap * sizeof *n2) : NULL;
                double *M2 = n2 ? realloc(M, cap * cap * sizeof *M2) : NULL;
                double *r2 = M2 ? realloc(rhs, cap * sizeof *r2) : NULL;
                if (l2)
                    list = l2;
                if (n2)
                    nv = n2;
                if (M2)
                    M = M2;
                if (r2)
                    rhs = r2;
                if (!r2) {
                    st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
                    goto end;
                }
            }
            list[m] = i;
            penetration(probe, c, b->x + 3 * i, nv + 3 * m, 1);
            for (int a = 0; a < 3; a++)
                if ((b->fix[i] >> a) & 1)
                    nv[3 * m + (size_t)a] = 0;
            m++;
        }
        force = assemble(b, b->x, probe, c, kp, w->hactive, w->g, NULL, &contacts);
        if (isnan(force)) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
            goto end;
        }
        apply_fixed(b, NULL, w->g);
        r = norm_inf(w->g, n);
        if (r <= 1e-8 * fscale)
            break;
        if ((st = haptic_solve(b, w, kp, list, nv, m, M, rhs, w->dx, err)) != CF_OK)
            goto end;
        for (size_t i = 0; i < nn; i++)
            for (int a = 0; a < 3; a++)
                if ((b->fix[i] >> a) & 1)
                    w->dx[3 * i + (size_t)a] = 0;
        double alpha = 2;
        int ok = 0;
        for (int bt = 0; bt < 40 && !ok; bt++) {
            alpha *= 0.5;
            for (size_t i = 0; i < n; i++)
                w->xt[i] = b->x[i] - alpha * w->dx[i];
            ok = admissible(b, w->xt);
        }
        if (!ok) {
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: at probe depth %g mm every haptic step would invert a "
                              "tetrahedron or take a spring to solid",
                              depth_mm);
            goto end;
        }
        memcpy(b->x, w->xt, n * sizeof *w->xt);
    }
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    free(list);
    free(nv);
    free(M);
    free(rhs);
    return st;
}
