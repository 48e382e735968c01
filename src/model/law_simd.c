/*
** Batches of the law through the branch-free lanes of law_simd.h, compiled for several
** instruction sets and dispatched at run time.
*/
#include "model/law_simd.h"

CF_DISPATCH
void cf_law_force_lanes(const cf_law_lanes *lanes, int form, size_t count, const double *u,
                        double *F)
{
    const cf_law_lanes c = *lanes; /* by value: its loads leave the loop */
    if (form == CF_LANE_TABLE && c.coef) {
#pragma omp simd
        for (size_t i = 0; i < count; i++)
            F[i] = cf_lane_table(&c, u[i]);
    } else {
#pragma omp simd
        for (size_t i = 0; i < count; i++)
            F[i] = cf_lane_closed(&c, u[i]);
    }
}
