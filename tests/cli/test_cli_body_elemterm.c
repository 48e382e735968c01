/*
** `conifit simulate` and `conifit export` of a body with its element term ("body":
** {"element_term": true}; cf_body_match_elements, src/notes/simulate.md, "The element term"): the
** muscle's telescoping fit (fits/series/muscle_compression_relaxation_fiber30.json) with the body's
** poisson_ratio 0.45 (its volume term) on a block 30 x 30 x 15 mm meshed by Gmsh (h 2.5 mm), held
** at its bottom, a flat punch of radius 5 mm pressed 1.5 mm (10 % of the height) in four steps:
**  - the summary says the body carries it; the punch's force is above the springs' alone at
**    every step (the network relaxes below its calibration without it), by a few per cent;
**  - `conifit export --format calculix` writes each tetrahedron's term as a C3D4 of its own
**    anisotropic material: ccx gives simulate's forces within 1 % (measured 1.7e-5; the ccx run
**    is skipped under the sanitizers, the deck still checked); about 12 s of CPU, 7 s of it ccx's;
**  - formats that cannot carry it (febio, sofa) refuse, naming the format; a value that is not
**    true or false, the term beside spring groups and with a double-acting law (the brain
**    cortex's pair, tests/unit/data/brain_cortex_pair.json: two stiffnesses at rest) are refused
**    (exit 65, naming the key).
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

TU_SCRATCH_GROUP("cli-body-elemterm")

#define FIT "fits/series/muscle_compression_relaxation_fiber30.json"
#define PAIR "tests/unit/data/brain_cortex_pair.json"
#define STEPS 4
#define DEPTH 1.501
#define PUNCH "\"probe\": {\"shape\": \"punch\", \"radius_mm\": 5, \"center_mm\": [15, 15, 15.001], " \
              "\"direction\": [0, 0, -1], \"depth_mm\": 1.501, \"steps\": 4}"

/* dir/NAME.json: the fit at fit on the block (nu 0.45), held at its bottom, the punch; body
** members extra and top-level members top (each may be ""). */
static void write_scene_fit(char *scene, size_t cap, const char *name, const char *fit,
                            const char *extra, const char *top)
{
    char mesh[600];
    snprintf(mesh, sizeof mesh, "%s/gblock.msh", dir);
    struct stat sb;
    if (stat(mesh, &sb) != 0) {
        const double lo[3] = {0, 0, 0}, hi[3] = {30, 30, 15}, f[3] = {15, 15, 15};
        cf_mesh m;
        cf_error err = {0};
        if (cf_mesh_box(lo, hi, f, 2.5, 2.5, 0, &m, &err) != CF_OK)
            fail_msg("%s", err.msg);
        write_msh(mesh, &m);
    }
    snprintf(scene, cap, "%s/%s.json", dir, name);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"fit\": \"%s\"},\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, "
               "\"poisson_ratio\": 0.45%s},\n"
               " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n " PUNCH "%s}\n",
            fit, mesh, extra, top);
    fclose(f);
}

static void write_scene(char *scene, size_t cap, const char *name, const char *extra,
                        const char *top)
{
    write_scene_fit(scene, cap, name, FIT, extra, top);
}

/* Runs the scene into dir/NAME.csv, its forces (STEPS + 1 rows) into F and the summary into out. */
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
    int n = 0;
    double d;
    while (n <= STEPS && fgets(line, sizeof line, f))
        if (sscanf(line, "%lf,%lf", &d, &F[n]) == 2) {
            assert_close(d, DEPTH * n / STEPS, 1e-12);
            n++;
        }
    fclose(f);
    assert_int_equal(n, STEPS + 1);
    for (int k = 1; k <= STEPS; k++)
        assert_true(isfinite(F[k]) && F[k] > F[k - 1]);
}

static void the_element_term_runs_and_exports_to_calculix(void **state)
{
    (void)state;
    char scene[600], scene0[600], out[8192], out0[8192];
    double F[STEPS + 1], F0[STEPS + 1];
    write_scene(scene, sizeof scene, "et", ", \"element_term\": true", "");
    write_scene(scene0, sizeof scene0, "et0", "", "");
    run_scene(scene, "et", F, out, sizeof out);
    run_scene(scene0, "et0", F0, out0, sizeof out0);
    if (!strstr(out, "element term: every tetrahedron carries the isotropic tensor"))
        fail_msg("no element term line in:\n%s", out);
    assert_null(strstr(out0, "element term:"));
    if (!strstr(out, "stability: 4 of 4 steps a stable equilibrium"))
        fail_msg("not every step stable:\n%s", out);
    for (int k = 1; k <= STEPS; k++) {
        print_message("depth %.4g mm: element term %.6g N, springs alone %.6g N (x%.4f)\n",
                      DEPTH * k / STEPS, F[k], F0[k], F[k] / F0[k]);
        assert_true(F[k] / F0[k] > 1.05 && F[k] / F0[k] < 1.3);
    }
    /* the export (bu_export_matches_simulate's steps, without its pair's check) */
    char inp[700], err[8192];
    snprintf(inp, sizeof inp, "%s/xet.inp", dir);
    if (tu_run(out0, sizeof out0, err, sizeof err, "export %s --lattice %s --format calculix -o %s",
               FIT, scene, inp) != 0)
        fail_msg("export: %s", err);
    char *deck = tu_slurp(inp);
    assert_non_null(deck);
    assert_non_null(strstr(deck, "*ELEMENT, TYPE=C3D4, ELSET=ET1\n"));
    assert_non_null(strstr(deck, "*ELASTIC, TYPE=ANISO\n"));
    int n = 0;
    for (const char *q = deck; n < STEPS && (q = strstr(q, "conifit reaction ")); q++) {
        double ref;
        if (sscanf(q, "conifit reaction %lf", &ref) == 1) {
            assert_true(fabs(ref - F[n + 1]) <= 1e-9 * F[n + 1]);
            n++;
        }
    }
    free(deck);
    assert_int_equal(n, STEPS);
    if (TU_SANITIZED) { /* ccx's 7 s of CPU add nothing the sanitizers check */
        print_message("ccx run: asserted by make test, skipped under the sanitizers (the deck "
                      "is checked)\n");
        return;
    }
    if (system("command -v ccx >/dev/null 2>&1") != 0) {
        print_message("ccx not installed: the deck is checked, not run\n");
        return;
    }
    double G[STEPS];
    assert_int_equal(bu_ccx_forces(dir, "xet", G, STEPS), STEPS);
    for (int k = 1; k <= STEPS; k++) {
        print_message("element term export, step %d: ccx %.7g N, conifit simulate %.7g N "
                      "(%+.2e)\n", k, G[k - 1], F[k], G[k - 1] / F[k] - 1);
        assert_true(fabs(G[k - 1] - F[k]) <= 1e-2 * F[k]);
    }
}

/* Exit 65 with the message holding w1 and w2, for `conifit ARGS`. */
static void refused(const char *args, const char *w1, const char *w2)
{
    char out[4096], err[4096];
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "%s", args), 65);
    if (!strstr(err, w1) || !strstr(err, w2))
        fail_msg("%s: no '%s' and '%s' in: %s", args, w1, w2, err);
}

static void what_cannot_carry_it_is_refused(void **state)
{
    (void)state;
    char scene[600], args[2000];
    write_scene(scene, sizeof scene, "etx", ", \"element_term\": true", "");
    snprintf(args, sizeof args, "export %s --lattice %s --format febio -o %s/x.feb", FIT, scene, dir);
    refused(args, "febio: the body's element term", "export it to calculix");
    write_scene(scene, sizeof scene, "etn", ", \"element_term\": 1", "");
    snprintf(args, sizeof args, "simulate %s -o %s/etn.csv", scene, dir);
    refused(args, "'body.element_term'", "true or false");
    write_scene(scene, sizeof scene, "etg", ", \"element_term\": true",
                ",\n \"groups\": [{\"region\": {\"below\": {\"axis\": \"z\", \"value_mm\": 7.5}}, "
                "\"spring\": {\"fit\": \"" FIT "\"}}]");
    snprintf(args, sizeof args, "simulate %s -o %s/etg.csv", scene, dir);
    refused(args, "'body.element_term'", "groups");
    write_scene_fit(scene, sizeof scene, "etp", PAIR, ", \"element_term\": true", "");
    snprintf(args, sizeof args, "simulate %s -o %s/etp.csv", scene, dir);
    refused(args, "'body.element_term'", "double-acting");
}

int main(void)
{
    if (access(FIT, R_OK) != 0 || access(PAIR, R_OK) != 0) {
        printf("skipped: %s or %s missing (run from the repository's root)\n", FIT, PAIR);
        return 0;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_element_term_runs_and_exports_to_calculix),
        cmocka_unit_test(what_cannot_carry_it_is_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
