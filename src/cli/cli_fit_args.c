/*
** The command line of `conifit fit` (cli_fit.h): the help, the options and the checks across
** them.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/cli_fit.h"
#include "cli/cli_summary.h"
#include "model/calibration.h"
#include "fit/fit.h"
#include "io/measures.h"
#include "conifit/spring.h"
#include "report/plot.h"

static const char fit_help[] =
    "usage: conifit fit TABLE... [-o OUT.json | -o DIR/ | -o -] [options]\n"
    "Fits the design parameters D1, D2, n, d [mm], G [MPa], H [mm] of a conical spring to a\n"
    "measured stress-strain (or force-displacement) table, for each spring type, with linear,\n"
    "Duffing, Fung, Yeoh and one-term Ogden baselines beside it (Yeoh and Ogden in the table's\n"
    "test mode). Prints a report; -o writes the JSON fit file.\n\n"
    "  TABLE                   .csv or .txt table; '-' reads one from standard input\n"
    "  -o, --output OUT.json | DIR/ | -   fit file (one table), folder (one NAME.json per\n"
    "                          table), or '-': the fit file on standard output (no report)\n"
    "  --type T                telescoping | non-telescoping | both (default both)\n"
    "  --law L                 conical | conical-tail | auto | double-acting (default\n"
    "                          conical): the conical spring, one with a cylindrical tail in\n"
    "                          series (a fourth quantity, the tail's compliance), a\n"
    "                          double-acting element (its own conical spring for extension,\n"
    "                          six quantities; by the joint fit, of one table or several),\n"
    "                          or all of them, kept by AIC (the pair with --joint);\n"
    "                          to the spring or through the lattice as the conical law,\n"
    "                          jointly with --joint (not with --fix or time series; a\n"
    "                          series holds a tailed spring with --elastic)\n"
    "  --fix NAME=VALUE        hold a parameter: D1, D2, d, H in mm, G in MPa, n (repeatable)\n"
    "  --index-max C           largest spring index D1/d, 3..50 (default 12; the smallest is 3)\n"
    "  --rho-min R             smallest diameter ratio D1/D2, 0.001..1 (default 0.05)\n"
    "  --n-max N               most active coils, 2..1000 (default 30; the fewest is 2), of\n"
    "                          the cone and of a tail\n"
    "  --D2-max-H R            largest outer diameter in free lengths, D2/H, up to 1000\n"
    "                          (default 10)\n"
    "  --G-max G               stiffest wire, shear modulus in MPa, up to 1e6 (default 80000,\n"
    "                          steel)\n"
    "  --relative              residuals relative to |stress| instead of absolute\n"
    "  --optimizer NAME        slsqp (default) | cobyla | mma: the constrained local optimiser\n"
    "  --seed S                seed of the global search (default 1); same seed, same result\n"
    "  --starts N              local starts of the global search (default 8)\n"
    "  --validate [SCENE.json] fit through the lattice (the scene's, or 3x3x3 cells calibrated\n"
    "                          isotropic) at the table's strains in the table's mode, check the\n"
    "                          spring in the full lattice and report both RMSEs in the table's\n"
    "                          stress unit (stress-strain tables)\n"
    "  --target lattice|spring what the fit's numbers are of: the lattice's curve in the table's\n"
    "                          mode (default with --validate and for every mode but uniaxial;\n"
    "                          implies --validate) or the single spring's (default otherwise;\n"
    "                          with --validate: the bare spring, then run in the lattice)\n"
    "  --through-msm [SCENE.json]  --target lattice [--validate SCENE.json]\n"
    "  --max-memory SIZE, --max-steps N, --max-work N  the validation's budget, as for\n"
    "                          simulate (defaults 2G, 1e7 static solves and 1e10 spring-steps\n"
    "                          of work): a larger lattice or table is refused\n"
    "  --joint                 one lattice for every table (one or more), each in its own\n"
    "                          mode\n"
    "  --fibres GROUPS         with --joint on biaxial and shear tables in a fibre frame (see\n"
    "                          --plane): also fit a lattice with a tension-only conical spring\n"
    "                          per cell along each named axis (f, s, n: e.g. f, fs, fn), each\n"
    "                          slack to its own fitted recruitment strain, on a matrix lattice\n"
    "                          of fitted family weights, beside the Holzapfel-Ogden baselines,\n"
    "                          for either cross-fibre axis\n"
    "  --calibration C         isotropic (default), axial, or fitted (with --joint)\n"
    "  --anisotropy-max A      with --calibration fitted: the fitted weights keep the springs'\n"
    "                          Zener ratio 2 C44/(C11 - C12) within [1 - A, 1 + A] (0.01..1;\n"
    "                          default: any weights in the search's box)\n"
    "  --volume fit            a volume term (kappa/2)(J - 1)^2 in every cell, kappa fitted\n"
    "                          (with --joint)\n"
    "  --volume-modulus K      the volume term's kappa declared, in the first table's stress\n"
    "                          unit, at most 1e6 MPa\n"
    "                          (with --joint)\n"
    "  --poisson NU            the lattice's small-strain nu declared, 0.25 <= NU < 0.5: kappa\n"
    "                          from it (with --joint; a double-acting element: its compression\n"
    "                          side)\n"
    "  --mode M                the table's test mode: uniaxial, shear, planar, equibiaxial,\n"
    "                          confined or biaxial (wins over a '# mode:' comment; default\n"
    "                          uniaxial; a biaxial table holds both directions' strain and\n"
    "                          stress columns and a '# ratio: A:B' comment)\n"
    "  --plane PLANE           where shear and biaxial tables lie in the fibre frame (f, s, n):\n"
    "                          ij for every table, or NAME=ij,NAME=ij... by file name without\n"
    "                          folder and extension (shear ij: i the normal of the sheared\n"
    "                          face, j the direction of shear; wins over a '# plane:' comment)\n"
    "  --plot FILE.png|.svg|.pdf  draw data, fits, baselines and residuals with gnuplot\n"
    "                          (with several tables: a folder DIR/, one NAME.png per table)\n"
    "  --title TEXT            title of the plot (default: the table's file name without\n"
    "                          folder and extension)\n"
    "  --x-col NAME, --y-col NAME   columns to use in wider tables (a name or a number)\n"
    "  --columns X,Y[,W]       the x, y (and weight) columns, by name or number, and no\n"
    "                          others: a time or weight column is then ignored\n"
    "  --header-row N          the header is line N (default: found after any preamble)\n"
    "  --stress-unit U         unit of a stress column without one (Pa, kPa, MPa, ...)\n"
    "  --force-unit U          unit of a force column without one (N, mN, ...)\n"
    "  --length-unit U         unit of a displacement column without one (mm, m, ...)\n"
    "  --stretch               the x column is stretch (strain = stretch - 1)\n"
    "  --stress-measure M      nominal | cauchy: what the stress column holds (default: the\n"
    "                          table's '# stress:' comment or column name, else nominal);\n"
    "                          Cauchy stress is converted to nominal under incompressibility\n"
    "  --strain-measure M      engineering | log | stretch (default: '# strain:' or the name)\n"
    "  -j, --jobs N            fit N tables at a time (default 1)\n"
    "  --shard K/N             fit share K (1..N) of N of the tables, sorted by name (every\n"
    "                          N-th), into -o DIR/, each fit file as soon as its table is done,\n"
    "                          skipping tables already fitted with the same options; writes\n"
    "                          DIR/summary-K-of-N.tsv, a failed table as a row (conifit merge\n"
    "                          joins them)\n";

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
    "                          (and its tail's compliance e_t when it has a cylindrical tail:\n"
    "                          the model then runs the conical-tail law)\n"
    "  --calibration C         the lattice's weights: axial (default for a series) or isotropic\n"
    "  --max-evaluations N     stop after about N model runs, keeping the best model so far\n"
    "                          (default 200000; a warning says when it is reached)\n"
    "The fitted spring stays within the design limits (--rho-min, --index-max, ...) and its\n"
    "lattice stable up to the series' largest strain (a held --elastic spring whose lattice\n"
    "would buckle within the series is refused).\n\n"
    "Tables: a header row naming the columns, units in the names (stress_kPa, stress [kPa])\n"
    "or in a units row under the header ((s),(mm),(N) as testing machines write it), '#'\n"
    "comments, ',' ';' TAB or blank-separated columns, an optional weight column. Tension\n"
    "positive. A spreadsheet (.xlsx, .ods) must be saved as CSV first. What the reader noticed\n"
    "(a skipped preamble, units from a units row, ...) is warned and kept in the report and in\n"
    "the fit file (data.notes).\n";

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
    OPT_PLANE,
    OPT_JOINT,
    OPT_FIBRES,
    OPT_CALIBRATION,
    OPT_ANISOTROPY_MAX,
    OPT_X_COL,
    OPT_Y_COL,
    OPT_COLUMNS,
    OPT_HEADER_ROW,
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
    OPT_MAX_EVALUATIONS,
    OPT_TITLE,
    OPT_STRESS_MEASURE,
    OPT_STRAIN_MEASURE,
    OPT_MAX_MEMORY,
    OPT_MAX_STEPS,
    OPT_MAX_WORK,
    OPT_LAW,
    OPT_VOLUME,
    OPT_VOLUME_MODULUS,
    OPT_POISSON
};

static const struct option fit_options[] = {
    {"plot", required_argument, NULL, OPT_PLOT},
    {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
    {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
    {"max-work", required_argument, NULL, OPT_MAX_WORK},
    {"type", required_argument, NULL, OPT_TYPE},
    {"law", required_argument, NULL, OPT_LAW},
    {"volume", required_argument, NULL, OPT_VOLUME},
    {"volume-modulus", required_argument, NULL, OPT_VOLUME_MODULUS},
    {"poisson", required_argument, NULL, OPT_POISSON},
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
    {"plane", required_argument, NULL, OPT_PLANE},
    {"joint", no_argument, NULL, OPT_JOINT},
    {"fibres", required_argument, NULL, OPT_FIBRES},
    {"calibration", required_argument, NULL, OPT_CALIBRATION},
    {"anisotropy-max", required_argument, NULL, OPT_ANISOTROPY_MAX},
    {"x-col", required_argument, NULL, OPT_X_COL},
    {"y-col", required_argument, NULL, OPT_Y_COL},
    {"columns", required_argument, NULL, OPT_COLUMNS},
    {"header-row", required_argument, NULL, OPT_HEADER_ROW},
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
    {"max-evaluations", required_argument, NULL, OPT_MAX_EVALUATIONS},
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

/* --columns X,Y[,W]: two or three names or numbers, none empty (the table says whether they
** exist). */
static int columns_option(const char *optval, cf_measure_options *mo)
{
    int parts = 1, empty = optval[0] == ',' || optval[0] == '\0';
    for (const char *c = optval; *c; c++)
        if (*c == ',') {
            parts++;
            empty |= c[1] == ',' || c[1] == '\0';
        }
    if (parts < 2 || parts > 3 || empty)
        return cf_cli_usage_error("fit", "--columns '%s': expected X,Y or X,Y,W (names or "
                                         "numbers from 1 of the x, y and weight columns)",
                                  optval);
    mo->columns = optval;
    return 0;
}

/* The options of fit by group: each applies an option of its group (0 to go on, else an exit
** status) and returns NOT_MINE for any other. */
#define NOT_MINE (-1)

/* The design limits and held parameters (--fix, --index-max, --rho-min, --n-max,
** --D2-max-H, --G-max). */
static int limits_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    cf_fit_options *fo = &a->popt.fit;
    switch (c) {
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
    default: return NOT_MINE;
    }
}

/* The fit's search: the spring type, the law, the residuals, the optimiser, seed and starts. */
static int search_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    cf_fit_options *fo = &a->popt.fit;
    long n;
    switch (c) {
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
    case OPT_RELATIVE: fo->relative = 1; return 0;
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
    case OPT_LAW:
        if (cf_law_kind_parse(optval, &fo->law, &err) != CF_OK)
            return cf_cli_usage_error("fit", "--law: %s", err.msg);
        return 0;
    default: return NOT_MINE;
    }
}

/* The lattice: validation, the fit's target, the joint fit, the volume term, the
** calibration, the validation's budget. */
static int lattice_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    cf_fit_options *fo = &a->popt.fit;
    switch (c) {
    case OPT_MAX_MEMORY:
        return cf_cli_budget_option("fit", "--max-memory", optval, &a->popt.budget);
    case OPT_MAX_STEPS:
        return cf_cli_budget_option("fit", "--max-steps", optval, &a->popt.budget);
    case OPT_MAX_WORK:
        return cf_cli_budget_option("fit", "--max-work", optval, &a->popt.budget);
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
    case OPT_FIBRES: {
        const size_t n = strlen(optval);
        int seen = 0;
        for (size_t k = 0; k < n && n <= 3; k++) {
            const char *at = strchr("fsn", optval[k]);
            const int bit = at && optval[k] ? 1 << (at - "fsn") : 0;
            seen = !bit || (seen & bit) ? -1 : seen | bit;
            if (seen < 0)
                break;
        }
        if (n < 1 || n > 3 || seen < 0)
            return cf_cli_usage_error("fit", "--fibres '%s': one to three of the fibre-frame "
                                             "axes f, s and n, each once (e.g. f, fs, fn)",
                                      optval);
        a->popt.fibres = optval;
        return 0;
    }
    case OPT_VOLUME:
        if (strcmp(optval, "fit") != 0)
            return cf_cli_usage_error("fit", "--volume '%s': expected fit (or declare kappa with "
                                             "--volume-modulus, nu with --poisson)", optval);
        if (fo->volume != CF_VOLUME_NONE && fo->volume != CF_VOLUME_FIT)
            return cf_cli_usage_error("fit", "--volume fit: kappa is declared already (one of "
                                             "--volume, --volume-modulus, --poisson)");
        fo->volume = CF_VOLUME_FIT;
        return 0;
    case OPT_VOLUME_MODULUS:
    case OPT_POISSON: {
        const int modulus = c == OPT_VOLUME_MODULUS;
        const char *name = modulus ? "--volume-modulus" : "--poisson";
        double v;
        if (cf_cli_parse_double(name, optval, &v, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (modulus && !(v >= 0 && isfinite(v)))
            return cf_cli_usage_error("fit", "--volume-modulus %s: kappa must be >= 0 (in the "
                                             "first table's stress unit) and at most %g MPa",
                                      optval, CF_KAPPA_MAX_MPA);
        if (!modulus && !(v >= 0.25 && v < 0.5))
            return cf_cli_usage_error("fit", "--poisson %s: nu must lie in [0.25, 0.5) (a lattice "
                                             "of central springs has 0.25; 0.5 is "
                                             "incompressible)", optval);
        if (fo->volume != CF_VOLUME_NONE)
            return cf_cli_usage_error("fit", "%s %s: kappa is set already (one of --volume, "
                                             "--volume-modulus, --poisson)", name, optval);
        fo->volume = modulus ? CF_VOLUME_MODULUS : CF_VOLUME_POISSON;
        fo->volume_value = v;
        return 0;
    }
    case OPT_ANISOTROPY_MAX: {
        double v;
        if (cf_cli_parse_double("--anisotropy-max", optval, &v, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        if (!(v >= 0.01 && v <= 1))
            return cf_cli_usage_error("fit", "--anisotropy-max %s: the Zener ratio's allowed "
                                             "departure from 1 must lie in [0.01, 1]",
                                      optval);
        fo->anisotropy_max = v;
        return 0;
    }
    case OPT_CALIBRATION: {
        cf_lattice_config *lc = &a->popt.lattice.cfg.lattice;
        if (cf_calibration_parse(optval, &lc->calibration, &err) != CF_OK)
            return cf_cli_usage_error("fit", "--%s", err.msg);
        if (lc->calibration != CF_CAL_FITTED)
            cf_calibration_weights(lc->calibration, lc->weight, NULL);
        a->calibration_given = 1;
        return 0;
    }
    default: return NOT_MINE;
    }
}

/* The table's reading: mode, columns, header row, units, stretch, measures. */
static int table_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    long n;
    switch (c) {
    case OPT_MODE: {
        cf_mode md;
        if (cf_mode_parse(optval, &md, &err) != CF_OK)
            return cf_cli_usage_error("fit", "--%s", err.msg);
        a->mopt.mode = optval;
        return 0;
    }
    case OPT_PLANE: a->mopt.plane = optval; return 0;
    case OPT_X_COL: a->mopt.x_col = optval; return 0;
    case OPT_Y_COL: a->mopt.y_col = optval; return 0;
    case OPT_COLUMNS: return columns_option(optval, &a->mopt);
    case OPT_HEADER_ROW:
        if (cf_cli_parse_long("--header-row", optval, 1, CF_MEASURE_MAX_LINES, &n, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        a->mopt.header_row = (size_t)n;
        return 0;
    case OPT_STRESS_UNIT: a->mopt.stress_unit = optval; return 0;
    case OPT_FORCE_UNIT: a->mopt.force_unit = optval; return 0;
    case OPT_LENGTH_UNIT: a->mopt.length_unit = optval; return 0;
    case OPT_STRETCH: a->mopt.x_is_stretch = 1; return 0;
    case OPT_STRESS_MEASURE:
    case OPT_STRAIN_MEASURE: return measure_option(c, optval, &a->mopt);
    default: return NOT_MINE;
    }
}

/* Time series: Prony branches, dashpot, relaxation, the held elastic fit, evaluations. */
static int series_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    long n;
    switch (c) {
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
    case OPT_MAX_EVALUATIONS:
        if (cf_cli_parse_long("--max-evaluations", optval, 1, 1000000000L, &n, &err) != CF_OK)
            return cf_cli_usage_error("fit", "%s", err.msg);
        a->vopt.max_evaluations = n;
        a->series_only = 1;
        return 0;
    default: return NOT_MINE;
    }
}

/* The plot and its title, the jobs. */
static int output_option(fit_args *a, int c, const char *optval)
{
    cf_error err = {0};
    switch (c) {
    case OPT_PLOT: a->plot = optval; return 0;
    case OPT_TITLE: a->popt.title = optval; return 0;
    case 'j':
        if (cf_cli_parse_long("-j", optval, 1, 256, &a->jobs, &err))
            return cf_cli_usage_error("fit", "%s", err.msg);
        return 0;
    default: return NOT_MINE;
    }
}

/* One option of fit: 0 to go on, else an exit status. */
static int fit_option_apply(void *ctx, int c, const char *optval)
{
    static int (*const groups[])(fit_args *, int, const char *) = {
        limits_option, search_option, lattice_option, table_option, series_option, output_option};
    for (size_t k = 0; k < sizeof groups / sizeof groups[0]; k++) {
        const int rc = groups[k](ctx, c, optval);
        if (rc != NOT_MINE)
            return rc;
    }
    return cf_cli_usage_error("fit", "unexpected option");
}

/* Appends the escaped word w (n bytes) to a->options, a blank before it unless first. */
static int record_word(fit_args *a, const char *w, size_t n)
{
    char *e = cf_summary_escape(w, n, 1);
    size_t have = a->options ? strlen(a->options) : 0;
    char *grown = e ? realloc(a->options, have + strlen(e) + 2) : NULL;
    if (!grown) {
        free(e);
        return -1;
    }
    snprintf(grown + have, strlen(e) + 2, "%s%s", have ? " " : "", e);
    a->options = grown;
    free(e);
    return 0;
}

/* Applies one option and records it in a->options by its long name, whatever form it was
** given in (short, abbreviated, --name=value), for the options of a sharded study; -j, which
** changes no fit, is not recorded (nor -o, -q, --progress, which never reach here). */
static int fit_option(void *ctx, int c, const char *optval)
{
    fit_args *a = ctx;
    const char *scene = a->scene;
    int rc = fit_option_apply(ctx, c, optval);
    if (rc != 0 || c == 'j')
        return rc;
    const char *name = NULL;
    for (const struct option *o = fit_options; o->name && !name; o++)
        if (o->val == c)
            name = o->name;
    if (!optval && (c == OPT_VALIDATE || c == OPT_THROUGH) && a->scene != scene)
        optval = a->scene; /* --validate SCENE.json */
    char flag[64];
    snprintf(flag, sizeof flag, "--%s", name ? name : "?");
    if (record_word(a, flag, strlen(flag)) != 0 ||
        (optval && record_word(a, optval, strlen(optval)) != 0)) {
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    return 0;
}

/* The operands and the checks across options. -1 to go on, else an exit status. */
int cf_cli_fit_parse(int argc, char **argv, fit_args *a)
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
    if (a->mopt.columns && (a->mopt.x_col || a->mopt.y_col))
        return cf_cli_usage_error(cmd, "--columns names x and y already: leave out --x-col and "
                                       "--y-col");
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
    /* a double-acting element is fitted by the joint fit, of one table as of several */
    if (a->popt.fit.law == CF_KIND_DOUBLE && a->popt.target == CF_TARGET_SPRING)
        return cf_cli_usage_error(cmd, "--law double-acting --target spring: the element is "
                                       "fitted through the lattice (drop --target spring)");
    if (!a->joint && a->popt.fit.law == CF_KIND_DOUBLE && a->nfiles > 1)
        return cf_cli_usage_error(cmd, "--law double-acting with %d tables: fit them together "
                                       "(--joint) or one at a time", a->nfiles);
    if (a->popt.fit.law == CF_KIND_DOUBLE)
        a->joint = 1;
    if (!a->joint && a->popt.fit.volume != CF_VOLUME_NONE)
        return cf_cli_usage_error(cmd, "%s: the volume term is fitted through the lattice with "
                                       "several tables (--joint)",
                                  a->popt.fit.volume == CF_VOLUME_FIT       ? "--volume fit"
                                  : a->popt.fit.volume == CF_VOLUME_POISSON ? "--poisson"
                                                                            : "--volume-modulus");
    if (a->popt.fit.law == CF_KIND_DOUBLE && a->popt.fit.volume == CF_VOLUME_POISSON)
        return cf_cli_usage_error(cmd, "--poisson %g with --law double-acting: its lattice has one "
                                       "small-strain nu in compression and another in tension; "
                                       "declare kappa (--volume-modulus) or fit it (--volume fit)",
                                  a->popt.fit.volume_value);
    if (a->joint && a->popt.fit.law == CF_KIND_TAIL && a->popt.fit.volume != CF_VOLUME_NONE)
        return cf_cli_usage_error(cmd, "--law conical-tail has no volume term yet (use conical, "
                                       "double-acting or auto)");
    const int fitted =
        a->calibration_given && a->popt.lattice.cfg.lattice.calibration == CF_CAL_FITTED;
    if (fitted && (!a->joint || a->nfiles < 2))
        return cf_cli_usage_error(cmd, "--calibration fitted: the family weights are fitted in a "
                                       "joint fit of several modes (--joint)");
    if (a->popt.fit.anisotropy_max > 0 && !fitted)
        return cf_cli_usage_error(cmd, "--anisotropy-max %g: it bounds fitted weights (add "
                                       "--calibration fitted)", a->popt.fit.anisotropy_max);
    if (a->popt.fibres && !a->joint)
        return cf_cli_usage_error(cmd, "--fibres %s: the fibre-reinforced lattice is fitted "
                                       "jointly to biaxial and shear tables (--joint)",
                                  a->popt.fibres);
    if (a->joint && a->out && (cf_cli_is_stdio(a->out) || cf_cli_is_dir_target(a->out)))
        return cf_cli_usage_error(cmd, "--joint -o %s: a joint fit writes one fit file "
                                       "(-o FILE.json)", a->out);
    if (a->joint && a->plot && cf_cli_is_dir_target(a->plot))
        return cf_cli_usage_error(cmd, "--joint --plot %s: a joint fit draws one figure "
                                       "(--plot FILE.png)", a->plot);
    if (a->joint) {
        if (a->plot && cf_plot_check_name(a->plot, &err) != CF_OK)
            return cf_cli_usage_error(cmd, "--plot %s: the file must end in .png or .svg",
                                      a->plot);
        return -1;
    }
    if (a->nfiles > 1 && a->out && !cf_cli_is_dir_target(a->out))
        return cf_cli_usage_error(cmd, "-o %s: with %d tables, -o must name a folder (DIR/)",
                                  a->out, a->nfiles);
    if (a->nfiles > 1 && a->plot && !cf_cli_is_dir_target(a->plot))
        return cf_cli_usage_error(cmd, "--plot %s: with %d tables, --plot must name a folder",
                                  a->plot, a->nfiles);
    if (a->plot && !cf_cli_is_dir_target(a->plot) && cf_plot_check_name(a->plot, &err) != CF_OK)
        return cf_cli_usage_error(cmd, "--plot %s: the file must end in .png, .svg or .pdf", a->plot);
    return -1;
}

