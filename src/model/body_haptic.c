/*
** Tissue bodies (body.h): the probe loop at haptic rate, chord iterations on the factored
** contact-free tangent corrected for the nodes in contact by Woodbury's identity.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

#ifndef HAPTIC_RINGS
#define HAPTIC_RINGS 2
#endif
#ifndef HAPTIC_REFRESH
#define HAPTIC_REFRESH 0
#endif

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

/* rhs = M^-1 rhs for the symmetric positive definite m x m matrix M (Cholesky in place). */
static cf_status small_chol_solve(double *M, double *rhs, size_t m, cf_error *err)
{
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
    return CF_OK;
}

/* M = I + U^T K0^-1 U (m x m) for the m nodes of list[] in contact, normals nv[3 m], penalty kp:
** M_qk = kp n_q^T Z_qk n_k + [q = k], Z_qk the block of node q in node k's columns (kept). */
static void contact_matrix(const body_work *w, size_t n, double kp, const size_t *list,
                           const double *nv, size_t m, double *M)
{
    for (size_t k = 0; k < m; k++) {
        const double *Zk = w->Z + (size_t)(w->slot[list[k]] - 1) * 3 * n;
        for (size_t q = 0; q < m; q++) {
            const size_t iq = list[q];
            double s = 0;
            for (int a = 0; a < 3; a++)     /* row of node iq, component a */
                for (int c = 0; c < 3; c++) /* column c of node k */
                    s += nv[3 * q + a] * Zk[(size_t)c * n + 3 * iq + (size_t)a] * nv[3 * k + c];
            M[q * m + k] = kp * s + (q == k);
        }
    }
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
        rhs[k] = 0;
        for (int a = 0; a < 3; a++)
            rhs[k] += sk * nv[3 * k + a] * dx[3 * list[k] + (size_t)a];
    }
    contact_matrix(w, n, kp, list, nv, m, M);
    if ((st = small_chol_solve(M, rhs, m, err)) != CF_OK)
        return st;
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

/* The loop's workspace on first use, and the contact-free tangent where the body is now,
** factored once (until the body moves on without the loop). */
static cf_status haptic_prepare(cf_body *b, body_work *w, cf_error *err)
{
    const size_t n = 3 * b->nn, nn = b->nn;
    cf_status st;
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
        if (isnan(cf_body_assemble(b, b->x, NULL, NULL, 0, NULL, w->g, &w->P, NULL)))
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's tangent");
        cf_body_apply_fixed(b, &w->P, w->g);
        if ((st = cf_sparse_chol_factor(w->hch, w->P.val, NULL, err)) != CF_OK)
            return st;
        w->factored = 0; /* the Newton solver's factors were of the same values: refactor */
        w->hfactored = 1;
        w->nslot = 0;
        memset(w->slot, 0, nn * sizeof *w->slot);
    }
    return CF_OK;
}

/* ---- the region near the probe ----------------------------------------------------------------
** Each update solves only the region L of nodes around the probe: the nodes that have touched it
** and their neighbours. The rest of the body answers linearly, through the contact-free tangent
** K0 already factored: loads s on L's components move the body by K0^-1 s from the reference
** positions xref, so with the columns of K0^-1 at L's components (kept) the positions of the nodes
** L's residual reads (E: L's two rings of tetrahedra) are xref + Z_E s, and a chord step on L's
** exact residual r_L is a change of s by r_L corrected for the contact by Woodbury's identity,
** all in L's components: no solve with the factor, no assembly of the whole body. */
typedef struct haptic_loc {
    size_t nE, nN1, nT1, nT2, nS;
    long updates;     /* updates since the last refresh */
    uint32_t *L;      /* nn: L's nodes in the order of their columns (slot - 1); w->nslot of them */
    uint32_t *N1;     /* nn: L and its ring: the nodes whose nodal volumes L's residual needs */
    uint32_t *E;      /* nn: the nodes of the tetrahedra around N1's nodes */
    uint32_t *T1;     /* nt: the tetrahedra around L's nodes */
    uint32_t *T2;     /* nt: the tetrahedra around N1's nodes */
    uint32_t *S;      /* ns: the springs with an end in N1 */
    uint8_t *nmark;   /* nn: bit 0 in L, bit 1 in N1, bit 2 in E */
    uint8_t *tmark;   /* nt: bit 0 in T1, bit 1 in T2 */
    double *xref;     /* 3 nn: the reference positions */
    double *s;        /* 3 nn: the loads on L's components (by column) */
    double *r, *wv;   /* 3 nn: L's residual, a step's loads */
    double *dxE;      /* 3 nn: a step's motion of E's nodes (in E's order) */
    double *Vn, *V0n; /* nn: nodal volumes now and at rest */
    double *Vt;       /* nt: volumes of T2's tetrahedra */
} haptic_loc;

/* The region's block (one allocation, freed by cf_body_work_free), empty, its reference the body
** where it is now. NULL when memory runs out. */
static haptic_loc *loc_create(const cf_body *b)
{
    const size_t nn = b->nn, nt = b->nt, ns = b->ns;
    const size_t nd = 5 * 3 * nn + 2 * nn + nt, nu = 3 * nn + 2 * nt + ns;
    haptic_loc *hl = calloc(1, sizeof *hl + nd * sizeof(double) + nu * sizeof(uint32_t) + nn + nt);
    if (!hl)
        return NULL;
    double *d = (double *)(hl + 1);
    hl->xref = d, d += 3 * nn;
    hl->s = d, d += 3 * nn;
    hl->r = d, d += 3 * nn;
    hl->wv = d, d += 3 * nn;
    hl->dxE = d, d += 3 * nn;
    hl->Vn = d, d += nn;
    hl->V0n = d, d += nn;
    hl->Vt = d, d += nt;
    uint32_t *u = (uint32_t *)d;
    hl->L = u, u += nn;
    hl->N1 = u, u += nn;
    hl->E = u, u += nn;
    hl->T1 = u, u += nt;
    hl->T2 = u, u += nt;
    hl->S = u, u += ns;
    hl->nmark = (uint8_t *)u;
    hl->tmark = hl->nmark + nn;
    memcpy(hl->xref, b->x, 3 * nn * sizeof *hl->xref);
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 4; k++)
            hl->V0n[b->tet[4 * t + k]] += b->V0[t] / 4;
    return hl;
}

/* Marks node a with bit (adding it to list, *n long, when new). */
static void loc_mark(uint8_t *mark, uint32_t *list, size_t *n, uint32_t a, uint8_t bit)
{
    if (!(mark[a] & bit)) {
        mark[a] |= bit;
        list[(*n)++] = a;
    }
}

/* The region's sets from its nodes L, and the positions xref + Z_E s of E's nodes into b->x. */
static void loc_sets(cf_body *b, const body_work *w, haptic_loc *hl)
{
    const pattern *P = &w->P;
    const size_t n = 3 * b->nn, nL = w->nslot;
    memset(hl->nmark, 0, b->nn);
    memset(hl->tmark, 0, b->nt);
    hl->nN1 = hl->nE = hl->nT1 = hl->nT2 = hl->nS = 0;
    for (size_t k = 0; k < nL; k++) {
        hl->nmark[hl->L[k]] |= 1;
        loc_mark(hl->nmark, hl->N1, &hl->nN1, hl->L[k], 2);
    }
    for (size_t k = 0; k < nL; k++)
        for (size_t q = P->tp[hl->L[k]]; q < P->tp[hl->L[k] + 1]; q++) {
            loc_mark(hl->tmark, hl->T1, &hl->nT1, P->tl[q], 1);
            for (int m = 0; m < 4; m++)
                loc_mark(hl->nmark, hl->N1, &hl->nN1, b->tet[4 * P->tl[q] + m], 2);
        }
    for (size_t k = 0; k < hl->nN1; k++)
        for (size_t q = P->tp[hl->N1[k]]; q < P->tp[hl->N1[k] + 1]; q++) {
            loc_mark(hl->tmark, hl->T2, &hl->nT2, P->tl[q], 2);
            for (int m = 0; m < 4; m++)
                loc_mark(hl->nmark, hl->E, &hl->nE, b->tet[4 * P->tl[q] + m], 4);
        }
    for (size_t s = 0; s < b->ns; s++)
        if ((hl->nmark[b->si[s]] | hl->nmark[b->sj[s]]) & 2)
            hl->S[hl->nS++] = (uint32_t)s;
    for (size_t e = 0; e < hl->nE; e++)
        for (size_t a = 0; a < 3; a++) {
            const size_t row = 3 * hl->E[e] + a;
            double x = hl->xref[row];
            for (size_t j = 0; j < 3 * nL; j++)
                x += w->Z[j * n + row] * hl->s[j];
            b->x[row] = x;
        }
}

/* Adds node i and the nodes within HAPTIC_RINGS rings of tetrahedra around it to the region: the
** columns of K0^-1 at their components (three solves with the factor per new node). */
static cf_status loc_add(cf_body *b, body_work *w, haptic_loc *hl, size_t i, cf_error *err)
{
    const pattern *P = &w->P;
    uint32_t *q = malloc(b->nn * sizeof *q);
    uint8_t *seen = calloc(b->nn, 1);
    cf_status st = CF_OK;
    if (!q || !seen) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        goto end;
    }
    size_t nq = 0, head = 0;
    q[nq++] = (uint32_t)i;
    seen[i] = 1;
    for (int ring = 0; ring < HAPTIC_RINGS; ring++) { /* breadth first, one ring at a time */
        const size_t tail = nq;
        for (; head < tail; head++)
            for (size_t k = P->tp[q[head]]; k < P->tp[q[head] + 1]; k++)
                for (int m = 0; m < 4; m++) {
                    const uint32_t a = b->tet[4 * P->tl[k] + m];
                    if (!seen[a]) {
                        seen[a] = 1;
                        q[nq++] = a;
                    }
                }
    }
    for (size_t k = 0; k < nq && st == CF_OK; k++) {
        const uint32_t a = q[k];
        const double *Z;
        if (w->slot[a] || b->fix[a] == CF_BODY_FIX_ALL)
            continue;
        if ((st = haptic_columns(w, b->nn, a, &Z, err)) != CF_OK)
            break;
        const size_t j = w->slot[a] - 1;
        hl->L[j] = a;
        hl->s[3 * j] = hl->s[3 * j + 1] = hl->s[3 * j + 2] = 0;
    }
end:
    free(q);
    free(seen);
    return st;
}

/* The gradient of tetrahedron t's volume at its four nodes (dV[m], m its corners) at positions x;
** returns the volume. */
static double loc_tet_grad(const cf_body *b, const double *x, size_t t, double dV[4][3])
{
    const uint32_t *v = b->tet + 4 * t;
    double e[3][3];
    for (int m = 0; m < 3; m++)
        for (int a = 0; a < 3; a++)
            e[m][a] = x[3 * v[m + 1] + a] - x[3 * v[0] + a];
    for (int m = 0; m < 3; m++) {
        const double *p = e[(m + 1) % 3], *q = e[(m + 2) % 3];
        for (int a = 0; a < 3; a++)
            dV[m + 1][a] = (p[(a + 1) % 3] * q[(a + 2) % 3] - p[(a + 2) % 3] * q[(a + 1) % 3]) / 6;
    }
    for (int a = 0; a < 3; a++)
        dV[0][a] = -(dV[1][a] + dV[2][a] + dV[3][a]);
    return e[0][0] * dV[1][0] + e[0][1] * dV[1][1] + e[0][2] * dV[1][2];
}

/* L's residual (by column, held components zero) at positions x (E's rows read): the springs,
** the volume term, the external forces and the penalty contact of the nodes of w->hactive.
** Returns the probe's force along its direction; *contacts the nodes in contact. */
static double loc_residual(const cf_body *b, const body_work *w, haptic_loc *hl,
                           const cf_probe *pr, const double *c, double kp, const double *x,
                           int *contacts)
{
    const pattern *P = &w->P;
    const size_t nL = w->nslot;
    double *r = hl->r;
    memset(r, 0, 3 * nL * sizeof *r);
    if (b->kappa_MPa > 0) {
        for (size_t k = 0; k < hl->nT2; k++) {
            const uint32_t *v = b->tet + 4 * (size_t)hl->T2[k];
            hl->Vt[hl->T2[k]] = body_vol6(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3]) / 6;
        }
        for (size_t k = 0; k < hl->nN1; k++) {
            double V = 0;
            for (size_t q = P->tp[hl->N1[k]]; q < P->tp[hl->N1[k] + 1]; q++)
                V += hl->Vt[P->tl[q]] / 4;
            hl->Vn[hl->N1[k]] = V;
        }
        for (size_t k = 0; k < hl->nT1; k++) {
            const size_t t = hl->T1[k];
            double dV[4][3], f = 0;
            loc_tet_grad(b, x, t, dV);
            for (int m = 0; m < 4; m++)
                f += b->kappa_MPa * (hl->Vn[b->tet[4 * t + m]] / hl->V0n[b->tet[4 * t + m]] - 1) / 4;
            for (int m = 0; m < 4; m++)
                if (hl->nmark[b->tet[4 * t + m]] & 1)
                    for (int a = 0; a < 3; a++)
                        r[3 * (w->slot[b->tet[4 * t + m]] - 1) + (size_t)a] += f * dV[m][a];
        }
    }
    for (size_t k = 0; k < hl->nS; k++) {
        const size_t s = hl->S[k], i = b->si[s], j = b->sj[s];
        if (!((hl->nmark[i] | hl->nmark[j]) & 1))
            continue;
        double nv[3], u, kk;
        body_spring_geom(b, x, s, nv, &u);
        const double T = -b->c[s] * cf_law_force(b->law, b->method, u, &kk, NULL);
        for (int a = 0; a < 3; a++) {
            if (hl->nmark[i] & 1)
                r[3 * (w->slot[i] - 1) + (size_t)a] -= T * nv[a];
            if (hl->nmark[j] & 1)
                r[3 * (w->slot[j] - 1) + (size_t)a] += T * nv[a];
        }
    }
    double force = 0;
    int nc = 0;
    for (size_t k = 0; k < nL; k++) {
        const size_t i = hl->L[k];
        for (int a = 0; a < 3; a++)
            r[3 * k + (size_t)a] -= b->f_ext ? b->f_ext[3 * i + (size_t)a] : 0;
        if (w->hactive[i]) {
            double nrm[3], d = cf_body_penetration(pr, c, x + 3 * i, nrm, 1);
            nc++;
            for (int a = 0; a < 3; a++)
                r[3 * k + (size_t)a] -= kp * d * nrm[a];
            force += kp * d * (nrm[0] * pr->dir[0] + nrm[1] * pr->dir[1] + nrm[2] * pr->dir[2]);
        }
        for (int a = 0; a < 3; a++)
            if ((b->fix[i] >> a) & 1)
                r[3 * k + (size_t)a] = 0;
    }
    *contacts = nc;
    return force;
}

/* A chord step on L: the loads wv = r - U M^-1 U^T Z_LL r (Woodbury's identity for the m nodes of
** list[] in contact, normals nv) and the motion Z_E wv of E's nodes into hl->dxE. */
static cf_status loc_step(const cf_body *b, const body_work *w, haptic_loc *hl, double kp,
                          const size_t *list, const double *nv, size_t m, double *M, double *rhs,
                          cf_error *err)
{
    const size_t n = 3 * b->nn, nL = w->nslot;
    const double sk = sqrt(kp);
    memcpy(hl->wv, hl->r, 3 * nL * sizeof *hl->wv);
    if (m > 0) {
        for (size_t k = 0; k < m; k++) { /* rhs = U^T Z_LL r at the contact nodes */
            const size_t i = list[k];
            rhs[k] = 0;
            for (int a = 0; a < 3; a++) {
                double y = 0;
                for (size_t j = 0; j < 3 * nL; j++)
                    y += w->Z[j * n + 3 * i + (size_t)a] * hl->r[j];
                rhs[k] += sk * nv[3 * k + a] * y;
            }
        }
        contact_matrix(w, n, kp, list, nv, m, M);
        cf_status st = small_chol_solve(M, rhs, m, err);
        if (st != CF_OK)
            return st;
        for (size_t k = 0; k < m; k++)
            for (int a = 0; a < 3; a++)
                hl->wv[3 * (w->slot[list[k]] - 1) + (size_t)a] -= sk * nv[3 * k + a] * rhs[k];
    }
    memset(hl->dxE, 0, 3 * hl->nE * sizeof *hl->dxE);
    for (size_t j = 0; j < 3 * nL; j++) {
        const double f = hl->wv[j], *z = w->Z + j * n;
        if (f == 0)
            continue;
        for (size_t e = 0; e < hl->nE; e++)
            for (size_t a = 0; a < 3; a++)
                hl->dxE[3 * e + a] += f * z[3 * hl->E[e] + a];
    }
    return CF_OK;
}

/* 1 when positions x (E's rows) invert none of T2's tetrahedra and take none of S's springs to
** solid. */
static int loc_admissible(const cf_body *b, const haptic_loc *hl, const double *x)
{
    for (size_t k = 0; k < hl->nS; k++) {
        double nv[3], u;
        body_spring_geom(b, x, hl->S[k], nv, &u);
        if (!(fabs(u) < b->law->travel_mm))
            return 0;
    }
    for (size_t k = 0; k < hl->nT2; k++) {
        const uint32_t *v = b->tet + 4 * (size_t)hl->T2[k];
        if (!(body_vol6(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3]) > 0))
            return 0;
    }
    return 1;
}

/* The nodes in contact in an update: list[m] (node indices), their normals nv[3 m] (held
** components zero), and the Woodbury matrix M (m x m) and its right side; cap the room. */
typedef struct haptic_set {
    size_t *list;
    double *nv, *M, *rhs;
    size_t m, cap;
} haptic_set;

/* Doubles the contact set's room; -1 when memory runs out (what was reallocated is kept for
** the caller to free). */
static int grow(haptic_set *hs)
{
    hs->cap = hs->cap ? 2 * hs->cap : 16;
    size_t *l2 = realloc(hs->list, hs->cap * sizeof *l2);
    double *n2 = l2 ? realloc(hs->nv, 3 * hs->cap * sizeof *n2) : NULL;
    double *M2 = n2 ? realloc(hs->M, hs->cap * hs->cap * sizeof *M2) : NULL;
    double *r2 = M2 ? realloc(hs->rhs, hs->cap * sizeof *r2) : NULL;
    if (l2)
        hs->list = l2;
    if (n2)
        hs->nv = n2;
    if (M2)
        hs->M = M2;
    if (r2)
        hs->rhs = r2;
    return r2 ? 0 : -1;
}

/* The contact set's normals where the body is now (held components zero). */
static void set_normals(const cf_body *b, const cf_probe *probe, const double *c, haptic_set *hs)
{
    for (size_t k = 0; k < hs->m; k++) {
        cf_body_penetration(probe, c, b->x + 3 * hs->list[k], hs->nv + 3 * k, 1);
        for (int a = 0; a < 3; a++)
            if ((b->fix[hs->list[k]] >> a) & 1)
                hs->nv[3 * k + (size_t)a] = 0;
    }
}

/* The contact set where the body is at the update's start: nodes inside the probe, and nodes of
** the last set still pushed; held through the update's iterations (a node the step leaves just
** outside a curved probe, by its slip along the surface, would otherwise drop out and spring back
** every other iteration), its normals renewed. Nodes new to the region are added to it. */
static cf_status set_contacts(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                              haptic_set *hs, cf_error *err)
{
    int added = 0;
    cf_status st;
    hs->m = 0;
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = w->touch[i] && b->fix[i] != CF_BODY_FIX_ALL &&
                     (cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0 ||
                      (w->hactive[i] && cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1) > 0));
        w->hactive[i] = in;
        if (!in)
            continue;
        if (hs->m == hs->cap && grow(hs) != 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        hs->list[hs->m++] = i;
    }
    for (size_t k = 0; k < hs->m; k++) /* nodes new to the region: its neighbours with them */
        if (!w->slot[hs->list[k]]) {
            if ((st = loc_add(b, w, w->hloc, hs->list[k], err)) != CF_OK)
                return st;
            added = 1;
        }
    if (added && w->nslot > 0)
        loc_sets(b, w, w->hloc);
    set_normals(b, probe, c, hs);
    return CF_OK;
}

/* At most max_iters chord iterations on the region at the probe's reference point c; *force,
** *contacts of the last residual, *iters the steps taken. */
static cf_status loc_iterations(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                                double kp, int max_iters, haptic_set *hs, double *force,
                                int *contacts, int *iters, double depth_mm, cf_error *err)
{
    haptic_loc *hl = w->hloc;
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it;
    cf_status st;
    for (it = 0; it < max_iters; it++) {
        if (it > 0)
            set_normals(b, probe, c, hs);
        *force = loc_residual(b, w, hl, probe, c, kp, b->x, contacts);
        if (body_norm_inf(hl->r, 3 * w->nslot) <= 1e-8 * fscale)
            break;
        if ((st = loc_step(b, w, hl, kp, hs->list, hs->nv, hs->m, hs->M, hs->rhs, err)) != CF_OK)
            return st;
        double alpha = 2;
        int ok = 0;
        for (int bt = 0; bt < 40 && !ok; bt++) {
            alpha *= 0.5;
            for (size_t e = 0; e < hl->nE; e++)
                for (size_t a = 0; a < 3; a++)
                    w->xt[3 * hl->E[e] + a] = b->x[3 * hl->E[e] + a] - alpha * hl->dxE[3 * e + a];
            ok = loc_admissible(b, hl, w->xt);
        }
        if (!ok)
            return cf_error_set(err, CF_E_NOCONV,
                                "body: at probe depth %g mm every haptic step would invert a "
                                "tetrahedron or take a spring to solid",
                                depth_mm);
        for (size_t e = 0; e < hl->nE; e++)
            memcpy(b->x + 3 * hl->E[e], w->xt + 3 * hl->E[e], 3 * sizeof *b->x);
        for (size_t j = 0; j < 3 * w->nslot; j++)
            hl->s[j] -= alpha * hl->wv[j];
    }
    *iters = it;
    return CF_OK;
}

/* The refresh of the whole body: its positions xref + Z s, one chord iteration with the exact
** residual of the whole body (the far field's own nonlinearity, which the region's linear answer
** leaves out), and the reference moved there (s = 0). */
static cf_status loc_refresh(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                             double kp, haptic_set *hs, double depth_mm, cf_error *err)
{
    haptic_loc *hl = w->hloc;
    const size_t n = 3 * b->nn;
    int contacts;
    cf_status st;
    memcpy(b->x, hl->xref, n * sizeof *b->x);
    for (size_t j = 0; j < 3 * w->nslot; j++)
        for (size_t r = 0; r < n && hl->s[j] != 0; r++)
            b->x[r] += hl->s[j] * w->Z[j * n + r];
    set_normals(b, probe, c, hs);
    if (isnan(cf_body_assemble(b, b->x, probe, c, kp, w->hactive, w->g, NULL, &contacts)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
    cf_body_keep_reaction(b, w->g);
    cf_body_apply_fixed(b, NULL, w->g);
    if ((st = haptic_solve(b, w, kp, hs->list, hs->nv, hs->m, hs->M, hs->rhs, w->dx, err)) != CF_OK)
        return st;
    double alpha = 2;
    int ok = 0;
    for (int bt = 0; bt < 40 && !ok; bt++) {
        alpha *= 0.5;
        for (size_t i = 0; i < n; i++)
            w->xt[i] = ((b->fix[i / 3] >> (i % 3)) & 1) ? b->x[i] : b->x[i] - alpha * w->dx[i];
        ok = cf_body_admissible(b, w->xt);
    }
    if (!ok)
        return cf_error_set(err, CF_E_NOCONV,
                            "body: at probe depth %g mm every haptic step would invert a "
                            "tetrahedron or take a spring to solid",
                            depth_mm);
    memcpy(b->x, w->xt, n * sizeof *b->x);
    memcpy(hl->xref, b->x, n * sizeof *b->x);
    memset(hl->s, 0, 3 * w->nslot * sizeof *hl->s);
    hl->updates = 0;
    set_normals(b, probe, c, hs);
    return CF_OK;
}

cf_status cf_body_haptic_step(cf_body *b, const cf_probe *probe, double depth_mm,
                              double penalty_N_per_mm, int max_iters, cf_body_step *out,
                              cf_error *err)
{
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : cf_body_penalty(b);
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = cf_body_work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    if ((st = haptic_prepare(b, w, err)) != CF_OK)
        return st;
    if (!w->hloc && !(w->hloc = loc_create(b)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
    haptic_set hs = {0};
    int it = 0, contacts = 0;
    double force = 0;
    if ((st = set_contacts(b, w, probe, c, &hs, err)) != CF_OK)
        goto end;
    if (HAPTIC_REFRESH > 0 && ++w->hloc->updates >= HAPTIC_REFRESH &&
        (st = loc_refresh(b, w, probe, c, kp, &hs, depth_mm, err)) != CF_OK)
        goto end;
    if ((st = loc_iterations(b, w, probe, c, kp, max_iters, &hs, &force, &contacts, &it, depth_mm,
                             err)) != CF_OK)
        goto end;
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    free(hs.list);
    free(hs.nv);
    free(hs.M);
    free(hs.rhs);
    return st;
}
