/*
** Tests of the joint search's guarantees (joint.h; issue 42): its stability check is the
** verification's, with a margin of CF_JOINT_STABLE_MARGIN past each table's farthest strain; a
** fitted kappa stays a material's (small-strain nu at most CF_JOINT_NU_MAX) and a lattice unstable
** at rest is never the better type; nested laws never lose (the pair against the single-sided
** law with the same kappa treatment, the tailed pair against the conical pair); and tables made
** by incompressible Ogden solids in the brain tables' three modes (tension to 10 %, compression to
** -10 %, simple shear to 0.2, 17 rows each, nominal stress) are fitted within a figure set from
** the data.
*/
#include "testutil.h"
#include "jointutil.h"

#include "model/calibration.h"
#include "model/cell.h"
#include "model/cell_stability.h"
#include "model/msm.h"
#include "fit/joint.h"
#include "io/measure.h"
#include "pipeline/pipeline_joint.h"
#include "report/jointreport.h"
#include "check/validate.h"

/* ---- tables of incompressible solids, from their analytic nominal stresses ----
** Ogden (Ogden 1972), W = sum_i (2 mu_i / alpha_i^2) (l1^a + l2^a + l3^a - 3):
**   uniaxial, stretch l:        P = sum_i (2 mu_i / alpha_i) (l^(a - 1) - l^(-a/2 - 1))
**   simple shear of amount g:   P = sum_i (2 mu_i / alpha_i) sinh(a s) / cosh(s),
**                               s = asinh(g/2) (the log of the larger principal stretch)
** Gent (Gent 1996), W = -(mu Jm / 2) ln(1 - (I1 - 3)/Jm), P = 2 W'(I1) (l - l^-2) in uniaxial
** and 2 W'(I1) g in simple shear, W'(I1) = (mu/2) / (1 - (I1 - 3)/Jm). mu is the shear modulus
** at rest in every form (sum mu_i for Ogden). */
typedef struct solid {
    int gent;          /* 0 Ogden of nterm terms, 1 Gent */
    int nterm;
    double mu[2], alpha[2]; /* MPa, - (Gent: mu[0] and Jm = alpha[0]) */
} solid;

static double solid_stress(const solid *s, cf_mode m, double x)
{
    if (s->gent) {
        const double mu = s->mu[0], jm = s->alpha[0];
        const double l = 1 + x;
        const double i1 = m == CF_MODE_SHEAR ? 3 + x * x : l * l + 2 / l;
        const double dw = 0.5 * mu / (1 - (i1 - 3) / jm);
        return m == CF_MODE_SHEAR ? 2 * dw * x : 2 * dw * (l - 1 / (l * l));
    }
    double p = 0;
    for (int i = 0; i < s->nterm; i++) {
        const double a = s->alpha[i], c = 2 * s->mu[i] / a;
        if (m == CF_MODE_SHEAR) {
            const double sh = asinh(0.5 * x);
            p += c * sinh(a * sh) / cosh(sh);
        } else {
            const double l = 1 + x;
            p += c * (pow(l, a - 1) - pow(l, -0.5 * a - 1));
        }
    }
    return p;
}

/* The three tables of solid s as the brain tables have them: 17 rows each from 0, tension to
** 0.1, compression to -0.1 (uniaxial), simple shear to 0.2. */
static void solid_tables(const solid *s, cf_table t[3], const cf_table *tabs[3])
{
    const cf_mode mode[3] = {CF_MODE_UNIAXIAL, CF_MODE_UNIAXIAL, CF_MODE_SHEAR};
    const double end[3] = {0.1, -0.1, 0.2};
    for (int k = 0; k < 3; k++) {
        double x[17], y[17];
        for (int i = 0; i < 17; i++) {
            x[i] = end[k] * i / 16.0;
            y[i] = solid_stress(s, mode[k], x[i]);
        }
        cf_error err = {0};
        assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 17, x, y, NULL, &t[k], &err),
                         CF_OK);
        t[k].mode = mode[k];
        tabs[k] = &t[k];
    }
}

static void assert_nested_never_lose(const cf_joint_report *r);

/* The joint fit conifit fit --joint --law auto --volume fit makes of the tables. */
static void fit_auto_volume(const cf_table *const *tabs, size_t n, cf_joint_report *r)
{
    cf_error err = {0};
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.law = CF_KIND_AUTO;
    po.fit.volume = CF_VOLUME_FIT;
    if (cf_pipeline_fit_joint(tabs, n, &po, r, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

/* The placed law of fit j (a pair through its extension spring, into *ext, which law points to:
** it must outlive law). */
static void law_of(const cf_joint_result *j, cf_law *law, cf_law *ext)
{
    assert_int_equal(cf_law_init(law, &j->fit.params, NULL), CF_OK);
    if (j->pair) {
        assert_int_equal(cf_law_init(ext, &j->ext.params, NULL), CF_OK);
        assert_int_equal(cf_law_pair(law, ext, NULL), CF_OK);
    }
}

/* The check the search applies is the verification's: for the kept fit, table by table and over
** all tables, cf_joint_lattice_stable says what the verification (stable_in_range) says. */
static void assert_check_is_verification(const cf_joint_result *j, const cf_table *const *tabs,
                                         size_t n)
{
    cf_law law, ext;
    law_of(j, &law, &ext);
    cf_validate_setup lat = cf_validate_default();
    int all = 1;
    for (size_t k = 0; k < n; k++) {
        const int one = cf_joint_lattice_stable(&law, j->weight, j->volume_modulus_MPa, &lat,
                                                &tabs[k], 1);
        assert_true(j->tab[k].stability_checked);
        if (one != j->tab[k].stable_in_range)
            fail_msg("table %zu: the check says %d, the verification %d", k, one,
                     j->tab[k].stable_in_range);
        all = all && one;
    }
    assert_int_equal(cf_joint_lattice_stable(&law, j->weight, j->volume_modulus_MPa, &lat, tabs, n),
                     all);
    cf_law_free(&law);
}

/* ---- the stability margin: a lattice that buckles within 1.05x a table's range is rejected ---- */

/* 1 when the 2^3 and 3^3 lattices (sliding bottom) of law with weights w are free of negative
** pivots at the homogeneous uniaxial state of strain e: computed here from the solver directly. */
static int lattices_stable_at(const cf_law *law, const double w[CF_FAMILY_COUNT], double e)
{
    cf_cell cell;
    assert_int_equal(cf_cell_init(&cell, law, CF_LAW_CLOSED, w, NULL), CF_OK);
    cf_cell_state st;
    if (cf_cell_mode(&cell, CF_MODE_UNIAXIAL, e, NULL, &st, NULL) != CF_OK)
        return 0;
    double lambda = 0;
    if (cf_cell_min_stiffness(&cell, st.F, &lambda, NULL) != CF_OK || !(lambda > 0))
        return 0;
    cf_validate_setup lat = cf_validate_default();
    for (int n = 2; n <= 3; n++) {
        cf_msm_config cfg = lat.cfg;
        memcpy(cfg.lattice.weight, w, sizeof cfg.lattice.weight);
        cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = n;
        cfg.lattice.bottom = CF_BOTTOM_AXIAL;
        long neg = -1;
        if (cf_msm_homogeneous_inertia(law, CF_LAW_CLOSED, &cfg, e, st.F[0], &neg, NULL) !=
                CF_OK ||
            neg != 0)
            return 0;
    }
    return 1;
}

/* A pair whose extension spring is a thousandth as stiff as its compression spring (what fits of
** brain ask for) buckles in compression at a few per cent in the full lattice. A compression
** table reaching 1/1.03 of that onset is stable over its own range (every strain checked directly
** in the solver) but not to 1.05x it: the check rejects it; a table reaching 1/1.1 of it passes. */
static void boundary_point_is_rejected(void **state)
{
    (void)state;
    const cf_ident qc = {.rho = 0.4, .solid = 0.5, .scale = 2e-3};
    const cf_ident qe = {.rho = 0.2, .solid = 0.7, .scale = 2e-6};
    const cf_spring pc = cf_ident_member(&qc), pe = cf_ident_member(&qe);
    cf_law law, ext;
    assert_int_equal(cf_law_init(&law, &pc, NULL), CF_OK);
    assert_int_equal(cf_law_init(&ext, &pe, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&law, &ext, NULL), CF_OK);
    double w[CF_FAMILY_COUNT];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    /* the onset in compression, scanned to 1e-4 then bisected */
    double good = 0, bad = 0;
    for (int i = 1; i <= 400 && bad == 0; i++) {
        const double e = -2.5e-4 * i;
        if (lattices_stable_at(&law, w, e))
            good = e;
        else
            bad = e;
    }
    if (bad == 0)
        fail_msg("the soft-extension pair is stable to -0.1: no boundary to test");
    for (int b = 0; b < 30; b++) {
        const double mid = 0.5 * (good + bad);
        if (lattices_stable_at(&law, w, mid))
            good = mid;
        else
            bad = mid;
    }
    const double onset = good;
    cf_validate_setup lat = cf_validate_default();
    for (int c = 0; c < 2; c++) {
        const double reach = onset / (c ? 1.1 : 1.03);
        double x[17], y[17];
        for (int i = 0; i < 17; i++) {
            x[i] = reach * i / 16.0;
            y[i] = x[i] * 1e-3;
            if (c == 0) /* stable over the table's own range, strain by strain */
                assert_true(lattices_stable_at(&law, w, x[i]));
        }
        cf_table t;
        cf_error err = {0};
        assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 17, x, y, NULL, &t, &err),
                         CF_OK);
        t.mode = CF_MODE_UNIAXIAL;
        const cf_table *tabs[1] = {&t};
        const int r = cf_joint_lattice_stable(&law, w, 0.0, &lat, tabs, 1);
        if (r != c)
            fail_msg("onset %.6g, table to %.6g: the check says %d, expected %d", onset, reach, r,
                     c);
        cf_table_free(&t);
    }
    cf_law_free(&law);
}

/* ---- kappa a material property: rubber-like tables (incompressible) drive a free kappa up ---- */

/* A neo-Hookean solid (Ogden alpha 2), 0.5 MPa, in the three modes: the fitted kappa stays at or
** below the one of nu 0.499, the better type's lattice is stable at rest, and the check the
** search applied is the verification's. */
static void kappa_bounded_and_stable_at_rest(void **state)
{
    (void)state;
    const solid s = {.nterm = 1, .mu = {0.5}, .alpha = {2.0}};
    cf_table t[3];
    const cf_table *tabs[3];
    solid_tables(&s, t, tabs);
    cf_joint_report r;
    fit_auto_volume(tabs, 3, &r);
    const int b = cf_joint_better(&r);
    assert_true(b >= 0);
    for (int i = 0; i < r.nfits; i++) {
        const cf_joint_result *j = &r.fits[i];
        if (j->volume == CF_VOLUME_FIT) {
            cf_law law, ext;
            law_of(j, &law, &ext);
            const double k0H = law.k0_N_per_mm / law.p.H_mm;
            const double kmax = cf_cubic_kappa_of_nu(j->weight, k0H, CF_JOINT_NU_MAX);
            if (!(j->volume_modulus_MPa <= kmax * (1 + 1e-6)))
                fail_msg("type %d: kappa %.6g MPa above the nu-0.499 bound %.6g MPa", i,
                         j->volume_modulus_MPa, kmax);
            cf_law_free(&law);
        }
    }
    assert_true(cf_joint_stable_at_rest(&r.fits[b]));
    assert_check_is_verification(&r.fits[b], tabs, 3);
    assert_nested_never_lose(&r);
    cf_joint_report_free(&r);
    for (int k = 0; k < 3; k++)
        cf_table_free(&t[k]);
}

/* The better type: a lattice unstable at rest never, even with the lower objective and a
** buildable spring against one that buckles inside a table's range or cannot be built. */
static void unstable_at_rest_is_never_better(void **state)
{
    (void)state;
    for (int other_feasible = 0; other_feasible < 2; other_feasible++) {
        cf_joint_report r;
        memset(&r, 0, sizeof r);
        r.nfits = 2;
        for (int i = 0; i < 2; i++) {
            cf_joint_result *j = &r.fits[i];
            j->ntables = 1;
            j->tab[0].stability_checked = 1;
            j->tab[0].stable_in_range = 0;
        }
        r.fits[0].fit.feasible = 1; /* unstable at rest, the lower objective */
        r.fits[0].objective = 0.01;
        r.fits[0].tab[0].stable_to = 0;
        r.fits[0].tab[0].unstable_at_rest = 1;
        r.fits[1].fit.feasible = other_feasible; /* buckles at 5 % */
        r.fits[1].objective = 0.1;
        r.fits[1].tab[0].stable_to = 0.05;
        assert_false(cf_joint_stable_at_rest(&r.fits[0]));
        assert_true(cf_joint_stable_at_rest(&r.fits[1]));
        assert_int_equal(cf_joint_better(&r), 1);
    }
}

/* ---- nested laws never lose, and the brain-like Ogden solids ---- */

/* 1 when a ranks at or above b on the tiers before the objective (a buildable spring, then a
** lattice stable over every table's range), so that its objective must not be the larger. */
static int same_or_better_tiers(int fa, int sa, int fb, int sb)
{
    return fa != fb ? fa > fb : sa >= sb;
}

/* In each type's joint fit: the pair (conical compression spring) never above the single-sided
** law with the same kappa treatment, the tailed pair never above the conical pair, whenever it
** ranks no lower on buildability and stability. */
static void assert_nested_never_lose(const cf_joint_report *r)
{
    for (int i = 0; i < r->nfits; i++) {
        const cf_joint_law_choice *lc = &r->law_choice[i];
        if (!lc->pair_ran)
            continue;
        const cf_joint_result *pair = lc->chose_pair ? &r->fits[i] : &lc->pair_other;
        const cf_joint_result *single = lc->chose_pair ? &lc->pair_other : &r->fits[i];
        assert_int_equal(single->volume, pair->volume);
        /* the conical pair: the kept pair, or the alternative the tailed one displaced */
        double cone_obj = pair->objective, tail_obj = NAN;
        int cone_f = pair->fit.feasible, cone_s = cf_joint_stable(pair), tail_f = 0, tail_s = 0;
        if (lc->pair_tail_ran && lc->pair_tail_kept) {
            tail_obj = pair->objective, tail_f = pair->fit.feasible, tail_s = cf_joint_stable(pair);
            cone_obj = lc->alt_objective, cone_f = lc->alt_feasible, cone_s = lc->alt_stable;
        } else if (lc->pair_tail_ran) {
            tail_obj = lc->alt_objective, tail_f = lc->alt_feasible, tail_s = lc->alt_stable;
        }
        if (same_or_better_tiers(cone_f, cone_s, single->fit.feasible, cf_joint_stable(single)) &&
            !(cone_obj <= single->objective * (1 + 1e-9)))
            fail_msg("type %d: the pair %.6g above the single-sided law %.6g it contains", i,
                     cone_obj, single->objective);
        if (lc->pair_tail_ran && same_or_better_tiers(tail_f, tail_s, cone_f, cone_s) &&
            !(tail_obj <= cone_obj * (1 + 1e-9)))
            fail_msg("type %d: the tailed pair %.6g above the conical pair %.6g it contains", i,
                     tail_obj, cone_obj);
    }
}

/* One-term Ogden solids of brain's exponents (mu 1 kPa, alpha -25 and -10; the generating law's
** own joint objective is 0): conifit's better type reaches at most OGDEN_BRAIN_MAX (set from the
** data, src/notes/lattice-fit.md: 0.00293 and 0.00146 measured, the bound 1.5x the larger; 0.00572
** and 0.00146 with a wall of 1e30; 0.076 and 0.011 before the projection to stability and the
** last search's rounds),
** buildable, stable at rest and over every table's range with the margin; its check is the
** verification's; nested laws never lose. */
#define OGDEN_BRAIN_MAX 0.0044
static void brain_like_ogden_solids(void **state)
{
    (void)state;
    TU_SKIP_SANITIZED("brain_like_ogden_solids");
    const double alphas[2] = {-25.0, -10.0};
    for (int a = 0; a < 2; a++) {
        const solid s = {.nterm = 1, .mu = {1e-3}, .alpha = {alphas[a]}};
        cf_table t[3];
        const cf_table *tabs[3];
        solid_tables(&s, t, tabs);
        cf_joint_report r;
        fit_auto_volume(tabs, 3, &r);
        const int b = cf_joint_better(&r);
        assert_true(b >= 0);
        const cf_joint_result *j = &r.fits[b];
        print_message("alpha %g: objective %.6g (type %d; %d starts, %d stable ends, %d projected, "
                      "%d restarts)\n", alphas[a], j->objective, b, j->starts, j->stable_ends,
                      j->projected, j->restarts);
        if (!(j->objective <= OGDEN_BRAIN_MAX))
            fail_msg("alpha %g: objective %.6g above %g", alphas[a], j->objective,
                     OGDEN_BRAIN_MAX);
        assert_true(j->fit.feasible && cf_joint_stable(j) && cf_joint_stable_at_rest(j));
        assert_check_is_verification(j, tabs, 3);
        assert_nested_never_lose(&r);
        cf_joint_report_free(&r);
        for (int k = 0; k < 3; k++)
            cf_table_free(&t[k]);
    }
}

/* The brain corona radiata in tension and compression (shared tables), --law auto --volume fit:
** every search's optimum buckles in the lattice, so the search keeps what it finds from stable
** points projected from its unstable ends (a stiffer extension spring, a smaller kappa). Kept:
** at most CORONA_MAX (0.002586 measured with the wall mirrored above the best stable point;
** 0.003448 with a wall of 1e30 asking for buildable springs too; 0.003686 with stability alone,
** 0.007818 before the projection, src/notes/lattice-fit.md),
** buildable, stable over every table's range with the margin, the check the verification's; the
** projection found stable points in some search; nested laws never lose. */
#define CORONA_MAX 0.0027
static void coronaradiata_projected_search(void **state)
{
    (void)state;
    cf_table t[2];
    const cf_table *tabs[2];
    static const char *const modes[2] = {"tension", "compression"};
    if (!tu_load_modes("brain_coronaradiata", modes, 2, t, tabs))
        skip();
    cf_joint_report r;
    fit_auto_volume(tabs, 2, &r);
    const int b = cf_joint_better(&r);
    assert_true(b >= 0);
    const cf_joint_result *j = &r.fits[b];
    print_message("corona radiata: objective %.6g (type %d; %d starts, %d stable ends, %d "
                  "projected, %d restarts)\n", j->objective, b, j->starts, j->stable_ends,
                  j->projected, j->restarts);
    if (!(j->objective <= CORONA_MAX))
        fail_msg("objective %.6g above %g", j->objective, CORONA_MAX);
    assert_true(j->pair && j->fit.feasible && j->ext.feasible);
    assert_true(cf_joint_stable(j) && cf_joint_stable_at_rest(j));
    assert_check_is_verification(j, tabs, 2);
    int projected = 0;
    for (int i = 0; i < r.nfits; i++) {
        const cf_joint_law_choice *lc = &r.law_choice[i];
        projected += r.fits[i].projected + lc->pair_other.projected;
    }
    assert_true(projected > 0);
    assert_nested_never_lose(&r);
    cf_joint_report_free(&r);
    for (int k = 0; k < 2; k++)
        cf_table_free(&t[k]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(boundary_point_is_rejected),
        cmocka_unit_test(unstable_at_rest_is_never_better),
        cmocka_unit_test(kappa_bounded_and_stable_at_rest),
        cmocka_unit_test(brain_like_ogden_solids),
        cmocka_unit_test(coronaradiata_projected_search),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
