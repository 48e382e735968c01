/*
** The `simulate` subcommand: runs a scene (scene.h) on the mass-spring lattice, writes the curve
** as CSV, prints a summary (loop energy, residual strain and the recovery test from hysteresis.h,
** creep or relaxation end values) and optionally plots it with gnuplot.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "cli/cli_body.h"
#include "cli/cli_probe.h"
#include "io/budget.h"
#include "check/hysteresis.h"
#include "model/msm.h"
#include "io/scene.h"
#include "pipeline/simulate.h"
#include "report/plot.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

static const char simulate_help[] =
    "usage: conifit simulate SCENE.json -o OUT.csv [--plot OUT.png|.svg|.pdf] [-q]\n"
    "       conifit simulate BODY-SCENE.json -o PROBE.csv [--vtu DIR] [--plot PNG] [-q]\n"
    "       conifit simulate BODY-SCENE.json --haptic -o FORCES.csv [--plot PNG] [-q]\n"
    "Runs the scene on a mass-spring lattice of conical springs and writes the CSV\n"
    "time_s,strain,stress_kPa,kinetic_energy_mJ,spring_stress_kPa,stable,lateral_stretch\n"
    "(compression positive: strain is the top face's shortening over the height, stress the top\n"
    "reaction over nx ny H^2, in kPa; spring_stress_kPa is one spring's F(strain H)/H^2 at the same\n"
    "strain, for comparison; stable is 1 up to the first sample whose tangent has a negative pivot\n"
    "and 0 from there on, -1 in explicit dynamics, which factors no tangent; lateral_stretch the\n"
    "lattice's width along x over its rest width, so that (1 - lateral_stretch)/strain is its\n"
    "Poisson's ratio under a uniaxial load).\n"
    "A scene with no inertia, damping or viscosity is solved as static equilibria.\n\n"
    "  -o, --output FILE   CSV to write (written to a temporary name, then renamed); '-'\n"
    "                      writes it to standard output and the summary to stderr\n"
    "  --plot FILE.png|.svg|.pdf  also plot the result with gnuplot (a body: the probe's\n"
    "                      force against depth, or against time with --haptic)\n"
    "  --table             write a measurement table instead: time_s,strain,stress_kPa in the\n"
    "                      published tables' sign (tension positive, compression negative),\n"
    "                      '#' lines naming the scene; conifit fit reads it as a time series\n"
    "  --noise REL         with --table: Gaussian noise on the stress, sd = REL x max |stress|\n"
    "  --seed S            seed of the noise (GSL mt19937, default 1)\n"
    "  --max-memory SIZE   refuse a scene estimated to need more memory (bytes, or with a\n"
    "                      K, M or G suffix; default 2G)\n"
    "  --max-steps N       refuse a scene estimated to need more time steps or static\n"
    "                      solves (default 1e7)\n"
    "  --max-work N        refuse a scene whose steps are estimated to cost more work, in\n"
    "                      spring-steps: one spring through one explicit step; a static solve\n"
    "                      or implicit step costs 3e4 on a 3x3x3 lattice, growing as the\n"
    "                      unknowns^1.5 (default 1e10, about 2 to 6 minutes of one core)\n"
    "The estimates are made before anything runs; a refused scene exits 65 naming the key.\n\n"
    "A scene with \"body\": {\"mesh\": FILE, \"unit_mm\": U} (a tetrahedral or hexahedral volume\n"
    "mesh Gmsh reads, or a closed surface .obj/.stl filled with tetrahedra of\n"
    "\"element_size_mm\": H), \"fixed\": {\"below\": {\"axis\", \"value_mm\"}} and \"probe\": {\"shape\":\n"
    "sphere|punch, \"radius_mm\", \"center_mm\", \"direction\", \"depth_mm\", \"steps\"} puts the\n"
    "fitted spring on every edge of the mesh and presses the probe in; it writes the CSV\n"
    "depth_mm,force_N (force along the direction, positive pushing into the body) and prints\n"
    "the body's small-strain E and nu. Regions (each an object or an array of them, with one\n"
    "selector: \"below\"/\"above\" {\"axis\", \"value_mm\"} or {\"normal\", \"point_mm\"},\n"
    "\"box\" {\"min_mm\", \"max_mm\"}, \"sphere\" {\"center_mm\", \"radius_mm\"}, \"group\" NAME|NUMBER\n"
    "or {\"name\"|\"tag\", \"dim\"}, a physical group of the mesh file): \"fixed\" holds them,\n"
    "\"displaced\" moves them by \"by_mm\": [dx, dy, dz] (null: that component free), \"loaded\"\n"
    "spreads \"force_N\": [Fx, Fy, Fz] over them; all ramp with the steps. Without a probe,\n"
    "\"body\": {\"steps\": N} (default 10) and the CSV starts with load_factor; displaced regions\n"
    "add their support force (_Fx_N..), loaded ones their mean displacement (_ux_mm..).\n"
    "\"probe\": {\"force_N\": F} instead of \"depth_mm\" presses the probe to the force F in equal\n"
    "steps of force (the depth of each found by regula falsi); \"path\": {\"t_s\": [...],\n"
    "\"center_mm\": [[x, y, z], ...]} instead of center_mm and depth moves it along a path in\n"
    "time, in steps equal in time (CSV time_s,depth_mm,force_N).\n"
    "A dynamic run of a body: \"effects\": {\"inertia\": true}, \"integrator\": {\"dt_s\": DT},\n"
    "\"density_t_per_mm3\" (default 1e-9) and \"body\": {\"duration_s\": T, \"ramp_s\": TR\n"
    "(default T; 0: at once), \"damping_per_s\": C (default 0), \"newmark_gamma\": G (1/2 to 1,\n"
    "default 1/2: average acceleration; 0.6 damps a probe's rattle on a coarse mesh)}: lumped\n"
    "nodal masses, the probe's depth and the regions' loads ramped over TR then held, implicit\n"
    "Newmark steps of DT to T, a row (CSV time_s first) and a VTU pair per step.\n"
    "  --vtu DIR           with a body: also write DIR/body_NNNN.vtu, DIR/springs_NNNN.vtu per\n"
    "                      step and DIR/body.pvd (ParaView: displacement, stress, strain,\n"
    "                      spring, contact and support forces; time the load factor k/n of a\n"
    "                      static run, else the run's time in s)\n"
    "  --haptic            with a body: move the probe along the scene's \"haptic\": {\"path\":\n"
    "                      [[t_ms, depth_mm], ...], \"iterations\": N} (linear between the\n"
    "                      points, from 0 ms), one update of the haptic loop per ms of simulated\n"
    "                      time (at most N chord iterations, default 3); writes\n"
    "                      t_ms,depth_mm,force_N and prints the wall time per update and, at\n"
    "                      the last depth, the static solve's force for comparison\n";

/* The recovery test (hysteresis.h), printed: whether the strain left at zero force recovers. */
static void recovery(FILE *o, const cf_scene *sc, const cf_law *law, const cf_msm_sample *s,
                     size_t n)
{
    cf_hysteresis_recovery r;
    cf_error err = {0};
    if (cf_hysteresis_recovery_test(sc, law, s, n, &r, &err) != CF_OK) {
        fprintf(o, "recovery test not run: %s\n", err.msg);
        return;
    }
    if (!r.ran)
        return;
    fprintf(o, "recovery (one force-driven cycle to the peak stress %.6g kPa, then zero force held "
               "%.6g s): strain at zero force %.6g, after the hold %.6g: %s\n",
            r.peak_MPa * 1e3, r.hold_s, r.zero_strain, r.end_strain,
            r.recovered ? "no permanent set (the springs are elastic; the strain left at zero "
                          "force is viscous and recovers)"
                        : "not recovered within the hold");
}

/* Progress on a terminal: one line, rewritten after every sample. */
static void show_progress(void *ctx, size_t done, size_t total, double t_s)
{
    (void)ctx;
    fprintf(stderr, "\rconifit simulate: sample %zu of %zu (t = %.4g s)", done, total, t_s);
    fflush(stderr);
}

static void summary(FILE *o, const cf_scene *sc, const cf_msm_sample *s, size_t n, const cf_msm_stats *st)
{
    const int timed = sc->effects.inertia || sc->effects.eta_MPa_s > 0 ||
                      sc->effects.maxwell_E_MPa > 0 || sc->effects.prony_count > 0;
    const cf_lattice_config *lc = &sc->cfg.lattice;
    fprintf(o, "spring: %s; lattice %d x %d x %d cells, calibration %s (weights edge %.4g, face "
           "%.4g, body %.4g); solver: %s\n",
           sc->spring_source, lc->nx, lc->ny, lc->nz, cf_calibration_name(lc->calibration),
           lc->weight[CF_FAMILY_EDGE], lc->weight[CF_FAMILY_FACE], lc->weight[CF_FAMILY_BODY],
           !timed ? "static equilibria"
           : sc->effects.inertia ? "explicit symplectic Euler" : "implicit quasi-static steps");
    for (size_t g = 0; g < sc->ngroups; g++) /* the spring groups with a law of their own */
        fprintf(o, "group %s: the %s springs take the law of spring %s\n",
                cf_scene_group_name(sc->groups[g].family), cf_scene_group_name(sc->groups[g].family),
                sc->groups[g].source);
    for (size_t g = 0; g < sc->nfibres; g++) /* the fibre groups, tension only */
        fprintf(o, "fibre group %zu: axis (%.6g, %.6g, %.6g), %.6g springs per cell of spring %s, "
                "in tension only\n",
                g, sc->fibres[g].axis[0], sc->fibres[g].axis[1], sc->fibres[g].axis[2],
                sc->fibres[g].density, sc->fibres[g].source);
    if (sc->has_extension || lc->volume_modulus_MPa > 0)
        fprintf(o, "element: %s; volume term: kappa %.6g MPa\n",
                sc->has_extension ? "double-acting (its own extension spring)"
                                  : "one spring both ways",
                lc->volume_modulus_MPa);
    const double hg = lc->hourglass < 0 ? (lc->volume_modulus_MPa > 0 ? CF_HOURGLASS_DEFAULT : 0)
                                        : lc->hourglass;
    if (hg > 0)
        fprintf(o, "hourglass control: %.6g of the cell's shear stiffness (lattice.hourglass)\n",
                hg);
    if (sc->effects.inertia)
        fprintf(o, "time step: stable %.6g s, smallest used %.6g s, %zu steps, %zu intervals "
               "sub-stepped\n",
               st->dt_stable_s, st->dt_used_min_s, st->steps, st->substepped);
    else
        fprintf(o, "solves: %zu, Newton iterations: %zu, linear solves: %zu\n", st->solves,
               st->newton_iters, st->linear_iters);
    fprintf(o, "largest spring compression: %.4g of travel\n", st->max_u_over_travel);
    size_t lost = cf_hysteresis_first_unstable(s, n);
    if (lost < n)
        fprintf(o, "lattice loses stability at strain %.6g (t = %.6g s): from there on the static "
                "equilibrium is unstable (its tangent has %ld negative pivots; a column of cells "
                "can buckle sideways), rows marked stable = 0\n",
                s[lost].strain, s[lost].t_s, s[lost].neg_pivots);
    else if (!sc->effects.inertia)
        fprintf(o, "lattice stable at every sample (every factored tangent positive definite)\n");
    if (sc->kind == CF_PROTO_CYCLES) {
        for (int c = 0; c < sc->cycles; c++) {
            const cf_hysteresis_cycle cy = cf_hysteresis_cycle_of(sc, s, n, c);
            fprintf(o, "cycle %d: dissipated energy %.6g kJ/m^3 (= kPa), %s %.6g\n", c + 1,
                    cy.energy_kPa,
                    sc->drive == CF_DRIVE_FORCE ? "strain at zero force after unloading"
                                                : "strain where the unloading stress reaches zero",
                    cy.zero_strain);
        }
    } else if (sc->kind == CF_PROTO_HOLD) {
        size_t r = (n - 1) / 2; /* end of the ramp (two segments of equal sample counts) */
        if (sc->drive == CF_DRIVE_FORCE)
            fprintf(o, "creep: strain %.6g at t = %.6g s (end of ramp), %.6g at t = %.6g s (end)\n",
                   s[r].strain, s[r].t_s, s[n - 1].strain, s[n - 1].t_s);
        else
            fprintf(o, "relaxation: stress %.6g kPa at t = %.6g s (end of ramp), %.6g kPa at "
                   "t = %.6g s (end)\n",
                   s[r].stress_MPa * 1e3, s[r].t_s, s[n - 1].stress_MPa * 1e3, s[n - 1].t_s);
    } else {
        fprintf(o, "end: strain %.6g, stress %.6g kPa\n", s[n - 1].strain, s[n - 1].stress_MPa * 1e3);
    }
}

enum {
    OPT_PLOT = CF_CLI_OPT_OWN,
    OPT_MAX_MEMORY,
    OPT_MAX_STEPS,
    OPT_MAX_WORK,
    OPT_TABLE,
    OPT_NOISE,
    OPT_SEED,
    OPT_VTU,
    OPT_HAPTIC
};

typedef struct sim_opts {
    const char *png;
    cf_budget budget;
    int table;      /* --table */
    double noise;   /* --noise REL */
    long seed;      /* --seed S */
    const char *vtu; /* --vtu DIR */
    int haptic;      /* --haptic */
} sim_opts;

/* simulate's own options: --plot, --table, --noise, --seed and the budget's. */
static int take_option(void *ctx, int c, const char *value)
{
    sim_opts *o = ctx;
    cf_error err = {0};
    if (c == OPT_PLOT) {
        o->png = value;
    } else if (c == OPT_VTU) {
        o->vtu = value;
    } else if (c == OPT_HAPTIC) {
        o->haptic = 1;
    } else if (c == OPT_TABLE) {
        o->table = 1;
    } else if (c == OPT_NOISE) {
        if (cf_cli_parse_double("--noise", value, &o->noise, &err) != CF_OK || !(o->noise >= 0))
            return cf_cli_usage_error("simulate", "--noise '%s': expected a number >= 0", value);
    } else if (c == OPT_SEED) {
        if (cf_cli_parse_long("--seed", value, 0, 2147483647L, &o->seed, &err) != CF_OK)
            return cf_cli_usage_error("simulate", "%s", err.msg);
    } else if (c == OPT_MAX_MEMORY || c == OPT_MAX_STEPS || c == OPT_MAX_WORK) {
        return cf_cli_budget_option("simulate",
                                    c == OPT_MAX_MEMORY  ? "--max-memory"
                                    : c == OPT_MAX_STEPS ? "--max-steps"
                                                         : "--max-work",
                                    value, &o->budget);
    }
    return 0;
}

/* What the command line asked for. */
typedef struct sim_request {
    sim_opts so;
    const char *scene_path, *out;
    int quiet, progress;
} sim_request;

/* Parses the arguments into q. -1 to go on, else an exit status. */
static int parse_request(int argc, char **argv, sim_request *q)
{
    static const struct option own[] = {{"plot", required_argument, NULL, OPT_PLOT},
                                        {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
                                        {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
                                        {"max-work", required_argument, NULL, OPT_MAX_WORK},
                                        {"table", no_argument, NULL, OPT_TABLE},
                                        {"noise", required_argument, NULL, OPT_NOISE},
                                        {"seed", required_argument, NULL, OPT_SEED},
                                        {"vtu", required_argument, NULL, OPT_VTU},
                                        {"haptic", no_argument, NULL, OPT_HAPTIC},
                                        {NULL, 0, NULL, 0}};
    cf_error err = {0};
    q->so = (sim_opts){NULL, cf_budget_default(), 0, 0, 1, NULL, 0};
    cf_cli_parser p;
    int rc = cf_cli_parser_init(&p, "simulate", simulate_help, 0, argc, argv, "", own);
    if (rc || (rc = cf_cli_parse(&p, take_option, &q->so)) >= 0)
        return rc;
    const char *png = q->so.png;
    q->out = p.output;
    q->quiet = p.quiet;
    q->progress = cf_cli_progress(&p);
    if (optind + 1 < argc)
        return cf_cli_usage_error("simulate", "more than one scene ('%s' and '%s')",
                                  argv[optind], argv[optind + 1]);
    if (optind >= argc)
        return cf_cli_usage_error("simulate", "no scene file given");
    q->scene_path = argv[optind];
    if (!q->out)
        return cf_cli_usage_error("simulate", "no output file given (-o OUT.csv, or -o - for "
                                              "standard output)");
    if (png && cf_plot_check_name(png, &err) != CF_OK)
        return cf_cli_usage_error("simulate", "--plot %s: the file must end in .png, .svg or .pdf", png);
    if (png && strcmp(png, q->out) == 0)
        return cf_cli_usage_error("simulate", "-o and --plot both name %s", q->out);
    return -1;
}

/* The lattice of the scene, run along its path into samples (allocated here, sc->nsamples). */
/* --table: a measurement table of the run, tension positive, with the noise asked for. */
static cf_status write_table(FILE *o, const cf_msm_sample *s, size_t n, const sim_opts *so,
                             cf_error *err)
{
    double smax = 0;
    for (size_t k = 0; k < n; k++)
        smax = fmax(smax, fabs(s[k].stress_MPa * 1e3));
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the noise generator");
    gsl_rng_set(rng, (unsigned long)so->seed);
    fprintf(o, "# conifit simulate --table: the lattice of a scene along its protocol\n");
    fprintf(o, "# noise: Gaussian, sd %.17g x max |stress| = %.17g kPa, seed %ld\n", so->noise,
            so->noise * smax, so->seed);
    fprintf(o, "# mode: uniaxial\n# columns: time [s], engineering strain [-], nominal "
               "stress [kPa]; compression negative\n");
    fprintf(o, "time_s,strain,stress_kPa\n");
    for (size_t k = 0; k < n; k++) {
        double y = -s[k].stress_MPa * 1e3;
        if (so->noise > 0 && k > 0)
            y += gsl_ran_gaussian(rng, so->noise * smax);
        fprintf(o, "%.17g,%.17g,%.17g\n", s[k].t_s, -s[k].strain, y);
    }
    gsl_rng_free(rng);
    return CF_OK;
}

/* The run's curve, with one spring's stress at the same strain (spring, MPa) beside it. */
static void write_curve(FILE *o, const cf_scene *sc, const cf_msm_sample *s, const double *spring)
{
    fprintf(o, "time_s,strain,stress_kPa,kinetic_energy_mJ,spring_stress_kPa,stable,"
               "lateral_stretch\n");
    size_t lost = cf_hysteresis_first_unstable(s, sc->nsamples);
    for (size_t k = 0; k < sc->nsamples; k++)
        fprintf(o, "%.17g,%.17g,%.17g,%.17g,%.17g,%d,%.17g\n", s[k].t_s, s[k].strain,
                s[k].stress_MPa * 1e3, s[k].kinetic_mJ, spring[k] * 1e3,
                sc->effects.inertia ? -1 : k < lost, s[k].lateral_stretch);
}

/* The inputs of a run, never to be outputs: the scene and the fit file it names (its name into
** fitfile, sizeof sc->spring_source), NULL-terminated. */
static void scene_inputs(const cf_scene *sc, const char *scene_path, char *fitfile,
                         const char *inputs[3])
{
    snprintf(fitfile, sizeof sc->spring_source, "%s", sc->spring_source);
    char *colon = strrchr(fitfile, ':');
    if (colon && strcmp(sc->spring_source, "params") != 0)
        *colon = '\0';
    inputs[0] = scene_path;
    inputs[1] = strcmp(sc->spring_source, "params") ? fitfile : NULL;
    inputs[2] = NULL;
}

/* Loads the scene, checks both outputs and the budget before the run (which may be long), runs
** it, writes the CSV (and the plot) atomically, and prints the summary. */
int cf_cli_simulate(int argc, char **argv)
{
    sim_request q;
    int rc = parse_request(argc, argv, &q);
    if (rc >= 0)
        return rc;
    const char *png = q.so.png, *out = q.out;
    cf_budget budget = q.so.budget;
    cf_error err = {0};
    cf_scene sc;
    if (cf_scene_load(q.scene_path, &sc, &err) != CF_OK)
        return cf_cli_fail(&err);
    if (sc.has_body || q.so.vtu || q.so.haptic) {
        if (!sc.has_body || q.so.table || (q.so.haptic && q.so.vtu)) {
            cf_scene_free(&sc);
            return cf_cli_usage_error("simulate", "%s",
                                      !sc.has_body ? "--vtu and --haptic need a scene with a body"
                                      : q.so.table ? "--table is for lattice scenes"
                                                   : "--vtu is for the static probe run, not "
                                                     "--haptic");
        }
        rc = q.so.haptic ? cf_cli_simulate_haptic(&sc, q.scene_path, out, png, &budget, q.quiet)
                         : cf_cli_simulate_body(&sc, q.scene_path, out, q.so.vtu, png, &budget,
                                                q.quiet);
        cf_scene_free(&sc);
        return rc;
    }
    char fitfile[sizeof sc.spring_source];
    const char *inputs[3];
    scene_inputs(&sc, q.scene_path, fitfile, inputs);
    if ((!cf_cli_is_stdio(out) && cf_atomic_check(out, inputs, &err) != CF_OK) ||
        (png && cf_atomic_check(png, inputs, &err) != CF_OK)) {
        cf_scene_free(&sc);
        return cf_cli_fail(&err);
    }
    cf_sim_run run;
    cf_cli_out a = {0};
    cf_atomic pa = {0};
    rc = CF_EXIT_OK;
    if (q.progress) {
        sc.cfg.progress = show_progress;
        sc.cfg.progress_ctx = NULL;
    }
    cf_status rs = cf_pipeline_simulate(&sc, q.scene_path, &budget, !q.quiet, &run, &err);
    if (sc.cfg.progress)
        fputs("\r\033[K", stderr); /* clear the progress line */
    if (rs != CF_OK || cf_cli_out_open(&a, out, inputs, &err) != CF_OK) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    const cf_msm_sample *samples = run.samples;
    const double *spring = run.spring_MPa;
    if (q.so.table) {
        if (write_table(a.fp, samples, sc.nsamples, &q.so, &err) != CF_OK) {
            rc = cf_cli_fail(&err);
            goto end;
        }
    } else {
        write_curve(a.fp, &sc, samples, spring);
    }
    /* both outputs exist as temporaries: put them in place together */
    if ((png && cf_plot_simulation(&sc, samples, spring, sc.nsamples, png, inputs, &pa, &err) !=
                    CF_OK) ||
        cf_cli_out_close(&a, &err) != CF_OK || (png && cf_atomic_commit(&pa, &err) != CF_OK)) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    cf_lattice_free(&run.lat); /* the recovery test builds its own */
    if (!q.quiet) {
        summary(a.to_stdout ? stderr : stdout, &sc, samples, sc.nsamples, &run.stats);
        recovery(a.to_stdout ? stderr : stdout, &sc, &run.law, samples, sc.nsamples);
    }
end:
    cf_cli_out_abort(&a);
    cf_atomic_abort(&pa);
    cf_sim_run_free(&run);
    cf_scene_free(&sc);
    return rc;
}
