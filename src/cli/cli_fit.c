/*
** `conifit fit`: fit conical springs (both types by default) to one or more measured tables,
** print a readable report, and write one JSON fit file (and optionally a plot) per table.
** Several tables run in parallel with -j N (one thread per table at a time; the fitter keeps no
** global state).
*/
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "conifit/baseline.h"
#include "conifit/pipeline.h"
#include "out/plot.h"

static const char fit_help[] =
    "usage: conifit fit FILE.csv... [-o OUT.json | -o DIR/] [options]\n"
    "Fits the design parameters D1, D2, n, d [mm], G [MPa], H [mm] of a conical spring to a\n"
    "measured stress-strain (or force-displacement) table, for each spring type, with linear,\n"
    "Duffing and Fung baselines beside it. Prints a report; -o writes the JSON fit file.\n\n"
    "  -o OUT.json | -o DIR/   fit file (one table) or folder (one NAME.json per table)\n"
    "  --type T                telescoping | non-telescoping | both (default both)\n"
    "  --fix NAME=VALUE        hold a parameter: D1, D2, d, H in mm, G in MPa, n (repeatable)\n"
    "  --index-max C           largest spring index D1/d (default 12; the smallest is 3)\n"
    "  --rho-min R             smallest diameter ratio D1/D2 (default 0.05)\n"
    "  --n-max N               most active coils (default 30; the fewest is 2)\n"
    "  --D2-max-H R            largest outer diameter in free lengths, D2/H (default 10)\n"
    "  --G-max G               stiffest wire, shear modulus in MPa (default 80000, steel)\n"
    "  --relative              residuals relative to |stress| instead of absolute\n"
    "  --optimizer NAME        slsqp (default) | cobyla | mma: the constrained local optimiser\n"
    "  --seed S                seed of the global search (default 1); same seed, same result\n"
    "  --starts N              local starts of the global search (default 8)\n"
    "  --validate [SCENE.json] run each fitted spring in the static uniaxial lattice (the scene's\n"
    "                          lattice, or 3x3x3 cells calibrated isotropic) at the\n"
    "                          table's strains and report the lattice's RMSE, R^2, max |error|\n"
    "                          in the table's stress unit (stress-strain tables only)\n"
    "  --through-msm [SCENE.json]  fit through the lattice: refine rho, s/H and F_C/H^2 so that\n"
    "                          the lattice's curve matches the table (implies --validate; slower)\n"
    "  --plot FILE.png|.svg    draw data, fits, baselines and residuals with gnuplot\n"
    "                          (with several tables: a folder DIR/, one NAME.png per table)\n"
    "  --x-col NAME, --y-col NAME   columns to use in wider tables\n"
    "  --stress-unit U         unit of a stress column without one (Pa, kPa, MPa, ...)\n"
    "  --force-unit U          unit of a force column without one (N, mN, ...)\n"
    "  --length-unit U         unit of a displacement column without one (mm, m, ...)\n"
    "  --stretch               the x column is stretch (strain = stretch - 1)\n"
    "  -j N                    fit N tables at a time (default 1)\n"
    "  --quiet                 no report on stdout (errors and warnings still on stderr)\n\n"
    "Tables: a header row naming the columns, units in the names (stress_kPa, stress [kPa]),\n"
    "'#' comments, ',' ';' or TAB delimiters, an optional weight column. Tension positive.\n";

typedef struct fit_args {
    const char **files;
    int nfiles;
    const char *out;
    const char *plot;
    cf_pipeline_options popt;    /* types, fitter options, validation lattice */
    cf_measure_options mopt;
    long jobs;
    int quiet;
    const char *scene;           /* the validation scene, or NULL for the default lattice */
} fit_args;

typedef struct fit_job {
    const fit_args *args;
    const char *file;
    cf_table m;
    cf_fit_report rep;
    char json_path[4096];        /* "" when not written */
    char plot_path[4096];
    cf_atomic json_out, plot_out; /* both complete, put in place only when every job succeeded */
    char *text;
    const char *const *inputs;   /* every input of the run: never an output */
    cf_error err;
    cf_status st;
} fit_job;

static int is_dir_target(const char *p)
{
    struct stat s;
    size_t n = strlen(p);
    return (n > 0 && p[n - 1] == '/') || (stat(p, &s) == 0 && S_ISDIR(s.st_mode));
}

/* DIR/BASENAME-without-extension.EXT */
static void path_in_dir(char *dst, size_t cap, const char *dir, const char *file, const char *ext)
{
    const char *base = strrchr(file, '/');
    base = base ? base + 1 : file;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot && dot != base)
        n = (size_t)(dot - base);
    size_t dl = strlen(dir);
    snprintf(dst, cap, "%s%s%.*s%s", dir, (dl && dir[dl - 1] == '/') ? "" : "/", (int)n, base,
             ext);
}

static int ends_with_json(const char *s)
{
    size_t n = strlen(s);
    return n > 5 && strcmp(s + n - 5, ".json") == 0;
}

/* `--validate`, `--validate=SCENE.json`, `--validate SCENE.json` (the value is taken only when
** it ends in .json, so a table may follow the flag); the same for --through-msm. 1 if consumed. */
static int validate_option(int argc, char **argv, int *i, const char *name, fit_args *a)
{
    size_t n = strlen(name);
    const char *arg = argv[*i];
    if (strncmp(arg, name, n) != 0 || (arg[n] != '\0' && arg[n] != '='))
        return 0;
    a->popt.validate = 1;
    if (strcmp(name, "--through-msm") == 0)
        a->popt.through_msm = 1;
    if (arg[n] == '=')
        a->scene = arg + n + 1;
    else if (*i + 1 < argc && argv[*i + 1][0] != '-' && ends_with_json(argv[*i + 1]))
        a->scene = argv[++*i];
    return 1;
}

/* The flag that widens a limit, by constraint bit. */
static const char *limit_flag(unsigned bit)
{
    switch (bit) {
    case CF_C_INDEX_MAX: return "--index-max";
    case CF_C_RHO_MIN: return "--rho-min";
    case CF_C_COILS_MAX: return "--n-max";
    case CF_C_G_MAX: return "--G-max";
    case CF_C_D2_H: return "--D2-max-H";
    case CF_C_TRAVEL: return "nothing: no spring reaches the largest strain (a solid strain is "
                             "below 1)";
    case CF_C_TYPE: return "--rho-min, --index-max, --D2-max-H (a telescoping spring needs "
                           "rho <= index_max/(index_max + 4))";
    }
    return "--fix";
}

/* Named warnings on stderr: a family that cannot be placed inside the limits, a law that goes
** solid close past the data. */
static void fit_warnings(const char *file, const cf_fit_report *r, const cf_fit_result *f)
{
    const char *type = cf_spring_type_name(f->type);
    for (int b = 0; b < CF_C_COUNT; b++) {
        unsigned bit = 1u << b;
        if (f->violated & bit)
            fprintf(stderr,
                    "conifit: warning: %s: no %s spring of this table meets the limit %s "
                    "(feasible: false); to widen it: %s\n",
                    file, type, cf_fit_constraint_name(bit), limit_flag(bit));
    }
    if (f->feasible && f->solid_ratio < CF_FIT_SOLID_RATIO_WARN)
        fprintf(stderr,
                "conifit: warning: %s: the %s law goes solid at %s %.4g, %.3g times the table's "
                "largest (below %.1f): it stiffens without bound just past the data\n",
                file, type, cf_table_is_force(r->table) ? "displacement [mm]" : "strain", f->ident[1],
                f->solid_ratio, CF_FIT_SOLID_RATIO_WARN);
}

static int parse_args(int argc, char **argv, fit_args *a)
{
    static const char *cmd = "fit";
    cf_error err = {0};
    memset(a, 0, sizeof *a);
    a->popt = cf_pipeline_default_options();
    a->mopt = cf_measure_default_options();
    a->jobs = 1;
    a->files = calloc((size_t)argc, sizeof *a->files);
    if (!a->files)
        return CF_EXIT_SOFTWARE;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int m;
        if (cf_cli_is_help(argv[i])) {
            fputs(fit_help, stdout);
            return CF_EXIT_OK;
        }
#define OPT(name) ((m = cf_cli_match(argc, argv, &i, name, &v, &err)) != 0)
#define BAD() return cf_cli_usage_error(cmd, "%s", err.msg)
        if (OPT("-o")) {
            if (m < 0)
                BAD();
            a->out = v;
        } else if (validate_option(argc, argv, &i, "--validate", a) ||
                   validate_option(argc, argv, &i, "--through-msm", a)) {
            continue;
        } else if (OPT("--plot")) {
            if (m < 0)
                BAD();
            a->plot = v;
        } else if (OPT("--type")) {
            if (m < 0)
                BAD();
            if (strcmp(v, "both") == 0)
                a->popt.types = CF_PIPELINE_BOTH;
            else if (strcmp(v, "telescoping") == 0)
                a->popt.types = CF_PIPELINE_TELESCOPING;
            else if (strcmp(v, "non-telescoping") == 0)
                a->popt.types = CF_PIPELINE_NON_TELESCOPING;
            else
                return cf_cli_usage_error(cmd, "--type '%s': expected telescoping, "
                                               "non-telescoping or both", v);
        } else if (OPT("--fix")) {
            if (m < 0)
                BAD();
            char name[32];
            const char *eq = strchr(v, '=');
            int k;
            double val;
            if (!eq || (size_t)(eq - v) >= sizeof name)
                return cf_cli_usage_error(cmd, "--fix '%s': expected NAME=VALUE", v);
            snprintf(name, sizeof name, "%.*s", (int)(eq - v), v);
            if ((k = cf_spring_param_find(name)) < 0)
                return cf_cli_usage_error(cmd, "--fix %s: unknown parameter '%s' (expected D1, "
                                               "D2, n, d, G or H)", v, name);
            if (cf_cli_parse_double("--fix", eq + 1, &val, &err) != CF_OK)
                BAD();
            if (!(val > 0))
                return cf_cli_usage_error(cmd, "--fix %s=%g: the value must be positive", name,
                                          val);
            a->popt.fit.fixed[k] = 1;
            a->popt.fit.fixed_value[k] = val;
        } else if (OPT("--index-max")) {
            if (m < 0 || cf_cli_parse_double("--index-max", v, &a->popt.fit.index_max, &err))
                BAD();
            if (a->popt.fit.index_max < 3)
                return cf_cli_usage_error(cmd, "--index-max %g: must be at least 3",
                                          a->popt.fit.index_max);
        } else if (OPT("--rho-min")) {
            if (m < 0 || cf_cli_parse_double("--rho-min", v, &a->popt.fit.rho_min, &err))
                BAD();
            if (!(a->popt.fit.rho_min > 0 && a->popt.fit.rho_min < 1))
                return cf_cli_usage_error(cmd, "--rho-min %g: a diameter ratio D1/D2 lies in (0, 1)",
                                          a->popt.fit.rho_min);
        } else if (OPT("--n-max")) {
            if (m < 0 || cf_cli_parse_double("--n-max", v, &a->popt.fit.upper[CF_P_N], &err))
                BAD();
            if (!(a->popt.fit.upper[CF_P_N] >= 2))
                return cf_cli_usage_error(cmd, "--n-max %g: a conical spring needs n >= 2",
                                          a->popt.fit.upper[CF_P_N]);
        } else if (OPT("--D2-max-H")) {
            if (m < 0 || cf_cli_parse_double("--D2-max-H", v, &a->popt.fit.D2_over_H_max, &err))
                BAD();
            if (!(a->popt.fit.D2_over_H_max > 0))
                return cf_cli_usage_error(cmd, "--D2-max-H %g: must be positive",
                                          a->popt.fit.D2_over_H_max);
        } else if (OPT("--G-max")) {
            if (m < 0 || cf_cli_parse_double("--G-max", v, &a->popt.fit.upper[CF_P_G], &err))
                BAD();
            if (!(a->popt.fit.upper[CF_P_G] > a->popt.fit.lower[CF_P_G]))
                return cf_cli_usage_error(cmd, "--G-max %g MPa: must be positive",
                                          a->popt.fit.upper[CF_P_G]);
        } else if (strcmp(argv[i], "--relative") == 0) {
            a->popt.fit.relative = 1;
        } else if (OPT("--optimizer")) {
            if (m < 0 || cf_fit_optimizer_parse(v, &a->popt.fit.optimizer, &err) != CF_OK)
                BAD();
        } else if (OPT("--seed")) {
            long s;
            if (m < 0 || cf_cli_parse_long("--seed", v, 0, 2147483647L, &s, &err))
                BAD();
            a->popt.fit.seed = (unsigned long)s;
        } else if (OPT("--starts")) {
            long s;
            if (m < 0 || cf_cli_parse_long("--starts", v, 1, 10000, &s, &err))
                BAD();
            a->popt.fit.multistart = (int)s;
        } else if (OPT("--x-col")) {
            if (m < 0)
                BAD();
            a->mopt.x_col = v;
        } else if (OPT("--y-col")) {
            if (m < 0)
                BAD();
            a->mopt.y_col = v;
        } else if (OPT("--stress-unit")) {
            if (m < 0)
                BAD();
            a->mopt.stress_unit = v;
        } else if (OPT("--force-unit")) {
            if (m < 0)
                BAD();
            a->mopt.force_unit = v;
        } else if (OPT("--length-unit")) {
            if (m < 0)
                BAD();
            a->mopt.length_unit = v;
        } else if (strcmp(argv[i], "--stretch") == 0) {
            a->mopt.x_is_stretch = 1;
        } else if (OPT("-j")) {
            if (m < 0 || cf_cli_parse_long("-j", v, 1, 256, &a->jobs, &err))
                BAD();
        } else if (strcmp(argv[i], "--quiet") == 0) {
            a->quiet = 1;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return cf_cli_usage_error(cmd, "unknown option '%s'", argv[i]);
        } else {
            a->files[a->nfiles++] = argv[i];
        }
#undef OPT
#undef BAD
    }
    if (a->nfiles == 0)
        return cf_cli_usage_error(cmd, "no table given");
    if (a->nfiles > 1 && a->out && !is_dir_target(a->out))
        return cf_cli_usage_error(cmd, "-o %s: with %d tables, -o must name a folder (DIR/)",
                                  a->out, a->nfiles);
    if (a->nfiles > 1 && a->plot && !is_dir_target(a->plot))
        return cf_cli_usage_error(cmd, "--plot %s: with %d tables, --plot must name a folder",
                                  a->plot, a->nfiles);
    if (a->plot && !is_dir_target(a->plot) && cf_plot_check_name(a->plot, &err) != CF_OK)
        return cf_cli_usage_error(cmd, "--plot %s: the file must end in .png or .svg", a->plot);
    return -1;
}

/* Through-the-lattice work takes seconds: say so on a terminal. */
static void show_progress(void *ctx, const char *table, const char *what)
{
    (void)ctx;
    if (strstr(what, "through the lattice"))
        fprintf(stderr, "conifit: %s: %s...\n", table, what);
}

/* Fits one loaded table and writes its outputs. */
static void run_job(fit_job *j)
{
    const fit_args *a = j->args;
    j->st = cf_pipeline_fit(&j->m, &a->popt, &j->rep, &j->err);
    if (j->st != CF_OK)
        return;
    /* both outputs as temporaries; cf_cli_fit puts them in place when every table succeeded */
    j->st = cf_pipeline_prepare(&j->rep, j->json_path[0] ? j->json_path : NULL,
                                j->plot_path[0] ? j->plot_path : NULL, j->inputs, &j->json_out,
                                &j->plot_out, &j->err);
    if (j->st != CF_OK)
        return;
    if (!a->quiet)
        j->text = cf_report_text(&j->rep);
}

typedef struct pool {
    fit_job *jobs;
    int count;
    int next;
    pthread_mutex_t lock;
} pool;

static void *worker(void *arg)
{
    pool *p = arg;
    for (;;) {
        pthread_mutex_lock(&p->lock);
        int k = p->next++;
        pthread_mutex_unlock(&p->lock);
        if (k >= p->count)
            return NULL;
        run_job(&p->jobs[k]);
    }
}

/* Names every output of the run before anything is read or fitted, and refuses the run when two
** outputs share a name (two tables with one base name in a batch, -o and --plot alike) or an
** output cannot be written (an input, a non-regular file, a missing folder). */
static int plan_outputs(const fit_args *a, fit_job *jobs, const char *const *inputs)
{
    cf_error err = {0};
    for (int i = 0; i < a->nfiles; i++) {
        fit_job *j = &jobs[i];
        j->inputs = inputs;
        if (a->out && is_dir_target(a->out))
            path_in_dir(j->json_path, sizeof j->json_path, a->out, a->files[i], ".json");
        else if (a->out)
            snprintf(j->json_path, sizeof j->json_path, "%s", a->out);
        if (a->plot && (a->nfiles > 1 || is_dir_target(a->plot)))
            path_in_dir(j->plot_path, sizeof j->plot_path, a->plot, a->files[i], ".png");
        else if (a->plot)
            snprintf(j->plot_path, sizeof j->plot_path, "%s", a->plot);
        const char *mine[2] = {j->json_path, j->plot_path};
        for (int k = 0; k < 2; k++) {
            if (!mine[k][0])
                continue;
            if (cf_atomic_check(mine[k], inputs, &err) != CF_OK)
                return cf_cli_fail(&err);
            /* against every output named so far, this table's included */
            for (int i2 = 0; i2 <= i; i2++)
                for (int k2 = 0; k2 < 2; k2++) {
                    const char *other = k2 == 0 ? jobs[i2].json_path : jobs[i2].plot_path;
                    if ((i2 == i && k2 >= k) || !other[0] || strcmp(other, mine[k]) != 0)
                        continue;
                    if (i2 == i)
                        return cf_cli_usage_error("fit", "-o and --plot both name %s", mine[k]);
                    return cf_cli_usage_error("fit", "tables %s and %s would both be written "
                                              "to %s; give them different names",
                                              a->files[i2], a->files[i], mine[k]);
                }
        }
    }
    return -1;
}

int cf_cli_fit(int argc, char **argv)
{
    fit_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) {
        free(a.files);
        return rc;
    }
    fit_job *jobs = calloc((size_t)a.nfiles, sizeof *jobs);
    if (!jobs) {
        free(a.files);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    /* every input of the run, never to be an output */
    const char **inputs = calloc((size_t)a.nfiles + 2, sizeof *inputs);
    if (!inputs) {
        free(jobs);
        free(a.files);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    for (int i = 0; i < a.nfiles; i++)
        inputs[i] = a.files[i];
    inputs[a.nfiles] = a.scene;
    rc = plan_outputs(&a, jobs, inputs);
    /* Read every table first: a bad one stops the run before anything is written. */
    for (int i = 0; i < a.nfiles && rc < 0; i++) {
        jobs[i].args = &a;
        jobs[i].file = a.files[i];
        cf_error err = {0};
        if (cf_measure_load(a.files[i], &a.mopt, &jobs[i].m, &err) != CF_OK)
            rc = cf_cli_fail(&err);
    }
    if (rc < 0 && a.scene) {
        cf_error err = {0};
        if (cf_pipeline_use_scene(&a.popt, a.scene, &err) != CF_OK)
            rc = cf_cli_fail(&err);
    }
    if (isatty(STDERR_FILENO))
        a.popt.progress = show_progress;
    if (rc < 0) {
        pool p = {jobs, a.nfiles, 0, PTHREAD_MUTEX_INITIALIZER};
        int nt = (int)(a.jobs < a.nfiles ? a.jobs : a.nfiles);
        pthread_t th[256];
        int started = 0;
        for (int t = 1; t < nt; t++)
            if (pthread_create(&th[started], NULL, worker, &p) == 0)
                started++;
        worker(&p);
        for (int t = 0; t < started; t++)
            pthread_join(th[t], NULL);
        /* all outputs or none: they go in place only when every table succeeded */
        int failed = 0;
        for (int i = 0; i < a.nfiles; i++)
            failed |= jobs[i].st != CF_OK;
        for (int i = 0; i < a.nfiles && !failed; i++) {
            fit_job *j = &jobs[i];
            if ((j->json_path[0] && (j->st = cf_atomic_commit(&j->json_out, &j->err)) != CF_OK) ||
                (j->plot_path[0] && (j->st = cf_atomic_commit(&j->plot_out, &j->err)) != CF_OK))
                failed = 1;
        }
        for (int i = 0; i < a.nfiles; i++) {
            cf_atomic_abort(&jobs[i].json_out);
            cf_atomic_abort(&jobs[i].plot_out);
            if (failed && jobs[i].st == CF_OK)
                jobs[i].json_path[0] = jobs[i].plot_path[0] = '\0'; /* not written */
        }
        rc = CF_EXIT_OK;
        for (int i = 0; i < a.nfiles; i++) {
            fit_job *j = &jobs[i];
            if (j->st != CF_OK) {
                int e = cf_cli_fail(&j->err);
                if (rc == CF_EXIT_OK)
                    rc = e;
                continue;
            }
            if (j->text) {
                fputs(j->text, stdout);
                if (j->json_path[0])
                    printf("Fit file: %s\n", j->json_path);
                if (j->plot_path[0])
                    printf("Plot: %s\n", j->plot_path);
                if (a.nfiles > 1)
                    fputc('\n', stdout);
            }
            for (int k = 0; k < j->rep.nfits; k++)
                fit_warnings(j->file, &j->rep, &j->rep.fits[k]);
        }
        if (failed && (a.out || a.plot))
            fprintf(stderr, "conifit: no output file written (outputs are written only when "
                            "every table succeeds)\n");
        if (a.nfiles > 1 && !a.quiet) {
            int wname = 5;
            for (int i = 0; i < a.nfiles; i++)
                if ((int)strlen(jobs[i].file) > wname)
                    wname = (int)strlen(jobs[i].file);
            printf("Summary (RMSE in each table's unit):\n");
            printf("  %-*s %-18s %-18s %-22s %-16s%s\n", wname, "table", "telescoping",
                   "non-telescoping", "best baseline", "better type",
                   a.popt.validate ? " lattice RMSE (better type)" : "");
            for (int i = 0; i < a.nfiles; i++) {
                fit_job *j = &jobs[i];
                if (j->st != CF_OK) {
                    printf("  %-*s failed\n", wname, j->file);
                    continue;
                }
                char cell[2][32] = {"-", "-"};
                for (int k = 0; k < j->rep.nfits; k++)
                    snprintf(cell[j->rep.fits[k].type], sizeof cell[0], "%.4g %s%s",
                             j->rep.fits[k].rmse * j->m.y_to_file, j->m.y_unit,
                             j->rep.fits[k].feasible ? "" : " (!)");
                int bb = 0;
                for (int k = 1; k < CF_BASE_COUNT; k++)
                    if (j->rep.baselines[k].rmse < j->rep.baselines[bb].rmse)
                        bb = k;
                char bcell[48];
                snprintf(bcell, sizeof bcell, "%s %.4g %s", cf_baseline_name((cf_baseline_kind)bb),
                         j->rep.baselines[bb].rmse * j->m.y_to_file, j->m.y_unit);
                int b = cf_report_better(&j->rep);
                char vcell[48] = "";
                if (a.popt.validate && b >= 0 && j->rep.val[b].done)
                    snprintf(vcell, sizeof vcell, " %.4g %s",
                             j->rep.val[b].rmse * j->m.y_to_file, j->m.y_unit);
                else if (a.popt.validate)
                    snprintf(vcell, sizeof vcell, " skipped");
                printf("  %-*s %-18s %-18s %-22s %-16s%s\n", wname, j->file, cell[0], cell[1],
                       bcell,
                       b < 0                          ? "none feasible"
                       : cf_report_types_tie(&j->rep) ? "tie"
                                                      : cf_spring_type_name(j->rep.fits[b].type),
                       vcell);
            }
        }
    }
    for (int i = 0; i < a.nfiles; i++) {
        cf_table_free(&jobs[i].m);
        free(jobs[i].text);
        cf_report_free(&jobs[i].rep);
    }
    free(jobs);
    free(inputs);
    free(a.files);
    return rc;
}
