/*
** Fibre groups in lattice scenes ("fibres", io/scene_fibres.c; src/notes/simulate.md):
**  - every bad entry is refused with CF_E_DATA (exit 65 in the CLI) naming its key and value: a
**    zero or malformed axis, a missing, zero or negative density, an unknown key, a missing or
**    invalid spring, an empty or too long list; a fibre scene is refused by validation, which
**    would drop its fibres;
**  - a good entry's axis is normalised and its spring and density kept, and the lattice export
**    takes them (cf_export_lattice_from_scene);
**  - `conifit simulate`'s run (cf_pipeline_simulate) of a 3 x 3 x 3 lattice with a volume term and
**    a fibre group along z, stretched along z by 10 %, reports at every sample the homogenised
**    cell's uniaxial stress along z with the same group (1e-9 relative), and without the fibre
**    group a stress at least 1.3 times smaller in magnitude; the run is stable throughout;
**  - a scene naming a fibre fit file ("fibres": {"fit", "cross_axis"}) takes the fit's matrix
**    spring, its groups (along x, y, z for f, s, n), weights and kappa: stretched 10 % along n it
**    reports the fit's own homogenised cell (fibre_fit.c's model) to 1e-9 relative; the other
**    cross axis, a missing fit file, a spring or lattice weight beside it are refused naming
**    the key.
*/
#include "testutil.h"

#include <string.h>

#include "export/export.h"
#include "fit/fibre_fit.h"
#include "io/scene.h"
#include "model/cell.h"
#include "pipeline/simulate.h"

#define SPRING "\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, " \
               "\"G_MPa\": 26, \"H_mm\": 10}}"
#define FSPRING "{\"params\": {\"D1_mm\": 5, \"D2_mm\": 12, \"n\": 3, \"d_mm\": 1.5, " \
                "\"G_MPa\": 26, \"H_mm\": 8}}"
#define LATTICE "\"lattice\": {\"nx\": 3, \"ny\": 3, \"nz\": 3, \"volume_modulus_MPa\": 0.05}"
#define STRETCH "\"protocol\": {\"kind\": \"ramp\", \"to_strain\": -0.1}, \"samples_per_segment\": 5"

typedef struct bad_case {
    const char *fibres;    /* the value of "fibres" */
    const char *must_name; /* text the message must contain */
} bad_case;

static void bad_fibres_are_refused_naming_the_key(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        {"[{\"axis\": [0, 0, 0], \"density\": 1, \"spring\": " FSPRING "}]",
         "'fibres[0].axis' = [0, 0, 0]"},
        {"[{\"axis\": [1, 0], \"density\": 1, \"spring\": " FSPRING "}]", "'fibres[0].axis'"},
        {"[{\"axis\": \"z\", \"density\": 1, \"spring\": " FSPRING "}]", "'fibres[0].axis'"},
        {"[{\"density\": 1, \"spring\": " FSPRING "}]", "'fibres[0].axis'"},
        {"[{\"axis\": [0, 0, 1], \"spring\": " FSPRING "}]", "'fibres[0].density' is required"},
        {"[{\"axis\": [0, 0, 1], \"density\": 0, \"spring\": " FSPRING "}]",
         "'fibres[0].density' = 0"},
        {"[{\"axis\": [0, 0, 1], \"density\": -2, \"spring\": " FSPRING "}]",
         "'fibres[0].density' = -2"},
        {"[{\"axis\": [0, 0, 1], \"density\": 1}]", "'fibres[0].spring' is required"},
        {"[{\"axis\": [0, 0, 1], \"density\": 1, \"spring\": {\"params\": {\"D1_mm\": 5}}}]",
         "fibres[0].spring.params"},
        {"[{\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING ", \"dir\": 1}]",
         "'fibres[0].dir'"},
        {"[{\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "}, 3]", "'fibres[1]'"},
        {"[]", "'fibres'"},
        {"{\"axis\": [0, 0, 1]}", "'fibres.axis'"}, /* an object is a fibre fit's */
        {"[{\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "},"
         " {\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "},"
         " {\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "},"
         " {\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "},"
         " {\"axis\": [0, 0, 1], \"density\": 1, \"spring\": " FSPRING "}]",
         "1 to 4"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char json[4096];
        snprintf(json, sizeof json, "{" SPRING ", " LATTICE ", " STRETCH ", \"fibres\": %s}",
                 cases[i].fibres);
        cf_scene sc;
        cf_error err = {0};
        const cf_status st = cf_scene_parse(json, "s.json", &sc, &err);
        if (st == CF_OK)
            cf_scene_free(&sc);
        if (st != CF_E_DATA || !strstr(err.msg, cases[i].must_name))
            fail_msg("case %zu: status %d, message '%s' (expected '%s')", i, (int)st, err.msg,
                     cases[i].must_name);
        if (!strstr(err.msg, "s.json"))
            fail_msg("case %zu: the message does not name the file: %s", i, err.msg);
    }
}

/* The scene with one fibre group along axis (a JSON array text), or none when axis is NULL. */
static void parse_scene(const char *axis, double density, cf_scene *sc)
{
    char json[2048];
    if (axis)
        snprintf(json, sizeof json,
                 "{" SPRING ", " LATTICE ", " STRETCH ", \"fibres\": [{\"axis\": %s, \"density\": "
                 "%.17g, \"spring\": " FSPRING "}]}",
                 axis, density);
    else
        snprintf(json, sizeof json, "{" SPRING ", " LATTICE ", " STRETCH "}");
    cf_error err = {0};
    if (cf_scene_parse(json, "s.json", sc, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

static void a_good_entry_is_kept_and_goes_to_the_export(void **state)
{
    (void)state;
    cf_scene sc;
    parse_scene("[1, 1, 0]", 2.5, &sc);
    assert_int_equal(sc.nfibres, 1);
    assert_true(fabs(sc.fibres[0].axis[0] - sqrt(0.5)) < 1e-15);
    assert_true(fabs(sc.fibres[0].axis[1] - sqrt(0.5)) < 1e-15);
    assert_true(sc.fibres[0].axis[2] == 0);
    assert_true(sc.fibres[0].density == 2.5);
    assert_true(sc.fibres[0].spring.H_mm == 8 && sc.fibres[0].spring.d_mm == 1.5);
    assert_string_equal(sc.fibres[0].source, "params");
    cf_export_lattice lx;
    cf_error err = {0};
    if (cf_export_lattice_from_scene(&sc, "s.json", &lx, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(lx.nfibre, 1); /* the export's writer builds its law (test_cli_fibres) */
    for (int i = 0; i < 3; i++)
        assert_true(lx.fibre_dir[0][i] == sc.fibres[0].axis[i]);
    assert_true(lx.fibre_density[0] == 2.5 && lx.fibre_spring[0].H_mm == 8);
    assert_null(lx.cfg.lattice.fibre); /* its validation lattice takes none */
    cf_scene_free(&sc);
}

/* The samples' compressive stresses (MPa) of the run of sc into s (count n). */
static void run_scene(const cf_scene *sc, cf_sim_run *run)
{
    const cf_budget budget = cf_budget_default();
    cf_error err = {0};
    if (cf_pipeline_simulate(sc, "s.json", &budget, 0, run, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

static void stretched_along_the_fibre_the_lattice_is_the_cell(void **state)
{
    (void)state;
    cf_scene sc, bare;
    parse_scene("[0, 0, 1]", 1.5, &sc);
    parse_scene(NULL, 0, &bare);
    cf_sim_run run, plain;
    run_scene(&sc, &run);
    run_scene(&bare, &plain);
    assert_int_equal(run.count, 6);
    /* the homogenised cell of the same lattice and group */
    cf_law flaw;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&flaw, &sc.fibres[0].spring, &err), CF_OK);
    const cf_fibre_group g = {&flaw, sc.method, {0, 0, 1}, 1.5};
    cf_cell cell;
    assert_int_equal(cf_cell_init(&cell, &run.law, sc.method, run.lat.cfg.weight, &err), CF_OK);
    cell.volume_modulus_MPa = run.lat.cfg.volume_modulus_MPa;
    cell.fibre = &g;
    cell.nfibre = 1;
    const cf_cell_load ld = {CF_MODE_UNIAXIAL, {2, 0}, 0};
    for (size_t k = 1; k < run.count; k++) {
        const cf_msm_sample *s = &run.samples[k];
        assert_true(s->neg_pivots == 0);
        cf_cell_state cs;
        if (cf_cell_load_state(&cell, &ld, -s->strain, &cs, &err) != CF_OK)
            fail_msg("%s", err.msg);
        const double want = -cs.P_MPa[2][2];
        if (!(fabs(s->stress_MPa - want) <= 1e-9 * fabs(want)))
            fail_msg("sample %zu, strain %g: the lattice %.17g MPa, the cell %.17g MPa", k,
                     s->strain, s->stress_MPa, want);
        if (!(fabs(s->stress_MPa) >= 1.3 * fabs(plain.samples[k].stress_MPa)))
            fail_msg("sample %zu: with fibres %.6g MPa, without %.6g MPa", k, s->stress_MPa,
                     plain.samples[k].stress_MPa);
    }
    cf_law_free(&flaw);
    cf_sim_run_free(&run);
    cf_sim_run_free(&plain);
    cf_scene_free(&sc);
    cf_scene_free(&bare);
}

TU_SCRATCH_GROUP("scenefibres")

/* A joint fit file's fibre lattice of cross axis n only: matrix (family weights 1, 0.4, 0.2), f
** and n groups (n recruited at strain 0.01), kappa. */
static const char *const fibre_fit_json =
    "{\"fibre_lattice\": [{\"model\": \"fibre-lattice\", \"cross_axis\": \"n\",\n"
    " \"matrix\": {\"rho\": 0.63, \"solid_strain\": 0.48, \"stress_scale_kPa\": 2.7},\n"
    " \"fibre_groups\": [{\"axis\": \"f\", \"rho\": 0.3, \"solid_strain\": 0.2, "
    "\"stress_scale_kPa\": 50},\n"
    "  {\"axis\": \"n\", \"rho\": 0.35, \"solid_strain\": 0.22, \"stress_scale_kPa\": 30, "
    "\"recruitment_strain\": 0.01}],\n"
    " \"family_weights\": [1, 0.4, 0.2], \"volume_modulus_kPa\": 0.6}]}\n";

/* Parses the scene text with "fibres" = fibres (and more root keys), path of the fit file in
** place of FIT. Returns its status, the message in err. */
static cf_status parse_fit_scene(const char *fibres, const char *more, cf_scene *sc,
                                 cf_error *err)
{
    char json[2048];
    snprintf(json, sizeof json,
             "{\"lattice\": {\"nx\": 3, \"ny\": 3, \"nz\": 3}, " STRETCH ", \"fibres\": %s%s}",
             fibres, more);
    return cf_scene_parse(json, "s.json", sc, err);
}

static void a_fibre_fit_file_gives_the_whole_lattice(void **state)
{
    (void)state;
    char fit[512], fibres[700];
    snprintf(fit, sizeof fit, "%s/fibre.json", dir);
    assert_int_equal(tu_write_bytes(fit, fibre_fit_json, strlen(fibre_fit_json)), 0);
    snprintf(fibres, sizeof fibres, "{\"fit\": \"%s\", \"cross_axis\": \"n\"}", fit);
    cf_scene sc;
    cf_error err = {0};
    if (parse_fit_scene(fibres, "", &sc, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(sc.nfibres, 2);
    assert_true(sc.fibres[0].axis[0] == 1 && sc.fibres[1].axis[2] == 1);
    assert_true(fabs(sc.cfg.lattice.volume_modulus_MPa - 0.6e-3) < 1e-18);
    assert_true(sc.fibres[0].slack == 0 && sc.fibres[1].slack == 0.01);
    cf_sim_run run;
    run_scene(&sc, &run);
    /* the fit's own model */
    cf_fibre_fit f = {.groups = "fn", .ngroups = 2, .cross = 'n', .kappa_MPa = 0.6e-3};
    f.matrix = (cf_ident){.rho = 0.63, .solid = 0.48, .scale = 2.7e-3};
    f.fibre[0] = (cf_ident){.rho = 0.3, .solid = 0.2, .scale = 50e-3};
    f.fibre[1] = (cf_ident){.rho = 0.35, .solid = 0.22, .scale = 30e-3};
    f.slack[1] = 0.01;
    f.family[0] = 1, f.family[1] = 0.4, f.family[2] = 0.2;
    cf_fibre_model m;
    assert_int_equal(cf_fibre_model_init(&m, &f, &err), CF_OK);
    const cf_cell_load ld = {CF_MODE_UNIAXIAL, {2, 0}, 0};
    for (size_t k = 1; k < run.count; k++) {
        const cf_msm_sample *s = &run.samples[k];
        cf_cell_state cs;
        assert_true(s->neg_pivots == 0);
        if (cf_cell_load_state(&m.cell, &ld, -s->strain, &cs, &err) != CF_OK)
            fail_msg("%s", err.msg);
        const double want = -cs.P_MPa[2][2];
        if (!(fabs(s->stress_MPa - want) <= 1e-9 * fabs(want)))
            fail_msg("sample %zu, strain %g: the scene's lattice %.17g MPa, the fit's cell %.17g "
                     "MPa", k, s->strain, s->stress_MPa, want);
    }
    cf_fibre_model_free(&m);
    cf_sim_run_free(&run);
    cf_scene_free(&sc);
    /* refusals, each naming its key */
    struct {
        const char *fibres, *more, *must;
    } bad[] = {
        {"{\"fit\": \"FIT\", \"cross_axis\": \"s\"}", "", "cross_axis 's'"},
        {"{\"fit\": \"FIT\", \"cross_axis\": \"x\"}", "", "'fibres.cross_axis'"},
        {"{\"fit\": \"FIT\"}", "", "'fibres.cross_axis'"},
        {"{\"fit\": \"FIT\", \"cross_axis\": \"n\", \"kappa\": 1}", "", "'fibres.kappa'"},
        {"{\"fit\": \"FIT\", \"cross_axis\": \"n\"}", ", " SPRING, "key 'spring'"},
        {"{\"fit\": \"FIT.missing\", \"cross_axis\": \"n\"}", "", "'fibres.fit'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char fb[700];
        const char *at = strstr(bad[i].fibres, "FIT");
        snprintf(fb, sizeof fb, "%.*s%s%s", (int)(at - bad[i].fibres), bad[i].fibres, fit,
                 at + 3);
        cf_error e = {0};
        cf_scene s2;
        const cf_status st = parse_fit_scene(fb, bad[i].more, &s2, &e);
        if (st == CF_OK)
            cf_scene_free(&s2);
        if (st == CF_OK || !strstr(e.msg, bad[i].must))
            fail_msg("case %zu: status %d, '%s' (expected '%s')", i, (int)st, e.msg, bad[i].must);
    }
    /* a lattice weight beside the fit */
    cf_error e = {0};
    char json[1024];
    snprintf(json, sizeof json, "{\"lattice\": {\"nx\": 3, \"poisson_ratio\": 0.3}, " STRETCH
             ", \"fibres\": %s}", fibres);
    assert_int_equal(cf_scene_parse(json, "s.json", &sc, &e), CF_E_DATA);
    assert_non_null(strstr(e.msg, "'lattice.poisson_ratio'"));
    /* a fit file with a recruitment strain or family weights out of range: refused, naming it */
    static const char *const from[2] = {"\"recruitment_strain\": 0.01",
                                        "\"family_weights\": [1, 0.4, 0.2]"};
    static const char *const to[2] = {"\"recruitment_strain\": 1.50",
                                      "\"family_weights\": [1, -4, 0.20]"};
    static const char *const key[2] = {"fibre_groups[1].recruitment_strain",
                                       "fibre_lattice[0].family_weights"};
    for (int k = 0; k < 2; k++) {
        char text[1024];
        snprintf(text, sizeof text, "%s", fibre_fit_json);
        char *at = strstr(text, from[k]);
        assert_non_null(at);
        memcpy(at, to[k], strlen(to[k]));
        assert_int_equal(tu_write_bytes(fit, text, strlen(text)), 0);
        cf_error fe = {0};
        cf_scene s3;
        assert_int_equal(parse_fit_scene(fibres, "", &s3, &fe), CF_E_DATA);
        if (!strstr(fe.msg, key[k]))
            fail_msg("expected '%s' in: %s", key[k], fe.msg);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bad_fibres_are_refused_naming_the_key),
        cmocka_unit_test(a_good_entry_is_kept_and_goes_to_the_export),
        cmocka_unit_test(stretched_along_the_fibre_the_lattice_is_the_cell),
        cmocka_unit_test(a_fibre_fit_file_gives_the_whole_lattice),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
