/*
** The measured table (table.h): building one from arrays, what it is, its name, releasing it.
** Reading one from a file is the reader's job (io/measure.c).
*/
#include "model/table.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cf_table_free(cf_table *m)
{
    if (!m)
        return;
    free(m->x);
    free(m->y);
    free(m->w);
    free(m->t);
    m->x = m->y = m->w = m->t = NULL;
    m->count = 0;
}

double cf_table_biaxial_k(const cf_table *m, size_t i)
{
    if (m->mode != CF_MODE_BIAXIAL || !(m->ratio[0] > 0) || !(m->ratio[1] > 0))
        return 1.0;
    return i < m->second ? m->ratio[1] / m->ratio[0] : m->ratio[0] / m->ratio[1];
}

cf_status cf_table_cell_curve(const cf_cell *c, const cf_table *m, double *out, cf_error *err)
{
    if (m->mode != CF_MODE_BIAXIAL)
        return cf_cell_curve(c, m->mode, m->x, m->count, out, err);
    cf_cell k = *c;
    cf_cell_state s;
    for (size_t i = 0; i < m->count; i++) {
        k.biaxial_k = cf_table_biaxial_k(m, i);
        cf_status st = cf_cell_mode(&k, m->mode, m->x[i], NULL, &s, err);
        if (st != CF_OK)
            return st;
        out[i] = s.stress_MPa;
    }
    return CF_OK;
}

int cf_table_is_force(const cf_table *m)
{
    return m->kind == CF_TABLE_FORCE_DISPLACEMENT;
}

void cf_table_name(const cf_table *m, char *out, size_t cap)
{
    const char *base = strrchr(m->path, '/');
    base = base ? base + 1 : m->path;
    const char *dot = strrchr(base, '.');
    int n = (dot && dot != base) ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, cap, "%.*s", n, base);
}

cf_status cf_table_from_arrays(cf_table_kind kind, size_t count, const double *x, const double *y,
                               const double *w, cf_table *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    m->kind = kind;
    size_t bytes = sizeof(double) * (count ? count : 1);
    m->x = malloc(bytes);
    m->y = malloc(bytes);
    m->w = malloc(bytes);
    if (!m->x || !m->y || !m->w) {
        cf_table_free(m);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a table of %zu points", count);
    }
    for (size_t i = 0; i < count; i++) {
        m->x[i] = x[i];
        m->y[i] = y[i];
        m->w[i] = w ? w[i] : 1.0;
    }
    m->count = count;
    m->y_to_file = 1.0;
    snprintf(m->path, sizeof m->path, "(table in memory)");
    snprintf(m->x_column, sizeof m->x_column, "x");
    snprintf(m->y_column, sizeof m->y_column, "y");
    snprintf(m->x_unit, sizeof m->x_unit, "%s", kind == CF_TABLE_FORCE_DISPLACEMENT ? "mm" : "-");
    snprintf(m->y_unit, sizeof m->y_unit, "%s", kind == CF_TABLE_FORCE_DISPLACEMENT ? "N" : "MPa");
    for (size_t i = 0; i < count; i++)
        if (x[i] > 0)
            return CF_OK;
    m->compression = count > 0;
    for (size_t i = 0; i < count; i++)
        if (x[i] < 0)
            return CF_OK;
    m->compression = 0;
    return CF_OK;
}
