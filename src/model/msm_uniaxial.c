/*
** The static uniaxial lattice (see msm.h): the validation curve, the strain where it first loses
** stability, and the inertia of a homogeneous state.
*/
#include "model/msm_internal.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Stability scan of the uniaxial lattice: steps up to STABILITY_REACH of the solid strain, then
** bisections between the last stable strain and the first unstable one (resolution
** REACH / STEPS / 2^BISECT of the solid strain, about 1e-5). */
#define STABILITY_REACH 0.995
#define STABILITY_STEPS 32
#define STABILITY_BISECT 11

/* ---- the uniaxial validation curve ----------------------------------------------------------- */

typedef struct keyed {
    double key;
    size_t i;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    double x = ((const keyed *)a)->key, y = ((const keyed *)b)->key;
    return (x > y) - (x < y);
}

cf_status cf_msm_uniaxial(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                          const double *strain, size_t count, double *stress_MPa,
                          cf_msm_stats *stats, cf_error *err)
{
    CF_GSL_GUARD;
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    cf_msm_stats local = {0};
    cf_msm_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    for (size_t i = 0; i < count; i++)
        if (!isfinite(strain[i]))
            return cf_error_set(err, CF_E_DATA, "strain[%zu] = %g is not finite", i, strain[i]);
    cf_lattice lat;
    cf_status rc = cf_lattice_create(&lat, law, m, &cfg.lattice, err);
    if (rc != CF_OK)
        return rc;
    keyed *idx = malloc((count ? count : 1) * sizeof(keyed));
    if (!idx) {
        cf_lattice_free(&lat);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < count; i++) {
        idx[i].key = fabs(strain[i]);
        idx[i].i = i;
    }
    qsort(idx, count, sizeof(keyed), cmp_keyed);
    solver s;
    if ((rc = cf_msm_solver_init(&s, &lat, NULL, &cfg, CF_DRIVE_DISPLACEMENT, st, err)) != CF_OK) {
        free(idx);
        cf_lattice_free(&lat);
        return rc;
    }
    s.chord = 1; /* only the curve is reported, not the inertia of each state */
    if ((rc = cf_msm_solver_secant(&s, err)) != CF_OK) {
        cf_msm_solver_free(&s);
        free(idx);
        cf_lattice_free(&lat);
        return rc;
    }
    /* Two passes from the reference state: compression (table strain < 0), then tension. */
    for (int pass = 0; pass < 2 && rc == CF_OK; pass++) {
        cf_lattice_reset(&lat);
        s.load = 0;
        s.refactor = 1;
        s.prev_ok = 0;
        for (size_t r = 0; r < count && rc == CF_OK; r++) {
            size_t i = idx[r].i;
            double e = -strain[i]; /* compressive-positive */
            if ((pass == 0) != (e > 0))
                continue;
            if (e == 0) {
                stress_MPa[i] = 0;
                continue;
            }
            /* the loaded edge's spring on the table's side (a pair: tension closes the extension
            ** spring) */
            const double side_travel = cf_lattice_travel_at(&lat, -e);
            if (fabs(e) * lat.H_mm >= side_travel) {
                rc = cf_error_set(err, CF_E_DATA,
                                  "strain %.6g is at or beyond the spring's solid strain %.6g",
                                  strain[i], side_travel / lat.H_mm);
                break;
            }
            rc = cf_msm_static_to(&s, e, err);
            if (rc == CF_OK)
                stress_MPa[i] = -cf_msm_reported_stress(&s);
        }
    }
    if (rc == CF_OK)
        for (size_t i = 0; i < count; i++)
            if (!isfinite(stress_MPa[i]))
                rc = cf_error_set(err, CF_E_INTERNAL, "non-finite lattice stress at strain %g",
                                  strain[i]);
    cf_msm_solver_free(&s);
    free(idx);
    cf_lattice_free(&lat);
    return rc;
}

/* ---- the stability limit of the uniaxial lattice --------------------------------------------- */

/* Negative pivots of the tangent at the current state (a converged equilibrium): assembled and
** factored once more, the update discarded. -1 when no factorisation reports its inertia; *oom
** set when memory ran out (then the count means nothing). */
static long inertia_here(solver *s, int *oom)
{
    double rn, fs;
    cf_msm_residual(s, &rn, &fs);
    s->neg_pivots = -1;
    cf_error e = {0};
    if (cf_msm_direction(s, &e) == CF_E_INTERNAL || e.status == CF_E_INTERNAL)
        *oom = 1;
    return s->neg_pivots;
}

/* The static lattice of cfg built from law and its displacement-driven solver (no effects). */
static cf_status static_open(const cf_law *law, cf_law_method m, const cf_msm_config *cfg,
                             cf_lattice *lat, solver *s, cf_msm_stats *st, cf_error *err)
{
    cf_status rc = cf_lattice_create(lat, law, m, &cfg->lattice, err);
    if (rc != CF_OK)
        return rc;
    if ((rc = cf_msm_solver_init(s, lat, NULL, cfg, CF_DRIVE_DISPLACEMENT, st, err)) != CF_OK)
        cf_lattice_free(lat);
    return rc;
}

cf_status cf_msm_stability_limit(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                                 int side, double *limit, cf_error *err)
{
    CF_GSL_GUARD;
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    *limit = 0;
    cf_lattice lat;
    cf_msm_stats st = {0};
    solver s;
    cf_status rc = static_open(law, m, &cfg, &lat, &s, &st, err);
    if (rc != CF_OK)
        return rc;
    double *keep = malloc(3 * lat.nn * sizeof(double));
    if (!keep) {
        rc = cf_error_set(err, CF_E_INTERNAL, "out of memory");
        goto done;
    }
    /* compressive-positive drive: a table strain of sign `side` is -side times it */
    const double dir = side < 0 ? 1.0 : -1.0;
    const double top = STABILITY_REACH * cf_lattice_travel_at(&lat, -side) / lat.H_mm;
    double stable = 0;
    s.load = 0;
    for (int k = 1; k <= STABILITY_STEPS; k++) {
        double e = top * k / STABILITY_STEPS;
        cf_msm_positions_get(&lat, keep);
        cf_error e1 = {0};
        int oom = 0;
        int lost = cf_msm_static_to(&s, dir * e, &e1) != CF_OK || inertia_here(&s, &oom) > 0;
        if (oom || e1.status == CF_E_INTERNAL) { /* not a loss of stability: memory */
            rc = cf_error_set(err, CF_E_INTERNAL, "out of memory in the stability scan");
            goto done;
        }
        if (!lost) {
            stable = e;
            continue;
        }
        /* Bisect between the last stable strain and this one, each solve from the stable state. */
        double hi = e;
        for (int b = 0; b < STABILITY_BISECT; b++) {
            double mid = 0.5 * (stable + hi);
            cf_msm_positions_set(&lat, keep);
            s.load = dir * stable;
            cf_msm_place_top(&lat, s.load);
            cf_error e2 = {0};
            int ok2 = cf_msm_static_to(&s, dir * mid, &e2) == CF_OK && inertia_here(&s, &oom) == 0;
            if (oom || e2.status == CF_E_INTERNAL) {
                rc = cf_error_set(err, CF_E_INTERNAL, "out of memory in the stability scan");
                goto done;
            }
            if (ok2) {
                stable = mid;
                cf_msm_positions_get(&lat, keep);
            } else {
                hi = mid;
            }
        }
        *limit = -dir * 0.5 * (stable + hi);
        break;
    }
done:
    free(keep);
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
    return rc;
}

/* ---- stability of a homogeneous state -------------------------------------------------------- */

cf_status cf_msm_homogeneous_inertia(const cf_law *law, cf_law_method m, const cf_msm_config *cfgin,
                                     double strain, double lateral, long *neg, cf_error *err)
{
    return cf_msm_homogeneous_inertias(law, m, cfgin, &strain, &lateral, 1, neg, err);
}

cf_status cf_msm_homogeneous_inertias(const cf_law *law, cf_law_method m,
                                      const cf_msm_config *cfgin, const double *strains,
                                      const double *laterals, size_t count, long *neg,
                                      cf_error *err)
{
    CF_GSL_GUARD;
    cf_msm_config cfg = cfgin ? *cfgin : cf_msm_default();
    /* the banded LDL^T (GSL): its D gives the inertia, and unlike the sparse factorisations it
    ** runs on any thread without waiting (every CHOLMOD and MUMPS call holds one process-wide
    ** lock, sparse_chol.c) */
    cfg.banded_only = 1;
    *neg = -1;
    for (size_t q = 0; q < count; q++)
        if (!isfinite(strains[q]) || !isfinite(laterals[q]) || !(laterals[q] > 0))
            return cf_error_set(err, CF_E_DATA, "strain %g, lateral stretch %g: not a "
                                "deformation", strains[q], laterals[q]);
    if (cfg.lattice.bottom != CF_BOTTOM_AXIAL)
        return cf_error_set(err, CF_E_DATA, "a clamped bottom holds the lattice's base: its "
                            "uniaxial state is never homogeneous");
    cf_lattice lat;
    cf_msm_stats st = {0};
    solver s;
    cf_status rc = static_open(law, m, &cfg, &lat, &s, &st, err);
    if (rc != CF_OK)
        return rc;
    s.homogeneous = 1;
    for (size_t q = 0; q < count && rc == CF_OK; q++) {
        const double strain = strains[q], lateral = laterals[q];
        /* F = diag(a, a, 1 + strain) about the pinned corner (the origin) */
        for (size_t p = 0; p < lat.nn; p++) {
            lat.x[p] = lateral * lat.X[p];
            lat.y[p] = lateral * lat.Y[p];
            lat.z[p] = (1 + strain) * lat.Z[p];
        }
        s.load = -strain;
        double rn, fs;
        double um = cf_msm_residual(&s, &rn, &fs);
        if (!(um < 1))
            rc = cf_error_set(err, CF_E_DATA, "strain %g: a spring of the lattice passes solid",
                              strain);
        else if (!(rn <= 1e-7 * fs))
            rc = cf_error_set(err, CF_E_DATA,
                              "strain %g, lateral stretch %.17g: not an equilibrium of this lattice "
                              "(residual %.3g of the largest tension; a clamped bottom is never "
                              "homogeneous)",
                              strain, lateral, rn / fs);
        else {
            /* a right-hand side of ones, whose solution is discarded, so that the factorisation's
            ** residual check means something at an equilibrium (R = 0) */
            for (size_t k = 0; k < s.ndof; k++)
                s.R[k] = 1.0;
            cf_error e = {0};
            (void)cf_msm_direction(&s, &e);
            *neg = s.neg_pivots;
            if (*neg < 0)
                rc = cf_error_set(err, CF_E_NOCONV, "strain %g: no factorisation of the tangent "
                                  "reported its inertia", strain);
        }
        if (rc == CF_OK && *neg != 0)
            break; /* the first state with a negative pivot */
    }
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
    return rc;
}
