/*
** A saved fit's prediction of tables (see predict.h): the model of the fit file, each table's rows
** evaluated in its mode, the figures over the rows the model follows.
*/
#include "pipeline/predict.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic.h"
#include "fit/fit.h"
#include "fit/joint.h"
#include "fit/lsq.h"
#include "io/measure.h"
#include "io/columns.h"
#include "model/cell.h"
#include "model/cell_stability.h"
#include "model/mode.h"

/* The fit's model, built once: the law (with the extension spring ext joined for a double-acting
** element) and, through the lattice, its homogenised cell. */
typedef struct pmodel {
    cf_predict_model kind;
    int force;     /* fitted to a force-displacement table */
    cf_law law, ext;
    cf_cell cell;
} pmodel;

/* The model of fit m into *pm (which must not move while in use: the law points at ext). */
static cf_status model_build(const cf_fitted_model *m, const char *path, pmodel *pm,
                             cf_error *err)
{
    memset(pm, 0, sizeof *pm);
    const cf_fitted_spring *s = &m->spring;
    pm->kind = s->target_lattice ? CF_PREDICT_CELL : CF_PREDICT_SPRING;
    pm->force = m->force_displacement;
    cf_error e = {0};
    cf_status st = cf_law_init(&pm->law, &s->params, &e);
    if (st == CF_OK && s->has_extension && (st = cf_law_init(&pm->ext, &s->extension, &e)) == CF_OK)
        st = cf_law_pair(&pm->law, &pm->ext, &e);
    if (st != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: %s", path, e.msg);
    if (pm->kind == CF_PREDICT_SPRING)
        return CF_OK;
    /* the fit's cell: a joint fit's closed (its verification's), a single fit's by the
    ** validation's law method (lattice_curve.c); the table's size is not recorded, the default
    ** is the validation's own */
    if (m->method == CF_LAW_TABLE &&
        (st = cf_law_table_build(&pm->law, CF_LAW_TABLE_DEFAULT, err)) != CF_OK)
        return st;
    if ((st = cf_cell_init(&pm->cell, &pm->law, m->method, m->weight, &e)) != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s: the lattice's weights: %s", path, e.msg);
    pm->cell.volume_modulus_MPa = s->volume_modulus_MPa;
    return CF_OK;
}

/* CF_OK when model pm can evaluate table t; CF_E_DATA saying why not. */
static cf_status check_table(const pmodel *pm, const cf_table *t, cf_error *err)
{
    const int force = cf_table_is_force(t);
    if (t->t)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a time series (it has a time column): its stress follows the "
                            "strain history, which a curve at its strains does not predict",
                            t->path);
    if (force != pm->force)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a %s table, and the fit was fitted to a %s table: a spring's "
                            "force at a displacement is not a stress at a strain",
                            t->path, force ? "force-displacement" : "stress-strain",
                            pm->force ? "force-displacement" : "stress-strain");
    /* a force-displacement table is one spring's curve whatever its '# mode:' (the fit does not
    ** honour one either) */
    if (pm->kind == CF_PREDICT_SPRING && !force && !cf_mode_row_of(t->mode)->spring_curve)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a table in %s, and the fit is of the single spring's law "
                            "(target 'spring'), which is a uniaxial curve only: only a fit "
                            "through the lattice (conifit fit --target lattice, or --joint) "
                            "predicts %s",
                            t->path, cf_mode_name(t->mode), cf_mode_name(t->mode));
    return CF_OK;
}

/* The model at row i of t into *y: 1 when it follows the row (the spring short of solid, the
** cell's mode reached), else 0. */
static int eval_row(const pmodel *pm, const cf_table *t, size_t i, double *y)
{
    if (pm->kind == CF_PREDICT_CELL && t->mode == CF_MODE_BIAXIAL) {
        /* the row along its own direction, the other at its ratio (cf_table_cell_curve) */
        cf_cell k = pm->cell;
        cf_cell_state s;
        k.biaxial_k = cf_table_biaxial_k(t, i);
        if (cf_cell_mode(&k, t->mode, t->x[i], NULL, &s, NULL) != CF_OK)
            return 0;
        *y = s.stress_MPa;
        return isfinite(*y);
    }
    if (pm->kind == CF_PREDICT_CELL)
        return cf_cell_curve(&pm->cell, t->mode, &t->x[i], 1, y, NULL) == CF_OK && isfinite(*y);
    /* cf_fit_model: the law at compression x H (x for a force-displacement table) */
    const double H = pm->force ? 1.0 : pm->law.p.H_mm;
    int flags = 0;
    const double F = cf_law_force(&pm->law, CF_LAW_CLOSED, t->x[i] * H, NULL, &flags);
    *y = pm->force ? F : F / (H * H);
    return !(flags & CF_LAW_SOLID) && isfinite(*y);
}

/* The strain (table sign, on the side of x) past which the model cannot go: the cell's first
** spring at solid, or the single spring's travel; 0 when it cannot be told. */
static double reach_limit(const pmodel *pm, const cf_table *t, double x)
{
    if (pm->kind == CF_PREDICT_SPRING) {
        const double H = pm->force ? 1.0 : pm->law.p.H_mm;
        return copysign(cf_law_travel_at(&pm->law, x * H) / H, x);
    }
    double e = 0;
    return cf_cell_solid_strain(&pm->cell, t->mode, x < 0 ? -1 : 1, &e, NULL) == CF_OK ? e : 0;
}

/* The farthest strain of t's rows on the side of sign sg that follows[] marks (0 when none). */
static double farthest(const cf_table *t, const unsigned char *follows, double sg)
{
    double m = 0;
    for (size_t i = 0; i < t->count; i++)
        if (follows[i] && sg * t->x[i] > sg * m)
            m = t->x[i];
    return m;
}

/* The cell's stability over the followed rows' range on each side: the first strain where its
** incremental stiffness stops being positive definite into pt. */
static void check_stability(const pmodel *pm, const cf_table *t, cf_predict_table *pt)
{
    if (pm->kind != CF_PREDICT_CELL)
        return;
    for (int side = -1; side <= 1; side += 2) {
        const double reach = farthest(t, pt->follows, side);
        double limit = reach;
        int lost = 0;
        if (reach == 0 || cf_cell_stable_to(&pm->cell, t->mode, reach, &limit, &lost, NULL) ||
            !lost)
            continue;
        if (!pt->stability_lost || fabs(limit) < fabs(pt->stable_to)) {
            pt->stability_lost = 1;
            pt->stable_to = limit;
        }
    }
}

/* The figures of pt over its followed rows (a copy of t's followed rows when some are not). */
static cf_status figures(const cf_table *t, cf_predict_table *pt, cf_error *err)
{
    const size_t n = pt->followed;
    cf_table sub = *t;
    double *buf = NULL;
    const double *g = pt->model;
    if (n < t->count) {
        buf = malloc(5 * n * sizeof(double) + 1);
        if (!buf)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu rows", n);
        sub.x = buf, sub.y = buf + n, sub.w = buf + 2 * n;
        double *gs = buf + 3 * n;
        for (size_t i = 0, k = 0; i < t->count; i++)
            if (pt->follows[i]) {
                sub.x[k] = t->x[i], sub.y[k] = t->y[i];
                sub.w[k] = t->w ? t->w[i] : 1.0;
                gs[k++] = pt->model[i];
            }
        sub.count = n;
        g = gs;
    }
    double *sw = n < t->count ? buf + 4 * n : malloc(n * sizeof(double) + 1);
    if (!sw) {
        free(buf);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu rows", n);
    }
    const cf_lsq_quality q = cf_lsq_quality_of(&sub, g);
    pt->rmse = q.rmse, pt->max_abs_error = q.max_abs_error, pt->r2 = q.r2;
    pt->term = 0;
    if (cf_joint_table_weights(&sub, &pt->rms, sw) == 0)
        for (size_t i = 0; i < n; i++) {
            const double r = sw[i] * (g[i] - sub.y[i]);
            pt->term += r * r;
        }
    if (sw != buf + 4 * n)
        free(sw);
    free(buf);
    return CF_OK;
}

/* The note of a table the model does not follow everywhere. */
static void reach_note(const pmodel *pm, const cf_table *t, cf_predict_table *pt, double xfirst)
{
    const char *what = pm->kind == CF_PREDICT_CELL
                           ? "a spring of the lattice's cell is at its solid length there"
                           : "the spring is solid there (its travel used up)";
    pt->reach_to = reach_limit(pm, t, xfirst);
    char limit[96] = "";
    if (pt->reach_to != 0)
        snprintf(limit, sizeof limit, " past %s %.4g %s", pm->force ? "displacement" : "strain",
                 pt->reach_to, pm->force ? "mm" : "(-)");
    if (!pt->ok)
        snprintf(pt->note, sizeof pt->note,
                 "the model follows none of the %zu rows%s: %s; no RMSE and no term", t->count,
                 limit, what);
    else
        snprintf(pt->note, sizeof pt->note,
                 "%zu of %zu rows are beyond the model's reach%s (%s); the RMSE, R^2, RMS "
                 "stress and term are over the other %zu rows",
                 t->count - pt->followed, t->count, limit, what, pt->followed);
}

/* The stability note (appended to any other). */
static void stability_note(const cf_table *t, cf_predict_table *pt)
{
    if (!pt->stability_lost)
        return;
    const size_t used = strlen(pt->note);
    snprintf(pt->note + used, sizeof pt->note - used,
             "%sthe lattice's cell loses stability at %s %.4g (-), inside the table's range: a "
             "lattice there would not stay homogeneous, the rows past it are the cell's "
             "homogeneous state",
             used ? "; " : "", cf_mode_row_of(t->mode)->x_short, pt->stable_to);
}

/* Whether t is the fit's table e: the same file, or the same name, rows and mode. */
static int same_table(const cf_table *t, const cf_fitfile_table *e)
{
    if (!e->file[0])
        return 0;
    if (strcmp(t->path, e->file) == 0 || cf_same_file(t->path, e->file))
        return 1;
    const char *a = strrchr(t->path, '/'), *b = strrchr(e->file, '/');
    a = a ? a + 1 : t->path;
    b = b ? b + 1 : e->file;
    return strcmp(a, b) == 0 && e->points == t->count && strcmp(e->mode, cf_mode_name(t->mode)) == 0;
}

/* The fit's own figures of t when the fit was fitted to it. */
static void match_fitted(const cf_fitted_model *m, const cf_table *t, cf_predict_table *pt)
{
    for (size_t k = 0; k < m->ntables; k++) {
        const cf_fitfile_table *e = &m->tab[k];
        double to = 0;
        if (!same_table(t, e) || cf_measure_unit(e->unit, &to) == CF_UNIT_UNKNOWN || !(to > 0))
            continue;
        pt->fitted = (int)k + 1;
        pt->fit_rmse = e->rmse * to;
        const double scale = isfinite(e->scale) ? e->scale * to : pt->rms;
        pt->fit_term = scale > 0 ? (pt->fit_rmse / scale) * (pt->fit_rmse / scale) : 0;
        return;
    }
}

/* Table t predicted by pm into pt. */
static cf_status predict_table(const pmodel *pm, const cf_fitted_model *m, const cf_table *t,
                               cf_predict_table *pt, cf_error *err)
{
    pt->table = t;
    cf_status st = check_table(pm, t, err);
    if (st != CF_OK)
        return st;
    pt->model = calloc(t->count + 1, sizeof(double));
    pt->follows = calloc(t->count + 1, 1);
    if (!pt->model || !pt->follows)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu rows", t->count);
    double xfirst = 0; /* the first row not followed */
    for (size_t i = 0; i < t->count; i++) {
        double y = 0;
        pt->follows[i] = (unsigned char)eval_row(pm, t, i, &y);
        pt->model[i] = pt->follows[i] ? y : 0.0;
        pt->followed += pt->follows[i];
        if (!pt->follows[i] && xfirst == 0)
            xfirst = t->x[i];
    }
    pt->ok = pt->followed > 0;
    if (pt->ok && (st = figures(t, pt, err)) != CF_OK)
        return st;
    if (pt->followed < t->count)
        reach_note(pm, t, pt, xfirst);
    check_stability(pm, t, pt);
    stability_note(t, pt);
    match_fitted(m, t, pt);
    return CF_OK;
}

cf_status cf_predict(const char *fit_path, const char *type, const cf_table *const *tables,
                     size_t n, cf_predict_result *r, cf_error *err)
{
    CF_GSL_GUARD;
    memset(r, 0, sizeof *r);
    snprintf(r->fit_path, sizeof r->fit_path, "%s", fit_path);
    if (n == 0)
        return cf_error_set(err, CF_E_DATA, "no table to predict");
    cf_status st = cf_fitfile_load_model(fit_path, type, &r->fit, err);
    if (st != CF_OK)
        return st;
    pmodel *pm = malloc(sizeof *pm);
    r->tab = calloc(n, sizeof *r->tab);
    if (!pm || !r->tab) {
        free(pm);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    }
    r->n = n;
    st = model_build(&r->fit, fit_path, pm, err);
    r->model = pm->kind;
    for (size_t k = 0; st == CF_OK && k < n; k++)
        st = predict_table(pm, &r->fit, tables[k], &r->tab[k], err);
    cf_law_free(&pm->law);
    free(pm);
    for (size_t k = 0; st == CF_OK && k < n; k++) {
        r->sum_terms += r->tab[k].ok ? r->tab[k].term : 0.0;
        r->fitted += r->tab[k].fitted != 0;
    }
    for (size_t k = 0; st == CF_OK && k < n; k++)
        r->tab[k].share = r->sum_terms > 0 && r->tab[k].ok ? r->tab[k].term / r->sum_terms : 0.0;
    if (st == CF_OK && r->fit.joint)
        st = cf_pf_predict(fit_path, tables, n, &r->fibre, err);
    return st;
}

void cf_predict_free(cf_predict_result *r)
{
    if (!r)
        return;
    for (size_t k = 0; r->tab && k < r->n; k++) {
        free(r->tab[k].model);
        free(r->tab[k].follows);
    }
    free(r->tab);
    r->tab = NULL;
    cf_pf_free(&r->fibre);
    r->n = 0;
}
