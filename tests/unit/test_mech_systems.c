/*
** The one Newton driver (model/mech.h) over both mechanical systems of the model, the cubic
** lattice (its hooks in model/msm_newton.c) and the tetrahedral body (model/body_work.c). The
** program is linked with the driver's two entries wrapped (the linker's --wrap, Makefile), so that
** it sees every call and what each returned:
**  - a lattice's static run (a fresh tangent at every step, each state's inertia), its uniaxial
**    curve (chord and Krylov steps on kept factors) and its stability limit (factored tangents'
**    inertia) are calls of cf_mech_newton and cf_mech_inertia on one system, and the run's and
**    the curve's statistics (solves, Newton iterations, linear solves) are the sums of what the
**    calls returned; the curve's stresses equal the run's to 1e-9, the run passes the stability
**    limit and the limit lies between its last stable and first unstable sample;
**  - a body probed by a sphere, statically and then in an implicit dynamic step, is solved by
**    calls of the same entry on another system (other hooks), its Newton iterations the sum of
**    the calls', and its supports carry the probe's force;
**  - the haptic loop's updates on that body are calls of the same entry on a third system (the
**    haptic hooks), one call per update, every direction from the kept factors (no tangent
**    factored by the driver), their iterations the updates', and at rest the loop's force is the
**    static solve's.
*/
#include "testutil.h"

#include "model/body.h"
#include "model/mech.h"
#include "model/msm.h"

/* What the wrapped entries saw since the last reset. */
typedef struct seen {
    size_t calls, conv, iters, reused, tangents, linear, inertia;
    const cf_mech_ops *ops; /* the hooks of the first call */
    int mixed;              /* 1: a later call had other hooks */
} seen;

static seen S;

cf_status __real_cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res,
                                cf_error *err);
cf_status __wrap_cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res,
                                cf_error *err);
cf_status __real_cf_mech_inertia(cf_mech *m, const double *r, double *dx, cf_mech_result *res,
                                 cf_error *err);
cf_status __wrap_cf_mech_inertia(cf_mech *m, const double *r, double *dx, cf_mech_result *res,
                                 cf_error *err);

static void saw(const cf_mech *m)
{
    if (!S.ops)
        S.ops = m->ops;
    else if (S.ops != m->ops)
        S.mixed = 1;
}

cf_status __wrap_cf_mech_newton(cf_mech *m, double *r, double *dx, cf_mech_result *res,
                                cf_error *err)
{
    cf_status st = __real_cf_mech_newton(m, r, dx, res, err);
    saw(m);
    S.calls++;
    S.conv += st == CF_OK && res->conv;
    S.iters += (size_t)res->iters;
    S.reused += (size_t)res->reused;
    S.tangents += (size_t)res->tangents;
    S.linear += res->linear_solves;
    return st;
}

cf_status __wrap_cf_mech_inertia(cf_mech *m, const double *r, double *dx, cf_mech_result *res,
                                 cf_error *err)
{
    cf_status st = __real_cf_mech_inertia(m, r, dx, res, err);
    saw(m);
    S.inertia++;
    S.linear += res->linear_solves;
    return st;
}

/* A soft, strongly stiffening non-telescoping spring (solid strain 0.5, H = 10 mm). */
static cf_law lattice_law(void)
{
    const cf_spring p = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &p, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

enum { N = 45 };

/* The lattice on 4^3 cells to a compressive strain of 0.45: the run, the curve, the limit. The
** hooks it was solved with into *ops. */
static void lattice_through_the_driver(const cf_mech_ops **ops)
{
    cf_law law = lattice_law();
    cf_msm_config cfg = cf_msm_default();
    cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = 4;
    double strain[N], ts[N], curve[N];
    for (int k = 0; k < N; k++) {
        strain[k] = -0.01 * (k + 1);
        ts[k] = (k + 1) / (double)N;
    }
    cf_error err = {0};
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const double t[2] = {0, 1}, v[2] = {0, 0.45};
    const cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    cf_msm_sample out[N];
    cf_msm_stats run;
    S = (seen){0};
    if (cf_msm_run(&lat, NULL, &cfg, &path, ts, N, out, NULL, &run, &err) != CF_OK)
        fail_msg("static run: %s", err.msg);
    cf_lattice_free(&lat);
    assert_true(S.calls >= N && S.calls == run.solves && !S.mixed);
    assert_int_equal(S.iters, run.newton_iters);
    assert_int_equal(S.linear, run.linear_iters);
    assert_int_equal(S.inertia, 0);
    assert_true(out[N - 1].neg_pivots > 0); /* the run went past the stability limit */
    *ops = S.ops;
    /* the curve: steps on kept factors, the same hooks */
    cf_msm_stats cur;
    S = (seen){0};
    if (cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, strain, N, curve, &cur, &err) != CF_OK)
        fail_msg("uniaxial: %s", err.msg);
    assert_true(S.ops == *ops && !S.mixed && S.calls == cur.solves && S.conv == S.calls);
    assert_int_equal(S.iters, cur.newton_iters);
    assert_int_equal(S.linear, cur.linear_iters);
    assert_true(cur.chord_iters > 0 && cur.linear_iters < run.linear_iters / 4);
    int first = -1;
    for (int k = 0; k < N; k++) {
        assert_close(curve[k], -out[k].stress_MPa, 1e-9 * fabs(out[k].stress_MPa));
        if (first < 0 && out[k].neg_pivots > 0)
            first = k;
    }
    assert_true(first > 0);
    /* the limit: a tangent factored for its inertia at each state of its scan */
    double limit = 0;
    S = (seen){0};
    assert_int_equal(cf_msm_stability_limit(&law, CF_LAW_CLOSED, &cfg, -1, &limit, &err), CF_OK);
    assert_true(S.ops == *ops && !S.mixed && S.inertia > 10 && S.calls >= S.inertia);
    print_message("lattice 4^3: %zu solves, %zu Newton iterations, %zu linear solves (curve: "
                  "%zu, %zu, %zu); stability limit at strain %.6f, between samples %.2f and "
                  "%.2f\n",
                  run.solves, run.newton_iters, run.linear_iters, cur.solves, cur.newton_iters,
                  cur.linear_iters, limit, strain[first - 1], strain[first]);
    assert_true(limit < strain[first - 1] + 1e-4 && limit > strain[first] - 1e-4);
    cf_law_free(&law);
}

/* The haptic loop on body b (probed by pr, last at 1.05 mm): 40 updates of at most 3 chord
** iterations at 1.1 mm, each one call of the driver with the haptic hooks, then a static solve
** there. */
static void haptic_through_the_driver(cf_body *b, const cf_probe *pr, const cf_mech_ops *lattice_ops,
                                      const cf_mech_ops *body_ops)
{
    enum { UPDATES = 40 };
    cf_error err = {0};
    cf_body_step st;
    size_t iters = 0;
    S = (seen){0};
    for (int k = 0; k < UPDATES; k++) {
        if (cf_body_haptic_step(b, pr, 1.1, 0, 3, &st, &err) != CF_OK)
            fail_msg("haptic update %d: %s", k, err.msg);
        iters += (size_t)st.newton_iters;
    }
    assert_int_equal(S.calls, UPDATES);
    assert_true(S.ops != lattice_ops && S.ops != body_ops && !S.mixed);
    assert_int_equal(S.iters, iters);
    assert_int_equal(S.reused, iters); /* every direction from the kept factors */
    assert_int_equal(S.tangents, 0);
    assert_int_equal(S.linear, 0);
    /* updates ended both ways: converged, and at the fixed count (the last state read by the
    ** loop, not the driver) */
    assert_true(iters > 0 && S.conv > 0 && S.conv < UPDATES && st.contacts > 0 && st.force_N > 0);
    const double haptic = st.force_N;
    const size_t conv = S.conv;
    S = (seen){0};
    if (cf_body_solve(b, pr, 1.1, 0, &st, &err) != CF_OK)
        fail_msg("static solve: %s", err.msg);
    assert_true(S.ops == body_ops);
    print_message("haptic loop: %d updates, %zu chord iterations (%zu converged updates), force "
                  "%.9g N at 1.1 mm, static %.9g N (%.2g relative)\n",
                  UPDATES, iters, conv, haptic, st.force_N, fabs(haptic / st.force_N - 1));
    assert_close(haptic, st.force_N, 2e-4 * st.force_N);
}

/* A block of 4 x 4 x 4 cells of 5 mm held at its base, a sphere of radius 10 mm pressed 1 mm into
** its top in four static steps and 0.05 mm more in an implicit dynamic step. */
static void body_through_the_driver(const cf_mech_ops *lattice_ops)
{
    const cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &p, &err), CF_OK);
    const double g[5] = {0, 5, 10, 15, 20};
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, g, 4, g, 4, g, 4, &err), CF_OK);
    assert_int_equal(cf_mesh_check(&m, "block", &err), CF_OK);
    cf_body b;
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                                    cf_body_kappa_for_nu(cf_body_mu_of_law(&law), 0.45), &err),
                     CF_OK);
    for (size_t i = 0; i < b.nn; i++)
        b.fix[i] = b.X[3 * i + 2] < 1e-9 ? CF_BODY_FIX_ALL : 0;
    b.reaction = calloc(3 * b.nn, sizeof *b.reaction);
    assert_non_null(b.reaction);
    cf_probe pr = {0};
    pr.shape = CF_PROBE_SPHERE;
    pr.radius_mm = 10;
    pr.center_mm[0] = pr.center_mm[1] = 10;
    pr.center_mm[2] = 30;
    pr.dir[2] = -1;
    cf_body_step st;
    size_t iters = 0;
    S = (seen){0};
    for (int k = 1; k <= 4; k++) {
        if (cf_body_solve(&b, &pr, 0.25 * k, 0, &st, &err) != CF_OK)
            fail_msg("body: %s", err.msg);
        iters += (size_t)st.newton_iters;
    }
    assert_true(S.calls >= 4 && S.ops != lattice_ops && !S.mixed);
    assert_int_equal(S.iters, iters);
    assert_true(st.contacts > 0 && st.force_N > 0 && st.min_J > 0);
    double support = 0;
    for (size_t i = 0; i < b.nn; i++)
        support += b.reaction[3 * i + 2];
    print_message("body: %zu nodes, %zu solves of %zu Newton iterations; force %.6g N at 1 mm, "
                  "supports %.6g N\n",
                  b.nn, S.calls, S.iters, st.force_N, support);
    assert_close(support, st.force_N, 1e-6 * st.force_N);
    /* an implicit dynamic step: the same entry, the same hooks */
    const cf_mech_ops *body_ops = S.ops;
    cf_body_motion mo;
    assert_int_equal(cf_body_motion_init(&b, 1e-9, 0, &mo, &err), CF_OK);
    const size_t before = S.calls;
    if (cf_body_dynamic_step(&b, &mo, &pr, 1.05, 1e-3, 0, &st, &err) != CF_OK)
        fail_msg("dynamic step: %s", err.msg);
    assert_true(S.calls > before && S.ops == body_ops && !S.mixed && st.force_N > 0);
    cf_body_motion_free(&mo);
    haptic_through_the_driver(&b, &pr, lattice_ops, body_ops);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

static void lattice_and_body_run_through_one_entry(void **state)
{
    (void)state;
    const cf_mech_ops *lattice_ops = NULL;
    lattice_through_the_driver(&lattice_ops);
    assert_non_null(lattice_ops);
    body_through_the_driver(lattice_ops);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lattice_and_body_run_through_one_entry),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
