/*
** Fibre groups: the embedded tension-only springs of the cell (fibre.h).
*/
#include "model/fibre.h"

#include <math.h>

/* A fibre spring closer to solid than this fraction of its travel is refused (as the cell's). */
#define SOLID_MARGIN (1.0 - 1e-9)

cf_status cf_fibre_check(const cf_fibre_group *g, cf_error *err)
{
    if (!g->law)
        return cf_error_set(err, CF_E_DATA, "fibre group: no law");
    double n2 = 0;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(g->dir[i]))
            return cf_error_set(err, CF_E_DATA, "fibre direction component %d = %g: not finite",
                                i, g->dir[i]);
        n2 += g->dir[i] * g->dir[i];
    }
    if (!(fabs(sqrt(n2) - 1) <= 1e-12))
        return cf_error_set(err, CF_E_DATA, "fibre direction (%g, %g, %g): length %.17g, not 1",
                            g->dir[0], g->dir[1], g->dir[2], sqrt(n2));
    if (!(isfinite(g->slack) && g->slack >= 0 && g->slack < 1))
        return cf_error_set(err, CF_E_DATA, "fibre recruitment strain %g: must be finite, in "
                            "[0, 1)", g->slack);
    if (!(isfinite(g->density) && g->density > 0))
        return cf_error_set(err, CF_E_DATA, "fibre density %g springs per cell: must be finite "
                            "and > 0", g->density);
    return CF_OK;
}

double cf_fibre_stretch(const cf_fibre_group *g, const double F[9], double Fa[3])
{
    for (int i = 0; i < 3; i++)
        Fa[i] = F[3 * i] * g->dir[0] + F[3 * i + 1] * g->dir[1] + F[3 * i + 2] * g->dir[2];
    return sqrt(Fa[0] * Fa[0] + Fa[1] * Fa[1] + Fa[2] * Fa[2]);
}

double cf_fibre_compression(const cf_fibre_group *g, double lambda)
{
    return lambda > 1 + g->slack ? g->law->p.H_mm * (lambda - 1 - g->slack) : 0;
}

/* Tension T (N) and dT/du k (N/mm) at stretch lambda; CF_E_DATA at solid. */
static cf_status tension(const cf_fibre_group *g, double lambda, double *T, double *k, double *r,
                         cf_error *err)
{
    *T = 0, *k = 0, *r = 0;
    const double Hf = g->law->p.H_mm, u = cf_fibre_compression(g, lambda);
    if (!(u > 0))
        return CF_OK; /* slack */
    *r = u / cf_law_travel_at(g->law, u);
    if (!(*r < SOLID_MARGIN))
        return cf_error_set(err, CF_E_DATA,
                            "the fibre spring along (%.6g, %.6g, %.6g) reaches solid (stretch "
                            "%.6g, solid at %.6g)",
                            g->dir[0], g->dir[1], g->dir[2], lambda,
                            1 + g->slack + cf_law_travel_at(g->law, u) / Hf);
    *T = cf_law_force(g->law, g->method, u, k, NULL);
    return CF_OK;
}

cf_status cf_fibre_add_stress(const cf_fibre_group *g, double H_mm, const double F[9],
                              double P[3][3], double *tension_N, double *r, cf_error *err)
{
    double Fa[3], T, k;
    const double lambda = cf_fibre_stretch(g, F, Fa);
    cf_status st = tension(g, lambda, &T, &k, r, err);
    *tension_N = T;
    if (st != CF_OK || T == 0)
        return st;
    const double phi = g->density * g->law->p.H_mm * T / (H_mm * H_mm * H_mm) / lambda;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            P[i][j] += phi * Fa[i] * g->dir[j];
    return CF_OK;
}

cf_status cf_fibre_add_tangent(const cf_fibre_group *g, double H_mm, const double F[9],
                               double A[81], cf_error *err)
{
    double Fa[3], T, k, r;
    const double lambda = cf_fibre_stretch(g, F, Fa);
    cf_status st = tension(g, lambda, &T, &k, &r, err);
    if (st != CF_OK || !(cf_fibre_compression(g, lambda) > 0))
        return st;
    const double Hf = g->law->p.H_mm, H3 = H_mm * H_mm * H_mm;
    const double phi = g->density * Hf * T / H3 / lambda;
    const double c1 = g->density * Hf * (Hf * k * lambda - T) / (H3 * lambda * lambda * lambda);
    const double *a = g->dir;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int kk = 0; kk < 3; kk++)
                for (int l = 0; l < 3; l++)
                    A[27 * i + 9 * j + 3 * kk + l] +=
                        c1 * Fa[i] * a[j] * Fa[kk] * a[l] + (i == kk ? phi * a[j] * a[l] : 0);
    return CF_OK;
}
