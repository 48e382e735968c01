/*
** Tissue bodies (body.h): the sparse pattern of the tangent, the springs' and the volume term's
** forces and tangent with the probe's penalty contact, the held components, and the workspace
** the solves keep between calls.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

void cf_body_pattern_free(pattern *P)
{
    if (!P->borrowed) {
        free(P->colptr);
        free(P->rowidx);
    }
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
    if (!(b->kappa_MPa > 0) || P->aug)
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

/* The rows of the pattern's columns into colptr and rowidx (see pattern): node j's three columns
** hold the blocks of its neighbours nb, and in the augmented form the pressure rows 3 nn + q of
** the same neighbours; pressure column a the rows of a's neighbours and its own diagonal. */
static int pattern_rows(pattern *P, size_t nn, size_t nnb)
{
    const size_t n = P->n, nnz = 9 * nnb + (P->aug ? 6 * nnb + nn : 0);
    if (nnz > 2147483647u)
        return 0;
    P->colptr = malloc((n + 1) * sizeof *P->colptr);
    P->rowidx = malloc(nnz * sizeof *P->rowidx);
    if (!P->colptr || !P->rowidx)
        return 0;
    size_t k = 0;
    P->colptr[0] = 0;
    for (size_t j = 0; j < nn; j++)
        for (int c = 0; c < 3; c++) {
            for (size_t q = P->nbp[j]; q < P->nbp[j + 1]; q++)
                for (int a = 0; a < 3; a++)
                    P->rowidx[k++] = (int)(3 * P->nb[q] + (size_t)a);
            for (size_t q = P->nbp[j]; P->aug && q < P->nbp[j + 1]; q++)
                P->rowidx[k++] = (int)(3 * nn + P->nb[q]);
            P->colptr[3 * j + c + 1] = (int)k;
        }
    for (size_t j = 0; P->aug && j < nn; j++) {
        for (size_t q = P->nbp[j]; q < P->nbp[j + 1]; q++)
            for (int a = 0; a < 3; a++)
                P->rowidx[k++] = (int)(3 * P->nb[q] + (size_t)a);
        P->rowidx[k++] = (int)(3 * nn + j);
        P->colptr[3 * nn + j + 1] = (int)k;
    }
    return 1;
}

int cf_body_pattern_build(const cf_body *b, pattern *P, int aug)
{
    memset(P, 0, sizeof *P);
    const size_t nn = b->nn, nt = b->nt;
    P->aug = aug && b->kappa_MPa > 0;
    const int two = b->kappa_MPa > 0 && !P->aug;
    P->n = 3 * nn + (P->aug ? nn : 0);
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
    if (!pattern_rows(P, nn, nnb))
        goto fail;
    if (!pattern_blocks(b, P, mark))
        goto fail;
    free(mark);
    return 1;
fail:
    free(mark);
    free(list);
    cf_body_pattern_free(P);
    return 0;
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
            body_add_block(P, v[q], P->tblk[16 * t + 4 * (size_t)m + (size_t)q], B);
        }
}

/* The augmented form's volume coupling: node a's pressure unknown (row and column 3 nn + a) holds
** w_a = dV_a/dx, the gradient of its volume, against the positions of its neighbours, and
** -V0_a/kappa on its diagonal. Eliminating the pressures gives back the condensed tangent's
** sum_a (kappa/V0_a) w_a w_a^T, so the positions' solution is the same, while the pattern keeps
** only the neighbours of each node (the condensed one couples the neighbours of neighbours). */
static void volume_coupling(const cf_body *b, const double *dVall, const double *V0n, pattern *P)
{
    const size_t nn = b->nn;
    for (size_t a = 0; a < nn; a++) {
        double *col = P->val + P->colptr[3 * nn + a];
        const size_t nr = P->nbp[a + 1] - P->nbp[a];
        memset(col, 0, 3 * nr * sizeof *col);
        for (size_t k = P->tp[a]; k < P->tp[a + 1]; k++) {
            const size_t t = P->tl[k];
            for (int m = 0; m < 4; m++) {
                const size_t q = blk_of(P, a, b->tet[4 * t + m]);
                for (int c = 0; c < 3; c++)
                    col[3 * q + (size_t)c] += dVall[12 * t + 3 * (size_t)m + (size_t)c] / 4;
            }
        }
        col[3 * nr] = -V0n[a] / b->kappa_MPa;
        for (size_t q = 0; q < nr; q++) { /* the same values in the rows of the pressure */
            const size_t j = P->nb[P->nbp[a] + q];
            const size_t off = 3 * (P->nbp[j + 1] - P->nbp[j]) + blk_of(P, j, a);
            for (int c = 0; c < 3; c++)
                P->val[(size_t)P->colptr[3 * j + (size_t)c] + off] = col[3 * q + (size_t)c];
        }
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
    if (P && P->aug)
        volume_coupling(b, dVall, V0n, P);
    else if (P) {
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
                    body_add_block(P, ring[cq], blk[rq * nr + cq], B);
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

/* The element term (cf_body_match_elements) of every tetrahedron into g and, when P is not NULL,
** the tangent. Returns 0 for a flat tetrahedron. */
static int elem_term(const cf_body *b, const double *x, double *g, pattern *P)
{
    double f[12], K[144];
    for (size_t t = 0; t < b->nt; t++) {
        if (!body_elem_tet(b, x, t, f, P ? K : NULL))
            return 0;
        const uint32_t *v = b->tet + 4 * t;
        for (int m = 0; m < 4; m++)
            for (int a = 0; a < 3; a++)
                g[3 * v[m] + a] += f[3 * m + a];
        if (!P)
            continue;
        for (int m = 0; m < 4; m++)
            for (int q = 0; q < 4; q++) {
                double B[9];
                for (int a = 0; a < 3; a++)
                    for (int c = 0; c < 3; c++)
                        B[3 * a + c] = K[12 * (3 * m + a) + 3 * q + c];
                body_add_block(P, v[q], P->tblk[16 * t + 4 * (size_t)m + (size_t)q], B);
            }
    }
    return 1;
}

/* Energy gradient g (3 nn) and, when P is not NULL, the tangent at positions x; contact forces of
** the probe at c added (as -f to g) with their tangent. Returns the reaction along the probe's
** direction and the number of nodes in contact. */
double cf_body_assemble(const cf_body *b, const double *x, const cf_probe *pr, const double *c,
                       double kp, const uint8_t *active, double *g, pattern *P, int *contacts)
{
    const cf_law *law = b->law;
    const double H = law->p.H_mm;
    memset(g, 0, 3 * b->nn * sizeof *g);
    if (P && !P->val && !(P->val = malloc((size_t)P->colptr[P->n] * sizeof *P->val)))
        return NAN; /* the haptic loop's first assembly */
    if (P)
        memset(P->val, 0, (size_t)P->colptr[P->n] * sizeof *P->val);
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u, k;
        double L = body_spring_geom(b, x, s, n, &u);
        double F = cf_law_force(b->group ? b->glaw[b->group[s]] : law, b->method, u, &k, NULL);
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
        body_add_block(P, i, P->sblk[4 * s], B);
        body_add_block(P, j, P->sblk[4 * s + 1], B);
        body_add_block(P, j, P->sblk[4 * s + 2], Bn);
        body_add_block(P, i, P->sblk[4 * s + 3], Bn);
    }
    if (b->kappa_MPa > 0 && !volume_term(b, x, g, P))
        return NAN;
    if (b->nfibre)
        cf_body_fibre_forces(b, x, g, P);
    if (b->elem && !elem_term(b, x, g, P))
        return NAN;
    if (b->f_ext)
        for (size_t i = 0; i < 3 * b->nn; i++)
            g[i] -= b->f_ext[i];
    double force = 0;
    int nc = 0;
    if (pr && c && active)
        for (size_t i = 0; i < b->nn; i++) {
            if (!active[i])
                continue;
            double nrm[3], d = cf_body_penetration(pr, c, x + 3 * i, nrm, 1);
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
            body_add_block(P, i, blk_of(P, i, i), B);
        }
    if (contacts)
        *contacts = nc;
    return force;
}

void cf_body_add_inertia(const cf_body *b, const body_work *w, const double *x, double *g,
                         pattern *P)
{
    if (!(w->mcoef > 0))
        return;
    for (size_t i = 0; i < b->nn; i++) {
        const double k = w->mcoef * w->mass[i];
        for (int a = 0; a < 3; a++)
            g[3 * i + (size_t)a] += k * (x[3 * i + (size_t)a] - w->xstar[3 * i + (size_t)a]);
        if (P) {
            const double B[9] = {k, 0, 0, 0, k, 0, 0, 0, k};
            body_add_block(P, i, blk_of(P, i, i), B);
        }
    }
}

/* Copies the residual g at the held components into b->reaction (when there is one): at an
** equilibrium, the force the supports apply there. */
void cf_body_keep_reaction(const cf_body *b, const double *g)
{
    if (!b->reaction)
        return;
    for (size_t i = 0; i < b->nn; i++)
        for (int a = 0; a < 3; a++)
            b->reaction[3 * i + (size_t)a] = ((b->fix[i] >> a) & 1) ? g[3 * i + (size_t)a] : 0;
}

/* The probe's penalty force kp d n on every node of the contact set (the force the assembly
** subtracts from g), 0 elsewhere, into b->contact (when there is one). */
void cf_body_keep_contact(const cf_body *b, const cf_probe *pr, const double *c, double kp,
                          const uint8_t *active)
{
    if (!b->contact)
        return;
    memset(b->contact, 0, 3 * b->nn * sizeof *b->contact);
    for (size_t i = 0; pr && c && active && i < b->nn; i++) {
        if (!active[i])
            continue;
        double nrm[3], d = cf_body_penetration(pr, c, b->x + 3 * i, nrm, 1);
        for (int a = 0; a < 3; a++)
            b->contact[3 * i + (size_t)a] = kp * d * nrm[a];
    }
}

/* Zeroes the rows and columns of fixed components (diagonal 1) and their gradient entries. */
void cf_body_apply_fixed(const cf_body *b, pattern *P, double *g)
{
    const size_t n3 = 3 * b->nn, ncol = P ? P->n : n3;
    for (size_t col = 0; col < ncol; col++) {
        const int colfix = col < n3 && ((b->fix[col / 3] >> (col % 3)) & 1);
        if (colfix)
            g[col] = 0;
        if (!P)
            continue;
        const int *ri = P->rowidx + P->colptr[col];
        double *v = P->val + P->colptr[col];
        const size_t len = (size_t)(P->colptr[col + 1] - P->colptr[col]);
        for (size_t k = 0; k < len; k++) {
            const size_t row = (size_t)ri[k];
            if (colfix || (row < n3 && ((b->fix[row / 3] >> (row % 3)) & 1)))
                v[k] = row == col ? 1 : 0;
        }
    }
}

cf_status cf_body_internal_force(const cf_body *b, double *g, cf_error *err)
{
    if (isnan(cf_body_assemble(b, b->x, NULL, NULL, 0, NULL, g, NULL, NULL)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
    if (b->f_ext)
        for (size_t i = 0; i < 3 * b->nn; i++)
            g[i] += b->f_ext[i];
    return CF_OK;
}

/* 1 when positions x invert no tetrahedron and take no spring to solid. */
int cf_body_admissible(const cf_body *b, const double *x)
{
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u;
        body_spring_geom(b, x, s, n, &u);
        if (!(fabs(u) < cf_law_travel_at(cf_body_spring_law(b, s), u))) /* a pair: each side its own */
            return 0;
    }
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        if (!(body_vol6(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3]) > 0))
            return 0;
    }
    return !b->nfibre || cf_body_fibre_umax(b, x) < 1;
}
