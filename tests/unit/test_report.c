/*
** The report (report/report.c, report_text.c): the JSON fit file and the text, from a report the
** pipeline made.
**  - the JSON holds the table's provenance and units, every number finite and no null (a value
**    that is not determined is left out, with a reason beside it; a document that would hold a
**    non-finite number is not written, and the error names its key), and reads back with the
**    fit-file reader;
**  - numbers in the file's own unit (kPa here), not conifit's MPa;
**  - the text names both types, the identifiable quantities and the units;
**  - a table that tells the types apart is reported with a better type, one that does not as a
**    tie;
**  - a profile interval is shown with at most 6 significant digits, its ends rounded outward and
**    never printed past the value (an end one ulp below the value printed 17 digits, the end
**    below the value).
*/
#include "testutil.h"

#include <jansson.h>

#include "io/fitfile.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "report/report_words.h"

/* A kPa stress-strain table of one spring's law (noise-free: both types fit it). */
static void law_table(const cf_spring *p, int n, double emax, cf_table *t)
{
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    double x[64], y[64];
    for (int i = 0; i < n; i++) {
        x[i] = emax * i / (n - 1);
        y[i] = cf_law_force(&law, CF_LAW_EXACT, x[i] * p->H_mm, NULL, NULL) / (p->H_mm * p->H_mm);
    }
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, (size_t)n, x, y, NULL, t, NULL),
                     CF_OK);
    /* as the reader would leave a kPa table */
    t->y_to_file = 1000;
    snprintf(t->y_unit, sizeof t->y_unit, "kPa");
    snprintf(t->y_column, sizeof t->y_column, "stress_kPa");
    snprintf(t->path, sizeof t->path, "spring.csv");
    cf_law_free(&law);
}

static void json_holds_units_finite_numbers_and_reads_back(void **state)
{
    (void)state;
    cf_spring p = {4, 10, 3, 0.5, 80000, 12};
    cf_table t;
    law_table(&p, 30, 0.5 * (12 - 0.5) / 12, &t);
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_fit_report r;
    cf_error err = {0};
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, &err), CF_OK);
    assert_int_equal(r.nfits, 2);
    char *s = cf_report_json_string(&r);
    assert_non_null(s);
    assert_null(strstr(s, "nan"));
    assert_null(strstr(s, "NaN"));
    assert_null(strstr(s, "inf"));
    assert_null(strstr(s, "null"));
    json_error_t je;
    json_t *root = json_loads(s, JSON_REJECT_DUPLICATES, &je);
    if (!root)
        fail_msg("not JSON: %s", je.text);
    json_t *data = json_object_get(root, "data");
    assert_string_equal(json_string_value(json_object_get(data, "file")), "spring.csv");
    assert_string_equal(json_string_value(json_object_get(data, "y_unit")), "kPa");
    assert_int_equal(json_integer_value(json_object_get(data, "points")), 30);
    json_t *f0 = json_array_get(json_object_get(root, "fits"), 0);
    json_t *f1 = json_array_get(json_object_get(root, "fits"), 1);
    assert_true(json_is_number(json_object_get(f1, "max_abs_error")));
    /* RMSE in kPa: the fit's MPa value times 1000 */
    assert_close(json_number_value(json_object_get(f0, "rmse")), r.fits[0].rmse * 1000,
                 1e-12 * fmax(1.0, r.fits[0].rmse * 1000));
    /* the five baselines in their order, each fitted, with its coefficients in kPa */
    json_t *base = json_object_get(root, "baselines");
    assert_int_equal(json_array_size(base), CF_BASE_COUNT);
    for (int k = 0; k < CF_BASE_COUNT; k++) {
        json_t *bk = json_array_get(base, (size_t)k);
        assert_string_equal(json_string_value(json_object_get(bk, "model")),
                            cf_baseline_name((cf_baseline_kind)k));
        assert_null(json_object_get(bk, "reason"));
        assert_close(json_number_value(json_object_get(bk, "rmse")), r.baselines[k].rmse * 1000,
                     1e-12 * r.baselines[k].rmse * 1000);
    }
    json_t *yc = json_object_get(json_array_get(base, CF_BASE_YEOH), "coefficients");
    assert_close(json_number_value(json_object_get(yc, "C2")), r.baselines[CF_BASE_YEOH].coef[1] * 1000,
                 1e-12 * fabs(r.baselines[CF_BASE_YEOH].coef[1]) * 1000);
    json_t *oc = json_object_get(json_array_get(base, CF_BASE_OGDEN), "coefficients");
    assert_true(json_number_value(json_object_get(oc, "alpha")) == r.baselines[CF_BASE_OGDEN].coef[1]);
    json_decref(root);
    /* what is written reads back: the spring of the first fit, bit for bit */
    char dir[] = "/tmp/conifit-report-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/r.json", dir);
    assert_int_equal(cf_report_json_write(&r, path, NULL, &err), CF_OK);
    cf_fitted_spring fs;
    assert_int_equal(cf_fitfile_load(path, "telescoping", &fs, &err), CF_OK);
    assert_true(fs.params.D1_mm == r.fits[0].params.D1_mm);
    assert_true(fs.params.G_MPa == r.fits[0].params.G_MPa);
    assert_string_equal(fs.y_unit, "kPa");
    remove(path);
    /* a value no fit should hold: the document is refused, naming the key, and nothing written */
    r.fits[1].max_abs_error = NAN;
    assert_null(cf_report_json_string(&r));
    cf_error e2 = {0};
    assert_int_equal(cf_report_json_write(&r, path, NULL, &e2), CF_E_INTERNAL);
    assert_non_null(strstr(e2.msg, "fits[1].max_abs_error"));
    assert_int_equal(access(path, F_OK), -1);
    rmdir(dir);
    free(s);
    cf_report_free(&r);
    cf_table_free(&t);
}

static void text_names_types_quantities_and_units(void **state)
{
    (void)state;
    cf_spring p = {4, 10, 3, 0.5, 80000, 12};
    cf_table t;
    law_table(&p, 30, 0.5 * (12 - 0.5) / 12, &t);
    cf_pipeline_options po = cf_pipeline_default_options();
    cf_fit_report r;
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, NULL), CF_OK);
    char *text = cf_report_text(&r);
    assert_non_null(text);
    const char *want[] = {"spring.csv", "telescoping", "non-telescoping", "rho = D1/D2",
                          "solid strain s/H", "stress scale F_C/H^2", " mm", " MPa", " kPa",
                          "RMSE", "Baselines", "duffing", "fung", "yeoh     C1 = ",
                          "ogden    mu = ", "uniaxial form"};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        if (!strstr(text, want[i]))
            fail_msg("the report text lacks '%s':\n%s", want[i], text);
    /* the law of one spring is met by both types: reported as a tie, and so is the JSON */
    assert_true(cf_report_types_tie(&r));
    assert_non_null(strstr(text, "tie"));
    free(text);
    char *s = cf_report_json_string(&r);
    json_t *root = json_loads(s, 0, NULL);
    assert_true(json_is_true(json_object_get(json_object_get(root, "comparison"), "tie")));
    json_decref(root);
    free(s);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* With one type only there is no comparison and the better fit is that one (if feasible). */
static void one_type_has_no_comparison(void **state)
{
    (void)state;
    cf_spring p = {4, 10, 3, 0.5, 80000, 12};
    cf_table t;
    law_table(&p, 30, 0.5 * (12 - 0.5) / 12, &t);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.types = CF_PIPELINE_NON_TELESCOPING;
    cf_fit_report r;
    assert_int_equal(cf_pipeline_fit(&t, &po, &r, NULL), CF_OK);
    assert_int_equal(r.nfits, 1);
    assert_false(cf_report_types_tie(&r));
    assert_int_equal(cf_report_better(&r), r.fits[0].feasible ? 0 : -1);
    char *s = cf_report_json_string(&r);
    json_t *root = json_loads(s, 0, NULL);
    assert_null(json_object_get(root, "comparison"));
    json_decref(root);
    free(s);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* The parts of "v [lo, hi]*" as printed; their significant digits (mantissa digits) at most
** `most`. */
static void interval_cell(double v, double lo, double hi, double *pv, double *plo, double *phi,
                          int most)
{
    cf_fit_result f;
    memset(&f, 0, sizeof f);
    f.ident.v[0] = v;
    f.ident_se.v[0] = -1;
    f.interval[0][0] = lo;
    f.interval[0][1] = hi;
    f.interval_ok[0] = 1;
    char cell[128], a[40], b[40], c[40];
    cf_report_ident_cell(&f, 0, 1, "", cell, sizeof cell);
    assert_int_equal(sscanf(cell, "%39[^ ] [%39[^,], %39[^]]]*", a, b, c), 3);
    const char *parts[3] = {a, b, c};
    for (int i = 0; i < 3; i++) {
        int digits = 0, seen = 0;
        for (const char *p = parts[i]; *p && *p != 'e'; p++)
            if (*p >= '0' && *p <= '9') {
                seen |= *p != '0';
                digits += seen;
            }
        if (digits > most)
            fail_msg("'%s' has %d significant digits in '%s'", parts[i], digits, cell);
    }
    *pv = strtod(a, NULL), *plo = strtod(b, NULL), *phi = strtod(c, NULL);
}

static void intervals_print_few_digits_and_hold_their_value(void **state)
{
    (void)state;
    double v, lo, hi;
    /* an end one ulp below the value: shown as the value */
    const double x = 0.37212345678901234;
    interval_cell(x, nextafter(x, 0), 0.9, &v, &lo, &hi, 6);
    assert_true(lo <= v && v <= hi);
    assert_true(lo == v);
    interval_cell(x, 0.1, nextafter(x, 1), &v, &lo, &hi, 6);
    assert_true(lo <= v && v <= hi && hi == v);
    /* ends close to the value: more digits, at most 6, rounded outward */
    interval_cell(1.23456789, 1.2345, 1.2347, &v, &lo, &hi, 6);
    assert_true(lo <= 1.2345 && hi >= 1.2347 && lo < v && v < hi);
    /* an ordinary interval: 3 digits for the ends, outward */
    interval_cell(9293.1, 24.52, 10234.5, &v, &lo, &hi, 4);
    assert_true(lo <= 24.52 && hi >= 10234.5 && lo <= v && v <= hi);
    /* many random intervals: the printed interval always holds the printed value */
    unsigned seed = 12345;
    for (int i = 0; i < 20000; i++) {
        seed = seed * 1103515245u + 12345u;
        double c = ldexp((double)(seed >> 8) / 16777216.0 + 0.5, (int)(seed % 40) - 20);
        seed = seed * 1103515245u + 12345u;
        double wl = c * ldexp((double)(seed >> 8) / 16777216.0, -(int)(seed % 56));
        seed = seed * 1103515245u + 12345u;
        double wh = c * ldexp((double)(seed >> 8) / 16777216.0, -(int)(seed % 56));
        interval_cell(c, c - wl, c + wh, &v, &lo, &hi, 6);
        if (!(lo <= v && v <= hi))
            fail_msg("value %.17g in [%.17g, %.17g] printed %.17g [%.17g, %.17g]", c, c - wl,
                     c + wh, v, lo, hi);
    }
}

/* The pipeline on the table at path (mode may be NULL), with law `law` and index_max (0: the
** default); its text, warnings and fit file into the arguments (the caller frees text and json). */
static void report_of(const char *path, const char *mode, cf_law_kind law, double index_max,
                      cf_table *t, cf_fit_report *r, char **text, char **json,
                      char w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN], int *nw)
{
    cf_measure_options mo = cf_measure_default_options();
    mo.mode = mode;
    cf_error err = {0};
    if (cf_measure_load(path, &mo, t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = law;
    if (index_max > 0)
        po.fit.index_max = index_max;
    if (cf_pipeline_fit(t, &po, r, &err) != CF_OK)
        fail_msg("%s: %s", path, err.msg);
    *text = cf_report_text(r);
    *json = cf_report_json_string(r);
    assert_non_null(*text);
    assert_non_null(*json);
    *nw = cf_report_warnings(r, w, CF_REPORT_WARNINGS_MAX);
}

/* How many of the n warnings hold `what`; each is in the text and the fit file as well. */
static int warned(char w[][CF_REPORT_WARNING_LEN], int n, const char *what, const char *text,
                  const char *json)
{
    int k = 0;
    for (int i = 0; i < n; i++)
        if (strstr(w[i], what)) {
            k++;
            assert_non_null(strstr(text, w[i]));
            assert_non_null(strstr(json, what));
        }
    return k;
}

/* Issue 37, items 14 and 16, on a ligament's force-displacement table (tu_ligament_csv): the
** non-telescoping spring the limits place is 16.7 m long for a 5 mm table (D1 3.6 m), which is
** warned of; with --index-max 20 the telescoping fit (a straight line, RMSE 36.4 N, no limit
** active where it ended, the same with 64 starts) loses to the non-telescoping one (26.9 N at
** rho 0.05), whose law is no telescoping spring within G_max: the verdict says so instead of
** blaming the optimiser. */
static void ligament_spring_scale_and_verdict(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-report-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/ligament.csv", dir);
    assert_int_equal(tu_ligament_csv(path), 0);
    cf_table t;
    cf_fit_report r;
    char *text, *json, w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
    int nw;
    report_of(path, NULL, CF_KIND_CONICAL, 0, &t, &r, &text, &json, w, &nw);
    assert_int_equal(warned(w, nw, "non-telescoping spring placed for this force-displacement "
                                   "table is", text, json), 1);
    /* the telescoping one (D2 0.21 m) is within 100 times: only the sentence above */
    assert_int_equal(warned(w, nw, "telescoping spring placed", text, json), 1);
    free(text);
    free(json);
    cf_report_free(&r);
    cf_table_free(&t);
    report_of(path, NULL, CF_KIND_CONICAL, 20, &t, &r, &text, &json, w, &nw);
    assert_int_equal(cf_report_better(&r), 1);
    assert_null(strstr(text, "optimiser stopped"));
    assert_non_null(strstr(text, "is no telescoping spring within the limit G_max"));
    free(text);
    free(json);
    cf_report_free(&r);
    cf_table_free(&t);
    remove(path);
    rmdir(dir);
}

/* Issue 37, item 15, on Treloar's rubber (../shared/datasets): both springs are infeasible (the
** table reaches strain 6.7, past any spring's travel) and 2.2 times the straight line's RMSE,
** which is warned of; their solid strain is 0.15 of the table's largest, "data past solid", not
** "close to solid"; read as equibiaxial, the fit through the lattice cannot run and the numbers
** are the single spring's, which is warned of. */
static void infeasible_rubber_warnings(void **state)
{
    (void)state;
    const char *ds = tu_datasets();
    if (!ds)
        skip();
    char path[300];
    snprintf(path, sizeof path, "%s/treloar1944_rubber_uniaxial.csv", ds);
    static const char *const modes[2] = {NULL, "equibiaxial"};
    for (int m = 0; m < 2; m++) {
        cf_table t;
        cf_fit_report r;
        char *text, *json, w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
        int nw;
        report_of(path, modes[m], CF_KIND_CONICAL, 0, &t, &r, &text, &json, w, &nw);
        for (int i = 0; i < r.nfits; i++)
            assert_false(r.fits[i].feasible);
        assert_int_equal(warned(w, nw, "worse than a straight line", text, json), 2);
        assert_null(strstr(text, "(close to solid!)"));
        assert_non_null(strstr(text, "(data past solid!)"));
        assert_int_equal(warned(w, nw, "is of the single spring, not the lattice in equibiaxial",
                                text, json),
                         m == 1 ? 2 : 0);
        free(text);
        free(json);
        cf_report_free(&r);
        cf_table_free(&t);
    }
}

/* Issue 37, item 16, on the aortic valve leaflet read as uniaxial with --law auto: the
** non-telescoping tailed fit (119 Pa) wins over the telescoping conical one (327 Pa), whose tailed
** fit (97.7 Pa) breaks D2_max_H: the verdict names that law choice. */
static void verdict_names_the_law_choice(void **state)
{
    (void)state;
    const char *ds = tu_datasets();
    if (!ds)
        skip();
    char path[300];
    snprintf(path, sizeof path, "%s/aortic_valve_circumferential.csv", ds);
    cf_table t;
    cf_fit_report r;
    char *text, *json, w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
    int nw;
    report_of(path, "uniaxial", CF_KIND_AUTO, 0, &t, &r, &text, &json, w, &nw);
    assert_int_equal(cf_report_better(&r), 1);
    if (!strstr(text, "telescoping keeps the conical law (the better one the conical-tail law): "
                      "its conical-tail fit is excluded by the limit D2_max_H"))
        fail_msg("the verdict does not name the law choice:\n%s", text);
    free(text);
    free(json);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* A force-displacement table's travel limit is said in displacements (issue 37, item 15). */
static void travel_limit_of_a_force_table_speaks_of_displacement(void **state)
{
    (void)state;
    const char *fd = cf_fit_constraint_flag_for(CF_C_TRAVEL, 1);
    assert_non_null(strstr(fd, "displacement"));
    assert_null(strstr(fd, "strain"));
    assert_string_equal(cf_fit_constraint_flag_for(CF_C_TRAVEL, 0),
                        cf_fit_constraint_flag(CF_C_TRAVEL));
    assert_string_equal(cf_fit_constraint_flag_for(CF_C_G_MAX, 1), "--G-max");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(json_holds_units_finite_numbers_and_reads_back),
        cmocka_unit_test(text_names_types_quantities_and_units),
        cmocka_unit_test(one_type_has_no_comparison),
        cmocka_unit_test(intervals_print_few_digits_and_hold_their_value),
        cmocka_unit_test(ligament_spring_scale_and_verdict),
        cmocka_unit_test(infeasible_rubber_warnings),
        cmocka_unit_test(verdict_names_the_law_choice),
        cmocka_unit_test(travel_limit_of_a_force_table_speaks_of_displacement),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
