/*
** The stress and strain fields of a body (body.h, cf_body_fields_at): per node the Cauchy stress
** of its dual cell (its halves of its springs, a quarter of the fibres and of the element term of
** each tetrahedron around it, and its volume term's pressure), per tetrahedron
** the mean of its corners', its von Mises value and the Green-Lagrange strain of its deformation
** gradient; per spring its force. The derivation is in src/notes/simulate.md, "Fields".
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* The Green-Lagrange strain (6, VTK's order) of tetrahedron v from reference X to current x:
** F = [x_m - x_0] [X_m - X_0]^-1 (m = 1, 2, 3), E = (F^T F - I)/2. */
static void green_lagrange(const double *X, const double *x, const uint32_t *v, double E[6])
{
    double D[3][3], d[3][3], inv[3][3];
    for (int m = 0; m < 3; m++)
        for (int a = 0; a < 3; a++) {
            D[a][m] = X[3 * v[m + 1] + a] - X[3 * v[0] + a];
            d[a][m] = x[3 * v[m + 1] + a] - x[3 * v[0] + a];
        }
    const double det = D[0][0] * (D[1][1] * D[2][2] - D[1][2] * D[2][1]) -
                       D[0][1] * (D[1][0] * D[2][2] - D[1][2] * D[2][0]) +
                       D[0][2] * (D[1][0] * D[2][1] - D[1][1] * D[2][0]);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            inv[i][j] = (D[i1][j1] * D[i2][j2] - D[i1][j2] * D[i2][j1]) / det;
        }
    double F[3][3], C[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            F[i][j] = 0;
            for (int k = 0; k < 3; k++)
                F[i][j] += d[i][k] * inv[k][j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            C[i][j] = 0;
            for (int k = 0; k < 3; k++)
                C[i][j] += F[k][i] * F[k][j];
        }
    E[0] = (C[0][0] - 1) / 2;
    E[1] = (C[1][1] - 1) / 2;
    E[2] = (C[2][2] - 1) / 2;
    E[3] = C[0][1] / 2;
    E[4] = C[1][2] / 2;
    E[5] = C[0][2] / 2;
}

static double von_mises(const double s[6])
{
    const double a = s[0] - s[1], c = s[1] - s[2], d = s[2] - s[0];
    return sqrt((a * a + c * c + d * d) / 2 + 3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

static double fin(double v)
{
    return isfinite(v) ? v : 0;
}

/* The spring forces (N, tension positive) at x into f->force. */
static void spring_forces(const cf_body *b, const double *x, cf_body_fields *f)
{
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u, k;
        body_spring_geom(b, x, s, n, &u);
        f->force[s] = fin(-b->c[s] * cf_law_force(cf_body_spring_law(b, s), b->method, u, &k, NULL));
    }
}

cf_status cf_body_fields_at(const cf_body *b, const double *x, cf_body_fields *f,
                            cf_error *err)
{
    const size_t nn = b->nn, nt = b->nt;
    double *Vn = calloc(nn ? nn : 1, sizeof *Vn), *V0n = calloc(nn ? nn : 1, sizeof *V0n);
    double *sn = calloc(6 * (nn ? nn : 1), sizeof *sn);
    if (!Vn || !V0n || !sn) {
        free(Vn);
        free(V0n);
        free(sn);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the fields of %zu nodes", nn);
    }
    spring_forces(b, x, f);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        const double V = body_vol6(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3]) / 6;
        for (int k = 0; k < 4; k++) {
            Vn[v[k]] += V / 4;
            V0n[v[k]] += b->V0[t] / 4;
        }
    }
    /* each node: half of every spring at it, (1/2) T l n n = (T/(2 l)) d d */
    for (size_t s = 0; s < b->ns; s++) {
        const double *p = x + 3 * b->si[s], *q = x + 3 * b->sj[s];
        const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        const double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(l > 0))
            continue;
        const double a = f->force[s] / (2 * l);
        const double v6[6] = {a * d[0] * d[0], a * d[1] * d[1], a * d[2] * d[2],
                              a * d[0] * d[1], a * d[1] * d[2], a * d[0] * d[2]};
        for (int k = 0; k < 6; k++) {
            sn[6 * b->si[s] + (size_t)k] += v6[k];
            sn[6 * b->sj[s] + (size_t)k] += v6[k];
        }
    }
    if (b->nfibre) /* and a quarter of each tetrahedron's fibres */
        cf_body_fibre_virial(b, x, sn);
    body_elem_virial(b, x, sn); /* and of its element term */
    for (size_t i = 0; i < nn; i++) {
        const double p = b->kappa_MPa > 0 && V0n[i] > 0 ? b->kappa_MPa * (Vn[i] / V0n[i] - 1) : 0;
        for (int k = 0; k < 6; k++)
            sn[6 * i + (size_t)k] = Vn[i] > 0 ? sn[6 * i + (size_t)k] / Vn[i] + (k < 3 ? p : 0) : 0;
    }
    for (size_t q = 0; q < 6 * nn; q++)
        f->node_stress[q] = fin(sn[q]);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        double *sig = f->stress + 6 * t;
        green_lagrange(b->X, x, v, f->strain + 6 * t);
        for (int k = 0; k < 6; k++) {
            f->strain[6 * t + (size_t)k] = fin(f->strain[6 * t + (size_t)k]);
            sig[k] = fin((sn[6 * v[0] + (size_t)k] + sn[6 * v[1] + (size_t)k] +
                          sn[6 * v[2] + (size_t)k] + sn[6 * v[3] + (size_t)k]) / 4);
        }
        f->mises[t] = fin(von_mises(sig));
    }
    free(Vn);
    free(V0n);
    free(sn);
    return CF_OK;
}
