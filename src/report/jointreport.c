/*
** Text, fit file and figure of a joint fit (see jointreport.h).
*/
#include "report/jointreport.h"
#include "model/mode.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "base/atomic.h"
#include "conifit/version.h"
#include "io/fitfile_json.h"
#include "fit/lawkind.h"
#include "report/gnuplot.h"
#include "report/report_fibre.h"
#include "report/report_baselines.h"
#include "report/report_json.h"
#include "report/report_notes.h"
#include "report/report_words.h"

void cf_joint_report_free(cf_joint_report *r)
{
    if (!r)
        return;
    for (int k = 0; k < 2; k++) {
        cf_joint_free(&r->fits[k]);
        cf_joint_free(&r->law_choice[k].other);
        cf_joint_free(&r->law_choice[k].pair_other);
    }
}

/* A lattice stable at rest before one that is not (it models no solid at all), then a spring that
** can be built before one that cannot, then a lattice stable over every table's range, then a
** cell strongly elliptic over every range within CF_JOINT_ELLIPTIC_SLACK of the objective
** (cf_joint_elliptic_wins), then the lower objective: a tie of the two types' laws (both tailed fits reach the same one) must not
** hand the user the infeasible spring. */
int cf_joint_better(const cf_joint_report *r)
{
    int b = -1;
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_result *fi_ = &r->fits[i], *fb_ = b >= 0 ? &r->fits[b] : NULL;
        const int ri = cf_joint_stable_at_rest(fi_), rb = fb_ && cf_joint_stable_at_rest(fb_);
        const int fi = fi_->fit.feasible != 0, si = cf_joint_stable(fi_);
        const int fb = fb_ && fb_->fit.feasible != 0, sb = fb_ && cf_joint_stable(fb_);
        /* between buildable, stable lattices, a cell that stays strongly elliptic first when
        ** its objective is close enough (cf_joint_elliptic_wins) */
        const int ei = fb_ && cf_joint_elliptic_wins(fi_, fb_);
        const int eb = fb_ && cf_joint_elliptic_wins(fb_, fi_);
        if (b < 0 || (ri != rb   ? ri
                      : fi != fb ? fi
                      : si != sb ? si
                      : ei != eb ? ei
                                 : fi_->objective < fb_->objective))
            b = i;
    }
    return b;
}

/* The conical and the tailed joint fit of type i, whichever was kept. */
static void both_laws(const cf_joint_report *r, int i, const cf_joint_result **cone,
                      const cf_joint_result **tail)
{
    const cf_joint_law_choice *lc = &r->law_choice[i];
    /* a kept double-acting element displaced the single-sided law kept (pair_other) */
    const cf_joint_result *kept = lc->chose_pair ? &lc->pair_other : &r->fits[i];
    *tail = lc->chose_tail ? kept : &lc->other;
    *cone = lc->chose_tail ? &lc->other : kept;
}

/* A tailed joint fit that is the conical optimum it contains (cf_joint_fit_tail): why, into buf
** (empty when it has its tail). */
static void joint_nested(const cf_joint_result *tail, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    if (!tail->fit.tail || tail->fit.params.n_tail != 0)
        return;
    cf_report_append(buf, cap, &n, "no tail: the conical optimum the tailed law contains, since ");
    if (!(tail->nested_objective > 0)) {
        cf_report_append(buf, cap, &n, "the tailed search found no spring running every table");
        return;
    }
    cf_report_append(buf, cap, &n, "the tailed spring its search ended on (objective %.4g) ",
                     tail->nested_objective);
    const unsigned v = tail->fit.nested_violated;
    if (!v) {
        cf_report_append(buf, cap, &n, "fits worse");
        return;
    }
    cf_report_append(buf, cap, &n, "breaks the limit%s", (v & (v - 1)) ? "s" : "");
    for (int b = 0; b < CF_C_COUNT; b++)
        if (v & (1u << b))
            cf_report_append(buf, cap, &n, " %s", cf_fit_constraint_name(1u << b));
}

static const char *weighting_text =
    "each table's residuals divided by its RMS stress and by the square root of its number of "
    "rows, so every table counts once whatever its stress scale and length";

/* Both laws of each type, when the fit asked for the tailed one: the joint AIC, the weighted
** objective, feasibility and each table's RMSE and AIC, and the law kept. */
static void law_choice_text(FILE *o, const cf_joint_report *r)
{
    if (r->law == CF_KIND_CONICAL || r->law == CF_KIND_DOUBLE ||
        (r->nfits > 0 && r->fits[0].volume != CF_VOLUME_NONE && !r->law_choice[0].ran))
        return;
    size_t rows = 0;
    for (size_t k = 0; k < r->ntables; k++)
        rows += r->tables[k]->count;
    fprintf(o, "\nLaw (--law %s): the conical law (3 quantities) against the conical spring with "
               "a cylindrical tail (4), both fitted jointly through the lattice; joint AIC = N "
               "ln(objective/N) + 2k over the N = %zu rows\n",
            cf_law_kind_name(r->law), rows);
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_law_choice *lc = &r->law_choice[i];
        const char *type = cf_spring_type_name(r->fits[i].fit.type);
        if (!lc->ran) {
            fprintf(o, "  %-16s no conical-tail law runs every table: conical kept\n", type);
            continue;
        }
        const cf_joint_result *cone, *tail;
        both_laws(r, i, &cone, &tail);
        const cf_joint_result *law[2] = {cone, tail};
        static const char *const lname[2] = {"conical", "conical-tail"};
        for (int l = 0; l < 2; l++) {
            fprintf(o, "  %-16s %-12s joint AIC %.2f, objective %.4g%s\n", l ? "" : type,
                    lname[l], law[l]->aic, law[l]->objective,
                    law[l]->fit.feasible ? "" : " (infeasible)");
            for (size_t k = 0; k < r->ntables; k++) {
                const cf_table *t = r->tables[k];
                fprintf(o, "  %-16s %-12s   %s: RMSE %.4g %s, AIC %.2f\n", "", "", t->path,
                        law[l]->tab[k].cell_rmse * t->y_to_file, t->y_unit, law[l]->tab[k].aic);
            }
        }
        char nested[320];
        joint_nested(tail, nested, sizeof nested);
        if (nested[0])
            fprintf(o, "  %-16s %s\n", "", nested);
        const char *why = r->law == CF_KIND_TAIL ? "asked for (--law conical-tail)"
                          : nested[0]              ? "the tailed law's fit is the conical one"
                          : lc->chose_tail         ? "lower joint AIC"
                          : !tail->fit.feasible    ? "the tailed spring is infeasible"
                                                   : "the tail does not lower the joint AIC";
        fprintf(o, "  %-16s kept: %s (%s)\n", "", lc->chose_tail ? "conical-tail" : "conical",
                why);
    }
}

/* The double-acting element against the single-sided law of each type (double-acting, auto). */
static void pair_choice_text(FILE *o, const cf_joint_report *r)
{
    if (r->law != CF_KIND_DOUBLE && r->law != CF_KIND_AUTO)
        return;
    fprintf(o, "\nDouble-acting element (--law %s): its own conical spring for extension (6 "
               "quantities, 7 with a fitted kappa, one more with a tailed compression spring) "
               "against the single-sided law kept above\n",
            cf_law_kind_name(r->law));
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_law_choice *lc = &r->law_choice[i];
        const char *type = cf_spring_type_name(r->fits[i].fit.type);
        if (!lc->pair_ran) {
            fprintf(o, "  %-16s %s%s\n", type,
                    r->fits[i].volume == CF_VOLUME_POISSON
                        ? "not fitted: a declared nu (--poisson) has no meaning for a pair's two "
                          "sides"
                    : lc->pair_refused[0] ? "not fitted: "
                                          : "no double-acting element runs every table",
                    r->fits[i].volume != CF_VOLUME_POISSON ? lc->pair_refused : "");
            continue;
        }
        const cf_joint_result *pair = lc->chose_pair ? &r->fits[i] : &lc->pair_other;
        const cf_joint_result *single = lc->chose_pair ? &lc->pair_other : &r->fits[i];
        const cf_joint_result *law[2] = {single, pair};
        static const char *const lname[2] = {"single-sided", "double-acting"};
        for (int l = 0; l < 2; l++)
            fprintf(o, "  %-16s %-13s joint AIC %.2f, objective %.4g (%d quantities)%s\n",
                    l ? "" : type, lname[l], law[l]->aic, law[l]->objective, law[l]->nparams,
                    law[l]->fit.feasible ? "" : " (infeasible)");
        if (pair->nested_objective > 0) {
            const unsigned v = pair->fit.nested_violated;
            if (!v)
                fprintf(o, "  %-16s two equal springs: the single-sided law's optimum the pair "
                           "contains, since the pair its search ended on (objective %.4g) ranks "
                           "below it",
                        "", pair->nested_objective);
            else
                fprintf(o, "  %-16s two equal springs: the single-sided law's optimum the pair "
                           "contains, since the pair its search ended on (objective %.4g) breaks "
                           "the limit%s",
                        "", pair->nested_objective, (v & (v - 1)) ? "s" : "");
            for (int b = 0; b < CF_C_COUNT; b++)
                if (v & (1u << b))
                    fprintf(o, " %s", cf_fit_constraint_name(1u << b));
            fputc('\n', o);
        }
        const char *why = r->law == CF_KIND_DOUBLE ? "asked for (--law double-acting)"
                          : lc->chose_pair && cf_joint_elliptic_wins(pair, single)
                              ? "its cell stays strongly elliptic, the single-sided law's not"
                          : lc->chose_pair      ? "lower joint AIC"
                          : !pair->fit.feasible ? "a spring of the pair is infeasible"
                          : cf_joint_elliptic_wins(single, pair)
                              ? "the pair's cell loses strong ellipticity inside a table's range"
                          : !cf_joint_stable(pair) && pair->aic < single->aic
                              ? "the pair's lattice loses stability inside a table's range"
                              : "the pair does not lower the joint AIC";
        fprintf(o, "  %-16s kept: %s (%s)\n", "", lc->chose_pair ? "double-acting" : "single-sided",
                why);
        if (lc->pair_tail_ran)
            fprintf(o, "  %-16s the pair's compression spring %s: %s (the %s one: objective "
                       "%.4g, joint AIC %.2f, %d quantities%s%s)\n",
                    "", lc->pair_tail_kept ? "with a tail" : "conical",
                    lc->pair_tail_kept ? "kept (buildable first, then stable over every "
                                         "table's range, then strongly elliptic within 1.1x "
                                         "the objective, then the lower joint AIC)"
                                       : "kept (the tailed one is not buildable, stable or "
                                         "lower in joint AIC before it)",
                    lc->pair_tail_kept ? "conical" : "tailed", lc->alt_objective, lc->alt_aic,
                    lc->alt_nparams, lc->alt_feasible ? "" : ", infeasible",
                    lc->alt_stable ? "" : ", its lattice loses stability inside a table's range");
    }
}

/* A quantity with its standard error, or "(not determined by the data)". */
static void value_se(char *buf, size_t cap, double v, double se, double scale, const char *unit)
{
    if (se >= 0)
        snprintf(buf, cap, "%.6g ± %.2g%s%s", v * scale, se * scale, unit[0] ? " " : "", unit);
    else
        snprintf(buf, cap, "%.6g%s%s (not determined by the data)", v * scale,
                 unit[0] ? " " : "", unit);
}

/* CF_JOINT_NU_MAX (joint.h) as the report states it */
#define NU_MAX_TEXT "0.499"

static const char *volume_how(cf_volume v)
{
    switch (v) {
    case CF_VOLUME_FIT: return "fitted";
    case CF_VOLUME_MODULUS: return "declared";
    case CF_VOLUME_POISSON: return "from the declared nu";
    default: return "none";
    }
}

/* The double-acting element's extension spring and the volume term of fit j, when it has them. */
static void pair_volume_text(FILE *o, const cf_joint_result *j)
{
    if (j->pair) {
        char sp[160], q[3][96];
        fprintf(o, " double-acting element: the spring above closes under compression; its "
                   "extension spring (the same H) closes under extension:\n  %s%s\n",
                cf_spring_text(&j->ext.params, 5, 0, sp, sizeof sp),
                j->ext.feasible ? "" : " (violates its constraints)");
        value_se(q[0], sizeof q[0], j->ext.ident.rho, j->ext.ident_se.rho, 1, "");
        value_se(q[1], sizeof q[1], j->ext.ident.solid, j->ext.ident_se.solid, 1, "");
        value_se(q[2], sizeof q[2], j->ext.ident.scale, j->ext.ident_se.scale, 1e3, "kPa");
        fprintf(o, "  extension: rho %s, solid strain s/H %s, stress scale F_C/H^2 %s\n", q[0],
                q[1], q[2]);
    }
    if (j->volume != CF_VOLUME_NONE) {
        char k[96];
        value_se(k, sizeof k, j->volume_modulus_MPa,
                 j->volume == CF_VOLUME_FIT ? j->volume_modulus_se : 0, 1e3, "kPa");
        if (j->volume != CF_VOLUME_FIT)
            snprintf(k, sizeof k, "%.6g kPa", j->volume_modulus_MPa * 1e3);
        if (!j->pair && j->volume == CF_VOLUME_FIT && j->volume_modulus_MPa == 0 &&
            j->nested_objective > 0)
            fprintf(o, " volume term: kappa 0, the law without it, which the fit contains, ranks "
                       "above what its search ended on (objective %.4g)\n",
                    j->nested_objective);
        fprintf(o, " volume term (kappa/2)(J - 1)^2 per cell: kappa %s (%s%s)\n", k,
                volume_how(j->volume),
                j->volume == CF_VOLUME_FIT ? ", at most the kappa of small-strain nu " NU_MAX_TEXT
                                             " in the compression spring's lattice"
                                           : "");
    }
    if (j->pair || j->volume != CF_VOLUME_NONE)
        fprintf(o, " small strain, along an axis: compression E %.4g kPa, nu %.4f; extension E "
                   "%.4g kPa, nu %.4f\n",
                j->E_compression_MPa * 1e3, j->nu_compression, j->E_extension_MPa * 1e3,
                j->nu_extension);
}

/* Whether the lattice of a pair or a volume term stays stable over every table's range. */
static void stability_text(FILE *o, const cf_joint_report *r, const cf_joint_result *j)
{
    int checked = 0, all = 1;
    for (size_t k = 0; k < r->ntables; k++) {
        const cf_joint_table *jt = &j->tab[k];
        checked += jt->stability_checked;
        if (jt->stability_checked && !jt->stable_in_range) {
            all = 0;
            if (jt->unstable_at_rest)
                fprintf(o, "  %s: the lattice is unstable at rest (strain 0): it models no "
                           "solid\n",
                        r->tables[k]->path);
            else
                fprintf(o, "  %s: the lattice loses stability at strain %.4g, inside %.2fx the "
                           "table's range\n",
                        r->tables[k]->path, jt->stable_to, CF_JOINT_STABLE_MARGIN);
        }
    }
    if (checked == (int)r->ntables && all)
        fprintf(o, "  stable over every table's range with a margin (the cell's incremental "
                   "stiffness positive definite and, for a uniaxial table, the full lattices of "
                   "2^3 and 3^3 cells free of negative pivots, at 8 strains from 0 to %.2fx each "
                   "table's farthest strain: the search's own check%s)\n",
                CF_JOINT_STABLE_MARGIN,
                j->volume_modulus_MPa > 0 ? "; the lattices with their cells' default hourglass "
                                            "control, which a scene's lattice.hourglass 0 turns off"
                                          : "");
    /* what the search tried */
    fprintf(o, "  search: %d starts, %d stable end%s, %d stable point%s projected from unstable "
               "ends, %d restart%s kept to lattices stable to %.2fx each table's farthest "
               "strain\n",
            j->starts, j->stable_ends, j->stable_ends == 1 ? "" : "s", j->projected,
            j->projected == 1 ? "" : "s", j->restarts, j->restarts == 1 ? "" : "s",
            CF_JOINT_STABLE_MARGIN);
}

/* Whether the homogenised cell stays strongly elliptic over each table's range. */
static void elliptic_text(FILE *o, const cf_joint_report *r, const cf_joint_result *j)
{
    for (size_t k = 0; k < r->ntables; k++) {
        const cf_joint_table *jt = &j->tab[k];
        if (!jt->elliptic_checked)
            continue;
        if (jt->elliptic_in_range) {
            fprintf(o, "  %s: strongly elliptic to %.2fx the table's range (the homogenised "
                       "cell's acoustic tensor positive definite in every direction)\n",
                    r->tables[k]->path, CF_JOINT_STABLE_MARGIN);
        } else if (jt->elliptic_n[0] == 0 && jt->elliptic_n[1] == 0 && jt->elliptic_n[2] == 0) {
            fprintf(o, "  %s: strong ellipticity checked to strain %.4g only (the mode goes no "
                       "further)\n",
                    r->tables[k]->path, jt->elliptic_to);
        } else {
            fprintf(o, "  %s: loses strong ellipticity at strain %.4g, inside %.2fx the table's "
                       "range (acoustic tensor singular for direction n = (%.3f, %.3f, %.3f)): "
                       "the bulk material may localise in bands there\n",
                    r->tables[k]->path, jt->elliptic_to, CF_JOINT_STABLE_MARGIN,
                    jt->elliptic_n[0], jt->elliptic_n[1], jt->elliptic_n[2]);
        }
    }
}

/* The better type and the reason that decided it. */
static void better_text(FILE *o, const cf_joint_report *r)
{
    const int b = cf_joint_better(r);
    if (b >= 0) {
        /* the reason that decided: buildability when only one spring can be built */
        int other_infeasible = 0, other_unstable = 0, other_nonelliptic = 0;
        for (int i = 0; i < r->nfits; i++) {
            const cf_joint_result *fi = &r->fits[i], *fb = &r->fits[b];
            other_infeasible |= i != b && !fi->fit.feasible && fb->fit.feasible;
            other_unstable |= i != b && fi->fit.feasible && !cf_joint_stable(fi) &&
                              cf_joint_stable(fb) && fi->objective < fb->objective;
            other_nonelliptic |= i != b && cf_joint_elliptic_wins(fb, fi) &&
                                 fi->objective < fb->objective;
        }
        fprintf(o, "\nBetter type: %s (%s %.4g)\n", cf_spring_type_name(r->fits[b].fit.type),
                other_infeasible ? "the other type's spring cannot be built; weighted objective"
                : other_unstable ? "the other type's lattice loses stability inside a table's "
                                   "range; weighted objective"
                : other_nonelliptic ? "the other type's cell loses strong ellipticity inside a "
                                      "table's range; weighted objective"
                                    : "lower weighted objective",
                r->fits[b].objective);
    }
}

char *cf_joint_text(const cf_joint_report *r)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *o = open_memstream(&buf, &len);
    if (!o)
        return NULL;
    if (r->ntables == 1) /* a double-acting element of one table goes by the joint fit */
        fprintf(o, "Fit through the lattice of one table, by the joint fit (its residuals divided "
                   "by its RMS stress and by the square root of its number of rows)\n");
    else
        fprintf(o, "Joint fit through the lattice of %zu tables (%s)\n", r->ntables,
                weighting_text);
    for (size_t k = 0; k < r->ntables; k++)
        if (r->tables[k]->notes[0]) {
            fprintf(o, " %s:\n", r->tables[k]->path);
            cf_report_notes_text(o, r->tables[k], "  ");
        }
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_result *j = &r->fits[i];
        const cf_spring *p = &j->fit.params;
        cf_cubic_moduli cm = cf_cubic_moduli_of(j->weight);
        char sp[160];
        fprintf(o, "\n%s spring: %s%s\n", cf_spring_type_name(j->fit.type),
                cf_spring_text(p, 5, 0, sp, sizeof sp),
                j->fit.feasible ? "" : " (violates its constraints)");
        char q[3][96];
        cf_report_ident_cell(&j->fit, 0, 1, "", q[0], sizeof q[0]);
        cf_report_ident_cell(&j->fit, 1, 1, "", q[1], sizeof q[1]);
        cf_report_ident_cell(&j->fit, 2, 1e3, "kPa", q[2], sizeof q[2]);
        fprintf(o, " lattice: rho %s, solid strain s/H %s, stress scale F_C/H^2 %s; "
                   "calibration %s (weights edge %.4g, face %.4g, body %.4g; nu %.3f; "
                   "springs' anisotropy 2 C44/(C11 - C12) %.3f, 1 isotropic",
                q[0], q[1], q[2], cf_calibration_name(j->calibration), j->weight[0],
                j->weight[1], j->weight[2], cm.nu, cm.zener);
        if (j->anisotropy_max > 0)
            fprintf(o, ", held within 1 +- %g", j->anisotropy_max);
        fputs(")\n", o);
        const cf_law_row *row = cf_fit_kind_of(&j->fit);
        for (int k = 0; k < row->nq; k++)
            if (j->fit.interval_ok[k]) {
                char why[512];
                cf_report_interval_reason(&j->fit, k, why, sizeof why);
                fprintf(o, "  * %s: %s\n", row->q[k].name, why);
            }
        if (j->fit.tail) {
            char et[96];
            cf_report_ident_cell(&j->fit, CF_REPORT_TAIL, 1, "", et, sizeof et);
            fprintf(o, "  tail compliance e_t %s\n", et);
        }
        if (isfinite(j->fit.corr[0][1]))
            fprintf(o, "  correlation rho-s %.3f, rho-A %.3f, s-A %.3f (the weights held)\n",
                    j->fit.corr[0][1], j->fit.corr[0][2], j->fit.corr[1][2]);
        pair_volume_text(o, j);
        fprintf(o, "  %-44s %-12s %6s %14s %14s %14s\n", "table", "mode", "points", "fit RMSE",
                "lattice RMSE", "vs law");
        for (size_t k = 0; k < r->ntables; k++) {
            const cf_table *t = r->tables[k];
            const cf_joint_table *jt = &j->tab[k];
            double u = t->y_to_file;
            char a[32], b[32], c[32];
            snprintf(a, sizeof a, "%.4g %s", jt->cell_rmse * u, t->y_unit);
            snprintf(b, sizeof b, "%.4g %s%s", jt->lattice_rmse * u, t->y_unit,
                     jt->by_cell ? "*" : "");
            if (isfinite(jt->law_rmse))
                snprintf(c, sizeof c, "%.4g %s", jt->law_rmse * u, t->y_unit);
            else
                snprintf(c, sizeof c, "-");
            fprintf(o, "  %-44s %-12s %6zu %14s %14s %14s\n", t->path, cf_mode_name(jt->mode),
                    jt->points, a, b, c);
        }
        stability_text(o, r, j);
        elliptic_text(o, r, j);
        fprintf(o, "  (* homogenised cell: the full lattice has no such boundary conditions; "
                   "%ld cell curves, %.3f s)\n",
                j->evaluations, j->wall_time_s);
    }
    law_choice_text(o, r);
    pair_choice_text(o, r);
    better_text(o, r);
    cf_report_ho_text(o, r, cf_joint_better(r));
    cf_report_fibre_text(o, r);
    if (fclose(o) != 0) {
        free(buf);
        return NULL;
    }
    return buf;
}

static json_t *num(double v)
{
    return cf_json_number(v);
}

/* One law's joint fit in the comparison: its joint AIC, objective, feasibility and each table's
** RMSE and AIC. */
static json_t *law_json(const cf_joint_report *r, const cf_joint_result *j)
{
    json_t *per = json_array();
    for (size_t k = 0; per && k < r->ntables; k++) {
        const cf_table *t = r->tables[k];
        json_array_append_new(per, json_pack("{s:s, s:s, s:o, s:o}", "file", t->path, "unit",
                                             t->y_unit, "rmse",
                                             num(j->tab[k].cell_rmse * t->y_to_file), "aic",
                                             num(j->tab[k].aic)));
    }
    json_t *o = json_pack("{s:o, s:o, s:b, s:o}", "aic", num(j->aic), "objective",
                          num(j->objective), "feasible", j->fit.feasible, "tables",
                          per ? per : json_array());
    if (o && j->fit.tail)
        json_object_set_new(o, "tail_compliance", cf_report_ident_json(&j->fit, CF_Q_TAIL));
    char nested[320];
    joint_nested(j, nested, sizeof nested);
    if (o && nested[0])
        json_object_set_new(o, "no_tail", json_string(nested));
    return o;
}

/* Both laws of type i as a single fit's law_comparison states them, through_lattice and joint
** true (their RMSE and AIC the cell's, the AIC the joint one over every row). */
static json_t *law_comparison_json(const cf_joint_report *r, int i)
{
    const cf_joint_result *cone, *tail;
    both_laws(r, i, &cone, &tail);
    return json_pack("{s:s, s:b, s:b, s:o, s:o}", "chosen",
                     r->law_choice[i].chose_tail ? "conical-tail" : "conical", "through_lattice",
                     1, "joint", 1, "conical", law_json(r, cone), "conical-tail",
                     law_json(r, tail));
}

/* A quantity and its standard error as the fit file states them: {value, stderr} or {value,
** determined: false}. */
static json_t *ident_json(double v, double se)
{
    return se >= 0 ? json_pack("{s:o, s:o}", "value", num(v), "stderr", num(se))
                   : json_pack("{s:o, s:b}", "value", num(v), "determined", 0);
}

/* The extension spring of a double-acting element: params_extension (its six parameters, H the
** compression spring's), derived_extension, identifiable_extension, feasible_extension. */
static void pair_json(json_t *f, const cf_joint_result *j)
{
    cf_law le;
    if (cf_law_init(&le, &j->ext.params, NULL) != CF_OK)
        return;
    json_t *e = cf_fitfile_spring_json(&le);
    if (e) {
        json_object_set(f, "params_extension", json_object_get(e, "params"));
        json_object_set(f, "derived_extension", json_object_get(e, "derived"));
        json_object_set(f, "type_extension", json_object_get(e, "type"));
        json_decref(e);
    }
    json_object_set_new(f, "identifiable_extension",
                        json_pack("{s:o, s:o, s:o}", "rho",
                                  ident_json(j->ext.ident.rho, j->ext.ident_se.rho),
                                  "solid_strain",
                                  ident_json(j->ext.ident.solid, j->ext.ident_se.solid),
                                  "stress_scale_MPa",
                                  ident_json(j->ext.ident.scale, j->ext.ident_se.scale)));
    json_object_set_new(f, "feasible_extension", json_boolean(j->ext.feasible));
    /* two equal springs in place of an infeasible pair (cf_joint_fit_pair): what its search
    ** ended on */
    if (j->nested_objective > 0) {
        json_t *bits = json_array();
        for (int b = 0; bits && b < CF_C_COUNT; b++)
            if (j->fit.nested_violated & (1u << b))
                json_array_append_new(bits, json_string(cf_fit_constraint_name(1u << b)));
        json_object_set_new(f, "equal_springs",
                            json_pack("{s:o, s:o}", "search_objective", num(j->nested_objective),
                                      "search_violated", bits ? bits : json_array()));
    }
}

/* The lattice's volume term and its small-strain moduli each side, into its `lattice` object. */
static void volume_json(json_t *lat, const cf_joint_result *j)
{
    if (!lat)
        return;
    json_object_set_new(lat, "volume_modulus_MPa", num(j->volume_modulus_MPa));
    if (j->volume == CF_VOLUME_FIT)
        json_object_set_new(lat, "volume_modulus",
                            ident_json(j->volume_modulus_MPa, j->volume_modulus_se));
    json_object_set_new(lat, "volume_term", json_string(volume_how(j->volume)));
    json_object_set_new(lat, "poisson_ratio_compression", num(j->nu_compression));
    json_object_set_new(lat, "poisson_ratio_extension", num(j->nu_extension));
    json_object_set_new(lat, "modulus_compression_MPa", num(j->E_compression_MPa));
    json_object_set_new(lat, "modulus_extension_MPa", num(j->E_extension_MPa));
}

/* Fit j's numbers in each table: its RMSE in the cell and the lattice, AIC, the stability of
** its lattice and the strong ellipticity of its cell over the table's range. */
static json_t *tables_json(const cf_joint_report *r, const cf_joint_result *j)
{
    json_t *per = json_array();
    for (size_t k = 0; k < r->ntables; k++) {
        const cf_table *t = r->tables[k];
        const cf_joint_table *jt = &j->tab[k];
        double u = t->y_to_file;
        json_t *e = json_pack("{s:s, s:s, s:I, s:s, s:o, s:o, s:s, s:o}", "file", t->path,
                              "mode", cf_mode_name(jt->mode), "points",
                              (json_int_t)jt->points, "unit", t->y_unit, "rmse",
                              num(jt->cell_rmse * u), "lattice_rmse",
                              num(jt->lattice_rmse * u), "lattice_model",
                              jt->by_cell ? "homogenised cell" : "full lattice", "scale",
                              num(jt->scale_MPa * u));
        if (e)
            json_object_set_new(e, "aic", num(jt->aic));
        if (e && isfinite(jt->law_rmse)) /* uniaxial tables only */
            json_object_set_new(e, "law_difference_rmse", num(jt->law_rmse * u));
        if (e && jt->stability_checked) {
            json_object_set_new(e, "stable_in_range", json_boolean(jt->stable_in_range));
            json_object_set_new(e, "stable_to_strain", num(jt->stable_to));
        }
        if (e && jt->elliptic_checked) {
            json_object_set_new(e, "elliptic_in_range", json_boolean(jt->elliptic_in_range));
            json_object_set_new(e, "elliptic_to_strain", num(jt->elliptic_to));
            if (!jt->elliptic_in_range)
                json_object_set_new(e, "elliptic_lost_direction",
                                    json_pack("[o, o, o]", num(jt->elliptic_n[0]),
                                              num(jt->elliptic_n[1]), num(jt->elliptic_n[2])));
        }
        json_array_append_new(per, e);
    }
    return per;
}

static json_t *joint_json(const cf_joint_report *r)
{
    json_t *root = json_object(), *fits = json_array(), *tabs = json_array();
    if (!root || !fits || !tabs) {
        json_decref(root);
        json_decref(fits);
        json_decref(tabs);
        return NULL;
    }
    json_object_set_new(root, "conifit_version", json_string(CF_VERSION));
    json_object_set_new(root, "joint", json_true());
    json_object_set_new(root, "weighting", json_string(weighting_text));
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_result *j = &r->fits[i];
        cf_law law;
        if (cf_law_init(&law, &j->fit.params, NULL) != CF_OK)
            continue;
        json_t *f = cf_fitfile_spring_json(&law);
        if (!f)
            continue;
        cf_cubic_moduli cm = cf_cubic_moduli_of(j->weight);
        /* the compression spring's quantities (the pair's extension spring's: pair_json) */
        const cf_law_row *row = cf_fit_kind_of(&j->fit);
        const char *names[CF_Q_MAX];
        json_t *ident = json_object();
        for (int k = 0; k < row->nq; k++) {
            names[k] = row->q[k].key;
            json_object_set_new(ident, names[k], cf_report_ident_json(&j->fit, k));
        }
        json_object_set_new(f, "identifiable", ident);
        json_object_set_new(f, "law", json_string(j->pair ? cf_law_double_row.name : row->name));
        if (j->pair)
            pair_json(f, j);
        const cf_joint_law_choice *lc = &r->law_choice[i];
        if (j->pair && lc->pair_tail_ran) /* the pair's other compression spring */
            json_object_set_new(
                f, "pair_alternative",
                json_pack("{s:s, s:o, s:o, s:i, s:b, s:b}", "compression_law",
                          lc->pair_tail_kept ? "conical" : "conical-tail", "objective",
                          num(lc->alt_objective), "aic", num(lc->alt_aic), "quantities",
                          lc->alt_nparams, "feasible", lc->alt_feasible, "stable",
                          lc->alt_stable));
        if (lc->pair_refused[0]) /* auto: the data do not determine the pair */
            json_object_set_new(f, "pair_not_fitted", json_string(lc->pair_refused));
        json_object_set_new(f, "aic", num(j->aic));
        if (r->law_choice[i].ran)
            json_object_set_new(f, "law_comparison", law_comparison_json(r, i));
        json_object_set_new(f, "identifiable_correlation",
                            cf_report_correlation_json(&j->fit, names,
                                                       row->ncorr ? row->ncorr : row->nq));
        json_object_set_new(f, "target", json_pack("{s:s, s:s}", "model", "lattice", "mode",
                                                   "joint"));
        json_object_set_new(
            f, "lattice",
            json_pack("{s:s, s:{s:o, s:o, s:o}, s:o, s:o, s:o}", "calibration",
                      cf_calibration_name(j->calibration), "weights", "edge", num(j->weight[0]),
                      "face", num(j->weight[1]), "body", num(j->weight[2]), "modulus_ratio",
                      num(cm.E), "poisson_ratio", num(cm.nu), "zener_ratio", num(cm.zener)));
        if (j->anisotropy_max > 0) /* the bound asked */
            json_object_set_new(json_object_get(f, "lattice"), "anisotropy_max", num(j->anisotropy_max));
        if (j->pair || j->volume != CF_VOLUME_NONE)
            volume_json(json_object_get(f, "lattice"), j);
        json_object_set_new(f, "feasible", json_boolean(j->fit.feasible));
        json_object_set_new(f, "objective", num(j->objective));
        json_object_set_new(f, "evaluations", json_integer(j->evaluations));
        json_object_set_new(f, "search",
                            json_pack("{s:i, s:i, s:i, s:i, s:f}", "starts", j->starts,
                                      "stable_ends", j->stable_ends, "projected", j->projected,
                                      "stable_restarts", j->restarts, "stability_margin",
                                      CF_JOINT_STABLE_MARGIN));
        json_object_set_new(f, "wall_time_s", num(r->with_timing ? j->wall_time_s : 0.0));
        json_object_set_new(f, "tables", tables_json(r, j));
        json_array_append_new(fits, f);
    }
    int b = cf_joint_better(r);
    json_object_set_new(root, "fits", fits);
    if (b >= 0) /* absent when neither type has a spring inside its limits */
        json_object_set_new(root, "better_type",
                            json_string(cf_spring_type_name(r->fits[b].fit.type)));
    /* tables[]: the better type's numbers, one entry per table */
    for (size_t k = 0; b >= 0 && k < r->ntables; k++) {
        const cf_table *t = r->tables[k];
        const cf_joint_table *jt = &r->fits[b].tab[k];
        double u = t->y_to_file;
        json_t *e = json_pack("{s:s, s:s, s:I, s:s, s:o, s:o}", "file", t->path, "mode",
                              cf_mode_name(jt->mode), "points", (json_int_t)jt->points, "unit",
                              t->y_unit, "rmse", num(jt->cell_rmse * u), "lattice_rmse",
                              num(jt->lattice_rmse * u));
        cf_report_notes_json(e, t);
        json_array_append_new(tabs, e);
    }
    json_object_set_new(root, "tables", tabs);
    json_t *ho = cf_report_ho_json(r); /* a set with a biaxial table only */
    if (ho)
        json_object_set_new(root, "holzapfel_ogden", ho);
    json_t *fl = cf_report_fibre_json(r); /* when asked for (--fibres) */
    if (fl)
        json_object_set_new(root, "fibre_lattice", fl);
    return root;
}

/* One panel per table: data (points) and the lattice of the better type (line). */
static cf_status joint_plot(const cf_joint_report *r, const char *path,
                            const char *const *inputs, cf_atomic *out, cf_error *err)
{
    int b = cf_joint_better(r);
    if (b < 0)
        return cf_error_set(err, CF_E_DATA, "no fit to plot");
    cf_gp g;
    cf_gp_init(&g);
    int n = (int)r->ntables;
    cf_gp_terminal(&g, path, 420 * n, 420);
    for (int k = 0; k < n; k++) {
        const cf_table *t = r->tables[k];
        char name[16];
        snprintf(name, sizeof name, "T%d", k);
        cf_gp_block_begin(&g, name);
        for (size_t i = 0; i < t->count; i++) {
            double row[3] = {t->x[i], t->y[i] * t->y_to_file,
                             r->fits[b].tab[k].lattice_MPa[i] * t->y_to_file};
            cf_gp_block_row(&g, 3, row);
        }
        cf_gp_block_end(&g);
    }
    cf_gp_cmd(&g, "set multiplot layout 1,%d", n);
    cf_gp_cmd(&g, "set grid");
    for (int k = 0; k < n; k++) {
        const cf_table *t = r->tables[k];
        cf_gp_cmd(&g, t->compression ? "set key bottom right box opaque"
                                     : "set key top left box opaque");
        const char *base = strrchr(t->path, '/');
        base = base ? base + 1 : t->path;
        cf_gp_cmd(&g, "set title %q noenhanced", base);
        char xl[64];
        snprintf(xl, sizeof xl, "%s [-]", cf_mode_row_of(t->mode)->x_short);
        cf_gp_cmd(&g, "set xlabel %q", xl);
        cf_gp_cmd(&g, "set ylabel %q noenhanced", t->y_unit);
        cf_gp_cmd(&g, "plot $T%d using 1:2 with points pt 7 ps 0.7 lc rgb %q title %q, "
                      "$T%d using 1:3 with lines lw 2 lc rgb %q title %q",
                  k, "black", "table", k, "#1f77b4", "one lattice, all tables");
    }
    cf_gp_cmd(&g, "unset multiplot");
    cf_status st = cf_gp_render(&g, path, inputs, out, err);
    cf_gp_free(&g);
    return st;
}

cf_status cf_joint_prepare(const cf_joint_report *r, const char *json_path, const char *plot_path,
                           const char *const *inputs, cf_atomic *json_out, cf_atomic *plot_out,
                           cf_error *err)
{
    cf_status st =
        cf_atomic_begin("cf_joint_prepare", r, json_path, json_out, plot_path, plot_out, err);
    if (st != CF_OK)
        return st;
    if (json_path) {
        json_t *root = joint_json(r);
        if (!root)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the fit file");
        st = cf_fitfile_prepare(root, json_path, inputs, json_out, err);
        json_decref(root);
    }
    if (st == CF_OK && plot_path)
        st = joint_plot(r, plot_path, inputs, plot_out, err);
    if (st != CF_OK) {
        cf_atomic_abort(json_out);
        cf_atomic_abort(plot_out);
    }
    return st;
}
