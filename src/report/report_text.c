/*
** The readable report of a fit (see report.h), written through a memory stream: the table, the
** quantities the data determine, the springs, the validation, the constraints, the verdict and
** the baselines.
*/
#include "report/report.h"
#include "model/mode.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/lawkind.h"
#include "io/measures.h"
#include "report/report_baselines.h"
#include "report/report_notes.h"
#include "report/report_words.h"

static void row(FILE *o, const cf_fit_report *r, const char *label, const char *fmt, int which)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const cf_spring *p = &f->params;
        char cell[64];
        double u = r->table->y_to_file;
        switch (which) {
        case 0: case 1: case 2: case 3: case 4: case 5: /* the design parameters (spring.h) */
            snprintf(cell, sizeof cell, fmt, cf_spring_get(p, which)); break;
        case 6: snprintf(cell, sizeof cell, fmt, f->law.index_c); break;
        case 7: snprintf(cell, sizeof cell, fmt, f->law.travel_mm); break;
        case 8: snprintf(cell, sizeof cell, fmt, f->law.F_T_N); break;
        case 9: snprintf(cell, sizeof cell, fmt, f->law.F_C_N); break;
        case 10: snprintf(cell, sizeof cell, fmt, f->rmse * u, r->table->y_unit); break;
        case 11: snprintf(cell, sizeof cell, fmt, f->max_abs_error * u, r->table->y_unit); break;
        case 12: snprintf(cell, sizeof cell, fmt, f->r2); break;
        case 13: snprintf(cell, sizeof cell, fmt, cf_report_fit_aic(r, i)); break;
        case 14: snprintf(cell, sizeof cell, fmt, f->law.k0_N_per_mm); break;
        case 15: case 16: /* the tail's parameters, blank for a spring without one */
            if (f->tail && p->n_tail > 0)
                snprintf(cell, sizeof cell, fmt, cf_spring_get(p, which - 15 + CF_P_N_TAIL));
            else
                snprintf(cell, sizeof cell, f->tail ? "none" : "-");
            break;
        case 17:
            if (f->tail && p->n_tail > 0)
                snprintf(cell, sizeof cell, fmt, f->law.k_tail_N_per_mm);
            else
                snprintf(cell, sizeof cell, "-");
            break;
        default: cell[0] = '\0';
        }
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* 1 when a fit has a tailed spring (its tail's design parameters get rows). */
static int any_tail(const cf_fit_report *r)
{
    for (int i = 0; i < r->nfits; i++)
        if (r->fits[i].tail)
            return 1;
    return 0;
}

/* The row of quantity `key` (value ± standard error, or value [low, high], the profile interval
** marked *): a cell per fit, "-" for a fit whose kind has no such quantity. */
static void ident_row(FILE *o, const cf_fit_report *r, const cf_law_row *row, int k)
{
    const char *key = cf_law_q_key(row, k, r->table);
    const char *unit = cf_law_q_unit(row, k, r->table);
    const int in_y = strcmp(unit, "y") == 0;
    fprintf(o, "  %-26s", cf_law_q_label(row, k, r->table));
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const cf_law_row *fk = cf_fit_kind_of(f);
        char cell[96];
        int m = 0;
        while (m < fk->nq && strcmp(cf_law_q_key(fk, m, r->table), key) != 0)
            m++;
        if (m == fk->nq)
            snprintf(cell, sizeof cell, "-");
        else if (fk->q[m].zero_text && f->q[m] == 0)
            snprintf(cell, sizeof cell, "%s", fk->q[m].zero_text);
        else
            cf_report_ident_cell(f, m, in_y ? r->table->y_to_file : 1,
                                 in_y ? r->table->y_unit : unit, cell, sizeof cell);
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* A row per quantity of the fits' kinds, each once, in the order of the first kind that has it. */
static void ident_rows(FILE *o, const cf_fit_report *r)
{
    for (int i = 0; i < r->nfits; i++) {
        const cf_law_row *row = cf_fit_kind_of(&r->fits[i]);
        for (int k = 0; k < row->nq; k++) {
            const char *key = cf_law_q_key(row, k, r->table);
            int seen = 0;
            for (int h = 0; h < i && !seen; h++) {
                const cf_law_row *prev = cf_fit_kind_of(&r->fits[h]);
                for (int m = 0; m < prev->nq; m++)
                    seen = seen || strcmp(cf_law_q_key(prev, m, r->table), key) == 0;
            }
            if (!seen)
                ident_row(o, r, row, k);
        }
    }
}

/* The kinds compared in law choice lc, as "the conical law (3 quantities) against the conical
** spring with a cylindrical tail (4)". */
static void kinds_compared(FILE *o, const cf_law_choice *lc)
{
    for (int j = 0; j < lc->n; j++) {
        const cf_law_row *row = cf_fit_kind_of(&lc->cand[j]);
        if (j == 0)
            fprintf(o, "the %s (%d quantities)", row->title, row->nq);
        else
            fprintf(o, " %s the %s (%d)", j == 1 ? "against" : "and", row->title, row->nq);
    }
}

/* Why lc kept the kind it kept, in words. */
static const char *kept_why(const cf_fit_report *r, const cf_law_choice *lc, char *buf,
                            size_t cap)
{
    if (lc->asked) {
        snprintf(buf, cap, "asked for (--law %s)", cf_law_kind_name(r->law));
        return buf;
    }
    if (lc->chosen != 0)
        return "lower AIC";
    /* the best of the others by AIC: infeasible, or no lower */
    int b = 1;
    for (int j = 2; j < lc->n; j++)
        if (lc->aic[j] < lc->aic[b])
            b = j;
    const cf_law_row *row = cf_fit_kind_of(&lc->cand[b]);
    if (!lc->cand[b].feasible)
        snprintf(buf, cap, "%s is infeasible", row->spring);
    else if (row->adds)
        snprintf(buf, cap, "%s does not lower the AIC", row->adds);
    else
        snprintf(buf, cap, "the %s does not lower the AIC", row->title);
    return buf;
}

/* The law kinds fitted to each type, when more than one was: quality, AIC, and the one kept. */
static void law_choice_text(FILE *o, const cf_fit_report *r)
{
    int first = -1;
    for (int i = 0; i < r->nfits && first < 0; i++)
        if (r->law_choice[i].ran)
            first = i;
    if (first < 0)
        return;
    const double u = r->table->y_to_file;
    int lattice = r->through_msm;
    for (int i = 0; i < r->nfits; i++)
        lattice &= r->thr[i].done;
    if (r->fit_options.nkinds > 0)
        fprintf(o, "\nLaw kinds compared: ");
    else
        fprintf(o, "\nLaw (--law %s): ", cf_law_kind_name(r->law));
    kinds_compared(o, &r->law_choice[first]);
    fprintf(o, "%s\n", lattice ? ", both fitted through the lattice (RMSE and AIC the lattice's)"
                               : "");
    for (int i = 0; i < r->nfits; i++) {
        const cf_law_choice *lc = &r->law_choice[i];
        if (!lc->ran)
            continue;
        for (int j = 0; j < lc->n; j++) {
            const cf_fit_result *f = &lc->cand[j];
            char nested[320];
            cf_report_nested(r, f, nested, sizeof nested);
            fprintf(o, "  %-16s %-12s RMSE %.4g %s  AIC %.2f%s%s%s%s\n",
                    j == 0 ? cf_spring_type_name(r->fits[i].type) : "", cf_fit_kind_of(f)->name,
                    f->rmse * u, r->table->y_unit, lc->aic[j], f->feasible ? "" : "  (infeasible)",
                    nested[0] ? "  (" : "", nested, nested[0] ? ")" : "");
        }
        char why[160];
        fprintf(o, "  %-16s kept: %s (%s)\n", "", cf_fit_kind_of(&lc->cand[lc->chosen])->name,
                kept_why(r, lc, why, sizeof why));
    }
}

/* Below the table: what each starred interval means, per type and quantity (the tail's
** compliance after the three). */
static void interval_notes(FILE *o, const cf_fit_report *r)
{
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const cf_law_row *row = cf_fit_kind_of(f);
        for (int k = 0; k < row->nq; k++) {
            if (!f->interval_ok[k])
                continue;
            char why[512];
            cf_report_interval_reason(f, k, why, sizeof why);
            fprintf(o, "  * %s, %s: %s\n", cf_spring_type_name(f->type),
                    cf_law_q_name(row, k, r->table), why);
        }
    }
}

/* One cell per fit from a printf format and a value (MPa values are converted by the caller). */
static void cells(FILE *o, const cf_fit_report *r, const char *label, const char *const *text)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++)
        fprintf(o, " %-24s", text[i]);
    fputc('\n', o);
}

/* The lattice the validation ran (the setup of a fit it was done for), its moduli and the test
** mode (the fit's target is stated once, at the top). */
static void validation_header(FILE *o, const cf_fit_report *r)
{
    const cf_validate_setup *su = &r->val[0].setup;
    const cf_validation *v0 = &r->val[0];
    for (int i = 0; i < r->nfits; i++)
        if (r->val[i].done) {
            su = &r->val[i].setup;
            v0 = &r->val[i];
        }
    const cf_lattice_config *lc = &su->cfg.lattice;
    cf_cubic_moduli cm = cf_cubic_moduli_of(lc->weight);
    fprintf(o,
            " validation in the lattice (%d x %d x %d cells, calibration %s: weights edge %.4g, "
            "face %.4g, body %.4g; small-strain modulus %.4g x k0/H, nu %.3f; bottom %s, %s):\n",
            lc->nx, lc->ny, lc->nz, cf_calibration_name(lc->calibration),
            lc->weight[CF_FAMILY_EDGE], lc->weight[CF_FAMILY_FACE], lc->weight[CF_FAMILY_BODY],
            cm.E, cm.nu, lc->bottom == CF_BOTTOM_CLAMPED ? "clamped" : "axial",
            cf_law_method_name(su->method));
    fprintf(o, "  mode %s, %s\n", cf_mode_name(v0->mode),
            v0->by_cell ? "homogenised cell (the full lattice has no such boundary conditions)"
                        : "full lattice");
}

/* Prints rows k < nrows of buf (one cell per fit) under their labels. */
static void cell_rows(FILE *o, const cf_fit_report *r, char (*buf)[2][64], int nrows,
                      const char *const *labels)
{
    const char *t[2];
    for (int k = 0; k < nrows; k++) {
        for (int i = 0; i < r->nfits; i++)
            t[i] = buf[k][i];
        cells(o, r, labels[k], t);
    }
}

/* The stability row of one validation: how far the table's range is stable, by which check. */
static void stability_cell(char *buf, size_t size, const cf_validation *v)
{
    if (!v->stability_checked)
        snprintf(buf, size, "not checked (%.40s)",
                 cf_report_why(v->stability_note, "the scan did not run"));
    else if (!v->unstable_in_range)
        snprintf(buf, size, "to strain %.4g (table's end, %s)", v->stable_to_strain,
                 v->by_cell ? "cell tangent" : "full lattice");
    else
        snprintf(buf, size, "to strain %.4g (!) (%s)", v->stable_to_strain,
                 v->by_cell ? "cell tangent" : "full lattice");
}

/* The warning of a table that reaches past the stability limit of fit i's target. */
static void stability_warning(FILE *o, const cf_fit_report *r, int i)
{
    const cf_validation *v = &r->val[i];
    if (v->by_cell)
        fprintf(o, "  (!) %s: the cell's incremental stiffness stops being positive definite at "
                "%s strain %.4g, inside the table's range: past it a homogeneous %s state is "
                "unstable (the tissue would localise)\n",
                cf_spring_type_name(r->fits[i].type), cf_mode_name(v->mode), v->stable_to_strain,
                cf_mode_name(v->mode));
    else
        fprintf(o, "  (!) %s: the lattice loses stability at strain %.4g, inside the table's "
                "range: past it the static curve is an unstable equilibrium (a column of "
                "cells buckles sideways in a dynamic run)\n",
                cf_spring_type_name(r->fits[i].type), v->stable_to_strain);
}

/* The validation's numbers, one column per fit. */
static void validation_rows(FILE *o, const cf_fit_report *r)
{
    enum { ROWS = 7 };
    char buf[ROWS][2][64];
    const double u = r->table->y_to_file;
    const char *yu = r->table->y_unit;
    for (int i = 0; i < r->nfits; i++) {
        const cf_validation *v = &r->val[i];
        if (!v->done) {
            for (int k = 0; k < ROWS; k++)
                snprintf(buf[k][i], sizeof buf[k][i], k ? "" : "skipped (see below)");
            continue;
        }
        const cf_through_msm *th = &r->thr[i];
        double fr = r->through_msm && th->done ? th->cell_rmse : r->fits[i].rmse;
        snprintf(buf[0][i], sizeof buf[0][i], "%.4g %s", fr * u, yu);
        snprintf(buf[1][i], sizeof buf[1][i], "%.4g %s", v->rmse * u, yu);
        if (isfinite(v->law_rmse))
            snprintf(buf[2][i], sizeof buf[2][i], "%.4g %s", v->law_rmse * u, yu);
        else
            snprintf(buf[2][i], sizeof buf[2][i], "- (not uniaxial)");
        snprintf(buf[3][i], sizeof buf[3][i], "%.4g %s", v->max_abs_error * u, yu);
        snprintf(buf[4][i], sizeof buf[4][i], "%.6f", v->r2);
        snprintf(buf[5][i], sizeof buf[5][i], "%.1f ms, %zu solves", 1e3 * v->wall_time_s,
                 v->solves);
        stability_cell(buf[6][i], sizeof buf[6][i], v);
    }
    static const char *const labels[ROWS] = {"fit RMSE (its target)", "lattice RMSE",
                                             "lattice vs law (RMSE)", "lattice max |error|",
                                             "lattice R^2", "lattice time", "lattice stable"};
    cell_rows(o, r, buf, ROWS, labels);
}

/* The fit through the lattice: its RMSE before and after, its check in the full lattice, cost. */
static void through_rows(FILE *o, const cf_fit_report *r)
{
    char buf[3][2][64];
    const double u = r->table->y_to_file;
    const char *yu = r->table->y_unit;
    for (int i = 0; i < r->nfits; i++) {
        const cf_through_msm *th = &r->thr[i];
        if (th->done)
            snprintf(buf[0][i], sizeof buf[0][i], "%.4g -> %.4g %s", th->rmse_before * u,
                     th->cell_rmse * u, yu);
        else
            snprintf(buf[0][i], sizeof buf[0][i], "not run");
        if (th->done && th->verified)
            snprintf(buf[1][i], sizeof buf[1][i], "max |full - cell| %.3g %s",
                     th->verify_max_abs * u, yu);
        else
            snprintf(buf[1][i], sizeof buf[1][i], "%s", th->done ? "cell only" : "");
        snprintf(buf[2][i], sizeof buf[2][i], "%.3f s, %ld cell curves (%ld for errors)",
                 th->wall_time_s, th->evaluations, th->uncertainty_curves);
    }
    static const char *const tl[3] = {"through lattice: RMSE", "verified in full lattice",
                                      "through lattice: cost"};
    cell_rows(o, r, buf, 3, tl);
}

/* The lattice validation (and the fit through the lattice) beside the single-spring quality. */
static void validation_text(FILE *o, const cf_fit_report *r)
{
    int any = 0;
    for (int i = 0; i < r->nfits; i++)
        any |= r->val[i].done;
    if (!any) {
        fprintf(o, " validation in the lattice: skipped: %s\n",
                cf_report_why(r->val[0].note, "the validation did not run (no reason recorded)"));
        return;
    }
    validation_header(o, r);
    validation_rows(o, r);
    for (int i = 0; i < r->nfits; i++)
        if (r->val[i].done && r->val[i].unstable_in_range)
            stability_warning(o, r, i);
    if (r->through_msm)
        through_rows(o, r);
    for (int i = 0; i < r->nfits; i++)
        if (!r->val[i].done)
            fprintf(o, "  (%s: validation skipped: %s)\n", cf_spring_type_name(r->fits[i].type),
                    cf_report_why(r->val[i].note, "no reason recorded"));
}

/* A mode stated for a table whose kind cannot honour it, and why. */
static void mode_dropped_text(FILE *o, const cf_table *t)
{
    const char *why = cf_report_mode_dropped(t);
    if (why)
        fprintf(o, " mode %s (stated) is not honoured: %s\n", cf_mode_name(t->mode), why);
}

/* The table: its size, columns, sign, and (stress-strain) its measures and their conversion. */
static void table_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, "%s: %zu points, %s [%s] against %s [%s], %s\n", r->table->path, r->table->count,
            r->table->x_column, r->table->x_unit, r->table->y_column, r->table->y_unit,
            r->table->compression ? "compression negative" : "tension positive");
    if (cf_table_is_force(r->table)) {
        mode_dropped_text(o, r->table);
        cf_report_notes_text(o, r->table, " ");
        return;
    }
    const cf_table_measures *m = &r->table->measures;
    char src[3][128], conv[256];
    cf_report_sources(r->table, src);
    cf_report_conversion(r->table, conv, sizeof conv);
    const char *strain = cf_report_strain_name(r->table, src);
    fprintf(o, " measures: stress %s (%s), strain %s (%s), mode %s (%s)\n",
            cf_stress_measure_name(m->stress), src[0], strain, src[1],
            cf_mode_name(r->table->mode), src[2]);
    if (*conv)
        fprintf(o, " fitted as engineering strain and nominal stress: %s\n", conv);
    cf_report_notes_text(o, r->table, " ");
    fputc('\n', o);
}

/* The fit's target, once: what every headline number below (quality, errors, the type's
** verdict) is of. */
static void target_text(FILE *o, const cf_fit_report *r)
{
    if (cf_report_target_is_lattice(r))
        fprintf(o, " fit target: the lattice in %s (its homogenised cell): every number below "
                   "is the lattice's unless named otherwise\n\n",
                cf_mode_name(r->table->mode));
    else if (!cf_table_is_force(r->table))
        fprintf(o, " fit target: the single spring (its law F(eH)/H^2 against the table)%s\n\n",
                r->validate ? "; the lattice below is a check of that spring" : "");
}

/* The three quantities the data determine, their intervals, correlations and distance to solid. */
static void identifiable_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, " identifiable (determined by the data):\n");
    ident_rows(o, r);
    interval_notes(o, r);
    fprintf(o, "  %-26s", "correlation rho-s, rho-A, s-A");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        const cf_fit_result *f = &r->fits[i];
        if (isfinite(f->corr[0][1]))
            snprintf(cell, sizeof cell, "%.3f, %.3f, %.3f", f->corr[0][1], f->corr[0][2],
                     f->corr[1][2]);
        else
            snprintf(cell, sizeof cell, "not determined");
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    fprintf(o, "  %-26s", cf_table_is_force(r->table) ? "solid / largest |u|" : "solid / largest |strain|");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        const cf_fit_result *f = &r->fits[i];
        /* below 1 the data run past the spring's solid: not "close" to it */
        snprintf(cell, sizeof cell, "%.3g%s", f->solid_ratio,
                 f->solid_ratio < 1                       ? " (data past solid!)"
                 : f->solid_ratio < CF_FIT_SOLID_RATIO_WARN ? " (close to solid!)"
                                                            : "");
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
}

/* The single spring's own law against the table, beside a lattice target: only for a uniaxial
** table (in the other modes the law has no curve to compare). */
static void spring_law_text(FILE *o, const cf_fit_report *r)
{
    if (!cf_report_target_is_lattice(r) || !cf_mode_row_of(r->table->mode)->spring_curve)
        return;
    enum { ROWS = 3 };
    char buf[ROWS][2][64];
    const double u = r->table->y_to_file;
    for (int i = 0; i < r->nfits; i++) {
        const cf_through_msm *t = &r->thr[i];
        snprintf(buf[0][i], sizeof buf[0][i], "%.4g %s", t->law_rmse * u, r->table->y_unit);
        snprintf(buf[1][i], sizeof buf[1][i], "%.4g %s", t->law_max_abs_error * u,
                 r->table->y_unit);
        snprintf(buf[2][i], sizeof buf[2][i], "%.6f", t->law_r2);
    }
    static const char *const labels[ROWS] = {"RMSE", "max |error|", "R^2"};
    fprintf(o, " the single spring against the table (uniaxial law):\n");
    cell_rows(o, r, buf, ROWS, labels);
}

/* One spring of the family (the field table's parameters and what follows from them), and the
** fit's quality. */
static void spring_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, " one spring of that family (chosen by the constraints):\n");
    for (int k = 0; k < CF_P_COUNT; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        char fmt[32];
        snprintf(fmt, sizeof fmt, "%%.6g%s%s", strcmp(sp->unit, "-") ? " " : "",
                 strcmp(sp->unit, "-") ? sp->unit : "");
        row(o, r, sp->name, fmt, k);
    }
    row(o, r, "spring index c = D1/d", "%.4g", 6);
    row(o, r, "travel s", "%.6g mm", 7);
    row(o, r, "F_T, F_C", "%.4g N", 8);
    row(o, r, "", "%.4g N", 9);
    row(o, r, "k0", "%.6g N/mm", 14);
    if (any_tail(r)) {
        row(o, r, "n_tail (tail coils)", "%.6g", 15);
        row(o, r, "H_tail (tail length)", "%.6g mm", 16);
        row(o, r, "k_tail", "%.6g N/mm", 17);
    }
    fprintf(o, " quality (the %s):\n", cf_report_target_is_lattice(r) ? "lattice's" : "spring's");
    row(o, r, "RMSE", "%.4g %s", 10);
    row(o, r, "max |error|", "%.4g %s", 11);
    row(o, r, "R^2", "%.6f", 12);
    row(o, r, any_tail(r) ? "AIC (k = 3, tailed 4)" : "AIC (k = 3)", "%.2f", 13);
    spring_law_text(o, r);
}

/* One row of constraint names per fit: those of its active (which = 0) or holding (1) mask,
** joined by commas, or `none` when there are none. */
static void constraint_row(FILE *o, const cf_fit_report *r, const char *label, int which,
                           const char *none)
{
    fprintf(o, "  %-26s", label);
    for (int i = 0; i < r->nfits; i++) {
        const cf_fit_result *f = &r->fits[i];
        const unsigned mask = which == 0 ? f->active : f->held;
        char cell[160] = "";
        size_t n = 0;
        for (int k = 0; k < CF_C_COUNT; k++)
            if (mask & (1u << k))
                cf_report_append(cell, sizeof cell, &n, "%s%s", n ? "," : "",
                                 cf_fit_constraint_name(1u << k));
        fprintf(o, " %-24s", n ? cell : none);
    }
    fputc('\n', o);
}

/* Feasibility, the constraints that are active and that hold the spring, the optimiser's cost,
** and the limits the fit ran under. */
static void constraints_text(FILE *o, const cf_fit_report *r)
{
    fprintf(o, "  %-26s", "feasible");
    for (int i = 0; i < r->nfits; i++) {
        char cell[160] = "yes";
        if (!r->fits[i].feasible) {
            snprintf(cell, sizeof cell, "NO:");
            for (int k = 0; k < CF_C_COUNT; k++)
                if (r->fits[i].violated & (1u << k))
                    snprintf(cell + strlen(cell), sizeof cell - strlen(cell), " %s",
                             cf_fit_constraint_name(1u << k));
        }
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    constraint_row(o, r, "active constraints", 0, "none");
    fprintf(o, "  %-26s", "optimizer, evaluations");
    for (int i = 0; i < r->nfits; i++) {
        char cell[64];
        snprintf(cell, sizeof cell, "%s, %ld, %.1f ms", r->fits[i].optimizer,
                 r->fits[i].evaluations, 1e3 * r->fits[i].wall_time_s);
        fprintf(o, " %-24s", cell);
    }
    fputc('\n', o);
    constraint_row(o, r, "held by", 1, "nothing");
    const cf_fit_options *fo = &r->fit_options;
    fprintf(o, "  limits: rho >= %g, %g <= n <= %g, 3 <= D1/d <= %g, D2 <= %g H, G <= %g MPa "
               "(flags --rho-min, --n-max, --index-max, --D2-max-H, --G-max)\n",
            fo->rho_min, fo->lower[CF_P_N], fo->upper[CF_P_N], fo->index_max, fo->D2_over_H_max,
            fo->upper[CF_P_G]);
}

/* The verdict on the type, the baselines, and what the six numbers mean. */
static void verdict_and_baselines(FILE *o, const cf_fit_report *r)
{
    int b = cf_report_better(r);
    if (r->nfits == 2 && b >= 0) {
        char text[1024];
        cf_report_verdict(r, text, sizeof text);
        fprintf(o, "\nType: %s\n", text);
    } else if (b < 0) {
        fprintf(o, "\nNo feasible fit: no spring meets every constraint on this table (see "
                   "'feasible' above).\n");
    }
    fprintf(o, "\nBaselines (plain least squares; Yeoh and Ogden in the %s form of an "
               "incompressible solid):\n",
            cf_mode_name(r->baselines[CF_BASE_YEOH].form));
    for (int k = 0; k < CF_BASE_COUNT; k++) {
        const cf_baseline *bl = &r->baselines[k];
        if (!bl->fitted) {
            fprintf(o, "  %-8s not fitted: %s\n", cf_baseline_name(bl->kind), bl->why);
            continue;
        }
        char co[128];
        cf_report_baseline_coefficients(r, k, co, sizeof co);
        fprintf(o, "  %-8s %-44s RMSE %.4g %s   AIC %.2f (k = %d)\n", cf_baseline_name(bl->kind),
                co, bl->rmse * r->table->y_to_file, r->table->y_unit,
                cf_report_baseline_aic(r, k), bl->k);
    }
    fprintf(o, "\nThe law seen through this table depends on the six design parameters only through "
               "rho,\nthe %s and the %s. The six numbers above are one member of a family of "
               "equally\ngood springs, chosen by the constraints (spring index, n >= 2, type, "
               "bounds, fixed values).\n",
            cf_table_is_force(r->table) ? "travel" : "solid strain",
            cf_table_is_force(r->table) ? "solid load" : "stress scale");
    if (any_tail(r))
        fprintf(o, "A spring with a tail (conical-tail) adds one quantity, the tail's compliance, "
                   "and two\nparameters, n_tail and H_tail, placed in closed form with the "
                   "others.\n");
}

/* What the model cannot follow, one sentence each. */
static void warnings_text(FILE *o, const cf_fit_report *r)
{
    char w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
    int n = cf_report_warnings(r, w, CF_REPORT_WARNINGS_MAX);
    if (n > 0)
        fprintf(o, "\nWarnings:\n");
    for (int k = 0; k < n; k++)
        fprintf(o, "  (!) %s\n", w[k]);
}

char *cf_report_text(const cf_fit_report *r)
{
    CF_GSL_GUARD;
    char *buf = NULL;
    size_t len = 0;
    FILE *o = open_memstream(&buf, &len);
    if (!o)
        return NULL;
    table_text(o, r);
    target_text(o, r);
    fprintf(o, "  %-26s", "");
    for (int i = 0; i < r->nfits; i++)
        fprintf(o, " %-24s", cf_spring_type_name(r->fits[i].type));
    fputc('\n', o);
    identifiable_text(o, r);
    spring_text(o, r);
    if (r->validate)
        validation_text(o, r);
    constraints_text(o, r);
    law_choice_text(o, r);
    verdict_and_baselines(o, r);
    warnings_text(o, r);
    fclose(o);
    return buf;
}
