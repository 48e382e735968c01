/*
** A tissue body with the double-acting element (the law's extension spring) and the volume term:
** the brain cortex's joint fit with its pair (tests/unit/data/brain_cortex_pair.json, made once by
** `conifit fit --joint --law double-acting` of ../shared/datasets/brain_cortex_{tension,
** compression,shear}.csv; its telescoping fit, better by AIC, is a tailed compression spring
** with a conical extension spring, its lattice stable to 1.05 times each table's range) on the
** block of 6 x 6 x 3 cells over 30 x 30 x 15 mm, nu 0.45, held at its bottom, pressed by a flat
** punch of radius 5 mm to 1 mm (6.7 % of its height, within the compression table's 10 %) in
** four steps:
**  - every step converges to a stable equilibrium (no negative eigenvalue of the tangent: the
**    augmented form's count less its pressure unknowns), no tetrahedron inverted, no spring solid,
**    the force increasing;
**  - springs are stretched there, so the extension spring carries them: the forces differ from the
**    compression spring alone (the odd law) by more than 1 %;
**  - a pair of two equal springs gives the odd law's forces bit for bit (the extension's branch
**    is the mirrored law).
*/
#include "testutil.h"

#include <math.h>

#include "bodyutil.h"
#include "io/fitfile.h"
#include "model/body.h"

#define FIT "tests/unit/data/brain_cortex_pair.json"
#define STEPS 4

/* The punch's forces at each step (STEPS) on the block with law; asserts each step stable and
** admissible; *stretched the springs in tension at the last step. */
static void probe_block(const cf_law *law, double *force, size_t *stretched)
{
    cf_mesh m;
    cf_error err = {0};
    make_block(&m);
    cf_body b;
    const double kappa = cf_body_kappa_for_nu(cf_body_mu_of_law(law), 0.45);
    if (cf_body_create(&b, &m, law, CF_LAW_CLOSED, kappa, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_mesh_free(&m);
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] <= 0)
            b.fix[i] = CF_BODY_FIX_ALL;
    const cf_probe pr = {CF_PROBE_PUNCH, 5, {15, 15, 15.001}, {0, 0, -1}, 1.001, STEPS, 0};
    for (int k = 1; k <= STEPS; k++) {
        cf_body_step st = {0};
        const double depth = pr.depth_mm * k / STEPS;
        if (cf_body_solve(&b, &pr, depth, 0, &st, &err) != CF_OK)
            fail_msg("depth %g mm: %s", depth, err.msg);
        assert_true(st.contacts > 0);
        assert_int_equal(st.neg_pivots, 0);
        assert_true(st.min_J > 0);
        assert_true(st.max_u_over_travel < 1);
        force[k - 1] = st.force_N;
        assert_true(k == 1 || force[k - 1] > force[k - 2]);
    }
    cf_body_state s = {malloc(b.ns * sizeof *s.strain), malloc(b.ns), malloc(b.nt * sizeof *s.J)};
    assert_non_null(s.strain);
    assert_non_null(s.solid);
    assert_non_null(s.J);
    cf_body_measure(&b, &s, NULL);
    *stretched = 0;
    for (size_t q = 0; q < b.ns; q++)
        *stretched += s.strain[q] > 1e-4;
    free(s.strain);
    free(s.solid);
    free(s.J);
    cf_body_free(&b);
}

static void the_cortex_pair_probes_a_block_stably(void **state)
{
    (void)state;
    if (access(FIT, R_OK) != 0)
        fail_msg("%s missing", FIT);
    cf_fitted_spring fs;
    cf_error err = {0};
    if (cf_fitfile_load_element(FIT, "telescoping", &fs, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(fs.has_extension);
    cf_law lc, le, odd;
    assert_int_equal(cf_law_init(&lc, &fs.params, NULL), CF_OK);
    assert_int_equal(cf_law_init(&le, &fs.extension, NULL), CF_OK);
    assert_int_equal(cf_law_init(&odd, &fs.params, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&lc, &le, NULL), CF_OK);
    double fp[STEPS], fo[STEPS];
    size_t sp, so;
    probe_block(&lc, fp, &sp);
    probe_block(&odd, fo, &so);
    for (int k = 0; k < STEPS; k++)
        print_message("depth %.4g mm: pair %.6g N, compression spring alone %.6g N (%+.2f %%)\n",
                      1.001 * (k + 1) / STEPS, fp[k], fo[k], 100 * (fp[k] / fo[k] - 1));
    print_message("springs stretched at the last step: %zu (pair), %zu (odd law)\n", sp, so);
    assert_true(sp > 0);
    assert_true(fabs(fp[STEPS - 1] / fo[STEPS - 1] - 1) > 0.01);
    cf_law_free(&lc);
    cf_law_free(&le);
    cf_law_free(&odd);
}

static void a_pair_of_equal_springs_is_the_odd_law(void **state)
{
    (void)state;
    cf_spring p = {0};
    cf_spring_set(&p, CF_P_D1, 10);
    cf_spring_set(&p, CF_P_D2, 30);
    cf_spring_set(&p, CF_P_N, 4);
    cf_spring_set(&p, CF_P_D, 1);
    cf_spring_set(&p, CF_P_G, 80000);
    cf_spring_set(&p, CF_P_H, 40);
    cf_law a, e, odd;
    assert_int_equal(cf_law_init(&a, &p, NULL), CF_OK);
    assert_int_equal(cf_law_init(&e, &p, NULL), CF_OK);
    assert_int_equal(cf_law_init(&odd, &p, NULL), CF_OK);
    assert_int_equal(cf_law_pair(&a, &e, NULL), CF_OK);
    double fp[STEPS], fo[STEPS];
    size_t sp, so;
    probe_block(&a, fp, &sp);
    probe_block(&odd, fo, &so);
    assert_memory_equal(fp, fo, sizeof fp);
    assert_int_equal(sp, so);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_cortex_pair_probes_a_block_stably),
        cmocka_unit_test(a_pair_of_equal_springs_is_the_odd_law),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
