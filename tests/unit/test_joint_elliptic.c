/*
** Tests of the better type's choice with strong ellipticity (report/jointreport.c,
** cf_joint_better; fit/joint.c, cf_joint_elliptic): between two buildable lattices stable over
** every range, the one whose cell stays strongly elliptic is kept even at a higher objective
** within CF_JOINT_ELLIPTIC_SLACK (1.1x), not beyond;
** between two that are both elliptic or both not, the lower objective as before; a fit that is
** not buildable or not stable still loses to one that is, elliptic or not.
*/
#include "testutil.h"

#include "fit/joint.h"
#include "report/jointreport.h"

/* A one-table fit: buildable or not, stable or not, elliptic or not, at objective obj. */
static void candidate(cf_joint_result *j, int feasible, int stable, int elliptic, double obj)
{
    memset(j, 0, sizeof *j);
    j->ntables = 1;
    j->fit.feasible = feasible;
    j->objective = obj;
    j->tab[0].stability_checked = 1;
    j->tab[0].stable_in_range = stable;
    j->tab[0].stable_to = stable ? 0.105 : 0.05;
    j->tab[0].elliptic_checked = 1;
    j->tab[0].elliptic_in_range = elliptic;
    j->tab[0].elliptic_to = elliptic ? 0.105 : 0.05;
}

static int better(int f0, int s0, int e0, double o0, int f1, int s1, int e1, double o1)
{
    cf_joint_report r;
    memset(&r, 0, sizeof r);
    r.nfits = 2;
    r.ntables = 1;
    candidate(&r.fits[0], f0, s0, e0, o0);
    candidate(&r.fits[1], f1, s1, e1, o1);
    return cf_joint_better(&r);
}

static void elliptic_kept_between_fits_within_the_targets(void **state)
{
    (void)state;
    cf_joint_result j;
    candidate(&j, 1, 1, 0, 0.01);
    assert_int_equal(cf_joint_elliptic(&j), 0);
    j.tab[0].elliptic_checked = 0; /* not scanned: no verdict against it */
    assert_int_equal(cf_joint_elliptic(&j), 1);
    /* both buildable and stable: the elliptic one at an objective within
    ** CF_JOINT_ELLIPTIC_SLACK of the other's, whichever is lower */
    assert_int_equal(better(1, 1, 0, 0.01, 1, 1, 1, 0.0105), 1);
    assert_int_equal(better(1, 1, 1, 0.0105, 1, 1, 0, 0.01), 0);
    /* further off, the lower objective (the report says where its cell loses ellipticity) */
    assert_int_equal(better(1, 1, 0, 0.01, 1, 1, 1, 0.02), 0);
    assert_int_equal(better(1, 1, 1, 0.02, 1, 1, 0, 0.01), 1);
    /* both elliptic, or both not: the lower objective, as before */
    assert_int_equal(better(1, 1, 1, 0.0105, 1, 1, 1, 0.01), 1);
    assert_int_equal(better(1, 1, 0, 0.01, 1, 1, 0, 0.0105), 0);
    /* buildable and stable come first */
    assert_int_equal(better(1, 1, 0, 0.0105, 0, 1, 1, 0.01), 0);
    assert_int_equal(better(1, 1, 0, 0.0105, 1, 0, 1, 0.01), 0);
    /* neither stable: ellipticity does not decide */
    assert_int_equal(better(1, 0, 0, 0.01, 1, 0, 1, 0.0105), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(elliptic_kept_between_fits_within_the_targets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
