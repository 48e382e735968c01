/*
** `fit --law`: the choice between the conical law and the conical spring with a tail as the
** command line sees it: the report shows both laws, the fit file names the law kept and carries the
** comparison, it goes through the lattice as the conical law does, and the combinations the tailed
** law does not support (a time series, fixed parameters) are usage errors (exit 2, nothing
** written); a joint fit of several tables compares both laws by its joint AIC.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <jansson.h>

#include "testutil.h"

static int exists(const char *p)
{
    return access(p, F_OK) == 0;
}

/* Runs `fit ARGS -o FILE` (exit 0), the report into out; the fit file, loaded (then removed). */
static json_t *fit_file_of(const char *args, char *out, size_t cap)
{
    char dir[] = "/tmp/conifit-law-XXXXXX", json[256];
    static char errb[1 << 14];
    assert_non_null(mkdtemp(dir));
    snprintf(json, sizeof json, "%s/t.json", dir);
    int st = tu_run(out, cap, errb, sizeof errb, "fit %s -o %s", args, json);
    if (st != 0)
        fail_msg("fit %s exited %d: %s", args, st, errb);
    json_error_t jerr;
    json_t *root = json_load_file(json, 0, &jerr);
    assert_non_null(root);
    remove(json);
    rmdir(dir);
    return root;
}

/* The law_comparison of fit f, present, its choice the law f names; the law kept. */
static const char *law_kept(json_t *f, json_t **lc)
{
    *lc = json_object_get(f, "law_comparison");
    assert_non_null(*lc);
    const char *kept = json_string_value(json_object_get(*lc, "chosen"));
    assert_string_equal(kept, json_string_value(json_object_get(f, "law")));
    return kept;
}

/* --law auto on a shipped table of a plain conical spring: both laws reported, the conical one
** kept (the tail cannot lower the AIC of an exact conical table by more than its extra term). */
static void auto_reports_both_laws(void **state)
{
    (void)state;
    static char out[1 << 16];
    json_t *root = fit_file_of("data/telescoping_noise1pct.csv --law auto", out, sizeof out);
    assert_non_null(strstr(out, "Law (--law auto)"));
    assert_non_null(strstr(out, "conical-tail RMSE"));
    json_t *fits = json_object_get(root, "fits");
    assert_true(json_array_size(fits) == 2);
    for (size_t i = 0; i < 2; i++) {
        json_t *lc;
        const char *kept = law_kept(json_array_get(fits, i), &lc);
        const double a0 = json_number_value(json_object_get(json_object_get(lc, "conical"), "aic"));
        const double a1 =
            json_number_value(json_object_get(json_object_get(lc, "conical-tail"), "aic"));
        /* the tail kept only with a lower AIC */
        assert_true(strcmp(kept, "conical-tail") != 0 || a1 < a0);
        assert_non_null(json_object_get(json_object_get(lc, "conical-tail"), "tail_compliance"));
    }
    json_decref(root);
}

/* --law conical-tail keeps the tailed law and writes its fourth quantity (the noisy telescoping
** table: the tailed spring of a noise-free conical table breaks a limit, and its tailed fit is
** the conical one with no tail). */
static void conical_tail_writes_the_tail(void **state)
{
    (void)state;
    static char out[1 << 16];
    json_t *root =
        fit_file_of("data/telescoping_noise1pct.csv --law conical-tail", out, sizeof out);
    assert_non_null(strstr(out, "tail compliance e_t"));
    assert_non_null(strstr(out, "n_tail"));
    json_t *f = json_array_get(json_object_get(root, "fits"), 0);
    assert_string_equal(json_string_value(json_object_get(f, "law")), "conical-tail");
    json_t *tc = json_object_get(json_object_get(f, "identifiable"), "tail_compliance");
    assert_non_null(tc);
    assert_true(json_number_value(json_object_get(tc, "value")) > 0);
    json_decref(root);
}

/* Through the lattice as the conical law: the lattice target of a uniaxial table and a table read
** in shear; the tailed law kept (conical-tail), its cell the fit's target, its fourth quantity and
** the comparison with the conical law's fit through the lattice written. */
static void conical_tail_goes_through_the_lattice(void **state)
{
    (void)state;
    static char out[1 << 16];
    const char *const cases[] = {
        "data/non_telescoping.csv --type non-telescoping --law conical-tail --target lattice",
        "data/non_telescoping.csv --type non-telescoping --law conical-tail --mode shear",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        json_t *root = fit_file_of(cases[i], out, sizeof out);
        assert_non_null(strstr(out, "fit target: the lattice"));
        assert_non_null(strstr(out, "conical-tail RMSE"));
        json_t *f = json_array_get(json_object_get(root, "fits"), 0);
        assert_string_equal(json_string_value(json_object_get(f, "law")), "conical-tail");
        assert_non_null(json_object_get(f, "through_msm"));
        json_t *tc = json_object_get(json_object_get(f, "identifiable"), "tail_compliance");
        assert_true(json_number_value(json_object_get(tc, "value")) > 0);
        json_t *lc = json_object_get(f, "law_comparison");
        assert_true(json_is_true(json_object_get(lc, "through_lattice")));
        /* in uniaxial the tailed spring's full lattice is the cell's curve to rounding */
        json_t *thr = json_object_get(f, "through_msm");
        if (i == 0) {
            assert_true(json_is_true(json_object_get(thr, "verified")));
            const double dv = json_number_value(json_object_get(thr, "verification_max_abs"));
            const double rmse = json_number_value(json_object_get(thr, "cell_rmse"));
            if (!(dv < 1e-9 && rmse > 0))
                fail_msg("full lattice against the cell: %g (fit RMSE %g)", dv, rmse);
        }
        json_decref(root);
    }
}

/* A force-displacement table has no lattice: with --target lattice the conical law's fit keeps
** its note and the tailed law goes to the spring, as without the option (exit 0). */
static void force_table_with_lattice_target_fits_the_tail_to_the_spring(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    static char out[1 << 16], args[1024];
    snprintf(args, sizeof args,
             "%s/thrombus_pureshear_force_displacement.csv --type non-telescoping "
             "--law conical-tail --target lattice",
             dir);
    json_t *root = fit_file_of(args, out, sizeof out);
    json_t *f = json_array_get(json_object_get(root, "fits"), 0);
    assert_string_equal(json_string_value(json_object_get(f, "law")), "conical-tail");
    json_t *lc = json_object_get(f, "law_comparison");
    assert_false(json_is_true(json_object_get(lc, "through_lattice")));
    json_decref(root);
}

/* The aortic valve leaflet read as uniaxial keeps the tail, whose four quantities the table trades
** against each other: the report prints each as value [low, high]* with the reason below, and the
** fit file gives each, the tail's compliance too, its interval and interval_reason. */
static void tailed_fit_reports_profile_intervals(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    static char out[1 << 16], args[1024];
    snprintf(args, sizeof args,
             "%s/aortic_valve_circumferential.csv --mode uniaxial --type non-telescoping "
             "--law auto",
             dir);
    json_t *root = fit_file_of(args, out, sizeof out);
    json_t *f = json_array_get(json_object_get(root, "fits"), 0);
    assert_string_equal(json_string_value(json_object_get(f, "law")), "conical-tail");
    const char *line = strstr(out, "tail compliance e_t");
    assert_non_null(line);
    const char *eol = strchr(line, '\n');
    assert_non_null(eol);
    const char *star = strstr(line, "]*");
    assert_true(star && star < eol);
    assert_non_null(strstr(out, "* non-telescoping, tail compliance: profile likelihood, 95 %"));
    json_t *id = json_object_get(f, "identifiable");
    static const char *const keys[4] = {"rho", "solid_strain", "stress_scale_MPa",
                                        "tail_compliance"};
    for (int k = 0; k < 4; k++) {
        json_t *q = json_object_get(id, keys[k]), *iv = json_object_get(q, "interval");
        assert_non_null(q);
        assert_true(json_array_size(iv) == 2);
        const double v = json_number_value(json_object_get(q, "value"));
        const double lo = json_number_value(json_array_get(iv, 0)),
                     hi = json_number_value(json_array_get(iv, 1));
        assert_true(lo <= v && v <= hi && lo < hi);
        assert_non_null(json_string_value(json_object_get(q, "interval_reason")));
    }
    /* the comparison of the laws carries the same */
    json_t *tc = json_object_get(json_object_get(json_object_get(f, "law_comparison"),
                                                 "conical-tail"),
                                 "tail_compliance");
    assert_true(json_array_size(json_object_get(tc, "interval")) == 2);
    json_decref(root);
}

/* What the tailed law does not do is refused with exit 2 and nothing written. */
static void unsupported_combinations_exit_2(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-law-XXXXXX", json[256];
    assert_non_null(mkdtemp(dir));
    snprintf(json, sizeof json, "%s/t.json", dir);
    static char out[1 << 14], errb[1 << 14];
    const char *const cases[] = {
        "fit data/telescoping.csv --law cone -o %s",
        "fit data/telescoping.csv --law auto --fix H=10 -o %s",
        "fit data/series/synthetic_relaxation.csv --law conical-tail -o %s",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int st = tu_run(out, sizeof out, errb, sizeof errb, cases[i], json);
        if (st != 2)
            fail_msg("'%s' exited %d: %s", cases[i], st, errb);
        assert_non_null(strstr(errb, "--law"));
        assert_false(exists(json));
    }
    rmdir(dir);
}

/* --joint --law auto: both laws fitted jointly for each type and reported, the fit file's law
** the one its comparison chose, the tail only with a lower joint AIC and a feasible spring. On
** the brain cortex tables (when present) the joint tailed spring exports as a lattice; auto keeps
** the double-acting element there, whose telescoping lattice exports with both springs. */
static void joint_auto_reports_both_laws(void **state)
{
    (void)state;
    static char out[1 << 16];
    json_t *root = fit_file_of("data/telescoping.csv data/non_telescoping.csv --joint --law auto",
                               out, sizeof out);
    assert_non_null(strstr(out, "Law (--law auto)"));
    assert_non_null(strstr(out, "conical-tail joint AIC"));
    json_t *fits = json_object_get(root, "fits");
    assert_true(json_array_size(fits) == 2);
    for (size_t i = 0; i < 2; i++) {
        json_t *f = json_array_get(fits, i), *lc;
        const char *kept = law_kept(f, &lc);
        assert_true(json_is_true(json_object_get(lc, "joint")));
        json_t *cone = json_object_get(lc, "conical"), *tail = json_object_get(lc, "conical-tail");
        const double a0 = json_number_value(json_object_get(cone, "aic"));
        const double a1 = json_number_value(json_object_get(tail, "aic"));
        assert_true(strcmp(kept, "conical-tail") != 0 ||
                    (a1 < a0 && json_is_true(json_object_get(tail, "feasible"))));
        assert_true(json_array_size(json_object_get(tail, "tables")) == 2);
        assert_true((json_object_get(json_object_get(f, "params"), "n_tail") != NULL) ==
                    (strcmp(kept, "conical-tail") == 0));
    }
    json_decref(root);
    const char *dir = tu_datasets();
    if (!dir)
        return;
    char tmp[] = "/tmp/conifit-law-XXXXXX", json[256], inp[256], args[1024];
    static char errb[1 << 14];
    assert_non_null(mkdtemp(tmp));
    snprintf(json, sizeof json, "%s/brain.json", tmp);
    snprintf(inp, sizeof inp, "%s/brain.inp", tmp);
    /* auto first: it keeps the pair, whose telescoping lattice exports with both springs along
    ** a scene's loading to the tables' 10 % compression (the kept elements' lattices are stable
    ** over the tables' range, not up to the default loading's half of the solid strain, which
    ** the export refuses); then the joint tailed fit, which exports with the default loading */
    char scene[300];
    snprintf(scene, sizeof scene, "%s/scene.json", tmp);
    FILE *sf = fopen(scene, "w");
    assert_non_null(sf);
    fprintf(sf, "{\"spring\": {\"fit\": \"%s\", \"type\": \"telescoping\"}, \"lattice\": "
                "{\"nx\": 2, \"ny\": 2, \"nz\": 2}, \"protocol\": {\"kind\": \"ramp\", "
                "\"to_strain\": 0.1, \"duration_s\": 1}, \"samples_per_segment\": 20}",
            json);
    fclose(sf);
    for (int law = 0; law < 2; law++) {
        snprintf(args, sizeof args, "%s/brain_cortex_tension.csv %s/brain_cortex_compression.csv "
                 "%s/brain_cortex_shear.csv --joint --law %s -o %s", dir, dir, dir,
                 law ? "conical-tail" : "auto", json);
        int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s", args);
        if (st != 0)
            fail_msg("fit %s exited %d: %s", args, st, errb);
        st = tu_run(out, sizeof out, errb, sizeof errb, "export %s --lattice %s --format calculix -o %s",
                    json, law ? "" : scene, inp);
        if (law == 0) {
            if (st != 0)
                fail_msg("export --lattice of the joint auto fit exited %d: %s", st, errb);
            char *x = tu_slurp(inp);
            assert_non_null(x);
            assert_non_null(strstr(x, "** extension spring"));
            free(x);
        } else if (st != 0) {
            fail_msg("export --lattice of the joint tailed fit exited %d: %s", st, errb);
        }
    }
    assert_true(exists(inp));
    remove(json);
    remove(inp);
    remove(scene);
    rmdir(tmp);
}

/* A tailed fit as the held elastic part of a time series keeps its tail: the fit file names the
** law conical-tail and carries the tail's compliance, and every placed spring has a tail. A
** tailed elastic part fitted with the series (--law conical-tail) is refused (exit 2), nothing
** written. */
static void tailed_elastic_part_is_held(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-law-XXXXXX", fit[256], json[256];
    assert_non_null(mkdtemp(dir));
    snprintf(fit, sizeof fit, "%s/tail.json", dir);
    snprintf(json, sizeof json, "%s/series.json", dir);
    static char out[1 << 16], errb[1 << 14];
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/non_telescoping_noise1pct.csv --law conical-tail --type "
                            "non-telescoping -o %s",
                            fit),
                     0);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/series/synthetic_relaxation.csv --law conical-tail -o %s",
                            json),
                     2);
    assert_non_null(strstr(errb, "--elastic"));
    assert_false(exists(json));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/series/synthetic_relaxation.csv --elastic %s -o %s", fit,
                            json),
                     0);
    json_error_t je;
    json_t *root = json_load_file(json, 0, &je);
    assert_non_null(root);
    json_t *it;
    size_t k;
    json_array_foreach(json_object_get(root, "fits"), k, it) {
        assert_string_equal(json_string_value(json_object_get(it, "law")), "conical-tail");
        assert_true(json_number_value(json_object_get(json_object_get(it, "params"), "n_tail")) >
                    0);
        assert_non_null(json_object_get(json_object_get(it, "identifiable"), "tail_compliance"));
    }
    json_decref(root);
    remove(json);
    remove(fit);
    rmdir(dir);
}

/* Both types' tailed joint fits of the shipped telescoping and non-telescoping tables reach the
** same objective, and the telescoping spring cannot be built: the better type is the one that
** can, and the report says why. */
static void joint_tie_prefers_the_buildable_spring(void **state)
{
    (void)state;
    static char out[1 << 16];
    json_t *root = fit_file_of("data/telescoping.csv data/non_telescoping.csv --joint "
                               "--law conical-tail",
                               out, sizeof out);
    const char *better = json_string_value(json_object_get(root, "better_type"));
    assert_non_null(better);
    json_t *fits = json_object_get(root, "fits");
    int seen = 0, infeasible = 0;
    for (size_t i = 0; i < json_array_size(fits); i++) {
        json_t *f = json_array_get(fits, i);
        const int feasible = json_is_true(json_object_get(f, "feasible"));
        infeasible |= !feasible;
        if (strcmp(json_string_value(json_object_get(f, "type")), better) == 0) {
            seen = 1;
            assert_true(feasible);
        }
    }
    assert_true(seen);
    if (infeasible)
        assert_non_null(strstr(out, "the other type's spring cannot be built"));
    json_decref(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(auto_reports_both_laws),
        cmocka_unit_test(conical_tail_writes_the_tail),
        cmocka_unit_test(conical_tail_goes_through_the_lattice),
        cmocka_unit_test(force_table_with_lattice_target_fits_the_tail_to_the_spring),
        cmocka_unit_test(tailed_fit_reports_profile_intervals),
        cmocka_unit_test(unsupported_combinations_exit_2),
        cmocka_unit_test(joint_auto_reports_both_laws),
        cmocka_unit_test(tailed_elastic_part_is_held),
        cmocka_unit_test(joint_tie_prefers_the_buildable_spring),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
