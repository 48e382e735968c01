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
#include "conifit/fitfile.h"
#include "conifit/joint.h"
#include "conifit/jointreport.h"
#include "conifit/pipeline.h"
#include "conifit/pipeline_series.h"
#include "report/plot.h"

static const char fit_help[] =
    "usage: conifit fit TABLE... [-o OUT.json | -o DIR/ | -o -] [options]\n"
    "Fits the design parameters D1, D2, n, d [mm], G [MPa], H [mm] of a conical spring to a\n"
    "measured stress-strain (or force-displacement) table, for each spring type, with linear,\n"
    "Duffing and Fung baselines beside it. Prints a report; -o writes the JSON fit file.\n\n"
    "  TABLE                   .csv or .txt table; '-' reads one from standard input\n"
    "  -o, --output OUT.json | DIR/ | -   fit file (one table), folder (one NAME.json per\n"
    "                          table), or '-': the fit file on standard output (no report)\n"
    "  --type T                telescoping | non-telescoping | both (default both)\n"
    "  --fix NAME=VALUE        hold a parameter: D1, D2, d, H in mm, G in MPa, n (repeatable)\n"
    "  --index-max C           largest spring index D1/d, 3..50 (default 12; the smallest is 3)\n"
    "  --rho-min R             smallest diameter ratio D1/D2, 0.001..1 (default 0.05)\n"
    "  --n-max N               most active coils, 2..1000 (default 30; the fewest is 2)\n"
    "  --D2-max-H R            largest outer diameter in free lengths, D2/H, up to 1000\n"
    "                          (default 10)\n"
    "  --G-max G               stiffest wire, shear modulus in MPa, up to 1e6 (default 80000,\n"
    "                          steel)\n"
    "  --relative              residuals relative to |stress| instead of absolute\n"
    "  --optimizer NAME        slsqp (default) | cobyla | mma: the constrained local optimiser\n"
    "  --seed S                seed of the global search (default 1); same seed, same result\n"
    "  --starts N              local starts of the global search (default 8)\n"
    "  --validate [SCENE.json] run each fitted spring in the lattice (the scene's, or 3x3x3 cells\n"
    "                          calibrated isotropic) at the table's strains in the table's mode\n"
    "                          and report the fit's RMSE, the lattice's RMSE and the lattice\n"
    "                          against the law, in the table's stress unit (stress-strain tables)\n"
    "  --target lattice|spring fit the lattice's curve in the table's mode (implies --validate)\n"
    "                          or the spring's (default for uniaxial tables)\n"
    "  --through-msm [SCENE.json]  --target lattice [--validate SCENE.json]\n"
    "  --max-memory SIZE, --max-steps N, --max-work N  the validation's budget, as for\n"
    "                          simulate (defaults 2G, 1e7 static solves and 1e10 spring-steps\n"
    "                          of work): a larger lattice or table is refused\n"
    "  --joint                 one lattice for every table, each in its own mode\n"
    "  --calibration C         isotropic (default), axial, or fitted (with --joint)\n"
    "  --mode M                the table's test mode: uniaxial, shear, planar, equibiaxial or\n"
    "                          confined (wins over a '# mode:' comment; default uniaxial)\n"
    "  --plot FILE.png|.svg|.pdf  draw data, fits, baselines and residuals with gnuplot\n"
    "                          (with several tables: a folder DIR/, one NAME.png per table)\n"
    "  --title TEXT            title of the plot (default: the table's file name without\n"
    "                          folder and extension)\n"
    "  --x-col NAME, --y-col NAME   columns to use in wider tables\n"
    "  --stress-unit U         unit of a stress column without one (Pa, kPa, MPa, ...)\n"
    "  --force-unit U          unit of a force column without one (N, mN, ...)\n"
    "  --length-unit U         unit of a displacement column without one (mm, m, ...)\n"
    "  --stretch               the x column is stretch (strain = stretch - 1)\n"
    "  --stress-measure M      nominal | cauchy: what the stress column holds (default: the\n"
    "                          table's '# stress:' comment or column name, else nominal);\n"
    "                          Cauchy stress is converted to nominal under incompressibility\n"
    "  --strain-measure M      engineering | log | stretch (default: '# strain:' or the name)\n"
    "  -j, --jobs N            fit N tables at a time (default 1)\n";

/* The help's second part (C17 guarantees string literals of 4095 characters only). */
static const char fit_help_series[] =
    "Time series (a table with a time column such as time_s) are fitted with the time-dependent\n"
    "model: the conical law plus a Prony series on every spring, in the lattice's homogenised\n"
    "cell, driven by the measured strain history:\n"
    "  --branches N            Prony terms, 1..8 (default: 1..4 chosen by AIC)\n"
    "  --dashpot               fit a dashpot beside every spring as well\n"
    "  --relaxation R          qlv: relative moduli g_i constant (quasi-linear);\n"
    "                          strain: g_i + g_per_strain_i |strain| at a spring's strain;\n"
    "                          auto (default): both; kept is the lowest AIC among the\n"
    "                          candidates whose terms the series determines\n"
    "  --elastic FIT.json[:TYPE]  hold rho, s/H and F_C/H^2 at those of a fit file's spring\n"
    "  --calibration C         the lattice's weights: axial (default for a series) or isotropic\n"
    "The fitted spring stays within the design limits (--rho-min, --index-max, ...) and its\n"
    "lattice stable up to the series' largest strain (a held --elastic spring whose lattice\n"
    "would buckle within the series is refused).\n\n"
    "Tables: a header row naming the columns, units in the names (stress_kPa, stress [kPa]),\n"
    "'#' comments, ',' ';' TAB or blank-separated columns, an optional weight column. Tension\n"
    "positive. A spreadsheet (.xlsx, .ods) must be saved as CSV first.\n";

typedef struct fit_args {
    const char **files;
    int nfiles;
    const char *out;
    const char *plot;
    cf_pipeline_options popt;    /* types, fitter options, validation lattice */
    cf_measure_options mopt;
    long jobs;
    int quiet;
    int progress;                /* progress lines on stderr */
    const char *scene;           /* the validation scene, or NULL for the default lattice */
    int argc;                    /* the command line, for --validate SCENE.json */
    char **argv;
    cf_visco_fit_options vopt;   /* time series: the viscoelastic fit */
    const char *elastic;         /* --elastic FIT.json[:TYPE] */
    int series_only;             /* an option for time series only was given */
    int joint;                   /* --joint: one lattice for every table */
    int calibration_given;       /* --calibration was given */
} fit_args;

typedef struct fit_job {
    const fit_args *args;
    const char *file;
    cf_table m;
    cf_fit_report rep;
    cf_visco_report vrep;        /* a time series (m.t not NULL) */
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
    if (strcmp(file, "-") == 0)
        file = "stdin"; /* a table read from standard input */
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

enum {
    OPT_PLOT = CF_CLI_OPT_OWN,
    OPT_TYPE,
    OPT_FIX,
    OPT_INDEX_MAX,
    OPT_RELATIVE,
    OPT_OPTIMIZER,
    OPT_SEED,
    OPT_STARTS,
    OPT_VALIDATE,
    OPT_THROUGH,
    OPT_TARGET,
    OPT_MODE,
    OPT_JOINT,
    OPT_CALIBRATION,
    OPT_X_COL,
    OPT_Y_COL,
    OPT_STRESS_UNIT,
    OPT_FORCE_UNIT,
    OPT_LENGTH_UNIT,
    OPT_STRETCH,
    OPT_RHO_MIN,
    OPT_N_MAX,
    OPT_D2_MAX_H,
    OPT_G_MAX,
    OPT_BRANCHES,
    OPT_DASHPOT,
    OPT_RELAXATION,
    OPT_ELASTIC,
    OPT_TITLE,
    OPT_STRESS_MEASURE,
    OPT_STRAIN_MEASURE,
    OPT_MAX_MEMORY,
    OPT_MAX_STEPS,
    OPT_MAX_WORK
};

static const struct option fit_options[] = {
    {"plot", required_argument, NULL, OPT_PLOT},
    {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
    {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
    {"max-work", required_argument, NULL, OPT_MAX_WORK},
    {"type", required_argument, NULL, OPT_TYPE},
    {"fix", required_argument, NULL, OPT_FIX},
    {"index-max", required_argument, NULL, OPT_INDEX_MAX},
    {"relative", no_argument, NULL, OPT_RELATIVE},
    {"optimizer", required_argument, NULL, OPT_OPTIMIZER},
    {"seed", required_argument, NULL, OPT_SEED},
    {"starts", required_argument, NULL, OPT_STARTS},
    {"validate", optional_argument, NULL, OPT_VALIDATE},
    {"through-msm", optional_argument, NULL, OPT_THROUGH},
    {"target", required_argument, NULL, OPT_TARGET},
    {"mode", required_argument, NULL, OPT_MODE},
    {"joint", no_argument, NULL, OPT_JOINT},
    {"calibration", required_argument, NULL, OPT_CALIBRATION},
    {"x-col", required_argument, NULL, OPT_X_COL},
    {"y-col", required_argument, NULL, OPT_Y_COL},
    {"stress-unit", required_argument, NULL, OPT_STRESS_UNIT},
    {"force-unit", required_argument, NULL, OPT_FORCE_UNIT},
    {"length-unit", required_argument, NULL, OPT_LENGTH_UNIT},
    {"stretch", no_argument, NULL, OPT_STRETCH},
    {"rho-min", required_argument, NULL, OPT_RHO_MIN},
    {"n-max", required_argument, NULL, OPT_N_MAX},
    {"D2-max-H", required_argument, NULL, OPT_D2_MAX_H},
    {"G-max", required_argument, NULL, OPT_G_MAX},
    {"branches", required_argument, NULL, OPT_BRANCHES},
    {"dashpot", no_argument, NULL, OPT_DASHPOT},
    {"relaxation", required_argument, NULL, OPT_RELAXATION},
    {"elastic", required_argument, NULL, OPT_ELASTIC},
    {"title", required_argument, NULL, OPT_TITLE},
    {"stress-measure", required_argument, NULL, OPT_STRESS_MEASURE},
    {"strain-measure", required_argument, NULL, OPT_STRAIN_MEASURE},
    {"jobs", required_argument, NULL, 'j'},
    {NULL, 0, NULL, 0}};

/* --fix NAME=VALUE: 0, or the exit status of a usage error. */
static int fix_option(const char *v, fit_args *a)
{
    cf_error err = {0};
    char name[32];
    const char *eq = strchr(v, '=');
    double val;
    if (!eq || (size_t)(eq - v) >= sizeof name)
        return cf_cli_usage_error("fit", "--fix '%s': expected NAME=VALUE", v);
    snprintf(name, sizeof name, "%.*s", (int)(eq - v), v);
    int k = cf_spring_param_find(name);
    if (k < 0)
        return cf_cli_usage_error("fit", "--fix %s: unknown parameter '%s' (expected D1, D2, n, "
                                         "d, G or H)", v, name);
    if (cf_cli_parse_double("--fix", eq + 1, &val, &err) != CF_OK)
        return cf_cli_usage_error("fit", "%s", err.msg);
    if (!(val > 0))
        return cf_cli_usage_error("fit", "--fix %s=%g: the value must be positive", name, val);
    a->popt.fit.fixed[k] = 1;
    a->popt.fit.fixed_value[k] = val;
    return 0;
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
                file, type, cf_table_is_force(r->table) ? "displacement [mm]" : "strain", f->ident.solid,
                f->solid_ratio, CF_FIT_SOLID_RATIO_WARN);
}

/* --validate[=SCENE.json] and --through-msm[=SCENE.json]; `--validate SCENE.json` takes the next
** argument too when it ends in .json (a table never does), as earlier versions did. */
static void validate_option(int c, const char *value, fit_args *a)
{
    a->popt.validate = 1;
    if (c == OPT_THROUGH)
        a->popt.target = CF_TARGET_LATTICE;
    if (value)
        a->scene = value;
    else if (optind < a->argc && a->argv[optind][0] != '-' && ends_with_json(a->argv[optind]))
        a->scene = a->argv[optind++];
}

/* --stress-measure, --strain-measure: a word the table reader knows (measure.h). */
static int measure_option(int c, const char *optval, cf_measure_options *mo)
{
    int bad;
    if (c == OPT_STRESS_MEASURE) {
        cf_stress_measure v = CF_STRESS_NOMINAL;
        bad = cf_stress_measure_parse(optval, &v) != 0;
        mo->stress_measure = (int)v;
    } else {
        cf_strain_measure v = CF_STRAIN_ENGINEERING;
        bad = cf_strain_measure_parse(optval, &v) != 0;
        mo->strain_measure = (int)v;
    }
    if (!bad)
        return 0;
    return cf_cli_usage_error("fit", "%s '%s': expected %s",
                              c == OPT_STRESS_MEASURE ? "--stress-measure" : "--strain-measure",
                              optval,
                              c == OPT_STRESS_MEASURE ? "nominal or cauchy"
                                                      : "engineering, log or stretch");
}

/* One option of fit: 0 to go on, else an exit status. Long only because fit has many options:
** one case per option, each a few lines of checking. */
static int fit_option(void *ctx, int c, const char *optval)
{
    fit_args *a = ctx;
    cf_error err = {0};
    cf_fit_options *fo = &a->popt.fit;
    long n;
    switch (c) {
    case OPT_PLOT: a->plot = optval; return 0;
    case OPT_TITLE: a->popt.title = optval; return 0;
    case OPT_TYPE:
        if (strcmp(optval, "both") == 0)
            a->popt.types = CF_PIPELINE_BOTH;
        else if (strcmp(optval, "telescoping") == 0)
            a->popt.types = CF_PIPELINE_TELESCOPING;
        else if (strcmp(optval, "non-telescoping") == 0)
            a->popt.types = CF_PIPELINE_NON_TELESCOPING;
        else
            return cf_cli_usage_error("fit", "--type '%s': expected telescoping, "
                                             "non-telescoping or both", optval);
        return 0;
    case OPT_FIX: return fix_option(optval, a);
    case OPT_INDEX_MAX:
        if (cf_cli_parse_double("--index-max", optval, &fo->index_max, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(fo->index_max >= 3 && fo->index_max <= CF_FIT_INDEX_MAX_LIMIT))
            return cf_cli_usage_error("fit", "--index-max %g: a spring index D1/d lies in [3, %g]",
                                      fo->index_max, CF_FIT_INDEX_MAX_LIMIT);
        return 0;
    case OPT_RHO_MIN:
        if (cf_cli_parse_double("--rho-min", optval, &fo->rho_min, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(fo->rho_min >= CF_FIT_RHO_MIN_LIMIT && fo->rho_min < 1))
            return cf_cli_usage_error("fit", "--rho-min %g: a diameter ratio D1/D2 the fit "
                                             "searches lies in [%g, 1)",
                                      fo->rho_min, CF_FIT_RHO_MIN_LIMIT);
        return 0;
    case OPT_N_MAX:
        if (cf_cli_parse_double("--n-max", optval, &fo->upper[CF_P_N], &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(fo->upper[CF_P_N] >= 2 && fo->upper[CF_P_N] <= CF_FIT_COILS_MAX_LIMIT))
            return cf_cli_usage_error("fit", "--n-max %g: a conical spring has 2 to %g coils",
                                      fo->upper[CF_P_N], CF_FIT_COILS_MAX_LIMIT);
        return 0;
    case OPT_D2_MAX_H:
        if (cf_cli_parse_double("--D2-max-H", optval, &fo->D2_over_H_max, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(fo->D2_over_H_max > 0 && fo->D2_over_H_max <= CF_FIT_D2_OVER_H_MAX_LIMIT))
            return cf_cli_usage_error("fit", "--D2-max-H %g: must lie in (0, %g]",
                                      fo->D2_over_H_max, CF_FIT_D2_OVER_H_MAX_LIMIT);
        return 0;
    case OPT_G_MAX:
        if (cf_cli_parse_double("--G-max", optval, &fo->upper[CF_P_G], &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(fo->upper[CF_P_G] > fo->lower[CF_P_G] && fo->upper[CF_P_G] <= CF_FIT_G_MAX_LIMIT))
            return cf_cli_usage_error("fit", "--G-max %g MPa: must lie in (0, %g] MPa (no wire "
                                             "is stiffer in shear)",
                                      fo->upper[CF_P_G], CF_FIT_G_MAX_LIMIT);
        return 0;
    case OPT_RELATIVE: fo->relative = 1; return 0;
    case OPT_MAX_MEMORY:
        return cf_cli_budget_option("fit", "--max-memory", optval, &a->popt.budget);
    case OPT_MAX_STEPS:
        return cf_cli_budget_option("fit", "--max-steps", optval, &a->popt.budget);
    case OPT_MAX_WORK:
        return cf_cli_budget_option("fit", "--max-work", optval, &a->popt.budget);
    case OPT_OPTIMIZER:
        if (cf_fit_optimizer_parse(optval, &fo->optimizer, &err) != CF_OK)
            return cf_cli_usage_error("fit", "option --optimizer: %s", err.msg);
        return 0;
    case OPT_SEED:
        if (cf_cli_parse_long("--seed", optval, 0, 2147483647L, &n, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        fo->seed = (unsigned long)n;
        return 0;
    case OPT_STARTS:
        if (cf_cli_parse_long("--starts", optval, 1, 10000, &n, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        fo->multistart = (int)n;
        return 0;
    case OPT_VALIDATE:
    case OPT_THROUGH: validate_option(c, optval, a); return 0;
    case OPT_TARGET:
        if (strcmp(optval, "lattice") == 0)
            a->popt.target = CF_TARGET_LATTICE, a->popt.validate = 1;
        else if (strcmp(optval, "spring") == 0)
            a->popt.target = CF_TARGET_SPRING;
        else
            return cf_cli_usage_error("fit", "--target '%s': expected lattice or spring", optval);
        return 0;
    case OPT_JOINT: a->joint = 1; return 0;
    case OPT_CALIBRATION: {
        cf_lattice_config *lc = &a->popt.lattice.cfg.lattice;
        if (cf_calibration_parse(optval, &lc->calibration, &err) != CF_OK)
            return cf_cli_usage_error("fit", "--%s", err.msg);
        if (lc->calibration != CF_CAL_FITTED)
            cf_calibration_weights(lc->calibration, lc->weight, NULL);
        a->calibration_given = 1;
        return 0;
    }
    case OPT_MODE: {
        cf_mode md;
        if (cf_mode_parse(optval, &md, &err) != CF_OK)
            return cf_cli_usage_error("fit", "--%s", err.msg);
        a->mopt.mode = optval;
        return 0;
    }
    case OPT_X_COL: a->mopt.x_col = optval; return 0;
    case OPT_Y_COL: a->mopt.y_col = optval; return 0;
    case OPT_STRESS_UNIT: a->mopt.stress_unit = optval; return 0;
    case OPT_FORCE_UNIT: a->mopt.force_unit = optval; return 0;
    case OPT_LENGTH_UNIT: a->mopt.length_unit = optval; return 0;
    case OPT_STRETCH: a->mopt.x_is_stretch = 1; return 0;
    case OPT_BRANCHES:
        if (cf_cli_parse_long("--branches", optval, 1, CF_PRONY_MAX, &n, &err) != CF_OK) {
            /* a branch count outside 1..8 is refused as bad data (65), as a bad table is */
            fprintf(stderr, "conifit fit: %s\n", err.msg);
            return CF_EXIT_DATAERR;
        }
        a->vopt.nbranch = (int)n;
        a->series_only = 1;
        return 0;
    case OPT_DASHPOT:
        a->vopt.dashpot = 1;
        a->series_only = 1;
        return 0;
    case OPT_RELAXATION:
        if (strcmp(optval, "auto") == 0)
            a->vopt.relaxation = CF_RELAX_AUTO;
        else if (strcmp(optval, "qlv") == 0)
            a->vopt.relaxation = CF_RELAX_QLV;
        else if (strcmp(optval, "strain") == 0)
            a->vopt.relaxation = CF_RELAX_STRAIN;
        else
            return cf_cli_usage_error("fit", "--relaxation '%s': expected auto, qlv or strain",
                                      optval);
        a->series_only = 1;
        return 0;
    case OPT_ELASTIC:
        a->elastic = optval;
        a->series_only = 1;
        return 0;
    case OPT_STRESS_MEASURE:
    case OPT_STRAIN_MEASURE: return measure_option(c, optval, &a->mopt);
    case 'j':
        if (cf_cli_parse_long("-j", optval, 1, 256, &a->jobs, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        return 0;
    default: return cf_cli_usage_error("fit", "unexpected option");
    }
}

/* The operands and the checks across options. -1 to go on, else an exit status. */
static int parse_args(int argc, char **argv, fit_args *a)
{
    static const char *cmd = "fit";
    cf_error err = {0};
    memset(a, 0, sizeof *a);
    a->popt = cf_pipeline_default_options();
    a->mopt = cf_measure_default_options();
    a->vopt = cf_visco_fit_default_options();
    a->vopt.relaxation = CF_RELAX_AUTO;
    a->jobs = 1;
    cf_cli_parser p;
    a->argc = argc;
    a->argv = argv;
    int rc = cf_cli_parser_init(&p, cmd, fit_help, 0, argc, argv, "j:", fit_options);
    p.help_more = fit_help_series;
    if (rc || (rc = cf_cli_parse(&p, fit_option, a)) >= 0)
        return rc;
    if (a->calibration_given && a->popt.lattice.cfg.lattice.calibration != CF_CAL_FITTED) {
        /* a time series is fitted in the lattice of the calibration asked for */
        a->vopt.setup.cfg.lattice.calibration = a->popt.lattice.cfg.lattice.calibration;
        memcpy(a->vopt.setup.cfg.lattice.weight, a->popt.lattice.cfg.lattice.weight,
               sizeof a->vopt.setup.cfg.lattice.weight);
    }
    a->out = p.output;
    a->quiet = p.quiet;
    a->progress = cf_cli_progress(&p);
    a->files = (const char **)argv + optind;
    a->nfiles = argc - optind;
    if (a->nfiles == 0)
        return cf_cli_usage_error(cmd, "no table given");
    for (int i = 0; i < a->nfiles; i++)
        if (cf_cli_is_stdio(a->files[i]) && a->nfiles > 1)
            return cf_cli_usage_error(cmd, "'-' (a table on standard input) must be the only "
                                           "table");
    if (cf_cli_is_stdio(a->out)) {
        if (a->nfiles > 1)
            return cf_cli_usage_error(cmd, "-o -: with %d tables, -o must name a folder (DIR/)",
                                      a->nfiles);
        a->quiet = 1; /* standard output holds the fit file */
    }
    if (a->joint && a->nfiles < 2)
        return cf_cli_usage_error(cmd, "--joint fits several tables at once; give at least two");
    if (a->calibration_given && a->popt.lattice.cfg.lattice.calibration == CF_CAL_FITTED &&
        !a->joint)
        return cf_cli_usage_error(cmd, "--calibration fitted: the family weights are fitted in a "
                                       "joint fit of several modes (--joint)");
    if (a->joint && a->out && (cf_cli_is_stdio(a->out) || is_dir_target(a->out)))
        return cf_cli_usage_error(cmd, "--joint -o %s: a joint fit writes one fit file "
                                       "(-o FILE.json)", a->out);
    if (a->joint && a->plot && is_dir_target(a->plot))
        return cf_cli_usage_error(cmd, "--joint --plot %s: a joint fit draws one figure "
                                       "(--plot FILE.png)", a->plot);
    if (a->joint) {
        if (a->plot && cf_plot_check_name(a->plot, &err) != CF_OK)
            return cf_cli_usage_error(cmd, "--plot %s: the file must end in .png or .svg",
                                      a->plot);
        return -1;
    }
    if (a->nfiles > 1 && a->out && !is_dir_target(a->out))
        return cf_cli_usage_error(cmd, "-o %s: with %d tables, -o must name a folder (DIR/)",
                                  a->out, a->nfiles);
    if (a->nfiles > 1 && a->plot && !is_dir_target(a->plot))
        return cf_cli_usage_error(cmd, "--plot %s: with %d tables, --plot must name a folder",
                                  a->plot, a->nfiles);
    if (a->plot && !is_dir_target(a->plot) && cf_plot_check_name(a->plot, &err) != CF_OK)
        return cf_cli_usage_error(cmd, "--plot %s: the file must end in .png, .svg or .pdf", a->plot);
    return -1;
}

/* Through-the-lattice work takes seconds: say so on a terminal. */
static void show_progress(void *ctx, const char *table, const char *what)
{
    (void)ctx;
    if (strstr(what, "through the lattice") || strstr(what, "viscoelastic"))
        fprintf(stderr, "conifit: %s: %s...\n", table, what);
}

/* Fits one loaded table and writes its outputs. */
static void run_job(fit_job *j)
{
    const fit_args *a = j->args;
    if (j->m.t) { /* a time series: the viscoelastic fit */
        j->st = cf_pipeline_fit_series(&j->m, &a->popt, &a->vopt, &j->vrep, &j->err);
        if (j->st == CF_OK)
            j->st = cf_pipeline_series_prepare(&j->vrep, j->json_path[0] ? j->json_path : NULL,
                                               j->plot_path[0] ? j->plot_path : NULL, j->inputs,
                                               &j->json_out, &j->plot_out, &j->err);
        if (j->st == CF_OK && !a->quiet)
            j->text = cf_visco_report_text(&j->vrep);
        return;
    }
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
        if (cf_cli_is_stdio(a->out))
            ; /* the fit file goes to standard output, written by cf_cli_fit */
        else if (a->out && is_dir_target(a->out))
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

/* --joint: one lattice fitted to every table (joint.h), each spring type asked for. */
static int run_joint(const fit_args *a, fit_job *jobs, const char *const *inputs)
{
    cf_error err = {0};
    const char *outs[2] = {a->out, a->plot};
    for (int k = 0; k < 2; k++)
        if (outs[k] && cf_atomic_check(outs[k], inputs, &err) != CF_OK)
            return cf_cli_fail(&err);
    if (a->out && a->plot && strcmp(a->out, a->plot) == 0)
        return cf_cli_usage_error("fit", "-o and --plot both name %s", a->out);
    const cf_table *tabs[CF_JOINT_MAX];
    if (a->nfiles > CF_JOINT_MAX)
        return cf_cli_usage_error("fit", "--joint takes at most %d tables", CF_JOINT_MAX);
    for (int i = 0; i < a->nfiles; i++)
        tabs[i] = &jobs[i].m;
    cf_joint_report r;
    memset(&r, 0, sizeof r);
    r.tables = tabs;
    r.ntables = (size_t)a->nfiles;
    r.with_timing = 1;
    int rc = CF_EXIT_OK;
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING && rc == CF_EXIT_OK; ty++) {
        if (!(a->popt.types & (1u << ty)))
            continue;
        if (a->progress)
            fprintf(stderr, "conifit fit: fitting the %s spring to %d tables jointly\n",
                    cf_spring_type_name((cf_spring_type)ty), a->nfiles);
        if (cf_joint_fit(tabs, r.ntables, &a->popt.fit, &a->popt.lattice, (cf_spring_type)ty,
                         &r.fits[r.nfits], &err) != CF_OK)
            rc = cf_cli_fail(&err);
        else
            r.nfits++;
    }
    cf_atomic jo, po;
    if (rc == CF_EXIT_OK &&
        cf_joint_prepare(&r, a->out, a->plot, inputs, &jo, &po, &err) != CF_OK)
        rc = cf_cli_fail(&err);
    if (rc == CF_EXIT_OK && ((a->out && cf_atomic_commit(&jo, &err) != CF_OK) ||
                             (a->plot && cf_atomic_commit(&po, &err) != CF_OK)))
        rc = cf_cli_fail(&err);
    if (rc == CF_EXIT_OK && !a->quiet) {
        char *text = cf_joint_text(&r);
        if (text)
            fputs(text, stdout);
        free(text);
        if (a->out)
            printf("Fit file: %s\n", a->out);
        if (a->plot)
            printf("Plot: %s\n", a->plot);
    }
    for (int k = 0; k < r.nfits; k++)
        cf_joint_free(&r.fits[k]);
    return rc;
}

/* Reads every table (a bad one stops the run before anything is written), the scene, and the
** elastic fit a series is held to, and checks the options against what was read. -1 to go on,
** else an exit status. */
static int load_inputs(fit_args *a, fit_job *jobs, int *nseries)
{
    int rc = -1;
    for (int i = 0; i < a->nfiles && rc < 0; i++) {
        jobs[i].args = a;
        jobs[i].file = a->files[i];
        cf_error err = {0};
        if (cf_measure_load(a->files[i], &a->mopt, &jobs[i].m, &err) != CF_OK)
            rc = cf_cli_fail(&err);
    }
    if (rc < 0 && a->scene) {
        cf_error err = {0};
        if (cf_pipeline_use_scene(&a->popt, a->scene, &err) != CF_OK)
            rc = cf_cli_fail(&err);
    }
    *nseries = 0;
    for (int i = 0; i < a->nfiles && rc < 0; i++)
        *nseries += jobs[i].m.t != NULL;
    /* as the series' options in a batch with stress-strain tables, these apply to the tables
    ** they concern; refused when no table is one */
    if (rc < 0 && *nseries == a->nfiles &&
        (a->popt.validate || a->popt.target == CF_TARGET_LATTICE))
        rc = cf_cli_usage_error("fit", "--validate and --target lattice apply to stress-strain "
                                       "tables; a time series is fitted through the lattice "
                                       "already");
    if (rc < 0 && *nseries == 0 && a->series_only)
        rc = cf_cli_usage_error("fit", "--branches, --dashpot, --relaxation and --elastic apply to time "
                                       "series "
                                       "(a table with a time column) only");
    if (rc < 0 && a->elastic) {
        cf_fitted_spring fs;
        cf_error err = {0};
        if (cf_fitfile_load_spec(a->elastic, &fs, &err) != CF_OK) {
            rc = cf_cli_fail(&err);
        } else {
            a->vopt.elastic = cf_ident_of(&fs.params, 0);
            a->vopt.hold_elastic = 1;
        }
    }
    return rc;
}

/* Fits every job on up to a->jobs threads. */
static void run_pool(const fit_args *a, fit_job *jobs)
{
    pool p = {jobs, a->nfiles, 0, PTHREAD_MUTEX_INITIALIZER};
    int nt = (int)(a->jobs < a->nfiles ? a->jobs : a->nfiles);
    pthread_t th[256];
    int started = 0;
    for (int t = 1; t < nt; t++)
        if (pthread_create(&th[started], NULL, worker, &p) == 0)
            started++;
    worker(&p);
    for (int t = 0; t < started; t++)
        pthread_join(th[t], NULL);
}

/* All outputs or none: they go in place only when every table succeeded. Returns 1 when none
** was put in place because a job failed. */
static int commit_outputs(const fit_args *a, fit_job *jobs)
{
    int failed = 0;
    for (int i = 0; i < a->nfiles; i++)
        failed |= jobs[i].st != CF_OK;
    for (int i = 0; i < a->nfiles && !failed; i++) {
        fit_job *j = &jobs[i];
        if ((j->json_path[0] && (j->st = cf_atomic_commit(&j->json_out, &j->err)) != CF_OK) ||
            (j->plot_path[0] && (j->st = cf_atomic_commit(&j->plot_out, &j->err)) != CF_OK))
            failed = 1;
    }
    for (int i = 0; i < a->nfiles; i++) {
        cf_atomic_abort(&jobs[i].json_out);
        cf_atomic_abort(&jobs[i].plot_out);
        if (failed && jobs[i].st == CF_OK)
            jobs[i].json_path[0] = jobs[i].plot_path[0] = '\0'; /* not written */
    }
    return failed;
}

/* What one job prints: its error, or the fit file on standard output (-o -), its report, where
** its files went, and its warnings. Returns its exit status. */
static int report_job(const fit_args *a, fit_job *j)
{
    if (j->st != CF_OK)
        return cf_cli_fail(&j->err);
    int rc = CF_EXIT_OK;
    if (cf_cli_is_stdio(a->out)) {
        char *json = cf_report_json_string(&j->rep);
        if (!json || fputs(json, stdout) < 0 || fflush(stdout) != 0) {
            cf_error e = {0};
            cf_error_set(&e, json ? CF_E_CANTWRITE : CF_E_INTERNAL,
                         "cannot write the fit file to standard output");
            rc = cf_cli_fail(&e);
        }
        free(json);
    }
    if (j->text) {
        fputs(j->text, stdout);
        if (j->json_path[0])
            printf("Fit file: %s\n", j->json_path);
        if (j->plot_path[0])
            printf("Plot: %s\n", j->plot_path);
        if (a->nfiles > 1)
            fputc('\n', stdout);
    }
    for (int k = 0; k < j->rep.nfits; k++) {
        fit_warnings(j->file, &j->rep, &j->rep.fits[k]);
        const cf_validation *v = &j->rep.val[k];
        if (j->rep.validate && v->done && v->unstable_in_range)
            fprintf(stderr,
                    "conifit: warning: %s: the %s spring's lattice loses stability at strain "
                    "%.4g, inside the table's range\n",
                    j->file, cf_spring_type_name(j->rep.fits[k].type), v->stable_to_strain);
    }
    return rc;
}

/* One row of the summary of several tables. */
static void summary_row(const fit_args *a, const fit_job *j, int wname)
{
    if (j->st != CF_OK) {
        printf("  %-*s failed\n", wname, j->file);
        return;
    }
    if (j->m.t) {
        printf("  %-*s time series: %d Prony term%s, RMSE %.4g %s\n", wname, j->file,
               j->vrep.fit.p.nbranch, j->vrep.fit.p.nbranch == 1 ? "" : "s",
               j->vrep.fit.rmse * j->m.y_to_file, j->m.y_unit);
        return;
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
    if (a->popt.validate && b >= 0 && j->rep.val[b].done)
        snprintf(vcell, sizeof vcell, " %.4g %s", j->rep.val[b].rmse * j->m.y_to_file,
                 j->m.y_unit);
    else if (a->popt.validate)
        snprintf(vcell, sizeof vcell, " skipped");
    printf("  %-*s %-18s %-18s %-22s %-16s%s\n", wname, j->file, cell[0], cell[1], bcell,
           b < 0                          ? "none feasible"
           : cf_report_types_tie(&j->rep) ? "tie"
                                          : cf_spring_type_name(j->rep.fits[b].type),
           vcell);
}

/* The summary of several tables: one row each. */
static void print_summary(const fit_args *a, const fit_job *jobs)
{
    int wname = 5;
    for (int i = 0; i < a->nfiles; i++)
        if ((int)strlen(jobs[i].file) > wname)
            wname = (int)strlen(jobs[i].file);
    printf("Summary (RMSE in each table's unit):\n");
    printf("  %-*s %-18s %-18s %-22s %-16s%s\n", wname, "table", "telescoping", "non-telescoping",
           "best baseline", "better type", a->popt.validate ? " lattice RMSE (better type)" : "");
    for (int i = 0; i < a->nfiles; i++)
        summary_row(a, &jobs[i], wname);
}

/* Fits the jobs, puts their outputs in place (all or none), prints each report and the summary.
** Returns the exit status: the first failure's, else 0. */
static int fit_all(const fit_args *a, fit_job *jobs)
{
    run_pool(a, jobs);
    const int failed = commit_outputs(a, jobs);
    int rc = CF_EXIT_OK;
    for (int i = 0; i < a->nfiles; i++) {
        const int e = report_job(a, &jobs[i]);
        if (jobs[i].st != CF_OK) /* the first failed table's status stands */
            rc = rc == CF_EXIT_OK ? e : rc;
        else if (e != CF_EXIT_OK) /* a fit file that standard output refused */
            rc = e;
    }
    if (failed && (a->out || a->plot))
        fprintf(stderr, "conifit: no output file written (outputs are written only when every "
                        "table succeeds)\n");
    if (a->nfiles > 1 && !a->quiet)
        print_summary(a, jobs);
    return rc;
}

/* fit: parse, name every output, read every input, then fit them all (fit_all) or jointly
** (run_joint). */
int cf_cli_fit(int argc, char **argv)
{
    fit_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0)
        return rc;
    fit_job *jobs = calloc((size_t)a.nfiles, sizeof *jobs);
    /* every input of the run, never to be an output */
    const char **inputs = calloc((size_t)a.nfiles + 3, sizeof *inputs);
    if (!jobs || !inputs) {
        free(jobs);
        free(inputs);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    for (int i = 0; i < a.nfiles; i++)
        inputs[i] = a.files[i];
    inputs[a.nfiles] = a.scene;
    inputs[a.nfiles + (a.scene != NULL)] = a.elastic;
    if (!a.joint)
        rc = plan_outputs(&a, jobs, inputs);
    int nseries = 0;
    if (rc < 0)
        rc = load_inputs(&a, jobs, &nseries);
    if (a.progress)
        a.popt.progress = show_progress;
    if (rc < 0 && a.joint)
        rc = nseries ? cf_cli_usage_error("fit", "--joint fits stress-strain tables; a time "
                                                 "series is fitted on its own")
                     : run_joint(&a, jobs, inputs);
    if (rc < 0)
        rc = fit_all(&a, jobs);
    for (int i = 0; i < a.nfiles; i++) {
        cf_table_free(&jobs[i].m);
        free(jobs[i].text);
        cf_report_free(&jobs[i].rep);
        cf_visco_report_free(&jobs[i].vrep);
    }
    free(jobs);
    free(inputs);
    return rc;
}
