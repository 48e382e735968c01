/*
** A law kind is a row of the law-kind table plus its evaluators (src/fit/lawkind.h) and its
** mechanics (src/model/lawmech.h). This test defines one the library does not have, a linear
** spring (one quantity, the modulus E of sigma = E epsilon; its spring a cylindrical one, whose law
** is linear up to solid), and has it fitted, compared by AIC, reported, written to a fit file and
** read back (through the registry), simulated in a lattice and in a body, and exported to
** CalculiX and run in ccx, with no code of the library knowing of it.
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>
#include <jansson.h>

#include "fit/baseline.h"
#include "model/family.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "report/report_baselines.h"
#include "fit/lawkind.h"
#include "export/export.h"
#include "io/fitfile.h"
#include "model/body.h"
#include "io/mesh.h"
#include "model/msm.h"
#include "testutil.h"

/* ---- the linear spring as a law kind: its row and its three evaluators ---- */

static double linear_eval(const double *q, int force, double x)
{
    (void)force;
    return q[0] * x;
}

/* Start at the secant slope of the table's largest point; range three decades either side. */
static void linear_range(const cf_table *t, double *start, double *lo, double *hi)
{
    size_t m = 0;
    for (size_t i = 0; i < t->count; i++)
        if (fabs(t->x[i]) > fabs(t->x[m]))
            m = i;
    start[0] = fabs(t->y[m] / t->x[m]);
    lo[0] = 1e-3 * start[0];
    hi[0] = 1e3 * start[0];
}

/* A cylindrical spring (D1 = D2) of free length H, two coils of index 8, that closes at strain
** 0.9: linear until then, its stress scale F_C/H^2 = E s/H, its wire's G from that load. */
#define LINEAR_SOLID 0.9
static cf_spring linear_spring(const double *q, double H)
{
    cf_spring p;
    memset(&p, 0, sizeof p);
    p.H_mm = H;
    p.n = 2.0;
    p.d_mm = (1.0 - LINEAR_SOLID) * H / p.n; /* solid length n d */
    p.D1_mm = p.D2_mm = 8.0 * p.d_mm;
    p.G_MPa = cf_ident_G_of_FC(q[0] * LINEAR_SOLID * H * H, p.n, p.D1_mm, p.d_mm,
                               LINEAR_SOLID * H);
    return p;
}

/* Its member, of free length 1 mm. */
static cf_spring linear_member(const double *q, int force, cf_spring_type type)
{
    (void)force, (void)type;
    return linear_spring(q, 1.0);
}

/* ---- its mechanics: the spring of free length H carries F = E H u, up to 0.9 H each side ---- */

static double linear_force(const double *q, double H, double u, double *k)
{
    if (k)
        *k = q[0] * H;
    return q[0] * H * u;
}

static double linear_travel(const double *q, double H, int side)
{
    (void)q, (void)side;
    return LINEAR_SOLID * H;
}

/* A line needs one row beyond 0 on each side: its end. */
static size_t linear_samples(const double *q, double H, int sign, double U, size_t max, double *u)
{
    (void)q, (void)H, (void)sign;
    if (max < 1)
        return 0;
    u[0] = U;
    return 1;
}

static const cf_law_mech linear_mech = {
    .name = "linear",
    .nq = 1,
    .key = {"modulus_MPa"},
    .force = linear_force,
    .travel = linear_travel,
    .samples = linear_samples,
    .spring = linear_spring,
};

static const cf_law_row linear_row = {
    .name = "linear",
    .title = "linear spring",
    .spring = "the linear spring",
    .nq = 1,
    .q = {{"modulus_MPa", "stiffness_N_per_mm", "modulus E", "stiffness k", "modulus",
           "stiffness", "y", "N/mm", NULL}},
    .eval = linear_eval,
    .range = linear_range,
    .member = linear_member,
    .mech = &linear_mech,
};

static const cf_law_row *const kinds[] = {&cf_law_conical_row, &linear_row};

/* ---- the pipeline with it ---- */

/* The weighted least-squares slope through the origin, the linear kind's optimum. */
static double ls_slope(const cf_table *t)
{
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < t->count; i++) {
        const double w = t->w ? t->w[i] : 1.0;
        sxy += w * t->x[i] * t->y[i];
        sxx += w * t->x[i] * t->x[i];
    }
    return sxy / sxx;
}

static void fit_with_linear(cf_table *t, cf_fit_report *r)
{
    cf_pipeline_options po = cf_pipeline_default_options();
    po.fit.relative = 0;
    po.fit.kinds = kinds;
    po.fit.nkinds = 2;
    po.types = 1u << CF_NON_TELESCOPING;
    po.with_timing = 0;
    cf_error err = {0};
    if (cf_pipeline_fit(t, &po, r, &err) != CF_OK)
        fail_msg("%s", err.msg);
}

/* What every fit with the linear kind shows: both kinds fitted, the linear one at the
** least-squares slope, its AIC with k = 1, and the choice the lower feasible AIC. */
static const cf_fit_result *check_choice(const cf_table *t, const cf_fit_report *r)
{
    const cf_law_choice *lc = &r->law_choice[0];
    assert_true(lc->ran);
    assert_int_equal(lc->n, 2);
    const cf_fit_result *lin = &lc->cand[1];
    assert_ptr_equal(lin->kind, &linear_row);
    assert_close(lin->q[0], ls_slope(t), 1e-5 * fabs(ls_slope(t)));
    assert_true(lin->q_se[0] > 0);
    const double u = t->y_to_file;
    double ymax = 0;
    for (size_t i = 0; i < t->count; i++)
        ymax = fmax(ymax, fabs(t->y[i]));
    assert_close(lc->aic[1], cf_baseline_aic(t->count, lin->rss * u * u, 1, ymax * u), 1e-9);
    assert_close(lc->aic[0],
                 cf_baseline_aic(t->count, lc->cand[0].rss * u * u, 3, ymax * u), 1e-9);
    const int want = lin->feasible && lc->aic[1] < lc->aic[0];
    assert_int_equal(lc->chosen, want);
    return lin;
}

/* On a published stiffening table the conical law wins, and the report and the fit file carry
** the linear kind's quantity under its own key and label. */
static void linear_kind_on_brain_tension(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir)
        skip();
    char path[1024];
    snprintf(path, sizeof path, "%s/brain_cortex_tension.csv", dir);
    cf_measure_options mo = cf_measure_default_options();
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(path, &mo, &t, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_fit_report r;
    fit_with_linear(&t, &r);
    const cf_fit_result *lin = check_choice(&t, &r);
    assert_int_equal(r.law_choice[0].chosen, 0); /* the brain stiffens: a line loses */
    assert_true(lin->rmse > 2 * r.fits[0].rmse);
    assert_true(lin->feasible);
    /* the line through the origin is the linear baseline too: the same AIC, by another path */
    assert_close(r.law_choice[0].aic[1], cf_report_baseline_aic(&r, CF_BASE_LINEAR), 1e-6);

    char *text = cf_report_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "Law kinds compared: the conical law (3 quantities) against "
                                 "the linear spring (1)"));
    assert_non_null(strstr(text, "linear       RMSE"));
    assert_non_null(strstr(text, "kept: conical (the linear spring does not lower the AIC)"));
    free(text);

    char *js = cf_report_json_string(&r);
    assert_non_null(js);
    json_error_t je;
    json_t *root = json_loads(js, 0, &je);
    free(js);
    assert_non_null(root);
    json_t *cmp = json_object_get(json_array_get(json_object_get(root, "fits"), 0),
                                  "law_comparison");
    assert_non_null(cmp);
    assert_string_equal(json_string_value(json_object_get(cmp, "chosen")), "conical");
    json_t *jl = json_object_get(cmp, "linear");
    assert_non_null(jl);
    /* the modulus in the file's own unit: the table's kPa */
    const double E = json_number_value(
        json_object_get(json_object_get(jl, "modulus_MPa"), "value"));
    assert_close(E, lin->q[0], 1e-12 * lin->q[0]);
    assert_close(json_number_value(json_object_get(jl, "aic")), r.law_choice[0].aic[1], 1e-9);
    json_decref(root);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* On a linear table the linear kind is kept: the fit in fits[] is its spring, and the report's
** identifiable rows and the fit file's keys are its own. */
/* A line of 40 points to strain 0.4, 50 kPa with 1 % alternating noise, fitted with the linear
** kind. */
static void fit_line(cf_table *t, cf_fit_report *r)
{
    enum { N = 40 };
    double x[N], y[N];
    for (int i = 0; i < N; i++) {
        x[i] = 0.4 * (i + 1) / N;
        y[i] = 0.05 * x[i] * (1 + 0.01 * (i % 2 ? 1 : -1));
    }
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, N, x, y, NULL, t, &err),
                     CF_OK);
    fit_with_linear(t, r);
}

static void linear_kind_kept_on_a_line(void **state)
{
    (void)state;
    cf_table t;
    cf_fit_report r;
    fit_line(&t, &r);
    check_choice(&t, &r);
    assert_int_equal(r.law_choice[0].chosen, 1);
    const cf_fit_result *f = &r.fits[0];
    assert_ptr_equal(f->kind, &linear_row);
    assert_true(f->feasible);
    assert_close(f->params.D1_mm, f->params.D2_mm, 1e-12); /* its spring is a cylinder */

    char *text = cf_report_text(&r);
    assert_non_null(text);
    assert_non_null(strstr(text, "modulus E"));
    assert_non_null(strstr(text, "kept: linear (lower AIC)"));
    free(text);
    char *js = cf_report_json_string(&r);
    json_error_t je;
    json_t *root = json_loads(js, 0, &je);
    free(js);
    assert_non_null(root);
    json_t *fit = json_array_get(json_object_get(root, "fits"), 0);
    assert_string_equal(json_string_value(json_object_get(fit, "law")), "linear");
    json_t *id = json_object_get(fit, "identifiable");
    assert_int_equal(json_object_size(id), 1);
    assert_close(json_number_value(json_object_get(json_object_get(id, "modulus_MPa"), "value")),
                 f->q[0], 1e-12 * f->q[0]);
    json_decref(root);
    cf_report_free(&r);
    cf_table_free(&t);
}

/* ---- its law everywhere: the fit file, the lattice, the body, CalculiX ---- */

static char dir[64];
static cf_table line_t;
static cf_fit_report line_r;
static int line_done;

/* The fit of the line (fit_line), made once for the tests below; the kind's fit is fits[0]. */
static const cf_fit_report *line_fit(void)
{
    if (!line_done) {
        fit_line(&line_t, &line_r);
        line_done = 1;
    }
    return &line_r;
}

/* The fit of the line written as conifit fit -o writes it (the report's JSON) to dir/name. */
static void write_fit_file(const cf_fit_report *r, const char *name, char *path, size_t cap)
{
    char *js = cf_report_json_string(r);
    assert_non_null(js);
    snprintf(path, cap, "%s/%s", dir, name);
    assert_int_equal(tu_write_bytes(path, js, strlen(js)), 0);
    free(js);
}

/* The fitted law is the kind's own; the fit file names the kind and carries its modulus, and
** reading it back gives the same law, bit for bit; a kind no one registered is refused, naming
** the kind and the file. */
static void linear_kind_written_and_read_back(void **state)
{
    (void)state;
    const cf_fit_report *r = line_fit();
    const cf_fit_result *f = &r->fits[0];
    assert_string_equal(cf_law_kind_of(&f->law), "linear");
    char path[128];
    write_fit_file(r, "line.json", path, sizeof path);
    cf_fitted_spring fs;
    cf_error err = {0};
    if (cf_fitfile_load(path, NULL, &fs, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_ptr_equal(fs.mech, &linear_mech);
    assert_true(fs.q[0] == f->q[0]);
    for (int k = 0; k < CF_P_ALL; k++)
        assert_true(cf_spring_get(&fs.params, k) == cf_spring_get(&f->params, k));
    cf_law law;
    assert_int_equal(cf_fitted_law(&fs, &law, &err), CF_OK);
    assert_string_equal(cf_law_kind_of(&law), "linear");
    for (int i = -4; i <= 4; i++) { /* inside, at and past each side's travel */
        const double u = 0.25 * i * cf_law_travel(&law, i);
        double k1, k2;
        assert_true(cf_law_force(&law, CF_LAW_CLOSED, u, &k1, NULL) ==
                    cf_law_force(&f->law, CF_LAW_CLOSED, u, &k2, NULL));
        assert_true(k1 == k2);
        assert_close(cf_law_force(&law, CF_LAW_EXACT, u, NULL, NULL),
                     f->q[0] * u, 1e-15 * f->q[0]); /* F = E H u, H = 1 mm */
    }
    assert_close(cf_law_travel(&law, -1), 0.9, 1e-15);
    assert_close(cf_law_solid_force(&law, -1), -0.9 * f->q[0], 1e-15 * f->q[0]);
    assert_close(cf_law_deflection(&law, 0.3 * f->q[0]), 0.3, 1e-14);

    /* the same file naming a kind this program does not know */
    char *text = tu_slurp(path);
    assert_non_null(text);
    json_error_t je;
    json_t *root = json_loads(text, 0, &je);
    free(text);
    assert_non_null(root);
    json_object_set_new(json_array_get(json_object_get(root, "fits"), 0), "law",
                        json_string("hookean-unknown"));
    char bad[128];
    snprintf(bad, sizeof bad, "%s/unknown.json", dir);
    assert_int_equal(json_dump_file(root, bad, 0), 0);
    json_decref(root);
    assert_int_equal(cf_fitfile_load(bad, NULL, &fs, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "hookean-unknown"));
    assert_non_null(strstr(err.msg, bad));
    /* a row that takes a library kind's name is refused */
    cf_law_mech impostor = linear_mech;
    impostor.name = "conical";
    assert_int_equal(cf_law_mech_register(&impostor, &err), CF_E_DATA);
    cf_law_free(&law);
}

/* The lattice of the kind's law: its uniaxial stress is the analytic linear lattice's (the
** calibrated network's modulus k0/H = E at small strain), and equals that of the lattice of its
** buildable spring's conical law (a cylinder, linear up to solid: the same line by another
** path) at every strain. */
static void linear_kind_simulated_in_a_lattice(void **state)
{
    (void)state;
    const cf_fit_result *f = &line_fit()->fits[0];
    const double E = f->q[0];
    cf_law cone;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&cone, &f->params, &err), CF_OK);
    assert_string_equal(cf_law_kind_of(&cone), "conical");
    const double strain[] = {-0.3, -0.1, -1e-3, 1e-3, 0.1, 0.3};
    enum { N = sizeof strain / sizeof strain[0] };
    double sk[N], sc[N];
    if (cf_msm_uniaxial(&f->law, CF_LAW_CLOSED, NULL, strain, N, sk, NULL, &err) != CF_OK ||
        cf_msm_uniaxial(&cone, CF_LAW_CLOSED, NULL, strain, N, sc, NULL, &err) != CF_OK)
        fail_msg("%s", err.msg);
    for (int i = 0; i < N; i++) {
        print_message("strain %+.3f: kind %.9g MPa, cylinder %.9g MPa, E eps %.9g MPa\n",
                      strain[i], sk[i], sc[i], E * strain[i]);
        assert_close(sk[i], sc[i], 1e-9 * fabs(sc[i]));
    }
    assert_close(sk[2], E * strain[2], 2e-3 * E * fabs(strain[2]));
    assert_close(sk[3], E * strain[3], 2e-3 * E * fabs(strain[3]));
    cf_law_free(&cone);
}

/* A Gmsh cube of 10 mm (elements of 1 mm, as test_body.c) compressed 1e-4 with lubricated faces: the reaction of the
** body of the kind's law, against the body of its cylinder's conical law and the network's
** reported E. */
static double block_reaction(const cf_law *law, double *E_ratio)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10}, f[3] = {5, 5, 5}, eps = 1e-4, tol = 1e-9;
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, f, 1, 1, 0, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_body b;
    if (cf_body_create(&b, &m, law, CF_LAW_CLOSED,
                       cf_body_kappa_for_nu(cf_body_mu_of_law(law), 0.3), &err) != CF_OK)
        fail_msg("%s", err.msg);
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] |= (X[0] < tol) | (X[1] < tol) << 1 | (X[2] < tol) << 2;
        if (X[2] > 10 - tol) {
            b.fix[i] |= 4;
            b.x[3 * i + 2] = X[2] * (1 - eps);
        }
    }
    cf_probe none = {0};
    none.dir[2] = 1;
    cf_body_step st;
    if (cf_body_solve(&b, &none, 0, 0, &st, &err) != CF_OK)
        fail_msg("%s", err.msg);
    double *gf = malloc(3 * b.nn * sizeof *gf);
    assert_non_null(gf);
    assert_int_equal(cf_body_internal_force(&b, gf, &err), CF_OK);
    double F = 0;
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] > 10 - tol)
            F -= gf[3 * i + 2];
    *E_ratio = F / 100 / eps / b.E_MPa;
    free(gf);
    cf_body_free(&b);
    cf_mesh_free(&m);
    return F;
}

static void linear_kind_simulated_in_a_body(void **state)
{
    (void)state;
    const cf_fit_result *f = &line_fit()->fits[0];
    cf_law cone;
    assert_int_equal(cf_law_init(&cone, &f->params, NULL), CF_OK);
    double ek, ec;
    const double Fk = block_reaction(&f->law, &ek), Fc = block_reaction(&cone, &ec);
    print_message("block: kind %.9g N, cylinder %.9g N; E measured / reported %.4f\n", Fk, Fc,
                  ek);
    assert_true(Fk > 0);
    assert_close(Fk, Fc, 1e-8 * Fc);
    assert_close(ek, 1, 0.05);
    cf_law_free(&cone);
}

/* The summed reactions of set NTOP at whole times 1, 2, ... of a ccx .dat. */
static int ccx_totals(const char *text, double *rz, int cap)
{
    int n = 0;
    const char *key = "total force (fx,fy,fz) for set NTOP and time";
    for (const char *p = text; (p = strstr(p, key)) != NULL; p++) {
        double tm, fx, fy, fz;
        if (sscanf(p + strlen(key), "%lf %lf %lf %lf", &tm, &fx, &fy, &fz) != 4)
            continue;
        const double k = floor(tm + 0.5);
        if (fabs(tm - k) < 1e-9 && k >= 1 && k <= cap) {
            rz[(int)k - 1] = fz;
            n = (int)k > n ? (int)k : n;
        }
    }
    return n;
}

/* The fit file of the kind, read back (fs), and the CalculiX file written from it by write (the
** one-spring example, or the lattice) as dir/job.inp, run in ccx: the file's text (caller
** frees), and ccx's summed top reactions rz[k - 1] at each step k (*n of them). */
static char *ccx_job(const char *job, int lattice, cf_fitted_spring *fs, double *rz, int *n)
{
    char path[128], inp[160];
    write_fit_file(line_fit(), "export.json", path, sizeof path);
    cf_error err = {0};
    if (cf_fitfile_load(path, NULL, fs, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_export_options opt = cf_export_default_options();
    assert_int_equal(cf_export_format_parse("calculix", &opt.format, &err), CF_OK);
    opt.example = !lattice;
    snprintf(inp, sizeof inp, "%s/%s.inp", dir, job);
    FILE *out = fopen(inp, "w");
    assert_non_null(out);
    cf_export_report rep;
    cf_status st;
    if (lattice) {
        cf_law law;
        assert_int_equal(cf_fitted_law(fs, &law, &err), CF_OK);
        cf_export_lattice lx = cf_export_lattice_default(&law);
        lx.nsteps = 4; /* compressive strains inside its stable range (0.35) */
        const double to[4] = {0.05, 0.1, 0.2, 0.3};
        memcpy(lx.strain, to, sizeof to);
        st = cf_export_write_lattice(out, fs, &opt, &lx, &rep, &err);
        cf_law_free(&law);
    } else {
        st = cf_export_write(out, fs, &opt, &rep, &err);
    }
    fclose(out);
    if (st != CF_OK)
        fail_msg("%s", err.msg);
    assert_true(rep.max_err_rel < 1e-12); /* a line's table is exact */
    char cmd[256];
    snprintf(cmd, sizeof cmd, "cd %s && ccx -i %s > %s.log 2>&1", dir, job, job);
    const int rc = system(cmd);
    if (!(WIFEXITED(rc) && WEXITSTATUS(rc) == 0))
        fail_msg("ccx failed on %s (see %s.log)", inp, job);
    char *x = tu_slurp(inp), p[160];
    snprintf(p, sizeof p, "%s/%s.dat", dir, job);
    char *dat = tu_slurp(p);
    assert_non_null(x);
    assert_non_null(dat);
    *n = ccx_totals(dat, rz, 16);
    free(dat);
    return x;
}

/* The next step line of an export's header from *q on: its number, top displacement and conifit's
** reaction; 0 when there is none. */
static int next_step(const char **q, int *k, double *dz, double *ref)
{
    for (; (*q = strstr(*q, "  step ")) != NULL; (*q)++)
        if (sscanf(*q, "  step %d: top z displacement %lf mm (strain %*f), conifit reaction %lf N",
                   k, dz, ref) == 3) {
            (*q)++;
            return 1;
        }
    return 0;
}

static int have_ccx(void)
{
    if (system("command -v ccx >/dev/null 2>&1") == 0)
        return 1;
    print_message("skipped: ccx is not on PATH\n");
    return 0;
}

/* The kind's fit file exported to CalculiX and run in ccx (lattice 0: the one-spring example;
** 1: the lattice, every family a group with the line's table, four steps to compressive strain
** 0.3, inside its stable range 0.35). The example: at every step ccx's reaction is the line's
** tension (its table, three rows, holds the line exactly), to ccx's printed digits. The lattice:
** ccx's top reaction is conifit's own run of the kind's lattice, written in the file's header,
** within the reaction tolerance the header states (the tables' tolerance: 8e-5 N; measured
** differences 0 to 5e-7 N, ccx's equilibrium). */
static void ccx_case(int lattice)
{
    if (!have_ccx())
        skip();
    cf_fitted_spring fs;
    double rz[16], dz, ref, tol = 0;
    int n, k, steps = 0;
    char *x = ccx_job(lattice ? "line_lattice" : "line", lattice, &fs, rz, &n);
    if (lattice) {
        const char *tt = strstr(x, "reaction tolerance implied by the tables: ");
        assert_non_null(tt);
        tol = atof(tt + strlen("reaction tolerance implied by the tables: "));
        assert_true(tol > 0);
    }
    for (const char *q = x; next_step(&q, &k, &dz, &ref);) {
        assert_true(k >= 1 && k <= n);
        const double line = fs.q[0] * fs.params.H_mm * dz; /* the line's tension at dz */
        const double want = lattice ? -ref : line;
        print_message("step %d: dz %.6g mm, ccx %.7g N, %s %.7g N\n", k, dz, rz[k - 1],
                      lattice ? "conifit" : "line", want);
        if (!lattice)
            assert_close(ref, -line, 1e-12 * fabs(line));
        assert_true(fabs(want) > 0);
        assert_close(rz[k - 1], want, tol + 1e-6 * fabs(want));
        steps++;
    }
    assert_true(steps == n && n == (lattice ? 4 : 6));
    free(x);
}

static void linear_kind_exported_to_calculix(void **state)
{
    (void)state;
    ccx_case(0);
}

static void linear_kind_lattice_exported_to_calculix(void **state)
{
    (void)state;
    ccx_case(1);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/conifit-lawkind-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    cf_error err = {0};
    return cf_law_mech_register(&linear_mech, &err) == CF_OK ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    if (line_done) {
        cf_report_free(&line_r);
        cf_table_free(&line_t);
    }
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_kind_on_brain_tension),
        cmocka_unit_test(linear_kind_kept_on_a_line),
        cmocka_unit_test(linear_kind_written_and_read_back),
        cmocka_unit_test(linear_kind_simulated_in_a_lattice),
        cmocka_unit_test(linear_kind_simulated_in_a_body),
        cmocka_unit_test(linear_kind_exported_to_calculix),
        cmocka_unit_test(linear_kind_lattice_exported_to_calculix),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
