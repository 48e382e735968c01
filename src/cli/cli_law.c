/*
** The subcommands that evaluate one spring: force, curve and info.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "io/fitfile.h"

static const char force_help[] =
    "usage: conifit force SPRING --u MM [--method M] [-o FILE]\n"
    "Prints the force F(u) of a conical spring, in N, on one line (17 significant digits).\n\n"
    "  --u MM       compression in mm (positive shortens the spring, negative stretches it)\n"
    "  --method M   exact | closed | closed+newton | table (default closed)\n"
    "  --table N    intervals of the table for --method table (default 256)\n"
    "  -o FILE      write the line to FILE (atomically) instead of standard output\n"
    "  --spring FILE.json[:TYPE]  instead of the six: the spring of a fit file or of an\n"
    "               exported spring (conifit export --format json); TYPE is telescoping or\n"
    "               non-telescoping (default: the better fit)\n\n";

static const char curve_help[] =
    "usage: conifit curve SPRING [--points N] [--method M] [-o FILE.csv]\n"
    "Prints the CSV table u_mm,force_N,stiffness_N_per_mm from full stretch (u = -travel)\n"
    "to solid (u = +travel), N points evenly spaced in u (default 201). At +-travel the\n"
    "spring is solid: the force is +-F_C (+-F_solid with a tail) and the stiffness is\n"
    "reported as 0.\n\n"
    "  --points N   number of rows, 2..10000000 (default 201)\n"
    "  --method M   exact | closed | closed+newton | table (default closed)\n"
    "  --table N    intervals of the table for --method table (default 256)\n"
    "  -o FILE.csv  write the table to FILE.csv (atomically) instead of standard output\n"
    "  --spring FILE.json[:TYPE]  instead of the six: the spring of a fit file or of an\n"
    "               exported spring (conifit export --format json)\n\n";

static const char info_help[] =
    "usage: conifit info SPRING [-o FILE]\n"
    "Prints the derived quantities of a conical spring: type, solid and maximum length,\n"
    "travel, transition and solid loads, linear stiffness, spring index and diameter ratio;\n"
    "with a cylindrical tail also its stiffness, the load and compression at which the cone\n"
    "closes, the load at which the whole spring is solid and the three regions.\n\n"
    "  -o FILE      write them to FILE (atomically) instead of standard output\n"
    "  --spring FILE.json[:TYPE]  instead of the six: the spring of a fit file or of an\n"
    "               exported spring (conifit export --format json)\n\n";

typedef struct law_args {
    cf_cli_spring spring;
    const char *spring_file; /* --spring FILE.json[:TYPE], or NULL */
    cf_law_method method;
    long table;
    double u;
    int have_u;
    long points;
    const char *out;         /* -o, or NULL: standard output */
    const char *cmd;         /* force, curve or info */
} law_args;

enum { OPT_SPRING = CF_CLI_OPT_OWN, OPT_U, OPT_POINTS, OPT_METHOD, OPT_TABLE };

/* Takes one option of force/curve/info: 0 to go on, else an exit status (-1: not one of them). */
static int law_option(void *ctx, int c, const char *optval)
{
    law_args *a = ctx;
    const char *cmd = a->cmd;
    cf_error err = {0};
    int m = cf_cli_spring_take(&a->spring, c, optval, &err);
    if (m != 0)
        return m < 0 ? cf_cli_usage_error(cmd, "%s", err.msg) : 0;
    switch (c) {
    case OPT_SPRING:
        a->spring_file = optval;
        return 0;
    case OPT_U:
        a->have_u = 1;
        return cf_cli_parse_double("--u", optval, &a->u, &err) ? cf_cli_usage_error(cmd, "%s", err.msg) : 0;
    case OPT_POINTS:
        return cf_cli_parse_long("--points", optval, 2, 10000000, &a->points, &err)
                   ? cf_cli_usage_error(cmd, "%s", err.msg) : 0;
    case OPT_METHOD:
        return cf_law_method_parse(optval, &a->method, &err) ? cf_cli_usage_error(cmd, "option --method: %s", err.msg) : 0;
    case OPT_TABLE:
        return cf_cli_parse_long("--table", optval, 2, 1 << 26, &a->table, &err)
                   ? cf_cli_usage_error(cmd, "%s", err.msg) : 0;
    default:
        return cf_cli_usage_error(cmd, "unexpected option");
    }
}

/* Parses the options of force/curve/info; `allowed` lists the extra options ("u", "points",
** "method"). Returns -1 when the command should go on, else an exit status. */
static int parse(const char *cmd, const char *help, const char *allowed, int argc, char **argv,
                 law_args *a)
{
    static const struct option all[] = {
        {"spring", required_argument, NULL, OPT_SPRING}, {"u", required_argument, NULL, OPT_U},
        {"points", required_argument, NULL, OPT_POINTS},
        {"method", required_argument, NULL, OPT_METHOD},
        {"table", required_argument, NULL, OPT_TABLE}, {NULL, 0, NULL, 0}};
    struct option own[6];
    int n = 0;
    for (int i = 0; all[i].name; i++)
        if (i == 0 || strstr(allowed, all[i].name) || (i == 4 && strstr(allowed, "method")))
            own[n++] = all[i];
    own[n] = (struct option){NULL, 0, NULL, 0};
    cf_error err = {0};
    memset(a, 0, sizeof *a);
    a->method = CF_LAW_CLOSED;
    a->table = CF_LAW_TABLE_DEFAULT;
    a->points = 201;
    cf_cli_parser p;
    a->cmd = cmd;
    int rc = cf_cli_parser_init(&p, cmd, help, 1, argc, argv, "", own);
    if (rc || (rc = cf_cli_parse(&p, law_option, a)) >= 0)
        return rc;
    a->out = p.output;
    if (optind < argc)
        return cf_cli_usage_error(cmd, "unexpected argument '%s'", argv[optind]);
    if (a->spring_file) {
        for (int k = 0; k < CF_P_ALL; k++)
            if (a->spring.have[k])
                return cf_cli_usage_error(cmd, "--spring replaces --D1 --D2 --n --d --G --H "
                                               "(and --n_tail --H_tail); give one or the other");
        cf_fitted_spring fs;
        if (cf_fitfile_load_spec(a->spring_file, &fs, &err) != CF_OK)
            return cf_cli_fail(&err);
        a->spring.p = fs.params;
    } else if (cf_cli_spring_complete(&a->spring, &err) != CF_OK)
        return cf_cli_usage_error(cmd, "%s", err.msg);
    if (strstr(allowed, "u") && !a->have_u)
        return cf_cli_usage_error(cmd, "missing option --u");
    return -1;
}

/* Prepares the law (and its table when asked for). Returns -1 on success, else an exit status. */
static int prepare(const law_args *a, cf_law *law)
{
    cf_error err = {0};
    if (cf_law_init(law, &a->spring.p, &err) != CF_OK)
        return cf_cli_usage_error(a->cmd, "%s", err.msg);
    if (a->method == CF_LAW_TABLE && cf_law_table_build(law, (size_t)a->table, &err) != CF_OK)
        return cf_cli_fail(&err);
    return -1;
}

/* The result goes to -o FILE (atomically) or standard output. -1 on success, else a status. */
static int open_out(const law_args *a, cf_cli_out *out, cf_law *law)
{
    cf_error err = {0};
    const char *inputs[2] = {a->spring_file, NULL};
    if (cf_cli_out_open(out, a->out, inputs, &err) != CF_OK) {
        cf_law_free(law);
        return cf_cli_fail(&err);
    }
    return -1;
}

static int close_out(cf_cli_out *out, cf_law *law)
{
    cf_error err = {0};
    cf_law_free(law);
    return cf_cli_out_close(out, &err) == CF_OK ? CF_EXIT_OK : cf_cli_fail(&err);
}

/* force, curve and info: parse (the options in `takes` beside the spring's), prepare the law,
** open the output, write the command's result with body, close. Returns the exit status. */
static int run(const char *cmd, const char *help, const char *takes, int argc, char **argv,
               void (*body)(FILE *o, const law_args *a, const cf_law *law))
{
    law_args a;
    cf_law law;
    cf_cli_out out;
    int rc = parse(cmd, help, takes, argc, argv, &a);
    if (rc >= 0)
        return rc;
    if ((rc = prepare(&a, &law)) >= 0)
        return rc;
    if ((rc = open_out(&a, &out, &law)) >= 0)
        return rc;
    body(out.fp, &a, &law);
    return close_out(&out, &law);
}

static void force_body(FILE *o, const law_args *a, const cf_law *law)
{
    fprintf(o, "%.17g\n", cf_law_force(law, a->method, a->u, NULL, NULL));
}

int cf_cli_force(int argc, char **argv)
{
    return run("force", force_help, "u method", argc, argv, force_body);
}

static void curve_body(FILE *o, const law_args *a, const cf_law *law)
{
    const double s = law->travel_mm;
    fprintf(o, "u_mm,force_N,stiffness_N_per_mm\n");
    for (long i = 0; i < a->points; i++) {
        /* symmetric sampling: -s + 2 s i/(N-1), with the ends exact */
        double u = (i == a->points - 1) ? s : -s + 2.0 * s * (double)i / (double)(a->points - 1);
        double k;
        double F = cf_law_force(law, a->method, u, &k, NULL);
        fprintf(o, "%.17g,%.17g,%.17g\n", u, F, k);
    }
}

int cf_cli_curve(int argc, char **argv)
{
    return run("curve", curve_help, "points method", argc, argv, curve_body);
}

/* The tail's block of info: its stiffness and share, where the cone closes, the whole spring's
** solid load and the three regions in compression (stretching mirrors them). */
static void info_tail(FILE *o, const cf_law *law)
{
    const double H = law->p.H_mm;
    fprintf(o, "tail (cylindrical, in series with the cone)\n");
    fprintf(o, "  %-34s %.10g N/mm\n", "k_tail = G d^4/(8 n_tail D1^3)", law->k_tail_N_per_mm);
    fprintf(o, "  %-34s %.10g\n", "tau = n_tail/n", law->tau);
    fprintf(o, "  %-34s %.10g\n", "beta = (1/rho - 1) tau", law->beta);
    fprintf(o, "  %-34s %.10g mm\n", "cone travel s", law->cone_travel_mm);
    fprintf(o, "  %-34s %.10g mm\n", "tail travel s_t", law->travel_mm - law->cone_travel_mm);
    fprintf(o, "  %-34s %.10g mm\n", "u_C (the cone closes)", law->u_C_mm);
    fprintf(o, "  %-34s %.10g N\n", "F_solid (the tail closes)", law->F_solid_N);
    fprintf(o, "  %-34s %.10g\n", "tail compliance F_C/(k_tail H)",
            law->F_C_N / (law->k_tail_N_per_mm * H));
    fprintf(o, "regions (compression; stretching mirrors them)\n");
    fprintf(o, "  %-34s 0 <= u <= %.10g mm (strain %.6g)\n", "1 linear, cone and tail",
            law->u_T_mm, law->u_T_mm / H);
    fprintf(o, "  %-34s %.10g < u < %.10g mm (strain %.6g)\n", "2 the cone's coils close",
            law->u_T_mm, law->u_C_mm, law->u_C_mm / H);
    fprintf(o, "  %-34s %.10g <= u < %.10g mm (strain %.6g)\n", "3 linear, the tail alone",
            law->u_C_mm, law->travel_mm, law->travel_mm / H);
    fprintf(o, "  %-34s u >= %.10g mm, F = %.10g N\n", "solid", law->travel_mm, law->F_solid_N);
}

static void info_body(FILE *o, const law_args *a, const cf_law *law)
{
    (void)a;
    const cf_spring *p = &law->p;
    fprintf(o, "conical spring, %s\n", cf_spring_type_name(law->type));
    /* the design parameters: name, unit and meaning from the spring's field table (a
    ** dimensionless one, unit "-", is printed bare) */
    for (int k = 0; k < (law->tail ? CF_P_ALL : CF_P_COUNT); k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        const int bare = strcmp(sp->unit, "-") == 0;
        char value[64];
        snprintf(value, sizeof value, "%.10g%s%s", cf_spring_get(p, k), bare ? "" : " ",
                 bare ? "" : sp->unit);
        const int w = law->tail ? 6 : 4; /* n_tail and H_tail widen the name's column */
        fprintf(o, "  %-*s %-*s %s\n", w, sp->name, 33 - w, value, sp->meaning);
    }
    fprintf(o, "derived\n");
    fprintf(o, "  %-34s %s ((D2-D1)/2 = %.6g mm %s n d = %.6g mm)\n", "type",
           cf_spring_type_name(law->type), 0.5 * (p->D2_mm - p->D1_mm),
           law->type == CF_TELESCOPING ? ">=" : "<", p->n * p->d_mm);
    fprintf(o, "  %-34s %.10g\n", "rho = D1/D2", law->rho);
    fprintf(o, "  %-34s %.10g\n", "spring index c = D1/d", law->index_c);
    fprintf(o, "  %-34s %.10g mm\n", "L_min (solid length)", law->L_min_mm);
    fprintf(o, "  %-34s %.10g mm\n", "L_max (full stretch)", law->L_max_mm);
    fprintf(o, "  %-34s %.10g mm\n", law->tail ? "travel s + s_t = H - L_min" : "travel s = H - L_min",
            law->travel_mm);
    fprintf(o, "  %-34s %.10g\n", law->tail ? "solid strain (s + s_t)/H" : "solid strain s/H",
            law->travel_mm / p->H_mm);
    fprintf(o, "  %-34s %.10g N/mm\n", "k0 (linear stiffness)", law->k0_N_per_mm);
    fprintf(o, "  %-34s %.10g mm\n", "u_T (end of linear region)", law->u_T_mm);
    fprintf(o, "  %-34s %.10g N\n", "F_T (transition load)", law->F_T_N);
    fprintf(o, "  %-34s %.10g N\n", law->tail ? "F_C (the cone's solid load)" : "F_C (solid load)",
            law->F_C_N);
    fprintf(o, "  %-34s %.10g MPa\n", "F_C/H^2 (stress scale)", law->F_C_N / (p->H_mm * p->H_mm));
    if (law->tail)
        info_tail(o, law);
}

int cf_cli_info(int argc, char **argv)
{
    return run("info", info_help, "", argc, argv, info_body);
}
