/*
** Huge and odd values of the fit's limit flags and of the scene's numeric keys: each is refused up
** front, naming the flag (exit 2) or key (exit 65) and the value, or yields what it asks for: a
** spring inside the limits, a lattice that is solved. Never an absurd spring marked feasible, never
** an internal error at strain 0.
*/
#include "testutil.h"

#include <jansson.h>

#include "fit/fit.h"
#include "io/measure.h"

static char out[1 << 16], errb[1 << 14];

/* Beyond its documented bound each flag is refused with its name and value (the value 1e308 once
** gave a "feasible" spring of D1 = 1e-6 mm and G = 1e-15 MPa with an RMSE a thousand times the
** default's). */
static void limit_flags_beyond_their_bounds_are_refused(void **state)
{
    (void)state;
    static const struct {
        const char *flag, *value;
    } bad[] = {{"--index-max", "1e308"}, {"--index-max", "51"},     {"--index-max", "2.9"},
               {"--n-max", "1e308"},     {"--n-max", "1001"},      {"--n-max", "1.5"},
               {"--G-max", "1e308"},     {"--G-max", "2e6"},       {"--G-max", "0"},
               {"--D2-max-H", "1e308"},  {"--D2-max-H", "1001"},   {"--D2-max-H", "-1"},
               {"--rho-min", "1e-308"},  {"--rho-min", "0.0009"},  {"--rho-min", "1"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        int st = tu_run(out, sizeof out, errb, sizeof errb, "fit data/strongly_conical.csv %s %s -q",
                        bad[k].flag, bad[k].value);
        if (st != 2 || !strstr(errb, bad[k].flag))
            fail_msg("%s %s: exit %d (want 2): %s", bad[k].flag, bad[k].value, st, errb);
        char v[64];
        snprintf(v, sizeof v, "%g", strtod(bad[k].value, NULL));
        if (!strstr(errb, v))
            fail_msg("%s %s: the message does not name the value: %s", bad[k].flag, bad[k].value,
                     errb);
    }
}

/* The library refuses the same options (a front end that skips the command line). */
static void library_refuses_limits_beyond_their_bounds(void **state)
{
    (void)state;
    double x[8] = {0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7}, y[8];
    for (int i = 0; i < 8; i++)
        y[i] = x[i] * (1 + 3 * x[i] * x[i]);
    cf_table t;
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 8, x, y, NULL, &t, NULL), CF_OK);
    for (int k = 0; k < 5; k++) {
        cf_fit_options o = cf_fit_default_options();
        if (k == 0)
            o.index_max = 1e308;
        else if (k == 1)
            o.upper[CF_P_N] = 1e308;
        else if (k == 2)
            o.upper[CF_P_G] = 1e308;
        else if (k == 3)
            o.D2_over_H_max = 1e308;
        else
            o.rho_min = 1e-308;
        cf_fit_result r;
        cf_error err = {0};
        assert_int_equal(cf_fit_run(&t, &o, CF_TELESCOPING, &r, &err), CF_E_DATA);
        assert_non_null(strstr(err.msg, "e+308") ? err.msg : strstr(err.msg, "e-308"));
    }
    cf_table_free(&t);
}

/* Every flag at its widest bound at once: both types fit, inside those limits and the parameter
** bounds, within 5 % of the RMSE with the defaults (the wider range is searched by the same grid:
** the nearly cylindrical table's telescoping fit lands 1.7 % above it). */
static void limit_flags_at_their_bounds_give_feasible_springs(void **state)
{
    (void)state;
    static const char *const tables[] = {"strongly_conical", "nearly_cylindrical",
                                         "telescoping_noise1pct"};
    char dir[] = "/tmp/conifit-bounds-XXXXXX", a[300], b[300];
    assert_non_null(mkdtemp(dir));
    snprintf(a, sizeof a, "%s/wide.json", dir);
    snprintf(b, sizeof b, "%s/default.json", dir);
    for (size_t k = 0; k < sizeof tables / sizeof tables[0]; k++) {
        int st = tu_run(out, sizeof out, errb, sizeof errb,
                        "fit data/%s.csv --index-max 50 --n-max 1000 --G-max 1e6 --D2-max-H 1000 "
                        "--rho-min 0.001 -q -o %s",
                        tables[k], a);
        if (st != 0)
            fail_msg("%s at the bounds: exit %d: %s", tables[k], st, errb);
        assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit data/%s.csv -q -o %s",
                                tables[k], b),
                         0);
        json_t *w = json_load_file(a, 0, NULL), *d = json_load_file(b, 0, NULL);
        assert_non_null(w);
        assert_non_null(d);
        for (int f = 0; f < 2; f++) {
            json_t *fw = json_array_get(json_object_get(w, "fits"), (size_t)f);
            json_t *fd = json_array_get(json_object_get(d, "fits"), (size_t)f);
            assert_true(json_is_true(json_object_get(fw, "feasible")));
            json_t *p = json_object_get(fw, "params");
            double D1 = json_real_value(json_object_get(p, "D1_mm"));
            double D2 = json_real_value(json_object_get(p, "D2_mm"));
            double n = json_real_value(json_object_get(p, "n"));
            double d_ = json_real_value(json_object_get(p, "d_mm"));
            double G = json_real_value(json_object_get(p, "G_MPa"));
            double H = json_real_value(json_object_get(p, "H_mm"));
            assert_true(D1 / d_ >= 3 * (1 - 1e-9) && D1 / d_ <= 50 * (1 + 1e-9));
            assert_true(n >= 2 * (1 - 1e-12) && n <= 1000);
            assert_true(G > 0 && G <= 1e6 * (1 + 1e-12));
            assert_true(D2 <= 1000 * H * (1 + 1e-9) && D1 / D2 >= 1e-3 * (1 - 1e-6));
            assert_true(d_ >= 1e-3 && H >= 1e-3 && D2 <= 1e6); /* a wire, a length, a coil */
            double rw = json_real_value(json_object_get(fw, "rmse"));
            double rd = json_real_value(json_object_get(fd, "rmse"));
            if (!(rw <= rd * 1.05 + 1e-12))
                fail_msg("%s, fit %d: RMSE %g with the widest limits against %g by default",
                         tables[k], f, rw, rd);
        }
        json_decref(w);
        json_decref(d);
    }
    remove(a);
    remove(b);
    rmdir(dir);
}

/* A scene file in dir from the shipped uniaxial scene with a 2^3 lattice and the given extra keys
** (JSON members, may be empty). */
static void scene(const char *path, const char *lattice, const char *extra)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
            "\"G_MPa\": 26, \"H_mm\": 10}},\n \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2%s},\n"
            " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.45, \"duration_s\": 1},\n"
            " \"samples_per_segment\": 10%s}\n",
            lattice, extra);
    fclose(f);
}

/* Scene keys at their bounds are solved (a diagonal weight of 1e4 to 1e6, a thousand implicit
** substeps of a dashpot lattice, a step of 1e-4 s in a long row of cells: each ended with exit 70,
** its force rounding above the Newton floor); beyond them, or where the solver cannot meet them, refused up front with
** the key (exit 65). */
static void scene_values_are_solved_or_refused_with_their_key(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-bounds-XXXXXX", sc[300], csv[300];
    assert_non_null(mkdtemp(dir));
    snprintf(sc, sizeof sc, "%s/s.json", dir);
    snprintf(csv, sizeof csv, "%s/s.csv", dir);
    static const char *const weights[] = {", \"diagonal_weight\": 1e4",
                                          ", \"diagonal_weight\": 1e6"};
    for (int k = 0; k < 2; k++) {
        scene(sc, weights[k], "");
        int st = tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv);
        if (st != 0)
            fail_msg("%s: exit %d: %s", weights[k], st, errb);
    }
    scene(sc, ", \"diagonal_weight\": 1.1e6", "");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv),
                     65);
    assert_non_null(strstr(errb, "lattice.diagonal_weight"));
    /* implicit steps of a dashpot lattice, many of them */
    scene(sc, "", ",\n \"effects\": {\"damping\": {\"eta_kPa_s\": 5}},"
                  " \"integrator\": {\"substeps\": 1000}");
    int st = tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv);
    if (st != 0)
        fail_msg("1000 substeps: exit %d: %s", st, errb);
    /* dt_s = 1e-4 s in a row of 1000 cells, through a held strain: the dashpots' forces
    ** kx (L - Lprev) are rounded to kx times the ulp of coordinates up to 1e4 mm, not of the 10 mm
    ** springs, and the Newton floor taken from kx L left the hold's first step stalled at 1.9 times
    ** it ("equilibrium not found", exit 70, after halving the step down to nothing) */
    FILE *f = fopen(sc, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
               "\"G_MPa\": 26, \"H_mm\": 10}},\n \"lattice\": {\"nx\": 1000, \"ny\": 1, \"nz\": 1},\n"
               " \"protocol\": {\"kind\": \"hold\", \"to_strain\": 0.3, \"ramp_s\": 5e-4, "
               "\"hold_s\": 2e-4},\n \"effects\": {\"damping\": {\"eta_kPa_s\": 5}},"
               " \"integrator\": {\"dt_s\": 1e-4}, \"samples_per_segment\": 5}\n");
    fclose(f);
    st = tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv);
    if (st != 0)
        fail_msg("dt_s 1e-4 in a row of 1000 cells: exit %d: %s", st, errb);
    /* a million: beyond the step budget, refused before anything runs */
    scene(sc, "", ",\n \"effects\": {\"damping\": {\"eta_kPa_s\": 5}},"
                  " \"integrator\": {\"substeps\": 1000000}");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv),
                     65);
    assert_non_null(strstr(errb, "integrator.substeps"));
    /* an explicit step above the stable one */
    scene(sc, "", ",\n \"effects\": {\"inertia\": true, \"damping\": {\"eta_kPa_s\": 5}},"
                  " \"integrator\": {\"dt_s\": 1e-3}");
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "simulate %s -o %s -q", sc, csv),
                     65);
    assert_non_null(strstr(errb, "integrator.dt_s"));
    remove(sc);
    remove(csv);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(limit_flags_beyond_their_bounds_are_refused),
        cmocka_unit_test(library_refuses_limits_beyond_their_bounds),
        cmocka_unit_test(limit_flags_at_their_bounds_give_feasible_springs),
        cmocka_unit_test(scene_values_are_solved_or_refused_with_their_key),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
