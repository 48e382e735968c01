/*
** The flat calls (conifit/flat.h, src/pipeline/flat.c): NULL and malformed arguments refused with
** a status and a message, never a crash (a displacement that is not finite among them); the
** batch force equal to the law's one-by-one; a fit of
** the published tables equal to the pipeline's own; a time series refused; a scene's samples and
** an export complete and finite; a scene with a body refused by the lattice's runner, saying so
** (it said "loading path is empty").
*/
#include "bodyutil.h"
#include "testutil.h"

#include <jansson.h>

#include "conifit/flat.h"
#include "model/law_internal.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"

static const double spring[6] = {4, 12, 5, 0.8, 80000, 10};

static void refused(cf_status got, cf_status want, const cf_error *e, const char *needle)
{
    assert_int_equal(got, want);
    assert_int_equal(e->status, want);
    assert_true(e->msg[0] != '\0');
    if (needle && !strstr(e->msg, needle))
        fail_msg("message '%s' does not name '%s'", e->msg, needle);
}

static void null_and_malformed_arguments_are_refused(void **state)
{
    (void)state;
    cf_error e = {0};
    double u[2] = {1, 2}, F[2], k[2];
    char *text = (char *)1;
    double *rows = (double *)1;
    size_t n = 7;
    refused(cf_flat_force(NULL, NULL, 2, u, F, k, &e), CF_E_USAGE, &e, "spring");
    refused(cf_flat_force(spring, NULL, 2, NULL, F, k, &e), CF_E_USAGE, &e, "displacements");
    refused(cf_flat_force(spring, NULL, 2, u, NULL, k, &e), CF_E_USAGE, &e, "force");
    refused(cf_flat_force(spring, "fast", 2, u, F, k, &e), CF_E_DATA, &e, "fast");
    const double bad[6] = {4, 2, 5, 0.8, 80000, 10};
    refused(cf_flat_force(bad, NULL, 2, u, F, k, &e), CF_E_DATA, &e, "D1");
    const double nan_spring[6] = {4, 12, NAN, 0.8, 80000, 10};
    refused(cf_flat_force(nan_spring, NULL, 2, u, F, k, &e), CF_E_DATA, &e, NULL);
    assert_int_equal(cf_flat_force(spring, NULL, 0, NULL, NULL, NULL, &e), CF_OK);
    assert_int_equal(cf_flat_force(spring, NULL, 2, u, F, NULL, NULL), CF_OK); /* err optional */

    refused(cf_flat_fit(NULL, NULL, 0, &text, &e), CF_E_USAGE, &e, "table");
    assert_null(text);
    refused(cf_flat_fit("data/telescoping.csv", NULL, 0, NULL, &e), CF_E_USAGE, &e, NULL);
    refused(cf_flat_fit("data/telescoping.csv", "helical", 0, &text, &e), CF_E_DATA, &e, "helical");
    refused(cf_flat_fit("no/such.csv", NULL, 0, &text, &e), CF_E_NOINPUT, &e, "no/such.csv");
    assert_null(text);

    refused(cf_flat_simulate(NULL, &rows, &n, &e), CF_E_USAGE, &e, "scene");
    assert_null(rows);
    assert_int_equal(n, 0);
    refused(cf_flat_simulate("data/scenes/uniaxial.json", NULL, &n, &e), CF_E_USAGE, &e, NULL);
    refused(cf_flat_simulate("data/scenes/uniaxial.json", &rows, NULL, &e), CF_E_USAGE, &e, NULL);
    refused(cf_flat_simulate("data/telescoping.csv", &rows, &n, &e), CF_E_DATA, &e, NULL);

    text = (char *)1;
    refused(cf_flat_export(NULL, NULL, "csv", 0, &text, &e), CF_E_USAGE, &e, "fit file");
    assert_null(text);
    refused(cf_flat_export("fits/telescoping.json", NULL, NULL, 0, &text, &e), CF_E_USAGE, &e, "format");
    refused(cf_flat_export("fits/telescoping.json", NULL, "nastran", 0, &text, &e), CF_E_DATA, &e, "nastran");
    refused(cf_flat_export("fits/telescoping.json", NULL, "csv", 0.5, &text, &e), CF_E_DATA, &e, "0.5");
    refused(cf_flat_export("fits/telescoping.json", NULL, "csv", NAN, &text, &e), CF_E_DATA, &e, NULL);
    refused(cf_flat_export("fits/telescoping.json", "conical", "csv", 0, &text, &e), CF_E_DATA, &e, NULL);
    assert_null(text);
    cf_flat_free(NULL);
}

/* A displacement that is not a finite number is refused, naming its index, for both calls and
** every method (before: CF_OK with 0 N at NaN and F_C at +-inf). */
static void non_finite_displacements_are_refused(void **state)
{
    (void)state;
    const double tail[8] = {10, 30, 4, 1, 80000, 40, 1, 10};
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    const char *methods[4] = {"closed", "exact", "closed+newton", "table"};
    for (int b = 0; b < 3; b++)
        for (int m = 0; m < 4; m++) {
            double u[3] = {0.5, 1.0, bad[b]}, F[3] = {7, 7, 7}, k[3];
            cf_error e = {0};
            refused(cf_flat_force(spring, methods[m], 3, u, F, k, &e), CF_E_DATA, &e,
                    "displacement 2 ");
            assert_null(strstr(e.msg, "nan"));
            e = (cf_error){0};
            refused(cf_flat_force_tail(tail, methods[m], 3, u, F, NULL, &e), CF_E_DATA, &e,
                    "displacement 2 ");
        }
}

static void the_batch_is_the_law_one_by_one(void **state)
{
    (void)state;
    cf_spring p = {spring[0], spring[1], spring[2], spring[3], spring[4], spring[5]};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    enum { N = 101 };
    double u[N], F[N], k[N];
    for (int i = 0; i < N; i++)
        u[i] = -12 + 24.0 * i / (N - 1); /* beyond solid on both sides */
    const char *methods[] = {"exact", "closed", "closed+newton", "table"};
    for (size_t m = 0; m < 4; m++) {
        cf_law_method lm;
        assert_int_equal(cf_law_method_parse(methods[m], &lm, NULL), CF_OK);
        if (lm == CF_LAW_TABLE)
            assert_int_equal(cf_law_table_build(&law, CF_LAW_TABLE_DEFAULT, NULL), CF_OK);
        assert_int_equal(cf_flat_force(spring, methods[m], N, u, F, k, NULL), CF_OK);
        for (int i = 0; i < N; i++) {
            double kk, f = cf_law_force(&law, lm, u[i], &kk, NULL);
            assert_true(isfinite(F[i]) && isfinite(k[i]));
            assert_close(F[i], f, 1e-12 * fmax(1, fabs(f)));
            assert_close(k[i], kk, 1e-9 * fmax(1, fabs(kk)));
        }
    }
    cf_law_free(&law);
}

/* fits[i].params of a fit file's text, by type name, into p[6]; 0 when there is no such fit. */
static int params_of(const char *json_text, const char *type, double p[6])
{
    json_error_t je;
    json_t *root = json_loads(json_text, 0, &je);
    assert_non_null(root);
    json_t *fits = json_object_get(root, "fits");
    int found = 0;
    for (size_t i = 0; i < json_array_size(fits); i++) {
        json_t *f = json_array_get(fits, i);
        if (strcmp(json_string_value(json_object_get(f, "type")), type) != 0)
            continue;
        const char *keys[6] = {"D1_mm", "D2_mm", "n", "d_mm", "G_MPa", "H_mm"};
        for (int k = 0; k < 6; k++)
            p[k] = json_number_value(json_object_get(json_object_get(f, "params"), keys[k]));
        found = 1;
    }
    json_decref(root);
    return found;
}

static void a_fit_of_the_published_tables_is_the_pipelines(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        print_message("test_flat: ../shared/datasets absent: the published tables are not fitted\n");
        skip();
    }
    const char *tables[] = {"brain_cortex_compression.csv", "treloar1944_rubber_uniaxial.csv",
                            "brain_cortex_tension.csv", "thrombus_pureshear_force_displacement.csv"};
    for (size_t i = 0; i < sizeof tables / sizeof tables[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", d, tables[i]);
        char *flat = NULL;
        cf_error e = {0};
        if (cf_flat_fit(path, NULL, 0, &flat, &e) != CF_OK)
            fail_msg("%s: %s", path, e.msg);
        cf_measure_options mo = cf_measure_default_options();
        cf_table t;
        assert_int_equal(cf_measure_load(path, &mo, &t, &e), CF_OK);
        cf_pipeline_options po = cf_pipeline_default_options();
        cf_fit_report r;
        assert_int_equal(cf_pipeline_fit(&t, &po, &r, &e), CF_OK);
        char *direct = cf_report_json_string(&r);
        assert_non_null(direct);
        for (int type = 0; type < 2; type++) {
            double a[6], b[6];
            const char *name = cf_spring_type_name((cf_spring_type)type);
            int fa = params_of(flat, name, a), fb = params_of(direct, name, b);
            assert_int_equal(fa, fb);
            for (int k = 0; fa && k < 6; k++)
                assert_close(a[k], b[k], 1e-12 * fabs(b[k]));
        }
        free(direct);
        cf_report_free(&r);
        cf_table_free(&t);
        cf_flat_free(flat);
    }
    /* a time series is the command's: refused with a message that says so */
    char path[512], *text = NULL;
    cf_error e = {0};
    snprintf(path, sizeof path, "%s/muscle_compression_relaxation_fiber30.csv", d);
    refused(cf_flat_fit(path, NULL, 0, &text, &e), CF_E_DATA, &e, "time series");
    assert_null(text);
}

static void a_scene_and_an_export_are_whole_and_finite(void **state)
{
    (void)state;
    double *rows = NULL;
    size_t n = 0;
    cf_error e = {0};
    assert_int_equal(cf_flat_simulate("data/scenes/uniaxial.json", &rows, &n, &e), CF_OK);
    assert_int_equal(n, 46); /* 45 samples a segment, one segment, and time 0 */
    for (size_t i = 0; i < n * CF_FLAT_SAMPLE_COLUMNS; i++)
        assert_true(isfinite(rows[i]));
    assert_close(rows[(n - 1) * CF_FLAT_SAMPLE_COLUMNS + 1], 0.45, 1e-12);
    for (size_t i = 1; i < n; i++) /* compression loads the lattice further at every sample */
        assert_true(rows[i * CF_FLAT_SAMPLE_COLUMNS + 2] > rows[(i - 1) * CF_FLAT_SAMPLE_COLUMNS + 2]);
    cf_flat_free(rows);

    char *text = NULL;
    assert_int_equal(cf_flat_export("fits/telescoping.json", NULL, "csv", 1e-4, &text, &e), CF_OK);
    assert_non_null(text);
    assert_memory_equal(text, "u_mm,force_N,stiffness_N_per_mm\n", 32);
    size_t lines = 0;
    for (const char *p = text; *p; p++)
        lines += *p == '\n';
    assert_true(lines > 50);
    assert_null(strstr(text, "nan"));
    assert_null(strstr(text, "inf"));
    cf_flat_free(text);
    /* a double-acting element: both springs in the table (u < 0 the extension spring's) */
    char dir[] = "/tmp/conifit-flat-XXXXXX", fit[64];
    assert_non_null(mkdtemp(dir));
    snprintf(fit, sizeof fit, "%s/pair.json", dir);
    FILE *f = fopen(fit, "w");
    assert_non_null(f);
    fputs("{\"fits\": [{\"type\": \"telescoping\", \"params\": {\"D1_mm\": 10, \"D2_mm\": 30, "
          "\"n\": 4, \"d_mm\": 1, \"G_MPa\": 80000, \"H_mm\": 40}, \"params_extension\": "
          "{\"D1_mm\": 8, \"D2_mm\": 24, \"n\": 6, \"d_mm\": 1.2, \"G_MPa\": 80000, "
          "\"H_mm\": 40}}]}\n", f);
    fclose(f);
    text = NULL;
    assert_int_equal(cf_flat_export(fit, NULL, "csv", 1e-4, &text, &e), CF_OK);
    assert_non_null(strstr(text, "# extension spring"));
    const cf_spring ext = {8, 24, 6, 1.2, 80000, 40};
    cf_law le;
    assert_int_equal(cf_law_init(&le, &ext, NULL), CF_OK);
    const char *row = strstr(text, "u_mm,force_N");
    assert_non_null(row);
    double u, F, k;
    assert_int_equal(sscanf(strchr(row, '\n') + 1, "%lf,%lf,%lf", &u, &F, &k), 3);
    /* the first row: the extension spring's end, within 1e-4 F_C of its law */
    assert_true(u < 0 && u >= -le.travel_mm);
    assert_close(F, -cf_law_force(&le, CF_LAW_EXACT, -u, NULL, NULL), 1e-4 * le.F_C_N);
    cf_flat_free(text);
    remove(fit);
    rmdir(dir);
}

static void a_body_scene_is_refused_by_the_lattice_runner(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-flat-XXXXXX", mesh[300], scene[300];
    assert_non_null(mkdtemp(dir));
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    snprintf(scene, sizeof scene, "%s/body.json", dir);
    write_block(mesh);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 5, \"center_mm\": [15, 15, 20], "
            "\"direction\": [0, 0, -1], \"depth_mm\": 0.1, \"steps\": 1}}\n",
            mesh);
    fclose(f);
    double *rows = (double *)1;
    size_t n = 7;
    cf_error e = {0};
    refused(cf_flat_simulate(scene, &rows, &n, &e), CF_E_USAGE, &e, "tissue body");
    assert_non_null(strstr(e.msg, "conifit simulate"));
    assert_null(strstr(e.msg, "loading path"));
    assert_null(rows);
    assert_int_equal(n, 0);
    unlink(mesh);
    unlink(scene);
    assert_int_equal(rmdir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(null_and_malformed_arguments_are_refused),
        cmocka_unit_test(non_finite_displacements_are_refused),
        cmocka_unit_test(the_batch_is_the_law_one_by_one),
        cmocka_unit_test(a_fit_of_the_published_tables_is_the_pipelines),
        cmocka_unit_test(a_scene_and_an_export_are_whole_and_finite),
        cmocka_unit_test(a_body_scene_is_refused_by_the_lattice_runner),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
