/*
** The design constraints of the fit (see fit.h), shared by the placement, the polish and the
** check of every reported spring: their values in log (relative) units and the check itself.
*/


#include <math.h>

#include "fit/fit_ctx.h"
#include "fit/lsq.h"

static const unsigned con_bit[NCON] = {CF_C_INDEX_MIN, CF_C_INDEX_MAX, CF_C_COILS, CF_C_DIAMETERS,
                                       CF_C_TRAVEL,    CF_C_TYPE,      CF_C_RHO_MIN, CF_C_D2_H};

/* Constraint values g_k <= 0 when satisfied, in log (relative) units, in the order of con_bit. */
void cf_fit_constraint_values(const double *p, cf_spring_type type, double xmax, int fd,
                              const cf_fit_options *opt, double g[NCON])
{
    double c = p[CF_P_D1] / p[CF_P_D];
    g[0] = log(3.0) - log(c);
    g[1] = log(c) - log(opt->index_max);
    g[2] = log(2.0) - log(p[CF_P_N]);
    g[3] = log(p[CF_P_D1]) - log(p[CF_P_D2]);
    double s = p[CF_P_H] - lmin_of(p, type);
    double umax = (fd ? xmax : xmax * p[CF_P_H]) * (1 + CF_FIT_TRAVEL_MARGIN);
    g[4] = s > 0 ? log(umax) - log(s) : 50.0;
    double step = (p[CF_P_D2] - p[CF_P_D1]) / 2, nd = p[CF_P_N] * p[CF_P_D];
    g[5] = type == CF_TELESCOPING ? (nd - step) / p[CF_P_D2] : (step - nd) / p[CF_P_D2] + 1e-12;
    g[6] = log(opt->rho_min * (1 - CF_IDENT_RHO_MIN_TOL)) - log(p[CF_P_D1] / p[CF_P_D2]);
    g[7] = log(p[CF_P_D2]) - log(opt->D2_over_H_max * p[CF_P_H]);
    for (int k = 0; k < NCON; k++)
        if (!isfinite(g[k]))
            g[k] = 50.0;
}

/* cf_fit_check for a table whose largest |x| is xmax (fd: force-displacement). */
static int check_spring(const cf_spring *sp, cf_spring_type type, double xmax, int fd,
                        const cf_fit_options *opt, unsigned *active, unsigned *violated)
{
    double p[CF_P_COUNT], g[NCON];
    to_array(sp, p);
    unsigned act = 0, vio = 0;
    cf_fit_constraint_values(p, type, xmax, fd, opt, g);
    for (int k = 0; k < NCON; k++) {
        if (g[k] > FEAS_TOL)
            vio |= con_bit[k];
        if (g[k] > -ACTIVE_TOL)
            act |= con_bit[k];
    }
    /* the geometry must be of the type fitted, judged by the law itself */
    cf_law law;
    if (cf_law_init(&law, sp, NULL) != CF_OK || law.type != type)
        vio |= CF_C_TYPE;
    for (int k = 0; k < CF_P_COUNT; k++) {
        if (opt->fixed[k]) {
            if (fabs(p[k] - opt->fixed_value[k]) > 1e-12 * fabs(opt->fixed_value[k]))
                vio |= CF_C_BOUNDS;
            continue;
        }
        /* the upper bounds of n and G are named; the other bounds are the wide defaults */
        unsigned ub = k == CF_P_N ? CF_C_COILS_MAX : k == CF_P_G ? CF_C_G_MAX : CF_C_BOUNDS;
        if (p[k] < opt->lower[k] * (1 - 1e-12))
            vio |= CF_C_BOUNDS;
        if (p[k] > opt->upper[k] * (1 + 1e-12))
            vio |= ub;
        if (p[k] <= opt->lower[k] * (1 + ACTIVE_TOL))
            act |= k == CF_P_N ? CF_C_COILS : CF_C_BOUNDS;
        if (p[k] >= opt->upper[k] * (1 - ACTIVE_TOL))
            act |= ub;
    }
    if (active)
        *active = act;
    if (violated)
        *violated = vio;
    return vio == 0;
}

int cf_fit_check(const cf_spring *sp, cf_spring_type type, const cf_table *data,
                 const cf_fit_options *opt, unsigned *active, unsigned *violated)
{
    return check_spring(sp, type, cf_lsq_xmax(data), cf_table_is_force(data), opt, active,
                        violated);
}

/* The check at the fit's own table, without a pass over it. */
int cf_fit_check_at(const fit_ctx *c, const cf_spring *sp, unsigned *active, unsigned *violated)
{
    return check_spring(sp, c->type, c->xmax, c->fd, c->opt, active, violated);
}
