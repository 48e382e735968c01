/*
** What the model cannot follow in a table, as sentences the text report, the fit file
** (warnings[]) and the command line's standard error share (report.h, cf_report_warnings).
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "report/report.h"
#include "report/report_words.h"

/* The table softens: the conical law only stiffens. */
static int softening_warning(const cf_fit_report *r, char *buf, size_t cap)
{
    const cf_softening *s = &r->softening;
    if (!s->found)
        return 0;
    snprintf(buf, cap,
             "the table softens (its curve is concave) from %s %.4g to %.4g, %.0f %% of its "
             "range: the conical law only stiffens with strain and cannot follow that part (it "
             "settles on a compromise through it)",
             cf_table_is_force(r->table) ? "displacement" : "strain", s->from, s->to,
             100 * s->share);
    return 1;
}

/* A design limit that holds fit i away from a better fit of the table, by more than
** CF_LIMIT_COST_WARN of RMSE. */
static int limit_cost_warning(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_limit_cost *lc = &r->limit_cost[i];
    if (!lc->checked || !(lc->rmse > (1 + CF_LIMIT_COST_WARN) * lc->rmse_free))
        return 0;
    char names[160] = "", flags[160] = "";
    size_t nn = 0, nf = 0;
    for (int b = 0; b < CF_C_COUNT; b++)
        if (lc->limits >> b & 1u) {
            nn += (size_t)snprintf(names + nn, sizeof names - nn, "%s%s", nn ? ", " : "",
                                   cf_fit_constraint_name(1u << b));
            nf += (size_t)snprintf(flags + nf, sizeof flags - nf, "%s%s", nf ? ", " : "",
                                   cf_fit_constraint_flag(1u << b));
            if (nn >= sizeof names || nf >= sizeof flags)
                break;
        }
    const double u = r->table->y_to_file, ratio = lc->rmse / lc->rmse_free;
    char worse[48];
    if (ratio < 10)
        snprintf(worse, sizeof worse, "%.0f %% worse", 100 * (ratio - 1));
    else
        snprintf(worse, sizeof worse, "%.3g times as large", ratio);
    snprintf(buf, cap,
             "the %s fit is held by the design limit%s %s: RMSE %.4g %s, against %.4g %s without "
             "(%s); widen with %s if a spring of that design is acceptable",
             cf_spring_type_name(r->fits[i].type), strchr(names, ',') ? "s" : "", names,
             lc->rmse * u, r->table->y_unit, lc->rmse_free * u, r->table->y_unit, worse, flags);
    return 1;
}

/* Why fit i cannot follow the table, in a few words after its sentence ("" when nothing says). */
static void worse_why(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_limit_cost *lc = &r->limit_cost[i];
    const unsigned held = r->fits[i].held;
    size_t n = 0;
    buf[0] = '\0';
    if (lc->checked && lc->rmse > (1 + CF_LIMIT_COST_WARN) * lc->rmse_free) {
        snprintf(buf, cap, " within its design limits (see the limit above)");
        return;
    }
    if (r->softening.found) {
        snprintf(buf, cap, " (it softens, see above)");
        return;
    }
    for (int b = 0; b < CF_C_COUNT && held; b++)
        if (held >> b & 1u && n + 1 < cap)
            n += (size_t)snprintf(buf + n, cap - n, "%s%s", n ? ", " : " (held by ",
                                  cf_fit_constraint_name(1u << b));
    if (n > 0 && n + 1 < cap)
        snprintf(buf + n, cap - n, ")");
}

/* A fit worse than the straight line through the table, for whatever reason: its target's RMSE
** (the cell's for a fit through the lattice) against the line's. */
static int worse_than_linear(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_fit_result *f = &r->fits[i];
    const cf_baseline *lin = &r->baselines[CF_BASE_LINEAR];
    const int thr = r->through_msm && r->thr[i].done;
    const double rmse = thr ? r->thr[i].cell_rmse : f->rmse;
    /* equal to rounding: the law stays in its first, linear region over the table (it is the
    ** line), which is said as such rather than as a loss to the line */
    const int same = fabs(rmse - lin->rmse) <= 1e-9 * lin->rmse;
    if (!lin->fitted || !(rmse > lin->rmse || same))
        return 0;
    const double u = r->table->y_to_file;
    char why[192];
    if (f->feasible)
        worse_why(r, i, why, sizeof why);
    else
        snprintf(why, sizeof why, " (and its spring is infeasible)");
    if (same)
        snprintf(buf, cap,
                 "the %s fit (%sRMSE %.4g %s) is no better than a straight line through the table: "
                 "the law stays in its first, linear region over the whole table%s",
                 cf_spring_type_name(f->type), thr ? "through the lattice, " : "", rmse * u,
                 r->table->y_unit, why);
    else
        snprintf(buf, cap,
                 "the %s fit (%sRMSE %.4g %s) is worse than a straight line through the table "
                 "(RMSE %.4g %s): the law cannot follow this table%s",
                 cf_spring_type_name(f->type), thr ? "through the lattice, " : "", rmse * u,
                 r->table->y_unit, lin->rmse * u, r->table->y_unit, why);
    return 1;
}

/* A force-displacement table's spring placed far beyond the table's own scale: its largest size
** (D2, H or the tail's length) over the table's largest |displacement| above this. */
#define SCALE_WARN 100.0

static int scale_warning(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_fit_result *f = &r->fits[i];
    if (!cf_table_is_force(r->table))
        return 0;
    double xmax = 0;
    for (size_t k = 0; k < r->table->count; k++)
        xmax = fmax(xmax, fabs(r->table->x[k]));
    const cf_spring *p = &f->params;
    const double size = fmax(fmax(p->D2_mm, p->H_mm), p->H_tail_mm);
    if (!(xmax > 0) || !(size > SCALE_WARN * xmax))
        return 0;
    snprintf(buf, cap,
             "the %s spring placed for this force-displacement table is %.3g times its largest "
             "displacement (%.4g mm): D1 %.4g mm, D2 %.4g mm, d %.4g mm, H %.4g mm; the limits, "
             "not the data, set its size, and no spring of the specimen's own scale was found: "
             "read the law's quantities (rho, the travel, the solid load), not these dimensions",
             cf_spring_type_name(f->type), size / xmax, xmax, p->D1_mm, p->D2_mm, p->d_mm,
             p->H_mm);
    return 1;
}

/* A fit through the lattice asked for (its mode, or --validate) that did not run: the numbers are
** the single spring's, not the lattice's. */
static int target_warning(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_through_msm *t = &r->thr[i];
    if (!r->through_msm || t->done)
        return 0;
    snprintf(buf, cap,
             "the %s fit is of the single spring, not the lattice in %s: the fit through the "
             "lattice did not run (%s)",
             cf_spring_type_name(r->fits[i].type), cf_mode_name(r->table->mode),
             t->note[0] ? t->note : r->val[i].note[0] ? r->val[i].note : "no reason given");
    return 1;
}

/* The tailed law asked for whose search did no better than the conical law it contains: the
** conical optimum with no tail is what is reported (cf_fit_tail_run). */
static int nested_warning(const cf_fit_report *r, int i, char *buf, size_t cap)
{
    const cf_fit_result *f = &r->fits[i];
    if (!f->tail || f->params.n_tail != 0)
        return 0;
    char why[320];
    cf_report_nested(r, f, why, sizeof why);
    snprintf(buf, cap, "the %s conical-tail fit has %s", cf_spring_type_name(f->type), why);
    return 1;
}

int cf_report_warnings(const cf_fit_report *r, char (*out)[CF_REPORT_WARNING_LEN], int cap)
{
    int n = 0;
    if (n < cap)
        n += softening_warning(r, out[n], CF_REPORT_WARNING_LEN);
    for (int i = 0; i < r->nfits; i++) {
        if (n < cap)
            n += limit_cost_warning(r, i, out[n], CF_REPORT_WARNING_LEN);
        if (n < cap)
            n += worse_than_linear(r, i, out[n], CF_REPORT_WARNING_LEN);
        if (n < cap)
            n += scale_warning(r, i, out[n], CF_REPORT_WARNING_LEN);
        if (n < cap)
            n += target_warning(r, i, out[n], CF_REPORT_WARNING_LEN);
        if (n < cap)
            n += nested_warning(r, i, out[n], CF_REPORT_WARNING_LEN);
    }
    return n;
}
