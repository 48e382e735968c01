/*
** Stress and strain measures and test modes of a table: declarations ('# stress:', '# strain:',
** '# mode:'), column names, options that win over the file, and the conversion of Cauchy stress and
** log strain to the nominal stress and engineering strain the law models, checked against hand
** computations (the published skin table is Cauchy stress; skipped when ../shared/datasets is
** absent).
*/
#include <math.h>
#include <sys/stat.h>

#include "testutil.h"

#include "io/measure.h"

TU_SCRATCH_GROUP("measures")
static char out[1 << 16], errb[1 << 14];

/* Writes text to DIR/name and returns the path (static storage). */
static const char *table(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static void load_ok(const char *path, const cf_measure_options *o, cf_table *t)
{
    cf_error err = {0};
    if (cf_measure_load(path, o, t, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

static void load_fails(const char *path, const cf_measure_options *o, const char *needle)
{
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, o, &t, &err), CF_E_DATA);
    if (!strstr(err.msg, needle))
        fail_msg("message '%s' lacks '%s'", err.msg, needle);
}

/* Hand computations: sigma = 1.2 kPa at strain 0.2 is P = 1.2/1.2 = 1 kPa (uniaxial,
** incompressible); in compression sigma = -0.8 kPa at strain -0.2 is P = -0.8/0.8 = -1 kPa. */
static void cauchy_uniaxial_is_divided_by_the_stretch(void **state)
{
    (void)state;
    const char *p = table("c.csv", "# mode: uniaxial\n# stress: cauchy\nstrain,stress_kPa\n"
                                   "0,0\n0.1,0.55\n0.2,1.2\n0.3,2.6\n0.4,4.2\n0.5,6\n");
    cf_measure_options o = cf_measure_default_options();
    cf_table t;
    load_ok(p, &o, &t);
    assert_int_equal(t.measures.stress, CF_STRESS_CAUCHY);
    assert_int_equal(t.measures.stress_from, CF_DECL_COMMENT);
    assert_int_equal(t.measures.stress_line, 2);
    assert_int_equal(t.mode, CF_MODE_UNIAXIAL);
    assert_true(t.measures.stress_converted);
    assert_close(t.y[2], 1e-3, 1e-18);         /* 1.2 kPa / 1.2 = 1 kPa, in MPa */
    assert_close(t.y[5], 6e-3 / 1.5, 1e-18);   /* 6 kPa / 1.5 = 4 kPa */
    assert_close(t.x[2], 0.2, 0);              /* the strain is untouched */
    cf_table_free(&t);
    p = table("cc.csv", "# stress: cauchy\nstrain,stress_kPa\n0,0\n-0.1,-0.45\n-0.2,-0.8\n"
                        "-0.3,-1.4\n-0.4,-2.4\n-0.5,-4\n");
    load_ok(p, &o, &t);
    assert_int_equal(t.mode_stated, 0); /* uniaxial, assumed and said */
    assert_close(t.y[2], -1e-3, 1e-18);
    assert_close(t.y[5], -8e-3, 1e-18);
    cf_table_free(&t);
}

/* Planar and equibiaxial divide by the stretch too; simple shear and confined compression do
** not (the face carrying the load keeps its area). */
static void the_mode_decides_the_conversion(void **state)
{
    (void)state;
    static const char *modes[] = {"planar", "equibiaxial", "shear", "confined"};
    static const double factor[] = {1 / 1.25, 1 / 1.25, 1, 1};
    for (int k = 0; k < 4; k++) {
        char text[256];
        snprintf(text, sizeof text,
                 "# mode: %s\n# stress: cauchy\nstrain,stress_kPa\n0,0\n0.05,1\n0.1,2\n0.15,3\n"
                 "0.2,4\n0.25,5\n",
                 modes[k]);
        cf_table t;
        cf_measure_options o = cf_measure_default_options();
        load_ok(table("m.csv", text), &o, &t);
        assert_close(t.y[5], 5e-3 * factor[k], 1e-18);
        cf_table_free(&t);
    }
}

/* Log strain e is engineering strain exp(e) - 1: ln 1.5 -> 0.5; with Cauchy stress the stretch
** used is the converted one (sigma = 3 kPa at stretch 1.5: P = 2 kPa). */
static void log_strain_becomes_engineering_strain(void **state)
{
    (void)state;
    char text[512];
    snprintf(text, sizeof text,
             "log_strain,true_stress_kPa\n0,0\n%.17g,1\n%.17g,1.5\n%.17g,2\n%.17g,2.5\n%.17g,3\n",
             log(1.1), log(1.2), log(1.3), log(1.4), log(1.5));
    cf_table t;
    cf_measure_options o = cf_measure_default_options();
    load_ok(table("l.csv", text), &o, &t);
    assert_int_equal(t.measures.strain, CF_STRAIN_LOG);
    assert_int_equal(t.measures.strain_from, CF_DECL_COLUMN);
    assert_int_equal(t.measures.stress, CF_STRESS_CAUCHY);
    assert_int_equal(t.measures.stress_from, CF_DECL_COLUMN);
    assert_close(t.x[5], 0.5, 1e-15);
    assert_close(t.y[5], 2e-3, 1e-17);
    cf_table_free(&t);
    /* a stretch column (lambda) with a 'cauchy' column */
    load_ok(table("s.csv", "lambda,cauchy [kPa]\n1,0\n1.1,1.1\n1.2,2.4\n1.3,3.9\n1.4,5.6\n"
                           "1.5,7.5\n"),
            &o, &t);
    assert_int_equal(t.measures.strain, CF_STRAIN_STRETCH);
    assert_close(t.x[5], 0.5, 1e-15);
    assert_close(t.y[5], 5e-3, 1e-17);
    cf_table_free(&t);
}

/* The published skin table (strip biaxial, declared Cauchy): every row is converted as
** P = sigma/(1 + strain); the first row by hand: 0.000456917 MPa / 1.002019386 =
** 0.00045599616772284686 MPa. */
static void skin_table_is_converted(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d)
        skip();
    char path[512];
    snprintf(path, sizeof path, "%s/skin_porcine_stripbiaxial_x.csv", d);
    cf_measure_options o = cf_measure_default_options();
    cf_table conv, raw;
    load_ok(path, &o, &conv);
    o.stress_measure = CF_STRESS_NOMINAL;
    load_ok(path, &o, &raw);
    assert_int_equal(conv.measures.stress, CF_STRESS_CAUCHY);
    assert_int_equal(conv.mode, CF_MODE_PLANAR);
    assert_true(conv.measures.stress_converted);
    assert_true(raw.measures.stress_overridden);
    assert_int_equal(raw.measures.stress_file, CF_STRESS_CAUCHY);
    assert_int_equal(conv.count, raw.count);
    assert_close(conv.y[0], 0.00045599616772284686, 1e-19);
    for (size_t i = 0; i < conv.count; i++)
        assert_close(conv.y[i], raw.y[i] / (1 + raw.x[i]), 1e-15 * fabs(raw.y[i]));
    cf_table_free(&conv);
    cf_table_free(&raw);
}

/* Bad declarations: an unknown measure or mode, two different declarations, a comment and a
** column that disagree, a log strain of simple shear, a Cauchy force. An option wins over the
** file and says so. */
static void bad_declarations_are_refused_with_the_line(void **state)
{
    (void)state;
    cf_measure_options o = cf_measure_default_options();
    const char *rows = "0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n";
    char text[512];
    snprintf(text, sizeof text, "# stress: piola2\nstrain,stress_kPa\n%s", rows);
    load_fails(table("b1.csv", text), &o, ":1:1: unknown stress measure");
    snprintf(text, sizeof text, "# mode: torsion\nstrain,stress_kPa\n%s", rows);
    load_fails(table("b2.csv", text), &o, ":1:1: comment 'mode: torsion'");
    /* a biaxial table without its ratio (the reading itself: tests/unit/test_biaxial.c) */
    snprintf(text, sizeof text, "# mode: biaxial\nstrain,stress_kPa\n%s", rows);
    load_fails(table("b2b.csv", text), &o, "'# ratio: A:B'");
    snprintf(text, sizeof text, "# stress: cauchy\n# stress: nominal\nstrain,stress_kPa\n%s", rows);
    load_fails(table("b3.csv", text), &o, ":2:1: stress measure declared twice");
    snprintf(text, sizeof text, "# stress: nominal\nstrain,true_stress_kPa\n%s", rows);
    load_fails(table("b4.csv", text), &o, "column 'true_stress_kPa' is named for 'cauchy'");
    snprintf(text, sizeof text, "# mode: shear\n# strain: log\ngamma,stress_kPa\n%s", rows);
    load_fails(table("b5.csv", text), &o, "simple-shear");
    snprintf(text, sizeof text, "# stress: cauchy\ndisplacement_mm,force_N\n%s", rows);
    load_fails(table("b6.csv", text), &o, "is a force");
    /* the option wins over the comment, and the table records both */
    snprintf(text, sizeof text, "# stress: cauchy\nstrain,stress_kPa\n%s", rows);
    o.stress_measure = CF_STRESS_NOMINAL;
    cf_table t;
    load_ok(table("b7.csv", text), &o, &t);
    assert_int_equal(t.measures.stress, CF_STRESS_NOMINAL);
    assert_int_equal(t.measures.stress_from, CF_DECL_OPTION);
    assert_true(t.measures.stress_overridden);
    assert_false(t.measures.stress_converted);
    assert_close(t.y[5], 5e-3, 0);
    cf_table_free(&t);
}

/* Through the program: the report says which measures it assumed or read and what it converted;
** a bad measure flag is a usage error (2); a bad declaration is bad data (65), nothing written. */
static void the_report_states_the_measures(void **state)
{
    (void)state;
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit data/telescoping.csv"), 0);
    assert_non_null(strstr(out, "measures: stress nominal (assumed), strain engineering (assumed)"));
    const char *p = table("r.csv", "# stress: cauchy\nstrain,stress_kPa\n0,0\n0.1,0.55\n0.2,1.2\n"
                                   "0.3,2.6\n0.4,4.2\n0.5,6\n0.55,7.5\n");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s", p), 0);
    assert_non_null(strstr(out, "stress cauchy (comment, line 1)"));
    assert_non_null(strstr(out, "Cauchy stress converted to nominal"));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s --stress-measure nominal", p),
                     0);
    assert_non_null(strstr(out, "which wins over the table's 'cauchy'"));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s --stress-measure piola2", p),
                     2);
    assert_non_null(strstr(errb, "piola2"));
    char o[600];
    snprintf(o, sizeof o, "%s/never.json", dir);
    const char *bad = table("bad.csv", "# strain: bogus\nstrain,stress_kPa\n0,0\n0.1,1\n0.2,2\n"
                                       "0.3,3\n0.4,4\n0.5,5\n");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s", bad, o), 65);
    assert_non_null(strstr(errb, "bogus"));
    struct stat st;
    assert_int_not_equal(stat(o, &st), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cauchy_uniaxial_is_divided_by_the_stretch),
        cmocka_unit_test(the_mode_decides_the_conversion),
        cmocka_unit_test(log_strain_becomes_engineering_strain),
        cmocka_unit_test(skin_table_is_converted),
        cmocka_unit_test(bad_declarations_are_refused_with_the_line),
        cmocka_unit_test(the_report_states_the_measures),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
