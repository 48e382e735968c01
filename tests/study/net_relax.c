/*
** How far a body's spring network relaxes below its calibration (src/notes/contact-study.md,
** "Why the sphere drifts"): the study's graded quarter block (contact_study.c), its springs at
** small strain (k = c k0 H / L0), an affine strain imposed on the block's boundary, the inner
** nodes left to find their equilibrium (conjugate gradients). Prints, per strain mode, the
** network's energy before relaxing (the calibration's Voigt average) and after, over that of
** the isotropic continuum of the body's mu and lambda = mu. SIDE mm (default 30) shrinks the
** block about the contact point, meshed as the study meshes it there (the contact zone's
** elements only).
**
**   net_relax REFINE [SIDE]
*/
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/mesh.h"
#include "model/body.h"
#include "model/body_internal.h"

/* y = K x for the springs' stiffness K = sum k n n^T on (i, j) pairs; free: per node 1 */
static void apply_k(const cf_body *b, const double *k, const double *x, double *y)
{
    memset(y, 0, 3 * b->nn * sizeof *y);
    for (size_t s = 0; s < b->ns; s++) {
        const uint32_t i = b->si[s], j = b->sj[s];
        double n[3], d = 0;
        for (int a = 0; a < 3; a++)
            n[a] = (b->X[3 * j + a] - b->X[3 * i + a]) / b->L0[s];
        for (int a = 0; a < 3; a++)
            d += n[a] * (x[3 * j + a] - x[3 * i + a]);
        for (int a = 0; a < 3; a++) {
            y[3 * j + a] += k[s] * d * n[a];
            y[3 * i + a] -= k[s] * d * n[a];
        }
    }
}

static double dot(const double *a, const double *c, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * c[i];
    return s;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: net_relax REFINE [RHO]\n");
        return 2;
    }
    const double r = atof(argv[1]);
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 70;
    const double W = argc > 2 ? atof(argv[2]) : 30, D = W;
    double lo[3] = {0, 0, -D}, hi[3] = {W, W, 0}, focus[3] = {0, 0, 0};
    cf_mesh m;
    if (cf_mesh_box(lo, hi, focus, 0.3 / r, 8 / r, 0.4 / r, &m, &err) != CF_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 70;
    }
    cf_body b;
    if (cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err) != CF_OK)
        return 70;
    const size_t n3 = 3 * b.nn;
    double *k = malloc(b.ns * sizeof *k), *u = malloc(n3 * sizeof *u), *res = malloc(n3 * sizeof *res),
           *pd = malloc(n3 * sizeof *pd), *q = malloc(n3 * sizeof *q), *z = malloc(n3 * sizeof *z),
           *dg = calloc(n3, sizeof *dg);
    uint8_t *fr = calloc(b.nn, 1);
    if (!k || !u || !res || !pd || !q || !z || !dg || !fr)
        return 70;
    for (size_t s = 0; s < b.ns; s++)
        k[s] = b.c[s] * law.k0_N_per_mm * law.p.H_mm / b.L0[s];
    size_t nfree = 0;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        const int bnd = X[0] < 1e-9 || X[1] < 1e-9 || X[2] > -1e-9 || X[0] > W - 1e-9 ||
                        X[1] > W - 1e-9 || X[2] < -D + 1e-9;
        fr[i] = !bnd;
        nfree += fr[i];
    }
    for (size_t s = 0; s < b.ns; s++)
        for (int a = 0; a < 3; a++) {
            double n = (b.X[3 * b.sj[s] + a] - b.X[3 * b.si[s] + a]) / b.L0[s];
            dg[3 * b.si[s] + a] += k[s] * n * n;
            dg[3 * b.sj[s] + a] += k[s] * n * n;
        }
    static const char *name[4] = {"uniaxial strain zz", "shear xz", "shear xy", "pure shear xx-yy"};
    static const double G[4][3][3] = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 1}},
                                      {{0, 0, .5}, {0, 0, 0}, {.5, 0, 0}},
                                      {{0, .5, 0}, {.5, 0, 0}, {0, 0, 0}},
                                      {{.5, 0, 0}, {0, -.5, 0}, {0, 0, 0}}};
    printf("refine %g, side %g mm, %zu nodes, %zu inner\n", r, W, b.nn, nfree);
    for (int mode = 0; mode < 4; mode++) {
        for (size_t i = 0; i < b.nn; i++)
            for (int a = 0; a < 3; a++)
                u[3 * i + a] = G[mode][a][0] * b.X[3 * i] + G[mode][a][1] * b.X[3 * i + 1] +
                               G[mode][a][2] * b.X[3 * i + 2];
        /* the springs' energy and the continuum's */
        double Wv = 0, Vfree = 0;
        for (size_t s = 0; s < b.ns; s++) {
                double d = 0;
                for (int a = 0; a < 3; a++)
                    d += (b.X[3 * b.sj[s] + a] - b.X[3 * b.si[s] + a]) / b.L0[s] *
                         (u[3 * b.sj[s] + a] - u[3 * b.si[s] + a]);
                Wv += 0.5 * k[s] * d * d;
            }
        for (size_t t = 0; t < b.nt; t++)
            Vfree += b.V0[t];
        double ee = 0, tr = G[mode][0][0] + G[mode][1][1] + G[mode][2][2];
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++)
                ee += G[mode][a][c] * G[mode][a][c];
        const double Wiso = Vfree * b.mu_MPa * (ee + 0.5 * tr * tr);
        /* conjugate gradients on the free nodes (Jacobi), from the affine field */
        apply_k(&b, k, u, res);
        for (size_t i = 0; i < n3; i++)
            res[i] = fr[i / 3] ? -res[i] : 0;
        for (size_t i = 0; i < n3; i++)
            pd[i] = z[i] = fr[i / 3] ? res[i] / dg[i] : 0;
        double rz = dot(res, z, n3), r0 = sqrt(dot(res, res, n3));
        int it = 0;
        double dW = 0;
        for (; it < 20000 && sqrt(dot(res, res, n3)) > 1e-10 * r0; it++) {
            apply_k(&b, k, pd, q);
            for (size_t i = 0; i < n3; i++)
                q[i] = fr[i / 3] ? q[i] : 0;
            const double al = rz / dot(pd, q, n3);
            for (size_t i = 0; i < n3; i++) {
                u[i] += al * pd[i];
                res[i] -= al * q[i];
            }
            dW += 0.5 * al * rz; /* the energy each step releases */
            for (size_t i = 0; i < n3; i++)
                z[i] = fr[i / 3] ? res[i] / dg[i] : 0;
            const double rz1 = dot(res, z, n3);
            for (size_t i = 0; i < n3; i++)
                pd[i] = z[i] + rz1 / rz * pd[i];
            rz = rz1;
        }
        printf("  %-20s Voigt/iso %.4f  relaxed/iso %.4f  relaxed/Voigt %.4f  (%d CG steps)\n",
               name[mode], Wv / Wiso, (Wv - dW) / Wiso, (Wv - dW) / Wv, it);
    }
    free(k), free(u), free(res), free(pd), free(q), free(z), free(dg), free(fr);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    return 0;
}
