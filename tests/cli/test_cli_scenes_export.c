/*
** Every scene shipped in data/scenes exports with a shipped fit (fits/telescoping.json) as a
** CalculiX lattice or body: the time protocols (hold, cycles; the creep's stress drive through
** conifit's elastic strains) as their quasi-static displacement history with a warning naming
** the viscosity left out, the uniaxial scene cut where the fit's lattice loses stability. A scene
** whose mesh lives in ../shared/meshes is skipped, visibly, when that folder is absent. When ccx
** is installed, the hysteresis and creep scenes run in it: its reaction at every step is
** conifit's within the header's tolerance (measured: hysteresis, 240 steps, within 0.0027 N of
** a tolerance of 0.0188 N). The body scene with fibres (lv_slab_fibres.json) is pressed by a
** sphere, which a body's export refuses before solving (exit 65, naming the probe); its fibres
** are exported with a flat punch in test_cli_fibres.
*/
#include "testutil.h"

#include <dirent.h>
#include <sys/stat.h>

TU_SCRATCH_GROUP("scenes-export")

static char errb[1 << 14];

/* Exports scene (a path) as dir/job.inp; returns the exit status, stderr in errb. */
static int export_scene(const char *scene, const char *job)
{
    return tu_run(NULL, 0, errb, sizeof errb,
                  "export fits/telescoping.json --lattice %s --format calculix -o %s/%s.inp", scene,
                  dir, job);
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void every_shipped_scene_exports(void **state)
{
    (void)state;
    DIR *d = opendir("data/scenes");
    assert_non_null(d);
    char *names[64];
    size_t n = 0;
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        const size_t len = strlen(e->d_name);
        if (len > 5 && strcmp(e->d_name + len - 5, ".json") == 0 && n < 64)
            names[n++] = strdup(e->d_name);
    }
    closedir(d);
    assert_true(n >= 7); /* creep, hysteresis, liver_probe, lv_slab_fibres, relaxation,
                         ** synthetic_relaxation, uniaxial */
    qsort(names, n, sizeof *names, by_name);
    struct stat sb;
    const int meshes = stat("../shared/meshes", &sb) == 0;
    for (size_t i = 0; i < n; i++) {
        char scene[300], job[64], *text;
        snprintf(scene, sizeof scene, "data/scenes/%s", names[i]);
        snprintf(job, sizeof job, "s%zu", i);
        text = tu_slurp(scene);
        assert_non_null(text);
        const int needs_mesh = strstr(text, "../shared/meshes/") != NULL;
        const int timed = strstr(text, "\"hold\"") || strstr(text, "\"cycles\"");
        const int fibres = strstr(text, "\"fibres\"") != NULL;
        free(text);
        if (needs_mesh && !meshes) {
            print_message("%s: skipped (../shared/meshes absent)\n", scene);
            continue;
        }
        const int rc = export_scene(scene, job);
        if (fibres) { /* its sphere is refused (a body's fibres: test_cli_fibres) */
            assert_int_equal(rc, 65);
            assert_non_null(strstr(errb, "probe: a body's export takes a flat punch"));
            print_message("%s: refused, as a body pressed by a sphere is (exit 65)\n", scene);
            continue;
        }
        if (rc != 0)
            fail_msg("%s: exit %d: %s", scene, rc, errb);
        print_message("%s: exported\n", scene);
        if (timed) {
            assert_non_null(strstr(errb, "quasi-static displacement history"));
            assert_non_null(strstr(errb, "not carried: 2 Prony terms (viscosity)"));
        }
        if (strcmp(names[i], "uniaxial.json") == 0)
            assert_non_null(strstr(errb, "the loading is cut after step "));
        char inp[200];
        snprintf(inp, sizeof inp, "%s/%s.inp", dir, job);
        text = tu_slurp(inp);
        assert_non_null(text);
        assert_non_null(strstr(text, "*STEP"));
        free(text);
    }
    for (size_t i = 0; i < n; i++)
        free(names[i]);
}

/* ccx on dir/job.inp: its compressive top reaction at every step against the header's. */
static void runs_in_ccx(const char *scene, const char *job, int nsteps)
{
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    if (export_scene(scene, job) != 0)
        fail_msg("%s: %s", scene, errb);
    char path[200], cmd[400];
    snprintf(path, sizeof path, "%s/%s.inp", dir, job);
    char *x = tu_slurp(path);
    assert_non_null(x);
    const double tol = tu_deck_tolerance(x);
    double *ref = calloc((size_t)nsteps, sizeof *ref);
    assert_non_null(ref);
    int n = 0;
    const char *p;
    for (p = strstr(x, "conifit reaction "); p && n < nsteps; p = strstr(p + 1, "conifit reaction "))
        ref[n++] = strtod(p + strlen("conifit reaction "), NULL);
    free(x);
    assert_int_equal(n, nsteps);
    snprintf(cmd, sizeof cmd, "cd '%s' && ccx -i %s > %s.log 2>&1", dir, job, job);
    assert_int_equal(system(cmd), 0);
    snprintf(path, sizeof path, "%s/%s.dat", dir, job);
    char *dat = tu_slurp(path);
    assert_non_null(dat);
    int k = 0;
    double worst = 0;
    for (p = strstr(dat, "total force"); p && k < nsteps; p = strstr(p + 1, "total force")) {
        const char *line = strchr(p, '\n');
        assert_non_null(line);
        double fx, fy, fz;
        assert_int_equal(sscanf(line, "%lf %lf %lf", &fx, &fy, &fz), 3);
        const double dev = fabs(-fz - ref[k]);
        if (dev > tol)
            fail_msg("%s, step %d: ccx %.9g N, conifit %.9g N: beyond the header's %.3g N", scene,
                     k + 1, -fz, ref[k], tol);
        worst = fmax(worst, dev);
        k++;
    }
    free(dat);
    free(ref);
    assert_int_equal(k, nsteps);
    print_message("%s: ccx within %.3g N of conifit at all %d steps (tolerance %.3g N)\n", scene,
                  worst, nsteps, tol);
}

static void the_hysteresis_scene_runs_in_ccx(void **state)
{
    (void)state;
    runs_in_ccx("data/scenes/hysteresis.json", "hyst", 240); /* 2 cycles x 2 segments x 60 */
}

static void the_creep_scene_runs_in_ccx(void **state)
{
    (void)state;
    runs_in_ccx("data/scenes/creep.json", "creep", 200); /* ramp and hold, 100 samples each */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_shipped_scene_exports),
        cmocka_unit_test(the_hysteresis_scene_runs_in_ccx),
        cmocka_unit_test(the_creep_scene_runs_in_ccx),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
