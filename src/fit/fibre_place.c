/*
** The fibre-reinforced lattice as buildable springs (fibre_fit.h, cf_fibre_place): each family's
** stress scale shared by equal springs in parallel, each placed under the design constraints as
** the spring fit places its own, and the cell built of those springs.
**
** Why springs in parallel: in a stress-strain table a family is seen only through (rho, s/H,
** F_C/H^2), and H is a pure scale, so the largest stress scale one spring of a type can carry at
** (rho, s/H) is fixed by the design limits alone (family.h, cf_ident_region_at: the stiffest wire
** G_max at the smallest index 3 and the fewest coils the type allows). A fibre family stiffer than
** that is no spring at any size; count springs of F_C/H^2 = scale / count each carry it, and the
** cell's stress of the family is count times one spring's, so the lattice is the fitted one.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fit/fibre_fit.h"

/* The share of the largest stress scale one spring may take, so that placement does not sit on
** the limits' edge. A stiff family's spring takes the least index, 3, at any share (the coils its
** type needs grow with the index, so its load falls as about the index's fifth power); the
** share's slack goes to a softer wire, G = SHARE G_max at most. */
#define SHARE 0.9

/* The fit through which placement sees the family: four strains up to reach, the family's
** stresses there (a table of the spring's travel; placement's own quality is not used). */
static cf_status reach_table(const cf_ident *q, double reach, double x[4], double y[4],
                             cf_table *t, cf_error *err)
{
    cf_law canon;
    cf_status st = cf_ident_canon_law(q->rho, &canon);
    if (st != CF_OK)
        return cf_error_set(err, CF_E_DATA, "diameter ratio rho = %g has no conical law", q->rho);
    for (int i = 0; i < 4; i++) {
        x[i] = reach * (i + 1) / 4.0;
        y[i] = cf_ident_reduced(&canon, q->scale, q->solid, x[i], NULL);
    }
    cf_law_free(&canon);
    memset(t, 0, sizeof *t);
    t->kind = CF_TABLE_STRESS_STRAIN;
    t->count = 4;
    t->x = x;
    t->y = y;
    t->y_to_file = 1;
    snprintf(t->y_unit, sizeof t->y_unit, "MPa");
    snprintf(t->path, sizeof t->path, "fibre-lattice family");
    return CF_OK;
}

/* The spring p scaled to free length H_mm: D1, D2, d and H by one factor, n and G kept, which
** keeps rho, s/H and F_C/H^2 (F_C = G d^4 s / (8 n D1^3) goes as the factor squared). */
static cf_spring scaled(const cf_spring *p, double H_mm)
{
    const double f = H_mm / p->H_mm;
    cf_spring s = *p;
    s.D1_mm *= f;
    s.D2_mm *= f;
    s.d_mm *= f;
    s.H_mm = H_mm;
    return s;
}

/* count springs of type sharing q's scale, placed (*out filled). */
static cf_status place_count(const cf_ident *q, double reach, const cf_fit_options *opt,
                             cf_spring_type type, int count, double H_mm, cf_fibre_spring *out,
                             cf_error *err)
{
    cf_ident one = *q;
    one.scale = q->scale / count;
    double x[4], y[4];
    cf_table t;
    cf_fit_result res;
    cf_status st = reach_table(&one, reach, x, y, &t, err);
    if (st != CF_OK || (st = cf_fit_place(&t, opt, type, &one, &res, err)) != CF_OK)
        return st;
    *out = (cf_fibre_spring){res.params, type, count, res.feasible, res.violated, reach};
    if (H_mm > 0) {
        unsigned active = 0;
        out->spring = scaled(&res.params, H_mm);
        out->violated = 0;
        out->buildable = cf_fit_check(&out->spring, type, &t, opt, &active, &out->violated);
    }
    return CF_OK;
}

/* The placement of one type (*out), buildable or not; 0 when the type cannot place q at all. */
static int place_type(const cf_ident *q, double reach, const cf_fit_options *opt,
                      cf_spring_type type, double H_mm, cf_fibre_spring *out, cf_status *st,
                      cf_error *err)
{
    double A_max = INFINITY;
    const double margin = cf_fit_ident_limit(opt, type, q->rho, q->solid, &A_max, NULL);
    if (!(margin <= 0) || !(A_max > 0))
        return 0;
    const double need = isfinite(A_max) ? ceil(q->scale / (SHARE * A_max)) : 1;
    if (!(need <= CF_FIBRE_COUNT_MAX))
        return 0;
    int count = need < 1 ? 1 : (int)need;
    /* the placement's search may miss a point the closed form allows: more springs, each
    ** lighter, a few times */
    for (int k = 0; k < 4 && count <= CF_FIBRE_COUNT_MAX; k++) {
        if ((*st = place_count(q, reach, opt, type, count, H_mm, out, err)) != CF_OK ||
            out->buildable)
            break;
        count = (int)ceil(count * 1.5);
    }
    return *st == CF_OK;
}

cf_status cf_fibre_place(const cf_ident *q, double reach, const cf_fit_options *opt, double H_mm,
                         cf_fibre_spring *out, cf_error *err)
{
    if (!(q->rho > 0 && q->solid > 0 && q->solid < 1 && q->scale > 0 && isfinite(q->scale) &&
          reach > 0 && isfinite(reach)))
        return cf_error_set(err, CF_E_DATA, "fibre-lattice family rho %g, s/H %g, F_C/H^2 %g MPa, "
                            "reach %g: not a family a spring can have", q->rho, q->solid,
                            q->scale, reach);
    const cf_spring_type order[2] = {CF_NON_TELESCOPING, CF_TELESCOPING};
    int have = 0;
    for (int k = 0; k < 2; k++) {
        cf_fibre_spring s;
        cf_status st = CF_OK;
        const int placed = place_type(q, reach, opt, order[k], H_mm, &s, &st, err);
        if (st == CF_E_INTERNAL)
            return st;
        if (placed && s.buildable && (!have || s.count < out->count)) {
            *out = s;
            have = 1;
        }
    }
    if (have)
        return CF_OK;
    /* no type places it: one spring, flagged with the limits it breaks */
    return place_count(q, reach, opt, CF_NON_TELESCOPING, 1, H_mm, out, err);
}
