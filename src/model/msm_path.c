/*
** A loading path's value at a time (linear between its points, held outside them): shared by the
** quasi-static runner (msm.c), the viscous and the explicit steps (msm_visco.c, msm_dynamic.c) and
** the viscoelastic model, none of which need each other for it.
*/
#include "model/msm.h"

double cf_msm_path_value(const cf_msm_path *p, double t)
{
    if (t <= p->t_s[0])
        return p->value[0];
    for (size_t i = 1; i < p->count; i++)
        if (t <= p->t_s[i]) {
            double h = p->t_s[i] - p->t_s[i - 1];
            double f = h > 0 ? (t - p->t_s[i - 1]) / h : 1.0;
            return p->value[i - 1] + f * (p->value[i] - p->value[i - 1]);
        }
    return p->value[p->count - 1];
}
