/*
** conifit's figures (see plot.h), written as gnuplot scripts under the rule of gnuplot.h.
*/
#include "report/plot.h"
#include "model/mode.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/cell.h"
#include "report/gnuplot.h"
#include "io/measures.h"

/* Points on each model curve. */
#define CURVE_POINTS 400

/* The figure of a fit, laid out for a paper: the model panel on top, the residual panel under
** it, both with the same x axis and margins, each with its legend in the column to their right
** (never over the data). Every curve differs from the others by its dash pattern, width or point
** symbol as well as by its colour, so that the figure reads in greyscale. */

/* Left and right edge of both panels, and where the legends start (fractions of the canvas). */
#define PANEL_LEFT 0.09
#define PANEL_RIGHT 0.66
#define KEY_LEFT 0.68

/* Line styles: 1-2 the conical fits, 3-7 the baselines, 8-9 the lattice curves. */
static void styles(cf_gp *g)
{
    cf_gp_cmd(g, "set style line 1 dt 1 lw 3.5 lc rgb %q", "#b2182b");
    cf_gp_cmd(g, "set style line 2 dt 2 lw 2.5 lc rgb %q", "#2166ac");
    cf_gp_cmd(g, "set style line 3 dt 3 lw 2 lc rgb %q", "#525252");
    cf_gp_cmd(g, "set style line 4 dt 4 lw 1.5 lc rgb %q", "#1b7837");
    cf_gp_cmd(g, "set style line 5 dt 5 lw 1.5 lc rgb %q", "#762a83");
    cf_gp_cmd(g, "set style line 6 dt (12, 4, 2, 4) lw 1.5 lc rgb %q", "#8c510a");
    cf_gp_cmd(g, "set style line 7 dt (8, 3, 2, 3, 2, 3) lw 2 lc rgb %q", "#01665e");
    cf_gp_cmd(g, "set style line 8 dt 1 lw 1.5 pt 4 ps 0.9 lc rgb %q", "#d6604d");
    cf_gp_cmd(g, "set style line 9 dt 2 lw 1.5 pt 8 ps 0.9 lc rgb %q", "#4393c3");
}

/* x, the lattice stress and its residual (file's unit) of every data point, sorted by x. */
static void lattice_block(cf_gp *g, const char *name, const cf_table *d,
                          const double *stress_MPa, double u)
{
    size_t *ord = malloc(sizeof(size_t) * (d->count ? d->count : 1));
    cf_gp_block_begin(g, name);
    if (ord) {
        for (size_t i = 0; i < d->count; i++)
            ord[i] = i;
        for (size_t i = 1; i < d->count; i++) /* insertion sort: tables are short, nearly sorted */
            for (size_t j = i; j > 0 && d->x[ord[j - 1]] > d->x[ord[j]]; j--) {
                size_t t = ord[j];
                ord[j] = ord[j - 1];
                ord[j - 1] = t;
            }
        for (size_t i = 0; i < d->count; i++) {
            size_t k = ord[i];
            double row[3] = {d->x[k], stress_MPa[k] * u, (stress_MPa[k] - d->y[k]) * u};
            cf_gp_block_row(g, 3, row);
        }
    }
    cf_gp_block_end(g);
    free(ord);
}

/* Which curves a panel draws: the fits (both, or one when the types tie) and the lattices (both,
** one when their curves coincide, or none). */
typedef struct fit_curves {
    int fit[2];       /* 1: draw fit k */
    int lattice[2];   /* 1: draw the lattice curve of fit k */
    int style[2];     /* line style of fit k (its lattice curve: style + 7) */
    int lattice_fit[2]; /* 1: fit k is drawn as the lattice's curve it was fitted through */
    char fit_title[2][96];
    char lattice_title[2][128];
} fit_curves;

/* The curve a fit through the lattice fitted, at the count strains x: its lattice's homogenised
** cell in the table's mode (in uniaxial mode the full lattice's curve wherever that deforms
** homogeneously: the validation's check). 0, or nonzero when the cell cannot run it. */
static int target_curve(const cf_fit_report *r, int k, const double *x, size_t count,
                        double *out)
{
    const cf_validate_setup *su = &r->val[k].setup;
    cf_law law;
    if (cf_law_init(&law, &r->fits[k].params, NULL) != CF_OK)
        return 1;
    cf_cell cell;
    int bad = cf_cell_init(&cell, &law, su->method == CF_LAW_TABLE ? CF_LAW_CLOSED : su->method,
                           su->cfg.lattice.weight, NULL) != CF_OK;
    cell.biaxial_k = cf_table_biaxial_k(r->table, 0); /* biaxial: the first direction's curve */
    bad = bad || cf_cell_curve(&cell, r->table->mode, x, count, out, NULL) != CF_OK;
    cf_law_free(&law);
    return bad;
}

/* The data blocks: $DATA (x, y, the residual of each fit then of each baseline) and $CURVES (x,
** each fit, each baseline) in the file's unit; a baseline not fitted has its columns (zero) but
** no curve. */
static void fit_blocks(cf_gp *g, const cf_fit_report *r, fit_curves *fc)
{
    const int *lattice_fit = fc->lattice_fit;
    const cf_table *d = r->table;
    const double u = d->y_to_file;
    const int fd = cf_table_is_force(d);
    double xmin = 0, xmax = 0, row[2 + 2 * (2 + CF_BASE_COUNT)];
    for (size_t i = 0; i < d->count; i++) {
        xmin = fmin(xmin, d->x[i]);
        xmax = fmax(xmax, d->x[i]);
    }
    double xs[CURVE_POINTS + 1], target[2][CURVE_POINTS + 1];
    for (int j = 0; j <= CURVE_POINTS; j++)
        xs[j] = xmin + (xmax - xmin) * j / CURVE_POINTS;
    for (int k = 0; k < r->nfits; k++)
        if (lattice_fit[k] && target_curve(r, k, xs, CURVE_POINTS + 1, target[k]) != 0) {
            /* the cell cannot run the curve between the points: the lattice at the table's
            ** strains (the validation's) is drawn as the fit instead */
            memset(target[k], 0, sizeof target[k]);
            if (fc->fit[k]) {
                fc->fit[k] = 0;
                fc->lattice[k] = 1;
                /* the fit's title (a terminated string shorter than the lattice's buffer) */
                _Static_assert(sizeof fc->fit_title[k] <= sizeof fc->lattice_title[k],
                               "a fit title fits a lattice title");
                memcpy(fc->lattice_title[k], fc->fit_title[k], sizeof fc->fit_title[k]);
            }
        }
    cf_gp_block_begin(g, "DATA");
    for (size_t i = 0; i < d->count; i++) {
        size_t c = 0;
        row[c++] = d->x[i];
        row[c++] = d->y[i] * u;
        for (int k = 0; k < r->nfits; k++)
            row[c++] = ((lattice_fit[k] ? r->val[k].stress_MPa[i]
                                        : cf_fit_model(&r->fits[k].law, fd, d->x[i])) -
                        d->y[i]) *
                       u;
        for (int k = 0; k < CF_BASE_COUNT; k++)
            row[c++] = r->baselines[k].fitted
                           ? (cf_baseline_eval(&r->baselines[k], d->x[i]) - d->y[i]) * u
                           : 0;
        cf_gp_block_row(g, c, row);
    }
    cf_gp_block_end(g);
    cf_gp_block_begin(g, "CURVES");
    for (int j = 0; j <= CURVE_POINTS; j++) {
        size_t c = 0;
        row[c++] = xs[j];
        for (int k = 0; k < r->nfits; k++)
            row[c++] = (lattice_fit[k] ? target[k][j] : cf_fit_model(&r->fits[k].law, fd, xs[j])) *
                       u;
        for (int k = 0; k < CF_BASE_COUNT; k++)
            row[c++] = r->baselines[k].fitted ? cf_baseline_eval(&r->baselines[k], xs[j]) * u
                                              : 0;
        cf_gp_block_row(g, c, row);
    }
    cf_gp_block_end(g);
}

/* Two curves that differ by less than this fraction of the largest |y| cannot be told apart in a
** figure: they are drawn once, and the legend says so. */
#define SAME_CURVE 2e-3

static void choose_curves(const cf_fit_report *r, fit_curves *c)
{
    memset(c, 0, sizeof *c);
    const cf_table *d = r->table;
    const int fd = cf_table_is_force(d);
    int keep = cf_report_better(r);
    if (keep < 0)
        keep = 0;
    for (int k = 0; k < r->nfits; k++)
        c->lattice_fit[k] = cf_report_target_is_lattice(r) && r->val[k].done &&
                            r->val[k].count == d->count && r->val[k].stress_MPa;
    for (int k = 0; k < r->nfits; k++) {
        c->fit[k] = 1;
        c->style[k] = 1 + (int)r->fits[k].type;
        /* the law kind named: a tailed fit is "conical-tail" */
        const char *law = r->fits[k].tail ? "conical-tail" : "conical";
        snprintf(c->fit_title[k], sizeof c->fit_title[k], "%s, %s", law,
                 cf_spring_type_name(r->fits[k].type));
        c->lattice[k] = r->validate && r->val[k].done && r->val[k].count == d->count;
        const cf_lattice_config *lc = &r->val[k].setup.cfg.lattice;
        snprintf(c->lattice_title[k], sizeof c->lattice_title[k], "lattice %dx%dx%d, %s", lc->nx,
                 lc->ny, lc->nz, cf_spring_type_name(r->fits[k].type));
        /* a fit through the lattice is its lattice's curve (the cell's in a mode the single
        ** spring has no form of), drawn as the fit; the spring's law is not what was fitted */
        if (c->lattice_fit[k]) {
            c->lattice[k] = 0;
            snprintf(c->fit_title[k], sizeof c->fit_title[k], "fit: lattice, %s%s",
                     cf_spring_type_name(r->fits[k].type), r->fits[k].tail ? ", tail" : "");
        }
    }
    if (c->lattice_fit[0] && (r->nfits == 1 || c->lattice_fit[1])) {
        if (r->nfits == 2 && cf_report_types_tie(r)) {
            c->fit[1 - keep] = 0;
            c->style[keep] = 1;
            snprintf(c->fit_title[keep], sizeof c->fit_title[keep],
                     "fit: lattice, both types (a tie)");
        }
        return;
    }
    if (r->nfits != 2)
        return;
    /* the two fits at the table's points and between them */
    double diff = 0, xmin = 0, xmax = 0;
    for (size_t i = 0; i < d->count; i++) {
        xmin = fmin(xmin, d->x[i]);
        xmax = fmax(xmax, d->x[i]);
    }
    for (int j = 0; j <= CURVE_POINTS; j++) {
        double x = xmin + (xmax - xmin) * j / CURVE_POINTS;
        diff = fmax(diff, fabs(cf_fit_model(&r->fits[0].law, fd, x) -
                               cf_fit_model(&r->fits[1].law, fd, x)));
    }
    if (cf_report_types_tie(r) || diff <= SAME_CURVE * r->ymax) {
        c->fit[1 - keep] = 0;
        c->style[keep] = 1; /* one curve for both: the solid style */
        if (cf_report_types_tie(r))
            snprintf(c->fit_title[keep], sizeof c->fit_title[keep],
                     "conical, both types (a tie)");
        else
            snprintf(c->fit_title[keep], sizeof c->fit_title[keep],
                     "conical, both types (coincide)");
    }
    if (c->lattice[0] && c->lattice[1]) {
        diff = 0;
        for (size_t i = 0; i < d->count; i++)
            diff = fmax(diff, fabs(r->val[0].stress_MPa[i] - r->val[1].stress_MPa[i]));
        if (diff <= SAME_CURVE * r->ymax) {
            c->lattice[1 - keep] = 0;
            const cf_lattice_config *lc = &r->val[keep].setup.cfg.lattice;
            snprintf(c->lattice_title[keep], sizeof c->lattice_title[keep],
                     "lattice %dx%dx%d, both types (coincide)", lc->nx, lc->ny, lc->nz);
        }
    }
}

/* One panel's plot command: the measured points (model panel only), the fits, the baselines and
** the lattice curves, columns from $DATA/$CURVES (residual: $DATA's residual columns). */
static void fit_panel(cf_gp *g, const cf_fit_report *r, const fit_curves *c, int residual)
{
    if (residual)
        cf_gp_cmd(g, "plot 0 with lines lc rgb %q lw 1 notitle \\", "black");
    else
        cf_gp_cmd(g, "plot $DATA using 1:2 with points pt 7 ps 0.7 lc rgb %q title %q \\",
                  "black", "measured");
    for (int k = 0; k < r->nfits; k++)
        if (c->fit[k]) {
            if (residual)
                cf_gp_cmd(g, "  , $DATA using 1:%d with lines ls %d title %q \\", 3 + k,
                          c->style[k], c->fit_title[k]);
            else
                cf_gp_cmd(g, "  , $CURVES using 1:%d with lines ls %d title %q \\", 2 + k,
                          c->style[k], c->fit_title[k]);
        }
    for (int k = 0; k < CF_BASE_COUNT; k++) {
        const char *name = cf_baseline_name((cf_baseline_kind)k);
        if (!r->baselines[k].fitted)
            continue;
        if (residual)
            cf_gp_cmd(g, "  , $DATA using 1:%d with lines ls %d title %q \\", 3 + r->nfits + k,
                      3 + k, name);
        else
            cf_gp_cmd(g, "  , $CURVES using 1:%d with lines ls %d title %q \\", 2 + r->nfits + k,
                      3 + k, name);
    }
    for (int k = 0; k < r->nfits; k++)
        if (c->lattice[k])
            cf_gp_cmd(g, "  , $LATTICE%d using 1:%d with linespoints ls %d title %q \\", k,
                      residual ? 3 : 2, 7 + c->style[k], c->lattice_title[k]);
    cf_gp_cmd(g, "");
}

/* The axes in the measures that were fitted (a table's columns are converted to engineering
** strain, or the amount of shear, and nominal stress), naming the column's own measure when it
** was converted: "nominal stress (from cauchy) [kPa]". */
static void axis_labels(const cf_table *d, char *x, size_t xcap, char *y, size_t ycap)
{
    if (cf_table_is_force(d)) {
        snprintf(x, xcap, "displacement [mm]");
        snprintf(y, ycap, "%s [%s]", d->y_column, d->y_unit);
        return;
    }
    const cf_table_measures *m = &d->measures;
    char from[64] = "";
    if (m->strain != CF_STRAIN_ENGINEERING)
        snprintf(from, sizeof from, " (from %s)", cf_strain_measure_name(m->strain));
    snprintf(x, xcap, "%s%s [-]",
             cf_mode_row_of(d->mode)->x_quantity, from);
    from[0] = '\0';
    if (m->stress != CF_STRESS_NOMINAL)
        snprintf(from, sizeof from, " (from %s)", cf_stress_measure_name(m->stress));
    snprintf(y, ycap, "nominal stress%s [%s]", from, d->y_unit);
}

static void fit_script(cf_gp *g, const void *fig)
{
    const cf_fit_report *r = fig;
    const cf_table *d = r->table;
    fit_curves c;
    choose_curves(r, &c);
    fit_blocks(g, r, &c);
    static const char *const lat_name[2] = {"LATTICE0", "LATTICE1"};
    for (int k = 0; k < r->nfits; k++)
        if (c.lattice[k])
            lattice_block(g, lat_name[k], d, r->val[k].stress_MPa, d->y_to_file);
    char title[300], label[400];
    if (r->title)
        snprintf(title, sizeof title, "%s", r->title);
    else
        cf_table_name(d, title, sizeof title);
    styles(g);
    cf_gp_cmd(g, "set multiplot");
    cf_gp_cmd(g, "set grid lc rgb %q", "#d9d9d9");
    cf_gp_cmd(g, "set format x %q", "%g");
    cf_gp_cmd(g, "set format y %q", "%g");
    cf_gp_cmd(g, "set lmargin at screen %g", PANEL_LEFT);
    cf_gp_cmd(g, "set rmargin at screen %g", PANEL_RIGHT);
    char xlabel[160];
    axis_labels(d, xlabel, sizeof xlabel, label, sizeof label);
    cf_gp_cmd(g, "set xlabel %q noenhanced", xlabel);
    /* the model panel */
    cf_gp_cmd(g, "set title %q noenhanced", title);
    cf_gp_cmd(g, "set tmargin at screen 0.93");
    cf_gp_cmd(g, "set bmargin at screen 0.42");
    cf_gp_cmd(g, "set key at screen %g,0.93 left top Left reverse noenhanced spacing 1.2 "
                 "samplen 3.5 title %q",
              KEY_LEFT, "model");
    cf_gp_cmd(g, "set ylabel %q noenhanced", label);
    fit_panel(g, r, &c, 0);
    /* the residual panel */
    cf_gp_cmd(g, "unset title");
    cf_gp_cmd(g, "set tmargin at screen 0.32");
    cf_gp_cmd(g, "set bmargin at screen 0.07");
    cf_gp_cmd(g, "set key at screen %g,0.32 left top Left reverse noenhanced spacing 1.2 "
                 "samplen 3.5 title %q",
              KEY_LEFT, "residual (model - measured)");
    snprintf(label, sizeof label, "residual [%s]", d->y_unit);
    cf_gp_cmd(g, "set ylabel %q noenhanced", label);
    fit_panel(g, r, &c, 1);
    cf_gp_cmd(g, "unset multiplot");
}

/* A figure of width x height pixels: its script, drawn to a temporary file beside path. */
static cf_status draw(void (*script)(cf_gp *, const void *), const void *fig, int width,
                      int height, const char *path, const char *const *inputs, cf_atomic *out,
                      cf_error *err)
{
    cf_gp g;
    memset(out, 0, sizeof *out);
    cf_gp_init(&g);
    cf_gp_terminal(&g, path, width, height);
    script(&g, fig);
    cf_status st = cf_gp_render(&g, path, inputs, out, err);
    cf_gp_free(&g);
    return st;
}

cf_status cf_plot_check_name(const char *path, cf_error *err)
{
    return cf_gp_check_name(path, err);
}

cf_status cf_plot_fit(const cf_fit_report *r, const char *path, const char *const *inputs,
                      cf_atomic *out, cf_error *err)
{
    return draw(fit_script, r, 1150, 820, path, inputs, out, err);
}

typedef struct simulation_figure {
    const cf_scene *sc;
    const cf_msm_sample *s;
    const double *spring_MPa;
    size_t n;
} simulation_figure;

static void simulation_script(cf_gp *g, const void *fig)
{
    const simulation_figure *f = fig;
    const cf_scene *sc = f->sc;
    const cf_msm_sample *s = f->s;
    const double *spring_MPa = f->spring_MPa;
    size_t n = f->n;
    /* columns: time [s], strain [-], stress [kPa], one spring's stress [kPa] */
    cf_gp_block_begin(g, "SIM");
    for (size_t k = 0; k < n; k++) {
        double row[4] = {s[k].t_s, s[k].strain, s[k].stress_MPa * 1e3, spring_MPa[k] * 1e3};
        cf_gp_block_row(g, 4, row);
    }
    cf_gp_block_end(g);
    /* the legend under the axes, never over the curve; styles that differ in greyscale */
    cf_gp_cmd(g, "set key below noenhanced spacing 1.2 samplen 3.5");
    cf_gp_cmd(g, "set bmargin 5");
    cf_gp_cmd(g, "set grid lc rgb %q", "#d9d9d9");
    cf_gp_cmd(g, "set format x %q", "%g");
    cf_gp_cmd(g, "set format y %q", "%g");
    styles(g);
    /* the curve is named after the spring it ran (a scene's fit file, or "params") */
    char lattice[700];
    snprintf(lattice, sizeof lattice, "lattice (spring: %s)", sc->spring_source);
    if (sc->kind == CF_PROTO_HOLD || sc->kind == CF_PROTO_HISTORY) {
        const int hist = sc->kind == CF_PROTO_HISTORY;
        cf_gp_cmd(g, "set xlabel %q", "time (s)");
        if (sc->drive == CF_DRIVE_FORCE) {
            cf_gp_cmd(g, "set ylabel %q", "compressive strain");
            cf_gp_cmd(g, "set title %q", hist ? "along a loading history" : "creep under a held load");
            cf_gp_cmd(g, "plot $SIM using 1:2 with lines ls 1 title %q", lattice);
        } else {
            cf_gp_cmd(g, "set ylabel %q", "compressive stress (kPa)");
            cf_gp_cmd(g, "set title %q",
                      hist ? "along a loading history" : "relaxation under a held strain");
            cf_gp_cmd(g, "plot $SIM using 1:3 with lines ls 1 title %q", lattice);
        }
        return;
    }
    cf_gp_cmd(g, "set xlabel %q", "compressive strain");
    cf_gp_cmd(g, "set ylabel %q", "compressive stress (kPa)");
    if (sc->kind == CF_PROTO_CYCLES) {
        cf_gp_cmd(g, "set title %q", "load-unload cycles");
        cf_gp_cmd(g, "plot $SIM using 2:3 with lines ls 1 title %q", lattice);
    } else {
        cf_gp_cmd(g, "set title %q", "uniaxial: lattice against one spring");
        cf_gp_cmd(g, "plot $SIM using 2:3 with lines ls 1 title %q, $SIM using 2:4 with lines "
                     "ls 2 title %q",
                  lattice, "single spring");
    }
}

cf_status cf_plot_simulation(const cf_scene *sc, const cf_msm_sample *s, const double *spring_MPa,
                             size_t n, const char *path, const char *const *inputs,
                             cf_atomic *out, cf_error *err)
{
    simulation_figure f = {sc, s, spring_MPa, n};
    return draw(simulation_script, &f, 800, 560, path, inputs, out, err);
}

typedef struct probe_figure {
    const char *title, *series, *xlabel;
    const double *x, *force_N;
    size_t n;
} probe_figure;

static void probe_script(cf_gp *g, const void *fig)
{
    const probe_figure *f = fig;
    cf_gp_block_begin(g, "PROBE");
    for (size_t k = 0; k < f->n; k++) {
        double row[2] = {f->x[k], f->force_N[k]};
        cf_gp_block_row(g, 2, row);
    }
    cf_gp_block_end(g);
    cf_gp_cmd(g, "set key below noenhanced spacing 1.2 samplen 3.5");
    cf_gp_cmd(g, "set bmargin 5");
    cf_gp_cmd(g, "set grid lc rgb %q", "#d9d9d9");
    cf_gp_cmd(g, "set format x %q", "%g");
    cf_gp_cmd(g, "set format y %q", "%g");
    styles(g);
    cf_gp_cmd(g, "set title %q noenhanced", f->title);
    cf_gp_cmd(g, "set xlabel %q", f->xlabel);
    cf_gp_cmd(g, "set ylabel %q", "probe force (N), pushing into the body");
    cf_gp_cmd(g, "plot $PROBE using 1:2 with linespoints ls 8 title %q", f->series);
}

cf_status cf_plot_probe(const char *title, const char *series, const char *xlabel,
                        const double *x, const double *force_N, size_t n, const char *path,
                        const char *const *inputs, cf_atomic *out, cf_error *err)
{
    probe_figure f = {title, series, xlabel, x, force_N, n};
    return draw(probe_script, &f, 800, 560, path, inputs, out, err);
}
