/*
** The joint fit of a fibre-reinforced lattice (fit/fibre_fit.c):
**  - a known lattice (matrix of unequal family weights, a fibre group along f, one along n, each
**    recruited at its own strain, kappa) is recovered from the
**    noiseless tables of its own cell: five biaxial tables at Sommer's ratios (cross-fibre n) and
**    shear fs, sf, nf, every quantity to 1e-6 relative, and every family placed as buildable
**    springs (the spring fit's design limits, all at one free length, the cell of those springs
**    the fitted cell to 1e-9);
**  - a family stiffer than one spring is built of springs in parallel, each buildable; one below
**    rho_min is flagged with that limit; one with s/H >= 1 is refused;
**  - on the shared myocardium set the fit with f, s and n groups (biaxial cross-fibre s) has an
**    objective at or below the better Holzapfel-Ogden full fit's with the same weights (either
**    cross-fibre axis; all fitted here; src/notes/lattice-fit.md records them), kappa within
**    its bound, the lattice stable along every table to 1.05x and every family placed as buildable springs as above (skipped when ../shared is absent).
*/
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "fit/fibre_fit.h"
#include "fit/holzapfel.h"
#include "fit/joint.h"
#include "io/measure.h"
#include "model/calibration.h"
#include "model/table.h"

static cf_table make_table(cf_mode mode, double r0, double r1, const char *pl, size_t n)
{
    double x[64] = {0}, y[64] = {0};
    const int bi = mode == CF_MODE_BIAXIAL;
    const double m = fmax(r0, r1);
    for (size_t i = 0; i < n; i++) {
        const double s = (double)(i + 1) / (double)n;
        x[i] = bi ? 0.1 * r0 / m * s : 0.5 * s;
        x[n + i] = 0.1 * r1 / m * s;
    }
    cf_table t;
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, bi ? 2 * n : n, x, y, NULL, &t,
                                          NULL),
                     CF_OK);
    t.mode = mode;
    if (bi) {
        t.second = n;
        t.ratio[0] = r0, t.ratio[1] = r1;
    }
    snprintf(t.plane, sizeof t.plane, "%s", pl);
    return t;
}

/* Every family of f placed as buildable springs: each spring within the spring fit's limits
** (index 3 to index_max, at least 2 coils, D2 >= D1, G at most G_max), all at the matrix
** spring's free length, count springs whose family times count is the fitted family (1e-9), and
** the cell built of them giving the fitted cell's stress at every row (1e-9 of the table's). */
static void assert_placed(const cf_fibre_fit *f)
{
    const cf_fit_options o = cf_fit_default_options();
    const double H = f->matrix_spring.spring.H_mm;
    assert_true(f->buildable);
    for (int g = -1; g < f->ngroups; g++) {
        const cf_fibre_spring *s = g < 0 ? &f->matrix_spring : &f->fibre_spring[g];
        const cf_ident *q = g < 0 ? &f->matrix : &f->fibre[g];
        const cf_spring *p = &s->spring;
        char sp[256];
        printf("  %s%c: %d x %s (%s), buildable %d\n", g < 0 ? "matrix" : "group ",
               g < 0 ? ' ' : f->groups[g], s->count, cf_spring_text(p, 4, 0, sp, sizeof sp),
               cf_spring_type_name(s->type), s->buildable);
        assert_true(s->buildable && s->violated == 0 && s->count >= 1);
        assert_true(p->D1_mm / p->d_mm >= 3 * (1 - 1e-9));
        assert_true(p->D1_mm / p->d_mm <= o.index_max * (1 + 1e-9));
        assert_true(p->n >= 2 * (1 - 1e-9) && p->D2_mm >= p->D1_mm && p->G_MPa <= o.upper[CF_P_G]);
        assert_close(p->H_mm, H, 1e-12 * H);
        const cf_ident got = cf_ident_of_type(p, s->type, 0);
        assert_close(got.rho, q->rho, 1e-9 * q->rho);
        assert_close(got.solid, q->solid, 1e-9 * q->solid);
        assert_close(s->count * got.scale, q->scale, 1e-9 * q->scale);
    }
    printf("  placed lattice against the fitted one: %.3g of the largest stress\n",
           f->placed_error);
    assert_true(f->placed_error >= 0 && f->placed_error <= 1e-9);
}

static void known_lattice_is_recovered(void **state)
{
    (void)state;
    const cf_fibre_fit truth = {.groups = "fn", .ngroups = 2, .cross = 'n',
                                .matrix = {.rho = 0.55, .solid = 0.35, .scale = 3e-3},
                                .fibre = {{.rho = 0.4, .solid = 0.2, .scale = 1.5e-2},
                                          {.rho = 0.7, .solid = 0.15, .scale = 4e-3}},
                                .slack = {0.012, 0.004},
                                .family = {1, 0.5, 0.3},
                                .kappa_MPa = 2e-2};
    cf_fibre_model m;
    assert_int_equal(cf_fibre_model_init(&m, &truth, NULL), CF_OK);
    const double r[5][2] = {{1, 1}, {1, 0.75}, {0.75, 1}, {1, 0.5}, {0.5, 1}};
    const char *sh[3] = {"fs", "sf", "nf"};
    cf_table tab[8];
    const cf_table *t[8];
    for (int k = 0; k < 8; k++) {
        tab[k] = k < 5 ? make_table(CF_MODE_BIAXIAL, r[k][0], r[k][1], "", 10)
                       : make_table(CF_MODE_SHEAR, 0, 0, sh[k - 5], 10);
        int ax[2];
        assert_int_equal(cf_ho_axes(&tab[k], 'n', ax), 0);
        for (size_t i = 0; i < tab[k].count; i++)
            assert_int_equal(cf_fibre_row_stress(&m, &tab[k], i, ax, &tab[k].y[i], NULL), CF_OK);
        t[k] = &tab[k];
    }
    cf_fibre_model_free(&m);
    cf_fibre_fit f;
    cf_error err = {0};
    const clock_t c0 = clock();
    if (cf_fibre_fit_joint(t, 8, "fn", 'n', &f, &err) != CF_OK)
        fail_msg("%s", err.msg);
    printf("recovery: objective %.3g, %.2f s CPU, %d starts\n", f.objective,
           (double)(clock() - c0) / CLOCKS_PER_SEC, f.starts);
    const double *got[3] = {f.matrix.v, f.fibre[0].v, f.fibre[1].v};
    const double *want[3] = {truth.matrix.v, truth.fibre[0].v, truth.fibre[1].v};
    for (int g = 0; g < 3; g++)
        for (int q = 0; q < 3; q++)
            if (!(fabs(got[g][q] - want[g][q]) <= 1e-6 * want[g][q]))
                fail_msg("family %d quantity %d: %.17g, made with %.17g", g, q, got[g][q],
                         want[g][q]);
    assert_close(f.kappa_MPa, truth.kappa_MPa, 1e-6 * truth.kappa_MPa);
    for (int q = 1; q < 3; q++)
        if (!(fabs(f.family[q] - truth.family[q]) <= 1e-6 * truth.family[q]))
            fail_msg("family weight %d: %.17g, made with %.17g", q, f.family[q], truth.family[q]);
    for (int g = 0; g < 2; g++)
        if (!(fabs(f.slack[g] - truth.slack[g]) <= 1e-6 * truth.slack[g]))
            fail_msg("group %d recruitment strain %.17g, made with %.17g", g, f.slack[g],
                     truth.slack[g]);
    assert_true(f.stable);
    assert_placed(&f);
    for (int k = 0; k < 8; k++)
        cf_table_free(&tab[k]);
}

/* A family stiffer than any one spring (the myocardium fit's f group: rho 0.072, s/H 0.16,
** F_C/H^2 2.35 MPa, largest about 0.13 MPa for one steel-wire spring) is shared by springs in
** parallel, each buildable, together the family; a family below rho_min is flagged, not built. */
static void stiff_family_is_shared_and_bad_family_flagged(void **state)
{
    (void)state;
    const cf_fit_options o = cf_fit_default_options();
    const cf_ident q = {.rho = 0.072, .solid = 0.16, .scale = 2.346};
    double A_max = 0;
    assert_true(cf_fit_ident_limit(&o, CF_NON_TELESCOPING, q.rho, q.solid, &A_max, NULL) <= 0);
    cf_fibre_spring s;
    cf_error err = {0};
    if (cf_fibre_place(&q, 0.15, &o, 7.0, &s, &err) != CF_OK)
        fail_msg("%s", err.msg);
    char sp[256];
    printf("f family (one spring carries %.4g MPa): %d x %s, buildable %d\n", A_max, s.count,
           cf_spring_text(&s.spring, 4, 0, sp, sizeof sp), s.buildable);
    assert_true(s.buildable && s.violated == 0);
    assert_true(s.count >= (int)ceil(q.scale / A_max) && s.count <= CF_FIBRE_COUNT_MAX);
    assert_close(s.spring.H_mm, 7.0, 1e-12);
    assert_true(s.spring.D1_mm / s.spring.d_mm >= 3 * (1 - 1e-9) && s.spring.n >= 2);
    assert_true(s.spring.H_mm - s.spring.n * s.spring.d_mm > 0.15 * s.spring.H_mm);
    const cf_ident got = cf_ident_of_type(&s.spring, s.type, 0);
    assert_close(got.rho, q.rho, 1e-9 * q.rho);
    assert_close(got.solid, q.solid, 1e-9 * q.solid);
    assert_close(s.count * got.scale, q.scale, 1e-9 * q.scale);
    const cf_ident bad = {.rho = 0.01, .solid = 0.16, .scale = 1e-3};
    assert_int_equal(cf_fibre_place(&bad, 0.15, &o, 0, &s, &err), CF_OK);
    assert_false(s.buildable);
    assert_true(s.violated & CF_C_RHO_MIN);
    const cf_ident none = {.rho = 0.5, .solid = 1.5, .scale = 1e-3};
    assert_int_equal(cf_fibre_place(&none, 0.15, &o, 0, &s, &err), CF_E_DATA);
    printf("refused: %s\n", err.msg);
}

/* Loads the shared set; 0 when it is absent. */
static int load_set(cf_table tab[8], const cf_table *t[8])
{
    const char *d = tu_datasets();
    if (!d)
        return 0;
    const char *names[8] = {"biaxial_1to1", "biaxial_1to075", "biaxial_075to1", "biaxial_1to05",
                            "biaxial_05to1", "shear_fs", "shear_sf", "shear_nf"};
    cf_measure_options o = cf_measure_default_options();
    o.plane = "heart_myocardium_shear_fs=fs,heart_myocardium_shear_sf=sf,"
              "heart_myocardium_shear_nf=nf";
    for (int k = 0; k < 8; k++) {
        char p[256];
        cf_error err = {0};
        snprintf(p, sizeof p, "%s/heart_myocardium_%s.csv", d, names[k]);
        if (cf_measure_load(p, &o, &tab[k], &err) != CF_OK)
            fail_msg("%s", err.msg);
        t[k] = &tab[k];
    }
    return 1;
}

static void print_fit(const char *what, const cf_fibre_fit *f, double cpu)
{
    printf("%s: objective %.4f (%.1f s CPU, %d starts), matrix rho %.4g s/H %.4g F_C/H^2 %.4g kPa, "
           "kappa %.4g kPa, stable %d (min stiffness %.3g kPa)\n", what, f->objective, cpu,
           f->starts, f->matrix.rho, f->matrix.solid, 1e3 * f->matrix.scale, 1e3 * f->kappa_MPa,
           f->stable, 1e3 * f->min_stiffness_MPa);
    for (int g = 0; g < f->ngroups; g++)
        printf("  group %c: rho %.4g s/H %.4g F_C/H^2 %.4g kPa, recruited at strain %.4g\n",
               f->groups[g], f->fibre[g].rho, f->fibre[g].solid, 1e3 * f->fibre[g].scale,
               f->slack[g]);
    printf("  terms:");
    for (size_t k = 0; k < f->ntables; k++)
        printf(" %.3f", f->term[k]);
    printf("\n");
}

static void myocardium_set_at_or_below_holzapfel_ogden(void **state)
{
    (void)state;
    /* the recovery above runs the same fit's code under the sanitizers; this fit of the eight
    ** tables takes over a minute of CPU unsanitised and several times that there */
    TU_SKIP_SANITIZED("the myocardium fit");
    cf_table tab[8];
    const cf_table *t[8];
    if (!load_set(tab, t)) {
        printf("skipped: ../shared/datasets is absent\n");
        skip();
    }
    /* Holzapfel-Ogden full fitted with the same weights for either biaxial cross-fibre axis (the
    ** better of the two, s, is the one to meet); the lattice's fibre, sheet and sheet-normal
    ** groups with the cross-fibre direction along s */
    cf_ho_fit ti, ho[2];
    const char cross[2] = {'n', 's'};
    for (int c = 0; c < 2; c++) {
        assert_int_equal(cf_ho_fit_joint(t, 8, CF_HO_TI, cross[c], NULL, &ti, NULL), CF_OK);
        assert_int_equal(cf_ho_fit_joint(t, 8, CF_HO_FULL, cross[c], &ti, &ho[c], NULL), CF_OK);
        printf("Holzapfel-Ogden full (cross-fibre %c): %.4f\n", cross[c], ho[c].objective);
    }
    cf_fibre_fit f;
    cf_error err = {0};
    const clock_t c0 = clock();
    if (cf_fibre_fit_joint(t, 8, "fsn", 's', &f, &err) != CF_OK)
        fail_msg("%s", err.msg);
    print_fit("fsn, cross-fibre s", &f, (double)(clock() - c0) / CLOCKS_PER_SEC);
    printf("  family weights edge %.4g face %.4g body %.4g\n", f.family[0], f.family[1],
           f.family[2]);
    /* taut groups and equal weights reached 0.4562 (HO 0.3718); recruited 0.4112 */
    assert_true(f.objective <= fmin(ho[0].objective, ho[1].objective));
    /* kappa within Poisson's ratio 0.499 of the matrix lattice (unbounded, the recruited fit ran
    ** it to the 1e6 MPa a lattice takes, 1e8 times the springs' stiffness) */
    const double E = cf_cubic_moduli_of(f.family).E;
    const double w[3] = {f.family[0] / E, f.family[1] / E, f.family[2] / E};
    const cf_spring pm = cf_ident_member(&f.matrix);
    cf_law lm;
    assert_int_equal(cf_law_init(&lm, &pm, NULL), CF_OK);
    const double kmax = cf_cubic_kappa_of_nu(w, lm.k0_N_per_mm / lm.p.H_mm, CF_JOINT_NU_MAX);
    cf_law_free(&lm);
    assert_true(f.kappa_MPa > 0 && f.kappa_MPa <= kmax * (1 + 1e-9));
    assert_true(f.stable && f.min_stiffness_MPa > 0);
    assert_placed(&f);
    for (int k = 0; k < 8; k++)
        cf_table_free(&tab[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stiff_family_is_shared_and_bad_family_flagged),
        cmocka_unit_test(known_lattice_is_recovered),
        cmocka_unit_test(myocardium_set_at_or_below_holzapfel_ogden),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
