/*
** The sentences a fit report states both in its text and in its JSON fit file (private to
** src/report/): why an interval was computed, the verdict on the spring type, where a table's
** measures came from and how its columns were converted.
*/
#include "report/report_words.h"
#include "fit/lawkind.h"
#include "io/measures.h"
#include "model/mode.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Appends to buf (capacity cap, *n used), never past its end. */
void cf_report_append(char *buf, size_t cap, size_t *n, const char *fmt, ...)
{
    if (*n + 1 >= cap)
        return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(buf + *n, cap - *n, fmt, ap);
    va_end(ap);
    if (k > 0)
        *n = fmin(*n + (size_t)k, cap - 1);
}

/* Quantity k of f with its error and profile interval: k < 3 the identifiable quantities,
** CF_REPORT_TAIL the tailed law's e_t. Returns interval_ok. */
static int quantity(const cf_fit_result *f, int k, double *v, double *se, const double **iv,
                    const unsigned **end, unsigned *why)
{
    *v = f->q[k], *se = f->q_se[k], *iv = f->interval[k];
    *end = f->interval_end[k], *why = f->interval_why[k];
    return f->interval_ok[k];
}

/* Why a profile interval was computed and where its ends come from, in words. */
void cf_report_interval_reason(const cf_fit_result *f, int k, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    double v, se;
    const double *iv;
    const unsigned *ends;
    unsigned why;
    quantity(f, k, &v, &se, &iv, &ends, &why);
    unsigned lim = why & ~CF_FIT_RANK_DEFICIENT;
    cf_report_append(buf, cap, &n, "profile likelihood, 95 %% (F-test), because ");
    if (why & CF_FIT_RANK_DEFICIENT)
        cf_report_append(buf, cap, &n, "the Jacobian is rank-deficient%s", lim ? " and " : "");
    if (lim) {
        cf_report_append(buf, cap, &n, "the fit sits on");
        for (int b = 0; b < CF_C_COUNT; b++)
            if (lim & (1u << b))
                cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
    }
    if (!why)
        cf_report_append(buf, cap, &n, "the standard error reaches past the quantity's range");
    for (int e = 0; e < 2; e++) {
        unsigned b = ends[e];
        if (b)
            cf_report_append(buf, cap, &n,
                             "; the %s end is the limit %s: the data do not bound it",
                             e ? "upper" : "lower", cf_fit_constraint_name(b & (0u - b)));
    }
}

/* The limits that keep the law of fit g (its rho, B, A) from a spring of type t: 0 where one is
** placed within them. A stress-strain table's spring is at (rho, B) with any free length; a force
** table's free length H is free too (B/H and A/H^2 the stress-strain quantities), searched over
** B/H in (0, 1). */
static unsigned law_blocked_for(const cf_fit_report *r, const cf_fit_result *g, cf_spring_type t)
{
    const cf_fit_options *o = &r->fit_options;
    const cf_ident_design d = {o->lower[CF_P_N], o->upper[CF_P_N], o->upper[CF_P_G],
                               o->D2_over_H_max, o->index_max, o->rho_min};
    const int fd = cf_table_is_force(r->table);
    const cf_ident gi = cf_fit_family(g, fd);
    const double rho = gi.rho, B = gi.solid, A = gi.scale;
    double best = INFINITY;
    unsigned bits = 0;
    const int steps = fd ? 400 : 1;
    for (int k = 0; k < steps; k++) {
        /* a force table: B/H from 1e-4 to 1 - 1e-4, logarithmically in B/H and in 1 - B/H */
        const double q = (k + 0.5) / steps;
        const double Bs = fd ? (q < 0.5 ? 1e-4 * pow(0.5e4, 2 * q) : 1 - 1e-4 * pow(0.5e4, 2 * (1 - q)))
                             : B;
        const double H = fd ? B / Bs : 1, As = A / (H * H);
        const cf_ident_region reg = cf_ident_region_at(&d, t, rho, Bs, 0);
        if (reg.margin <= 0 && As <= reg.A_max * (1 + 1e-9))
            return 0;
        /* the nearest miss: outside the region by the least, or inside it with too large a load */
        const double miss = reg.margin > 0 ? reg.margin + 100 : log(As / reg.A_max);
        if (miss < best) {
            best = miss;
            bits = reg.margin > 0 ? reg.lo_bit | reg.hi_bit : CF_C_G_MAX;
        }
    }
    return bits;
}

void cf_report_nested(const cf_fit_report *r, const cf_fit_result *f, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    if (!f->tail || f->params.n_tail != 0)
        return;
    const double u = r->table->y_to_file;
    cf_report_append(buf, cap, &n, "no tail: the conical optimum the tailed law contains, since ");
    if (!(f->nested_rmse > 0)) {
        cf_report_append(buf, cap, &n, "the tailed search found no spring");
        return;
    }
    cf_report_append(buf, cap, &n, "the tailed spring its search ended on (RMSE %.4g %s) ",
                     f->nested_rmse * u, r->table->y_unit);
    const unsigned v = f->nested_violated;
    if (!v) {
        cf_report_append(buf, cap, &n, "fits worse");
        return;
    }
    cf_report_append(buf, cap, &n, "breaks the limit%s", (v & (v - 1)) ? "s" : "");
    for (int b = 0; b < CF_C_COUNT; b++)
        if (v & (1u << b))
            cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
}

/* The one sentence that compares the two types (both fitted, at least one feasible). */
void cf_report_verdict(const cf_fit_report *r, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    const cf_fit_verdict v = r->verdict;
    if (v.better < 0) {
        cf_report_append(buf, cap, &n, "no verdict: neither type has a spring inside its limits");
        return;
    }
    const cf_fit_result *g = &r->fits[v.better], *w = &r->fits[1 - v.better];
    double u = r->table->y_to_file;
    if (!w->feasible) {
        cf_report_append(buf, cap, &n,
                         "%s: the %s type has no spring inside its limits (violated:",
                         cf_spring_type_name(g->type), cf_spring_type_name(w->type));
        for (int b = 0; b < CF_C_COUNT; b++)
            if (w->violated & (1u << b))
                cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
        cf_report_append(buf, cap, &n, ")");
        return;
    }
    double base = g->objective > 0 ? g->objective : 1.0;
    if (v.tie) {
        cf_report_append(buf, cap, &n,
            "tie: the data do not tell the types apart (RMSE %.4g against %.4g %s; the residual "
            "sum of squares differs by %.3g of the better one's, below the F-test threshold "
            "%.3g at 95 %%)",
            r->fits[0].rmse * u, r->fits[1].rmse * u, r->table->y_unit, v.delta_rss / base,
            v.threshold / base);
        return;
    }
    cf_report_append(buf, cap, &n,
        "%s (RMSE %.4g against %.4g %s; the residual sum of squares of %s is higher by %.3g of "
        "the better one's, above the F-test threshold %.3g at 95 %%); ",
        cf_spring_type_name(g->type), g->rmse * u, w->rmse * u, r->table->y_unit,
        cf_spring_type_name(w->type), v.delta_rss / base, v.threshold / base);
    const cf_law_choice *lw = &r->law_choice[1 - v.better];
    unsigned blocked = 0;
    const cf_law_row *gk = cf_fit_kind_of(g), *wk = cf_fit_kind_of(w);
    const cf_fit_result *wt = NULL; /* the worse type's fit of the better one's kind */
    for (int j = 0; lw->ran && j < lw->n; j++)
        if (cf_fit_kind_of(&lw->cand[j]) == gk)
            wt = &lw->cand[j];
    if (wt && wk != gk) {
        /* the law choice decided: the better type keeps one kind, the other another */
        cf_report_append(buf, cap, &n, "%s keeps the %s law (the better one the %s law): its "
                                       "%s fit ",
                         cf_spring_type_name(w->type), wk->name, gk->name, gk->name);
        /* its spring of that kind broke limits: infeasible, or held at no tail by them (tail.h,
        ** cf_tail_nest) */
        const unsigned lim = !wt->feasible           ? wt->violated
                             : wt->params.n_tail == 0 ? wt->nested_violated
                                                      : 0;
        if (lim) {
            cf_report_append(buf, cap, &n, "is excluded by the limit%s",
                             (lim & (lim - 1)) ? "s" : "");
            for (int b = 0; b < CF_C_COUNT; b++)
                if (lim & (1u << b))
                    cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
        } else {
            cf_report_append(buf, cap, &n, "does not lower its AIC");
        }
        if (w->held) {
            cf_report_append(buf, cap, &n, "; its %s fit is held by", wk->name);
            for (int b = 0; b < CF_C_COUNT; b++)
                if (w->held & (1u << b))
                    cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
        }
    } else if (v.held) {
        cf_report_append(buf, cap, &n, "%s is held back by", cf_spring_type_name(w->type));
        for (int b = 0; b < CF_C_COUNT; b++)
            if (v.held & (1u << b))
                cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
    } else if (g->tail == w->tail && !g->tail && (blocked = law_blocked_for(r, g, w->type))) {
        /* no limit holds the worse fit where it ended, but the better one's law is no spring of
        ** the worse type: the limits there decide */
        cf_report_append(buf, cap, &n,
                         "no limit of %s is active where its fit ended, but the law %s fits "
                         "(rho %.4g) is no %s spring within the limit%s",
                         cf_spring_type_name(w->type), cf_spring_type_name(g->type),
                         cf_fit_family(g, cf_table_is_force(r->table)).rho,
                         cf_spring_type_name(w->type),
                         (blocked & (blocked - 1)) ? "s" : "");
        for (int b = 0; b < CF_C_COUNT; b++)
            if (blocked & (1u << b))
                cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
    } else {
        cf_report_append(buf, cap, &n,
                         "no limit of %s is active: its optimiser stopped at a worse point",
                         cf_spring_type_name(w->type));
    }
}

/* Where one measure came from, in words: "comment, line 12", "column name", "assumed", ... */
static void source_text(char *buf, size_t cap, cf_decl_source from, size_t line, int overridden,
                        const char *file_value)
{
    size_t n = 0;
    buf[0] = '\0';
    cf_report_append(buf, cap, &n, "%s", cf_decl_source_name(from));
    if (overridden)
        cf_report_append(buf, cap, &n, ", which wins over the table's '%s'", file_value);
    if (line)
        cf_report_append(buf, cap, &n, "%sline %zu", overridden ? " on " : ", ", line);
}

/* The sources of a table's measures (stress, strain) and its mode. */
void cf_report_sources(const cf_table *t, char src[3][128])
{
    const cf_table_measures *m = &t->measures;
    source_text(src[0], sizeof src[0], m->stress_from, m->stress_line, m->stress_overridden,
                cf_stress_measure_name((cf_stress_measure)m->stress_file));
    source_text(src[1], sizeof src[1], m->strain_from, m->strain_line, m->strain_overridden,
                cf_strain_measure_name((cf_strain_measure)m->strain_file));
    snprintf(src[2], sizeof src[2], "%s", t->mode_stated ? "stated" : "assumed");
}

/* What was done to the stress and strain columns, in one sentence ("" when nothing). */
void cf_report_conversion(const cf_table *t, char *buf, size_t cap)
{
    const cf_table_measures *m = &t->measures;
    size_t n = 0;
    buf[0] = '\0';
    if (m->strain_converted)
        cf_report_append(buf, cap, &n, "%s",
                         m->strain == CF_STRAIN_LOG
                             ? "log strain e converted to engineering strain exp(e) - 1"
                             : "stretch l converted to engineering strain l - 1");
    if (m->stress_converted) {
        cf_report_append(buf, cap, &n, "%sCauchy stress converted to nominal ", n ? "; " : "");
        cf_report_append(buf, cap, &n, "%s", cf_mode_row_of(t->mode)->cauchy_words);
    }
}

/* Most significant digits an interval is shown with: an end closer to the value than this
** shows (a bound the fit sits on, or one a rounding step away) is shown as the value itself. */
#define INTERVAL_MAX_DIGITS 6

/* 1 when end e of an interval about v is v as far as INTERVAL_MAX_DIGITS digits show. */
static int end_is_value(double v, double e)
{
    return fabs(e - v) <= 0.5 * pow(10.0, -INTERVAL_MAX_DIGITS) * fabs(v);
}

/* Significant digits that tell the ends of the interval [lo, hi] from the value v: 3, or more
** when an end lies closer to v than 3 digits show (a precise or long table), at most
** INTERVAL_MAX_DIGITS; ends that are the value (end_is_value) do not count. */
static int interval_digits(double v, double lo, double hi)
{
    double w = INFINITY;
    if (v - lo > 0 && !end_is_value(v, lo))
        w = v - lo;
    if (hi - v > 0 && !end_is_value(v, hi))
        w = fmin(w, hi - v);
    if (!(v != 0) || !isfinite(w))
        return 3;
    double d = floor(log10(fabs(v))) - floor(log10(w)) + 1;
    return (int)fmin(INTERVAL_MAX_DIGITS, fmax(3, d));
}

/* x to `digits` significant digits, rounded away from the value (down for a lower end, dir -1;
** up for an upper end, dir +1), so that the printed interval holds the interval. */
static void outward(char *buf, size_t cap, double x, int digits, int dir)
{
    if (x == 0 || !isfinite(x)) {
        snprintf(buf, cap, "%.*g", digits, x);
        return;
    }
    const double step = pow(10.0, floor(log10(fabs(x))) - digits + 1);
    const double r = (dir < 0 ? floor(x / step) : ceil(x / step)) * step;
    snprintf(buf, cap, "%.*g", digits, r);
}

/* The cell "v [lo, hi]" of an interval: v with at least 4 digits, the ends rounded outward; an end
** that is the value, or that would print past it, printed as the value, so that the printed
** interval always holds the printed value. */
static void interval_text(double v, double lo, double hi, char *cell, size_t cap, const char *sp,
                          const char *unit)
{
    const int dg = interval_digits(v, lo, hi);
    char tv[40], tl[40], th[40];
    snprintf(tv, sizeof tv, "%.*g", dg > 4 ? dg : 4, v);
    const double pv = strtod(tv, NULL);
    outward(tl, sizeof tl, lo, dg, -1);
    outward(th, sizeof th, hi, dg, +1);
    if (end_is_value(v, lo) || strtod(tl, NULL) > pv)
        snprintf(tl, sizeof tl, "%s", tv);
    if (end_is_value(v, hi) || strtod(th, NULL) < pv)
        snprintf(th, sizeof th, "%s", tv);
    snprintf(cell, cap, "%s [%s, %s]*%s%s", tv, tl, th, sp, unit);
}

void cf_report_ident_cell(const cf_fit_result *f, int k, double scale, const char *unit,
                          char *cell, size_t cap)
{
    const char *sp = *unit ? " " : "";
    double q, se;
    const double *iv;
    const unsigned *ends;
    unsigned why;
    if (quantity(f, k, &q, &se, &iv, &ends, &why)) {
        interval_text(q * scale, iv[0] * scale, iv[1] * scale, cell, cap, sp, unit);
    } else if (f->tail && se > fabs(q)) {
        /* the tailed law's four quantities traded against each other by the data */
        snprintf(cell, cap, "%.4g%s%s (not determined)", q * scale, sp, unit);
    } else if (se >= 0) {
        snprintf(cell, cap, "%.6g ± %.2g%s%s", q * scale, se * scale, sp, unit);
    } else if (k == CF_REPORT_TAIL) {
        snprintf(cell, cap, "%.6g%s%s (error not determined)", q * scale, sp, unit);
    } else { /* the uncertainty code computes an interval wherever the error is undetermined */
        snprintf(cell, cap, "%.6g%s%s (no error: not determined)", q * scale, sp, unit);
    }
}

const char *cf_report_why(const char *note, const char *fallback)
{
    return note && note[0] ? note : fallback;
}

const char *cf_report_strain_name(const cf_table *t, char src[3][128])
{
    if (!cf_mode_row_of(t->mode)->any_sign)
        return cf_strain_measure_name(t->measures.strain);
    snprintf(src[1], sizeof src[1], "simple shear: the amount of shear, either sign");
    return "shear strain gamma";
}

const char *cf_report_mode_dropped(const cf_table *t)
{
    if (!cf_table_is_force(t) || !t->mode_stated || cf_mode_row_of(t->mode)->spring_curve)
        return NULL;
    return "a force-displacement table is one spring's force against its displacement: it is "
           "fitted as that spring along its axis, not as a test of a block of tissue in this mode "
           "(give stress against strain to fit the mode)";
}
