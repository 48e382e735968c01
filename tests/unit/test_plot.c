/*
** The figures (report/plot.c): PNG, SVG and PDF are written (recognised by their first bytes); the
** SVG, which is text, shows what the figure holds: the title (the table's name, or the one asked
** for), one curve for two types that tie, the legends of both panels, the lattice residual, and
** the simulation figures' legend. Skipped cleanly when gnuplot is not installed.
*/
#include "testutil.h"

#include <sys/stat.h>

#include "model/msm.h"
#include "pipeline/pipeline.h"
#include "io/scene.h"
#include "report/plot.h"

TU_SCRATCH_GROUP("plot")

static int have_gnuplot(void)
{
    return system("command -v gnuplot >/dev/null 2>&1") == 0;
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    static char buf[1 << 22];
    *len = fread(buf, 1, sizeof buf - 1, f);
    buf[*len] = '\0';
    fclose(f);
    return buf;
}

static size_t count(const char *hay, const char *needle)
{
    size_t n = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

/* Fits data/NAME.csv through the pipeline (validated when asked: 1 through the lattice, the
** default, 2 the bare spring checked in the lattice) and draws it to dir/OUT. */
static char *fit_and_draw(const char *name, int validate, const char *title, const char *out,
                          size_t *len)
{
    char table_path[256], path[300];
    snprintf(table_path, sizeof table_path, "data/%s.csv", name);
    snprintf(path, sizeof path, "%s/%s", dir, out);
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(table_path, NULL, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.validate = validate != 0;
    if (validate == 2)
        po.target = CF_TARGET_SPRING;
    po.title = title;
    cf_fit_report r;
    if (cf_pipeline_fit(&t, &po, &r, &err) != CF_OK ||
        cf_pipeline_write(&r, NULL, path, NULL, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_report_free(&r);
    cf_table_free(&t);
    return slurp(path, len);
}

static void every_format_is_written(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    size_t len;
    char *b = fit_and_draw("telescoping", 0, NULL, "f.png", &len);
    assert_non_null(b);
    assert_memory_equal(b, "\x89PNG", 4);
    b = fit_and_draw("telescoping", 0, NULL, "f.pdf", &len);
    assert_non_null(b);
    assert_memory_equal(b, "%PDF", 4);
    assert_true(len > 1000);
    b = fit_and_draw("telescoping", 0, NULL, "f.svg", &len);
    assert_non_null(b);
    assert_non_null(strstr(b, "<svg"));
    cf_error err = {0};
    assert_int_equal(cf_plot_check_name("f.PDF", &err), CF_OK);
    assert_int_equal(cf_plot_check_name("f.gif", &err), CF_E_DATA);
}

/* data/telescoping.csv fits both types equally well: one conical curve, labelled as a tie, in
** both panels; the title is the table's name; both panels carry a legend. (The bare spring's
** fit, checked in the lattice.) */
static void a_tie_is_one_labelled_curve_and_the_title_is_the_table(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    size_t len;
    char *svg = fit_and_draw("telescoping", 2, NULL, "tie.svg", &len);
    assert_non_null(svg);
    /* a legend entry is <text>NAME</text> in the SVG */
    assert_int_equal(count(svg, "<text>conical, both types (a tie)</text>"), 2);
    assert_null(strstr(svg, "<text>conical, telescoping</text>"));
    assert_null(strstr(svg, "<text>conical, non-telescoping</text>"));
    assert_non_null(strstr(svg, "<text>telescoping</text>")); /* the title: the table's name */
    assert_null(strstr(svg, "data/telescoping.csv"));         /* not the path */
    assert_non_null(strstr(svg, ">residual (model - measured)</tspan>"));
    assert_non_null(strstr(svg, ">model</tspan>"));
    /* the lattice curve in both panels (its residual below) */
    assert_int_equal(count(svg, "<text>lattice 3x3x3, both types (coincide)</text>"), 2);
    /* five baselines, each in both panels */
    const char *const base[] = {"<text>linear</text>", "<text>duffing</text>", "<text>fung</text>",
                                "<text>yeoh</text>", "<text>ogden</text>"};
    for (int k = 0; k < 5; k++)
        assert_int_equal(count(svg, base[k]), 2);
}

/* A fit through the lattice draws what was fitted: the lattice's curve and its residuals (one
** curve for the tie), not the single spring's law; the axes name the fitted measures. */
static void a_lattice_fit_draws_the_lattice(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    size_t len;
    char *svg = fit_and_draw("telescoping", 1, NULL, "lat.svg", &len);
    assert_non_null(svg);
    assert_int_equal(count(svg, "<text>fit: lattice, both types (a tie)</text>"), 2);
    assert_null(strstr(svg, "<text>conical,"));
    assert_non_null(strstr(svg, "nominal stress [kPa]"));
    assert_non_null(strstr(svg, "engineering strain [-]"));
    assert_int_equal(count(svg, "<text>duffing</text>"), 2);
}

static void a_title_can_be_given(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    size_t len;
    char *svg = fit_and_draw("strongly_conical", 0, "Figure 3: a conical table", "t.svg", &len);
    assert_non_null(svg);
    assert_non_null(strstr(svg, "Figure 3: a conical table"));
}

/* A simulation's figure: the curve and its legend (under the axes). */
static void a_simulation_figure_has_its_legend(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    char path[300];
    snprintf(path, sizeof path, "%s/sim.svg", dir);
    cf_scene sc;
    cf_error err = {0};
    if (cf_scene_load("data/scenes/uniaxial.json", &sc, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_msm_sample s[3] = {{0}};
    double spring[3] = {0, 1e-4, 3e-4};
    for (int k = 0; k < 3; k++) {
        s[k].strain = 0.1 * k;
        s[k].stress_MPa = 1e-4 * k * k;
    }
    cf_atomic a;
    assert_int_equal(cf_plot_simulation(&sc, s, spring, 3, path, NULL, &a, &err), CF_OK);
    assert_int_equal(cf_atomic_commit(&a, &err), CF_OK);
    size_t len;
    char *svg = slurp(path, &len);
    assert_non_null(svg);
    assert_non_null(strstr(svg, "<text>single spring</text>"));
    assert_non_null(strstr(svg, "lattice (spring: "));
    cf_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_format_is_written),
        cmocka_unit_test(a_tie_is_one_labelled_curve_and_the_title_is_the_table),
        cmocka_unit_test(a_lattice_fit_draws_the_lattice),
        cmocka_unit_test(a_title_can_be_given),
        cmocka_unit_test(a_simulation_figure_has_its_legend),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
