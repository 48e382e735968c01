/*
** Tests of the double-acting element and the volume term in joint fits (joint.h,
** cf_joint_fit_pair; pipeline_joint.h): a known pair and kappa are recovered from the cell's
** uniaxial tension, uniaxial compression and simple shear tables; --law auto keeps the odd law on
** tables an odd law made (the pair buys no AIC); a declared nu gives the lattice that nu; the brain
** cortex in three modes reaches 0.3 of one-term Ogden's weighted objective (0.0343) with a
** buildable pair, and the fit file says so.
*/
#include "jointutil.h"
#include "testutil.h"

#include "model/cell.h"
#include "model/cell_elliptic.h"
#include "io/fitfile.h"
#include "fit/joint.h"
#include "report/jointreport.h"
#include "io/measure.h"
#include "conifit/output.h"
#include "pipeline/pipeline_joint.h"
#include "check/validate.h"

#include <gsl/gsl_eigen.h>

/* The known springs at H = 1 mm from their quantities (family.h: a stress-strain table sees only
** rho, s/H and F_C/H^2): compression rho 0.4, s/H 0.5, 2 kPa; extension rho 0.2, s/H 0.7, 0.5 kPa. */
static const cf_ident known_c = {.rho = 0.4, .solid = 0.5, .scale = 2e-3};
static const cf_ident known_e = {.rho = 0.2, .solid = 0.7, .scale = 5e-4};

/* The stress-strain table of mode m: the cell (isotropic lattice, exact law) of the pair
** (ext may be NULL: the odd law) and kappa at n strains from 0 to e_end; rel_noise > 0 adds a
** deterministic relative wobble. */
static void cell_table(const cf_ident *qc, const cf_ident *qe, double kappa, cf_mode m,
                       double e_end, size_t n, double rel_noise, cf_table *t)
{
    const cf_spring pc = cf_ident_member(qc);
    cf_law law, ext;
    assert_int_equal(cf_law_init(&law, &pc, NULL), CF_OK);
    if (qe) {
        const cf_spring pe = cf_ident_member(qe);
        assert_int_equal(cf_law_init(&ext, &pe, NULL), CF_OK);
        assert_int_equal(cf_law_pair(&law, &ext, NULL), CF_OK);
    }
    double w[CF_FAMILY_COUNT];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, w, NULL), CF_OK);
    c.volume_modulus_MPa = kappa;
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    assert_non_null(x);
    assert_non_null(y);
    for (size_t i = 0; i < n; i++) {
        cf_cell_state s;
        x[i] = e_end * (double)(i + 1) / (double)n;
        cf_error err = {0};
        if (cf_cell_mode(&c, m, x[i], NULL, &s, &err) != CF_OK)
            fail_msg("%s", err.msg);
        y[i] = s.stress_MPa * (1 + rel_noise * sin(7.3 * (double)i + 1.1 * m + (e_end < 0)));
    }
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, n, x, y, NULL, t, &err), CF_OK);
    t->mode = m;
    free(x);
    free(y);
}

static void close_rel(const char *what, double got, double want, double rel)
{
    if (!(fabs(got - want) <= rel * fabs(want)))
        fail_msg("%s: %.12g, expected %.12g (relative %.1g)", what, got, want, rel);
}

/* Tension (the extension spring past its transition), compression (the compression spring past
** its) and shear of a known pair with kappa = 3 k0/H: the pair and kappa recovered to 1e-6, with
** finite errors; the odd law with the volume term cannot reproduce them. */
static void known_pair_and_kappa_are_recovered(void **state)
{
    (void)state;
    const cf_spring pc = cf_ident_member(&known_c);
    cf_law lc;
    assert_int_equal(cf_law_init(&lc, &pc, NULL), CF_OK);
    const double kappa = 3 * lc.k0_N_per_mm / lc.p.H_mm;
    cf_table t[3];
    cell_table(&known_c, &known_e, kappa, CF_MODE_UNIAXIAL, 0.45, 25, 0, &t[0]);
    cell_table(&known_c, &known_e, kappa, CF_MODE_UNIAXIAL, -0.4, 25, 0, &t[1]);
    cell_table(&known_c, &known_e, kappa, CF_MODE_SHEAR, 0.6, 25, 0, &t[2]);
    const cf_table *tabs[3] = {&t[0], &t[1], &t[2]};
    cf_fit_options o = cf_fit_default_options();
    o.volume = CF_VOLUME_FIT;
    cf_validate_setup s = cf_validate_default();
    cf_joint_result plain, pair, single;
    cf_error err = {0};
    if (cf_joint_fit(tabs, 3, &o, &s, CF_NON_TELESCOPING, &plain, &err) != CF_OK)
        fail_msg("%s", err.msg);
    if (cf_joint_fit_pair(tabs, 3, &o, &s, CF_NON_TELESCOPING, 1, &plain, &pair, &err) != CF_OK)
        fail_msg("%s", err.msg);
    if (cf_joint_fit_pair(tabs, 3, &o, &s, CF_NON_TELESCOPING, 0, &plain, &single, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(pair.pair && pair.nparams == 7 && single.nparams == 4);
    close_rel("rho_c", pair.ident.rho, known_c.rho, 1e-6);
    close_rel("s/H_c", pair.ident.solid, known_c.solid, 1e-6);
    close_rel("A_c", pair.ident.scale, known_c.scale, 1e-6);
    close_rel("rho_e", pair.ext.ident.rho, known_e.rho, 1e-6);
    close_rel("s/H_e", pair.ext.ident.solid, known_e.solid, 1e-6);
    close_rel("A_e", pair.ext.ident.scale, known_e.scale, 1e-6);
    close_rel("kappa", pair.volume_modulus_MPa, kappa, 1e-6);
    for (int k = 0; k < 3; k++) {
        assert_true(pair.fit.ident_se.v[k] >= 0 && isfinite(pair.fit.ident_se.v[k]));
        assert_true(pair.ext.ident_se.v[k] >= 0 && isfinite(pair.ext.ident_se.v[k]));
    }
    assert_true(pair.volume_modulus_se >= 0 && isfinite(pair.volume_modulus_se));
    /* both springs placed with one free length, the extension spring's quantities its own */
    assert_true(pair.ext.params.H_mm == pair.fit.params.H_mm);
    cf_ident qe = cf_ident_of(&pair.ext.params, 0);
    close_rel("placed rho_e", qe.rho, known_e.rho, 1e-6);
    /* the small-strain moduli each side: the cell's at -+1e-6 (a bimodular lattice's nu per
    ** side is not bounded by 0.5: in compression its lateral springs work on their extension
    ** side); compression the stiffer side here */
    assert_true(isfinite(pair.nu_compression) && pair.nu_compression > 0 &&
                pair.nu_compression < 1);
    assert_true(isfinite(pair.nu_extension) && pair.nu_extension > 0 && pair.nu_extension < 1);
    assert_true(pair.E_compression_MPa > pair.E_extension_MPa && pair.E_extension_MPa > 0);
    for (int k = 0; k < 3; k++)
        assert_true(pair.tab[k].cell_rmse <= 1e-6 * pair.tab[k].scale_MPa);
    assert_true(single.objective > 1e3 * pair.objective);
    assert_true(pair.aic < single.aic);
    cf_joint_free(&plain);
    cf_joint_free(&pair);
    cf_joint_free(&single);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* The pair is refused (CF_E_DATA naming the spring left free) where the tables do not determine
** it: simple shear alone, a compression table alone (the extension spring), an equibiaxial
** tension table alone (the compression spring), two compression tables; the volume term alone
** (pair 0) is not. Shear beside one side determines the other: the known pair is recovered from
** its compression and shear curves (noiseless) as from all three modes. Measured with the check
** bypassed, on these noiseless tables of the known pair: shear alone fits to 1e-14 and recovers
** neither spring (rho_c 0.403, rho_e 0.167 for 0.4, 0.2; every error not determined); the
** compression table alone recovers the compression spring to 1e-5 and not the extension spring
** (rho_e 0.164, A_e 9.1e-4 for 0.2, 5e-4; not determined). */
static void pair_refused_where_the_tables_do_not_determine_it(void **state)
{
    (void)state;
    cf_table t[4];
    cell_table(&known_c, &known_e, 0, CF_MODE_SHEAR, 0.6, 25, 0, &t[0]);
    cell_table(&known_c, &known_e, 0, CF_MODE_UNIAXIAL, -0.4, 25, 0, &t[1]);
    cell_table(&known_c, &known_e, 0, CF_MODE_EQUIBIAXIAL, 0.2, 25, 0, &t[2]);
    cell_table(&known_c, &known_e, 0, CF_MODE_CONFINED, -0.2, 25, 0, &t[3]);
    cf_fit_options o = cf_fit_default_options();
    cf_validate_setup s = cf_validate_default();
    static const struct {
        int first, n;
        const char *says;
    } refused[] = {
        {0, 1, "not determined by simple shear alone"},
        {1, 1, "extension spring is not determined by the table"},
        {2, 1, "compression spring is not determined by the table"},
    };
    cf_joint_result r;
    for (size_t i = 0; i < 3; i++) {
        const cf_table *tabs[1] = {&t[refused[i].first]};
        cf_error err = {0};
        assert_int_equal(cf_joint_fit_pair(tabs, 1, &o, &s, CF_NON_TELESCOPING, 1, NULL, &r, &err),
                         CF_E_DATA);
        if (!strstr(err.msg, refused[i].says))
            fail_msg("'%s' does not say '%s'", err.msg, refused[i].says);
    }
    const cf_table *two_c[2] = {&t[1], &t[3]};
    cf_error err = {0};
    assert_int_equal(cf_joint_fit_pair(two_c, 2, &o, &s, CF_NON_TELESCOPING, 2, NULL, &r, &err),
                     CF_E_DATA);
    assert_non_null(strstr(err.msg, "extension spring is not determined by the 2 tables"));
    /* compression and shear: determined */
    const cf_table *cs[2] = {&t[1], &t[0]};
    cf_joint_result plain;
    if (cf_joint_fit(cs, 2, &o, &s, CF_NON_TELESCOPING, &plain, &err) != CF_OK)
        fail_msg("%s", err.msg);
    if (cf_joint_fit_pair(cs, 2, &o, &s, CF_NON_TELESCOPING, 1, &plain, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    print_message("compression + shear: rho_e %.9g (%.9g), s/H_e %.9g (%.9g), A_e %.9g (%.9g), "
                  "rho_c %.9g, objective %.3g\n", r.ext.ident.rho, known_e.rho, r.ext.ident.solid,
                  known_e.solid, r.ext.ident.scale, known_e.scale, r.ident.rho, r.objective);
    close_rel("rho_c", r.ident.rho, known_c.rho, 1e-6);
    close_rel("s/H_c", r.ident.solid, known_c.solid, 1e-6);
    close_rel("rho_e", r.ext.ident.rho, known_e.rho, 1e-6);
    close_rel("s/H_e", r.ext.ident.solid, known_e.solid, 1e-6);
    close_rel("A_e", r.ext.ident.scale, known_e.scale, 1e-6);
    cf_joint_free(&r);
    cf_joint_free(&plain);
    /* the volume term alone on one compression table */
    o.volume = CF_VOLUME_FIT;
    const cf_table *one[1] = {&t[1]};
    if (cf_joint_fit_pair(one, 1, &o, &s, CF_NON_TELESCOPING, 0, NULL, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_joint_free(&r);
    for (int k = 0; k < 4; k++)
        cf_table_free(&t[k]);
}

/* Tables an odd law made (with 0.5 % wobble): --law auto --volume fit keeps the single-sided law
** (the pair's three more quantities buy no AIC); with --law double-acting the pair is fitted and
** finds two nearly equal springs. */
static void auto_keeps_the_odd_law_where_the_pair_buys_nothing(void **state)
{
    (void)state;
    const cf_spring pc = cf_ident_member(&known_c);
    cf_law lc;
    assert_int_equal(cf_law_init(&lc, &pc, NULL), CF_OK);
    const double kappa = 1.5 * lc.k0_N_per_mm / lc.p.H_mm;
    cf_table t[3];
    cell_table(&known_c, NULL, kappa, CF_MODE_UNIAXIAL, 0.3, 20, 5e-3, &t[0]);
    cell_table(&known_c, NULL, kappa, CF_MODE_UNIAXIAL, -0.35, 20, 5e-3, &t[1]);
    cell_table(&known_c, NULL, kappa, CF_MODE_SHEAR, 0.5, 20, 5e-3, &t[2]);
    const cf_table *tabs[3] = {&t[0], &t[1], &t[2]};
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    po.fit.volume = CF_VOLUME_FIT;
    po.types = 1u << CF_NON_TELESCOPING;
    cf_joint_report r;
    cf_error err = {0};
    if (cf_pipeline_fit_joint(tabs, 3, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.nfits, 1);
    const cf_joint_law_choice *lc0 = &r.law_choice[0];
    assert_true(lc0->pair_ran);
    assert_false(lc0->chose_pair);
    assert_false(r.fits[0].pair);
    assert_true(lc0->pair_other.pair);
    assert_true(lc0->pair_other.aic > r.fits[0].aic);
    assert_true(r.fits[0].volume == CF_VOLUME_FIT && r.fits[0].volume_modulus_MPa > 0);
    close_rel("kappa (odd law)", r.fits[0].volume_modulus_MPa, kappa, 0.05);
    char *text = cf_joint_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "the pair does not lower the joint AIC"));
    free(text);
    cf_joint_report_free(&r);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* A declared nu: the fitted lattice's small-strain nu (compression side) is that nu; a nu below the
** springs' own is refused. */
static void declared_nu_is_the_lattices(void **state)
{
    (void)state;
    cf_table t[2];
    cell_table(&known_c, NULL, 0, CF_MODE_UNIAXIAL, 0.3, 15, 0, &t[0]);
    cell_table(&known_c, NULL, 0, CF_MODE_SHEAR, 0.4, 15, 0, &t[1]);
    const cf_table *tabs[2] = {&t[0], &t[1]};
    cf_fit_options o = cf_fit_default_options();
    o.volume = CF_VOLUME_POISSON;
    o.volume_value = 0.45;
    cf_validate_setup s = cf_validate_default();
    cf_joint_result r;
    cf_error err = {0};
    if (cf_joint_fit_pair(tabs, 2, &o, &s, CF_NON_TELESCOPING, 0, NULL, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    close_rel("nu", r.nu_compression, 0.45, 1e-5); /* the cell's at strain -1e-6 */
    close_rel("nu (tension)", r.nu_extension, 0.45, 1e-5);
    assert_true(r.volume_modulus_MPa > 0);
    /* the cell of the fitted springs and kappa: lateral over axial strain -0.45 at small strain */
    cf_law law;
    assert_int_equal(cf_law_init(&law, &r.fit.params, NULL), CF_OK);
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &law, CF_LAW_EXACT, r.weight, NULL), CF_OK);
    c.volume_modulus_MPa = r.volume_modulus_MPa;
    cf_cell_state st;
    assert_int_equal(cf_cell_mode(&c, CF_MODE_UNIAXIAL, 1e-7, NULL, &st, NULL), CF_OK);
    close_rel("lateral/axial", (1 - st.free_stretch) / 1e-7, 0.45, 1e-5);
    cf_joint_free(&r);
    o.volume_value = 0.2;
    assert_int_equal(cf_joint_fit_pair(tabs, 2, &o, &s, CF_NON_TELESCOPING, 0, NULL, &r, &err),
                     CF_E_DATA);
    assert_non_null(strstr(err.msg, "--poisson 0.2"));
    for (int k = 0; k < 2; k++)
        cf_table_free(&t[k]);
}

/* The smallest eigenvalue of the acoustic tensor of cell's tangent at mode m, strain e, for the
** one direction n: formed here and solved by GSL, apart from cf_acoustic_min. */
static double acoustic_at(const cf_cell *cell, cf_mode m, double e, const double n[3])
{
    cf_cell_state s;
    double A[81];
    assert_int_equal(cf_cell_mode(cell, m, e, NULL, &s, NULL), CF_OK);
    assert_int_equal(cf_cell_tangent(cell, s.F, NULL, &s, A, NULL), CF_OK);
    gsl_matrix *q = gsl_matrix_alloc(3, 3);
    gsl_vector *ev = gsl_vector_alloc(3);
    gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(3);
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            double v = 0;
            for (int j = 0; j < 3; j++)
                for (int l = 0; l < 3; l++)
                    v += 0.5 * (A[27 * i + 9 * j + 3 * k + l] + A[27 * k + 9 * j + 3 * i + l]) *
                         n[j] * n[l];
            gsl_matrix_set(q, i, k, v);
        }
    assert_int_equal(gsl_eigen_symm(q, ev, w), 0);
    const double lo = gsl_vector_min(ev);
    gsl_eigen_symm_free(w);
    gsl_vector_free(ev);
    gsl_matrix_free(q);
    return lo;
}

/* Every fit of r states for each table whether its cell stays strongly elliptic to 1.05x the
** range; where it does not, the acoustic tensor at the direction reported is positive definite
** before the strain reported and not just past it (checked apart from the scan); no other type
** is elliptic within CF_JOINT_ELLIPTIC_SLACK of the kept fit's objective where the kept one is
** not (the cortex: the kept non-telescoping pair, 0.008504, loses it in tension at 5.6 %; the
** telescoping one, elliptic, ends at 0.02987), and the report and the fit file (file, its text)
** say so. */
static void assert_elliptic_verdicts(const cf_joint_report *r, const char *file)
{
    int lost = 0;
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_result *j = &r->fits[i];
        cf_law law, ext;
        assert_int_equal(cf_law_init(&law, &j->fit.params, NULL), CF_OK);
        if (j->pair) {
            assert_int_equal(cf_law_init(&ext, &j->ext.params, NULL), CF_OK);
            assert_int_equal(cf_law_pair(&law, &ext, NULL), CF_OK);
        }
        cf_cell cell;
        assert_int_equal(cf_cell_init(&cell, &law, CF_LAW_CLOSED, j->weight, NULL), CF_OK);
        cell.volume_modulus_MPa = j->volume_modulus_MPa;
        for (size_t k = 0; k < r->ntables; k++) {
            const cf_joint_table *jt = &j->tab[k];
            assert_true(jt->elliptic_checked);
            if (jt->elliptic_in_range)
                continue;
            lost++;
            const double e = jt->elliptic_to, n2 = jt->elliptic_n[0] * jt->elliptic_n[0] +
                                                   jt->elliptic_n[1] * jt->elliptic_n[1] +
                                                   jt->elliptic_n[2] * jt->elliptic_n[2];
            assert_true(fabs(n2 - 1) < 1e-9);
            const double past = e + 1e-4 * (e >= 0 ? 1 : -1);
            if (!(acoustic_at(&cell, jt->mode, past, jt->elliptic_n) <= 0))
                fail_msg("fit %d table %zu: Q(n) positive definite past the loss at %g", i, k, e);
            if (fabs(e) > 2e-3)
                assert_true(acoustic_at(&cell, jt->mode, 0.5 * e, jt->elliptic_n) > 0);
        }
        cf_law_free(&law);
    }
    const int b = cf_joint_better(r);
    assert_true(b >= 0);
    for (int i = 0; i < r->nfits; i++) /* no other type elliptic within the slack */
        assert_false(cf_joint_elliptic_wins(&r->fits[i], &r->fits[b]));
    char *text = cf_joint_text(r);
    assert_non_null(text);
    assert_non_null(strstr(text, "strongly elliptic to 1.05x the table's range"));
    assert_true(!lost || strstr(text, "loses strong ellipticity at strain"));
    free(text);
    assert_non_null(strstr(file, "\"elliptic_in_range\": true"));
    assert_non_null(strstr(file, "\"elliptic_to_strain\""));
    assert_true(!lost || strstr(file, "\"elliptic_lost_direction\""));
}

/* The brain cortex (Budday et al. 2017) in tension, compression and shear, --joint --law auto
** --volume fit (issue 35's target): the kept element a buildable double-acting pair whose full
** lattice (2^3 and 3^3 cells) is stable over every table's range, its weighted objective at or
** below CORTEX_MAX (0.00802 measured with the search kept to stable lattices and buildable springs,
** a tailed compression spring; 0.008504 when the search saw stability alone: the bound holds
** that the search no longer walks off to unbuildable springs; 0.3 of one-term Ogden's 0.0343,
** 0.01029, before; 0.01248 before the hourglass control);
** every table's cell curve finite; the fit file holds params_extension, the tail and
** lattice.volume_modulus_MPa; each table's strong-ellipticity verdict
** (assert_elliptic_verdicts). */
#define CORTEX_MAX 0.0083
static void brain_cortex_stable_pair_below_ogden(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("brain_cortex_stable_pair_below_ogden");
    cf_table t[3];
    const cf_table *tabs[3];
    if (!tu_load_modes("brain_cortex", tu_tcs, 3, t, tabs))
        skip();
    cf_error err = {0};
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    po.fit.volume = CF_VOLUME_FIT;
    cf_joint_report r;
    if (cf_pipeline_fit_joint(tabs, 3, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    const int b = cf_joint_better(&r);
    assert_true(b >= 0);
    const cf_joint_result *j = &r.fits[b];
    if (!(j->objective <= CORTEX_MAX))
        fail_msg("objective %.6g above %g (one-term Ogden's: 0.0343)", j->objective, CORTEX_MAX);
    assert_true(j->pair && j->fit.feasible && j->ext.feasible);
    /* which compression spring: with the lattice's hourglass control (lattice_hourglass.h) the
    ** conical pair's optimum, 0.01713, is stable, and the tailed pair's, 0.00802, stable and
    ** buildable, is kept (its search's last rounds, seeing stability alone, had walked on to an
    ** unbuildable 0.007851 and given way to the round before, 0.008504); before the control, the
    ** tailed pair was kept at 0.01248 */
    const int tail = r.law_choice[b].pair_tail_kept;
    assert_int_equal(j->fit.tail != 0, tail);
    if (tail)
        assert_true(j->fit.params.n_tail > 0 && j->fit.q[CF_Q_TAIL] > 0 &&
                    r.law_choice[b].alt_stable && r.law_choice[b].alt_objective > j->objective);
    assert_true(j->volume_modulus_MPa > 0 && isfinite(j->nu_compression) &&
                isfinite(j->nu_extension));
    /* brain is stiffer in compression than in tension at small strain too */
    assert_true(j->E_compression_MPa > j->E_extension_MPa && j->E_extension_MPa > 0);
    /* the lattice stable over every table's range (the cell's incremental stiffness, and for
    ** the uniaxial tables the full lattice's tangent) */
    for (size_t k = 0; k < 3; k++) {
        assert_true(isfinite(j->tab[k].cell_rmse));
        assert_true(j->tab[k].stability_checked && j->tab[k].stable_in_range);
        assert_int_equal(j->tab[k].lattice_checked, j->tab[k].mode == CF_MODE_UNIAXIAL);
        /* the uniaxial tables run in the full lattice, pair and volume term included: its RMSE
        ** is the cell's */
        if (j->tab[k].mode == CF_MODE_UNIAXIAL) {
            assert_false(j->tab[k].by_cell);
            close_rel("lattice RMSE", j->tab[k].lattice_rmse, j->tab[k].cell_rmse, 1e-6);
        }
    }
    char dirt[] = "/tmp/conifit-jp-XXXXXX", json[256];
    assert_non_null(mkdtemp(dirt));
    snprintf(json, sizeof json, "%s/joint.json", dirt);
    cf_output *jo = NULL;
    assert_int_equal(cf_output_new(&jo, &err), CF_OK);
    assert_int_equal(cf_joint_prepare(&r, json, NULL, NULL, jo, NULL, &err), CF_OK);
    assert_int_equal(cf_output_commit(jo, &err), CF_OK);
    cf_output_free(jo);
    char *file = tu_slurp(json);
    assert_non_null(file);
    assert_non_null(strstr(file, "\"params_extension\""));
    assert_non_null(strstr(file, "\"volume_modulus_MPa\""));
    assert_non_null(strstr(file, "\"double-acting\""));
    assert_non_null(strstr(file, "\"poisson_ratio_extension\""));
    assert_true(!tail || strstr(file, "\"tail_compliance\""));
    assert_non_null(strstr(file, "\"pair_alternative\""));
    assert_elliptic_verdicts(&r, file);
    free(file);
    remove(json);
    rmdir(dirt);
    cf_joint_report_free(&r);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* The chicken breast in tension, compression and shear (issue 37): the single-sided law's joint
** fit is checked and kept stable in the full lattice; the pair contains the single-sided law (two
** equal springs), so its joint fit from that law's optimum never ends above it in the weighted
** objective. Before the contained optimum was a start counted as it is, the
** telescoping pair ended at 1.197 (infeasible, G_max) against the law's 0.912. */
static void chicken_breast_pair_never_loses_to_the_odd_law(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("chicken_breast_pair_never_loses_to_the_odd_law");
    cf_table t[3];
    const cf_table *tabs[3];
    if (!tu_load_modes("chicken_breast", tu_tcs, 3, t, tabs))
        skip();
    cf_error err = {0};
    cf_fit_options o = cf_fit_default_options();
    cf_validate_setup s = cf_validate_default();
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        cf_joint_result plain, pair;
        if (cf_joint_fit(tabs, 3, &o, &s, (cf_spring_type)ty, &plain, &err) != CF_OK)
            fail_msg("%s", err.msg);
        if (cf_joint_fit_pair(tabs, 3, &o, &s, (cf_spring_type)ty, 1, &plain, &pair, &err) !=
            CF_OK)
            fail_msg("%s", err.msg);
        assert_true(pair.pair);
        /* the single-sided law's verdict is the full lattice's too, and its search keeps to
        ** stable lattices: the odd law's optimum of each type buckles in the 2^3 lattice
        ** (objectives 0.912 and 0.842), the stable ones end at 1.114 and 1.105 */
        for (size_t k = 0; k < 3; k++) {
            assert_true(plain.tab[k].stability_checked);
            assert_int_equal(plain.tab[k].lattice_checked, tabs[k]->mode == CF_MODE_UNIAXIAL);
        }
        if (!cf_joint_stable(&plain))
            fail_msg("type %d: the odd law's lattice loses stability inside a table's range "
                     "(objective %.6g)", ty, plain.objective);
        /* never worse than the odd law it contains, unless the search left the odd law's optimum
        ** for stability: the odd law's element buckles in the full lattice inside a table's range
        ** (non-telescoping chicken breast: its 2^3 lattice does) and the pair kept is stable */
        const int left_for_stability = pair.tab[1].stability_checked && cf_joint_stable(&pair);
        if (!(pair.objective <= plain.objective * (1 + 1e-9)) && !left_for_stability)
            fail_msg("type %d: the pair's joint objective %.6g above the odd law's %.6g", ty,
                     pair.objective, plain.objective);
        if (plain.fit.feasible && pair.objective == plain.objective)
            assert_true(pair.fit.feasible); /* the equal springs: the law's own spring twice */
        cf_joint_free(&plain);
        cf_joint_free(&pair);
    }
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* The corona radiata in tension and compression (issues 37, 42): the telescoping pair (conical
** compression spring, cf_joint_fit_pair pair 1) never ends above the buildable odd law (0.579)
** it contains. Before issue 42 its search ended on an element whose extension spring breaks the
** least spring index (0.0072), so the pair was that law's optimum as two equal springs (the
** report then says what the search ended on); its restarts from every stable end now reach a
** buildable pair stable to 1.05x the tables' range (0.00869). The pipeline (--law double-acting)
** also fits the pair with a tailed compression spring, which never ends above the conical pair,
** and names the one it does not keep. */
static void coronaradiata_pair_never_above_the_odd_law(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("coronaradiata_pair_never_above_the_odd_law");
    cf_table t[2];
    const cf_table *tabs[2];
    static const char *const modes[2] = {"tension", "compression"};
    if (!tu_load_modes("brain_coronaradiata", modes, 2, t, tabs))
        skip();
    cf_error err = {0};
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_DOUBLE;
    po.types = 1u << CF_TELESCOPING;
    /* the conical pair through the library, beside the odd law it contains */
    cf_joint_report r;
    memset(&r, 0, sizeof r);
    r.tables = tabs;
    r.ntables = 2;
    r.nfits = 1;
    r.law = CF_KIND_DOUBLE;
    cf_joint_law_choice *lc = &r.law_choice[0];
    cf_joint_result *pair = &r.fits[0], *odd = &lc->pair_other;
    if (cf_joint_fit(tabs, 2, &po.fit, &po.lattice, CF_TELESCOPING, odd, &err) != CF_OK)
        fail_msg("%s", err.msg);
    if (cf_joint_fit_pair(tabs, 2, &po.fit, &po.lattice, CF_TELESCOPING, 1, odd, pair, &err) !=
        CF_OK)
        fail_msg("%s", err.msg);
    lc->pair_ran = lc->chose_pair = 1;
    assert_true(pair->pair && odd->fit.feasible);
    assert_true(pair->fit.feasible && pair->ext.feasible);
    assert_true(pair->objective <= odd->objective * (1 + 1e-9));
    const int equal = pair->nested_objective > 0;
    if (equal) { /* the odd law's optimum as two equal springs */
        close_rel("pair objective", pair->objective, odd->objective, 1e-9);
        close_rel("extension D1", pair->ext.params.D1_mm, pair->fit.params.D1_mm, 1e-9);
    } else {
        assert_true(cf_joint_stable(pair) && cf_joint_stable_at_rest(pair));
    }
    char *text = cf_joint_text(&r);
    assert_non_null(text);
    if (equal && !strstr(text, "two equal springs: the single-sided law's optimum the pair "
                               "contains"))
        fail_msg("the report does not say what the pair's search ended on:\n%s", text);
    free(text);
    char dirt[] = "/tmp/conifit-jp-XXXXXX", json[256];
    assert_non_null(mkdtemp(dirt));
    snprintf(json, sizeof json, "%s/joint.json", dirt);
    cf_output *jo = NULL;
    assert_int_equal(cf_output_new(&jo, &err), CF_OK);
    assert_int_equal(cf_joint_prepare(&r, json, NULL, NULL, jo, NULL, &err), CF_OK);
    assert_int_equal(cf_output_commit(jo, &err), CF_OK);
    cf_output_free(jo);
    char *file = tu_slurp(json);
    assert_non_null(file);
    if (equal)
        assert_non_null(strstr(file, "\"equal_springs\""));
    free(file);
    const double conical_pair = pair->objective;
    cf_joint_report_free(&r);
    /* the pipeline: the tailed compression spring, buildable and stable, kept before the
    ** conical pair (the two equal springs), which the report and the fit file name */
    if (cf_pipeline_fit_joint(tabs, 2, &po, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    lc = &r.law_choice[0];
    assert_true(lc->pair_ran && lc->chose_pair && lc->pair_tail_ran);
    pair = &r.fits[0];
    assert_true(pair->pair && pair->fit.feasible && pair->ext.feasible && cf_joint_stable(pair));
    if (lc->pair_tail_kept) { /* the tailed pair, never above the conical one it contains */
        assert_true(pair->fit.tail);
        assert_true(pair->objective <= conical_pair * (1 + 1e-9));
        close_rel("the conical pair named", lc->alt_objective, conical_pair, 1e-9);
    } else {
        close_rel("the conical pair kept", pair->objective, conical_pair, 1e-9);
        assert_true(lc->alt_objective <= conical_pair * (1 + 1e-9) || !lc->alt_feasible ||
                    !lc->alt_stable);
    }
    text = cf_joint_text(&r);
    assert_non_null(text);
    if (!strstr(text, "the pair's compression spring"))
        fail_msg("the report does not name the other compression spring:\n%s", text);
    free(text);
    jo = NULL;
    assert_int_equal(cf_output_new(&jo, &err), CF_OK);
    assert_int_equal(cf_joint_prepare(&r, json, NULL, NULL, jo, NULL, &err), CF_OK);
    assert_int_equal(cf_output_commit(jo, &err), CF_OK);
    cf_output_free(jo);
    file = tu_slurp(json);
    assert_non_null(file);
    assert_non_null(strstr(file, "\"pair_alternative\""));
    assert_non_null(strstr(file, "\"params_extension\""));
    free(file);
    remove(json);
    rmdir(dirt);
    cf_joint_report_free(&r);
    for (int k = 0; k < 2; k++)
        cf_table_free(&t[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(known_pair_and_kappa_are_recovered),
        cmocka_unit_test(pair_refused_where_the_tables_do_not_determine_it),
        cmocka_unit_test(auto_keeps_the_odd_law_where_the_pair_buys_nothing),
        cmocka_unit_test(declared_nu_is_the_lattices),
        cmocka_unit_test(brain_cortex_stable_pair_below_ogden),
        cmocka_unit_test(chicken_breast_pair_never_loses_to_the_odd_law),
        cmocka_unit_test(coronaradiata_pair_never_above_the_odd_law),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
