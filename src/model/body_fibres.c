/*
** Fibre groups of a tissue body (body.h, cf_body_add_fibres): per tetrahedron a tension-only
** spring along a reference direction, the homogenised cell's fibre group (fibre.h) evaluated at
** the tetrahedron's deformation gradient. A linear tetrahedron deforms affinely, so its
** F = sum_m x_m (grad N_m)^T is exact, and the group's energy V0 W(F) gives the nodal forces
** V0 P grad N_m and the stiffness blocks V0 A_ijkl (grad N_m)_j (grad N_q)_l (the total
** Lagrangian form of the linear tetrahedron; Bonet & Wood, Nonlinear Continuum Mechanics for
** Finite Element Analysis, 2nd ed. 2008, ch. 9).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

#define PI 3.14159265358979323846

/* Reference shape-function gradients of every tetrahedron into b->fgrad (12 nt): with the edge
** matrix D = [X1 - X0, X2 - X0, X3 - X0], grad N_m (m = 1..3) is row m - 1 of D^-1 and grad N_0
** minus their sum. */
static int shape_gradients(cf_body *b)
{
    b->fgrad = malloc((b->nt ? 12 * b->nt : 1) * sizeof *b->fgrad);
    if (!b->fgrad)
        return 0;
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        double D[3][3], *G = b->fgrad + 12 * t;
        for (int i = 0; i < 3; i++)
            for (int m = 0; m < 3; m++)
                D[i][m] = b->X[3 * v[m + 1] + (size_t)i] - b->X[3 * v[0] + (size_t)i];
        const double det = D[0][0] * (D[1][1] * D[2][2] - D[1][2] * D[2][1]) -
                           D[0][1] * (D[1][0] * D[2][2] - D[1][2] * D[2][0]) +
                           D[0][2] * (D[1][0] * D[2][1] - D[1][1] * D[2][0]);
        for (int r = 0; r < 3; r++) /* inverse by cofactors: (D^-1)_rc = C_cr / det */
            for (int c = 0; c < 3; c++) {
                const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
                G[3 * (r + 1) + c] = (D[r1][c1] * D[r2][c2] - D[r1][c2] * D[r2][c1]) / det;
            }
        for (int c = 0; c < 3; c++)
            G[c] = -(G[3 + c] + G[6 + c] + G[9 + c]);
    }
    return 1;
}

cf_status cf_body_add_fibres(cf_body *b, const cf_spring *spring, double density, double slack,
                             const double *dir, size_t table_intervals, const char *key,
                             cf_error *err)
{
    if (b->nfibre >= CF_FIBRE_MAX)
        return cf_error_set(err, CF_E_DATA, "%s: a body has at most %d fibre groups", key,
                            CF_FIBRE_MAX);
    if (!(isfinite(density) && density > 0))
        return cf_error_set(err, CF_E_DATA, "%s: density = %g springs per cell: must be finite and "
                            "> 0", key, density);
    if (!(isfinite(slack) && slack >= 0 && slack < 1))
        return cf_error_set(err, CF_E_DATA, "%s: recruitment_strain = %g: must be in [0, 1)", key,
                            slack);
    for (size_t t = 0; t < b->nt; t++) {
        const double *a = dir + 3 * t, n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        if (!(fabs(n - 1) <= 1e-12))
            return cf_error_set(err, CF_E_DATA, "%s: the direction in tetrahedron %zu, (%g, %g, "
                                "%g), is not a finite unit vector", key, t, a[0], a[1], a[2]);
    }
    if (!b->flaw && !(b->flaw = calloc(CF_FIBRE_MAX, sizeof *b->flaw)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's fibres");
    if (!b->fdir && !(b->fdir = calloc(b->nt ? 3 * CF_FIBRE_MAX * b->nt : 1, sizeof *b->fdir)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's fibres");
    if (!b->fgrad && !shape_gradients(b))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's fibres");
    cf_law *law = &b->flaw[b->nfibre];
    cf_error lerr = {0};
    cf_status st = cf_law_init(law, spring, &lerr);
    if (st == CF_OK && b->method == CF_LAW_TABLE)
        st = cf_law_table_build(law, table_intervals, &lerr);
    if (st != CF_OK) {
        cf_law_free(law);
        return cf_error_set(err, st, "%s.spring: %s", key, lerr.msg);
    }
    const size_t k = b->nfibre++;
    b->fdensity[k] = density;
    b->fslack[k] = slack;
    for (size_t t = 0; t < b->nt; t++)
        memcpy(b->fdir + 3 * (CF_FIBRE_MAX * t + k), dir + 3 * t, 3 * sizeof *dir);
    return CF_OK;
}

/* Tetrahedron t's deformation gradient at positions x (row-major). */
static void tet_F(const cf_body *b, const double *x, size_t t, double F[9])
{
    const uint32_t *v = b->tet + 4 * t;
    const double *G = b->fgrad + 12 * t;
    memset(F, 0, 9 * sizeof *F);
    for (int m = 0; m < 4; m++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                F[3 * i + j] += x[3 * v[m] + (size_t)i] * G[3 * m + j];
}

/* Group k of tetrahedron t as the cell's fibre group. */
static cf_fibre_group group_at(const cf_body *b, size_t k, size_t t)
{
    cf_fibre_group fg = {&b->flaw[k], b->method, {0, 0, 0}, b->fdensity[k], b->fslack[k]};
    memcpy(fg.dir, b->fdir + 3 * (CF_FIBRE_MAX * t + k), sizeof fg.dir);
    return fg;
}

/* Adds V0 A_ijkl G_mj G_ql, the stiffness of corners m and q, to the tangent. */
static void tet_tangent(const cf_body *b, size_t t, const double A[81], pattern *P)
{
    const uint32_t *v = b->tet + 4 * t;
    const double *G = b->fgrad + 12 * t, V0 = b->V0[t];
    for (int m = 0; m < 4; m++)
        for (int q = 0; q < 4; q++) {
            double B[9] = {0};
            for (int i = 0; i < 3; i++)
                for (int kk = 0; kk < 3; kk++) {
                    double s = 0;
                    for (int j = 0; j < 3; j++)
                        for (int l = 0; l < 3; l++)
                            s += A[27 * i + 9 * j + 3 * kk + l] * G[3 * m + j] * G[3 * q + l];
                    B[3 * i + kk] = V0 * s;
                }
            body_add_block(P, v[q], P->tblk[16 * t + 4 * (size_t)m + (size_t)q], B);
        }
}

void cf_body_fibre_forces(const cf_body *b, const double *x, double *g, pattern *P)
{
    const double H = b->law->p.H_mm;
    for (size_t t = 0; t < b->nt; t++) {
        double F[9], Pk[3][3] = {{0}}, A[81] = {0};
        int any = 0;
        tet_F(b, x, t, F);
        for (size_t k = 0; k < b->nfibre; k++) {
            const cf_fibre_group fg = group_at(b, k, t);
            double T = 0, r = 0;
            if (cf_fibre_add_stress(&fg, H, F, Pk, &T, &r, NULL) != CF_OK || T == 0)
                continue; /* slack, or at solid (an inadmissible state) */
            any = 1;
            if (P)
                cf_fibre_add_tangent(&fg, H, F, A, NULL);
        }
        if (!any)
            continue;
        const uint32_t *v = b->tet + 4 * t;
        const double *G = b->fgrad + 12 * t;
        for (int m = 0; m < 4; m++)
            for (int i = 0; i < 3; i++)
                g[3 * v[m] + (size_t)i] += b->V0[t] * (Pk[i][0] * G[3 * m] + Pk[i][1] * G[3 * m + 1] +
                                                      Pk[i][2] * G[3 * m + 2]);
        if (P)
            tet_tangent(b, t, A, P);
    }
}

void cf_body_fibre_virial(const cf_body *b, const double *x, double *sn)
{
    const double H = b->law->p.H_mm;
    static const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    for (size_t t = 0; t < b->nt; t++) {
        double F[9], Pk[3][3] = {{0}};
        tet_F(b, x, t, F);
        for (size_t k = 0; k < b->nfibre; k++) {
            const cf_fibre_group fg = group_at(b, k, t);
            double T, r;
            cf_fibre_add_stress(&fg, H, F, Pk, &T, &r, NULL);
        }
        for (int q = 0; q < 6; q++) { /* (F P^T)_ij = sum_l F_il P_jl */
            const int i = ij[q][0], j = ij[q][1];
            const double w = b->V0[t] * (F[3 * i] * Pk[j][0] + F[3 * i + 1] * Pk[j][1] +
                                         F[3 * i + 2] * Pk[j][2]) / 4;
            for (int m = 0; m < 4; m++)
                sn[6 * b->tet[4 * t + (size_t)m] + (size_t)q] += w;
        }
    }
}

double cf_body_fibre_umax(const cf_body *b, const double *x)
{
    double umax = 0;
    for (size_t t = 0; t < b->nt; t++) {
        double F[9], Fa[3];
        tet_F(b, x, t, F);
        for (size_t k = 0; k < b->nfibre; k++) {
            const cf_fibre_group fg = group_at(b, k, t);
            const double lambda = cf_fibre_stretch(&fg, F, Fa);
            if (!isfinite(lambda))
                return INFINITY;
            const double u = cf_fibre_compression(&fg, lambda);
            if (u > 0)
                umax = fmax(umax, u / cf_law_travel_at(fg.law, u));
        }
    }
    return umax;
}

/* The unit vector of v, or 0 when it has no finite length. */
static int unit(const double v[3], double out[3])
{
    const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(isfinite(n) && n > 0))
        return 0;
    for (int i = 0; i < 3; i++)
        out[i] = v[i] / n;
    return 1;
}

cf_status cf_body_helix_dirs(const cf_body *b, const double normal[3], const double reference[3],
                             double from_deg, double to_deg, double *dir, cf_error *err)
{
    double n[3], e1[3], e2[3];
    if (!unit(normal, n))
        return cf_error_set(err, CF_E_DATA, "normal (%g, %g, %g): not a finite nonzero vector",
                            normal[0], normal[1], normal[2]);
    const double rn = reference[0] * n[0] + reference[1] * n[1] + reference[2] * n[2];
    const double pr[3] = {reference[0] - rn * n[0], reference[1] - rn * n[1],
                          reference[2] - rn * n[2]};
    const double rl = sqrt(reference[0] * reference[0] + reference[1] * reference[1] +
                           reference[2] * reference[2]);
    if (!(isfinite(from_deg) && isfinite(to_deg)))
        return cf_error_set(err, CF_E_DATA, "angles %g, %g degrees: not finite", from_deg, to_deg);
    if (!unit(pr, e1) || !(sqrt(pr[0] * pr[0] + pr[1] * pr[1] + pr[2] * pr[2]) > 1e-6 * rl))
        return cf_error_set(err, CF_E_DATA, "reference (%g, %g, %g): parallel to the normal or not "
                            "finite (it gives the angle's zero in the plane normal to it)",
                            reference[0], reference[1], reference[2]);
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < b->nn; i++) {
        const double *X = b->X + 3 * i, h = n[0] * X[0] + n[1] * X[1] + n[2] * X[2];
        lo = fmin(lo, h);
        hi = fmax(hi, h);
    }
    if (!(hi > lo))
        return cf_error_set(err, CF_E_DATA, "the body has no thickness along the normal (%g, %g, "
                            "%g)", n[0], n[1], n[2]);
    for (size_t t = 0; t < b->nt; t++) {
        double h = 0;
        for (int m = 0; m < 4; m++)
            for (int i = 0; i < 3; i++)
                h += n[i] * b->X[3 * b->tet[4 * t + (size_t)m] + (size_t)i] / 4;
        const double s = (h - lo) / (hi - lo), th = (from_deg + s * (to_deg - from_deg)) * PI / 180;
        double a[3];
        for (int i = 0; i < 3; i++)
            a[i] = cos(th) * e1[i] + sin(th) * e2[i];
        unit(a, dir + 3 * t); /* renormalised to the last bit */
    }
    return CF_OK;
}
