/*
** Tests that every headline number of a fit is its target's. On published tables in shear,
** planar and equibiaxial modes, in a uniaxial fit through the lattice and in a joint fit: the fit
** file's top-level RMSE and R^2 are the lattice's (the cell's RMSE the fit reports, the
** validation's), the target is stated, and every identifiable quantity has a standard error or a
** profile interval. On the hydrogel compression table, whose single-spring and lattice figures
** favour different types, the type verdict is the lattice's. The shipped example's lattice RMSE
** with --validate alone is within 10 % of the fit's. A fit file states its target and export
** reads it back (an older file without it is a spring's).
*/
#include "testutil.h"

#include <jansson.h>

#include "io/fitfile.h"

static char out[1 << 16], errb[1 << 14];

TU_SCRATCH_GROUP("targetnum")

static double num_at(json_t *obj, const char *key)
{
    json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("key '%s' is missing or not a number", key);
    return json_number_value(v);
}

static void close_rel(const char *what, double got, double want, double rel)
{
    if (!(fabs(got - want) <= rel * fmax(fabs(want), 1e-300)))
        fail_msg("%s: %.17g, expected %.17g (relative %.1g)", what, got, want, rel);
}

/* Every identifiable quantity of fit f has a standard error or a profile interval, finite and
** holding its value, and the correlation is a matrix or says why not. */
static void every_quantity_has_an_uncertainty(json_t *f, const char *table)
{
    static const char *const keys[3] = {"rho", "solid_strain", "stress_scale_MPa"};
    json_t *id = json_object_get(f, "identifiable");
    for (int k = 0; k < 3; k++) {
        json_t *q = json_object_get(id, keys[k]);
        double v = num_at(q, "value");
        json_t *se = json_object_get(q, "stderr"), *iv = json_object_get(q, "interval");
        if (!se && !iv)
            fail_msg("%s: %s has neither a standard error nor an interval", table, keys[k]);
        if (se && !(json_number_value(se) >= 0 && isfinite(json_number_value(se))))
            fail_msg("%s: %s stderr %g", table, keys[k], json_number_value(se));
        if (iv) {
            double lo = json_number_value(json_array_get(iv, 0)),
                   hi = json_number_value(json_array_get(iv, 1));
            if (!(lo <= v && v <= hi && isfinite(lo) && isfinite(hi)))
                fail_msg("%s: %s = %g outside its interval [%g, %g]", table, keys[k], v, lo, hi);
            assert_non_null(json_string_value(json_object_get(q, "interval_reason")));
        }
        /* by the spring fit's rules: a fit held by a limit, or a Wald interval that leaves the
        ** quantity's range (rho and s/H in (0, 1], the stress scale > 0), gets a profile */
        const double e = se ? 1.96 * json_number_value(se) : 0,
                     top = k == 2 ? INFINITY : 1;
        if (json_array_size(json_object_get(f, "held_by")) > 0 || v - e <= 0 || v + e > top)
            if (!iv)
                fail_msg("%s: %s = %g +- %g (held by %zu limits) has no profile interval", table,
                         keys[k], v, e / 1.96, json_array_size(json_object_get(f, "held_by")));
    }
    json_t *c = json_object_get(f, "identifiable_correlation");
    assert_true(json_object_get(c, "matrix") || json_object_get(c, "reason"));
}

/* The fit file at json (caller frees the root) and its fits, which are the two types. */
static json_t *two_fits(const char *json, json_t **fits)
{
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    if (!root)
        fail_msg("%s: %s", json, e.text);
    *fits = json_object_get(root, "fits");
    assert_int_equal(json_array_size(*fits), 2);
    return root;
}

/* Fits table (in the published folder) with extra flags into a fit file and checks each fit:
** target lattice in mode, rmse = the cell's RMSE and the validation's, R^2 the validation's, the
** single spring's law figures only for uniaxial tables, an uncertainty for every quantity. */
static void check_lattice_target(const char *table, const char *flags, const char *mode)
{
    const char *ds = tu_datasets();
    char json[512];
    snprintf(json, sizeof json, "%s/%s.json", dir, table);
    int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s/%s %s -o %s", ds, table,
                    flags, json);
    if (st != 0)
        fail_msg("%s: exit %d: %s", table, st, errb);
    assert_non_null(strstr(out, "fit target: the lattice"));
    json_t *fits, *root = two_fits(json, &fits);
    for (size_t i = 0; i < 2; i++) {
        json_t *f = json_array_get(fits, i);
        json_t *t = json_object_get(f, "target");
        assert_string_equal(json_string_value(json_object_get(t, "model")), "lattice");
        assert_string_equal(json_string_value(json_object_get(t, "mode")), mode);
        double rmse = num_at(f, "rmse");
        json_t *v = json_object_get(f, "validation"), *th = json_object_get(f, "through_msm");
        close_rel("rmse vs the cell's", rmse, num_at(th, "cell_rmse"), 1e-12);
        close_rel("rmse vs validation.fit_rmse", rmse, num_at(v, "fit_rmse"), 1e-12);
        /* the full lattice (uniaxial) equals the cell where it deforms homogeneously */
        close_rel("rmse vs validation.rmse", rmse, num_at(v, "rmse"), 1e-6);
        close_rel("r2 vs validation.r2", num_at(f, "r2"), num_at(v, "r2"), 1e-6);
        close_rel("max error vs validation", num_at(f, "max_abs_error"),
                  num_at(v, "max_abs_error"), 1e-6);
        /* a shear table fitted through the cell is not reported as the law at eps = gamma */
        assert_true(num_at(f, "r2") > 0.5);
        json_t *law = json_object_get(f, "spring_law");
        if (strcmp(mode, "uniaxial") == 0) {
            assert_non_null(law);
            assert_true(num_at(law, "rmse") > 0);
        } else {
            assert_null(law);
        }
        every_quantity_has_an_uncertainty(f, table);
    }
    json_decref(root);
}

/* Shear, planar and equibiaxial tables (through the lattice by default), and uniaxial ones with
** --target lattice or --validate alone. */
static void fits_in_every_mode_report_the_lattice(void **state)
{
    (void)state;
    if (!tu_datasets())
        skip();
    static const char *const cases[][3] = {
        {"heart_myocardium_shear_fs.csv", "", "shear"},
        {"skin_porcine_stripbiaxial_x.csv", "", "planar"},
        {"aortic_valve_circumferential.csv", "", "equibiaxial"},
        {"heart_myocardium_biaxial_1to1_fiber.csv", "--validate", "equibiaxial"},
        {"brain_cortex_tension.csv", "--target lattice", "uniaxial"},
        {"brain_cortex_compression.csv", "--validate", "uniaxial"}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        check_lattice_target(cases[k][0], cases[k][1], cases[k][2]);
}

/* The hydrogel compression table: by the single springs' own law the types are about equal
** (non-telescoping marginally ahead); through the lattice telescoping is better beyond the
** F-test's threshold. The verdict, comparison and better type are the lattice's. */
static void type_verdict_is_the_lattice_s(void **state)
{
    (void)state;
    if (!tu_datasets())
        skip();
    char json[512];
    snprintf(json, sizeof json, "%s/hydrogel.json", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s/hydrogel_fibre_reinforced_compression.csv --target lattice -o %s",
                    tu_datasets(), json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "\nType: telescoping ("));
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    assert_non_null(root);
    assert_string_equal(json_string_value(json_object_get(root, "better_type")), "telescoping");
    json_t *c = json_object_get(root, "comparison");
    assert_false(json_is_true(json_object_get(c, "tie")));
    assert_true(num_at(c, "delta_weighted_rss") > num_at(c, "threshold_weighted_rss"));
    json_t *fits = json_object_get(root, "fits");
    json_t *tel = json_array_get(fits, 0), *non = json_array_get(fits, 1);
    assert_string_equal(json_string_value(json_object_get(tel, "type")), "telescoping");
    double cell_t = num_at(json_object_get(tel, "through_msm"), "cell_rmse"),
           cell_n = num_at(json_object_get(non, "through_msm"), "cell_rmse");
    close_rel("rmse ratio", num_at(c, "rmse_ratio_other_to_better"), cell_n / cell_t, 1e-12);
    /* the single spring's own figures point the other way */
    double law_t = num_at(json_object_get(tel, "spring_law"), "rmse"),
           law_n = num_at(json_object_get(non, "spring_law"), "rmse");
    if (!(cell_t < cell_n && law_n < law_t))
        fail_msg("lattice %g vs %g, spring law %g vs %g", cell_t, cell_n, law_t, law_n);
    json_decref(root);
}

/* Joint fit of a tissue's tension, compression and shear tables: each table's RMSE is the
** lattice's (the cell's, and the full lattice's for the uniaxial ones), and each quantity has an
** uncertainty with the tables' weights. */
static void joint_fit_has_uncertainty_for_every_quantity(void **state)
{
    (void)state;
    const char *ds = tu_datasets();
    if (!ds)
        skip();
    char json[512];
    snprintf(json, sizeof json, "%s/joint.json", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s/brain_cortex_tension.csv %s/brain_cortex_compression.csv "
                    "%s/brain_cortex_shear.csv --joint -o %s --quiet",
                    ds, ds, ds, json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_null(strstr(out, "no error"));
    json_t *fits, *root = two_fits(json, &fits);
    for (size_t i = 0; i < 2; i++) {
        json_t *f = json_array_get(fits, i);
        assert_string_equal(
            json_string_value(json_object_get(json_object_get(f, "target"), "model")), "lattice");
        every_quantity_has_an_uncertainty(f, "joint");
        json_t *tabs = json_object_get(f, "tables");
        for (size_t k = 0; k < 3; k++) {
            json_t *t = json_array_get(tabs, k);
            close_rel("joint table rmse", num_at(t, "rmse"), num_at(t, "lattice_rmse"), 1e-6);
        }
    }
    json_decref(root);
}

/* make example: the shipped table with --validate alone; the lattice's RMSE within 10 % of the
** fit's. */
static void example_lattice_rmse_is_the_fit_s(void **state)
{
    (void)state;
    char json[512];
    snprintf(json, sizeof json, "%s/example.json", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping_noise1pct.csv --validate -o %s --quiet", json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    assert_non_null(root);
    json_t *fits = json_object_get(root, "fits");
    for (size_t i = 0; i < json_array_size(fits); i++) {
        json_t *f = json_array_get(fits, i);
        double fit = num_at(f, "rmse"), lat = num_at(json_object_get(f, "validation"), "rmse");
        if (!(lat <= 1.1 * fit))
            fail_msg("fit %zu: lattice RMSE %g above 1.1 x the fit's %g", i, lat, fit);
    }
    json_decref(root);
}

/* The fit file's target is read back; a file without one (written before it existed) is a
** spring's; export --lattice of a spring-target fit says it was fitted as a single spring. */
static void fit_file_target_reads_back(void **state)
{
    (void)state;
    char lat[512], spr[512], old[512];
    snprintf(lat, sizeof lat, "%s/lat.json", dir);
    snprintf(spr, sizeof spr, "%s/spr.json", dir);
    snprintf(old, sizeof old, "%s/old.json", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping_noise1pct.csv --validate -o %s --quiet", lat),
                     0);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping_noise1pct.csv --validate --target spring -o %s",
                            spr),
                     0);
    assert_non_null(strstr(out, "fit target: the single spring"));
    cf_fitted_spring fs;
    cf_error err = {0};
    assert_int_equal(cf_fitfile_load(lat, NULL, &fs, &err), CF_OK);
    assert_int_equal(fs.target_lattice, 1);
    assert_int_equal(cf_fitfile_load(spr, NULL, &fs, &err), CF_OK);
    assert_int_equal(fs.target_lattice, 0);
    /* an older file: the same without its targets */
    json_error_t e;
    json_t *root = json_load_file(lat, 0, &e);
    assert_non_null(root);
    json_t *fits = json_object_get(root, "fits");
    for (size_t i = 0; i < json_array_size(fits); i++)
        json_object_del(json_array_get(fits, i), "target");
    assert_int_equal(json_dump_file(root, old, 0), 0);
    json_decref(root);
    assert_int_equal(cf_fitfile_load(old, NULL, &fs, &err), CF_OK);
    assert_int_equal(fs.target_lattice, 0);
    char inp[512];
    snprintf(inp, sizeof inp, "%s/l.inp", dir);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "export %s --lattice --format calculix -o %s", spr, inp),
                     0);
    assert_non_null(strstr(errb, "fitted as a single spring"));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "export %s --lattice --format calculix -o %s", lat, inp),
                     0);
    assert_null(strstr(errb, "fitted as a single spring"));
}

/* --target spring on a table in a mode the single spring has no curve of is refused (exit 2,
** naming the flag and the mode), not reported as the law at a uniaxial strain. */
static void spring_target_in_shear_is_refused(void **state)
{
    (void)state;
    if (!tu_datasets())
        skip();
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit %s/heart_myocardium_shear_fs.csv --target spring",
                            tu_datasets()),
                     2);
    assert_non_null(strstr(errb, "--target spring"));
    assert_non_null(strstr(errb, "shear"));
    /* given as uniaxial, it is the spring's to fit */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit %s/heart_myocardium_shear_fs.csv --target spring --mode uniaxial",
                            tu_datasets()),
                     0);
    assert_non_null(strstr(out, "fit target: the single spring"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fits_in_every_mode_report_the_lattice),
        cmocka_unit_test(type_verdict_is_the_lattice_s),
        cmocka_unit_test(joint_fit_has_uncertainty_for_every_quantity),
        cmocka_unit_test(example_lattice_rmse_is_the_fit_s),
        cmocka_unit_test(fit_file_target_reads_back),
        cmocka_unit_test(spring_target_in_shear_is_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
