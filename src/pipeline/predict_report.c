/*
** What a prediction reports (see predict.h): the readable text, the CSV of measured against
** predicted, and the figure through the one gnuplot runner (data as blocks of numbers, text from
** input as string literals only).
*/
#include "pipeline/predict.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/safetext.h"
#include "model/mode.h"
#include "report/gnuplot.h"

/* The model in words (a fit through the lattice: its weights and what else it holds) into out. */
static void model_words(const cf_predict_result *r, char *out, size_t cap)
{
    const cf_fitted_model *m = &r->fit;
    const cf_fitted_spring *s = &m->spring;
    const char *law = s->params.n_tail > 0 ? "conical-tail" : "conical";
    if (r->model == CF_PREDICT_SPRING) {
        snprintf(out, cap, "the single spring's %s law (a fit to the spring, %s)", law,
                 m->force_displacement ? "force against displacement" : "stress F/H^2 against "
                                                                        "strain u/H");
        return;
    }
    char kappa[64] = "no volume term";
    if (s->volume_modulus_MPa > 0)
        snprintf(kappa, sizeof kappa, "volume term kappa %.4g MPa", s->volume_modulus_MPa);
    snprintf(out, cap,
             "the lattice's homogenised cell in each table's mode (%s through the lattice; %s "
             "%s; family weights edge %.4f, face %.4f, body %.4f; %s; law evaluated %s)",
             m->joint ? "a joint fit" : "a fit", s->has_extension ? "double-acting element,"
                                                                 : "one spring per element,",
             s->has_extension ? (s->params.n_tail > 0 ? "its compression spring conical-tail"
                                                      : "both springs conical")
                              : law,
             m->weight[0], m->weight[1], m->weight[2], kappa, cf_law_method_name(m->method));
}

/* The mode column of t: its test mode, or what a force-displacement table is (one spring's
** curve, whatever its '# mode:'). */
static const char *mode_word(const cf_table *t)
{
    return cf_table_is_force(t) ? "force-displacement" : cf_mode_name(t->mode);
}

/* The fit's own figures of a table it was fitted to, or "not fitted", into out. */
static void fitted_cell(const cf_predict_table *pt, char *out, size_t cap)
{
    const cf_table *t = pt->table;
    if (!pt->fitted)
        snprintf(out, cap, "not fitted to it");
    else
        snprintf(out, cap, "%.6g %s, term %.6g", pt->fit_rmse * t->y_to_file, t->y_unit,
                 pt->fit_term);
}

/* One table's row of the report. */
static void table_row(FILE *o, const cf_predict_table *pt, int width)
{
    const cf_table *t = pt->table;
    const double u = t->y_to_file;
    char rows[48], fit[96];
    snprintf(rows, sizeof rows, "%zu/%zu", pt->followed, t->count);
    fitted_cell(pt, fit, sizeof fit);
    if (!pt->ok) {
        fprintf(o, "  %-*s %-18s %9s %16s %9s %16s %12s %7s  %s\n", width, t->path,
                mode_word(t), rows, "-", "-", "-", "-", "-", fit);
        return;
    }
    char rmse[48], rms[48];
    snprintf(rmse, sizeof rmse, "%.6g %s", pt->rmse * u, t->y_unit);
    snprintf(rms, sizeof rms, "%.6g %s", pt->rms * u, t->y_unit);
    fprintf(o, "  %-*s %-18s %9s %16s %9.5f %16s %12.6g %6.1f%%  %s\n", width, t->path,
            mode_word(t), rows, rmse, pt->r2, rms, pt->term, 100 * pt->share, fit);
}

char *cf_predict_text(const cf_predict_result *r)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *o = open_memstream(&buf, &len);
    if (!o)
        return NULL;
    char words[512];
    model_words(r, words, sizeof words);
    fprintf(o, "Prediction by %s, its %s spring, without refitting:\n %s\n\n", r->fit_path,
            cf_spring_type_name(r->fit.spring.type), words);
    int width = 5;
    for (size_t k = 0; k < r->n; k++)
        width = (int)fmax(width, (double)strlen(r->tab[k].table->path));
    fprintf(o, "  %-*s %-18s %9s %16s %9s %16s %12s %7s  %s\n", width, "table", "mode", "rows",
            "RMSE", "R^2", r->fit.force_displacement ? "RMS force" : "RMS stress", "term", "share",
            "the fit's own RMSE");
    for (size_t k = 0; k < r->n; k++)
        table_row(o, &r->tab[k], width);
    fprintf(o, "\n term: the table's part of the joint objective, (RMSE / RMS stress)^2 with every "
               "row weighted alike\n (sqrt(w_i / n) / RMS stress with a weight column), as a "
               "joint fit weights it; share: its part of the sum.\n");
    fprintf(o, " sum of the terms: %.6g over %zu table%s", r->sum_terms, r->n,
            r->n == 1 ? "" : "s");
    if (r->fit.joint)
        fprintf(o, "; the fit's own weighted objective over the %zu table%s it was fitted to: "
                   "%.6g",
                r->fit.ntables, r->fit.ntables == 1 ? "" : "s", r->fit.objective);
    fprintf(o, "\n");
    int notes = 0;
    for (size_t k = 0; k < r->n; k++)
        if (r->tab[k].note[0])
            fprintf(o, "%s %s: %s\n", notes++ ? "" : "\nnotes:\n", r->tab[k].table->path,
                    r->tab[k].note);
    if (r->fibre.n) {
        const cf_table **tp = malloc((r->n + 1) * sizeof *tp);
        for (size_t k = 0; tp && k < r->n; k++)
            tp[k] = r->tab[k].table;
        if (tp)
            cf_pf_text(o, &r->fibre, tp);
        free(tp);
    }
    if (fclose(o) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

void cf_predict_write_csv(const cf_predict_result *r, FILE *f)
{
    fprintf(f, "# conifit predict: measured against predicted at every row of each table (the "
               "table's own units); predicted and residual empty where the model cannot follow "
               "the row\n");
    for (size_t k = 0; k < r->n; k++) {
        char safe[1100];
        const char *p = r->tab[k].table->path;
        fprintf(f, "# table %zu: %s\n", k + 1, cf_safe_text(safe, sizeof safe, p, strlen(p)));
    }
    fprintf(f, "table,mode,row,x,x_unit,measured,predicted,residual,y_unit,followed\n");
    for (size_t k = 0; k < r->n; k++) {
        const cf_predict_table *pt = &r->tab[k];
        const cf_table *t = pt->table;
        const double u = t->y_to_file;
        char unit[40];
        cf_safe_text(unit, sizeof unit, t->y_unit, strlen(t->y_unit));
        for (size_t i = 0; i < t->count; i++) {
            fprintf(f, "%zu,%s,%zu,%.12g,%s,%.12g,", k + 1, mode_word(t), i + 1,
                    t->x[i], cf_table_is_force(t) ? "mm" : "-", t->y[i] * u);
            if (pt->follows[i])
                fprintf(f, "%.12g,%.12g,", pt->model[i] * u, (pt->model[i] - t->y[i]) * u);
            else
                fprintf(f, ",,");
            fprintf(f, "%s,%d\n", unit, pt->follows[i]);
        }
    }
}

/* The figure: one panel per table, its measured points and the prediction at its rows. */
static cf_status draw(const cf_predict_result *r, const char *path, const char *const *inputs,
                      cf_atomic *out, cf_error *err)
{
    cf_gp g;
    cf_gp_init(&g);
    const int n = (int)r->n;
    cf_gp_terminal(&g, path, 420 * (n < 4 ? n : 4), 420 * ((n + 3) / 4));
    for (int k = 0; k < n; k++) {
        const cf_predict_table *pt = &r->tab[k];
        const cf_table *t = pt->table;
        char name[16];
        snprintf(name, sizeof name, "M%d", k);
        cf_gp_block_begin(&g, name);
        for (size_t i = 0; i < t->count; i++) {
            const double row[2] = {t->x[i], t->y[i] * t->y_to_file};
            cf_gp_block_row(&g, 2, row);
        }
        cf_gp_block_end(&g);
        snprintf(name, sizeof name, "P%d", k);
        cf_gp_block_begin(&g, name);
        for (size_t i = 0; i < t->count; i++)
            if (pt->follows[i]) {
                const double row[2] = {t->x[i], pt->model[i] * t->y_to_file};
                cf_gp_block_row(&g, 2, row);
            }
        if (!pt->ok) { /* an empty block cannot be plotted: the origin stands for it */
            const double row[2] = {0, 0};
            cf_gp_block_row(&g, 2, row);
        }
        cf_gp_block_end(&g);
    }
    cf_gp_cmd(&g, "set multiplot layout %d,%d", (n + 3) / 4, n < 4 ? n : 4);
    cf_gp_cmd(&g, "set grid");
    for (int k = 0; k < n; k++) {
        const cf_table *t = r->tab[k].table;
        cf_gp_cmd(&g, t->compression ? "set key bottom right box opaque"
                                     : "set key top left box opaque");
        const char *base = strrchr(t->path, '/');
        cf_gp_cmd(&g, "set title %q noenhanced", base ? base + 1 : t->path);
        char xl[64], yl[64];
        snprintf(xl, sizeof xl, "%s [%s]", cf_table_is_force(t) ? "displacement"
                                                                : cf_mode_row_of(t->mode)->x_short,
                 cf_table_is_force(t) ? "mm" : "-");
        snprintf(yl, sizeof yl, "%s [%s]", cf_table_is_force(t) ? "force" : "stress", t->y_unit);
        cf_gp_cmd(&g, "set xlabel %q noenhanced", xl);
        cf_gp_cmd(&g, "set ylabel %q noenhanced", yl);
        cf_gp_cmd(&g, "plot $M%d using 1:2 with points pt 7 ps 0.7 lc rgb %q title %q, "
                      "$P%d using 1:2 with linespoints pt 6 ps 0.5 lw 2 lc rgb %q title %q",
                  k, "black", "measured", k, "#d62728",
                  r->tab[k].fitted ? "predicted (fitted to it)" : "predicted (not fitted)");
    }
    cf_gp_cmd(&g, "unset multiplot");
    cf_status st = cf_gp_render(&g, path, inputs, out, err);
    cf_gp_free(&g);
    return st;
}

cf_status cf_predict_prepare(const cf_predict_result *r, const char *csv_path,
                             const char *plot_path, const char *const *inputs,
                             cf_atomic *csv_out, cf_atomic *plot_out, cf_error *err)
{
    cf_status st = cf_atomic_begin("cf_predict_prepare", r, csv_path, csv_out, plot_path,
                                   plot_out, err);
    if (st != CF_OK)
        return st;
    if (plot_path && (st = cf_gp_check_name(plot_path, err)) != CF_OK)
        return st;
    if (csv_path && (st = cf_atomic_open(csv_out, csv_path, inputs, err)) == CF_OK) {
        cf_predict_write_csv(r, csv_out->fp);
        st = cf_atomic_finish(csv_out, err);
    }
    if (st == CF_OK && plot_path)
        st = draw(r, plot_path, inputs, plot_out, err);
    if (st != CF_OK) {
        cf_atomic_abort(csv_out);
        cf_atomic_abort(plot_out);
    }
    return st;
}
