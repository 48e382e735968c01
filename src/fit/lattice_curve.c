/*
** One spring's lattice curve at a table's strains (see lattice_curve.h).
*/
#include "fit/lattice_curve.h"
#include "model/mode.h"

#include <math.h>
#include <string.h>

#include "model/cell.h"
#include "fit/lsq.h"

cf_status cf_lattice_curve(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                           int full, double *out, double *law_out, cf_msm_stats *stats,
                           int *by_cell, cf_error *err)
{
    cf_law law;
    cf_status st = cf_law_init(&law, p, err);
    if (st != CF_OK)
        return st;
    if (s->method == CF_LAW_TABLE && (st = cf_law_table_build(&law, s->table_intervals, err)))
        return st;
    int cell = !full || !cf_mode_row_of(d->mode)->spring_curve; /* the full lattice runs the
                                                                  spring's own (uniaxial) test */
    if (by_cell)
        *by_cell = cell;
    if (!cell) {
        st = cf_msm_uniaxial(&law, s->method, &s->cfg, d->x, d->count, out, stats, err);
    } else {
        cf_cell c;
        if (stats)
            memset(stats, 0, sizeof *stats);
        st = cf_cell_init(&c, &law, s->method, s->cfg.lattice.weight, err);
        if (st == CF_OK)
            st = cf_table_cell_curve(&c, d, out, err);
    }
    for (size_t i = 0; st == CF_OK && law_out && i < d->count; i++)
        law_out[i] = cf_fit_model(&law, 0, d->x[i]);
    cf_law_free(&law);
    return st;
}

cf_table cf_lattice_reach(const cf_table *d, double *spring_x)
{
    cf_table reach = *d;
    reach.x = spring_x;
    for (size_t i = 0; i < d->count; i++)
        spring_x[i] = copysign(cf_cell_spring_strain(d->mode, d->x[i]), d->x[i]);
    return reach;
}

void cf_lattice_take_quality(const cf_table *d, const double *g, const double *sw, double ynorm,
                             cf_fit_result *res, double law[3])
{
    const int uniaxial = cf_mode_row_of(d->mode)->spring_curve;
    law[0] = uniaxial ? res->rmse : NAN;
    law[1] = uniaxial ? res->max_abs_error : NAN;
    law[2] = uniaxial ? res->r2 : NAN;
    cf_lsq_quality q = cf_lsq_quality_of(d, g);
    double wrss = 0;
    for (size_t i = 0; i < d->count; i++) {
        double r = sw[i] * (g[i] - d->y[i]);
        wrss += r * r;
    }
    res->rss = q.rss;
    res->rmse = q.rmse;
    res->max_abs_error = q.max_abs_error;
    res->r2 = q.r2;
    res->objective = wrss;
    res->objective_zero = ynorm;
}
