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
    if (form == CF_LANE_TABLE && c.coef)
        cf_lanes_table(&c, count, u, F);
    else if (form == CF_LANE_POLY && c.poly_fit)
        cf_lanes_poly(&c, count, u, F);
    else
        cf_lanes_closed(&c, count, u, F);
}
