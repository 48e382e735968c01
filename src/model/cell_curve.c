/*
** The homogenised cell's curves and reach (cell.h): the springs' strain at a table strain, a mode's
** stress at many strains, and the strain at which a mode brings the first spring to solid. On
** cf_cell_mode alone; apart from cell.c so that it stays within its size.
*/
#include "model/cell.h"

#include <math.h>

double cf_cell_spring_strain(cf_mode m, double e)
{
    double F[9], r = 0;
    cf_mode_place(m, e, 1, F);
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], fam;
        cf_cell_direction(d, N, &fam);
        double X[3] = {N[0], N[1], N[2]}, L2 = 0, L02 = 0;
        for (int i = 0; i < 3; i++) {
            double xi = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
            L2 += xi * xi;
            L02 += X[i] * X[i];
        }
        r = fmax(r, fabs(sqrt(L2 / L02) - 1));
    }
    return r;
}

cf_status cf_cell_curve(const cf_cell *c, cf_mode m, const double *strain, size_t count,
                        double *stress_MPa, cf_error *err)
{
    cf_cell_state s;
    for (size_t i = 0; i < count; i++) {
        cf_status st = cf_cell_mode(c, m, strain[i], NULL, &s, err);
        if (st != CF_OK)
            return st;
        stress_MPa[i] = s.stress_MPa;
    }
    return CF_OK;
}

/* 1 when mode m reaches table strain e (no spring at solid, the free stretch found). */
static int reaches(const cf_cell *c, cf_mode m, double e)
{
    cf_cell_state s;
    return cf_cell_mode(c, m, e, NULL, &s, NULL) == CF_OK;
}

cf_status cf_cell_solid_strain(const cf_cell *c, cf_mode m, int side, double *e_solid,
                               cf_error *err)
{
    const double sg = side < 0 ? -1.0 : 1.0;
    /* a bracket [good, bad] in |e|: the far end doubles until the mode cannot reach it (a
    ** compression cannot pass -1 in a mode that stretches the loaded edge) */
    double good = 0, bad = 0.1;
    const int stretch = cf_mode_row_of(m) && !cf_mode_row_of(m)->any_sign;
    while (reaches(c, m, sg * bad)) {
        good = bad;
        bad *= 2;
        if (bad > 1e3 || (sg < 0 && stretch && bad >= 1))
            break;
    }
    if (sg < 0 && stretch)
        bad = fmin(bad, 1);
    if (reaches(c, m, sg * bad))
        return cf_error_set(err, CF_E_DATA, "%s strain %g: no spring of the cell reaches solid",
                            cf_mode_name(m), sg * bad);
    for (int k = 0; k < 200 && bad - good > 1e-12 * bad; k++) {
        const double mid = 0.5 * (good + bad);
        if (reaches(c, m, sg * mid))
            good = mid;
        else
            bad = mid;
    }
    *e_solid = sg * good;
    return CF_OK;
}
