/*
** `conifit simulate` of a body scene whose spring is the brain cortex's joint fit with its pair
** and its lattice's volume term (issue #44; tests/unit/data/brain_cortex_pair_volume.json, a
** `conifit fit --joint --law auto --volume fit` of the shared cortex tables, κ 2.96 kPa), on a
** block 30 x 30 x 15 mm meshed by Gmsh (h 2.5 mm), held at its bottom, a flat punch of radius 5 mm
** pressed 1.5 mm (10 % of the height) in four steps:
**  - the body takes the fit's κ whole (the isotropic lattice and the body share mu = k0/(2.5 H)
**    and lambda = mu + κ; src/notes/simulate.md): the summary says so, with nu =
**    (mu + κ)/(2 (2 mu + κ)) computed here from the fit; every step is a stable equilibrium;
**  - the volume term is used: the same fit with κ = 0 is softer at every step (measured 6.1 % at
**    the first, less than the 13 % a single-sided law's nu 1/4 -> 0.34 gives a punch on a
**    half-space, F = 2 a E δ/(1 - nu^2) = 4 a mu δ/(1 - nu): the pair raises nu without κ too);
**  - the first step's stiffness against that formula with the lattice's small-strain E and nu in
**    compression (the fit file's): measured 0.94 of it;
**  - a scene that gives its own volume term beside the fit's, and a fit through a lattice of
**    other weights, are refused (exit 65, naming the key);
**  - `conifit export` of the body writes a CalculiX model; ccx gives simulate's forces within 1 %.
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

#include "io/fitfile.h"

TU_SCRATCH_GROUP("cli-body-volume")

#define FIT "tests/unit/data/brain_cortex_pair_volume.json"
#define STEPS 4
#define DEPTH 1.501
#define RADIUS 5.0
#define PUNCH "\"probe\": {\"shape\": \"punch\", \"radius_mm\": 5, \"center_mm\": [15, 15, 15.001], " \
              "\"direction\": [0, 0, -1], \"depth_mm\": 1.501, \"steps\": 4}"

/* The block 30 x 30 x 15 mm meshed by Gmsh at 2.5 mm, as a Gmsh 2.2 file at path. */
static void write_gmsh_block(const char *path)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {30, 30, 15}, f[3] = {15, 15, 15};
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, f, 2.5, 2.5, 0, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    write_msh(path, &m);
}

/* dir/NAME.json: the fit at fit on the block, held at its bottom, the punch; body members extra
** (may be ""). */
static void write_scene(char *scene, size_t cap, const char *name, const char *fit,
                        const char *extra)
{
    char mesh[600];
    snprintf(mesh, sizeof mesh, "%s/gblock.msh", dir);
    struct stat sb;
    if (stat(mesh, &sb) != 0)
        write_gmsh_block(mesh);
    snprintf(scene, cap, "%s/%s.json", dir, name);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"fit\": \"%s\"},\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1%s},\n"
               " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n " PUNCH "}\n",
            fit, mesh, extra);
    fclose(f);
}

/* A copy of src (FIT or an earlier copy) at dir/NAME.json with the text from replaced by to (which
** must occur). */
static void fit_copy_of(const char *src, char *path, size_t cap, const char *name,
                        const char *from, const char *to)
{
    char *text = tu_slurp(src);
    assert_non_null(text);
    char *v = strstr(text, from);
    assert_non_null(v);
    snprintf(path, cap, "%s/%s.json", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "%.*s%s%s", (int)(v - text), text, to, v + strlen(from));
    fclose(f);
    free(text);
}

static void fit_copy(char *path, size_t cap, const char *name, const char *from, const char *to)
{
    fit_copy_of(FIT, path, cap, name, from, to);
}

/* Runs the scene into dir/NAME.csv, its forces (STEPS + 1 rows) into F and the summary into out;
** the depths as asked, forces finite and increasing. */
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
            assert_close(d, DEPTH * n / STEPS, 1e-12);
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

/* The compression spring's shear modulus k0/(2.5 H) (MPa) and the fit's kappa (MPa). */
static void fit_moduli(double *mu, double *kappa)
{
    cf_fitted_spring fs;
    cf_error e = {0};
    cf_law law;
    if (cf_fitfile_load_element(FIT, NULL, &fs, &e) != CF_OK || cf_fitted_law(&fs, &law, &e) != CF_OK)
        fail_msg("%s", e.msg);
    assert_true(fs.has_extension);
    *mu = law.k0_N_per_mm / law.p.H_mm / 2.5;
    *kappa = fs.volume_modulus_MPa;
}

static void the_cortex_fit_with_its_volume_term_runs_in_a_body(void **state)
{
    (void)state;
    double mu, kappa;
    fit_moduli(&mu, &kappa);
    assert_close(kappa, 0.0029634644827944115, 1e-15);
    const double nu = (mu + kappa) / (2 * (2 * mu + kappa));
    char scene[600], out[8192], want[256], fit0[600];
    double F[STEPS + 1], F0[STEPS + 1];
    write_scene(scene, sizeof scene, "vol", FIT, "");
    run_scene(scene, "vol", F, out, sizeof out);
    const char *line = strstr(out, "volume term: the fit's lattice's, kappa = ");
    if (!line)
        fail_msg("no volume term line in:\n%s", out);
    double k_kPa, nu_out;
    const char *q = strstr(line, "nu = ");
    assert_non_null(q);
    assert_int_equal(sscanf(line, "volume term: the fit's lattice's, kappa = %lf kPa", &k_kPa), 1);
    assert_int_equal(sscanf(q, "nu = %lf", &nu_out), 1);
    assert_close(k_kPa, kappa * 1e3, 1e-5 * kappa * 1e3);
    assert_close(nu_out, nu, 1e-5);
    assert_non_null(strstr(out, "double-acting element: edges in compression take the spring"));
    snprintf(want, sizeof want, "stability: %d of %d steps a stable equilibrium", STEPS, STEPS);
    if (!strstr(out, want))
        fail_msg("no '%s' in the summary:\n%s", want, out);
    /* the same fit without its volume term: nu 1/4, softer */
    fit_copy(fit0, sizeof fit0, "kappa0", "\"volume_modulus_MPa\": 0.0029634644827944115,",
             "\"volume_modulus_MPa\": 0.0,");
    write_scene(scene, sizeof scene, "vol0", fit0, "");
    run_scene(scene, "vol0", F0, out, sizeof out);
    assert_null(strstr(out, "volume term: the fit's"));
    /* a flat punch on a half-space: F/d = 2 a E/(1 - nu^2) = 4 a mu/(1 - nu) (Sneddon 1965), mu
    ** the same with and without kappa; the pair's springs stretched beside the punch take the
    ** softer extension spring, which raises the body's nu without kappa too, so kappa adds less */
    const double ratio_hs = (1 - 0.25) / (1 - nu), ratio1 = F[1] / F0[1];
    for (int k = 1; k <= STEPS; k++) {
        print_message("depth %.4g mm: with kappa %.6g N, without %.6g N (x%.4f)\n",
                      DEPTH * k / STEPS, F[k], F0[k], F[k] / F0[k]);
        assert_true(F[k] > F0[k]);
    }
    assert_true(ratio1 > 1.03 && ratio1 < ratio_hs);
    /* the first step's stiffness against the half-space of the lattice's own small-strain modulus
    ** and Poisson's ratio in compression (the fit file's, from its homogenised cell) */
    char *text = tu_slurp(FIT);
    assert_non_null(text);
    const char *pe = strstr(text, "\"modulus_compression_MPa\":"), *pn = strstr(text, "\"poisson_ratio_compression\":");
    double Ec, nuc;
    assert_true(pe && pn);
    assert_int_equal(sscanf(pe, "\"modulus_compression_MPa\": %lf", &Ec), 1);
    assert_int_equal(sscanf(pn, "\"poisson_ratio_compression\": %lf", &nuc), 1);
    free(text);
    const double slope = F[1] / (DEPTH / STEPS), slope_hs = 2 * RADIUS * Ec / (1 - nuc * nuc);
    print_message("first step: with/without kappa x%.4f (a single-sided law on a half-space "
                  "x%.4f); stiffness %.5g N/mm, the half-space of the lattice's E %.4g kPa and nu "
                  "%.4f in compression %.5g N/mm (x%.4f)\n",
                  ratio1, ratio_hs, slope, Ec * 1e3, nuc, slope_hs, slope / slope_hs);
    assert_true(slope / slope_hs > 0.85 && slope / slope_hs < 1.15);
}

/* Exit 65, the message holding each of the words, and no CSV written. */
static void refused(const char *name, const char *fit, const char *extra, const char *w1,
                    const char *w2)
{
    char scene[600], csv[600], out[4096], err[4096];
    write_scene(scene, sizeof scene, name, fit, extra);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 65);
    if (!strstr(err, w1) || !strstr(err, w2))
        fail_msg("%s: no '%s' and '%s' in: %s", name, w1, w2, err);
    struct stat sb;
    assert_int_not_equal(stat(csv, &sb), 0);
}

static void a_second_volume_term_or_another_lattice_is_refused(void **state)
{
    (void)state;
    refused("nu", FIT, ", \"poisson_ratio\": 0.45", "'body.poisson_ratio'",
            "give one or the other");
    refused("kap", FIT, ", \"volume_modulus_MPa\": 0.01", "'body.volume_modulus_MPa'",
            "give one or the other");
    char fit[600];
    fit_copy(fit, sizeof fit, "axial_fit", "\"edge\": 0.60848984692814911", "\"edge\": 0.5");
    refused("axial", fit, "", "edge weight 0.5", "isotropic lattice only");
    /* a joint fit's fitted weights, without a volume term too: another material */
    char fit2[600];
    fit_copy(fit, sizeof fit, "fitted_w", "\"edge\": 0.60848984692814911",
             "\"edge\": 0.676");
    fit_copy_of(fit, fit2, sizeof fit2, "fitted_w0", "\"volume_modulus_MPa\": 0.0029634644827944115",
                "\"volume_modulus_MPa\": 0");
    refused("fittedw", fit2, "", "fitted weights (edge 0.676", "isotropic lattice only");
}

static void the_body_exports_to_calculix(void **state)
{
    (void)state;
    char scene[600], out[8192];
    double F[STEPS + 1];
    write_scene(scene, sizeof scene, "xvol", FIT, "");
    run_scene(scene, "xvol", F, out, sizeof out);
    bu_export_matches_simulate(dir, FIT, scene, "xvol", F, STEPS, "volume body", 1e-2);
}

int main(void)
{
    if (access(FIT, R_OK) != 0) {
        printf("skipped: %s missing (run from the repository's root)\n", FIT);
        return 0;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_cortex_fit_with_its_volume_term_runs_in_a_body),
        cmocka_unit_test(a_second_volume_term_or_another_lattice_is_refused),
        cmocka_unit_test(the_body_exports_to_calculix),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
