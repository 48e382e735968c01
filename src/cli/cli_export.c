/*
** The export subcommand: a fitted spring, or the whole calibrated lattice, written for another
** simulator (see export.h). The whole output is produced in memory first, so a failure never
** leaves partial output on stdout or in the -o file.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "pipeline/export.h"
#include "export/export.h"
#include "io/fitfile.h"
#include "io/budget.h"
#include "io/scene.h"
#include "cli/cli_body.h"

static const char export_help[] =
    "usage: conifit export FIT.json --format F [--type T] [-o FILE] [--tol REL] [--range LO:HI]\n"
    "                      [--example]\n"
    "       conifit export FIT.json --lattice [SCENE.json] --format F [--type T] [-o FILE]\n"
    "                      [--tol REL]\n"
    "Writes a fitted spring for another simulator as a force-displacement table within --tol\n"
    "of F_C of the law (nodes placed where the interpolation error is, the achieved error\n"
    "measured on an independent dense grid). With --lattice, writes the validation lattice\n"
    "built from the spring (every spring family with its weight and its own table, boundary\n"
    "conditions, the uniaxial loading of SCENE.json or, without it, 20 steps to half the solid\n"
    "strain, and output requests) as a model that runs in the target as it is; conifit's own\n"
    "reaction at every step is written in its header. A time protocol (hold, cycles, history)\n"
    "is written as its quasi-static displacement history, one static step per sample, of the\n"
    "elastic lattice (a stress drive through the strains conifit's elastic lattice takes under\n"
    "it), a warning naming what is not carried (Prony terms, dashpots, inertia): the header's\n"
    "reactions are conifit's elastic run along that path. A loading the lattice cannot follow\n"
    "(unstable, past a table, no solution) is cut after its last step that works, with a\n"
    "warning and a note in the header (refused only when its first step fails). A SCENE.json\n"
    "with a body (calculix, febio; sofa without a volume term, poisson_ratio 0.25) writes the\n"
    "body: every edge a spring with its own table, the volume term per node as conifit\n"
    "takes it (calculix: a grounded spring per node tied by *EQUATION to its volume change\n"
    "about conifit's solved state at each step; febio: tet4 in a ut4 domain with alpha 0),\n"
    "the held nodes, and the flat punch replayed as conifit ran it: its contact set at every\n"
    "step (calculix: conifit's penalty springs against nodes of the punch's face, one *STEP\n"
    "per load step; febio, sofa: each contact node moved along z as conifit solved it), with\n"
    "a warning that the contact is replayed, not solved; conifit's probe force at every step\n"
    "in its header (a sphere probe is refused). Row count and error go to stderr.\n"
    "Units: mm, N, s, tonne (stated inside each file).\n\n"
    "  FIT.json         '-' reads the fit file from standard input\n"
    "  --format F       one of the formats below (default: the format -o's extension names)\n"
    "  --type T         telescoping | non-telescoping (default: the fit's better type)\n"
    "  -o, --output F   output file (default, or '-': standard output); written atomically\n"
    "  --tol REL        table tolerance as a fraction of F_C, 1e-9..0.1 (default 1e-4; for\n"
    "                   formats whose target reads a limited table, without --tol, the\n"
    "                   smallest of 1e-4, 2e-4, 5e-4, ... whose table fits (CalculiX: 200 pairs))\n"
    "  --range LO:HI    compressions (mm, > 0 shortens) the table covers, LO <= 0 <= HI, e.g.\n"
    "                   0:4.5 for compression only (default: full stretch to just before solid)\n"
    "  --example        a complete one-spring model that runs as it is (formats with models;\n"
    "                   sofa always writes a scene)\n"
    "  --lattice        the whole lattice model (see above)\n"
    "  --max-memory SIZE, --max-steps N, --max-work N  the budget of SCENE.json's lattice and\n"
    "                   conifit's static run on it, as for simulate (refused, exit 65, naming\n"
    "                   the key and a value that would fit)\n\n"
    "FIT.json is a fit file (conifit fit -o) or an exported spring (--format json).\n";

/* The formats, from the export module's registry. */
static void formats_help(FILE *out)
{
    fputs("\nFormats (--format; models: also --example and --lattice):\n"
          "  name      file   models  what the block is\n",
          out);
    for (int f = 0; f < CF_EXPORT_FORMAT_COUNT; f++) {
        const cf_export_format_info *fi = cf_export_format_get((cf_export_format)f);
        fprintf(out, "  %-9s %-6s %-7s %s\n", fi->name, fi->extension, fi->model ? "yes" : "no",
                fi->description);
    }
    fputc('\n', out);
}

/* Parses "LO:HI" (mm). */
static cf_status parse_range(const char *text, double *lo, double *hi, cf_error *err)
{
    const char *colon = text ? strchr(text, ':') : NULL;
    if (!colon)
        return cf_error_set(err, CF_E_USAGE, "option --range: '%s' is not LO:HI (mm)",
                            text ? text : "");
    char a[64];
    size_t n = (size_t)(colon - text);
    if (n == 0 || n >= sizeof a)
        return cf_error_set(err, CF_E_USAGE, "option --range: '%s' is not LO:HI (mm)", text);
    memcpy(a, text, n);
    a[n] = '\0';
    if (cf_cli_parse_double("--range", a, lo, err) != CF_OK ||
        cf_cli_parse_double("--range", colon + 1, hi, err) != CF_OK)
        return CF_E_USAGE;
    if (*lo > 0.0 || *hi < 0.0 || !(*hi > *lo))
        return cf_error_set(err, CF_E_USAGE,
                            "option --range: %g:%g must have LO <= 0 <= HI and LO < HI (mm; the "
                            "rest state u = 0 is always in the table)",
                            *lo, *hi);
    return CF_OK;
}

enum {
    OPT_FORMAT = CF_CLI_OPT_OWN,
    OPT_TYPE,
    OPT_TOL,
    OPT_RANGE,
    OPT_EXAMPLE,
    OPT_LATTICE,
    OPT_MAX_MEMORY,
    OPT_MAX_STEPS,
    OPT_MAX_WORK
};

typedef struct export_args {
    cf_export_options opt;
    const char *type;
    int have_format, tol_given, lattice;
    cf_budget budget; /* of the scene's lattice and its static run (--lattice SCENE) */
} export_args;

/* One option of export: 0 to go on, else an exit status. */
static int export_option(void *ctx, int c, const char *value)
{
    export_args *a = ctx;
    cf_error err = {0};
    cf_spring_type t;
    switch (c) {
    case OPT_FORMAT:
        if (cf_export_format_parse(value, &a->opt.format, &err) != CF_OK)
            return cf_cli_usage_error("export", "option --format: %s", err.msg);
        a->have_format = 1;
        return 0;
    case OPT_TYPE:
        if (cf_spring_type_parse(value, &t, &err) != CF_OK)
            return cf_cli_usage_error("export", "option --type: %s", err.msg);
        a->type = value;
        return 0;
    case OPT_TOL:
        if (cf_cli_parse_double("--tol", value, &a->opt.tol, &err) != CF_OK)
            return cf_cli_usage_error("export", "%s", err.msg);
        if (a->opt.tol < CF_EXPORT_TOL_MIN || a->opt.tol > CF_EXPORT_TOL_MAX)
            return cf_cli_usage_error("export", "option --tol: %g is outside [%g, %g]",
                                      a->opt.tol, CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
        a->tol_given = 1;
        return 0;
    case OPT_RANGE:
        if (parse_range(value, &a->opt.u_lo_mm, &a->opt.u_hi_mm, &err) != CF_OK)
            return cf_cli_usage_error("export", "%s", err.msg);
        a->opt.have_range = 1;
        return 0;
    case OPT_EXAMPLE:
        a->opt.example = 1;
        return 0;
    case OPT_LATTICE:
        a->lattice = 1;
        return 0;
    case OPT_MAX_MEMORY:
        return cf_cli_budget_option("export", "--max-memory", value, &a->budget);
    case OPT_MAX_STEPS:
        return cf_cli_budget_option("export", "--max-steps", value, &a->budget);
    case OPT_MAX_WORK:
        return cf_cli_budget_option("export", "--max-work", value, &a->budget);
    default:
        return cf_cli_usage_error("export", "unexpected option");
    }
}

/* What the command line asked for. */
typedef struct export_request {
    export_args ea;
    const char *out_path, *fit_path, *scene_path;
    char scene_fit[4096]; /* the fit file the scene names, "" when none */
    int quiet;
    int body;             /* the scene holds a body: its model is in body_buf (body_len bytes) */
    char *body_buf;
    size_t body_len;
    cf_export_report body_rep;
} export_request;

/* Parses the arguments into q and checks their combinations (the format from -o's extension
** when not given). -1 to go on, else an exit status. */
static int parse_request(int argc, char **argv, export_request *q)
{
    static const struct option own[] = {{"format", required_argument, NULL, OPT_FORMAT},
                                        {"type", required_argument, NULL, OPT_TYPE},
                                        {"tol", required_argument, NULL, OPT_TOL},
                                        {"range", required_argument, NULL, OPT_RANGE},
                                        {"example", no_argument, NULL, OPT_EXAMPLE},
                                        {"lattice", no_argument, NULL, OPT_LATTICE},
                                        {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
                                        {"max-steps", required_argument, NULL, OPT_MAX_STEPS},
                                        {"max-work", required_argument, NULL, OPT_MAX_WORK},
                                        {NULL, 0, NULL, 0}};
    cf_error err = {0};
    export_args *ea = &q->ea;
    *ea = (export_args){cf_export_default_options(), NULL, 0, 0, 0, cf_budget_default()};
    cf_cli_parser p;
    int rc = cf_cli_parser_init(&p, "export", export_help, 0, argc, argv, "", own);
    p.help_extra = formats_help;
    if (rc || (rc = cf_cli_parse(&p, export_option, ea)) >= 0)
        return rc;
    q->out_path = p.output;
    q->quiet = p.quiet;
    const int npos = argc - optind;
    if (npos < 1)
        return cf_cli_usage_error("export", "missing the fit file");
    if (npos > (ea->lattice ? 2 : 1))
        return cf_cli_usage_error("export", "unexpected argument '%s'", argv[optind + npos - 1]);
    q->fit_path = argv[optind];
    q->scene_path = npos == 2 ? argv[optind + 1] : NULL;
    if (!ea->have_format) {
        if (!q->out_path || cf_cli_is_stdio(q->out_path))
            return cf_cli_usage_error("export", "missing option --format");
        if (cf_export_format_of_path(q->out_path, &ea->opt.format, &err) != CF_OK)
            return cf_cli_usage_error("export", "missing option --format: %s", err.msg);
    }
    const cf_export_format_info *fi = cf_export_format_get(ea->opt.format);
    char models[128];
    if ((ea->opt.example || ea->lattice) && !fi->model)
        return cf_cli_usage_error("export", "%s needs a simulator format (%s): %s is data, not "
                                            "a model",
                                  ea->opt.example ? "--example" : "--lattice",
                                  cf_export_format_list(models, sizeof models, 1), fi->name);
    if (ea->lattice && (ea->opt.example || ea->opt.have_range))
        return cf_cli_usage_error("export", "--lattice takes neither --example nor --range (the "
                                            "lattice's tables cover the whole travel)");
    return -1;
}

/* conifit's static run of the export (one solve a step, budget.h) against the step and work
** limits: CF_E_DATA naming samples_per_segment and the samples that would fit. */
static cf_status static_run_fits(const char *name, const cf_export_lattice *lx,
                                 const cf_scene_cost *cost, const cf_budget *b, cf_error *err)
{
    const double each = cf_budget_solve_work(3.0 * (double)cost->nodes);
    /* a stress drive: a force-driven run first, for the strains (export_lattice.c) */
    const double steps = (double)lx->nsteps * (lx->stress_drive ? 2.0 : 1.0);
    if (steps <= b->max_steps && steps * each <= b->max_work)
        return CF_OK;
    const double can = fmin(b->max_steps, floor(b->max_work / each));
    char fits[128];
    if (can >= 1)
        snprintf(fits, sizeof fits, "at most %.0f samples would fit", can);
    else
        snprintf(fits, sizeof fits, "not even one solve fits: reduce 'lattice.nx/ny/nz'");
    return cf_error_set(err, CF_E_DATA,
                        "%s: key 'samples_per_segment': the export's static run needs %.0f static "
                        "solves of %.3g spring-steps of work each, above the limit of %.4g steps "
                        "or %.3g of work (raise them with --max-steps and --max-work); %s",
                        name, steps, each, b->max_steps, b->max_work, fits);
}

/* A body scene's model into q->body_buf: the body solved with the fit file's element (a
** double-acting one's extension spring too, never its compression spring alone) as simulate
** solves it; the fit's lattice volume term is the body's (cf_scene_body_fit_volume). */
static cf_status body_model(export_request *q, const cf_fitted_spring *fs, cf_scene *sc,
                            cf_error *err)
{
    /* before solving: what cf_export_write_body refuses whatever the run gives */
    const cf_probe *pr = &sc->probe;
    if (sc->has_probe && (pr->shape != CF_PROBE_PUNCH || fabs(pr->dir[0]) > 1e-12 ||
                          fabs(pr->dir[1]) > 1e-12))
        return cf_error_set(err, CF_E_DATA, "probe: a body's export takes a flat punch moving "
                            "along z (its contact set replayed as prescribed z motions); a sphere "
                            "pushes its nodes along their own normals (%s)", q->scene_path);
    if (sc->body_nfibres > 0 && q->ea.opt.format != CF_EXPORT_CALCULIX)
        return cf_error_set(err, CF_E_DATA, "%s: key 'fibres': the body's fibre groups have no "
                            "form in this export; export it to calculix (%s)",
                            cf_export_format_name(q->ea.opt.format), q->scene_path);
    cf_status st = cf_scene_body_fit_volume(sc, q->scene_path, q->fit_path, fs, err);
    if (st != CF_OK)
        return st;
    sc->spring = fs->params;
    sc->extension = fs->extension;
    sc->has_extension = fs->has_extension;
    FILE *mem = open_memstream(&q->body_buf, &q->body_len);
    if (!mem)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    cf_export_options opt = q->ea.opt;
    opt.source = cf_cli_is_stdio(q->fit_path) ? "(standard input)" : q->fit_path;
    opt.output = q->out_path && !cf_cli_is_stdio(q->out_path) ? q->out_path : NULL;
    opt.auto_tol = !q->ea.tol_given;
    st = cf_cli_body_export(sc, q->scene_path, &q->ea.budget, mem, &opt, &q->body_rep, err);
    if (fclose(mem) != 0 && st == CF_OK)
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
    return st;
}

/* The lattice to export: the scene's (the fit file it names into q->scene_fit), or the
** validation's default for the spring. */
static cf_status lattice_of(export_request *q, const cf_fitted_spring *fs,
                            cf_export_lattice *lx, cf_error *err)
{
    cf_status st;
    const char *scene_path = q->scene_path;
    if (scene_path) {
        cf_scene sc;
        if ((st = cf_scene_load(scene_path, &sc, err)) != CF_OK)
            return st;
        snprintf(q->scene_fit, sizeof q->scene_fit, "%s", sc.fit_path);
        if (sc.has_body) {
            st = body_model(q, fs, &sc, err);
            q->body = 1;
            cf_scene_free(&sc);
            return st;
        }
        cf_scene_cost cost;
        if ((st = cf_budget_check_size(&sc, scene_path, &q->ea.budget, &cost, err)) == CF_OK &&
            (st = cf_export_lattice_from_scene(&sc, scene_path, lx, err)) == CF_OK)
            st = static_run_fits(scene_path, lx, &cost, &q->ea.budget, err);
        cf_scene_free(&sc);
        return st;
    }
    cf_law law;
    if ((st = cf_fitted_law(fs, &law, err)) != CF_OK)
        return st;
    *lx = cf_export_lattice_default(&law);
    lx->cfg.lattice.volume_modulus_MPa = fs->volume_modulus_MPa;
    if (cf_fitted_own_weights(fs)) { /* a joint fit's fitted weights: its lattice */
        memcpy(lx->cfg.lattice.weight, fs->weight, sizeof lx->cfg.lattice.weight);
        lx->cfg.lattice.calibration = CF_CAL_FITTED;
    }
    cf_law_free(&law);
    return CF_OK;
}

/* buf to the -o file (atomically) or to standard output. */
static cf_status emit(const export_request *q, const char *buf, size_t len, cf_error *err)
{
    if (q->out_path && strcmp(q->out_path, "-") != 0) {
        cf_atomic a;
        /* every input: the fit file, the scene and the fit file the scene names (none without
        ** a scene) */
        const char *inputs[4] = {q->fit_path, q->scene_path, q->scene_fit[0] ? q->scene_fit : NULL,
                                 NULL};
        cf_status st = cf_atomic_open(&a, q->out_path, inputs, err);
        if (st != CF_OK)
            return st;
        fwrite(buf, 1, len, a.fp);
        return cf_atomic_commit(&a, err);
    }
    if (fwrite(buf, 1, len, stdout) != len || fflush(stdout) != 0)
        return cf_error_set(err, CF_E_CANTWRITE, "cannot write to standard output");
    return CF_OK;
}

/* Rows and achieved error (and the lattice's size) on stderr; for an evenly spaced table, its
** range, how far the law's force goes there and what the target does past it. */
static void print_summary(const cf_export_format_info *fi, int lattice,
                          const cf_export_report *rep)
{
    if (lattice)
        cf_cli_printf_safe(stderr,
                "conifit export: %s lattice, %zu nodes, %zu springs in %zu groups, %zu load "
                "steps; tables of %zu rows, max error %.3g of F_C (%.3g N), tol %g\n",
                fi->name, rep->nodes, rep->springs, rep->groups, rep->steps, rep->rows,
                rep->max_err_rel, rep->max_err_N, rep->tol);
    else
        cf_cli_printf_safe(stderr,
                "conifit export: %s, %zu rows, max error %.3g of F_C (%.3g N), tol %g, table "
                "over u in [%.10g, %.10g] mm\n",
                fi->name, rep->rows, rep->max_err_rel, rep->max_err_N, rep->tol, rep->u_lo_mm,
                rep->u_hi_mm);
    if (!rep->even)
        return;
    const int cut = rep->u_lo_mm != rep->req_lo_mm || rep->u_hi_mm != rep->req_hi_mm;
    fprintf(stderr, "conifit export: %s rows evenly spaced, and LCINT = rows: the target's "
                    "resampling of each curve to LCINT even points gives them back; ",
            fi->name);
    if (cut)
        fprintf(stderr,
                "the range is shortened from [%.10g, %.10g] to [%.10g, %.10g] mm (spring "
                "compression), where at most %zu evenly spaced rows meet the tolerance; ",
                rep->req_lo_mm, rep->req_hi_mm, rep->u_lo_mm, rep->u_hi_mm, fi->max_rows);
    fprintf(stderr, "at its ends the law carries %.4g of F_C; past them the curve is extrapolated "
                    "along its end segments ",
            rep->end_force_rel);
    if (rep->solid_force_rel > 1.0) /* a tail: region 3 rises linearly to the solid force */
        fprintf(stderr, "(the law reaches %.4g of F_C at solid)\n", rep->solid_force_rel);
    else
        fprintf(stderr, "(the law stiffens to F_C at solid)\n");
}

/* export: parse, load the spring (and the lattice), render the whole output in memory, write it,
** then the summary. */
int cf_cli_export(int argc, char **argv)
{
    export_request q;
    int rc = parse_request(argc, argv, &q);
    if (rc >= 0)
        return rc;
    cf_error err = {0};
    cf_export_options opt = q.ea.opt;
    cf_fitted_spring fs;
    if (cf_fitfile_load_element(q.fit_path, q.ea.type, &fs, &err) != CF_OK)
        return cf_cli_fail(&err);
    opt.source = cf_cli_is_stdio(q.fit_path) ? "(standard input)" : q.fit_path;
    opt.output = q.out_path && !cf_cli_is_stdio(q.out_path) ? q.out_path : NULL;
    opt.auto_tol = !q.ea.tol_given;
    cf_export_lattice lx;
    q.scene_fit[0] = '\0';
    q.body = 0;
    q.body_buf = NULL;
    if (q.ea.lattice && lattice_of(&q, &fs, &lx, &err) != CF_OK) {
        free(q.body_buf);
        return cf_cli_fail(&err);
    }
    if (q.body) {
        cf_status st = emit(&q, q.body_buf, q.body_len, &err);
        free(q.body_buf);
        if (st != CF_OK)
            return cf_cli_fail(&err);
        if (q.body_rep.warning[0])
            cf_cli_printf_safe(stderr, "conifit export: warning: %s\n", q.body_rep.warning);
        if (!q.quiet)
            cf_cli_printf_safe(stderr,
                               "conifit export: %s body, %zu nodes, %zu edge springs in %zu "
                               "groups, %zu load steps; tables of %zu rows, max error %.3g of "
                               "F_C (%.3g N), tol %g\n",
                               cf_export_format_name(opt.format), q.body_rep.nodes,
                               q.body_rep.springs, q.body_rep.groups, q.body_rep.steps,
                               q.body_rep.rows, q.body_rep.max_err_rel, q.body_rep.max_err_N,
                               q.body_rep.tol);
        return CF_EXIT_OK;
    }
    if (q.ea.lattice && !fs.target_lattice && !q.quiet)
        fputs("conifit export: note: the fit file's spring was fitted as a single spring "
              "(--target spring), not through the lattice: its lattice may miss the table; fit "
              "it again with --validate, which fits through the lattice\n",
              stderr);
    char *buf;
    size_t len;
    cf_export_report rep;
    if (cf_pipeline_export(&fs, &opt, q.ea.lattice ? &lx : NULL, &rep, &buf, &len, &err) != CF_OK ||
        emit(&q, buf, len, &err) != CF_OK) {
        free(buf);
        return cf_cli_fail(&err);
    }
    free(buf);
    if (q.ea.lattice && rep.warning[0])
        cf_cli_printf_safe(stderr, "conifit export: warning: %s\n", rep.warning);
    const cf_export_format_info *fi = cf_export_format_get(opt.format);
    if (!q.quiet && fi->table)
        print_summary(fi, q.ea.lattice, &rep);
    return CF_EXIT_OK;
}
