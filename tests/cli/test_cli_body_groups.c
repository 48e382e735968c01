/*
** Spring groups by region in a tissue body ("groups": [{"region": ..., "spring": ...}],
** src/notes/simulate.md): a 30 x 30 x 15 mm block whose springs carry one shipped fit (the
** muscle fit) and whose lower half's springs another (fits/telescoping.json, about five times
** softer at rest), pressed by a flat punch. `conifit simulate` states the group, its force differs
** from the one-law body's, and its CalculiX export (one spring table per group law) runs in ccx
** with the punch force at every step within the header's stated tolerance of simulate's (and
** within 1e-3 relative, as the one-law body's test). Overlapping and empty regions are refused
** (exit 65, the key named).
*/
#include "bodyutil.h"

TU_SCRATCH_GROUP("body-groups")

#define FIT "fits/series/muscle_compression_relaxation_fiber30.json"
#define LOWER "{\"region\": {\"below\": {\"axis\": \"z\", \"value_mm\": 7.5}}, " \
              "\"spring\": {\"fit\": \"fits/telescoping.json\"}}"

static char outb[1 << 14], errb[1 << 14];

/* The punch scene with groups (a JSON array, "" for none) and extra root keys (", ..." or "") at
** dir/name. */
static void write_scene(const char *name, const char *groups, const char *extra)
{
    char path[600], mesh[600];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    write_block(mesh);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{\"spring\": {\"fit\": \"%s\"}, \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, "
            "\"poisson_ratio\": 0.25}, \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, "
            "\"probe\": {\"shape\": \"punch\", \"radius_mm\": 6, \"center_mm\": [15, 15, 15], "
            "\"direction\": [0, 0, -1], \"depth_mm\": 0.2, \"steps\": 2}%s%s%s}",
            FIT, mesh, *groups ? ", \"groups\": " : "", groups, extra);
    fclose(f);
}

/* simulate's punch force at steps 1 and 2 of dir/name into F[0], F[1]. */
static void simulate(const char *name, double F[2])
{
    char csv[600];
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    if (tu_run(outb, sizeof outb, errb, sizeof errb, "simulate %s/%s -o %s", dir, name, csv) != 0)
        fail_msg("simulate %s: %s", name, errb);
    FILE *c = fopen(csv, "r");
    assert_non_null(c);
    char line[256];
    int n = 0;
    double d, G[3];
    assert_non_null(fgets(line, sizeof line, c));
    while (n < 3 && fgets(line, sizeof line, c))
        if (sscanf(line, "%lf,%lf", &d, &G[n]) == 2)
            n++;
    fclose(c);
    assert_int_equal(n, 3);
    F[0] = G[1], F[1] = G[2];
}

static void two_regions_simulate_and_run_in_ccx(void **state)
{
    (void)state;
    write_scene("one.json", "", "");
    write_scene("two.json", "[" LOWER "]", "");
    double one[2], two[2];
    simulate("one.json", one);
    assert_null(strstr(outb, "group 0"));
    simulate("two.json", two);
    if (!strstr(outb, "group 0 (region 'below'):") ||
        !strstr(outb, "take the law of spring fits/telescoping.json"))
        fail_msg("summary: %s", outb);
    for (int k = 0; k < 2; k++) /* the softer lower half: a smaller force */
        if (!(two[k] < 0.95 * one[k]))
            fail_msg("step %d: two regions %.6g N, one law %.6g N", k + 1, two[k], one[k]);
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    if (tu_run(outb, sizeof outb, errb, sizeof errb,
               "export %s --lattice %s/two.json --format calculix -o %s/two.inp", FIT, dir, dir) !=
        0)
        fail_msg("export: %s", errb);
    char path[700];
    snprintf(path, sizeof path, "%s/two.inp", dir);
    char *x = tu_slurp(path);
    assert_non_null(x);
    const double tol = tu_deck_tolerance(x);
    assert_non_null(strstr(x, ": spring (telescoping):")); /* the group's law in the header */
    free(x);
    double G[2];
    if (bu_ccx_forces(dir, "two", G, 2) != 2)
        fail_msg("ccx: not every step in two.dat");
    for (int k = 0; k < 2; k++) {
        print_message("two regions, step %d: ccx %.7g N, conifit simulate %.7g N (tolerance %.3g "
                      "N)\n",
                      k + 1, G[k], two[k], tol);
        if (!(fabs(G[k] - two[k]) <= tol) || !(fabs(G[k] - two[k]) <= 1e-3 * two[k]))
            fail_msg("step %d: ccx %.7g N, conifit simulate %.7g N: beyond %.3g N or 1e-3", k + 1,
                     G[k], two[k], tol);
    }
}

static void overlapping_and_empty_regions_are_refused(void **state)
{
    (void)state;
    write_scene("overlap.json",
                "[" LOWER ", {\"region\": {\"above\": {\"axis\": \"z\", \"value_mm\": 5}}, "
                "\"spring\": {\"fit\": \"fits/telescoping.json\"}}]",
                "");
    int rc = tu_run(outb, sizeof outb, errb, sizeof errb, "simulate %s/overlap.json -o %s/o.csv",
                    dir, dir);
    if (rc != 65 || !strstr(errb, "groups[1]: its region overlaps that of groups[0]"))
        fail_msg("overlap: exit %d, %s", rc, errb);
    write_scene("empty.json", "[{\"region\": {\"sphere\": {\"center_mm\": [100, 100, 100], "
                              "\"radius_mm\": 1}}, \"spring\": {\"fit\": \"fits/telescoping.json\"}}]",
                "");
    rc = tu_run(outb, sizeof outb, errb, sizeof errb, "simulate %s/empty.json -o %s/e.csv", dir,
                dir);
    if (rc != 65 || !strstr(errb, "groups[0]: the group is empty"))
        fail_msg("empty: exit %d, %s", rc, errb);
    write_scene("lattice_key.json", "[{\"springs\": \"face\", \"spring\": {\"fit\": "
                                    "\"fits/telescoping.json\"}}]",
                "");
    rc = tu_run(outb, sizeof outb, errb, sizeof errb, "simulate %s/lattice_key.json -o %s/l.csv",
                dir, dir);
    if (rc != 65 || !strstr(errb, "groups[0].springs"))
        fail_msg("a lattice's key in a body: exit %d, %s", rc, errb);
}

/* The body's estimate in bytes under --max-memory limit (exit 65, "needs about"). */
static double body_estimate(const char *name, const char *limit)
{
    int rc = tu_run(outb, sizeof outb, errb, sizeof errb,
                    "simulate %s/%s -o %s/b.csv --max-memory %s", dir, name, dir, limit);
    const char *p = strstr(errb, "needs about ");
    if (rc != 65 || !p)
        fail_msg("%s under %s: exit %d, %s", name, limit, rc, errb);
    return strtod(p + strlen("needs about "), NULL);
}

#define TABLE ", \"law_method\": \"table\", \"table_intervals\": 100000"

/* A body's spring groups are in its memory estimate: with the law by table each group's law
** carries a table of two values an end and four coefficients an interval (48 bytes), so a second
** law raises the estimate by at least that, and the scene's own table stands in it too; tables
** that alone pass the limit are refused before the mesh is read, naming the key. */
static void groups_are_in_the_body_estimate(void **state)
{
    (void)state;
    write_scene("t1.json", "", TABLE);
    write_scene("t2.json", "[" LOWER "]", TABLE);
    write_scene("e1.json", "", "");
    const double table = 48.0 * (100000 + 1);
    const double plain = body_estimate("e1.json", "12M"), one = body_estimate("t1.json", "12M"),
                 two = body_estimate("t2.json", "12M");
    print_message("estimates: exact law %.4g B, table %.4g B, table and a group %.4g B (a table "
                  "%.4g B)\n", plain, one, two, table);
    /* the estimates are printed to three digits: 1e5 B of rounding each */
    if (!(fabs(one - plain - table) <= 1e5) || !(two - one >= table - 1e5))
        fail_msg("estimates %.6g, %.6g, %.6g B: the tables (%.6g B each) not counted", plain,
                 one, two, table);
    int rc = tu_run(outb, sizeof outb, errb, sizeof errb,
                    "simulate %s/t2.json -o %s/b.csv --max-memory 8M", dir, dir);
    if (rc != 65 || !strstr(errb, "t2.json: key 'table_intervals' = 100000: the law tables need"))
        fail_msg("tables over the limit: exit %d, %s", rc, errb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(two_regions_simulate_and_run_in_ccx),
        cmocka_unit_test(overlapping_and_empty_regions_are_refused),
        cmocka_unit_test(groups_are_in_the_body_estimate),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
