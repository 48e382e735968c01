/*
** The fit of the time-dependent model (viscofit.h): recovery of known terms without and with
** noise, refusal of series that cannot be fitted, held elastic quantities, the shipped synthetic
** series, undetermined extra terms and the coverage of the standard errors.
*/
#include "testutil.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include <jansson.h>

#include "model/cell.h"
#include "io/measure.h"
#include "model/msm.h"
#include "fit/viscofit.h"
#include "model/viscomodel.h"
#include "viscoutil.h"

/* The ramp and hold of the model p evaluated as setup s says: times t, strains x, stresses y
** (MPa, table sign), NS points each. */
static void synth_series(const cf_visco_params *p, const cf_visco_setup *s, double *t, double *x,
                         double *y)
{
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(p, s, &ser, y, NULL, &err), CF_OK);
}

/* The series of p (synth_series) with Gaussian noise of 0.5 % of the largest stress on every
** point after the first (seed). */
static void noisy_series(const cf_visco_params *p, const cf_visco_fit_options *o, double *t,
                         double *x, double *y, unsigned long seed)
{
    synth_series(p, &o->setup, t, x, y);
    double ymax = 0;
    for (int k = 0; k < NS; k++)
        ymax = fmax(ymax, fabs(y[k]));
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, seed);
    for (int k = 1; k < NS; k++)
        y[k] += gsl_ran_gaussian(r, 0.005 * ymax);
    gsl_rng_free(r);
}

static void assert_recovered(const cf_visco_fit *f, const cf_visco_params *p, double tol)
{
    assert_close(f->p.ident.rho, p->ident.rho, tol * p->ident.rho);
    assert_close(f->p.ident.solid, p->ident.solid, tol * p->ident.solid);
    assert_close(f->p.ident.scale, p->ident.scale, tol * p->ident.scale);
    assert_int_equal(f->p.nbranch, p->nbranch);
    /* the fit may list the terms in another order: match by time constant */
    for (int i = 0; i < p->nbranch; i++) {
        int j = 0;
        for (int k = 1; k < f->p.nbranch; k++)
            if (fabs(log(f->p.tau_s[k] / p->tau_s[i])) < fabs(log(f->p.tau_s[j] / p->tau_s[i])))
                j = k;
        assert_close(f->p.g[j], p->g[i], tol * p->g[i]);
        assert_close(f->p.tau_s[j], p->tau_s[i], tol * p->tau_s[i]);
    }
}

/* Every fitted quantity within twice its reported standard error of the truth: for one noisy
** series a single standard error holds each quantity only 68 % of the time (all seven at once
** about 7 %); that the errors are calibrated is test_stderr_coverage's to show. */
static void assert_within_stderr(const cf_visco_fit *f, const cf_visco_params *p)
{
    /* an elastic quantity on a limit (rho_min, the stability bound, the design cap) has no
    ** standard error: it is set by the limit, which the fit says */
    const int on_limit[3] = {f->rho_at_limit, f->at_stability_limit, f->at_design_limit};
    const double got[3] = {f->p.ident.rho, f->p.ident.solid, f->p.ident.scale},
                 want[3] = {p->ident.rho, p->ident.solid, p->ident.scale};
    for (int i = 0; i < 3; i++) {
        assert_true(f->ident_se.v[i] > 0 || on_limit[i]);
        if (f->ident_se.v[i] > 0)
            assert_close(got[i], want[i], 2 * f->ident_se.v[i]);
    }
    for (int i = 0; i < 2; i++) {
        int j = fabs(log(f->p.tau_s[0] / p->tau_s[i])) < fabs(log(f->p.tau_s[1] / p->tau_s[i])) ? 0
                                                                                              : 1;
        assert_true(f->se_g[j] > 0 && f->se_tau_s[j] > 0);
        assert_close(f->p.g[j], p->g[i], 2 * f->se_g[j]);
        assert_close(f->p.tau_s[j], p->tau_s[i], 2 * f->se_tau_s[j]);
    }
}

/* A series made by the model from known terms is fitted back to 1e-6. */
/* The noiseless series of the known terms fitted with two terms and options o. */
static void fit_known_noiseless(const cf_visco_fit_options *o, cf_visco_fit *f)
{
    cf_visco_params p = known();
    double t[NS], x[NS], y[NS];
    synth_series(&p, &o->setup, t, x, y);
    cf_error err = {0};
    cf_visco_fit_options o2 = *o;
    o2.nbranch = 2;
    cf_visco_data d = {NS, t, x, y, NULL};
    if (cf_visco_fit_run(&d, &o2, f, &err) != CF_OK)
        fail_msg("the fit of the known terms failed: %s", err.msg);
}

static void test_recover_noiseless(void **state)
{
    (void)state;
    cf_visco_params p = known();
    cf_visco_fit_options o = cf_visco_fit_default_options();
    cf_visco_fit f;
    fit_known_noiseless(&o, &f);
    assert_recovered(&f, &p, 1e-6);
    assert_true(f.rmse < 1e-9 * p.ident.scale);
    assert_int_equal(f.n_ramp, 16);
    assert_int_equal(f.n_hold, NS - 16);
    cf_visco_fit_free(&f);
}

/* A bound on the model runs stops the fit after its first start with the best model so far and
** says so; without the bound the same fit runs every start and does not. */
static void test_evaluation_bound(void **state)
{
    (void)state;
    cf_visco_params p = known();
    cf_visco_fit_options o = cf_visco_fit_default_options();
    cf_visco_fit all, bounded;
    fit_known_noiseless(&o, &all);
    assert_int_equal(all.evaluation_bound_reached, 0);
    o.max_evaluations = 50; /* fewer than the stand-in's grid: one start is fitted */
    fit_known_noiseless(&o, &bounded);
    assert_int_equal(bounded.evaluation_bound_reached, 1);
    assert_true(bounded.evaluations < all.evaluations);
    assert_int_equal(bounded.p.nbranch, 2);
    assert_true(isfinite(bounded.rmse) && bounded.rmse < 1e-3 * p.ident.scale);
    cf_visco_fit_free(&all);
    cf_visco_fit_free(&bounded);
}

/* Two fits of one series by two paths agree: the same number of terms, every quantity within a
** tenth of its standard error, the RMSE to 1e-6. */
static void assert_same_fit(const cf_visco_fit *fast, const cf_visco_fit *full)
{
    assert_int_equal(fast->p.nbranch, full->p.nbranch);
    for (int i = 0; i < 3; i++)
        if (full->ident_se.v[i] > 0)
            assert_close(fast->p.ident.v[i], full->p.ident.v[i], 0.1 * full->ident_se.v[i]);
    for (int i = 0; i < full->p.nbranch; i++) {
        assert_true(full->se_g[i] > 0 && full->se_tau_s[i] > 0);
        assert_close(fast->p.g[i], full->p.g[i], 0.1 * full->se_g[i]);
        assert_close(fast->p.tau_s[i], full->p.tau_s[i], 0.1 * full->se_tau_s[i]);
    }
    assert_close(fast->rmse, full->rmse, 1e-6 * full->rmse);
}

/* The Jacobian carried by Broyden's update between differences (the default) and the one by
** differences at every step reach the same fit of a noisy series: every quantity within a
** tenth of its standard error, for fewer model runs. */
static void test_updated_jacobian_matches_full(void **state)
{
    (void)state;
    cf_visco_params p = known();
    cf_visco_fit_options o = cf_visco_fit_default_options();
    double t[NS], x[NS], y[NS];
    noisy_series(&p, &o, t, x, y, 3);
    o.nbranch = 2;
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit fast, full;
    cf_error err = {0};
    assert_int_equal(cf_visco_fit_run(&d, &o, &fast, &err), CF_OK);
    o.full_jacobian = 1;
    assert_int_equal(cf_visco_fit_run(&d, &o, &full, &err), CF_OK);
    assert_true(fast.evaluations < full.evaluations);
    assert_same_fit(&fast, &full);
    cf_visco_fit_free(&fast);
    cf_visco_fit_free(&full);
}

/* The stand-in solved in the space of each grid point's base (the default) and on every point of
** the series reach the same fit of a noisy series, quasi-linear and with relaxation depending on
** strain (whose stand-in is non-negative least squares): every quantity within a tenth of its
** standard error. */
static void test_reduced_standin_matches_full(void **state)
{
    (void)state;
    for (int strain = 0; strain < 2; strain++) {
        cf_visco_params p = known();
        p.k[0] = strain ? -0.8 : 0.0;
        cf_visco_fit_options o = cf_visco_fit_default_options();
        double t[NS], x[NS], y[NS];
        noisy_series(&p, &o, t, x, y, 5);
        o.nbranch = 2;
        o.relaxation = strain ? CF_RELAX_STRAIN : CF_RELAX_QLV;
        cf_visco_data d = {NS, t, x, y, NULL};
        cf_visco_fit fast, full;
        cf_error err = {0};
        assert_int_equal(cf_visco_fit_run(&d, &o, &fast, &err), CF_OK);
        o.full_standin = 1;
        assert_int_equal(cf_visco_fit_run(&d, &o, &full, &err), CF_OK);
        assert_same_fit(&fast, &full);
        cf_visco_fit_free(&fast);
        cf_visco_fit_free(&full);
    }
}

/* With 0.5 % noise the terms are found within twice their reported standard errors. */
static void test_recover_with_noise(void **state)
{
    (void)state;
    cf_visco_params p = known();
    cf_visco_fit_options o = cf_visco_fit_default_options();
    double t[NS], x[NS], y[NS];
    cf_error err = {0};
    noisy_series(&p, &o, t, x, y, 1);
    o.nbranch = 2;
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_within_stderr(&f, &p);
    cf_visco_fit_free(&f);
}

/* A series made from known strain-dependent terms is fitted back to 1e-6 (--relaxation strain);
** the quasi-linear fit of it is worse. */
static void test_strain_relaxation_recovered(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.k[0] = -0.8;
    p.k[1] = 0.5;
    cf_visco_fit_options o = cf_visco_fit_default_options();
    double t[NS], x[NS], y[NS];
    synth_series(&p, &o.setup, t, x, y);
    cf_error err = {0};
    o.nbranch = 2;
    o.relaxation = CF_RELAX_STRAIN;
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_recovered(&f, &p, 1e-6);
    assert_true(f.strain_relaxation);
    for (int i = 0; i < 2; i++) {
        int j = fabs(log(f.p.tau_s[0] / p.tau_s[i])) < fabs(log(f.p.tau_s[1] / p.tau_s[i])) ? 0 : 1;
        assert_close(f.p.k[j], p.k[i], 1e-6 * fabs(p.k[i]));
    }
    assert_true(f.rmse < 1e-9 * p.ident.scale);
    const double rmse_strain = f.rmse;
    cf_visco_fit_free(&f);
    o.relaxation = CF_RELAX_QLV;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_false(f.strain_relaxation);
    assert_true(f.rmse > 1e3 * rmse_strain);
    cf_visco_fit_free(&f);
}

static void test_series_refused(void **state)
{
    (void)state;
    double t[NS], x[NS], y[NS];
    ramp_hold(t, x);
    for (int k = 0; k < NS; k++)
        y[k] = x[k];
    unsigned char hold[NS];
    cf_error err = {0};
    cf_visco_data d = {NS, t, x, y, NULL};
    assert_int_equal(cf_visco_data_check(&d, hold, &err), CF_OK);
    assert_int_equal(hold[15], 0);
    assert_int_equal(hold[16], 1);
    /* a single ramp: no hold, no reversal */
    double xr[NS];
    for (int k = 0; k < NS; k++)
        xr[k] = -0.001 * k;
    cf_visco_data dr = {NS, t, xr, y, NULL};
    assert_int_equal(cf_visco_data_check(&dr, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "hold"));
    /* no change of strain */
    double x0[NS] = {0};
    cf_visco_data d0 = {NS, t, x0, y, NULL};
    assert_int_equal(cf_visco_data_check(&d0, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "never changes"));
    /* time going backwards */
    double tb[NS];
    memcpy(tb, t, sizeof tb);
    tb[20] = tb[19];
    cf_visco_data db = {NS, tb, x, y, NULL};
    assert_int_equal(cf_visco_data_check(&db, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "point 21"));
    /* a held elastic fit whose solid strain is below the series' strain */
    cf_visco_fit_options o = cf_visco_fit_default_options();
    o.hold_elastic = 1;
    o.elastic.rho = 0.3;
    o.elastic.solid = 0.2;
    o.elastic.scale = 0.01;
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_E_DATA);
    assert_null(f.model_MPa);
}

/* The ramp-and-hold series of the one-branch model p into t, x, y, and options that hold p's
** elastic part and fit one branch. */
static void held_series(const cf_visco_params *p, cf_visco_fit_options *o, double *t, double *x,
                        double *y)
{
    *o = cf_visco_fit_default_options();
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(p, &o->setup, &ser, y, NULL, &err), CF_OK);
    o->nbranch = 1;
    o->hold_elastic = 1;
    o->elastic = p->ident;
}

/* Holding the elastic part recovers the Prony terms alone. */
static void test_held_elastic(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.nbranch = 1;
    cf_visco_fit_options o;
    double t[NS], x[NS], y[NS];
    cf_error err = {0};
    held_series(&p, &o, t, x, y);
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_int_equal(f.held_elastic, 1);
    assert_int_equal(f.k, 2);
    assert_true(f.p.ident.rho == p.ident.rho && f.p.ident.scale == p.ident.scale);
    assert_close(f.p.g[0], p.g[0], 1e-6 * p.g[0]);
    assert_close(f.p.tau_s[0], p.tau_s[0], 1e-6 * p.tau_s[0]);
    assert_close(f.ident_se.rho, -1, 0);
    /* the held spring's lattice is checked as a fitted one: stable beyond the series */
    assert_true(f.stable_to_strain == 0 || f.stable_to_strain < -0.3);
    cf_visco_fit_free(&f);
}

/* A held spring with a cylindrical tail: the series of a known tailed spring (its cone closing at
** strain 0.25, within the series' 0.3, so the tail's linear region is run) and two Prony terms,
** fitted with that spring held, recovers the terms to 1e-6 and keeps the tail in the model; the
** same three quantities without the tail cannot even run the series (the cone passes solid at
** 0.15), so a dropped tail could not fit. A tail without a held elastic part, or one that leaves
** the cone no room, is refused. */
static void test_held_tailed_elastic(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.ident.rho = 0.8; /* its one-cell lattice stable to 0.3 (at rho 0.3 it buckles at 0.19) */
    p.ident.solid = 0.15;
    p.e_tail = 0.1;
    cf_visco_fit_options o;
    double t[NS], x[NS], y[NS], yc[NS];
    cf_error err = {0};
    held_series(&p, &o, t, x, y);
    o.nbranch = 2;
    o.elastic_e_tail = p.e_tail;
    cf_visco_params cone = p;
    cone.e_tail = 0;
    cf_visco_series ser = {NS, t, x};
    assert_true(cf_visco_curve(&cone, &o.setup, &ser, yc, NULL, &err) != CF_OK);
    double ymax = 0;
    for (int k = 0; k < NS; k++)
        ymax = fmax(ymax, fabs(y[k]));
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_int_equal(f.held_elastic, 1);
    assert_int_equal(f.k, 4);
    assert_true(f.p.e_tail == p.e_tail && f.p.ident.solid == p.ident.solid);
    int a = f.p.tau_s[0] < f.p.tau_s[1] ? 0 : 1;
    for (int i = 0; i < 2; i++) {
        assert_close(f.p.g[(a + i) % 2], p.g[i], 1e-6 * p.g[i]);
        assert_close(f.p.tau_s[(a + i) % 2], p.tau_s[i], 1e-6 * p.tau_s[i]);
    }
    assert_true(f.rmse < 1e-8 * ymax);
    cf_visco_fit_free(&f);
    /* a tail with the elastic part fitted; a tail past the free length */
    o.hold_elastic = 0;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "tail"));
    o.hold_elastic = 1;
    o.elastic_e_tail = 0.85;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "tail compliance"));
    cone.e_tail = 0.85;
    assert_int_equal(cf_visco_curve(&cone, &o.setup, &ser, yc, NULL, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "tail compliance"));
}

/* A held elastic fit whose lattice buckles within the series is refused, naming the strain where
** it loses stability (from the library and from the command line, nothing written); the same
** spring with the check switched off is fitted. */
static void test_held_elastic_unstable(void **state)
{
    (void)state;
    cf_visco_params p = known();
    p.ident.rho = 0.1;
    p.ident.solid = 0.35; /* the one-cell lattice needs s/H >= 0.49 at rho 0.1 to reach 0.30 */
    p.nbranch = 1;
    cf_visco_fit_options o;
    double t[NS], x[NS], y[NS];
    cf_error err = {0};
    held_series(&p, &o, t, x, y);
    cf_visco_data d = {NS, t, x, y, NULL};
    cf_visco_fit f;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_E_DATA);
    assert_null(f.model_MPa);
    const char *at = strstr(err.msg, "loses stability at strain ");
    assert_non_null(at);
    double lim = atof(at + strlen("loses stability at strain "));
    assert_true(lim < 0 && lim > -0.3);
    /* the scan agrees with the one-factorisation check on both sides of that strain */
    const cf_ident unit = {.rho = p.ident.rho, .solid = p.ident.solid, .scale = 1.0};
    cf_spring sp = cf_ident_member(&unit);
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    cf_msm_config cfg = o.setup.cfg;
    cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = 1;
    cf_cell cell;
    assert_int_equal(cf_cell_init(&cell, &law, o.setup.method, cfg.lattice.weight, &err), CF_OK);
    for (int side = 0; side < 2; side++) {
        cf_cell_state cs;
        long neg = -1;
        double e = lim * (side ? 1.01 : 0.99);
        assert_int_equal(cf_cell_mode(&cell, CF_MODE_UNIAXIAL, e, NULL, &cs, &err), CF_OK);
        cf_status st = cf_msm_homogeneous_inertia(&law, o.setup.method, &cfg, e, cs.free_stretch,
                                                  &neg, &err);
        assert_true(side ? st != CF_OK || neg > 0 : st == CF_OK && neg == 0);
    }
    cf_law_free(&law);
    o.stable_cells = 0;
    assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
    assert_close(f.p.g[0], p.g[0], 1e-6 * p.g[0]);
    assert_close(f.stable_to_strain, 0, 0); /* not checked */
    cf_visco_fit_free(&f);
    /* the same history in tension: the lattice is checked where the series goes, and a stretched
    ** lattice of this spring stays stable */
    double xt[NS], yt[NS];
    for (int k = 0; k < NS; k++)
        xt[k] = -x[k];
    cf_visco_series sert = {NS, t, xt};
    assert_int_equal(cf_visco_curve(&p, &o.setup, &sert, yt, NULL, &err), CF_OK);
    cf_visco_data dt = {NS, t, xt, yt, NULL};
    o.stable_cells = 1;
    assert_int_equal(cf_visco_fit_run(&dt, &o, &f, &err), CF_OK);
    assert_close(f.p.g[0], p.g[0], 1e-6 * p.g[0]);
    assert_true(f.stable_to_strain == 0 || f.stable_to_strain > 0.3);
    cf_visco_fit_free(&f);

    /* the command line: --elastic with a fit file of that spring */
    char dir[] = "/tmp/conifit-visco-XXXXXX", series[256], spring[256], out[256];
    assert_non_null(mkdtemp(dir));
    snprintf(series, sizeof series, "%s/series.csv", dir);
    snprintf(spring, sizeof spring, "%s/spring.json", dir);
    snprintf(out, sizeof out, "%s/fit.json", dir);
    FILE *fs = fopen(series, "w");
    assert_non_null(fs);
    fprintf(fs, "time_s,strain,stress_kPa\n");
    for (int k = 0; k < NS; k++)
        fprintf(fs, "%.17g,%.17g,%.17g\n", t[k], x[k], 1e3 * y[k]);
    fclose(fs);
    sp = cf_ident_member(&p.ident);
    assert_int_equal(cf_law_init(&law, &sp, &err), CF_OK);
    json_t *params = json_object(), *item = json_object(), *root = json_object();
    for (int k = 0; k < CF_P_COUNT; k++)
        json_object_set_new(params, cf_spring_param_info(k)->key,
                            json_real(cf_spring_get(&sp, k)));
    json_object_set_new(item, "type", json_string(cf_spring_type_name(law.type)));
    json_object_set_new(item, "params", params);
    json_object_set_new(root, "fits", json_pack("[o]", item));
    assert_int_equal(json_dump_file(root, spring, 0), 0);
    json_decref(root);
    cf_law_free(&law);
    char so[4096], se[4096];
    assert_int_equal(tu_run(so, sizeof so, se, sizeof se, "fit %s --elastic %s --branches 1 -o %s",
                            series, spring, out),
                     65);
    assert_non_null(strstr(se, "loses stability at strain"));
    assert_non_null(strstr(se, "--elastic"));
    assert_int_equal(access(out, F_OK), -1);
    unlink(series);
    unlink(spring);
    rmdir(dir);
}

/* The shipped synthetic series: made by the documented command, fitted back to its known terms
** (1e-6 without noise; within twice the reported standard errors with 1 % noise). */
static void fit_shipped_n(const char *path, int nbranch, cf_visco_fit *f)
{
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_OK);
    assert_non_null(t.t);
    cf_visco_fit_options o = cf_visco_fit_default_options();
    o.nbranch = nbranch;
    cf_visco_data d = {t.count, t.t, t.x, t.y, NULL};
    assert_int_equal(cf_visco_fit_run(&d, &o, f, &err), CF_OK);
    cf_table_free(&t);
}

static void fit_shipped(const char *path, cf_visco_fit *f)
{
    fit_shipped_n(path, 2, f);
}

static cf_visco_params shipped_truth(void)
{
    cf_spring sp = {7.8, 15.6, 2.5, 2.6, 60, 10};
    cf_visco_params p = known();
    p.ident = cf_ident_of(&sp, 0);
    return p;
}

static void test_shipped_synthetic_series(void **state)
{
    (void)state;
    /* The documented command writes the shipped file: the same text and noise, and the same
    ** numbers up to rounding, which depends on the processor (the vector copy in use and the C
    ** library's own per-processor math functions): an AVX2-only processor gave numbers up to
    ** 1.6e-15 relative apart. 1e-12 relative leaves room for that and is still ten billion times
    ** finer than the 1 % noise, so any change to the series fails. */
    char dir[] = "/tmp/conifit-visco-XXXXXX", out[256], so[4096], se[4096];
    assert_non_null(mkdtemp(dir));
    snprintf(out, sizeof out, "%s/s.csv", dir);
    assert_int_equal(tu_run(so, sizeof so, se, sizeof se,
                            "simulate data/scenes/synthetic_relaxation.json --table --noise 0.01 "
                            "--seed 1 -o %s",
                            out),
                     0);
    assert_text_close(out, "data/series/synthetic_relaxation_noise1pct.csv", 1e-12);
    unlink(out);
    rmdir(dir);
    cf_visco_params p = shipped_truth();
    cf_visco_fit f;
    fit_shipped("data/series/synthetic_relaxation.csv", &f);
    assert_recovered(&f, &p, 1e-6);
    cf_visco_fit_free(&f);
    fit_shipped("data/series/synthetic_relaxation_noise1pct.csv", &f);
    assert_within_stderr(&f, &p);
    cf_visco_fit_free(&f);
}

/* A term more than the series holds is not determined: the noisy shipped series (made from two
** terms) fitted with four quasi-linear terms leaves some time constant or modulus within its
** standard error, and the fit says so; with two, each is larger than its error. */
static void test_extra_terms_undetermined(void **state)
{
    (void)state;
    cf_visco_fit f;
    fit_shipped_n("data/series/synthetic_relaxation_noise1pct.csv", 4, &f);
    assert_false(f.identified);
    int within = 0;
    for (int i = 0; i < 4; i++)
        within |= !(f.se_tau_s[i] > 0 && f.se_tau_s[i] < f.p.tau_s[i]) ||
                  !(f.se_g[i] > 0 && f.se_g[i] < f.p.g[i]);
    assert_true(within);
    cf_visco_fit_free(&f);
    fit_shipped("data/series/synthetic_relaxation_noise1pct.csv", &f);
    assert_true(f.identified);
    for (int i = 0; i < 2; i++) {
        assert_true(f.se_tau_s[i] > 0 && f.se_tau_s[i] < f.p.tau_s[i]);
        assert_true(f.se_g[i] > 0 && f.se_g[i] < f.p.g[i]);
    }
    cf_visco_fit_free(&f);
}

/* The standard errors are calibrated: over 12 noisy series of the shipped synthetic tissue (0.5 %
** noise, seeds 1..12), about 68 % of the fitted quantities (rho, s/H, F_C/H^2, g_i, tau_i) lie
** within one reported standard error of the truth and the root mean square of the standardised
** errors is about 1. Bounds: 84 quantities, binomial sd 0.051 around 0.68, so [0.55, 0.81] is
** 2.5 sd; an error underestimated twofold would put the coverage near 0.38 and the rms near 2
** (measured: 0.77 and 1.00; 20 seeds at 1 % noise: 0.73, and 0.8 to 1.4 per quantity). */
static void test_stderr_coverage(void **state)
{
    (void)state;
    cf_visco_params p = shipped_truth();
    cf_visco_fit_options o = cf_visco_fit_default_options();
    o.nbranch = 2;
    double t[NS], x[NS], y0[NS], y[NS];
    ramp_hold(t, x);
    cf_visco_series ser = {NS, t, x};
    cf_error err = {0};
    assert_int_equal(cf_visco_curve(&p, &o.setup, &ser, y0, NULL, &err), CF_OK);
    double ymax = 0;
    for (int k = 0; k < NS; k++)
        ymax = fmax(ymax, fabs(y0[k]));
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    int within = 0, count = 0;
    double z2 = 0;
    for (unsigned long seed = 1; seed <= 12; seed++) {
        gsl_rng_set(r, seed);
        for (int k = 0; k < NS; k++)
            y[k] = y0[k] + (k ? gsl_ran_gaussian(r, 0.005 * ymax) : 0.0);
        cf_visco_data d = {NS, t, x, y, NULL};
        cf_visco_fit f;
        assert_int_equal(cf_visco_fit_run(&d, &o, &f, &err), CF_OK);
        const int j = f.p.tau_s[0] < f.p.tau_s[1] ? 0 : 1;
        const double est[7] = {f.p.ident.rho,    f.p.ident.solid, f.p.ident.scale, f.p.g[j],
                               f.p.tau_s[j], f.p.g[1 - j],     f.p.tau_s[1 - j]};
        const double se[7] = {f.ident_se.rho, f.ident_se.solid,  f.ident_se.scale, f.se_g[j],
                              f.se_tau_s[j], f.se_g[1 - j], f.se_tau_s[1 - j]};
        const double truth[7] = {p.ident.rho, p.ident.solid, p.ident.scale, p.g[0],
                                 p.tau_s[0], p.g[1], p.tau_s[1]};
        for (int i = 0; i < 7; i++) {
            assert_true(se[i] > 0);
            double z = (est[i] - truth[i]) / se[i];
            within += fabs(z) <= 1;
            z2 += z * z;
            count++;
        }
        cf_visco_fit_free(&f);
    }
    gsl_rng_free(r);
    const double coverage = (double)within / count, rmsz = sqrt(z2 / count);
    assert_true(coverage >= 0.55 && coverage <= 0.81);
    assert_true(rmsz >= 0.7 && rmsz <= 1.4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_recover_noiseless),
        cmocka_unit_test(test_recover_with_noise),
        cmocka_unit_test(test_evaluation_bound),
        cmocka_unit_test(test_updated_jacobian_matches_full),
        cmocka_unit_test(test_reduced_standin_matches_full),
        cmocka_unit_test(test_strain_relaxation_recovered),
        cmocka_unit_test(test_series_refused),
        cmocka_unit_test(test_held_elastic),
        cmocka_unit_test(test_held_elastic_unstable),
        cmocka_unit_test(test_held_tailed_elastic),
        cmocka_unit_test(test_shipped_synthetic_series),
        cmocka_unit_test(test_stderr_coverage),
        cmocka_unit_test(test_extra_terms_undetermined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
