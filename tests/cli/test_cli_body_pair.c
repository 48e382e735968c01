/*
** `conifit simulate` of a body scene whose spring is a double-acting element (issue #44): the
** brain cortex's joint fit with its pair (tests/unit/data/brain_cortex_pair.json, a `conifit fit
** --joint --law double-acting` of the shared cortex tables) on the block of 6 x 6 x 3 cells over
** 30 x 30 x 15 mm, nu 0.45, held at its bottom, a flat punch of radius 5 mm pressed 1 mm in four
** steps (as tests/unit/test_body_pair.c solves it):
**  - the run writes finite forces increasing with depth, the summary names the pair and says
**    every step is a stable equilibrium;
**  - the extension spring is used: the forces differ from the compression spring alone (the same
**    fit's params without the pair) by more than 1 %;
**  - a pair of two equal springs ('spring_extension' the spring's own params) writes the
**    compression-only body's CSV byte for byte;
**  - what is not built is refused, exit 65 naming the key: the pair with a dynamic run or a haptic
**    loop; a fit holding its lattice's volume term beside the scene's 'body.poisson_ratio';
**  - `conifit export` of the pair's body scene writes a CalculiX model with both springs' tables,
**    its header holding simulate's forces; ccx (when installed) gives them within 1 %. Measured:
**    +1.3e-7, +2.7e-3, +5.6e-3, +2.2e-3 at the four steps, where the compression spring alone gives
**    +0, +1.0e-3, +4.4e-3, +4.3e-3: the tables' error is 1e-4 of the spring's F_C (6.8 N) per unit
**    weight, large beside this soft block's 0.02-0.09 N (the liver's probe agrees to 3e-6), and
**    CalculiX's 200 rows allow no tighter table for this spring (8.2e-5 at best).
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

#include "io/fitfile.h"

TU_SCRATCH_GROUP("cli-body-pair")

#define FIT "tests/unit/data/brain_cortex_pair.json"
#define STEPS 4
#define PUNCH "\"probe\": {\"shape\": \"punch\", \"radius_mm\": 5, \"center_mm\": [15, 15, 15.001], " \
              "\"direction\": [0, 0, -1], \"depth_mm\": 1.001, \"steps\": 4}"

/* Writes dir/NAME.json: spring (a JSON member or members) on the block, held at its bottom, the
** punch, extra members (may be ""); the path into scene. */
static void write_scene(char *scene, size_t cap, const char *name, const char *spring,
                        const char *extra)
{
    char mesh[600];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    struct stat sb;
    if (stat(mesh, &sb) != 0)
        write_block(mesh);
    snprintf(scene, cap, "%s/%s.json", dir, name);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{%s,\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
               " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n " PUNCH "%s}\n",
            spring, mesh, extra);
    fclose(f);
}

/* A spring's params as the members of a "params" object. */
static void params_json(char *buf, size_t cap, const cf_spring *p, int tail)
{
    int n = snprintf(buf, cap, "\"D1_mm\": %.17g, \"D2_mm\": %.17g, \"n\": %.17g, \"d_mm\": %.17g, "
                               "\"G_MPa\": %.17g, \"H_mm\": %.17g",
                     p->D1_mm, p->D2_mm, p->n, p->d_mm, p->G_MPa, p->H_mm);
    if (tail)
        snprintf(buf + n, cap - (size_t)n, ", \"n_tail\": %.17g, \"H_tail_mm\": %.17g", p->n_tail,
                 p->H_tail_mm);
}

/* Runs the scene into dir/NAME.csv, reads its forces (STEPS + 1 rows) into F and the summary into
** out; asserts the CSV's header, the depths, forces finite and increasing. */
static void run_scene(const char *scene, const char *name, double *F, char *out, size_t cap)
{
    char csv[600], err[8192];
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    if (tu_run(out, cap, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
        fail_msg("simulate %s: %s", name, err);
    FILE *f = fopen(csv, "r");
    assert_non_null(f);
    char line[256];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "depth_mm,force_N\n");
    int n = 0;
    double d;
    while (n <= STEPS && fgets(line, sizeof line, f))
        if (sscanf(line, "%lf,%lf", &d, &F[n]) == 2) {
            assert_close(d, 1.001 * n / STEPS, 1e-12);
            n++;
        }
    fclose(f);
    assert_int_equal(n, STEPS + 1);
    assert_true(F[0] == 0);
    for (int k = 1; k <= STEPS; k++) {
        assert_true(isfinite(F[k]));
        assert_true(F[k] > F[k - 1]);
    }
}

static void the_cortex_pair_runs_in_a_body_stably(void **state)
{
    (void)state;
    cf_fitted_spring fs;
    cf_error e = {0};
    if (cf_fitfile_load_element(FIT, NULL, &fs, &e) != CF_OK)
        fail_msg("%s", e.msg);
    assert_true(fs.has_extension);
    char scene[600], out[8192], spring[1200], params[600];
    double Fp[STEPS + 1], Fo[STEPS + 1];
    write_scene(scene, sizeof scene, "pair", "\"spring\": {\"fit\": \"" FIT "\"}", "");
    run_scene(scene, "pair", Fp, out, sizeof out);
    assert_non_null(strstr(out, "double-acting element: edges in compression take the spring"));
    char want[128];
    snprintf(want, sizeof want, "stability: %d of %d steps a stable equilibrium", STEPS, STEPS);
    if (!strstr(out, want))
        fail_msg("no '%s' in the summary:\n%s", want, out);
    assert_null(strstr(out, "unstable from step"));
    /* the compression spring alone: the fit's params, without the pair */
    params_json(params, sizeof params, &fs.params, 1);
    snprintf(spring, sizeof spring, "\"spring\": {\"params\": {%s}}", params);
    write_scene(scene, sizeof scene, "odd", spring, "");
    run_scene(scene, "odd", Fo, out, sizeof out);
    assert_null(strstr(out, "double-acting"));
    for (int k = 1; k <= STEPS; k++)
        print_message("depth %.4g mm: pair %.6g N, compression spring alone %.6g N (%+.2f %%)\n",
                      1.001 * k / STEPS, Fp[k], Fo[k], 100 * (Fp[k] / Fo[k] - 1));
    assert_true(fabs(Fp[STEPS] / Fo[STEPS] - 1) > 0.01);
}

static void a_pair_of_equal_springs_is_the_compression_only_body(void **state)
{
    (void)state;
    const cf_spring p = {10, 30, 4, 1, 8e4, 40};
    char params[600], spring[1400], scene[600], out[8192];
    params_json(params, sizeof params, &p, 0);
    double Fe[STEPS + 1], Fo[STEPS + 1];
    snprintf(spring, sizeof spring, "\"spring\": {\"params\": {%s}}, \"spring_extension\": "
                                    "{\"params\": {%s}}", params, params);
    write_scene(scene, sizeof scene, "equal", spring, "");
    run_scene(scene, "equal", Fe, out, sizeof out);
    assert_non_null(strstr(out, "double-acting element"));
    snprintf(spring, sizeof spring, "\"spring\": {\"params\": {%s}}", params);
    write_scene(scene, sizeof scene, "single", spring, "");
    run_scene(scene, "single", Fo, out, sizeof out);
    char a[600], b[600];
    snprintf(a, sizeof a, "%s/equal.csv", dir);
    snprintf(b, sizeof b, "%s/single.csv", dir);
    char *ta = tu_slurp(a), *tb = tu_slurp(b);
    assert_non_null(ta);
    assert_non_null(tb);
    assert_string_equal(ta, tb);
    free(ta);
    free(tb);
}

/* Exit 65, the message holding each of the words, and no CSV written. */
static void refused(const char *name, const char *spring, const char *extra, const char *w1,
                    const char *w2)
{
    char scene[600], csv[600], out[4096], err[4096];
    write_scene(scene, sizeof scene, name, spring, extra);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 65);
    if (!strstr(err, w1) || !strstr(err, w2))
        fail_msg("%s: no '%s' and '%s' in: %s", name, w1, w2, err);
    struct stat sb;
    assert_int_not_equal(stat(csv, &sb), 0);
}

static void what_is_not_built_is_refused(void **state)
{
    (void)state;
    refused("dyn", "\"spring\": {\"fit\": \"" FIT "\"}",
            ", \"effects\": {\"inertia\": true}, \"density_t_per_mm3\": 1e-9, "
            "\"integrator\": {\"dt_s\": 0.01}",
            "'effects.inertia'", "dynamic run is not built");
    refused("hap", "\"spring\": {\"fit\": \"" FIT "\"}",
            ", \"haptic\": {\"path\": [[0, 0], [10, 0.5]]}", "'haptic'",
            "haptic loop is not built");
    /* the fit with a lattice volume term: its copy with volume_modulus_MPa 0.01 */
    char *text = tu_slurp(FIT), fit[600], spring[800];
    assert_non_null(text);
    char *v = strstr(text, "\"volume_modulus_MPa\": 0.0,");
    assert_non_null(v);
    snprintf(fit, sizeof fit, "%s/kappa_fit.json", dir);
    FILE *f = fopen(fit, "w");
    assert_non_null(f);
    fprintf(f, "%.*s\"volume_modulus_MPa\": 0.01,%s", (int)(v - text), text,
            v + strlen("\"volume_modulus_MPa\": 0.0,"));
    fclose(f);
    free(text);
    snprintf(spring, sizeof spring, "\"spring\": {\"fit\": \"%s\"}", fit);
    /* the body takes the fit's lattice volume term (test_cli_body_volume.c), not beside a
    ** 'body.poisson_ratio' of its own */
    refused("kappa", spring, "", "volume_modulus_MPa = 0.01", "give one or the other");
}

static void the_pair_body_exports_to_calculix(void **state)
{
    (void)state;
    char scene[600], out[8192];
    double F[STEPS + 1];
    write_scene(scene, sizeof scene, "xpair", "\"spring\": {\"fit\": \"" FIT "\"}", "");
    run_scene(scene, "xpair", F, out, sizeof out);
    bu_export_matches_simulate(dir, FIT, scene, "xpair", F, STEPS, "pair body", 1e-2);
}

int main(void)
{
    if (access(FIT, R_OK) != 0) {
        printf("skipped: %s missing (run from the repository's root)\n", FIT);
        return 0;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_cortex_pair_runs_in_a_body_stably),
        cmocka_unit_test(a_pair_of_equal_springs_is_the_compression_only_body),
        cmocka_unit_test(what_is_not_built_is_refused),
        cmocka_unit_test(the_pair_body_exports_to_calculix),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
