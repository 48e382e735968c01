/*
** Tests of the analysis of a scene's run (src/check/hysteresis.c):
**  - the first unstable sample;
**  - the loop energy: a rectangle exactly, a viscous ellipse against pi eta omega e0^2, the sign of
**    the orientation;
**  - the cycles of a run: energy per cycle and the strain where the unloading stress reaches zero
**    (interpolated), or the strain at zero force under a force drive;
**  - the recovery test on a dashpot lattice: strain left at zero force, then recovered; not run
**    for a scene it does not apply to.
*/
#include "testutil.h"

#include "check/hysteresis.h"
#include "model/lattice.h"
#include "conifit/spring.h"

static void the_first_unstable_sample_is_found(void **state)
{
    (void)state;
    cf_msm_sample s[6];
    memset(s, 0, sizeof s);
    s[0].neg_pivots = -1; /* unknown is not unstable */
    assert_int_equal(cf_hysteresis_first_unstable(s, 6), 6);
    s[4].neg_pivots = 2;
    s[5].neg_pivots = 1;
    assert_int_equal(cf_hysteresis_first_unstable(s, 6), 4);
    assert_int_equal(cf_hysteresis_first_unstable(s, 4), 4);
}

static void loop_energy_is_the_enclosed_area(void **state)
{
    (void)state;
    /* rectangle: load at 1 MPa from strain 0 to 0.1, unload at zero stress: 0.1 MPa = 100 kPa */
    cf_msm_sample r[5];
    memset(r, 0, sizeof r);
    const double e[5] = {0, 0.1, 0.1, 0, 0}, sg[5] = {1, 1, 0, 0, 1};
    for (int k = 0; k < 5; k++)
        r[k].strain = e[k], r[k].stress_MPa = sg[k];
    assert_close(cf_hysteresis_loop_energy(r, 0, 4), 100.0, 1e-12);
    /* the same path run backwards gives back energy */
    cf_msm_sample b[5];
    for (int k = 0; k < 5; k++)
        b[k] = r[4 - k];
    assert_close(cf_hysteresis_loop_energy(b, 0, 4), -100.0, 1e-12);
    /* a single sample encloses nothing */
    assert_close(cf_hysteresis_loop_energy(r, 2, 2), 0.0, 0.0);
    /* Kelvin-Voigt material sigma = E e + eta de/dt under e = e0 sin(w t): one cycle dissipates
    ** pi eta w e0^2 whatever E; trapezoids converge to it as the square of the step */
    enum { N = 4001 };
    static cf_msm_sample v[N];
    const double E = 2.0, eta = 0.3, w = 2.0 * M_PI / 10.0, e0 = 0.05;
    for (int k = 0; k < N; k++) {
        const double t = 10.0 * k / (N - 1);
        v[k].t_s = t;
        v[k].strain = e0 * sin(w * t);
        v[k].stress_MPa = E * v[k].strain + eta * e0 * w * cos(w * t);
    }
    const double want = M_PI * eta * w * e0 * e0 * 1e3;
    assert_close(cf_hysteresis_loop_energy(v, 0, N - 1), want, 1e-6 * want);
}

/* A two-cycle run: strain up to 0.2 and back in each cycle, stress linear in strain on loading
** and shifted down by 0.01 MPa on unloading, so that it reaches zero at strain 0.05. */
static void cycles_of_a_run_give_their_energy_and_zero_stress_strain(void **state)
{
    (void)state;
    enum { PER = 20, N = 2 * PER + 1 };
    cf_msm_sample s[N];
    memset(s, 0, sizeof s);
    for (int k = 0; k < N; k++) {
        const int j = k % PER; /* place in the cycle: loading up to PER / 2, then unloading */
        const int up = j <= PER / 2 && !(k > 0 && j == 0);
        const double e = 0.02 * (up ? j : (PER - j) % PER);
        s[k].strain = e;
        s[k].stress_MPa = up ? 0.2 * e : 0.2 * e - 0.01;
    }
    cf_scene sc;
    memset(&sc, 0, sizeof sc);
    sc.kind = CF_PROTO_CYCLES;
    sc.drive = CF_DRIVE_DISPLACEMENT;
    sc.cycles = 2;
    for (int c = 0; c < 2; c++) {
        const cf_hysteresis_cycle cy = cf_hysteresis_cycle_of(&sc, s, N, c);
        /* unloading: 0.2 e - 0.01 = 0 at e = 0.05 (between samples, interpolated exactly) */
        assert_close(cy.zero_strain, 0.05, 1e-12);
        assert_close(cy.energy_kPa, cf_hysteresis_loop_energy(s, (size_t)c * PER,
                                                              (size_t)(c + 1) * PER),
                     0.0);
        /* the band between the branches, 0.01 MPa wide over 0.2 of strain, is 2 kPa; the jumps
        ** between the branches at the turning points cut 0.1 kPa each (trapezoids of 0.02
        ** strain): cycle 1 has one such jump inside, cycle 2 two */
        assert_close(cy.energy_kPa, c == 0 ? 1.9 : 1.8, 1e-12);
    }
    /* under a force drive the residual strain is the strain at the cycle's end */
    sc.drive = CF_DRIVE_FORCE;
    s[PER].strain = 0.03;
    assert_close(cf_hysteresis_cycle_of(&sc, s, N, 0).zero_strain, 0.03, 0.0);
    /* an unloading that never reaches zero stress leaves the end strain */
    sc.drive = CF_DRIVE_DISPLACEMENT;
    for (int k = PER / 2; k <= PER; k++)
        s[k].stress_MPa = 0.001;
    assert_close(cf_hysteresis_cycle_of(&sc, s, N, 0).zero_strain, 0.03, 0.0);
}

/* Writes a scene of one cell with the given protocol and effects; returns its path. */
static const char *scene_file(const char *dir, const char *name, const char *rest)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    const cf_spring sp = {6, 15, 2.5, 2, 26, 10};
    fprintf(f, "{\"spring\": {\"params\": {");
    for (int k = 0; k < CF_P_COUNT; k++)
        fprintf(f, "%s\"%s\": %.17g", k ? ", " : "", cf_spring_param_info(k)->key,
                cf_spring_get(&sp, k));
    fprintf(f, "}}, \"lattice\": {\"nx\": 1, \"ny\": 1, \"nz\": 1}, %s}", rest);
    fclose(f);
    return path;
}

/* Loads and runs a scene; the samples are malloc'd into *s. */
static void run_scene(const char *file, cf_scene *sc, cf_law *law, cf_msm_sample **s)
{
    cf_error err = {0};
    if (cf_scene_load(file, sc, &err) != CF_OK)
        fail_msg("scene refused: %s", err.msg);
    assert_int_equal(cf_law_init(law, &sc->spring, &err), CF_OK);
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, law, sc->method, &sc->cfg.lattice, &err), CF_OK);
    *s = calloc(sc->nsamples, sizeof **s);
    assert_non_null(*s);
    const cf_msm_path path = cf_scene_path(sc);
    if (cf_msm_run(&lat, &sc->effects, &sc->cfg, &path, sc->sample_t_s, sc->nsamples, *s, NULL,
                   NULL, &err) != CF_OK)
        fail_msg("run failed: %s", err.msg);
    cf_lattice_free(&lat);
}

static void a_dashpot_lattice_recovers_the_strain_left_at_zero_force(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-hyst-XXXXXX";
    assert_non_null(mkdtemp(dir));
    cf_scene sc;
    cf_law law;
    cf_msm_sample *s;
    run_scene(scene_file(dir, "cyc.json",
                         "\"protocol\": {\"kind\": \"cycles\", \"to_strain\": 0.2, \"period_s\": "
                         "10, \"count\": 1}, \"effects\": {\"damping\": {\"eta_kPa_s\": 5}}, "
                         "\"samples_per_segment\": 20"),
              &sc, &law, &s);
    /* the dashpots dissipate: a positive loop, and the unloading reaches zero stress early */
    const cf_hysteresis_cycle cy = cf_hysteresis_cycle_of(&sc, s, sc.nsamples, 0);
    assert_true(cy.energy_kPa > 0);
    assert_true(cy.zero_strain > 1e-3 && cy.zero_strain < 0.2);
    cf_hysteresis_recovery r;
    cf_error err = {0};
    assert_int_equal(cf_hysteresis_recovery_test(&sc, &law, s, sc.nsamples, &r, &err), CF_OK);
    assert_int_equal(r.ran, 1);
    double peak = 0;
    for (size_t k = 0; k < sc.nsamples; k++)
        peak = fmax(peak, s[k].stress_MPa);
    assert_close(r.peak_MPa, peak, 0.0);
    assert_close(r.hold_s, 100.0, 1e-9); /* ten periods */
    assert_true(r.zero_strain > 1e-3);   /* held shortened at zero force */
    assert_true(fabs(r.end_strain) < 1e-3 * r.zero_strain); /* and back */
    assert_int_equal(r.recovered, 1);
    free(s);
    cf_law_free(&law);
    cf_scene_free(&sc);
    /* a static scene: no test */
    run_scene(scene_file(dir, "ramp.json",
                         "\"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.1, \"duration_s\": "
                         "1}"),
              &sc, &law, &s);
    r.ran = 7;
    assert_int_equal(cf_hysteresis_recovery_test(&sc, &law, s, sc.nsamples, &r, &err), CF_OK);
    assert_int_equal(r.ran, 0);
    assert_close(r.end_strain, 0.0, 0.0);
    free(s);
    cf_law_free(&law);
    cf_scene_free(&sc);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_first_unstable_sample_is_found),
        cmocka_unit_test(loop_energy_is_the_enclosed_area),
        cmocka_unit_test(cycles_of_a_run_give_their_energy_and_zero_stress_strain),
        cmocka_unit_test(a_dashpot_lattice_recovers_the_strain_left_at_zero_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
