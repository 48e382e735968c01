/*
** The element term of a body (body.h, cf_body_match_elements): what a tetrahedron's six springs
** leave of the isotropic tensor, carried by the tetrahedron itself. Small-strain reasoning: with
** the displacement linear in every tetrahedron, an edge's stretch is n.eps.n L for every
** tetrahedron that holds it, so the springs store sum_t (V_t/2) eps_t : C_t : eps_t with C_t the
** tetrahedron's share of its springs' tensors, (1/V_t) sum_s w_s k_s L_s^2 n (x) n (x) n (x) n
** (w_s = 1 / the number of tetrahedra around spring s; k_s its axial stiffness at rest). The
** element term D_t = C_iso - C_t makes every tetrahedron's tensor C_iso exactly (lambda = mu, the
** volume term adding kappa as before), so the body is the linear tetrahedron of the isotropic
** material at small strain and has no heterogeneity left to relax (src/notes/contact-study.md,
** "The element term"). At finite strain the term is a Saint Venant-Kirchhoff one: energy
** (V0/2) E : D_t : E with E = (F^T F - I)/2 the tetrahedron's Green-Lagrange strain.
*/
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* Reference shape gradients G[4][3] of tetrahedron t. Returns 0 for a flat one. */
static int tet_grad(const cf_body *b, size_t t, double G[4][3])
{
    const uint32_t *v = b->tet + 4 * t;
    double A[3][3]; /* rows: edges X_m - X_0 */
    for (int m = 0; m < 3; m++)
        for (int a = 0; a < 3; a++)
            A[m][a] = b->X[3 * v[m + 1] + a] - b->X[3 * v[0] + a];
    const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                       A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                       A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(fabs(det) > 0))
        return 0;
    /* G[m+1] = column m of A^-1 (the gradient of the barycentric coordinate of node m+1) */
    for (int m = 0; m < 3; m++) {
        const double *p = A[(m + 1) % 3], *q = A[(m + 2) % 3];
        G[m + 1][0] = (p[1] * q[2] - p[2] * q[1]) / det;
        G[m + 1][1] = (p[2] * q[0] - p[0] * q[2]) / det;
        G[m + 1][2] = (p[0] * q[1] - p[1] * q[0]) / det;
    }
    for (int a = 0; a < 3; a++)
        G[0][a] = -(G[1][a] + G[2][a] + G[3][a]);
    return 1;
}

/* The spring of the edge between nodes p and q, found in the springs around p (CSR adj). */
static size_t edge_spring(const cf_body *b, const size_t *ap, const uint32_t *al, uint32_t p,
                          uint32_t q)
{
    for (size_t k = ap[p]; k < ap[p + 1]; k++) {
        const size_t s = al[k];
        if ((b->si[s] == p && b->sj[s] == q) || (b->si[s] == q && b->sj[s] == p))
            return s;
    }
    return SIZE_MAX;
}

/* Per tetrahedron its six springs (SIZE_MAX where an edge has none) into ts. */
static int tet_springs(const cf_body *b, size_t *ts)
{
    size_t *ap = calloc(b->nn + 1, sizeof *ap);
    uint32_t *al = malloc((2 * b->ns + 1) * sizeof *al);
    if (!ap || !al) {
        free(ap);
        free(al);
        return 0;
    }
    for (size_t s = 0; s < b->ns; s++)
        ap[b->si[s] + 1]++, ap[b->sj[s] + 1]++;
    for (size_t i = 0; i < b->nn; i++)
        ap[i + 1] += ap[i];
    size_t *pos = malloc((b->nn + 1) * sizeof *pos);
    if (!pos) {
        free(ap);
        free(al);
        return 0;
    }
    memcpy(pos, ap, (b->nn + 1) * sizeof *pos);
    for (size_t s = 0; s < b->ns; s++) {
        al[pos[b->si[s]]++] = (uint32_t)s;
        al[pos[b->sj[s]]++] = (uint32_t)s;
    }
    static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (size_t t = 0; t < b->nt; t++)
        for (int e = 0; e < 6; e++)
            ts[6 * t + e] = edge_spring(b, ap, al, b->tet[4 * t + E[e][0]], b->tet[4 * t + E[e][1]]);
    free(pos);
    free(ap);
    free(al);
    return 1;
}

/* The Voigt vector (n1^2, n2^2, n3^2, n2 n3, n1 n3, n1 n2) of spring s at rest: n.eps.n = m . e
** for the engineering strain e = (e11, e22, e33, 2 e23, 2 e13, 2 e12). */
static void spring_m(const cf_body *b, size_t s, double m[6])
{
    double n[3];
    for (int a = 0; a < 3; a++)
        n[a] = (b->X[3 * b->sj[s] + a] - b->X[3 * b->si[s] + a]) / b->L0[s];
    m[0] = n[0] * n[0], m[1] = n[1] * n[1], m[2] = n[2] * n[2];
    m[3] = n[1] * n[2], m[4] = n[0] * n[2], m[5] = n[0] * n[1];
}

cf_status cf_body_match_elements(cf_body *b, cf_error *err)
{
    if (b->group)
        return cf_error_set(err, CF_E_DATA, "body: the element term needs one law for every "
                                            "spring (the body has %zu spring groups)",
                            b->ngroups);
    if (b->law->extension)
        return cf_error_set(err, CF_E_DATA, "body: the element term takes a spring of one "
                            "stiffness at rest, not the double-acting element (k0 %g N/mm in "
                            "compression, %g N/mm in extension): edges in extension would leave "
                            "the isotropic tensor short",
                            b->law->k0_N_per_mm, b->law->extension->k0_N_per_mm);
    size_t *ts = malloc((6 * b->nt + 1) * sizeof *ts);
    double *ks = calloc(b->ns + 1, sizeof *ks), *cnt = calloc(b->ns + 1, sizeof *cnt);
    double *D = malloc((36 * b->nt + 1) * sizeof *D);
    if (!ts || !ks || !cnt || !D || !tet_springs(b, ts)) {
        free(ts), free(ks), free(cnt), free(D);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the element term of %zu "
                                                "tetrahedra", b->nt);
    }
    const double H = b->law->p.H_mm, mu = b->mu_MPa;
    for (size_t s = 0; s < b->ns; s++) {
        double k;
        cf_law_force(b->law, b->method, 0, &k, NULL);
        ks[s] = b->c[s] * k * H / b->L0[s] * b->L0[s] * b->L0[s]; /* k_s L_s^2, N mm */
    }
    for (size_t k = 0; k < 6 * b->nt; k++)
        if (ts[k] != SIZE_MAX)
            cnt[ts[k]] += 1;
    for (size_t t = 0; t < b->nt; t++) {
        double *Dt = D + 36 * t;
        memset(Dt, 0, 36 * sizeof *Dt);
        for (int a = 0; a < 3; a++) {
            for (int q = 0; q < 3; q++)
                Dt[6 * a + q] = mu; /* lambda = mu */
            Dt[6 * a + a] = 3 * mu;
            Dt[6 * (a + 3) + a + 3] = mu;
        }
        for (int e = 0; e < 6; e++) {
            const size_t s = ts[6 * t + e];
            if (s == SIZE_MAX)
                continue;
            double m[6];
            spring_m(b, s, m);
            const double w = ks[s] / (cnt[s] * b->V0[t]);
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++)
                    Dt[6 * i + j] -= w * m[i] * m[j];
        }
    }
    free(ts), free(ks), free(cnt);
    free(b->elem);
    b->elem = D;
    return CF_OK;
}

int body_elem_tet(const cf_body *b, const double *x, size_t t, double f[12], double K[144])
{
    double G[4][3], F[3][3] = {{0}};
    if (!tet_grad(b, t, G))
        return 0;
    const uint32_t *v = b->tet + 4 * t;
    for (int m = 0; m < 4; m++)
        for (int i = 0; i < 3; i++)
            for (int J = 0; J < 3; J++)
                F[i][J] += x[3 * v[m] + i] * G[m][J];
    double C[3][3];
    for (int I = 0; I < 3; I++)
        for (int J = 0; J < 3; J++)
            C[I][J] = F[0][I] * F[0][J] + F[1][I] * F[1][J] + F[2][I] * F[2][J];
    const double e[6] = {(C[0][0] - 1) / 2, (C[1][1] - 1) / 2, (C[2][2] - 1) / 2,
                         C[1][2], C[0][2], C[0][1]};
    const double *D = b->elem + 36 * t, V0 = b->V0[t];
    double S6[6] = {0}, beta[4][3][6];
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            S6[i] += D[6 * i + j] * e[j];
    const double S[3][3] = {{S6[0], S6[5], S6[4]}, {S6[5], S6[1], S6[3]}, {S6[4], S6[3], S6[2]}};
    for (int m = 0; m < 4; m++)
        for (int j = 0; j < 3; j++) {
            const double *g = G[m], *Fj = F[j];
            double *bt = beta[m][j];
            bt[0] = Fj[0] * g[0], bt[1] = Fj[1] * g[1], bt[2] = Fj[2] * g[2];
            bt[3] = Fj[1] * g[2] + Fj[2] * g[1];
            bt[4] = Fj[0] * g[2] + Fj[2] * g[0];
            bt[5] = Fj[0] * g[1] + Fj[1] * g[0];
            double s = 0;
            for (int k = 0; k < 6; k++)
                s += bt[k] * S6[k];
            f[3 * m + j] = V0 * s;
        }
    if (!K)
        return 1;
    for (int m = 0; m < 4; m++)
        for (int q = 0; q < 4; q++) {
            double gSg = 0;
            for (int I = 0; I < 3; I++)
                for (int J = 0; J < 3; J++)
                    gSg += G[m][I] * S[I][J] * G[q][J];
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    double Db[6] = {0}, s = i == j ? gSg : 0;
                    for (int r = 0; r < 6; r++)
                        for (int c = 0; c < 6; c++)
                            Db[r] += D[6 * r + c] * beta[q][j][c];
                    for (int r = 0; r < 6; r++)
                        s += beta[m][i][r] * Db[r];
                    K[12 * (3 * m + i) + 3 * q + j] = V0 * s;
                }
        }
    return 1;
}

/* The element term's part of the nodal virial sn (6 per node, VTK's order xx yy zz xy yz xz; the
** fields, body_fields.c): a quarter of each tetrahedron's V sigma = V0 F S F^T (J V0 = V, sigma =
** F S F^T / J) at each of its corners. A flat tetrahedron adds nothing. */
void body_elem_virial(const cf_body *b, const double *x, double *sn)
{
    for (size_t t = 0; b->elem && t < b->nt; t++) {
        double G[4][3], F[3][3] = {{0}}, C[3][3], S6[6] = {0}, P[3][3], T[3][3];
        if (!tet_grad(b, t, G))
            continue;
        const uint32_t *v = b->tet + 4 * t;
        for (int m = 0; m < 4; m++)
            for (int i = 0; i < 3; i++)
                for (int J = 0; J < 3; J++)
                    F[i][J] += x[3 * v[m] + i] * G[m][J];
        for (int I = 0; I < 3; I++)
            for (int J = 0; J < 3; J++)
                C[I][J] = F[0][I] * F[0][J] + F[1][I] * F[1][J] + F[2][I] * F[2][J];
        const double e[6] = {(C[0][0] - 1) / 2, (C[1][1] - 1) / 2, (C[2][2] - 1) / 2,
                             C[1][2], C[0][2], C[0][1]};
        const double *D = b->elem + 36 * t;
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++)
                S6[i] += D[6 * i + j] * e[j];
        const double S[3][3] = {{S6[0], S6[5], S6[4]}, {S6[5], S6[1], S6[3]}, {S6[4], S6[3], S6[2]}};
        for (int i = 0; i < 3; i++) /* P = F S, T = P F^T */
            for (int J = 0; J < 3; J++)
                P[i][J] = F[i][0] * S[0][J] + F[i][1] * S[1][J] + F[i][2] * S[2][J];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                T[i][j] = b->V0[t] / 4 * (P[i][0] * F[j][0] + P[i][1] * F[j][1] + P[i][2] * F[j][2]);
        const double v6[6] = {T[0][0], T[1][1], T[2][2], T[0][1], T[1][2], T[0][2]};
        for (int m = 0; m < 4; m++)
            for (int k = 0; k < 6; k++)
                sn[6 * v[m] + (size_t)k] += v6[k];
    }
}
