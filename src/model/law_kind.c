/*
** A law of another kind than the conical spring's (lawmech.h, law_internal.h): its evaluations
** behind law.h's entry points, and the public accessors of the opaque cf_law. Its law is made in
** law_make.c (which calls this file and law.c; law.c calls this file: no cycle).
*/
#include "model/law_internal.h"

#include <math.h>
#include <string.h>

double cf_law_kind_force(const cf_law *law, double u_mm, double *k_N_per_mm, int *flags)
{
    const double H = law->p.H_mm;
    const double s = u_mm < 0 ? law->travel_stretch_mm : law->travel_mm;
    double F, k = 0.0;
    int fl = 0;
    if (isnan(u_mm)) {
        F = 0.0;
        fl = CF_LAW_SOLID;
    } else if (!(fabs(u_mm) < s)) { /* at or past a side's travel: held there, as solid */
        F = law->mech->force(law->q, H, u_mm < 0 ? -s : s, NULL);
        fl = CF_LAW_SOLID;
    } else {
        F = law->mech->force(law->q, H, u_mm, &k);
    }
    if (!isfinite(F))
        F = 0.0;
    if (!(isfinite(k) && k >= 0))
        k = 0.0;
    if (k_N_per_mm)
        *k_N_per_mm = k;
    if (flags)
        *flags = fl;
    return F;
}

void cf_law_kind_force_many(const cf_law *law, size_t count, const double *u_mm, double *F_N,
                            double *k_N_per_mm)
{
    int inside = law->mech->force_many != NULL;
    for (size_t i = 0; inside && i < count; i++)
        inside = fabs(u_mm[i]) < (u_mm[i] < 0 ? law->travel_stretch_mm : law->travel_mm);
    if (inside) { /* the row's own batch: every point within the travels */
        law->mech->force_many(law->q, law->p.H_mm, count, u_mm, F_N, k_N_per_mm);
        return;
    }
    for (size_t i = 0; i < count; i++)
        F_N[i] = cf_law_kind_force(law, u_mm[i], k_N_per_mm ? &k_N_per_mm[i] : NULL, NULL);
}

double cf_law_kind_deflection(const cf_law *law, double F_N)
{
    if (isnan(F_N))
        return 0.0;
    const double sign = F_N < 0 ? -1.0 : 1.0, s = sign < 0 ? law->travel_stretch_mm
                                                          : law->travel_mm;
    if (fabs(F_N) >= fabs(cf_law_kind_force(law, sign * s, NULL, NULL)))
        return sign * s;
    double lo = 0.0, hi = s; /* |F| rises with |u| on [0, s]: bisection to the last bit */
    for (int it = 0; it < 200 && hi - lo > 0; it++) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (fabs(cf_law_kind_force(law, sign * mid, NULL, NULL)) < fabs(F_N))
            lo = mid;
        else
            hi = mid;
    }
    return sign * 0.5 * (lo + hi);
}

/* ---- the public constructor and accessors ----------------------------------------------------- */

double cf_law_travel(const cf_law *law, double u_mm)
{
    return cf_law_travel_at(law, u_mm);
}

double cf_law_solid_force(const cf_law *law, double u_mm)
{
    if (law->mech)
        return cf_law_kind_force(law, u_mm < 0 ? -law->travel_stretch_mm : law->travel_mm, NULL,
                                 NULL);
    if (u_mm < 0)
        return -(law->extension ? law->extension : law)->F_solid_N;
    return law->F_solid_N;
}

cf_spring cf_law_spring(const cf_law *law)
{
    return law->p;
}

const char *cf_law_kind_of(const cf_law *law)
{
    if (law->mech)
        return law->mech->name;
    return law->extension ? "double-acting" : law->tail ? "conical-tail" : "conical";
}
