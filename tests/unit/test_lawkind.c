/*
** A law kind is a row of the law-kind table plus its evaluators (src/fit/lawkind.h). This test
** defines one the library does not have, a linear spring (one quantity, the modulus E of
** sigma = E epsilon; its spring a cylindrical one, whose law is linear up to solid), and has it
** fitted, compared by AIC, reported and written to a fit file by the pipeline, with no code of
** the fit, the profile, the report or the fit file knowing of it.
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <jansson.h>

#include "fit/baseline.h"
#include "model/family.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "fit/lawkind.h"
#include "testutil.h"

/* ---- the linear spring as a law kind: its row and its three evaluators ---- */

static double linear_eval(const double *q, int force, double x)
{
    (void)force;
    return q[0] * x;
}

/* Start at the secant slope of the table's largest point; range three decades either side. */
static void linear_range(const cf_table *t, double *start, double *lo, double *hi)
{
    size_t m = 0;
    for (size_t i = 0; i < t->count; i++)
        if (fabs(t->x[i]) > fabs(t->x[m]))
            m = i;
    start[0] = fabs(t->y[m] / t->x[m]);
    lo[0] = 1e-3 * start[0];
    hi[0] = 1e3 * start[0];
}

/* A cylindrical spring (D1 = D2) of free length 1 mm, two coils of index 8, that closes at strain
** 0.9: linear until then, its stress scale F_C/H^2 = E s/H, its wire's G from that load. */
#define LINEAR_SOLID 0.9
static cf_spring linear_member(const double *q, int force, cf_spring_type type)
{
    (void)force, (void)type;
    cf_spring p;
    memset(&p, 0, sizeof p);
    p.H_mm = 1.0;
    p.n = 2.0;
    p.d_mm = (1.0 - LINEAR_SOLID) / p.n; /* solid length n d */
    p.D1_mm = p.D2_mm = 8.0 * p.d_mm;
    p.G_MPa = cf_ident_G_of_FC(q[0] * LINEAR_SOLID, p.n, p.D1_mm, p.d_mm, LINEAR_SOLID);
    return p;
}

static const cf_law_row linear_row = {
    .name = "linear",
    .title = "linear spring",
    .spring = "the linear spring",
    .nq = 1,
    .q = {{"modulus_MPa", "stiffness_N_per_mm", "modulus E", "stiffness k", "modulus",
           "stiffness", "y", "N/mm", NULL}},
    .eval = linear_eval,
    .range = linear_range,
    .member = linear_member,
};

static const cf_law_row *const kinds[] = {&cf_law_conical_row, &linear_row};

/* ---- the pipeline with it ---- */

/* The weighted least-squares slope through the origin, the linear kind's optimum. */
static double ls_slope(const cf_table *t)
{
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < t->count; i++) {
        const double w = t->w ? t->w[i] : 1.0;
        sxy += w * t->x[i] * t->y[i];
        sxx += w * t->x[i] * t->x[i];
    }
    return sxy / sxx;
}

static void fit_with_linear(cf_table *t, cf_fit_report *r)
{
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.relative = 0;
    po.fit.kinds = kinds;
    po.fit.nkinds = 2;
    po.types = 1u << CF_NON_TELESCOPING;
    po.with_timing = 0;
    cf_error err = {0};
    if (cf_pipeline_fit(t, &po, r, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

/* What every fit with the linear kind shows: both kinds fitted, the linear one at the
** least-squares slope, its AIC with k = 1, and the choice the lower feasible AIC. */
static const cf_fit_result *check_choice(const cf_table *t, const cf_fit_report *r)
{
    const cf_law_choice *lc = &r->law_choice[0];
    assert_true(lc->ran);
    assert_int_equal(lc->n, 2);
    const cf_fit_result *lin = &lc->cand[1];
    assert_ptr_equal(lin->kind, &linear_row);
    assert_close(lin->q[0], ls_slope(t), 1e-5 * fabs(ls_slope(t)));
    assert_true(lin->q_se[0] > 0);
    const double u = t->y_to_file;
    double ymax = 0;
    for (size_t i = 0; i < t->count; i++)
        ymax = fmax(ymax, fabs(t->y[i]));
    assert_close(lc->aic[1], cf_baseline_aic(t->count, lin->rss * u * u, 1, ymax * u), 1e-9);
    assert_close(lc->aic[0],
                 cf_baseline_aic(t->count, lc->cand[0].rss * u * u, 3, ymax * u), 1e-9);
    const int want = lin->feasible && lc->aic[1] < lc->aic[0];
    assert_int_equal(lc->chosen, want);
    return lin;
}

/* On a published stiffening table the conical law wins, and the report and the fit file carry
** the linear kind's quantity under its own key and label. */
static void linear_kind_on_brain_tension(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    char path[1024];
    snprintf(path, sizeof path, "%s/brain_cortex_tension.csv", dir);
    cf_measure_options mo = cf_measure_default_options();
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(path, &mo, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_fit_report r;
    fit_with_linear(&t, &r);
    const cf_fit_result *lin = check_choice(&t, &r);
    assert_int_equal(r.law_choice[0].chosen, 0); /* the brain stiffens: a line loses */
    assert_true(lin->rmse > 2 * r.fits[0].rmse);
    assert_true(lin->feasible);
    /* the line through the origin is the linear baseline too: the same AIC, by another path */
    assert_close(r.law_choice[0].aic[1], cf_report_baseline_aic(&r, CF_BASE_LINEAR), 1e-6);

    char *text = cf_report_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "Law kinds compared: the conical law (3 quantities) against "
                                 "the linear spring (1)"));
    assert_non_null(strstr(text, "linear       RMSE"));
    assert_non_null(strstr(text, "kept: conical (the linear spring does not lower the AIC)"));
    free(text);

    char *js = cf_report_json_string(&r);
    assert_non_null(js);
    json_error_t je;
    json_t *root = json_loads(js, 0, &je);
    free(js);
    assert_non_null(root);
    json_t *cmp = json_object_get(json_array_get(json_object_get(root, "fits"), 0),
                                  "law_comparison");
    assert_non_null(cmp);
    assert_string_equal(json_string_value(json_object_get(cmp, "chosen")), "conical");
    json_t *jl = json_object_get(cmp, "linear");
    assert_non_null(jl);
    /* the modulus in the file's own unit: the table's kPa */
    const double E = json_number_value(
        json_object_get(json_object_get(jl, "modulus_MPa"), "value"));
    assert_close(E, lin->q[0], 1e-12 * lin->q[0]);
    assert_close(json_number_value(json_object_get(jl, "aic")), r.law_choice[0].aic[1], 1e-9);
    json_decref(root);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* On a linear table the linear kind is kept: the fit in fits[] is its spring, and the report's
** identifiable rows and the fit file's keys are its own. */
static void linear_kind_kept_on_a_line(void **state)
{
    (void)state;
    enum { N = 40 };
    double x[N], y[N];
    for (int i = 0; i < N; i++) {
        x[i] = 0.4 * (i + 1) / N;
        y[i] = 0.05 * x[i] * (1 + 0.01 * (i % 2 ? 1 : -1)); /* 50 kPa, 1 % alternating */
    }
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, N, x, y, NULL, &t, &err),
                     CF_OK);
    cf_fit_report r;
    fit_with_linear(&t, &r);
    check_choice(&t, &r);
    assert_int_equal(r.law_choice[0].chosen, 1);
    const cf_fit_result *f = &r.fits[0];
    assert_ptr_equal(f->kind, &linear_row);
    assert_true(f->feasible);
    assert_close(f->params.D1_mm, f->params.D2_mm, 1e-12); /* its spring is a cylinder */

    char *text = cf_report_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "modulus E"));
    assert_non_null(strstr(text, "kept: linear (lower AIC)"));
    free(text);
    char *js = cf_report_json_string(&r);
    json_error_t je;
    json_t *root = json_loads(js, 0, &je);
    free(js);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    assert_string_equal(json_string_value(json_object_get(fit, "law")), "linear");
    json_t *id = json_object_get(fit, "identifiable");
    assert_int_equal(json_object_size(id), 1);
    assert_close(json_number_value(json_object_get(json_object_get(id, "modulus_MPa"), "value")),
                 f->q[0], 1e-12 * f->q[0]);
    json_decref(root);
    cf_report_free(&r);
    cf_table_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_kind_on_brain_tension),
        cmocka_unit_test(linear_kind_kept_on_a_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
