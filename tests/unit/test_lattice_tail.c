/*
** The conical-tail law through the lattice (lattice_fit.h, cf_lattice_fit_tail): a known tailed
** spring recovered from its own homogenised cell's equibiaxial curve; --law auto on published
** tables in their own modes: both laws reported, the tail kept only with an AIC gain and a feasible
** spring, kept on the aortic valve leaflet (equibiaxial, non-telescoping) and not on a softening
** shear table (chicken breast). In a joint fit (joint.h, cf_joint_fit_tail): the known spring
** recovered from a uniaxial and a shear curve together, and the three brain cortex tables with
** --law auto, the tail kept only with a lower joint AIC, its fit file loading back with the tail.
*/
#include "jointutil.h"
#include "testutil.h"

#include "model/calibration.h"
#include "model/cell.h"
#include "io/fitfile.h"
#include "fit/joint.h"
#include "report/jointreport.h"
#include "fit/lattice_fit.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "pipeline/pipeline_joint.h"
#include "report/report.h"
#include "check/validate.h"

/* A non-telescoping tailed spring: D1 = 3, D2 = 10, n = 4, d = 1 (solid length 4), cone travel
** 3 mm, a tail of 2 coils whose gap per coil is 1.5 times the cone's. s/H = 0.267, the cone
** closes at strain 0.4 and the whole spring at 0.467. */
static cf_spring known_spring(void)
{
    cf_spring p = {3, 10, 4, 1, 8e4, 0};
    p.n_tail = 2;
    p.H_tail_mm = 2 + 1.5 * 0.5 * 3;
    p.H_mm = 3 + 4 + p.H_tail_mm;
    return p;
}

/* The stress-strain table of mode m: the cell's curve of spring p (isotropic lattice, exact law)
** at n strains up to e_end. */
static void cell_table(const cf_spring *p, cf_mode m, double e_end, size_t n, cf_table *t)
{
    cf_law law;
    assert_int_equal(cf_law_init(&law, p, NULL), CF_OK);
    double w[CF_FAMILY_COUNT];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, w, NULL), CF_OK);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    assert_non_null(x);
    assert_non_null(y);
    for (size_t i = 0; i < n; i++) {
        cf_cell_state s;
        x[i] = e_end * (double)(i + 1) / (double)n;
        assert_int_equal(cf_cell_mode(&c, m, x[i], NULL, &s, NULL), CF_OK);
        y[i] = s.stress_MPa;
    }
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, n, x, y, NULL, t, &err), CF_OK);
    t->mode = m;
    free(x);
    free(y);
}

/* The known spring, its four quantities (rho, s/H, F_C/H^2, e_t) into q. */
static cf_spring known_quantities(double q[4])
{
    const cf_spring p = known_spring();
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    const double H = p.H_mm;
    q[0] = law.rho;
    q[1] = law.cone_travel_mm / H;
    q[2] = law.F_C_N / (H * H);
    q[3] = law.F_C_N / (law.k_tail_N_per_mm * H);
    return p;
}

static void close_rel(const char *what, double got, double want, double rel)
{
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("%s: %.12g, expected %.12g (relative %.1g)", what, got, want, rel);
}

/* The known spring's equibiaxial cell curve past the cone's closing: the conical law's fit through
** the lattice, then the tailed law's, recovers the four quantities. */
static void known_tailed_spring_is_recovered_through_the_lattice(void **state)
{
    (void)state;
    double q[4];
    const cf_spring p = known_quantities(q);
    cf_table t;
    cell_table(&p, CF_MODE_EQUIBIAXIAL, 0.44, 40, &t);
    cf_fit_options o = cf_fit_default_options();
    cf_validate_setup s = cf_validate_default();
    cf_fit_result plain, tail;
    cf_through_msm thr, thr_tail;
    cf_error err = {0};
    assert_int_equal(cf_fit_run(&t, &o, CF_NON_TELESCOPING, &plain, &err), CF_OK);
    cf_lattice_fit(&t, &o, &s, &plain, &thr, &err);
    if (cf_lattice_fit_tail(&t, &o, &s, &plain, &tail, &thr_tail, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(thr_tail.done);
    assert_true(tail.tail);
    assert_true(cf_spring_has_tail(&tail.params));
    close_rel("rho", tail.ident.rho, q[0], 1e-6);
    close_rel("s/H", tail.ident.solid, q[1], 1e-6);
    close_rel("F_C/H^2", tail.ident.scale, q[2], 1e-6);
    close_rel("e_t", tail.q[CF_Q_TAIL], q[3], 1e-6);
    /* the placed spring's cell reproduces the table; the conical law's cannot */
    double ymax = 0;
    for (size_t i = 0; i < t.count; i++)
        ymax = fmax(ymax, fabs(t.y[i]));
    assert_true(tail.rmse <= 1e-5 * ymax);
    assert_true(thr.cell_rmse > 100 * tail.rmse);
    cf_table_free(&t);
}

/* --law auto through the pipeline on a published table read in its own mode (the fit goes through
** the lattice): both laws fitted for each type, the AIC the rule; 0 when the tables are absent. */
static int auto_in_lattice(const char *name, cf_mode mode, cf_table *t, cf_fit_report *r)
{
    const char *dir = tu_datasets();
    if (!dir)
        return 0;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    cf_measure_options mo = cf_measure_default_options();
    cf_error err = {0};
    if (cf_measure_load(path, &mo, t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(t->mode, mode);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    if (cf_pipeline_fit(t, &po, r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(r->through_msm);
    for (int i = 0; i < r->nfits; i++) {
        const cf_law_choice *lc = &r->law_choice[i];
        assert_true(lc->ran);
        assert_true(r->thr[i].done);
        /* never the tail without an AIC gain and a feasible spring */
        if (lc->chosen)
            assert_true(lc->aic[1] < lc->aic[0] && r->fits[i].feasible);
        assert_int_equal(r->fits[i].tail, lc->chosen);
        assert_true(isfinite(lc->aic[1]) && isfinite(lc->aic[0]));
    }
    return 1;
}

/* The aortic valve leaflet in its own mode (equibiaxial): through the lattice the conical law
** reaches 346.9 Pa (telescoping) and 264.4 Pa (non-telescoping), AIC 181.5 and 173.3; the tailed
** law 97.53 Pa for both, AIC 145.4, its cone closing inside the table (s/H 0.194, the table's
** largest strain 0.224) so that the tail's compliance is determined (e_t 0.0104 +- 0.0044), its
** profile interval [0.0051, 0.0217] about as wide. The
** non-telescoping tailed spring is feasible and kept; the telescoping one is not (a tail of one
** coil at tau = n_tail/n = 0.053 asks for 19 cone coils, and D2 then exceeds 10 H), so that type's
** tailed fit is the conical optimum it contains, with no tail, and auto keeps the conical law. */
static void valve_in_equibiaxial_keeps_the_tail(void **state)
{
    (void)state;
    cf_fit_report r;
    cf_table t; /* the report points at it */
    if (!auto_in_lattice("aortic_valve_circumferential.csv", CF_MODE_EQUIBIAXIAL, &t, &r))
        skip();
    assert_int_equal(r.nfits, 2);
    for (int i = 0; i < r.nfits; i++) {
        const cf_law_choice *lc = &r.law_choice[i];
        const cf_fit_result *tail = lc->chosen ? &r.fits[i] : &lc->cand[1 - lc->chosen];
        const cf_fit_result *cone = lc->chosen ? &lc->cand[1 - lc->chosen] : &r.fits[i];
        if (tail->params.n_tail == 0) {
            /* telescoping: the tailed spring its search ends on (97.5 Pa) breaks D2_max_H, so
            ** the tailed law's fit is the conical optimum it contains, with no tail (issue 37) */
            assert_int_equal(i, 0);
            assert_true(tail->feasible && tail->rmse == cone->rmse);
            assert_true(tail->nested_violated & CF_C_D2_H);
            const double lost = tail->nested_rmse * 1e6;
            if (!(lost > 95 && lost < 100))
                fail_msg("the telescoping tailed spring lost: RMSE %.4g Pa, expected 97.5", lost);
            assert_false(lc->chosen);
            continue;
        }
        const double pa = tail->rmse * 1e6;
        if (!(pa > 95 && pa < 100))
            fail_msg("tailed law through the lattice: RMSE %.4g Pa, expected 97.5", pa);
        assert_true(cone->rmse * 1e6 > 250);
        assert_true(lc->aic[0] - lc->aic[1] > 20);
        assert_true(tail->q_se[CF_Q_TAIL] > 0 && tail->q_se[CF_Q_TAIL] < tail->q[CF_Q_TAIL]);
        assert_true(tail->ident.solid < 0.224);
        /* the other quantities trade off, so all four have profile intervals (the plain law's
        ** rule) that hold their values; e_t's, which its error determines, is about as wide as
        ** +-1.96 of it (0.0051 to 0.0217 against 0.0018 to 0.019: the profile is skewed) */
        assert_true(tail->interval_ok[CF_Q_TAIL]);
        for (int k = 0; k < 3; k++) {
            assert_true(tail->interval_ok[k]);
            assert_true(tail->interval[k][0] <= tail->ident.v[k] &&
                        tail->ident.v[k] <= tail->interval[k][1]);
        }
        const double *ie = tail->interval[CF_Q_TAIL];
        assert_true(ie[0] <= tail->q[CF_Q_TAIL] && tail->q[CF_Q_TAIL] <= ie[1]);
        const double ratio = (ie[1] - ie[0]) / (2 * 1.96 * tail->q_se[CF_Q_TAIL]);
        if (!(ratio > 0.5 && ratio < 2))
            fail_msg("e_t %.4g: interval [%.4g, %.4g] against ± 1.96 × %.3g", tail->q[CF_Q_TAIL],
                     ie[0], ie[1], tail->q_se[CF_Q_TAIL]);
        assert_int_equal(lc->chosen, tail->feasible);
        assert_true(r.thr[i].cell_rmse == r.fits[i].rmse);
    }
    assert_false(r.law_choice[0].chosen); /* telescoping: the tailed spring is infeasible */
    assert_true(r.law_choice[0].cand[1 - r.law_choice[0].chosen].nested_violated & CF_C_D2_H);
    assert_true(r.law_choice[1].chosen);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* The chicken breast in simple shear softens: both laws settle on the same compromise through the
** lattice (0.1003 kPa), so the tail's extra quantity costs 2 in the AIC (-83.97 against -85.97)
** and the conical law is kept. */
static void softening_shear_keeps_the_conical_law(void **state)
{
    (void)state;
    cf_fit_report r;
    cf_table t; /* the report points at it */
    if (!auto_in_lattice("chicken_breast_shear.csv", CF_MODE_SHEAR, &t, &r))
        skip();
    for (int i = 0; i < r.nfits; i++) {
        const cf_law_choice *lc = &r.law_choice[i];
        assert_false(lc->chosen);
        assert_false(r.fits[i].tail);
        assert_true(lc->cand[1 - lc->chosen].tail);
        assert_true(lc->aic[1] > lc->aic[0]);
        assert_true(lc->cand[1 - lc->chosen].rmse > 0.99 * r.fits[i].rmse);
    }
    cf_report_free(&r);
    cf_table_free(&t);
}

/* Issue 37, item 13: the brain cortex in tension, fitted through the lattice (--validate) with
** --law auto: the telescoping tailed search ended on an infeasible spring 5e-4 worse than the
** conical fit (RMSE 5.961 against 5.958 Pa); the tailed law contains the conical one, so its fit
** is that conical optimum with no tail, never worse. */
static void tail_through_the_lattice_never_loses_to_the_conical_law(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    char path[1024];
    snprintf(path, sizeof path, "%s/brain_cortex_tension.csv", dir);
    cf_measure_options mo = cf_measure_default_options();
    cf_table t;
    cf_fit_report r;
    cf_error err = {0};
    if (cf_measure_load(path, &mo, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    po.validate = 1;
    if (cf_pipeline_fit(&t, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(r.through_msm);
    for (int i = 0; i < r.nfits; i++) {
        const cf_law_choice *lc = &r.law_choice[i];
        assert_true(lc->ran && r.thr[i].done);
        const cf_fit_result *tail = lc->chosen ? &r.fits[i] : &lc->cand[1 - lc->chosen];
        const cf_fit_result *cone = lc->chosen ? &lc->cand[1 - lc->chosen] : &r.fits[i];
        if (cone->feasible && !tail->feasible)
            fail_msg("%s: the tailed fit is infeasible (RMSE %.6g) beside a feasible conical one",
                     cf_spring_type_name(cone->type), tail->rmse);
        if (cone->feasible == tail->feasible && !(tail->objective <= cone->objective * (1 + 1e-9)))
            fail_msg("%s: the tailed fit's RMSE %.8g above the conical fit's %.8g",
                     cf_spring_type_name(cone->type), tail->rmse, cone->rmse);
        assert_false(lc->chosen);
    }
    cf_report_free(&r);
    cf_table_free(&t);
}

/* A uniaxial and a shear table of the known spring's cell, both past the cone's closing: the
** conical law's joint fit, then the tailed law's from it, recovers the four quantities. */
static void known_tailed_spring_is_recovered_jointly(void **state)
{
    (void)state;
    double q[4];
    const cf_spring p = known_quantities(q);
    cf_table t[2];
    cell_table(&p, CF_MODE_UNIAXIAL, 0.42, 30, &t[0]);
    cell_table(&p, CF_MODE_SHEAR, 0.6, 30, &t[1]);
    /* both tables past the cone's closing (spring strain 0.4), short of the whole spring's */
    for (int k = 0; k < 2; k++) {
        const double e = cf_cell_spring_strain(t[k].mode, t[k].x[t[k].count - 1]);
        assert_true(e > 0.3 && e < 0.46);
    }
    const cf_table *tabs[2] = {&t[0], &t[1]};
    cf_fit_options o = cf_fit_default_options();
    cf_validate_setup s = cf_validate_default();
    cf_joint_result plain, tail;
    cf_error err = {0};
    if (cf_joint_fit(tabs, 2, &o, &s, CF_NON_TELESCOPING, &plain, &err) != CF_OK)
        fail_msg("%s", err.msg);
    if (cf_joint_fit_tail(tabs, 2, &o, &s, &plain, &tail, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(tail.fit.tail);
    assert_true(cf_spring_has_tail(&tail.fit.params));
    close_rel("rho", tail.ident.rho, q[0], 1e-4);
    close_rel("s/H", tail.ident.solid, q[1], 1e-4);
    close_rel("F_C/H^2", tail.ident.scale, q[2], 1e-4);
    close_rel("e_t", tail.fit.q[CF_Q_TAIL], q[3], 1e-4);
    /* the errors of the four quantities from the joint residuals, as a single fit's */
    for (int k = 0; k < 3; k++)
        assert_true(tail.fit.ident_se.v[k] >= 0 && isfinite(tail.fit.ident_se.v[k]));
    assert_true(tail.fit.q_se[CF_Q_TAIL] >= 0 && isfinite(tail.fit.q_se[CF_Q_TAIL]));
    /* the tables reproduced by the tail, not by the cone alone; the tail's AIC far lower */
    for (int k = 0; k < 2; k++) {
        assert_true(tail.tab[k].cell_rmse <= 1e-4 * tail.tab[k].scale_MPa);
        assert_true(plain.tab[k].cell_rmse > 10 * tail.tab[k].cell_rmse);
    }
    assert_true(tail.aic < plain.aic - 20);
    assert_true(tail.objective < plain.objective);
    cf_joint_free(&plain);
    cf_joint_free(&tail);
    cf_table_free(&t[0]);
    cf_table_free(&t[1]);
}

/* The brain cortex in tension, compression and shear, --joint --law auto: both laws for each
** type, finite joint AICs, the tail kept only with a lower one and a feasible spring, never worse
** in the weighted objective than the conical law it nests; the fit file holds both laws and its
** kept spring loads back with its tail. */
static void brain_cortex_joint_auto(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("brain_cortex_joint_auto");
    cf_table t[3];
    const cf_table *tabs[3];
    if (!tu_load_modes("brain_cortex", tu_tcs, 3, t, tabs))
        skip();
    cf_error err = {0};
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    cf_joint_report r;
    if (cf_pipeline_fit_joint(tabs, 3, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.nfits, 2);
    for (int i = 0; i < r.nfits; i++) {
        const cf_joint_law_choice *lc = &r.law_choice[i];
        assert_true(lc->ran);
        /* auto also fits the double-acting element: the single-sided law kept is then the one
        ** the pair displaced */
        const cf_joint_result *kept = lc->chose_pair ? &lc->pair_other : &r.fits[i];
        const cf_joint_result *tail = lc->chose_tail ? kept : &lc->other;
        const cf_joint_result *cone = lc->chose_tail ? &lc->other : kept;
        assert_true(tail->fit.tail && !cone->fit.tail);
        assert_true(isfinite(tail->aic) && isfinite(cone->aic));
        assert_int_equal(lc->chose_tail, tail->fit.feasible && tail->aic < cone->aic);
        assert_int_equal(kept->fit.tail, lc->chose_tail);
        assert_true(tail->objective <= cone->objective * (1 + 1e-9));
        for (size_t k = 0; k < 3; k++)
            assert_true(isfinite(tail->tab[k].cell_rmse) && isfinite(tail->tab[k].aic));
    }
    char *text = cf_joint_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "conical-tail joint AIC"));
    assert_non_null(strstr(text, "kept: "));
    free(text);
    char dirt[] = "/tmp/conifit-jt-XXXXXX", json[256];
    assert_non_null(mkdtemp(dirt));
    snprintf(json, sizeof json, "%s/joint.json", dirt);
    cf_output *jo = NULL;
    assert_int_equal(cf_output_new(&jo, &err), CF_OK);
    assert_int_equal(cf_joint_prepare(&r, json, NULL, NULL, jo, NULL, &err), CF_OK);
    assert_int_equal(cf_output_commit(jo, &err), CF_OK);
    cf_output_free(jo);
    char *file = tu_slurp(json);
    assert_non_null(file);
    assert_non_null(strstr(file, "\"law_comparison\""));
    free(file);
    for (int i = 0; i < r.nfits; i++) {
        cf_fitted_spring fs;
        const char *tn = cf_spring_type_name(r.fits[i].fit.type);
        if (r.fits[i].pair) { /* a kept double-acting element: read whole, never half */
            assert_int_equal(cf_fitfile_load(json, tn, &fs, &err), CF_E_DATA);
            assert_non_null(strstr(err.msg, "params_extension"));
            if (cf_fitfile_load_element(json, tn, &fs, &err) != CF_OK)
                fail_msg("%s", err.msg);
            assert_true(fs.has_extension);
            close_rel("extension D1", fs.extension.D1_mm, r.fits[i].ext.params.D1_mm, 1e-12);
            continue;
        }
        if (cf_fitfile_load(json, tn, &fs, &err) != CF_OK)
            fail_msg("%s", err.msg);
        assert_int_equal(cf_spring_has_tail(&fs.params), r.fits[i].fit.tail);
        if (r.fits[i].fit.tail) {
            close_rel("n_tail", fs.params.n_tail, r.fits[i].fit.params.n_tail, 1e-12);
            close_rel("H_tail", fs.params.H_tail_mm, r.fits[i].fit.params.H_tail_mm, 1e-12);
        }
    }
    remove(json);
    rmdir(dirt);
    cf_joint_report_free(&r);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* The chicken breast in tension, compression and shear, jointly (issue 37): the tailed search of
** either type ends on a spring that breaks a limit (telescoping D2_max_H and index_max,
** non-telescoping the travel; on main reported so) beside a feasible conical fit, so the tailed law's joint fit is the conical
** optimum it contains, with no tail, never infeasible or worse in the weighted objective; --law
** conical-tail reports that optimum and says what the search ended on. */
static void chicken_breast_joint_tail_never_loses(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("chicken_breast_joint_tail_never_loses");
    cf_table t[3];
    const cf_table *tabs[3];
    if (!tu_load_modes("chicken_breast", tu_tcs, 3, t, tabs))
        skip();
    cf_error err = {0};
    cf_fit_options o = cf_fit_default_options();
    cf_validate_setup s = cf_validate_default();
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        cf_joint_result plain, tail;
        if (cf_joint_fit(tabs, 3, &o, &s, (cf_spring_type)ty, &plain, &err) != CF_OK)
            fail_msg("%s", err.msg);
        assert_true(plain.fit.feasible);
        if (cf_joint_fit_tail(tabs, 3, &o, &s, &plain, &tail, &err) != CF_OK)
            fail_msg("%s", err.msg);
        assert_true(tail.fit.tail);
        assert_true(tail.fit.feasible);
        if (!(tail.objective <= plain.objective * (1 + 1e-9)))
            fail_msg("type %d: tailed joint objective %.6g above the conical %.6g", ty,
                     tail.objective, plain.objective);
        /* here the search's own spring lost: lower objective, broken limits */
        assert_true(tail.fit.params.n_tail == 0 && tail.fit.q[CF_Q_TAIL] == 0);
        assert_true(tail.nested_objective > 0 && tail.nested_objective < plain.objective);
        assert_true(tail.fit.nested_rmse > 0);
        assert_true(tail.fit.nested_violated != 0);
        assert_true(tail.objective == plain.objective && tail.aic == plain.aic);
        for (size_t k = 0; k < 3; k++)
            assert_true(tail.tab[k].lattice_MPa != plain.tab[k].lattice_MPa &&
                        tail.tab[k].lattice_MPa[0] == plain.tab[k].lattice_MPa[0]);
        cf_joint_free(&plain);
        cf_joint_free(&tail);
    }
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_TAIL;
    cf_joint_report r;
    if (cf_pipeline_fit_joint(tabs, 3, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    for (int i = 0; i < r.nfits; i++) {
        assert_true(r.law_choice[i].ran && r.law_choice[i].chose_tail);
        assert_true(r.fits[i].fit.feasible && r.fits[i].fit.params.n_tail == 0);
    }
    char *text = cf_joint_text(&r);
    assert_non_null(text);
    if (!strstr(text, "no tail: the conical optimum the tailed law contains, since the tailed "
                      "spring its search ended on (objective"))
        fail_msg("the report does not say what the tailed search ended on:\n%s", text);
    assert_non_null(strstr(text, "breaks the limit"));
    free(text);
    cf_joint_report_free(&r);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(known_tailed_spring_is_recovered_through_the_lattice),
        cmocka_unit_test(valve_in_equibiaxial_keeps_the_tail),
        cmocka_unit_test(softening_shear_keeps_the_conical_law),
        cmocka_unit_test(tail_through_the_lattice_never_loses_to_the_conical_law),
        cmocka_unit_test(known_tailed_spring_is_recovered_jointly),
        cmocka_unit_test(brain_cortex_joint_auto),
        cmocka_unit_test(chicken_breast_joint_tail_never_loses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
