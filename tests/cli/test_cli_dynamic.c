/*
** Dynamic runs of a body in `conifit simulate` ("effects": {"inertia": true}, "integrator.dt_s",
** "body.duration_s", "body.ramp_s", "body.damping_per_s"; Newmark's average-acceleration step,
** cf_body_dynamic_step): a slow ramp of a sphere into a Gmsh cube gives the static run's force at
** every depth (the quasi-static limit); a load applied at once on the top of a column on rollers
** (the one-dimensional wave problem) makes its top oscillate between 0 and twice the static
** displacement with the period 4 L / c of the body's P wave, without decay (the scheme conserves
** energy) and, damped, settles at the static displacement; bad keys and a run over the budget
** are refused with exit 65 naming the key, and nothing is written.
*/
#include "bodyutil.h"
#include "testutil.h"

#include <sys/stat.h>

#include "model/body.h"
#include "io/mesh.h"

TU_SCRATCH_GROUP("cli-dynamic")

/* Reads the CSV at path: its header into head (cap bytes) and up to maxrows rows of ncol numbers
** into v (row-major). Returns the number of rows. */
static int read_csv(const char *path, char *head, size_t cap, double *v, int ncol, int maxrows)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(head, (int)cap, f));
    char line[4096];
    int n = 0;
    while (n < maxrows && fgets(line, sizeof line, f)) {
        char *p = line;
        for (int c = 0; c < ncol; c++) {
            char *e;
            v[n * ncol + c] = strtod(p, &e);
            assert_true(e != p);
            assert_true(isfinite(v[n * ncol + c]));
            p = *e == ',' ? e + 1 : e;
        }
        n++;
    }
    fclose(f);
    return n;
}

/* The body's E (kPa) and nu from the summary. */
static void body_E_nu(const char *out, double *E_kPa, double *nu)
{
    const char *s = strstr(out, "body: E = ");
    assert_non_null(s);
    assert_int_equal(sscanf(s, "body: E = %lf kPa, nu = %lf", E_kPa, nu), 2);
}

#define PROBE "\"probe\": {\"shape\": \"sphere\", \"radius_mm\": 3, \"center_mm\": [5, 5, 13.2], " \
              "\"direction\": [0, 0, -1], \"depth_mm\": 1"

static void a_slow_ramp_gives_the_static_force_depth_curve(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    write_cube(mesh, 1.25);
    /* the static run, 8 steps */
    snprintf(scene, sizeof scene, "%s/static.json", dir);
    snprintf(csv, sizeof csv, "%s/static.csv", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n " PROBE
            ", \"steps\": 32}}\n",
            mesh);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
        fail_msg("%s", err);
    double s[33 * 2];
    assert_int_equal(read_csv(csv, head, sizeof head, s, 2, 33), 33);
    double E_kPa, nu;
    body_E_nu(out, &E_kPa, &nu);
    /* the period of the cube's slowest mode is of the order of 4 L / c_s (c_s of the shear wave,
    ** a third of the P wave's at nu 0.45): the ramp takes 50 of them */
    const double rho = 1e-9, mu = E_kPa * 1e-3 / (2 * (1 + nu));
    const double T = 4 * 10 / sqrt(mu / rho), ramp = 50 * T;
    snprintf(scene, sizeof scene, "%s/slow.json", dir);
    snprintf(csv, sizeof csv, "%s/slow.csv", dir);
    f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45, "
            "\"duration_s\": %.17g, \"ramp_s\": %.17g, \"damping_per_s\": %.17g},\n"
            " \"effects\": {\"inertia\": true}, \"density_t_per_mm3\": %g,\n"
            " \"integrator\": {\"dt_s\": %.17g},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n " PROBE "}}\n",
            mesh, ramp + 5 * T, ramp, 0.0, rho, (ramp + 5 * T) / 110);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
        fail_msg("%s", err);
    double d[111 * 3];
    assert_int_equal(read_csv(csv, head, sizeof head, d, 3, 111), 111);
    assert_string_equal(head, "time_s,depth_mm,force_N\n");
    assert_non_null(strstr(out, "dynamic: 110 implicit steps"));
    /* every dynamic step's force against the static curve at its depth (linear between the
    ** static steps, past the depth where the sphere touches, 0.2 mm) */
    double worst = 0;
    for (int k = 1; k <= 110; k++) {
        const double dk = d[3 * k + 1], Fk = d[3 * k + 2];
        assert_close(d[3 * k], k * (ramp + 5 * T) / 110, 1e-9 * ramp);
        if (dk < 0.375)
            continue;
        int j = (int)(dk / 0.03125);
        if (j >= 32)
            j = 31;
        const double w = (dk - s[2 * j]) / (s[2 * (j + 1)] - s[2 * j]);
        const double Fs = (1 - w) * s[2 * j + 1] + w * s[2 * (j + 1) + 1];
        worst = fmax(worst, fabs(Fk / Fs - 1));
    }
    print_message("slow ramp (50 periods 4L/c_s = %.4g s) of a sphere 1 mm into the cube, nu %.3g: "
                  "force at 1 mm %.6g N, static %.6g N; worst departure from the static curve "
                  "past 0.375 mm %.3f %%\n",
                  T, nu, d[3 * 110 + 2], s[2 * 32 + 1], 100 * worst);
    assert_close(d[3 * 110 + 1], 1, 1e-12);
    assert_true(worst < 0.02);
    assert_close(d[3 * 110 + 2] / s[2 * 32 + 1], 1, 0.005); /* held at the end */
}

/* The cube's sides on rollers (x held on x = 0 and 10, y on y = 0 and 10), its bottom held in z,
** a uniform traction on its top: a column in uniaxial strain, whose axial waves travel at
** c = sqrt(M / rho), M = lambda + 2 mu. */
#define COLUMN                                                                                     \
    " \"displaced\": [{\"below\": {\"axis\": \"z\", \"value_mm\": 0}, \"by_mm\": [null, null, 0]},\n" \
    "  {\"below\": {\"axis\": \"x\", \"value_mm\": 0}, \"by_mm\": [0, null, null]},\n"             \
    "  {\"above\": {\"axis\": \"x\", \"value_mm\": 10}, \"by_mm\": [0, null, null]},\n"            \
    "  {\"below\": {\"axis\": \"y\", \"value_mm\": 0}, \"by_mm\": [null, 0, null]},\n"             \
    "  {\"above\": {\"axis\": \"y\", \"value_mm\": 10}, \"by_mm\": [null, 0, null]}],\n"           \
    " \"loaded\": {\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, %g]}"

/* Runs the column with the load applied at once over `periods` of 4 L / c in `steps` steps,
** damping c (1/s; negative: a damping ratio of 0.2 in the slowest axial mode); the top's mean uz per step into uz (steps + 1), the static one into *us, the
** period 4 L / c into *T. */
static void column(const char *name, double periods, int steps, double damping, double *uz,
                   double *us, double *T)
{
    char mesh[600], scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(mesh, sizeof mesh, "%s/column.msh", dir);
    write_cube(mesh, 2);
    const double F = -2e-3; /* 2e-5 MPa on the top: the linear range */
    snprintf(scene, sizeof scene, "%s/%s-static.json", dir, name);
    snprintf(csv, sizeof csv, "%s/%s-static.csv", dir, name);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45, "
            "\"steps\": 1},\n" COLUMN "}\n", mesh, F);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
        fail_msg("%s", err);
    double v[2 * 19];
    assert_int_equal(read_csv(csv, head, sizeof head, v, 19, 2), 2);
    *us = v[19 + 18];
    double E_kPa, nu;
    body_E_nu(out, &E_kPa, &nu);
    const double rho = 1e-9, M = E_kPa * 1e-3 * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
    *T = 4 * 10 / sqrt(M / rho);
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    f = fopen(scene, "w");
    assert_non_null(f);
    if (damping < 0) /* damping ratio 0.2 in the slowest mode */
        damping = 0.4 * 2 * M_PI / *T;
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45, "
            "\"duration_s\": %.17g, \"ramp_s\": 0, \"damping_per_s\": %.17g},\n"
            " \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": %.17g},\n" COLUMN "}\n",
            mesh, periods * *T, damping, periods * *T / steps, F);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
        fail_msg("%s", err);
    double *w = malloc((size_t)(steps + 1) * 20 * sizeof *w);
    assert_non_null(w);
    assert_int_equal(read_csv(csv, head, sizeof head, w, 20, steps + 1), steps + 1);
    assert_non_null(strstr(head, "time_s,load_factor,"));
    for (int k = 0; k <= steps; k++)
        uz[k] = w[20 * k + 19];
    free(w);
}

static void a_load_applied_at_once_makes_the_column_ring_at_its_wave_period(void **state)
{
    (void)state;
    enum { STEPS = 300 };
    double uz[STEPS + 1], us, T;
    column("ring", 3, STEPS, 0, uz, &us, &T);
    /* crossings of the static displacement, upward and downward: half periods apart */
    double cross[20];
    int nc = 0;
    double peak = 0, lastpeak = 0, firstpeak = 0;
    for (int k = 1; k <= STEPS && nc < 20; k++) {
        const double a = uz[k - 1] - us, b = uz[k] - us;
        if ((a < 0) != (b < 0) && k > 1)
            cross[nc++] = (k - 1 + a / (a - b)) * 3 * T / STEPS;
        peak = fmin(peak, uz[k]);
        if (k <= STEPS / 3)
            firstpeak = fmin(firstpeak, uz[k]);
        if (k > 2 * STEPS / 3)
            lastpeak = fmin(lastpeak, uz[k]);
    }
    /* the oscillation's mean square about the static displacement over the first and the last
    ** period (a triangle wave from 0 to 2 us: us^2 / 3), which a scheme that loses energy lowers */
    double ms[2] = {0, 0};
    for (int k = 0; k < STEPS / 3; k++) {
        ms[0] += (uz[k] - us) * (uz[k] - us) / (STEPS / 3);
        ms[1] += (uz[k + 2 * STEPS / 3] - us) * (uz[k + 2 * STEPS / 3] - us) / (STEPS / 3);
    }
    print_message("column: rms about the static displacement over the first and third periods "
                  "%.4f, %.4f of it (triangle wave: %.4f)\n", sqrt(ms[0]) / fabs(us),
                  sqrt(ms[1]) / fabs(us), 1 / sqrt(3.0));
    assert_true(nc >= 5);
    const double period = 2 * (cross[nc - 1] - cross[0]) / (nc - 1);
    print_message("column, load at once: static %.6g mm, peaks %.6g (first period) %.6g (third) "
                  "= %.4f, %.4f of it; period %.6g s from %d crossings, 4L/c %.6g s (%.2f %%)\n",
                  us, firstpeak, lastpeak, firstpeak / us, lastpeak / us, period, nc, T,
                  100 * (period / T - 1));
    (void)peak;
    assert_close(period / T, 1, 0.03);
    assert_close(firstpeak / us, 2, 0.2);
    assert_close(sqrt(ms[0]) / fabs(us), 1 / sqrt(3.0), 0.05);
    assert_close(sqrt(ms[1]) / sqrt(ms[0]), 1, 0.01); /* no energy lost */
}

static void a_damped_column_settles_at_the_static_displacement(void **state)
{
    (void)state;
    enum { STEPS = 300 };
    double uz[STEPS + 1], us, T;
    /* damping ratio 0.2 in the slowest axial mode (omega = 2 pi / T): c = 0.4 omega */
    column("damped", 6, STEPS, -1, uz, &us, &T);
    print_message("damped column: after 6 periods %.6g mm, static %.6g mm (%.3f %%)\n",
                  uz[STEPS], us, 100 * (uz[STEPS] / us - 1));
    assert_close(uz[STEPS] / us, 1, 0.02);
    assert_true(fabs(uz[STEPS / 2] / us - 1) > fabs(uz[STEPS] / us - 1)); /* decaying */
}

/* A small dynamic scene of the cube with the given extra keys (body keys, root keys); its run's
** exit status, stderr in err. */
static int dynamic_scene(const char *name, const char *body_keys, const char *root_keys,
                         const char *args, char *err, size_t cap)
{
    char mesh[600], scene[600], csv[600], out[8192];
    snprintf(mesh, sizeof mesh, "%s/small.msh", dir);
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    write_cube(mesh, 2.5);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1%s},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"loaded\": {\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"force_N\": [0, 0, -1e-3]}%s}\n",
            mesh, body_keys, root_keys);
    fclose(f);
    return tu_run(out, sizeof out, err, cap, "simulate %s -o %s %s", scene, csv, args);
}

static void bad_dynamic_keys_are_refused_naming_the_key_and_write_nothing(void **state)
{
    (void)state;
    static const struct {
        const char *body, *root, *args, *must;
    } cases[] = {
        {", \"duration_s\": 1", "", "", "key 'body.duration_s' goes with a dynamic run"},
        {"", ", \"integrator\": {\"dt_s\": 0.01}", "", "key 'integrator' goes with a body's dynamic"},
        {"", ", \"density_t_per_mm3\": 1e-9", "", "key 'density_t_per_mm3' goes with"},
        {"", ", \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": 0.01}", "",
         "missing key 'body.duration_s'"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}", "",
         "missing key 'integrator.dt_s'"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": -1}", "",
         "'integrator.dt_s'"},
        {", \"duration_s\": 1, \"ramp_s\": -2", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "'body.ramp_s'"},
        {", \"duration_s\": 1, \"damping_per_s\": \"x\"", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "'body.damping_per_s'"},
        {", \"duration_s\": 1, \"steps\": 4", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "key 'body.steps': a dynamic run's steps"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true, \"gravity\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "key 'effects.gravity': a body takes"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1, \"substeps\": 3}", "", "key 'integrator.substeps'"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 1e-8}", "", "key 'integrator.dt_s' = 1e-08"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, \"density_t_per_mm3\": 0, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "'density_t_per_mm3'"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}, \"haptic\": {\"path\": [[0, 0], [10, 0.1]]}", "",
         "key 'haptic': the haptic loop"},
        {", \"duration_s\": 1, \"newmark_gamma\": 0.4", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.1}", "", "'body.newmark_gamma'"},
        {", \"newmark_gamma\": 0.6", "", "", "key 'body.newmark_gamma' goes with a dynamic run"},
        /* the budget: 1000 implicit steps over --max-steps, and over --max-work */
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.001}", "--max-steps 999",
         "key 'integrator.dt_s' = 0.001: 1000 implicit steps"},
        {", \"duration_s\": 1", ", \"effects\": {\"inertia\": true}, "
         "\"integrator\": {\"dt_s\": 0.001}", "--max-work 1e6", "at most"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char err[8192], csv[600];
        int rc = dynamic_scene("bad", cases[k].body, cases[k].root, cases[k].args, err, sizeof err);
        if (rc != 65 || !strstr(err, cases[k].must))
            fail_msg("case %zu: exit %d, expected 65 with \"%s\"; stderr: %s", k, rc,
                     cases[k].must, err);
        snprintf(csv, sizeof csv, "%s/bad.csv", dir);
        struct stat sb;
        assert_true(stat(csv, &sb) != 0);
    }
    /* the same scene within the budget runs, and writes one VTU pair per step and their times */
    char err[8192], path[700];
    assert_int_equal(dynamic_scene("good", ", \"duration_s\": 0.004, \"ramp_s\": 0.002",
                                   ", \"effects\": {\"inertia\": true}, "
                                   "\"integrator\": {\"dt_s\": 0.001}",
                                   "--max-steps 4 --vtu /dev/null/x", err, sizeof err), 73);
    snprintf(path, sizeof path, "--vtu %s/vtu", dir);
    if (dynamic_scene("good", ", \"duration_s\": 0.004, \"ramp_s\": 0.002",
                      ", \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": 0.001}",
                      path, err, sizeof err) != 0)
        fail_msg("%s", err);
    snprintf(path, sizeof path, "%s/vtu/body.pvd", dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char pvd[8192];
    size_t n = fread(pvd, 1, sizeof pvd - 1, f);
    pvd[n] = 0;
    fclose(f);
    assert_non_null(strstr(pvd, "timestep=\"0.004\" group=\"\" part=\"1\" file=\"springs_0004.vtu\""));
    assert_null(strstr(pvd, "0005"));
    snprintf(path, sizeof path, "%s/vtu/body_0002.vtu", dir);
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    char head[256];
    double v[5 * 5];
    snprintf(path, sizeof path, "%s/good.csv", dir);
    assert_int_equal(read_csv(path, head, sizeof head, v, 5, 5), 5);
    assert_string_equal(head, "time_s,load_factor,loaded_ux_mm,loaded_uy_mm,loaded_uz_mm\n");
    assert_close(v[5 * 1 + 1], 0.5, 1e-12); /* half the ramp at 1 ms */
    assert_close(v[5 * 4 + 1], 1, 0);
    assert_true(v[5 * 4 + 4] < 0);
}

/* The shipped liver scene run in time: the punch ramped 8 mm in 0.5 s, held 0.5 s, damping
** 50 1/s (about half the critical damping of the liver's slowest modes), 100 steps; without
** numerical damping (gamma 1/2) the one or two nodes on the punch's face vibrate on its penalty
** from step to step; with gamma 0.6 the force settles at the static run's. */
static void the_liver_punched_in_time_settles_at_the_static_force(void **state)
{
    (void)state;
    struct stat sb;
    if (stat("../shared/meshes/liver2.msh", &sb) != 0)
        skip(); /* the shared meshes are absent */
    char scene[600], csv[600], out[8192], err[8192], head[2048];
    snprintf(csv, sizeof csv, "%s/liver-static.csv", dir);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate data/scenes/liver_probe.json -o %s",
               csv) != 0)
        fail_msg("%s", err);
    double s[17 * 2];
    assert_int_equal(read_csv(csv, head, sizeof head, s, 2, 17), 17);
    const double Fs = s[2 * 16 + 1];
    double last[2][6];
    for (int g = 0; g < 2; g++) {
        snprintf(scene, sizeof scene, "%s/liver-%d.json", dir, g);
        snprintf(csv, sizeof csv, "%s/liver-%d.csv", dir, g);
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f, "{\"spring\": {\"fit\": \"fits/series/muscle_compression_relaxation_fiber30.json\"},\n"
                " \"body\": {\"mesh\": \"../shared/meshes/liver2.msh\", \"unit_mm\": 100, "
                "\"poisson_ratio\": 0.45, \"duration_s\": 1, \"ramp_s\": 0.5, \"damping_per_s\": 50, "
                "\"newmark_gamma\": %g},\n"
                " \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": 0.01},\n"
                " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": -60}},\n"
                " \"probe\": {\"shape\": \"punch\", \"radius_mm\": 20, \"center_mm\": [77.56, 3.07, "
                "45.93], \"direction\": [0, 0, -1], \"depth_mm\": 8}}\n", g ? 0.6 : 0.5);
        fclose(f);
        if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv) != 0)
            fail_msg("%s", err);
        double v[101 * 3];
        assert_int_equal(read_csv(csv, head, sizeof head, v, 3, 101), 101);
        for (int k = 0; k < 6; k++)
            last[g][k] = v[3 * (95 + k) + 2] / Fs;
    }
    print_message("liver punched 8 mm in 0.5 s, held 0.5 s: static %.6g N; the last 6 steps' "
                  "force over it, gamma 0.5: %.3f %.3f %.3f %.3f %.3f %.3f; gamma 0.6: %.4f %.4f "
                  "%.4f %.4f %.4f %.4f\n", Fs, last[0][0], last[0][1], last[0][2], last[0][3],
                  last[0][4], last[0][5], last[1][0], last[1][1], last[1][2], last[1][3],
                  last[1][4], last[1][5]);
    for (int k = 0; k < 6; k++)
        assert_close(last[1][k], 1, 0.02);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_slow_ramp_gives_the_static_force_depth_curve),
        cmocka_unit_test(a_load_applied_at_once_makes_the_column_ring_at_its_wave_period),
        cmocka_unit_test(a_damped_column_settles_at_the_static_displacement),
        cmocka_unit_test(bad_dynamic_keys_are_refused_naming_the_key_and_write_nothing),
        cmocka_unit_test(the_liver_punched_in_time_settles_at_the_static_force),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
