/*
** The pipeline of a time series (see pipeline_series.h).
*/
#include "pipeline/pipeline_series.h"
#include "base/gslguard.h"

#include <math.h>
#include <string.h>

#include "base/atomic.h"
#include "conifit/version.h"
#include "fit/lsq.h"
#include "fit/tail.h"
#include "pipeline/outputs.h"

/* Member m of the fitted family scaled to the preferred free length (all lengths scaled, G kept:
** the identifiable quantities are unchanged) into f, checked against the design limits, so that a
** spring the limits would not allow is reported infeasible. A tail's travel is the law's whole
** travel, which the plain check (the cone alone) does not see. 0 when m has no law or, with
** want >= 0, not that type. */
static int scaled_member(const cf_table *t, const cf_pipeline_options *opt, cf_spring m, int want,
                         cf_fit_result *f)
{
    const double h = opt->fit.H_preferred_mm > 0 ? opt->fit.H_preferred_mm / m.H_mm : 10.0;
    m.D1_mm *= h;
    m.D2_mm *= h;
    m.d_mm *= h;
    m.H_mm *= h;
    m.H_tail_mm *= h;
    cf_error e = {0};
    cf_law law;
    if (cf_law_init(&law, &m, &e) != CF_OK || (want >= 0 && law.type != (cf_spring_type)want))
        return 0;
    f->params = m;
    f->law = law;
    f->type = law.type;
    f->feasible = cf_fit_check(&m, law.type, t, &opt->fit, &f->active, &f->violated);
    if (cf_spring_has_tail(&m)) {
        f->violated &= ~(unsigned)CF_C_TRAVEL;
        f->active &= ~(unsigned)CF_C_TRAVEL;
        if (!(law.travel_mm > cf_lsq_xmax(t) * m.H_mm * (1 + CF_FIT_TRAVEL_MARGIN)))
            f->violated |= CF_C_TRAVEL;
        f->feasible = f->violated == 0;
    }
    return 1;
}

/* The reported spring must carry the fitted model: a placement that the design limits pushed off
** the fitted rho, s/H, F_C/H^2 is replaced by the spring of cf_ident_member scaled to the
** preferred free length (scaled_member). 0 when no spring results. */
static int exact_member(const cf_table *t, const cf_pipeline_options *opt, const cf_ident *ident,
                        cf_fit_result *f)
{
    const cf_ident got = cf_ident_of(&f->params, 0);
    int same = 1;
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        same = same && fabs(got.v[k] - ident->v[k]) <= 1e-9 * fabs(ident->v[k]);
    return same || scaled_member(t, opt, cf_ident_member(ident), -1, f);
}

/* The held tailed spring of type ty placed for the series as a tailed static fit places it
** (cf_tail_result: the cone's and the tail's coils in closed form, the whole spring solid past the
** series' largest strain), with the four quantities of p (rho, s/H, F_C/H^2, e_t). A placement
** that does not carry them to 1e-9 is replaced by the model's own member (cf_visco_member) scaled
** to the preferred free length, checked against the same limits. 0 when no spring of the type
** results. */
static int place_tail(const cf_table *t, const cf_pipeline_options *opt, cf_spring_type ty,
                      const cf_visco_params *p, cf_fit_result *f)
{
    memset(f, 0, sizeof *f);
    const double B = p->ident.solid, tau = p->e_tail / B;
    const double v[4] = {p->ident.rho, B, p->ident.scale, tau}, se[4] = {-1, -1, -1, -1};
    double corr[4][4];
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++)
            corr[a][b] = NAN;
    cf_error e = {0};
    if (cf_tail_result(t, &opt->fit, ty, v, se, corr, NAN, f, &e) != CF_OK)
        return 0;
    f->optimizer = "placement";
    f->q_se[CF_Q_TAIL] = -1;
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        f->ident_se.v[k] = -1;
    const cf_ident got = cf_ident_of(&f->params, 0);
    const double got_et = got.solid * f->params.n_tail / f->params.n;
    int same = fabs(got_et - p->e_tail) <= 1e-9 * p->e_tail;
    for (int k = 0; k < CF_IDENT_COUNT; k++)
        same = same && fabs(got.v[k] - p->ident.v[k]) <= 1e-9 * fabs(p->ident.v[k]);
    if (same)
        return f->law.type == ty;
    return scaled_member(t, opt, cf_visco_member(p), (int)ty, f);
}

cf_status cf_pipeline_fit_series(const cf_table *t, const cf_pipeline_options *opt,
                                 const cf_visco_fit_options *vo, cf_visco_report *r,
                                 cf_error *err)
{
    CF_GSL_GUARD;
    memset(r, 0, sizeof *r);
    r->version = CF_VERSION;
    r->table = t;
    r->setup = vo->setup;
    r->with_timing = opt->with_timing;
    r->title = opt->title;
    if (!t->t)
        return cf_error_set(err, CF_E_DATA, "%s: not a time series (no time column)", t->path);
    if (t->mode != CF_MODE_UNIAXIAL)
        return cf_error_set(err, CF_E_DATA,
                            "%s: the time-dependent model runs in uniaxial loading; this table "
                            "is in mode '%s'",
                            t->path, cf_mode_name(t->mode));
    if (opt->progress)
        opt->progress(opt->progress_ctx, t->path, "fitting the viscoelastic model along the series");
    cf_visco_data d = {t->count, t->t, t->x, t->y, t->w};
    cf_visco_fit_options o = *vo;
    o.rho_min = opt->fit.rho_min; /* the placement's limits are the fit's */
    o.limits = &opt->fit;
    o.limit_types = opt->types;
    cf_error e = {0};
    cf_status st = cf_visco_fit_run(&d, &o, &r->fit, &e);
    if (st != CF_OK)
        return cf_error_set(err, st, "%s: %s", t->path, e.msg);
    /* one spring of each type from the identifiable quantities, placed as the elastic fit does;
    ** a placement replaced by the exact member keeps its slot only if the member is of its type
    ** (the member is non-telescoping: a telescoping placement the limits pushed off the fitted
    ** quantities is dropped, not reported as a non-telescoping spring in place of the
    ** non-telescoping placement) */
    const cf_ident *ident = &r->fit.p.ident;
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        cf_error pe = {0};
        if (!(opt->types & (1u << ty)))
            continue;
        if (r->fit.p.e_tail > 0 ? place_tail(t, opt, (cf_spring_type)ty, &r->fit.p,
                                             &r->placed[r->nplaced])
                                : cf_fit_place(t, &opt->fit, (cf_spring_type)ty, ident,
                                               &r->placed[r->nplaced], &pe) == CF_OK &&
                                      exact_member(t, opt, ident, &r->placed[r->nplaced]) &&
                                      r->placed[r->nplaced].type == (cf_spring_type)ty)
            r->nplaced++;
    }
    if (r->nplaced == 0) {
        cf_visco_report_free(r);
        return cf_error_set(err, CF_E_DATA,
                            "%s: no spring of the requested type has rho = %.6g, s/H = %.6g",
                            t->path, ident->rho, ident->solid);
    }
    return CF_OK;
}

cf_status cf_pipeline_series_prepare(const cf_visco_report *r, const char *json_path,
                                     const char *plot_path, const char *const *inputs,
                                     cf_output *json_out, cf_output *plot_out,
                                     cf_error *err)
{
    cf_status st = cf_atomic_begin("cf_pipeline_series_prepare", r, json_path, json_out,
                                   plot_path, plot_out, err);
    if (st != CF_OK)
        return st;
    st = json_path ? cf_visco_report_json_prepare(r, json_path, inputs, json_out, err) : CF_OK;
    if (st == CF_OK && plot_path)
        st = cf_visco_plot(r, plot_path, inputs, plot_out, err);
    return cf_pipeline_outputs_end(st, plot_path, json_out, plot_out, err);
}
