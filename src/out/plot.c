/*
** conifit's figures (see plot.h), written as gnuplot scripts under the rule of gnuplot.h.
*/
#include "out/plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "out/gnuplot.h"

/* Points on each model curve. */
#define CURVE_POINTS 400

/* x and the lattice stress (file's unit) of every data point, sorted by x. */
static void lattice_block(cf_gp *g, const char *name, const cf_table *d,
                          const double *stress_MPa, double u)
{
    size_t *ord = malloc(sizeof(size_t) * (d->count ? d->count : 1));
    if (!ord) {
        cf_gp_block_begin(g, name);
        cf_gp_block_end(g);
        return;
    }
    for (size_t i = 0; i < d->count; i++)
        ord[i] = i;
    for (size_t i = 1; i < d->count; i++) /* insertion sort: tables are short and nearly sorted */
        for (size_t j = i; j > 0 && d->x[ord[j - 1]] > d->x[ord[j]]; j--) {
            size_t t = ord[j];
            ord[j] = ord[j - 1];
            ord[j - 1] = t;
        }
    cf_gp_block_begin(g, name);
    for (size_t i = 0; i < d->count; i++) {
        double row[2] = {d->x[ord[i]], stress_MPa[ord[i]] * u};
        cf_gp_block_row(g, 2, row);
    }
    cf_gp_block_end(g);
    free(ord);
}

static void fit_script(cf_gp *g, const void *fig)
{
    const cf_fit_report *r = fig;
    const cf_table *d = r->table;
    const double u = d->y_to_file;
    double xmin = 0, xmax = 0;
    for (size_t i = 0; i < d->count; i++) {
        xmin = fmin(xmin, d->x[i]);
        xmax = fmax(xmax, d->x[i]);
    }
    cf_law laws[2];
    for (int i = 0; i < r->nfits; i++)
        laws[i] = r->fits[i].law;
    double row[2 + 2 * (2 + CF_BASE_COUNT)];
    /* data: x, y, then the residual of each model (fits then baselines) */
    cf_gp_block_begin(g, "DATA");
    for (size_t i = 0; i < d->count; i++) {
        size_t c = 0;
        row[c++] = d->x[i];
        row[c++] = d->y[i] * u;
        for (int k = 0; k < r->nfits; k++)
            row[c++] = (cf_fit_model(&laws[k], cf_table_is_force(d), d->x[i]) - d->y[i]) * u;
        for (int k = 0; k < CF_BASE_COUNT; k++)
            row[c++] = (cf_baseline_eval(&r->baselines[k], d->x[i]) - d->y[i]) * u;
        cf_gp_block_row(g, c, row);
    }
    cf_gp_block_end(g);
    cf_gp_block_begin(g, "CURVES");
    for (int j = 0; j <= CURVE_POINTS; j++) {
        size_t c = 0;
        double x = xmin + (xmax - xmin) * j / CURVE_POINTS;
        row[c++] = x;
        for (int k = 0; k < r->nfits; k++)
            row[c++] = cf_fit_model(&laws[k], cf_table_is_force(d), x) * u;
        for (int k = 0; k < CF_BASE_COUNT; k++)
            row[c++] = cf_baseline_eval(&r->baselines[k], x) * u;
        cf_gp_block_row(g, c, row);
    }
    cf_gp_block_end(g);
    /* the lattice curve of each validated fit, at the table's strains in increasing order */
    static const char *const lat_name[2] = {"LATTICE0", "LATTICE1"};
    int lat[2] = {0, 0};
    if (r->validate)
        for (int k = 0; k < r->nfits; k++)
            if (r->val[k].done && r->val[k].count == d->count) {
                lattice_block(g, lat_name[k], d, r->val[k].stress_MPa, u);
                lat[k] = 1;
            }
    cf_gp_cmd(g, "set multiplot");
    cf_gp_cmd(g, "set title %q noenhanced", d->path);
    cf_gp_cmd(g, "set size 1,0.66");
    cf_gp_cmd(g, "set origin 0,0.34");
    cf_gp_cmd(g, "set grid");
    cf_gp_cmd(g, "set key top left box opaque");
    cf_gp_cmd(g, "set xlabel %q", cf_table_is_force(d) ? "displacement [mm]" : "strain [-]");
    char yl[400];
    snprintf(yl, sizeof yl, "%s [%s]", d->y_column, d->y_unit);
    cf_gp_cmd(g, "set ylabel %q noenhanced", yl);
    static const char *colors[2] = {"#d62728", "#1f77b4"};
    static const char *bcolors[CF_BASE_COUNT] = {"#7f7f7f", "#2ca02c", "#9467bd"};
    /* one plot command over several lines: each item ends in a backslash, an empty line ends it */
    cf_gp_cmd(g, "plot $DATA using 1:2 with points pt 7 ps 0.6 lc rgb %q title %q \\", "black",
              "measured");
    for (int k = 0; k < r->nfits; k++) {
        char t[64];
        snprintf(t, sizeof t, "conical, %s", cf_spring_type_name(r->fits[k].type));
        cf_gp_cmd(g, "  , $CURVES using 1:%d with lines lw %d lc rgb %q title %q \\", 2 + k,
                  k == 0 ? 4 : 2, colors[k], t);
    }
    for (int k = 0; k < CF_BASE_COUNT; k++)
        cf_gp_cmd(g, "  , $CURVES using 1:%d with lines lw 1 dt 2 lc rgb %q title %q \\",
                  2 + r->nfits + k, bcolors[k], cf_baseline_name((cf_baseline_kind)k));
    for (int k = 0; k < r->nfits; k++)
        if (lat[k]) {
            char t[96];
            snprintf(t, sizeof t, "lattice %dx%dx%d, %s", r->val[k].setup.cfg.lattice.nx,
                     r->val[k].setup.cfg.lattice.ny, r->val[k].setup.cfg.lattice.nz,
                     cf_spring_type_name(r->fits[k].type));
            cf_gp_cmd(g, "  , $LATTICE%d using 1:2 with linespoints lw 2 dt 4 pt 6 ps 0.5 "
                         "lc rgb %q title %q \\",
                      k, colors[k], t);
        }
    cf_gp_cmd(g, "");
    cf_gp_cmd(g, "set size 1,0.34");
    cf_gp_cmd(g, "set origin 0,0");
    cf_gp_cmd(g, "unset title");
    cf_gp_cmd(g, "set key off");
    char rl[96];
    snprintf(rl, sizeof rl, "residual [%s]", d->y_unit);
    cf_gp_cmd(g, "set ylabel %q noenhanced", rl);
    cf_gp_cmd(g, "plot 0 with lines lc rgb %q notitle \\", "black");
    for (int k = 0; k < r->nfits; k++)
        cf_gp_cmd(g, "  , $DATA using 1:%d with linespoints pt 7 ps 0.4 lc rgb %q \\", 3 + k,
                  colors[k]);
    for (int k = 0; k < CF_BASE_COUNT; k++)
        cf_gp_cmd(g, "  , $DATA using 1:%d with lines dt 2 lc rgb %q \\", 3 + r->nfits + k,
                  bcolors[k]);
    cf_gp_cmd(g, "");
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
    return draw(fit_script, r, 900, 800, path, inputs, out, err);
}

cf_status cf_plot_write(const cf_fit_report *r, const char *path, const char *const *inputs,
                        cf_error *err)
{
    cf_atomic a;
    cf_status st = cf_plot_fit(r, path, inputs, &a, err);
    if (st == CF_OK)
        st = cf_atomic_commit(&a, err);
    return st;
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
    cf_gp_cmd(g, "set key top left noenhanced");
    cf_gp_cmd(g, "set grid");
    /* the curve is named after the spring it ran (a scene's fit file, or "params") */
    char lattice[700];
    snprintf(lattice, sizeof lattice, "lattice (spring: %s)", sc->spring_source);
    if (sc->kind == CF_PROTO_HOLD) {
        cf_gp_cmd(g, "set xlabel %q", "time (s)");
        if (sc->drive == CF_DRIVE_FORCE) {
            cf_gp_cmd(g, "set ylabel %q", "compressive strain");
            cf_gp_cmd(g, "set title %q", "creep under a held load");
            cf_gp_cmd(g, "plot $SIM using 1:2 with lines lw 2 title %q", lattice);
        } else {
            cf_gp_cmd(g, "set ylabel %q", "compressive stress (kPa)");
            cf_gp_cmd(g, "set title %q", "relaxation under a held strain");
            cf_gp_cmd(g, "plot $SIM using 1:3 with lines lw 2 title %q", lattice);
        }
        return;
    }
    cf_gp_cmd(g, "set xlabel %q", "compressive strain");
    cf_gp_cmd(g, "set ylabel %q", "compressive stress (kPa)");
    if (sc->kind == CF_PROTO_CYCLES) {
        cf_gp_cmd(g, "set title %q", "load-unload cycles");
        cf_gp_cmd(g, "plot $SIM using 2:3 with lines lw 2 title %q", lattice);
    } else {
        cf_gp_cmd(g, "set title %q", "uniaxial: lattice against one spring");
        cf_gp_cmd(g, "plot $SIM using 2:3 with lines lw 2 title %q, $SIM using 2:4 with lines "
                     "lw 2 dt 2 title %q",
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
