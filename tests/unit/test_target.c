/*
** Tests of the fit through the lattice (`conifit fit --target lattice`) and of test modes: on
** noiseless tables made from known springs and reaching 95 % of the solid strain, in tension and
** in compression, the full lattice of the reported spring lies within 1.5 % of the table's largest
** stress (a single-spring fit validated in the same lattice does not); on the shipped noisy table
** the lattice error is within 1.3 times the spring fit's own; the verification in the full lattice
** agrees with the homogenised cell; a table's '# mode:' comment is read, --mode wins, a shear table
** is fitted and validated in shear; bad modes are refused.
*/
#include "testutil.h"

#include <jansson.h>

#include "model/law_internal.h"
#include "model/cell.h"

static char out[1 << 16], errb[1 << 14];

static double num_at(json_t *obj, const char *key)
{
    json_t *v = json_object_get(obj, key);
    if (!json_is_number(v))
        fail_msg("key '%s' is missing or not a number", key);
    return json_number_value(v);
}

/* Writes the table of spring p from 0 to frac of its solid strain (sign: +1 tension, -1
** compression), 40 rows, optionally with a mode comment; returns the largest |stress| in kPa. */
static double write_spring_table(const char *path, const cf_spring *p, double frac, int sign,
                                 const char *mode)
{
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    if (mode)
        fprintf(f, "# mode: %s\n", mode);
    fprintf(f, "strain,stress_kPa\n");
    double H = law.p.H_mm, smax = 0;
    for (int i = 0; i <= 40; i++) {
        double e = frac * law.travel_mm / H * i / 40;
        double s = cf_law_force(&law, CF_LAW_EXACT, e * H, NULL, NULL) / (H * H) * 1e3;
        fprintf(f, "%.17g,%.17g\n", sign * e, sign * s);
        smax = fmax(smax, s);
    }
    fclose(f);
    return smax;
}

/* Runs fit with the given target on table and returns (in kPa) the fit file's validation RMSE
** of fits[0]; *fit_rmse the fit RMSE of its target. */
static double lattice_rmse(const char *table, const char *json, const char *target,
                           double *fit_rmse, double *verify)
{
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s --type non-telescoping --target %s --validate -o %s --quiet", table,
                    target, json);
    if (st != 0)
        fail_msg("%s --target %s: exit %d: %s", table, target, st, errb);
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    assert_non_null(root);
    json_t *f = json_array_get(json_object_get(root, "fits"), 0);
    json_t *v = json_object_get(f, "validation");
    assert_string_equal(json_string_value(json_object_get(v, "model")), "full lattice");
    double r = num_at(v, "rmse");
    *fit_rmse = num_at(v, "fit_rmse");
    json_t *t = json_object_get(f, "through_msm");
    *verify = t && json_is_true(json_object_get(t, "verified")) ? num_at(t, "verification_max_abs")
                                                                 : -1;
    json_decref(root);
    return r;
}

static void lattice_target_reproduces_deep_known_spring_tables(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char table[256], json[256];
    snprintf(table, sizeof table, "%s/t.csv", dir);
    snprintf(json, sizeof json, "%s/t.json", dir);
    const cf_spring springs[2] = {{6, 15, 2.5, 2, 26, 10}, {8, 20, 3, 1.5, 200, 6}};
    for (int k = 0; k < 2; k++)
        for (int sign = -1; sign <= 1; sign += 2) {
            double smax = write_spring_table(table, &springs[k], 0.95, sign, NULL);
            double fr_s, fr_l, ver_s, ver_l;
            double spring = lattice_rmse(table, json, "spring", &fr_s, &ver_s);
            double lattice = lattice_rmse(table, json, "lattice", &fr_l, &ver_l);
            /* the single spring fits to rounding, but its lattice is several percent off */
            assert_true(fr_s < 1e-9 * smax);
            if (!(spring > 0.03 * smax))
                fail_msg("spring %d sign %d: spring fit in the lattice %.4g kPa of %.4g", k, sign,
                         spring, smax);
            if (!(lattice <= 0.015 * smax))
                fail_msg("spring %d sign %d: --target lattice leaves %.4g kPa (%.2f %% of %.4g)",
                         k, sign, lattice, 100 * lattice / smax, smax);
            /* the cell's fit error is the full lattice's, to the solver's tolerance */
            assert_true(fabs(fr_l - lattice) <= 1e-6 * smax);
            assert_true(ver_l >= 0 && ver_l <= 1e-8 * smax);
        }
    remove(table);
    remove(json);
    rmdir(dir);
}

static void lattice_target_on_the_shipped_noisy_table_is_near_the_spring_fit(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/n.json", dir);
    double fr_s, fr_l, v_s, v_l;
    const char *table = "data/telescoping_noise1pct.csv";
    double spring = lattice_rmse(table, json, "spring", &fr_s, &v_s);
    double lattice = lattice_rmse(table, json, "lattice", &fr_l, &v_l);
    assert_true(v_s < 0); /* no fit through the lattice with --target spring */
    if (!(lattice <= 1.3 * fr_s && lattice < spring))
        fail_msg("lattice rmse %.4g kPa against the spring fit's %.4g (spring in the lattice "
                 "%.4g)", lattice, fr_s, spring);
    remove(json);
    rmdir(dir);
}

/* Writes mode m's cell curve of spring p (isotropic lattice) from 0 to e_end, 25 rows. */
static void write_cell_table(const char *path, const cf_spring *p, cf_mode m, double e_end)
{
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    double w[3];
    cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, w, NULL), CF_OK);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "# mode: %s\nstrain,stress_kPa\n", cf_mode_name(m));
    for (int i = 0; i <= 24; i++) {
        cf_cell_state s;
        double e = e_end * i / 24;
        assert_int_equal(cf_cell_mode(&c, m, e, NULL, &s, NULL), CF_OK);
        fprintf(f, "%.17g,%.17g\n", e, s.stress_MPa * 1e3);
    }
    fclose(f);
}

/* A table made as the cell's simple-shear curve of a known spring is read as shear from its
** comment, fitted through the lattice by default, validated by the homogenised cell, and the
** JSON names the mode; --mode uniaxial makes it a uniaxial table again. */
static void shear_table_is_fitted_and_validated_in_shear(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char table[256], json[256];
    snprintf(table, sizeof table, "%s/shear.csv", dir);
    snprintf(json, sizeof json, "%s/s.json", dir);
    cf_spring p = {6, 15, 2.5, 2, 26, 10};
    write_cell_table(table, &p, CF_MODE_SHEAR, 0.6);
    const double tol_kPa = 1e-3; /* the table reaches a few tenths of a kPa and more */
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s --type non-telescoping -o %s", table, json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "mode shear"));
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    json_t *v = json_object_get(fit, "validation");
    assert_string_equal(json_string_value(json_object_get(v, "mode")), "shear");
    assert_string_equal(json_string_value(json_object_get(v, "model")), "homogenised cell");
    assert_non_null(json_object_get(fit, "through_msm"));
    if (!(num_at(v, "rmse") <= tol_kPa))
        fail_msg("shear through the lattice: rmse %.4g kPa", num_at(v, "rmse"));
    json_decref(root);
    /* --mode wins over the comment */
    st = tu_run(out, sizeof out, errb, sizeof errb,
                "fit %s --type non-telescoping --mode uniaxial --validate -o %s", table, json);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "mode uniaxial"));
    remove(table);
    remove(json);
    rmdir(dir);
}

/* The validation states the lattice's stability limit: the shipped compression table reaches past
** it (warning, stable_in_range false), the tension table does not (stable to its end). */
static void validation_reports_the_stability_limit(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/s.json", dir);
    const char *tables[2] = {"data/telescoping_compression.csv", "data/telescoping.csv"};
    for (int k = 0; k < 2; k++) {
        int st = tu_run(out, sizeof out, errb, sizeof errb,
                        "fit %s --type telescoping --validate -o %s", tables[k], json);
        if (st != 0)
            fail_msg("%s: exit %d: %s", tables[k], st, errb);
        json_error_t e;
        json_t *root = json_load_file(json, 0, &e);
        assert_non_null(root);
        json_t *v = json_object_get(json_array_get(json_object_get(root, "fits"), 0),
                                    "validation");
        json_t *lim = json_object_get(v, "stable_to_strain");
        if (k == 0) {
            assert_non_null(lim);
            double x = json_number_value(lim);
            assert_true(json_is_number(lim) && x < 0 && x > -0.6);
            assert_true(json_is_false(json_object_get(v, "stable_in_range")));
            assert_non_null(strstr(errb, "loses stability at strain"));
            assert_non_null(strstr(out, "lattice stable"));
        } else {
            /* stable over the whole range: the limit is the table's end */
            assert_true(json_is_number(lim) && json_number_value(lim) > 0.3);
            assert_true(json_is_true(json_object_get(v, "stable_in_range")));
            assert_null(strstr(errb, "loses stability"));
        }
        json_decref(root);
    }
    remove(json);
    rmdir(dir);
}

/* Tension, compression and shear tables of one known lattice, fitted jointly, are each recovered
** (fit and full-lattice RMSE far below their stresses); the fit file lists the tables. */
static void joint_fit_recovers_one_lattice_from_three_modes(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char tb[3][256], json[256], png[256];
    const cf_mode modes[3] = {CF_MODE_UNIAXIAL, CF_MODE_UNIAXIAL, CF_MODE_SHEAR};
    const double ends[3] = {0.35, -0.3, 0.5};
    cf_spring p = {6, 15, 2.5, 2, 26, 10};
    for (int k = 0; k < 3; k++) {
        snprintf(tb[k], sizeof tb[k], "%s/t%d.csv", dir, k);
        write_cell_table(tb[k], &p, modes[k], ends[k]);
    }
    snprintf(json, sizeof json, "%s/j.json", dir);
    snprintf(png, sizeof png, "%s/j.png", dir);
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s %s %s --joint --type non-telescoping -o %s --plot %s", tb[0], tb[1],
                    tb[2], json, png);
    if (st != 0)
        fail_msg("exit %d: %s", st, errb);
    assert_non_null(strstr(out, "Joint fit through the lattice of 3 tables"));
    assert_int_equal(access(png, F_OK), 0);
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    assert_non_null(root);
    assert_true(json_is_true(json_object_get(root, "joint")));
    json_t *tabs = json_object_get(root, "tables");
    assert_int_equal(json_array_size(tabs), 3);
    for (size_t k = 0; k < 3; k++) {
        json_t *t = json_array_get(tabs, k);
        assert_string_equal(json_string_value(json_object_get(t, "mode")),
                            cf_mode_name(modes[k]));
        assert_int_equal(json_integer_value(json_object_get(t, "points")), 25);
        double r = num_at(t, "rmse"), l = num_at(t, "lattice_rmse");
        if (!(r < 1e-3 && l < 1e-3)) /* kPa; the tables reach about 0.3 to 1 kPa */
            fail_msg("table %zu: rmse %.3g kPa, lattice %.3g kPa", k, r, l);
    }
    json_decref(root);
    /* bad input: fitted weights from one table, a fitted calibration without --joint, -o a
    ** folder (one table alone is a joint fit of that table) */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit %s --joint --calibration fitted", tb[0]),
                     2);
    assert_non_null(strstr(errb, "--calibration fitted"));
    assert_int_equal(
        tu_run(out, sizeof out, errb, sizeof errb, "fit %s --calibration fitted", tb[0]), 2);
    assert_non_null(strstr(errb, "--joint"));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s %s --joint -o %s/",
                            tb[0], tb[1], dir),
                     2);
    for (int k = 0; k < 3; k++)
        remove(tb[k]);
    remove(json);
    remove(png);
    rmdir(dir);
}

static void bad_modes_are_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-target-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char table[256], json[256];
    snprintf(table, sizeof table, "%s/bad.csv", dir);
    snprintf(json, sizeof json, "%s/b.json", dir);
    cf_spring p = {6, 15, 2.5, 2, 26, 10};
    write_spring_table(table, &p, 0.5, 1, "torsion");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s", table, json), 65);
    assert_non_null(strstr(errb, "bad.csv:1:"));
    assert_non_null(strstr(errb, "torsion"));
    assert_int_equal(access(json, F_OK), -1);
    write_spring_table(table, &p, 0.5, 1, NULL);
    assert_int_equal(
        tu_run(out, sizeof out, errb, sizeof errb, "fit %s --mode twist -o %s", table, json), 2);
    assert_non_null(strstr(errb, "twist"));
    assert_int_equal(
        tu_run(out, sizeof out, errb, sizeof errb, "fit %s --target cell -o %s", table, json), 2);
    assert_non_null(strstr(errb, "--target"));
    assert_int_equal(access(json, F_OK), -1);
    remove(table);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lattice_target_reproduces_deep_known_spring_tables),
        cmocka_unit_test(lattice_target_on_the_shipped_noisy_table_is_near_the_spring_fit),
        cmocka_unit_test(shear_table_is_fitted_and_validated_in_shear),
        cmocka_unit_test(validation_reports_the_stability_limit),
        cmocka_unit_test(joint_fit_recovers_one_lattice_from_three_modes),
        cmocka_unit_test(bad_modes_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
