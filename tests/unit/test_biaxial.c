/*
** Biaxial tables at any ratio of strains (model/mode.c's biaxial row, io/measure.c, io/biaxial.c):
**  - the reader stacks both directions of a '# mode: biaxial' table, checks its '# ratio:' row by
**    row and refuses a mismatch, a missing or malformed ratio and a missing second pair of
**    columns with the file, line and column; '# plane:' and the option plane name the plane;
**  - the homogenised cell in the biaxial mode is the full lattice's homogeneous state: the
**    lattice deformed by the cell's F (free stretch solved) has no force on any node off its x
**    and y faces (the z faces traction-free), and its x and y faces carry the cell's nominal
**    stresses (1e-9 relative), with and without the volume term, at ratios 1:0.5 and 0.75:1;
**  - the shared myocardium tables read as their comments say (skipped when ../shared is absent).
*/
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/measure.h"
#include "model/cell.h"
#include "model/lattice.h"
#include "model/mode.h"
#include "model/table.h"

TU_SCRATCH_GROUP("biaxial")

/* Writes text to dir/name and returns the path (static storage, one at a time). */
static const char *write_table(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (tu_write_bytes(path, text, strlen(text)) != 0)
        fail_msg("cannot write %s", path);
    return path;
}

#define HEAD "# mode: biaxial\n# stress: nominal\n"
#define ROWS                                                                                       \
    "0,0,0,0\n0.02,0.01,1,0.4\n0.04,0.02,2.5,1\n0.06,0.03,4.5,1.9\n0.08,0.04,7,3\n"              \
    "0.1,0.05,10,4.4\n"

static void a_biaxial_table_stacks_both_directions(void **state)
{
    (void)state;
    const char *p = write_table("good.csv", HEAD "# ratio: 1:0.5\n"
                                             "strain_f,strain_c,stress_f_kPa,stress_c_kPa\n" ROWS);
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(p, NULL, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(t.mode, CF_MODE_BIAXIAL);
    assert_int_equal(t.count, 12);
    assert_int_equal(t.second, 6);
    assert_true(t.ratio[0] == 1 && t.ratio[1] == 0.5);
    assert_int_equal(t.ratio_line, 3);
    assert_true(t.x[5] == 0.1 && t.x[11] == 0.05);
    assert_close(t.y[5], 0.010, 1e-15);
    assert_close(t.y[11], 0.0044, 1e-15);
    assert_string_equal(t.x_column, "strain_f");
    assert_string_equal(t.x2_column, "strain_c");
    assert_string_equal(t.y2_column, "stress_c_kPa");
    assert_true(cf_table_biaxial_k(&t, 0) == 0.5 && cf_table_biaxial_k(&t, 6) == 2);
    cf_table_free(&t);
}

/* Loads text as a table and expects CF_E_DATA with each of the fragments in its message. */
static void refused(const char *name, const char *text, const char *opt_planes,
                    const char *const *frags, int nfrag)
{
    const char *p = write_table(name, text);
    cf_measure_options o = cf_measure_default_options();
    o.plane = opt_planes;
    cf_table t;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(p, &o, &t, &err), CF_E_DATA);
    for (int k = 0; k < nfrag; k++)
        if (!strstr(err.msg, frags[k]))
            fail_msg("'%s' not in: %s", frags[k], err.msg);
    assert_null(t.x);
}

static void a_mismatch_or_missing_ratio_is_refused_where_it_is(void **state)
{
    (void)state;
    /* line 8 is the row 0.06,0.031: strain_c is the second column */
    const char *m1[] = {"bad.csv:8:2:", "strain_c 0.031", "ratio 1:0.5", "line 3", "0.03"};
    refused("bad.csv", HEAD "# ratio: 1:0.5\nstrain_f,strain_c,stress_f_kPa,stress_c_kPa\n"
            "0,0,0,0\n0.02,0.01,1,0.4\n0.04,0.02,2.5,1\n0.06,0.031,4.5,1.9\n0.08,0.04,7,3\n"
            "0.1,0.05,10,4.4\n", NULL, m1, 5);
    const char *m2[] = {"noratio.csv", "'# ratio: A:B'", "none found"};
    refused("noratio.csv", HEAD "strain_f,strain_c,stress_f_kPa,stress_c_kPa\n" ROWS, NULL, m2,
            3);
    const char *m3[] = {"badratio.csv:3:10:", "two positive numbers"};
    refused("badratio.csv", HEAD "# ratio: 1:-2\nstrain_f,strain_c,stress_f_kPa,stress_c_kPa\n" ROWS,
            NULL, m3, 2);
    const char *m4[] = {"onepair.csv:4:1:", "no second strain column"};
    refused("onepair.csv", HEAD "# ratio: 1:1\nstrain_f,stress_f_kPa\n0,0\n0.01,1\n0.02,2\n"
            "0.03,3\n0.04,4\n0.05,5\n", NULL, m4, 2);
    const char *m5[] = {"expected uniaxial, shear, planar, equibiaxial, confined or biaxial"};
    refused("torsion.csv", "# mode: torsion\nstrain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n"
            "0.4,4\n0.5,5\n", NULL, m5, 1);
}

#define SHEAR "# mode: shear\nstrain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n"

static void planes_come_from_the_comment_or_the_option(void **state)
{
    (void)state;
    cf_table t;
    cf_error err = {0};
    cf_measure_options o = cf_measure_default_options();
    const char *p = write_table("shear_sf.csv", "# plane: sf\n" SHEAR);
    assert_int_equal(cf_measure_load(p, &o, &t, &err), CF_OK);
    assert_string_equal(t.plane, "sf");
    assert_int_equal(t.plane_line, 1);
    cf_table_free(&t);
    o.plane = "other=nf,shear_sf=fs"; /* the option wins, by the table's name */
    assert_int_equal(cf_measure_load(p, &o, &t, &err), CF_OK);
    assert_string_equal(t.plane, "fs");
    cf_table_free(&t);
    p = write_table("plain.csv", SHEAR);
    assert_int_equal(cf_measure_load(p, &o, &t, &err), CF_OK); /* not in the list: none */
    assert_string_equal(t.plane, "");
    cf_table_free(&t);
    o.plane = "fs"; /* one plane for every table: a uniaxial one is left alone */
    p = write_table("uniax.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n");
    assert_int_equal(cf_measure_load(p, &o, &t, &err), CF_OK);
    assert_string_equal(t.plane, "");
    cf_table_free(&t);
    const char *m0[] = {"uniax.csv: plane 'fs' given for a uniaxial table"};
    refused("uniax.csv", "strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            "uniax=fs", m0, 1);
    const char *m1[] = {"ff.csv:1:10:", "comment 'plane: ff'"};
    refused("ff.csv", "# plane: ff\n" SHEAR, NULL, m1, 2);
    const char *m2[] = {"option plane", "'fx'"};
    refused("fx.csv", SHEAR, "fx", m2, 2);
    const char *m3[] = {"uni.csv:1:1:", "uniaxial table"};
    refused("uni.csv", "# plane: fs\nstrain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            NULL, m3, 2);
}

static void place_affine(cf_lattice *lat, const double F[9])
{
    for (size_t p = 0; p < lat->nn; p++) {
        const double X[3] = {lat->X[p], lat->Y[p], lat->Z[p]};
        lat->x[p] = F[0] * X[0] + F[1] * X[1] + F[2] * X[2];
        lat->y[p] = F[3] * X[0] + F[4] * X[1] + F[5] * X[2];
        lat->z[p] = F[6] * X[0] + F[7] * X[1] + F[8] * X[2];
    }
}

/* The lattice of 2 x 3 x 2 cells at the cell's biaxial state: checks node by node. */
static void lattice_at(const cf_law *law, const cf_cell *c, const cf_cell_state *s, double kappa)
{
    cf_lattice_config lc = cf_lattice_default();
    lc.nx = 2, lc.ny = 3, lc.nz = 2;
    lc.volume_modulus_MPa = kappa;
    memcpy(lc.weight, c->weight, sizeof lc.weight);
    cf_lattice lat;
    cf_error err = {0};
    if (cf_lattice_create(&lat, law, CF_LAW_CLOSED, &lc, &err) != CF_OK)
        fail_msg("%s", err.msg);
    place_affine(&lat, s->F);
    cf_lattice_forces(&lat);
    const double H = law->p.H_mm, xmax = lc.nx * H, ymax = lc.ny * H;
    double fx = 0, fy = 0, big = 0;
    for (size_t p = 0; p < lat.nn; p++)
        big = fmax(big, fabs(lat.fx[p]) + fabs(lat.fy[p]) + fabs(lat.fz[p]));
    for (size_t p = 0; p < lat.nn; p++) {
        const int onx = lat.X[p] == 0 || lat.X[p] == xmax, ony = lat.Y[p] == 0 || lat.Y[p] == ymax;
        assert_close(lat.fz[p], 0, 1e-9 * big); /* the z faces traction-free, the inside at rest */
        if (!onx)
            assert_close(lat.fx[p], 0, 1e-9 * big);
        if (!ony)
            assert_close(lat.fy[p], 0, 1e-9 * big);
        if (lat.X[p] == xmax)
            fx -= lat.fx[p]; /* the load the +x face takes */
        if (lat.Y[p] == ymax)
            fy -= lat.fy[p];
    }
    assert_close(fx, s->P_MPa[0][0] * (ymax * lc.nz * H), 1e-9 * fabs(fx));
    assert_close(fy, s->P_MPa[1][1] * (xmax * lc.nz * H), 1e-9 * fabs(fy));
    cf_lattice_free(&lat);
}

static void cell_equals_the_full_lattice_in_biaxial_mode(void **state)
{
    (void)state;
    const cf_spring sp = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &sp, NULL), CF_OK);
    double w[3];
    assert_int_equal(cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL), CF_OK);
    const double ks[2] = {0.5, 1 / 0.75}, es[3] = {-0.05, 0.04, 0.09};
    for (int v = 0; v < 2; v++)
        for (int kk = 0; kk < 2; kk++)
            for (int ie = 0; ie < 3; ie++) {
                cf_cell c;
                assert_int_equal(cf_cell_init(&c, &law, CF_LAW_CLOSED, w, NULL), CF_OK);
                c.volume_modulus_MPa = v ? 0.3 * law.k0_N_per_mm / law.p.H_mm : 0;
                c.biaxial_k = ks[kk];
                cf_cell_state s;
                cf_error err = {0};
                if (cf_cell_mode(&c, CF_MODE_BIAXIAL, es[ie], NULL, &s, &err) != CF_OK)
                    fail_msg("%s", err.msg);
                assert_true(s.F[0] == 1 + es[ie] && s.F[4] == 1 + ks[kk] * es[ie]);
                assert_true(fabs(s.P_MPa[2][2]) <= 1e-12 * fabs(s.P_MPa[0][0]));
                lattice_at(&law, &c, &s, c.volume_modulus_MPa);
                /* the second direction's row: the same state with x and y swapped */
                cf_cell d = c;
                cf_cell_state t;
                d.biaxial_k = 1 / ks[kk];
                assert_int_equal(cf_cell_mode(&d, CF_MODE_BIAXIAL, ks[kk] * es[ie], NULL, &t,
                                              NULL), CF_OK);
                assert_close(t.stress_MPa, s.P_MPa[1][1], 1e-12 * fabs(s.P_MPa[1][1]));
            }
    cf_law_free(&law);
}

static void shared_myocardium_tables_read_as_stated(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        printf("skipped: ../shared/datasets is absent\n");
        skip();
    }
    const char *names[5] = {"1to1", "1to075", "075to1", "1to05", "05to1"};
    const double r[5][2] = {{1, 1}, {1, 0.75}, {0.75, 1}, {1, 0.5}, {0.5, 1}};
    for (int k = 0; k < 5; k++) {
        char p[256];
        snprintf(p, sizeof p, "%s/heart_myocardium_biaxial_%s.csv", d, names[k]);
        cf_table t;
        cf_error err = {0};
        if (cf_measure_load(p, NULL, &t, &err) != CF_OK)
            fail_msg("%s", err.msg);
        assert_int_equal(t.mode, CF_MODE_BIAXIAL);
        assert_int_equal(t.count, 22);
        assert_int_equal(t.second, 11);
        assert_true(t.ratio[0] == r[k][0] && t.ratio[1] == r[k][1]);
        assert_close(fmax(t.x[10], t.x[21]), 0.1, 1e-15);
        assert_string_equal(t.y_unit, "kPa");
        cf_table_free(&t);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_biaxial_table_stacks_both_directions),
        cmocka_unit_test(a_mismatch_or_missing_ratio_is_refused_where_it_is),
        cmocka_unit_test(planes_come_from_the_comment_or_the_option),
        cmocka_unit_test(cell_equals_the_full_lattice_in_biaxial_mode),
        cmocka_unit_test(shared_myocardium_tables_read_as_stated),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
