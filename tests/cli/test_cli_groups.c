/*
** Spring groups in lattice scenes ("groups", src/notes/simulate.md): a 3 x 3 x 3 isotropic lattice
** whose edges carry a shipped fit (fits/telescoping.json) and whose face and body diagonals that
** spring with twice its wire's shear modulus (twice the force at every compression) runs in `conifit simulate`, its reaction differs from the
** one-law lattice's, and its CalculiX export (one spring table per group, each with its own law)
** runs in ccx with the top reaction at every step within the header's stated tolerance of both
** the header's reference and `conifit simulate`'s CSV. Bad groups are refused with exit 65 naming
** the key and the value.
*/
#include "testutil.h"

TU_SCRATCH_GROUP("groups")

static char errb[1 << 14];
static char outb[1 << 16];

#define NSTEPS 10

/* Writes the scene with groups text (a JSON array, or "" for none) to dir/name. */
static void write_scene(const char *name, const char *groups)
{
    char path[200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{\"spring\": {\"fit\": \"fits/telescoping.json\"},\n"
            " \"lattice\": {\"nx\": 3, \"ny\": 3, \"nz\": 3, \"calibration\": \"isotropic\"},\n"
            "%s%s%s"
            " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.2, \"duration_s\": 1},\n"
            " \"samples_per_segment\": %d}\n",
            *groups ? " \"groups\": " : "", groups, *groups ? ",\n" : "", NSTEPS);
    fclose(f);
}

/* The telescoping fit's spring with twice its wire's shear modulus: twice its force at every
** compression (the same travel), a scaled spring */
#define DOUBLED "{\"params\": {\"D1_mm\": 24.338723466802737, \"D2_mm\": 75.29566864698658, " \
                "\"n\": 3.9999999999591864, \"d_mm\": 4.056453911206146, \"G_MPa\": " \
                "1576.87330169658, \"H_mm\": 10.000000000323476}}"

static const char *two_groups = "[{\"springs\": \"face\", \"spring\": " DOUBLED "},"
                                " {\"springs\": \"body\", \"spring\": " DOUBLED "}]";

/* The top reactions (N) of `conifit simulate` on dir/scene at its samples after t = 0. */
static void simulate_forces(const char *scene, double F[NSTEPS])
{
    char csv[200];
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, scene);
    if (tu_run(outb, sizeof outb, errb, sizeof errb, "simulate %s/%s -o %s", dir, scene, csv) != 0)
        fail_msg("simulate %s: %s", scene, errb);
    char *x = tu_slurp(csv);
    assert_non_null(x);
    const double area = 9 * 10.000000000323476 * 10.000000000323476; /* nx ny H^2, mm^2 */
    int n = 0;
    for (const char *p = strchr(x, '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
        double t, e, s;
        if (sscanf(p + 1, "%lf,%lf,%lf", &t, &e, &s) != 3 || !(t > 0))
            continue;
        assert_true(n < NSTEPS);
        F[n++] = s * 1e-3 * area;
    }
    free(x);
    assert_int_equal(n, NSTEPS);
}

static void two_groups_simulate_and_differ_from_one_law(void **state)
{
    (void)state;
    write_scene("two.json", two_groups);
    write_scene("one.json", "");
    double two[NSTEPS], one[NSTEPS];
    simulate_forces("two.json", two);
    /* the summary states the groups */
    if (!strstr(outb, "group face: the face springs take the law of spring params") ||
        !strstr(outb, "group body: the body springs"))
        fail_msg("summary: %s", outb);
    simulate_forces("one.json", one);
    assert_null(strstr(outb, "group "));
    for (int k = 0; k < NSTEPS; k++)
        if (!(fabs(two[k] - one[k]) > 0.2 * fabs(one[k])))
            fail_msg("step %d: two groups %.6g N, one law %.6g N: the groups do not show", k + 1,
                     two[k], one[k]);
}

static void two_groups_run_in_ccx_within_the_stated_tolerance(void **state)
{
    (void)state;
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    write_scene("two.json", two_groups);
    double sim[NSTEPS];
    simulate_forces("two.json", sim);
    if (tu_run(NULL, 0, errb, sizeof errb,
               "export fits/telescoping.json --lattice %s/two.json --format calculix -o %s/two.inp",
               dir, dir) != 0)
        fail_msg("export: %s", errb);
    char path[200], cmd[400];
    snprintf(path, sizeof path, "%s/two.inp", dir);
    char *x = tu_slurp(path);
    assert_non_null(x);
    const double tol = tu_deck_tolerance(x);
    /* each group's own law and table are in the header */
    assert_non_null(strstr(x, "group 2: spring (telescoping):"));
    assert_non_null(strstr(x, "G = 1576.87330169658"));
    double ref[NSTEPS];
    int n = 0;
    const char *p;
    for (p = strstr(x, "conifit reaction "); p && n < NSTEPS; p = strstr(p + 1, "conifit reaction "))
        ref[n++] = strtod(p + strlen("conifit reaction "), NULL);
    free(x);
    assert_int_equal(n, NSTEPS);
    snprintf(cmd, sizeof cmd, "cd '%s' && ccx -i two > two.log 2>&1", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(path, sizeof path, "%s/two.dat", dir);
    char *dat = tu_slurp(path);
    assert_non_null(dat);
    int k = 0;
    double worst = 0, worst_sim = 0;
    for (p = strstr(dat, "total force"); p && k < NSTEPS; p = strstr(p + 1, "total force")) {
        const char *line = strchr(p, '\n');
        assert_non_null(line);
        double fx, fy, fz;
        assert_int_equal(sscanf(line, "%lf %lf %lf", &fx, &fy, &fz), 3);
        const double dev = fabs(-fz - ref[k]), dsim = fabs(-fz - sim[k]);
        if (dev > tol || dsim > tol)
            fail_msg("step %d: ccx %.9g N, header %.9g N, simulate %.9g N: beyond the header's "
                     "%.3g N",
                     k + 1, -fz, ref[k], sim[k], tol);
        worst = fmax(worst, dev);
        worst_sim = fmax(worst_sim, dsim);
        k++;
    }
    free(dat);
    assert_int_equal(k, NSTEPS);
    print_message("two groups: ccx within %.3g N of the header's reference and %.3g N of conifit "
                  "simulate at all %d steps (tolerance %.3g N, top reaction up to %.4g N)\n",
                  worst, worst_sim, NSTEPS, tol, sim[NSTEPS - 1]);
}

/* A bad "groups" exits 65 with a message naming the key and the value. */
static void bad_groups_are_refused(void **state)
{
    (void)state;
    static const struct {
        const char *groups, *want;
    } cases[] = {
        {"[{\"springs\": \"spiral\", \"spring\": {\"fit\": \"fits/non_telescoping.json\"}}]",
         "'groups[0].springs' = 'spiral': unknown group"},
        {"[{\"springs\": \"face\", \"spring\": {\"fit\": \"fits/non_telescoping.json\"}},"
         " {\"springs\": \"face\", \"spring\": {\"fit\": \"fits/telescoping.json\"}}]",
         "'groups[1].springs' = 'face': that group is already groups[0]"},
        {"[{\"springs\": \"edge\", \"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": "
         "2.5, \"d_mm\": 2, \"G_MPa\": 26, \"H_mm\": 20}}}]",
         "'groups[0].spring': free length H = 20 mm"},
        {"[]", "'groups' must be a non-empty array"},
        {"[{\"springs\": \"face\"}]", "'groups[0].spring' is required"},
        {"[{\"springs\": \"face\", \"spring\": {\"fit\": \"fits/none.json\"}}]",
         "'groups[0].spring.fit'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        write_scene("bad.json", cases[i].groups);
        const int rc =
            tu_run(NULL, 0, errb, sizeof errb, "simulate %s/bad.json -o %s/bad.csv", dir, dir);
        if (rc != 65 && !(i == 5 && rc == 66))
            fail_msg("case %zu: exit %d (%s)", i, rc, errb);
        if (!strstr(errb, cases[i].want))
            fail_msg("case %zu: message '%s' lacks '%s'", i, errb, cases[i].want);
        if (!strstr(errb, "bad.json"))
            fail_msg("case %zu: message '%s' does not name the scene", i, errb);
    }
    /* an empty group: a family of weight 0 */
    char path[200];
    snprintf(path, sizeof path, "%s/empty.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("{\"spring\": {\"fit\": \"fits/telescoping.json\"},\n"
          " \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, \"weights\": {\"edge\": 1, "
          "\"face\": 0.5, \"body\": 0}},\n"
          " \"groups\": [{\"springs\": \"body\", \"spring\": {\"fit\": "
          "\"fits/non_telescoping.json\"}}],\n"
          " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.1, \"duration_s\": 1}}\n",
          f);
    fclose(f);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "simulate %s -o %s/e.csv", path, dir), 65);
    if (!strstr(errb, "'groups[0].springs' = 'body': the group is empty"))
        fail_msg("empty group: %s", errb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(two_groups_simulate_and_differ_from_one_law),
        cmocka_unit_test(two_groups_run_in_ccx_within_the_stated_tolerance),
        cmocka_unit_test(bad_groups_are_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
