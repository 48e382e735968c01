/*
** Batches of the law through the branch-free lanes of law_simd.h, compiled for several
** instruction sets and dispatched at run time.
*/
#include "model/law_simd.h"

#include <stdatomic.h>
#include <stdlib.h>

static const char *const simd_names[] = {"sse2", "avx2", "avx512"};

int cf_simd_parse(const char *name)
{
    for (int i = 0; name && i < (int)(sizeof simd_names / sizeof simd_names[0]); i++)
        if (strcmp(name, simd_names[i]) == 0)
            return i;
    return -1;
}

const char *cf_simd_name(cf_simd level)
{
    return level >= CF_SIMD_SSE2 && level <= CF_SIMD_AVX512 ? simd_names[level] : "unknown";
}

cf_simd cf_simd_level_supported(void)
{
#if CF_SIMD_MULTI
    __builtin_cpu_init();
    if (__builtin_cpu_supports("x86-64-v4"))
        return CF_SIMD_AVX512;
    if (__builtin_cpu_supports("x86-64-v3"))
        return CF_SIMD_AVX2;
#endif
    return CF_SIMD_SSE2;
}

cf_simd cf_simd_level(void)
{
    static atomic_int cached = -1; /* each thread that finds it unset computes the same value */
    int level = atomic_load_explicit(&cached, memory_order_relaxed);
    if (level < 0) {
        level = (int)cf_simd_level_supported();
        const int limit = cf_simd_parse(getenv("CONIFIT_SIMD"));
        if (limit >= 0 && limit < level)
            level = limit;
        atomic_store_explicit(&cached, level, memory_order_relaxed);
    }
    return (cf_simd)level;
}

#define LAW_FORCE_LANES(attr, sfx, unused)                                                         \
    attr static void force_lanes##sfx(const cf_law_lanes *lanes, int form, size_t count,            \
                                      const double *u, double *F)                                  \
    {                                                                                              \
        const cf_law_lanes c = *lanes; /* by value: its loads leave the loop */                    \
        if (c.tail && !(form == CF_LANE_POLY && c.poly_fit))                                       \
            cf_law_force_scalar_many(c.law, CF_LAW_CLOSED, count, u, F, NULL); /* scalar law */ \
        else if (form == CF_LANE_TABLE && c.coef)                                                  \
            cf_lanes_table(&c, count, u, F);                                                       \
        else if (form == CF_LANE_POLY && c.poly_fit)                                               \
            cf_lanes_poly(&c, count, u, F);                                                        \
        else                                                                                       \
            cf_lanes_closed(&c, count, u, F);                                                      \
    }
CF_SIMD_COPIES(LAW_FORCE_LANES, 0)

void cf_law_force_lanes(const cf_law_lanes *lanes, int form, size_t count, const double *u,
                        double *F)
{
    CF_SIMD_CALL(force_lanes, (lanes, form, count, u, F));
}

/* The lanes of a law (law_simd.h): its fields, and its table's coefficients (law_internal.h). */
void cf_law_lanes_init(const cf_law *law, cf_law_lanes *lanes)
{
    memset(lanes, 0, sizeof *lanes);
    lanes->u_T = law->u_T_mm;
    lanes->s = law->travel_mm;
    lanes->inv_s = law->inv_travel;
    lanes->k0 = law->k0_N_per_mm;
    lanes->F_C = law->F_C_N;
    lanes->rim1 = law->rho_inv_m1;
    lanes->coef = law->table ? law->table->coef : NULL;
    lanes->inv_h = law->table ? law->table->inv_h : 0.0;
    lanes->xmax = law->table ? (double)(law->table->intervals - 1) : 0.0;
    lanes->law = law;
    if (law->tail) { /* the polynomial only (law_simd.h); kappa2 and z0 come with its fit */
        lanes->tail = 1;
        lanes->u_C = law->u_C_mm;
        lanes->k_t = law->k_tail_N_per_mm;
        lanes->F_sol = law->F_solid_N;
        lanes->b4 = 4.0 * law->beta;
    }
}

/* The law over many points (conifit/law.h): forces alone of a law the lanes carry go through
** them, everything else through the scalar law (law.c). */
void cf_law_force_many(const cf_law *law, cf_law_method method, size_t count, const double *u_mm,
                       double *F_N, double *k_N_per_mm)
{
    if (!k_N_per_mm && !law->tail && !law->extension && !law->mech &&
        (method == CF_LAW_CLOSED || (method == CF_LAW_TABLE && law->table))) {
        cf_law_lanes lanes;
        cf_law_lanes_init(law, &lanes);
        cf_law_force_lanes(&lanes, method == CF_LAW_TABLE ? CF_LANE_TABLE : CF_LANE_CLOSED,
                           count, u_mm, F_N);
        return;
    }
    cf_law_force_scalar_many(law, method, count, u_mm, F_N, k_N_per_mm);
}
