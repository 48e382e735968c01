/*
** The law's curve over a table's abscissae, in the table's units (stress over strain or force over
** displacement): what every spring fit compares with its data. Kept apart from the fit's driver
** (fit.c), which the stages it calls (fit_placement.c, tail.c) must not call back.
*/
#include "fit/fit.h"

void cf_fit_model_many(const cf_law *law, int force_displacement, size_t count, const double *x,
                       double *out)
{
    const double H = force_displacement ? 1.0 : law->p.H_mm;
    for (size_t i = 0; i < count; i++)
        out[i] = x[i] * H;
    cf_law_force_many(law, CF_LAW_CLOSED, count, out, out, NULL);
    if (!force_displacement)
        for (size_t i = 0; i < count; i++)
            out[i] /= H * H;
}
