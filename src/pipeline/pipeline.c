/*
** The fitting pipeline (see pipeline.h).
*/
#include "pipeline/pipeline.h"
#include "model/mode.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit/baseline.h"
#include "model/cell.h"
#include "io/scene.h"
#include "conifit/version.h"
#include "base/atomic.h"
#include "report/plot.h"
#include "fit/lawkind.h"
#include "pipeline/outputs.h"

cf_pipeline_options cf_pipeline_default_options(void)
{
    cf_pipeline_options o;
    memset(&o, 0, sizeof o);
    o.types = CF_PIPELINE_BOTH;
    o.fit = cf_fit_default_options();
    o.lattice = cf_validate_default();
    o.budget = cf_budget_default();
    o.with_timing = 1;
    return o;
}

cf_status cf_pipeline_use_scene(cf_pipeline_options *opt, const char *path, cf_error *err)
{
    cf_scene sc;
    cf_status st = cf_scene_load(path, &sc, err);
    if (st != CF_OK)
        return st;
    cf_scene_cost cost;
    st = cf_budget_check_size(&sc, path, &opt->budget, &cost, err);
    if (st == CF_OK)
        st = cf_validate_from_scene(&sc, path, &opt->lattice, err);
    cf_scene_free(&sc);
    return st;
}

static void progress(const cf_pipeline_options *opt, const cf_table *t, const char *fmt,
                     const char *arg)
{
    if (!opt->progress)
        return;
    char what[128];
    snprintf(what, sizeof what, fmt, arg);
    opt->progress(opt->progress_ctx, t->path, what);
}

/* What a fit of a table will do, decided once on entry to cf_pipeline_fit and read by every
** stage. The target: the option, or AUTO's choice: the lattice whenever a lattice is involved (a
** validation, or a mode the single spring has no form of), a force-displacement table's own
** spring otherwise. */
typedef struct fit_plan {
    int lattice;  /* the fit's target is the lattice: the spring's fit is the start of a fit
                     through it (a stress-strain table validated, or in a mode the single
                     spring has no curve of, or asked for) */
    int validate; /* each fit run in the lattice (or fitted through it) */
    /* the law kinds fitted beside the conical one (--law conical-tail or auto: the tailed law;
    ** or cf_fit_options.kinds), and whether the one other kind was asked for (conical-tail) */
    const cf_law_row *others[CF_LAW_KINDS_MAX];
    int nothers;
    int asked;
    int solves;   /* the lattice's static solves are part of the run: their budget checked */
} fit_plan;

/* What cf_pipeline_fit will do with table t, decided once on entry. */
static fit_plan plan_of(const cf_table *t, const cf_pipeline_options *opt)
{
    fit_plan p;
    if (opt->target == CF_TARGET_AUTO)
        p.lattice = !cf_table_is_force(t) &&
                    (opt->validate || !cf_mode_row_of(t->mode)->spring_curve);
    else
        p.lattice = opt->target == CF_TARGET_LATTICE;
    p.validate = opt->validate || p.lattice;
    p.nothers = 0;
    p.asked = 0;
    if (opt->fit.nkinds > 0) {
        for (int i = 0; i < opt->fit.nkinds && p.nothers < CF_LAW_KINDS_MAX - 1; i++)
            if (opt->fit.kinds[i] != &cf_law_conical_row)
                p.others[p.nothers++] = opt->fit.kinds[i];
    } else if (opt->fit.law == CF_KIND_TAIL || opt->fit.law == CF_KIND_AUTO) {
        p.others[p.nothers++] = &cf_law_tail_row;
        p.asked = opt->fit.law == CF_KIND_TAIL;
    }
    p.solves = p.validate && !cf_table_is_force(t);
    return p;
}

/* AIC of a fit: the report's (cf_report_fit_aic, k the kind's quantities), on the plain
** residual sum of squares, so that the choice is the one the report's AIC rows show. */
static double law_aic(const cf_fit_result *f, const cf_fit_report *r)
{
    const double u = r->table->y_to_file;
    return cf_baseline_aic(r->table->count, f->rss * u * u, cf_fit_kind_of(f)->nq, r->ymax * u);
}

/* The law kinds of the plan fitted for fits[k] (the conical law's fit, to the spring or through
** the lattice, thr[k]), each to the fit's own target, and the one kept (report.h,
** cf_law_choice): fits[k] and thr[k] follow it. A kind that cannot be fitted leaves the choice
** to the others, unless it alone was asked for. */
static cf_status choose_law(const cf_table *t, const cf_pipeline_options *opt,
                            const fit_plan *plan, cf_fit_report *r, int k, cf_error *err)
{
    cf_law_choice *lc = &r->law_choice[k];
    const int lattice = r->through_msm && r->thr[k].done;
    cf_through_msm thr[CF_LAW_KINDS_MAX];
    lc->cand[0] = r->fits[k];
    lc->aic[0] = law_aic(&r->fits[k], r);
    thr[0] = r->thr[k];
    lc->n = 1;
    for (int j = 0; j < plan->nothers; j++) {
        const cf_law_row *row = plan->others[j];
        char what[120];
        snprintf(what, sizeof what, "fitting the %s spring with the %s",
                 cf_spring_type_name(r->fits[k].type), row->title);
        progress(opt, t, "%s", what);
        cf_error e = {0};
        cf_fit_result *c = &lc->cand[lc->n];
        thr[lc->n] = r->thr[k]; /* a kind fitted to the spring leaves the lattice record */
        cf_status st;
        if (!lattice)
            st = cf_law_kind_fit(row, t, &opt->fit, r->fits[k].type, &r->fits[k], c, &e);
        else if (row->fit_lattice)
            st = row->fit_lattice(t, &opt->fit, &opt->lattice, &r->fits[k], &r->thr[k], c,
                                  &thr[lc->n], &e);
        else
            st = cf_error_set(&e, CF_E_DATA, "the %s cannot be fitted through the lattice",
                              row->title);
        if (st == CF_OK)
            c->kind = row;
        if (st == CF_E_INTERNAL || (st != CF_OK && plan->asked))
            return cf_error_set(err, st, "%s", e.msg);
        if (st != CF_OK)
            continue;
        lc->aic[lc->n++] = law_aic(c, r);
    }
    lc->ran = lc->n > 1;
    lc->asked = plan->asked;
    cf_law_standing st[CF_LAW_KINDS_MAX];
    for (int j = 0; j < lc->n; j++)
        st[j] = (cf_law_standing){lc->cand[j].feasible, 1, lc->aic[j]};
    lc->chosen = cf_law_pick(st, lc->n, plan->asked && lc->n > 1 ? 1 : -1);
    if (lc->chosen != 0) {
        r->fits[k] = lc->cand[lc->chosen];
        r->thr[k] = thr[lc->chosen];
        memset(&r->limit_cost[k], 0, sizeof r->limit_cost[k]); /* measured for the conical law */
    }
    return CF_OK;
}

/* Static solves of a validation's stability scan, at most (32 steps and the bisection). */
#define VALIDATE_SCAN_SOLVES 64

/* Each fit in the lattice, or through it. A fit the lattice cannot run keeps its validation's
** note (the report states it) and is not an error; running out of memory is (CF_E_INTERNAL). */
static cf_status validate_fits(const cf_table *t, const cf_pipeline_options *opt,
                               const fit_plan *plan, cf_fit_report *r, cf_error *err)
{
    r->validate = 1;
    r->through_msm = plan->lattice;
    for (int k = 0; k < r->nfits; k++) {
        cf_error verr = {0};
        const char *type = cf_spring_type_name(r->fits[k].type);
        if (!r->through_msm) {
            progress(opt, t, "validating the %s spring in the lattice", type);
            cf_validate_run(&r->fits[k].params, &opt->lattice, t, &r->val[k], &verr);
        } else {
            progress(opt, t, "fitting the %s spring through the lattice", type);
            cf_lattice_fit(t, &opt->fit, &opt->lattice, &r->fits[k], &r->thr[k], &verr);
            /* the other law kinds through the lattice where the conical law went through it,
            ** else (a force table, a lattice that could not run) to the spring */
            if (plan->nothers > 0 && verr.status != CF_E_INTERNAL) {
                cf_error terr = {0};
                if (choose_law(t, opt, plan, r, k, &terr) != CF_OK)
                    return cf_error_set(err, terr.status, "%s: %s", t->path, terr.msg);
            }
            cf_validate_lattice_fit(t, &opt->lattice, &r->fits[k], &r->val[k], &r->thr[k], &verr);
        }
        if (verr.status == CF_E_INTERNAL)
            return cf_error_set(err, CF_E_INTERNAL, "%s: %s", t->path, verr.msg);
    }
    return CF_OK;
}

/* What the design limits holding feasible fit f cost: the same fit with them widened as far as
** their flags go. Only memory running out is an error; a widened fit that fails is not checked.
** A fit through the lattice is not: the spring's own RMSE compared here is not its target's. */
static cf_status limit_cost(const cf_table *t, const cf_pipeline_options *opt,
                            const fit_plan *plan, const cf_fit_result *f, cf_limit_cost *lc,
                            cf_error *err)
{
    memset(lc, 0, sizeof *lc);
    cf_fit_options wide;
    if (!f->feasible || plan->lattice ||
        !(lc->limits = cf_fit_relax(&opt->fit, f->held, &wide)))
        return CF_OK;
    progress(opt, t, "fitting the %s spring without the limits that hold it",
             cf_spring_type_name(f->type));
    cf_fit_result *free_fit = malloc(sizeof *free_fit);
    if (!free_fit)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    cf_error e = {0};
    cf_status st = cf_fit_run(t, &wide, f->type, free_fit, &e);
    if (st == CF_OK && free_fit->feasible) {
        lc->checked = 1;
        lc->rmse = f->rmse;
        lc->rmse_free = free_fit->rmse;
    }
    free(free_fit);
    if (st == CF_E_INTERNAL)
        return cf_error_set(err, st, "%s", e.msg);
    return CF_OK;
}

/* Where fit f's first spring reaches solid in the table's own mode (a stress-strain table in a
** mode of the cell): the table strain the solid-strain ratio and its warning are stated in. A
** mode the cell cannot follow to solid leaves the spring's own solid strain. */
static void solid_in_mode(const cf_table *t, const cf_pipeline_options *opt, cf_fit_result *f)
{
    if (cf_table_is_force(t) || cf_mode_row_of(t->mode)->spring_curve || !(cf_fit_family(f, 0).solid > 0))
        return;
    double xmax = 0;
    int side = 1;
    for (size_t i = 0; i < t->count; i++)
        if (fabs(t->x[i]) > xmax)
            xmax = fabs(t->x[i]), side = t->x[i] < 0 ? -1 : 1;
    cf_law law;
    cf_cell c;
    double e = 0;
    if (cf_law_init(&law, &f->params, NULL) != CF_OK)
        return;
    if (cf_cell_init(&c, &law, CF_LAW_CLOSED, opt->lattice.cfg.lattice.weight, NULL) == CF_OK &&
        cf_cell_solid_strain(&c, t->mode, side, &e, NULL) == CF_OK) {
        f->solid_table_strain = fabs(e);
        f->solid_ratio = xmax > 0 ? fabs(e) / xmax : INFINITY;
    }
    cf_law_free(&law);
}

cf_status cf_pipeline_fit(const cf_table *t, const cf_pipeline_options *opt, cf_fit_report *r,
                          cf_error *err)
{
    CF_GSL_GUARD;
    memset(r, 0, sizeof *r);
    r->version = CF_VERSION;
    r->table = t;
    r->with_timing = opt->with_timing;
    r->title = opt->title;
    r->fit_options = opt->fit;
    for (size_t i = 0; i < t->count; i++)
        r->ymax = fmax(r->ymax, fabs(t->y[i]));
    r->law = opt->fit.law;
    const fit_plan plan = plan_of(t, opt);
    if (plan.solves) {
        /* a static solve per row and type in the validation lattice, and its stability scan */
        int types = !!(opt->types & (1u << CF_TELESCOPING)) +
                    !!(opt->types & (1u << CF_NON_TELESCOPING));
        double solves = (double)types * ((double)t->count + VALIDATE_SCAN_SOLVES);
        const cf_lattice_config *lc = &opt->lattice.cfg.lattice;
        if (solves > opt->budget.max_steps)
            return cf_error_set(err, CF_E_DATA,
                                "%s: the validation needs about %.3g static solves of the "
                                "%dx%dx%d lattice (%zu rows, %d types and the stability scan), "
                                "above the limit of %g (raise it with --max-steps)",
                                t->path, solves, lc->nx, lc->ny, lc->nz, t->count, types,
                                opt->budget.max_steps);
        /* and what they cost on that lattice (budget.h) */
        const double each = cf_budget_solve_work(
            3.0 * (lc->nx + 1.0) * (lc->ny + 1.0) * (lc->nz + 1.0));
        if (solves * each > opt->budget.max_work)
            return cf_error_set(err, CF_E_DATA,
                                "%s: the validation needs about %.3g spring-steps of work (%.3g "
                                "static solves of the %dx%dx%d lattice, %.3g each), above the "
                                "limit of %.3g (raise it with --max-work); at most %.0f rows "
                                "would fit",
                                t->path, solves * each, solves, lc->nx, lc->ny, lc->nz, each,
                                opt->budget.max_work,
                                fmax(0.0, floor(opt->budget.max_work / each / types) -
                                              VALIDATE_SCAN_SOLVES));
    }
    cf_fit_shared shared; /* the types' common stage A (fit.h) */
    memset(&shared, 0, sizeof shared);
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        if (!(opt->types & (1u << ty)))
            continue;
        progress(opt, t, "fitting the %s spring", cf_spring_type_name((cf_spring_type)ty));
        cf_error e = {0};
        cf_status st = cf_fit_run_shared(t, &opt->fit, (cf_spring_type)ty, &shared,
                                         &r->fits[r->nfits], &e);
        if (st == CF_OK)
            st = limit_cost(t, opt, &plan, &r->fits[r->nfits], &r->limit_cost[r->nfits], &e);
        if (st == CF_OK && plan.nothers > 0 && !plan.lattice)
            st = choose_law(t, opt, &plan, r, r->nfits, &e);
        if (st != CF_OK)
            return cf_error_set(err, st, "%s: %s", t->path, e.msg);
        r->nfits++;
    }
    if (r->nfits == 0)
        return cf_error_set(err, CF_E_DATA, "%s: no spring type chosen to fit", t->path);
    cf_error be = {0};
    r->softening = cf_softening_of(t);
    if (cf_baseline_fit_all(t, r->baselines, &be) != CF_OK)
        return cf_error_set(err, be.status, "%s: %s", t->path, be.msg);
    cf_status vst = CF_OK;
    if (plan.validate && (vst = validate_fits(t, opt, &plan, r, err)) != CF_OK)
        return vst;
    for (int k = 0; k < r->nfits; k++)
        solid_in_mode(t, opt, &r->fits[k]);
    cf_report_settle(r);
    return CF_OK;
}

cf_status cf_pipeline_prepare(const cf_fit_report *r, const char *json_path,
                              const char *plot_path, const char *const *inputs,
                              cf_output *json_out, cf_output *plot_out,
                              cf_error *err)
{
    CF_GSL_GUARD;
    cf_status st = cf_atomic_begin("cf_pipeline_prepare", r, json_path, json_out, plot_path,
                                   plot_out, err);
    if (st != CF_OK)
        return st;
    st = json_path ? cf_report_json_prepare(r, json_path, inputs, json_out, err) : CF_OK;
    if (st == CF_OK && plot_path)
        st = cf_plot_fit(r, plot_path, inputs, plot_out, err);
    return cf_pipeline_outputs_end(st, plot_path, json_out, plot_out, err);
}

cf_status cf_pipeline_outputs_end(cf_status st, const char *plot_path, cf_atomic *json_out,
                                  cf_atomic *plot_out, cf_error *err)
{
    if (st == CF_OK && plot_path)
        st = cf_atomic_finish(plot_out, err);
    if (st != CF_OK) {
        cf_atomic_abort(json_out);
        cf_atomic_abort(plot_out);
    }
    return st;
}

cf_status cf_pipeline_write(const cf_fit_report *r, const char *json_path, const char *plot_path,
                            const char *const *inputs, cf_error *err)
{
    CF_GSL_GUARD;
    cf_atomic a = {0}, b = {0};
    cf_status st = cf_pipeline_prepare(r, json_path, plot_path, inputs, &a, &b, err);
    if (st == CF_OK && json_path)
        st = cf_atomic_commit(&a, err);
    if (st == CF_OK && plot_path)
        st = cf_atomic_commit(&b, err);
    cf_atomic_abort(&a);
    cf_atomic_abort(&b);
    return st;
}
