/*
** The volume modulus kappa has one bound wherever it enters (model/calibration.h): at most
** CF_KAPPA_MAX_MPA (1e6 MPa) from a scene's 'lattice.volume_modulus_MPa' or
** 'body.volume_modulus_MPa', conifit fit --volume-modulus and the library's lattice; and, where
** a scene declares it, at most CF_KAPPA_MAX_RATIO times the spring's k0/H. Beyond, each is
** refused naming the key (or option) and the value and saying the bound. Earlier the lattice key
** took up to 1e100 and from about 1e14 a run exited 0 with stresses of the wrong sign and a false
** buckling report; --volume-modulus 1e300 said "must be a finite number".
*/
#include "bodyutil.h"
#include "testutil.h"

#include "model/calibration.h"
#include "model/lattice.h"

TU_SCRATCH_GROUP("kappa")

/* The shipped uniaxial scene (spring k0/H = 1.518e-3 MPa) with the lattice's kappa. */
static void lattice_scene(const char *path, const char *kappa)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
               "\"G_MPa\": 26, \"H_mm\": 10}},\n"
               " \"lattice\": {\"nx\": 3, \"ny\": 3, \"nz\": 3, \"calibration\": \"isotropic\", "
               "\"bottom\": \"axial\", \"volume_modulus_MPa\": %s},\n"
               " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.1, \"duration_s\": 1},\n"
               " \"samples_per_segment\": 5}\n",
            kappa);
    fclose(f);
}

static void the_lattice_key_is_bounded(void **state)
{
    (void)state;
    char scene[600], out[8192], err[8192];
    snprintf(scene, sizeof scene, "%s/lattice.json", dir);
    const char *big[] = {"1e14", "1e25", "1e100", "2e6"};
    for (size_t k = 0; k < sizeof big / sizeof big[0]; k++) {
        lattice_scene(scene, big[k]);
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/x.csv", scene,
                                dir),
                         65);
        assert_non_null(strstr(err, "'lattice.volume_modulus_MPa'"));
        assert_non_null(strstr(err, "at most 1e+06 MPa"));
        assert_non_null(strstr(err, "bulk modulus"));
    }
    /* within 1e6 MPa but above 1e6 k0/H of this spring (1518 MPa) */
    lattice_scene(scene, "1e4");
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/x.csv", scene, dir),
                     65);
    assert_non_null(strstr(err, "'lattice.volume_modulus_MPa' = 10000"));
    assert_non_null(strstr(err, "k0/H = 0.00151797 MPa"));
    /* below both: runs */
    lattice_scene(scene, "1000");
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/x.csv -q", scene,
                            dir),
                     0);
}

static void the_body_key_is_bounded_alike(void **state)
{
    (void)state;
    char mesh[600], scene[600], out[8192], err[8192];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    write_block(mesh);
    snprintf(scene, sizeof scene, "%s/body.json", dir);
    const char *kappa[] = {"2e6", "1e12", "1e4"}; /* the spring's k0/H: 6.25e-3 MPa */
    const char *needle[] = {"at most 1e+06 MPa", "at most 1e+06 MPa", "k0/H = 0.00625 MPa"};
    for (int k = 0; k < 3; k++) {
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f,
                "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, "
                "\"volume_modulus_MPa\": %s},\n"
                " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
                " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 5, \"center_mm\": [15, 15, 20], "
                "\"direction\": [0, 0, -1], \"depth_mm\": 0.1, \"steps\": 1}}\n",
                mesh, kappa[k]);
        fclose(f);
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s/b.csv", scene,
                                dir),
                         65);
        assert_non_null(strstr(err, "'body.volume_modulus_MPa'"));
        assert_non_null(strstr(err, needle[k]));
    }
}

static void the_option_says_its_bound(void **state)
{
    (void)state;
    char out[8192], err[8192];
    const char *values[] = {"1e300", "2e9", "-1"}; /* kPa: the table's unit */
    for (int k = 0; k < 3; k++) {
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                                "fit data/telescoping.csv data/telescoping.csv --joint "
                                "--volume-modulus %s -o %s/f.json",
                                values[k], dir),
                         2);
        assert_non_null(strstr(err, "--volume-modulus"));
        assert_non_null(strstr(err, "at most 1e+06 MPa"));
    }
}

static void the_library_lattice_is_bounded_alike(void **state)
{
    (void)state;
    const cf_spring p = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    cf_lattice_config cfg = cf_lattice_default();
    cfg.nx = cfg.ny = cfg.nz = 2;
    cfg.volume_modulus_MPa = 1e14;
    cf_lattice lat;
    cf_error e = {0};
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, &e), CF_E_DATA);
    assert_non_null(strstr(e.msg, "volume_modulus_MPa = 1e+14"));
    assert_non_null(strstr(e.msg, "at most 1e+06 MPa"));
    cfg.volume_modulus_MPa = CF_KAPPA_MAX_MPA;
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, &e), CF_OK);
    cf_lattice_free(&lat);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_lattice_key_is_bounded),
        cmocka_unit_test(the_body_key_is_bounded_alike),
        cmocka_unit_test(the_option_says_its_bound),
        cmocka_unit_test(the_library_lattice_is_bounded_alike),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
