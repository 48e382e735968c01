/*
** The hourglass control in a lattice pressed on part of its top face (issue 42, lattice-fit.md,
** "A non-uniform state does feel it"). A lattice scene drives its whole top face; no scene key
** presses part of it, so the test loads the library's lattice directly: the brain cortex's
** joint fit with its volume term (tests/unit/data/brain_cortex_pair_volume.json, made once by
** `conifit fit --joint --law auto --volume fit` of ../shared/datasets/brain_cortex_{compression,
** tension,shear}.csv; its better type, the telescoping pair, κ = 0.00296 MPa) on 8 x 8 x 4
** cells clamped at the base, the top-face list cut down to the 3 x 3 nodes over the middle
** 2 x 2 cells and the force drive putting the same force on each of them (a pressure patch,
** not a rigid punch; the rest of the top is free), ramped in 40 static steps to 2.394 N:
**  - the control stiffens the patch: its force at 5 % of the height (mean indentation of the
**    patch nodes) rises with the fraction, by 0.3 to 1.5 % at 0.1 and 2 to 5 % at 0.5 (measured
**    0.64 % and 3.10 % with these 40 steps);
**  - without it the lattice loses stability inside the run (measured: from 10.9 % indentation,
**    2.05 N; a spring reaches solid at 11.9 %), with the default 0.5 every step is stable.
*/
#include "testutil.h"

#include <string.h>

#include "io/scene.h"
#include "model/lattice.h"
#include "model/msm.h"

#define FIT "tests/unit/data/brain_cortex_pair_volume.json"
#define NS 40
#define LOAD_MPA 0.00266 /* force per patch node over H^2: 9 nodes, 2.394 N in all */

/* Runs the patch at hourglass fraction hg; fills e[NS] (patch indentation over the height),
** F[NS] (N) and neg[NS] (negative pivots); returns the samples done. */
static size_t run_patch(double hg, double *e, double *F, long *neg)
{
    static const char scene[] = "{\"spring\": {\"fit\": \"" FIT "\"}, \"lattice\": {\"nx\": 8, "
                                "\"ny\": 8, \"nz\": 4, \"bottom\": \"clamped\"}, \"protocol\": "
                                "{\"kind\": \"ramp\", \"to_strain\": 0.1, \"duration_s\": 1}}";
    cf_scene sc;
    cf_law law, ext;
    cf_lattice lat;
    cf_error err = {0};
    memset(&ext, 0, sizeof ext);
    if (cf_scene_parse(scene, "patch scene", &sc, &err) != CF_OK ||
        cf_scene_law(&sc, &law, &ext, &err) != CF_OK)
        fail_msg("%s", err.msg);
    sc.cfg.lattice.hourglass = hg;
    if (cf_lattice_create(&lat, &law, sc.method, &sc.cfg.lattice, &err) != CF_OK)
        fail_msg("%s", err.msg);
    const double H = lat.H_mm;
    size_t k = 0;
    for (size_t t = 0; t < lat.ntop; t++) { /* the middle 2 x 2 cells: 3H <= X, Y <= 5H */
        const uint32_t p = lat.top[t];
        if (lat.X[p] > 2.99 * H && lat.X[p] < 5.01 * H && lat.Y[p] > 2.99 * H &&
            lat.Y[p] < 5.01 * H) {
            lat.top[k] = p;
            lat.top_share[k++] = 1.0;
        }
    }
    assert_int_equal(k, 9);
    lat.ntop = k;
    const double tp[2] = {0, 1}, vp[2] = {0, LOAD_MPA};
    const cf_msm_path path = {CF_DRIVE_FORCE, 2, tp, vp};
    double ts[NS];
    cf_msm_sample out[NS];
    for (int i = 0; i < NS; i++)
        ts[i] = (i + 1.0) / NS;
    cf_msm_effects fx;
    memset(&fx, 0, sizeof fx);
    size_t done = 0;
    if (cf_msm_run(&lat, &fx, &sc.cfg, &path, ts, NS, out, &done, NULL, &err) != CF_OK)
        fail_msg("hourglass %g: %s", hg, err.msg);
    for (size_t i = 0; i < done; i++) {
        e[i] = out[i].strain;
        F[i] = out[i].t_s * LOAD_MPA * H * H * (double)k;
        neg[i] = out[i].neg_pivots;
    }
    cf_lattice_free(&lat);
    cf_law_free(&law);
    cf_law_free(&ext);
    cf_scene_free(&sc);
    return done;
}

/* The force at indentation x, linear between the samples. */
static double force_at(const double *e, const double *F, size_t n, double x)
{
    double e0 = 0, F0 = 0;
    for (size_t i = 0; i < n; i++) {
        if (e[i] >= x)
            return F0 + (F[i] - F0) * (x - e0) / (e[i] - e0);
        e0 = e[i];
        F0 = F[i];
    }
    fail_msg("indentation %g not reached (%g)", x, e0);
    return 0;
}

static void hourglass_control_under_a_pressure_patch(void **state)
{
    (void)state;
    const double fr[3] = {0, 0.1, 0.5};
    double e[3][NS], F[3][NS], F5[3];
    long neg[3][NS];
    size_t first_unstable[3];
    for (int j = 0; j < 3; j++) {
        assert_int_equal(run_patch(fr[j], e[j], F[j], neg[j]), NS);
        F5[j] = force_at(e[j], F[j], NS, 0.05);
        first_unstable[j] = NS;
        for (size_t i = NS; i-- > 0;)
            if (neg[j][i] > 0)
                first_unstable[j] = i;
        print_message("hourglass %g: %.5g N at 5 %% indentation (%+.3f %%), first unstable "
                      "sample %zu of %d (indentation %.4g, %.4g N)\n",
                      fr[j], F5[j], 100 * (F5[j] / F5[0] - 1), first_unstable[j], NS,
                      first_unstable[j] < NS ? e[j][first_unstable[j]] : 0,
                      first_unstable[j] < NS ? F[j][first_unstable[j]] : 0);
    }
    const double d1 = F5[1] / F5[0] - 1, d5 = F5[2] / F5[0] - 1;
    assert_true(d1 > 0.003 && d1 < 0.015);
    assert_true(d5 > 0.02 && d5 < 0.05);
    /* without control the node-scale mode takes over past 10 % (inside the run), never below */
    assert_true(first_unstable[0] < NS && e[0][first_unstable[0]] > 0.10);
    assert_true(first_unstable[2] == NS); /* the default holds it over the whole run */
    for (size_t i = 0; i < NS; i++)
        assert_true(neg[2][i] == 0 && e[2][i] < e[0][i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hourglass_control_under_a_pressure_patch),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
