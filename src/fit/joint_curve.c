/*
** What every joint search evaluates (joint_ctx.h): the tables' cell curves for a point of the
** search, the cell's volume modulus for a law, the family weights of a ratio, and each table's
** weights in the objective (joint.h). Below the
** searches (joint.c, joint_pair.c) and the stability checks (joint_stable.c), which all call it.
*/
#include "fit/joint_ctx.h"

#include <math.h>

#include "model/cell.h"
#include "model/family.h"

/* The cell's volume modulus for a curve whose compression law (at stress scale 1) is law. */
double cf_joint_curve_kappa(const jctx *c, const cf_law *law)
{
    const double k0H = law->k0_N_per_mm / law->p.H_mm; /* H = 1 mm: MPa */
    switch (c->kappa_mode) {
    case KAPPA_REL: return c->kappa * k0H;
    case KAPPA_UNIT: return c->kappa;
    case KAPPA_NU: return fmax(0.0, cf_cubic_kappa_of_nu(c->weight, k0H, c->kappa));
    default: return 0.0;
    }
}

/* Family weights of ratio q (face = body = q edge), scaled to the law's small-strain modulus. */
void cf_joint_weights_of(double q, double w[CF_FAMILY_COUNT])
{
    double u[CF_FAMILY_COUNT] = {1, q, q};
    double E = cf_cubic_moduli_of(u).E;
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        w[f] = u[f] / E;
}

/* Every table's cell curve at stress scale 1 for (rho, B), the tables one after another. */
int cf_joint_curve(void *ctx, double rho, double B, double *out)
{
    const jctx *c = ctx;
    const cf_ident q = {.rho = rho, .solid = B, .scale = 1.0};
    cf_spring p = c->tail ? cf_ident_member_tail(&q, c->tau) : cf_ident_member(&q);
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 1;
    cf_law ext;
    if (c->pair) {
        const cf_ident qe = {.rho = c->ext[0], .solid = c->ext[1], .scale = c->ext[2]};
        const cf_spring pe = cf_ident_member(&qe);
        if (cf_law_init(&ext, &pe, NULL) != CF_OK || cf_law_pair(&law, &ext, NULL) != CF_OK)
            return 1;
    }
    cf_cell cell;
    if (cf_cell_init(&cell, &law, c->lat->method == CF_LAW_TABLE ? CF_LAW_CLOSED : c->lat->method,
                     c->weight, NULL) != CF_OK)
        return 1;
    if (c->kappa_mode != KAPPA_NONE)
        cell.volume_modulus_MPa = cf_joint_curve_kappa(c, &law);
    for (size_t k = 0, m = 0; k < c->n; m += c->t[k++]->count)
        if (cf_table_cell_curve(&cell, c->t[k], out + m, NULL) != CF_OK)
            return 1;
    return 0;
}

int cf_joint_table_weights(const cf_table *t, double *scale, double *sw)
{
    double ss = 0;
    for (size_t i = 0; i < t->count; i++)
        ss += t->y[i] * t->y[i];
    const double s = sqrt(ss / (double)t->count);
    *scale = s > 0 ? s : 0;
    if (!(s > 0))
        return -1;
    for (size_t i = 0; sw && i < t->count; i++)
        sw[i] = sqrt((t->w ? t->w[i] : 1.0) / (double)t->count) / s;
    return 0;
}

void cf_joint_q_box(const cf_fit_options *opt, double *lb, double *ub)
{
    double lo = Q_LO, hi = Q_HI;
    if (opt->anisotropy_max > 0) {
        const double a = cf_cubic_q_of_zener(1 - opt->anisotropy_max),
                     b = cf_cubic_q_of_zener(1 + opt->anisotropy_max);
        if (a > lo)
            lo = a;
        if (b < hi) /* NAN (beyond the ratio's limit): the box's end */
            hi = b;
    }
    *lb = log(lo), *ub = log(hi);
}

double cf_joint_q_step(double lb, double ub, int fine)
{
    return fmin(fine ? 0.05 : 0.2, 0.4 * (ub - lb));
}
