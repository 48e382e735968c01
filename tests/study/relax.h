/*
** The relaxation of a body's spring network below its calibration (src/notes/contact-study.md,
** "Why the sphere drifts"), shared by tests/study/net_relax.c and tests/unit/test_body.c: the
** springs at small strain (k = c k0 H / L0), the affine displacement u = G X imposed on every
** node whose free[i] is 0, the others left to find their equilibrium by conjugate gradients
** (Jacobi). Returns the springs' energy after relaxing over their energy in the affine field (the
** calibration's average, the Voigt bound) and sets *voigt_over_iso to that energy over the
** isotropic continuum's of the body's mu and lambda = mu; -1 when memory runs out.
*/
#ifndef CONIFIT_TESTS_STUDY_RELAX_H
#define CONIFIT_TESTS_STUDY_RELAX_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "model/body.h"

/* y = K x for the springs' stiffness K = sum k n n^T */
static void relax_apply(const cf_body *b, const double *k, const double *x, double *y)
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

static double relax_dot(const double *a, const double *c, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * c[i];
    return s;
}

/* The energy the conjugate gradients release from the affine field u (changed in place). */
static double relax_cg(const cf_body *b, const double *k, const uint8_t *fr, const double *dg,
                       double *u, double *res, double *pd, double *q, double *z)
{
    const size_t n3 = 3 * b->nn;
    relax_apply(b, k, u, res);
    for (size_t i = 0; i < n3; i++) {
        res[i] = fr[i / 3] ? -res[i] : 0;
        pd[i] = z[i] = fr[i / 3] ? res[i] / dg[i] : 0;
    }
    double rz = relax_dot(res, z, n3), dW = 0;
    const double r0 = sqrt(relax_dot(res, res, n3));
    for (int it = 0; it < 20000 && sqrt(relax_dot(res, res, n3)) > 1e-10 * r0; it++) {
        relax_apply(b, k, pd, q);
        for (size_t i = 0; i < n3; i++)
            q[i] = fr[i / 3] ? q[i] : 0;
        const double al = rz / relax_dot(pd, q, n3);
        for (size_t i = 0; i < n3; i++) {
            u[i] += al * pd[i];
            res[i] -= al * q[i];
        }
        dW += 0.5 * al * rz; /* the energy each exact line minimisation releases */
        for (size_t i = 0; i < n3; i++)
            z[i] = fr[i / 3] ? res[i] / dg[i] : 0;
        const double rz1 = relax_dot(res, z, n3);
        for (size_t i = 0; i < n3; i++)
            pd[i] = z[i] + rz1 / rz * pd[i];
        rz = rz1;
    }
    return dW;
}

static double relax_ratio(const cf_body *b, const cf_law *law, const double G[3][3],
                          const uint8_t *fr, double *voigt_over_iso)
{
    const size_t n3 = 3 * b->nn;
    *voigt_over_iso = NAN;
    double *k = malloc(b->ns * sizeof *k), *w = malloc(5 * n3 * sizeof *w),
           *dg = calloc(n3, sizeof *dg);
    if (!k || !w || !dg) {
        free(k), free(w), free(dg);
        return -1;
    }
    double *u = w, *res = w + n3, *pd = w + 2 * n3, *q = w + 3 * n3, *z = w + 4 * n3;
    for (size_t s = 0; s < b->ns; s++)
        k[s] = b->c[s] * law->k0_N_per_mm * law->p.H_mm / b->L0[s];
    for (size_t i = 0; i < b->nn; i++)
        for (int a = 0; a < 3; a++)
            u[3 * i + a] =
                G[a][0] * b->X[3 * i] + G[a][1] * b->X[3 * i + 1] + G[a][2] * b->X[3 * i + 2];
    double Wv = 0, V = 0, ee = 0;
    for (size_t s = 0; s < b->ns; s++) {
        double d = 0;
        for (int a = 0; a < 3; a++) {
            const double n = (b->X[3 * b->sj[s] + a] - b->X[3 * b->si[s] + a]) / b->L0[s];
            d += n * (u[3 * b->sj[s] + a] - u[3 * b->si[s] + a]);
            dg[3 * b->si[s] + a] += k[s] * n * n;
            dg[3 * b->sj[s] + a] += k[s] * n * n;
        }
        Wv += 0.5 * k[s] * d * d;
    }
    for (size_t t = 0; t < b->nt; t++)
        V += b->V0[t];
    const double tr = G[0][0] + G[1][1] + G[2][2];
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++)
            ee += 0.25 * (G[a][c] + G[c][a]) * (G[a][c] + G[c][a]);
    *voigt_over_iso = Wv / (V * b->mu_MPa * (ee + 0.5 * tr * tr));
    const double dW = relax_cg(b, k, fr, dg, u, res, pd, q, z);
    free(k), free(w), free(dg);
    return (Wv - dW) / Wv;
}

#endif
