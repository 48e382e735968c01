/*
** The prediction of a saved fibre-lattice fit and its Holzapfel-Ogden baselines at tables they
** were not fitted to (pipeline/predict_fibre.c, conifit predict): a fit file written here holds
** "fibre_lattice" and "holzapfel_ogden" entries (the quantities of the myocardium fit recorded in
** src/notes/lattice-fit.md, cross-fibre n; with an extra field, as later fit files may carry);
** predicted at the shared myocardium tables shear nf and biaxial 1:0.5 and a uniaxial table:
**  - shear nf against an independent computation: the isotropic cell of the matrix spring
**    alone (the old solver, no fibres) plus the n group's closed form, density Hf T(lambda)
**    gamma / lambda / H^3 with lambda = sqrt(1 + gamma^2), T at Hf (lambda - 1 - 0.02) (the
**    group recruited at strain 0.02, zero below; the matrix's family weights 1, 0.5, 0.25) (the f and s groups are not stretched
**    in nf), and Holzapfel-Ogden's closed form a gamma e^(b gamma^2) (I4f = I4s = 1, I8fs = 0);
**    RMSE to 1e-9 relative, the term (RMSE / RMS)^2 from the table's own RMS stress;
**  - the biaxial table is in the fibre frame, the uniaxial one is not (left out, no failure);
**  - a fibre spring solid inside a table's range leaves that table out of the lattice's figures,
**    naming the first row without a cell state, never a failure;
**  - a missing quantity is refused naming its key.
** Skipped when ../shared/datasets is absent. About 0.05 s of CPU.
*/
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "conifit/law.h"
#include "io/measure.h"
#include "model/calibration.h"
#include "model/cell.h"
#include "model/family.h"
#include "pipeline/predict_fibre.h"

TU_SCRATCH_GROUP("predict-fibre")

/* The fit file's fibre-frame objects (kPa), cross-fibre n; "extra" stands for fields this
** reader does not know. */
static const char fit_json[] =
    "{\"joint\": true,\n"
    " \"fibre_lattice\": [{\"model\": \"fibre-lattice\", \"cross_axis\": \"n\",\n"
    "   \"matrix\": {\"rho\": 0.631, \"solid_strain\": 0.482, \"stress_scale_kPa\": 2.70},\n"
    "   \"fibre_groups\": [\n"
    "     {\"axis\": \"f\", \"rho\": 0.0624, \"solid_strain\": 0.161, \"stress_scale_kPa\": 3591,"
    "      \"extra\": {\"placed\": false}},\n"
    "     {\"axis\": \"s\", \"rho\": 0.105, \"solid_strain\": 0.184, \"stress_scale_kPa\": 967},\n"
    "     {\"axis\": \"n\", \"rho\": 0.0702, \"solid_strain\": 0.181, \"stress_scale_kPa\": 1928,"
    "      \"recruitment_strain\": 0.02}],\n"
    "   \"family_weights\": [1, 0.5, 0.25],\n"
    "   \"volume_modulus_kPa\": 0.61, \"objective\": 0.469, \"stable\": true}],\n"
    " \"holzapfel_ogden\": [{\"model\": \"holzapfel-ogden\", \"cross_axis\": \"n\",\n"
    "   \"parameters_a_kPa_b_dimensionless\": {\"a\": 2.782, \"b\": 2.23, \"a_f\": 1.444,"
    "    \"b_f\": 38.8, \"a_s\": 0.0069, \"b_s\": 104, \"a_fs\": 1e-6, \"b_fs\": 1},\n"
    "   \"objective\": 0.7063}]}\n";

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* The independent shear (nf) stress of the lattice at gamma, MPa. */
static double lattice_nf(const cf_cell *matrix, const cf_law *ngroup, double g)
{
    double tau = 0;
    assert_int_equal(cf_cell_curve(matrix, CF_MODE_SHEAR, &g, 1, &tau, NULL), CF_OK);
    const double lam = sqrt(1 + g * g), H = ngroup->p.H_mm;
    const double u = H * (lam - 1 - 0.02); /* the n group recruited at strain 0.02 */
    const double T = u > 0 ? cf_law_force(ngroup, CF_LAW_CLOSED, u, NULL, NULL) : 0;
    return tau + H * T * g / lam / (H * H * H);
}

static void check_nf(const cf_pf_result *r, const cf_table *t)
{
    /* the matrix alone, the file's family weights scaled as the fibre fit's (modulus k0/H) */
    const cf_ident qm = {.rho = 0.631, .solid = 0.482, .scale = 2.70e-3};
    const cf_ident qn = {.rho = 0.0702, .solid = 0.181, .scale = 1.928};
    const cf_spring pm = cf_ident_member(&qm), pn = cf_ident_member(&qn);
    cf_law lm, ln;
    assert_int_equal(cf_law_init(&lm, &pm, NULL), CF_OK);
    assert_int_equal(cf_law_init(&ln, &pn, NULL), CF_OK);
    const double u[3] = {1, 0.5, 0.25};
    const double E = cf_cubic_moduli_of(u).E;
    const double w[3] = {1 / E, 0.5 / E, 0.25 / E};
    cf_cell c;
    assert_int_equal(cf_cell_init(&c, &lm, CF_LAW_CLOSED, w, NULL), CF_OK);
    double ss = 0, sh = 0, sy = 0;
    for (size_t i = 0; i < t->count; i++) {
        const double g = t->x[i];
        const double dl = lattice_nf(&c, &ln, g) - t->y[i];
        const double dh = 2.782e-3 * g * exp(2.23 * g * g) - t->y[i];
        ss += dl * dl, sh += dh * dh, sy += t->y[i] * t->y[i];
    }
    const double n = (double)t->count;
    const double rl = sqrt(ss / n), rh = sqrt(sh / n), rms = sqrt(sy / n);
    assert_close(r->m[0].rmse_MPa[0], rl, 1e-9 * rl);
    assert_close(r->m[0].term[0], (rl / rms) * (rl / rms), 1e-9 * (rl / rms) * (rl / rms));
    assert_close(r->m[1].rmse_MPa[0], rh, 1e-9 * rh);
    assert_close(r->m[1].term[0], (rh / rms) * (rh / rms), 1e-9 * (rh / rms) * (rh / rms));
    assert_close(r->rms_MPa[0], rms, 1e-12 * rms);
    /* the notes' per-table term of Holzapfel-Ogden (quantities rounded there): nf 0.085; the
    ** lattice's recorded 0.009 was of taut groups, which the recruitment strain here changes */
    assert_close(r->m[1].term[0], 0.085, 0.001);
    printf("nf: fibre lattice RMSE %.4f kPa (term %.4f), HO %.4f kPa (term %.4f)\n", rl * 1e3,
           r->m[0].term[0], rh * 1e3, r->m[1].term[0]);
    cf_law_free(&lm);
    cf_law_free(&ln);
}

static void predicts_held_out_shared_tables(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d) {
        printf("skipped: ../shared/datasets is absent\n");
        skip();
    }
    char fit[sizeof dir + 16];
    snprintf(fit, sizeof fit, "%s/fit.json", dir);
    write_file(fit, fit_json);
    const char *names[3] = {"heart_myocardium_shear_nf", "heart_myocardium_biaxial_1to05",
                            "brain_cortex_tension"};
    cf_measure_options o = cf_measure_default_options();
    o.plane = "heart_myocardium_shear_nf=nf";
    cf_table tab[3];
    const cf_table *t[3];
    for (int k = 0; k < 3; k++) {
        char p[256];
        cf_error err = {0};
        snprintf(p, sizeof p, "%s/%s.csv", d, names[k]);
        if (cf_measure_load(p, &o, &tab[k], &err) != CF_OK)
            fail_msg("%s", err.msg);
        t[k] = &tab[k];
    }
    cf_pf_result r;
    cf_error err = {0};
    if (cf_pf_predict(fit, t, 3, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(r.n, 2);
    assert_int_equal(r.m[0].kind, CF_PF_LATTICE);
    assert_int_equal(r.m[1].kind, CF_PF_HO);
    assert_string_equal(r.m[0].lattice.groups, "fsn");
    assert_true(r.ok[0] && r.ok[1] && !r.ok[2]);
    check_nf(&r, t[0]);
    for (int j = 0; j < 2; j++) {
        assert_true(r.m[j].term[1] > 0 && isfinite(r.m[j].term[1]));
        assert_int_equal(r.m[j].term[2], 0);
        assert_close(r.m[j].sum_terms, r.m[j].term[0] + r.m[j].term[1], 1e-15);
    }
    assert_int_equal(r.m[0].failed_row[0] + r.m[0].failed_row[1], 0);
    cf_pf_free(&r);
    /* a fibre spring solid at 2 % stretch: the cell finds no state past it, and the table is
    ** left out of that model's figures with the row named, never a failure */
    char solid[sizeof fit_json];
    snprintf(solid, sizeof solid, "%s", fit_json);
    memcpy(strstr(solid, "\"solid_strain\": 0.161"), "\"solid_strain\": 0.020", 21);
    write_file(fit, solid);
    if (cf_pf_predict(fit, t, 3, &r, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(r.m[0].failed_row[1] > 1 && r.m[0].failed_row[1] <= t[1]->count);
    assert_int_equal(r.m[0].term[1], 0);
    assert_true(r.m[1].term[1] > 0);
    cf_pf_free(&r);
    /* a quantity missing: refused, naming its key */
    char bad[sizeof fit_json];
    snprintf(bad, sizeof bad, "%s", fit_json);
    char *k = strstr(bad, "\"volume_modulus_kPa\"");
    memcpy(k, "\"volume_modulus_kPb\"", 20);
    write_file(fit, bad);
    assert_int_equal(cf_pf_predict(fit, t, 3, &r, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "fibre_lattice[0].volume_modulus_kPa: missing"));
    cf_pf_free(&r);
    /* a negative family weight: refused, naming the key */
    snprintf(bad, sizeof bad, "%s", fit_json);
    k = strstr(bad, "[1, 0.5, 0.25]");
    memcpy(k, "[1, -0.5, 0.2]", 14);
    write_file(fit, bad);
    assert_int_equal(cf_pf_predict(fit, t, 3, &r, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "fibre_lattice[0].family_weights"));
    cf_pf_free(&r);
    for (int j = 0; j < 3; j++)
        cf_table_free(&tab[j]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(predicts_held_out_shared_tables)};
    return cmocka_run_group_tests(tests, setup, teardown);
}
