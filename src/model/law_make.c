/*
** Making laws: a law kind's law from its mechanics row and quantities (cf_law_init_kind), the
** registry of kinds by name (lawmech.h), and the public constructor of the opaque cf_law.
*/
#include "model/law_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the registry ---------------------------------------------------------------------------- */

static const cf_law_mech *registry[CF_LAW_MECH_MAX];
static int registered;

static cf_status mech_check(const cf_law_mech *m, cf_error *err)
{
    if (!m || !m->name || !m->name[0])
        return cf_error_set(err, CF_E_DATA, "a law kind's mechanics row needs a name");
    if (!m->force || !m->travel || !m->spring)
        return cf_error_set(err, CF_E_DATA,
                            "law kind '%s': its mechanics row needs force, travel and spring",
                            m->name);
    if (m->nq < 1 || m->nq > CF_LAW_Q_MAX)
        return cf_error_set(err, CF_E_DATA, "law kind '%s': %d quantities (1 to %d)", m->name,
                            m->nq, CF_LAW_Q_MAX);
    for (int k = 0; k < m->nq; k++)
        if (!m->key[k] || !m->key[k][0])
            return cf_error_set(err, CF_E_DATA, "law kind '%s': quantity %d has no key", m->name,
                                k);
    return CF_OK;
}

cf_status cf_law_mech_register(const cf_law_mech *mech, cf_error *err)
{
    cf_status st = mech_check(mech, err);
    if (st != CF_OK)
        return st;
    static const char *const own[] = {"conical", "conical-tail", "double-acting", "auto"};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++)
        if (strcmp(mech->name, own[i]) == 0)
            return cf_error_set(err, CF_E_DATA, "law kind '%s' is one of the library's own",
                                mech->name);
    const cf_law_mech *known = cf_law_mech_find(mech->name);
    if (known == mech)
        return CF_OK;
    if (known)
        return cf_error_set(err, CF_E_DATA, "another law kind named '%s' is registered already",
                            mech->name);
    if (registered >= CF_LAW_MECH_MAX)
        return cf_error_set(err, CF_E_INTERNAL, "the law-kind registry is full (%d kinds)",
                            CF_LAW_MECH_MAX);
    registry[registered++] = mech;
    return CF_OK;
}

const cf_law_mech *cf_law_mech_find(const char *name)
{
    for (int i = 0; name && i < registered; i++)
        if (strcmp(registry[i]->name, name) == 0)
            return registry[i];
    return NULL;
}

/* ---- a kind's law ----------------------------------------------------------------------------- */

cf_status cf_law_init_kind(cf_law *law, const cf_law_mech *mech, const double *q, double H_mm,
                           cf_error *err)
{
    cf_status st = mech_check(mech, err);
    if (st != CF_OK)
        return st;
    if (!(isfinite(H_mm) && H_mm > 0))
        return cf_error_set(err, CF_E_DATA, "law kind '%s': free length H = %g mm must be > 0",
                            mech->name, H_mm);
    for (int k = 0; k < mech->nq; k++)
        if (!(isfinite(q[k]) && q[k] > 0))
            return cf_error_set(err, CF_E_DATA, "law kind '%s': quantity %s = %.17g must be a "
                                "finite number > 0", mech->name, mech->key[k], q[k]);
    const cf_spring p = mech->spring(q, H_mm);
    if ((st = cf_law_init(law, &p, err)) != CF_OK)
        return st;
    law->mech = mech;
    memcpy(law->q, q, (size_t)mech->nq * sizeof *q);
    const double sc = mech->travel(q, H_mm, +1), ss = mech->travel(q, H_mm, -1);
    if (!(sc > 0 && sc <= H_mm) || !(ss > 0 && ss <= H_mm))
        return cf_error_set(err, CF_E_DATA,
                            "law kind '%s': travels %.17g mm (compression) and %.17g mm "
                            "(stretch) must be in (0, H = %g mm]",
                            mech->name, sc, ss, H_mm);
    law->travel_mm = law->u_C_mm = law->cone_travel_mm = sc;
    law->inv_travel = 1.0 / sc;
    law->travel_stretch_mm = ss;
    law->u_T_mm = 0.0;
    law->tail = 0;
    double k0;
    mech->force(q, H_mm, 0.0, &k0);
    law->k0_N_per_mm = k0;
    law->F_C_N = law->F_solid_N = law->F_T_N = fabs(mech->force(q, H_mm, sc, NULL));
    if (!(isfinite(k0) && k0 > 0) || !(isfinite(law->F_C_N) && law->F_C_N > 0))
        return cf_error_set(err, CF_E_DATA,
                            "law kind '%s': its tangent at rest %.17g N/mm and force at solid "
                            "%.17g N must be finite and > 0",
                            mech->name, k0, law->F_C_N);
    return CF_OK;
}

/* ---- the public constructor (law.h) ---------------------------------------------------------- */

cf_law *cf_law_create(const cf_spring *p, cf_error *err)
{
    cf_law *law = malloc(sizeof *law);
    if (!law) {
        cf_error_set(err, CF_E_INTERNAL, "out of memory for a law");
        return NULL;
    }
    if (cf_law_init(law, p, err) != CF_OK) {
        free(law);
        return NULL;
    }
    return law;
}

void cf_law_destroy(cf_law *law)
{
    if (!law)
        return;
    cf_law_free(law);
    free(law);
}
