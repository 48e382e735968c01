/*
** Deterministic subsample of a long table (see subsample.h).
*/
#include "fit/subsample.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { NSPECIAL = 3 };

cf_status cf_subsample(const cf_table *t, size_t rows, cf_table *out, cf_error *err)
{
    memset(out, 0, sizeof *out);
    if (rows < 8)
        rows = 8;
    /* the rows that are always kept: smallest x, largest x, largest |y| */
    size_t sp[NSPECIAL] = {0, 0, 0};
    for (size_t i = 1; i < t->count; i++) {
        if (t->x[i] < t->x[sp[0]])
            sp[0] = i;
        if (t->x[i] > t->x[sp[1]])
            sp[1] = i;
        if (fabs(t->y[i]) > fabs(t->y[sp[2]]))
            sp[2] = i;
    }
    const size_t nbin = rows - NSPECIAL;
    const double x0 = t->count ? t->x[sp[0]] : 0, width = t->count ? (t->x[sp[1]] - x0) / (double)nbin : 0;
    size_t *pick = malloc(sizeof(size_t) * nbin);
    double *wsum = calloc(nbin, sizeof(double));
    double *xs = malloc(sizeof(double) * rows), *ys = malloc(sizeof(double) * rows),
           *ws = malloc(sizeof(double) * rows);
    cf_status st = CF_OK;
    if (!pick || !wsum || !xs || !ys || !ws) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for a subsample of %zu rows", rows);
        goto done;
    }
    for (size_t b = 0; b < nbin; b++)
        pick[b] = (size_t)-1;
    for (size_t i = 0; i < t->count; i++) {
        if (i == sp[0] || i == sp[1] || i == sp[2])
            continue;
        double u = width > 0 ? (t->x[i] - x0) / width : 0;
        size_t b = u > 0 && u < (double)nbin ? (size_t)u : u >= (double)nbin ? nbin - 1 : 0;
        wsum[b] += t->w ? t->w[i] : 1.0;
        double centre = x0 + ((double)b + 0.5) * width;
        if (pick[b] == (size_t)-1 || fabs(t->x[i] - centre) < fabs(t->x[pick[b]] - centre))
            pick[b] = i;
    }
    size_t k = 0;
    for (size_t s = 0; s < NSPECIAL && s < t->count; s++) {
        int dup = 0;
        for (size_t r = 0; r < s; r++)
            dup |= sp[r] == sp[s];
        if (dup)
            continue;
        xs[k] = t->x[sp[s]];
        ys[k] = t->y[sp[s]];
        ws[k++] = t->w ? t->w[sp[s]] : 1.0;
    }
    for (size_t b = 0; b < nbin; b++) {
        if (pick[b] == (size_t)-1)
            continue;
        xs[k] = t->x[pick[b]];
        ys[k] = t->y[pick[b]];
        ws[k++] = wsum[b];
    }
    st = cf_table_from_arrays(t->kind, k, xs, ys, ws, out, err);
done:
    free(pick);
    free(wsum);
    free(xs);
    free(ys);
    free(ws);
    return st;
}
