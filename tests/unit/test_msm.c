/*
** Tests of the lattice solvers' public functions (src/model/msm*.c; the lattice itself, its
** moduli, energy of the symplectic integrator and the stability of a buckling column are in
** test_lattice.c):
**  - cf_msm_path_value, cf_msm_default, cf_msm_prony_check;
**  - cf_msm_run's refusals: an empty or backward path, samples out of order, a Maxwell branch
**    without a time, Prony terms with inertia, an explicit step above the stable one, a spring
**    driven past solid (with the samples done so far);
**  - force balance: a static displacement-driven run and a force-driven run to its stresses meet
**    at the same strains, and cf_msm_uniaxial gives the same curve in the table's sign;
**  - decay rates against theory in the linear range of the law, where the lattice is a linear
**    network: creep under dashpots (Kelvin-Voigt, time constant H eta / k0), stress relaxation of
**    a Maxwell branch (its tau) and of a Prony term (its tau_i, amplitude g_i);
**  - cf_msm_stability_limit: stable just below the limit, unstable just above;
**  - cf_msm_stable_step: the step an explicit run reports, shortened by dashpots;
**  - the steps on reused factors of the static solver (private: the chord and Krylov stages of
**    the Newton driver, model/mech_newton.c over model/linsolve_krylov.c, with the lattice's
**    tangent of model/msm_tangent.c, and the secant predictor of model/msm_newton.c): a
**    Krylov step solves the current tangent, and the uniaxial curve through those steps equals the one Newton finds with a fresh
**    tangent at every iteration, past the stability limit, with a fraction of the factorisations.
*/
/* conifit: vector-level: explicit lattice runs, the vectorised step */
#include "testutil.h"

#include "model/lattice.h"
#include "model/msm.h"
#include "model/msm_internal.h"

/* A soft, strongly stiffening non-telescoping spring (solid strain 0.5, H = 10 mm). */
static cf_law make_law(void)
{
    const cf_spring p = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &p, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
    return law;
}

static cf_msm_config small_config(int n)
{
    cf_msm_config c = cf_msm_default();
    c.lattice.nx = c.lattice.ny = c.lattice.nz = n;
    return c;
}

/* The law of make_law, the default configuration on n^3 cells, and its lattice. */
static void open_lattice(int n, cf_law *law, cf_msm_config *cfg, cf_lattice *lat)
{
    cf_error err = {0};
    *law = make_law();
    *cfg = small_config(n);
    if (cf_lattice_create(lat, law, CF_LAW_CLOSED, &cfg->lattice, &err) != CF_OK)
        fail_msg("lattice refused: %s", err.msg);
}

/* A strain well inside the law's linear range (|u| < u_T), compressive. */
static double linear_strain(const cf_law *law)
{
    return 0.2 * law->u_T_mm / law->p.H_mm;
}

static void path_value_is_linear_between_points_and_held_outside(void **state)
{
    (void)state;
    const double t[3] = {0, 1, 3}, v[3] = {0, 0.1, -0.1};
    const cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 3, t, v};
    assert_close(cf_msm_path_value(&p, -1), 0.0, 0.0);
    assert_close(cf_msm_path_value(&p, 0.5), 0.05, 1e-15);
    assert_close(cf_msm_path_value(&p, 2), 0.0, 1e-15);
    assert_close(cf_msm_path_value(&p, 2.5), -0.05, 1e-15);
    assert_close(cf_msm_path_value(&p, 7), -0.1, 0.0);
    const cf_msm_config c = cf_msm_default();
    assert_close(c.newton_rtol, 1e-11, 0.0);
    assert_int_equal(c.newton_max_iter, 50);
    assert_int_equal(c.lattice.nx, 3);
    assert_int_equal(c.lattice.nz, 3);
    assert_close(c.dt_s, 0.0, 0.0);
    assert_null(c.progress);
}

static void prony_terms_are_checked_naming_the_term(void **state)
{
    (void)state;
    cf_msm_effects fx = {0};
    cf_error err = {0};
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_OK);
    fx.prony_count = 2;
    fx.prony_g[0] = 0.3, fx.prony_tau_s[0] = 1;
    fx.prony_g[1] = 0.2, fx.prony_tau_s[1] = 10;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_OK);
    fx.prony_tau_s[1] = 0;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "Prony term 2"));
    fx.prony_tau_s[1] = 10;
    fx.prony_g[0] = NAN;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "Prony term 1"));
    fx.prony_g[0] = 0.8; /* 0.8 + 0.2 = 1: nothing left at equilibrium */
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "sum"));
    fx.prony_g[0] = 0.3;
    fx.prony_count = CF_PRONY_MAX + 1;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
    fx.prony_count = -1;
    assert_int_equal(cf_msm_prony_check(&fx, &err), CF_E_DATA);
}

static void bad_runs_are_refused_with_their_reason(void **state)
{
    (void)state;
    cf_law law;
    cf_msm_config cfg;
    cf_lattice lat;
    cf_error err = {0};
    open_lattice(1, &law, &cfg, &lat);
    const double t[2] = {0, 1}, v[2] = {0, 0.1}, ts[3] = {0.2, 0.6, 1.0};
    cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    cf_msm_sample out[3];
    size_t done = 99;
    cf_msm_effects fx = {0};
    /* empty path */
    cf_msm_path empty = {CF_DRIVE_DISPLACEMENT, 0, t, v};
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &empty, ts, 3, out, &done, NULL, &err),
                     CF_E_DATA);
    assert_int_equal(done, 0);
    /* a path going back in time */
    const double tb[2] = {1, 0};
    cf_msm_path back = {CF_DRIVE_DISPLACEMENT, 2, tb, v};
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &back, ts, 3, out, NULL, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "backwards"));
    /* samples out of order */
    const double tbad[3] = {0.2, 0.1, 1.0};
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &p, tbad, 3, out, NULL, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "sample time 1"));
    /* a Maxwell branch with no relaxation time */
    fx.maxwell_E_MPa = 0.01;
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &p, ts, 3, out, NULL, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "tau_s"));
    /* Prony terms are quasi-static only */
    memset(&fx, 0, sizeof fx);
    fx.inertia = 1;
    fx.prony_count = 1, fx.prony_g[0] = 0.5, fx.prony_tau_s[0] = 1;
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &p, ts, 3, out, NULL, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "inertia"));
    /* an explicit step above the stable one */
    fx.prony_count = 0;
    cf_lattice_reset(&lat);
    const double dt = cf_msm_stable_step(&lat, &fx);
    assert_true(dt > 0 && isfinite(dt));
    cfg.dt_s = 1.5 * dt;
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &p, ts, 3, out, NULL, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "stable explicit step"));
    /* statically past solid: refused at the sample that needs it, the earlier ones kept */
    cfg.dt_s = 0;
    memset(&fx, 0, sizeof fx);
    cf_lattice_reset(&lat);
    const double vs[2] = {0, 0.9 * law.travel_mm / law.p.H_mm * 2};
    cf_msm_path deep = {CF_DRIVE_DISPLACEMENT, 2, t, vs};
    const double tss[3] = {0.1, 0.2, 1.0}; /* strains 0.09, 0.18, 0.9 against solid at 0.5 */
    cf_status st = cf_msm_run(&lat, &fx, &cfg, &deep, tss, 3, out, &done, NULL, &err);
    assert_int_not_equal(st, CF_OK);
    assert_int_equal(done, 2);
    assert_close(out[1].strain, 0.18, 1e-12);
    assert_true(out[1].stress_MPa > out[0].stress_MPa && out[0].stress_MPa > 0);
    /* and the uniaxial curve refuses a strain at solid, naming it */
    const double at_solid = -law.travel_mm / law.p.H_mm;
    double stress;
    assert_int_equal(cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, &at_solid, 1, &stress, NULL, &err),
                     CF_E_DATA);
    assert_non_null(strstr(err.msg, "solid strain"));
    cf_lattice_free(&lat);
    cf_law_free(&law);
}

/* Static equilibria driven by displacement and by force meet: the force-driven run to the
** stresses of the displacement-driven one ends at its strains, and carries exactly the stress it
** was asked for; cf_msm_uniaxial is the same curve in the table's sign. */
static void displacement_and_force_drives_meet_at_the_same_equilibria(void **state)
{
    (void)state;
    cf_law law = make_law();
    cf_msm_config cfg = small_config(2);
    cf_lattice lat;
    cf_error err = {0};
    enum { N = 6 };
    const double emax = 0.3; /* well into the stiffening: solid at 0.5 */
    const double t[2] = {0, 1}, v[2] = {0, emax};
    double ts[N];
    for (int k = 0; k < N; k++)
        ts[k] = (k + 1) / (double)N;
    cf_msm_sample sd[N], sf[N];
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const cf_msm_path pd = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    assert_int_equal(cf_msm_run(&lat, NULL, &cfg, &pd, ts, N, sd, NULL, NULL, &err), CF_OK);
    cf_lattice_free(&lat);
    /* the force path through the same stresses, sampled at the same times */
    double tf[N + 1], vf[N + 1];
    tf[0] = 0, vf[0] = 0;
    for (int k = 0; k < N; k++) {
        tf[k + 1] = ts[k];
        vf[k + 1] = sd[k].stress_MPa;
        assert_close(sd[k].strain, emax * ts[k], 1e-14);
        assert_true(k == 0 || sd[k].stress_MPa > sd[k - 1].stress_MPa);
    }
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const cf_msm_path pf = {CF_DRIVE_FORCE, N + 1, tf, vf};
    assert_int_equal(cf_msm_run(&lat, NULL, &cfg, &pf, ts, N, sf, NULL, NULL, &err), CF_OK);
    cf_lattice_free(&lat);
    double strain[N], stress[N];
    for (int k = 0; k < N; k++) {
        assert_close(sf[k].stress_MPa, sd[k].stress_MPa, 1e-9 * sd[k].stress_MPa);
        assert_close(sf[k].strain, sd[k].strain, 1e-8 * sd[k].strain);
        strain[k] = -sd[k].strain;
    }
    assert_int_equal(cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, strain, N, stress, NULL, &err),
                     CF_OK);
    for (int k = 0; k < N; k++)
        assert_close(stress[k], -sd[k].stress_MPa, 1e-9 * sd[k].stress_MPa);
    cf_law_free(&law);
}

/* Runs the 2 x 2 x 2 lattice of make_law with effects fx along path p, sampled every dt from
** t0 (n samples), with implicit steps of h; the samples into out. */
static void run_quasi(const cf_msm_effects *fx, const cf_msm_path *p, double t0, double dt,
                      size_t n, double h, cf_msm_sample *out)
{
    cf_law law = make_law();
    cf_msm_config cfg = small_config(2);
    cfg.dt_s = h;
    cf_lattice lat;
    cf_error err = {0};
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    double *ts = malloc(n * sizeof *ts);
    assert_non_null(ts);
    for (size_t k = 0; k < n; k++)
        ts[k] = t0 + dt * (double)k;
    if (cf_msm_run(&lat, fx, &cfg, p, ts, n, out, NULL, NULL, &err) != CF_OK)
        fail_msg("run failed: %s", err.msg);
    free(ts);
    cf_lattice_free(&lat);
    cf_law_free(&law);
}

/* Decay per sample interval of a quantity approaching its limit geometrically: from three
** equally spaced samples, (x2 - x1) / (x1 - x0). */
static double decay_ratio(double x0, double x1, double x2)
{
    return (x2 - x1) / (x1 - x0);
}

/* Dashpots beside every spring, each with the spring's own weight and rest length, make the
** linear lattice a Kelvin-Voigt solid sigma = E (eps + tau deps/dt) with tau = H eta / k0: under
** a held stress the strain approaches its limit as exp(-t / tau). */
static void creep_under_dashpots_decays_at_the_kelvin_voigt_rate(void **state)
{
    (void)state;
    cf_law law = make_law();
    const double k0 = law.k0_N_per_mm, H = law.p.H_mm;
    const double tau = 1.0, eta = tau * k0 / H; /* MPa s */
    /* the stress of the static lattice at a small strain inside the linear range (the change of
    ** geometry under the held stress shifts the rate by about half the strain) */
    double strain = -0.025 * linear_strain(&law), stress;
    cf_msm_config cfg = small_config(2);
    cf_error err = {0};
    assert_int_equal(cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, &strain, 1, &stress, NULL, &err),
                     CF_OK);
    cf_law_free(&law);
    cf_msm_effects fx = {0};
    fx.eta_MPa_s = eta;
    const double t[3] = {0, 0.01, 10}, v[3] = {0, -stress, -stress};
    const cf_msm_path p = {CF_DRIVE_FORCE, 3, t, v};
    enum { N = 40 };
    cf_msm_sample s[N];
    const double dt = 0.1, h = 1e-3 * tau;
    run_quasi(&fx, &p, 0.5, dt, N, h, s);
    /* the rate 1/tau, within what backward Euler (h / (2 tau)) and the geometry leave */
    for (int k = 0; k + 2 < N; k += 5) {
        const double rate = -log(decay_ratio(s[k].strain, s[k + 1].strain, s[k + 2].strain)) / dt;
        if (!(fabs(rate * tau - 1) <= 3e-3))
            fail_msg("creep at t = %g s decays at %.6g /s, Kelvin-Voigt 1/tau = %.6g /s",
                     s[k].t_s, rate, 1 / tau);
    }
    /* and it creeps towards the static strain */
    assert_true(s[N - 1].strain < -strain && s[N - 1].strain > s[0].strain);
    assert_close(s[N - 1].strain, -strain, 0.05 * -strain);
}

/* A Maxwell branch beside every spring: under a held strain its stress relaxes as exp(-t/tau)
** exactly (the branch is advanced by its exact exponential update), the springs' does not. */
static void held_strain_relaxes_at_the_maxwell_time(void **state)
{
    (void)state;
    cf_law law = make_law();
    const double e = linear_strain(&law);
    cf_law_free(&law);
    cf_msm_effects fx = {0};
    fx.maxwell_E_MPa = 0.05;
    fx.maxwell_tau_s = 2.0;
    const double t[3] = {0, 0.5, 20}, v[3] = {0, e, e};
    const cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 3, t, v};
    enum { N = 12 };
    cf_msm_sample s[N];
    const double dt = 1.0;
    run_quasi(&fx, &p, 1.0, dt, N, 0.05, s);
    const double theory = exp(-dt / fx.maxwell_tau_s);
    for (int k = 0; k + 2 < N; k++) {
        assert_close(s[k].strain, e, 1e-15);
        const double r = decay_ratio(s[k].stress_MPa, s[k + 1].stress_MPa, s[k + 2].stress_MPa);
        if (!(fabs(r - theory) <= 1e-6))
            fail_msg("Maxwell relaxation over %g s at t = %g s: %.9g, exp(-dt/tau) = %.9g", dt,
                     s[k].t_s, r, theory);
    }
    assert_true(s[N - 1].stress_MPa < s[0].stress_MPa && s[N - 1].stress_MPa > 0);
}

/* One Prony term (quasi-linear viscoelasticity): under a held strain the stress relaxes towards
** g_inf times the elastic one, as exp(-t / tau_1). */
static void held_strain_relaxes_by_its_prony_term(void **state)
{
    (void)state;
    cf_law law = make_law();
    double strain = -linear_strain(&law), elastic;
    cf_msm_config cfg = small_config(2);
    cf_error err = {0};
    assert_int_equal(cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, &strain, 1, &elastic, NULL,
                                     &err),
                     CF_OK);
    cf_law_free(&law);
    elastic = -elastic; /* compressive positive */
    cf_msm_effects fx = {0};
    fx.prony_count = 1;
    fx.prony_g[0] = 0.4;
    fx.prony_tau_s[0] = 3.0;
    const double t[3] = {0, 0.3, 60}, v[3] = {0, -strain, -strain};
    const cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 3, t, v};
    enum { N = 30 };
    cf_msm_sample s[N];
    const double dt = 2.0;
    run_quasi(&fx, &p, 0.3, dt, N, 0.05, s);
    const double theory = exp(-dt / fx.prony_tau_s[0]);
    for (int k = 0; k + 2 < N / 2; k++) {
        const double r = decay_ratio(s[k].stress_MPa, s[k + 1].stress_MPa, s[k + 2].stress_MPa);
        if (!(fabs(r - theory) <= 1e-6))
            fail_msg("Prony relaxation over %g s at t = %g s: %.9g, exp(-dt/tau) = %.9g", dt,
                     s[k].t_s, r, theory);
    }
    /* from nearly the instantaneous response at the end of the short ramp to g_inf of it */
    assert_true(s[0].stress_MPa > 0.9 * elastic && s[0].stress_MPa < elastic);
    assert_close(s[N - 1].stress_MPa, (1 - fx.prony_g[0]) * elastic, 1e-6 * elastic);
}

static void the_stability_limit_separates_stable_from_unstable_states(void **state)
{
    (void)state;
    cf_law law = make_law();
    cf_msm_config cfg = small_config(2);
    cf_error err = {0};
    double limit = 1;
    assert_int_equal(cf_msm_stability_limit(&law, CF_LAW_CLOSED, &cfg, -1, &limit, &err), CF_OK);
    assert_true(limit < 0 && -limit < law.travel_mm / law.p.H_mm);
    /* static runs to just below and just above: stable, then a negative pivot */
    const double t[2] = {0, 1}, v[2] = {0, -limit * 1.02};
    const double ts[3] = {0.5, 0.98 / 1.02, 1.0};
    const cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    cf_msm_sample s[3];
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    cf_status st = cf_msm_run(&lat, NULL, &cfg, &p, ts, 3, s, NULL, NULL, &err);
    cf_lattice_free(&lat);
    assert_int_equal(st, CF_OK);
    assert_int_equal(s[0].neg_pivots, 0);
    assert_int_equal(s[1].neg_pivots, 0);
    assert_true(s[2].neg_pivots > 0);
    cf_law_free(&law);
}

/* The explicit run reports the stable step of its rest lattice; dashpots shorten it. */
static void explicit_runs_report_the_stable_step(void **state)
{
    (void)state;
    cf_law law;
    cf_msm_config cfg;
    cf_lattice lat;
    cf_error err = {0};
    open_lattice(1, &law, &cfg, &lat);
    cf_msm_effects fx = {0};
    fx.inertia = 1;
    const double dt0 = cf_msm_stable_step(&lat, &fx);
    fx.eta_MPa_s = 1e-3;
    const double dt_damped = cf_msm_stable_step(&lat, &fx);
    assert_true(dt_damped < dt0 && dt_damped > 0);
    fx.eta_MPa_s = 0;
    const double t[2] = {0, 1}, v[2] = {0, 0.01};
    const double ts[2] = {0.5, 1.0};
    const cf_msm_path p = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    cf_msm_sample s[2];
    cf_msm_stats st;
    cf_lattice_reset(&lat);
    assert_int_equal(cf_msm_run(&lat, &fx, &cfg, &p, ts, 2, s, NULL, &st, &err), CF_OK);
    assert_close(st.dt_stable_s, dt0, 1e-12 * dt0);
    assert_true(st.dt_used_min_s > 0 && st.dt_used_min_s <= st.dt_stable_s);
    assert_true(st.steps >= (size_t)(1.0 / st.dt_stable_s));
    cf_lattice_free(&lat);
    cf_law_free(&law);
}

/* Relative 2-norm distance |a - b| / |b| over n entries. */
static double rel_dist(const double *a, const double *b, size_t n)
{
    double d = 0, r = 0;
    for (size_t e = 0; e < n; e++) {
        d += (a[e] - b[e]) * (a[e] - b[e]);
        r += b[e] * b[e];
    }
    return sqrt(d / r);
}

/* Equilibrium at compressive strain e (Newton with a fresh tangent every iteration). */
static void solve_at(solver *s, double e)
{
    cf_error err = {0};
    if (cf_msm_static_to(s, e, &err) != CF_OK)
        fail_msg("static solve at %g: %s", e, err.msg);
}

/* A Krylov step preconditioned by the factors of an earlier tangent solves the current one: the
** direction a fresh factorisation gives, across the loss of stability between the two, where a
** chord step on the same factors does not. */
static void krylov_step_solves_the_current_tangent(void **state)
{
    (void)state;
    cf_law law;
    cf_msm_config cfg;
    cf_lattice lat;
    open_lattice(4, &law, &cfg, &lat);
    cf_error err = {0};
    solver s;
    assert_int_equal(cf_msm_solver_init(&s, &lat, NULL, &cfg, CF_DRIVE_DISPLACEMENT, NULL, &err),
                     CF_OK);
    /* factors of the tangent at an equilibrium short of the stability limit */
    solve_at(&s, 0.30);
    double rn, fs;
    cf_msm_residual(&s, &rn, &fs);
    assert_int_equal(cf_msm_direction(&s, &err), CF_OK);
    assert_true(cf_linsolve_factored(s.mech.ls));
    assert_int_equal(s.neg_pivots, 0); /* still stable */
    /* a state further on, its residual solved three ways */
    s.load = 0.33;
    cf_msm_place_top(&lat, s.load);
    for (size_t p = 0; p < lat.nn; p++)
        if (s.eq[3 * p + 2] >= 0)
            lat.z[p] -= 0.03 * lat.Z[p];
    cf_msm_residual(&s, &rn, &fs);
    assert_true(rn > 1e-6 * fs);
    const size_t n = s.ndof;
    double *kry = malloc(n * sizeof *kry), *chord = malloc(n * sizeof *chord);
    assert_non_null(kry);
    assert_non_null(chord);
    int fatal = 0;
    assert_int_equal(cf_linsolve_krylov(s.mech.ls, s.R, s.dx, 1e-9, &fatal, &err), 1);
    assert_int_equal(fatal, 0);
    memcpy(kry, s.dx, n * sizeof *kry);
    assert_int_equal(cf_linsolve_chord(s.mech.ls, s.R, s.dx, &fatal, &err), 1);
    memcpy(chord, s.dx, n * sizeof *chord);
    assert_int_equal(cf_msm_direction(&s, &err), CF_OK); /* a fresh factorisation */
    const double dk = rel_dist(kry, s.dx, n), dc = rel_dist(chord, s.dx, n);
    assert_true(s.neg_pivots > 0); /* and past the stability limit: the factors are of a
                                       positive definite tangent, the current one is not */
    assert_true(dk < 1e-7);
    assert_true(dc > 1e-3); /* the factors are stale: the chord direction is not the tangent's */
    free(kry);
    free(chord);
    cf_msm_solver_free(&s);
    cf_lattice_free(&lat);
    cf_law_free(&law);
}

/* The spring of the shipped uniaxial scene on 5^3 cells: 45 strains to 0.45 (the lattice loses stability on the
** way), through cf_msm_uniaxial (chord and Krylov steps, secant predictor) and through cf_msm_run
** (a fresh tangent at every Newton iteration, the affine predictor). */
static void uniaxial_curve_equals_fresh_newton(void **state)
{
    (void)state;
    cf_law law = make_law();
    cf_msm_config cfg = small_config(5);
    enum { N = 45 };
    double strain[N], fast[N], ts[N];
    for (int k = 0; k < N; k++) {
        strain[k] = -0.01 * (k + 1);
        ts[k] = (k + 1) / (double)N;
    }
    cf_error err = {0};
    cf_msm_stats st;
    if (cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, strain, N, fast, &st, &err) != CF_OK)
        fail_msg("uniaxial: %s", err.msg);
    cf_lattice lat;
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg.lattice, &err), CF_OK);
    const double t[2] = {0, 1}, v[2] = {0, 0.45};
    const cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 2, t, v};
    cf_msm_sample out[N];
    cf_msm_stats full;
    if (cf_msm_run(&lat, NULL, &cfg, &path, ts, N, out, NULL, &full, &err) != CF_OK)
        fail_msg("static run: %s", err.msg);
    cf_lattice_free(&lat);
    for (int k = 0; k < N; k++) {
        assert_close(out[k].strain, -strain[k], 1e-14);
        assert_close(fast[k], -out[k].stress_MPa, 1e-9 * fabs(out[k].stress_MPa));
    }
    assert_true(out[N - 1].neg_pivots > 0); /* the curve went past the stability limit */
    /* factors were reused: far fewer factorisations than Newton iterations */
    assert_int_equal(full.chord_iters, 0);
    assert_true(st.chord_iters > 0);
    assert_true(4 * st.linear_iters < st.newton_iters);
    assert_true(st.linear_iters < full.linear_iters / 10);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(path_value_is_linear_between_points_and_held_outside),
        cmocka_unit_test(prony_terms_are_checked_naming_the_term),
        cmocka_unit_test(bad_runs_are_refused_with_their_reason),
        cmocka_unit_test(displacement_and_force_drives_meet_at_the_same_equilibria),
        cmocka_unit_test(creep_under_dashpots_decays_at_the_kelvin_voigt_rate),
        cmocka_unit_test(held_strain_relaxes_at_the_maxwell_time),
        cmocka_unit_test(held_strain_relaxes_by_its_prony_term),
        cmocka_unit_test(the_stability_limit_separates_stable_from_unstable_states),
        cmocka_unit_test(explicit_runs_report_the_stable_step),
        cmocka_unit_test(krylov_step_solves_the_current_tangent),
        cmocka_unit_test(uniaxial_curve_equals_fresh_newton),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
