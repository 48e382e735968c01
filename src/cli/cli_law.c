/*
** The subcommands that evaluate one spring: force, curve and info.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "conifit/fitfile.h"

static const char force_help[] =
    "usage: conifit force SPRING --u MM [--method M]\n"
    "Prints the force F(u) of a conical spring in newtons (%.17g) on one line.\n\n"
    "  --u MM       compression in mm (positive shortens the spring, negative stretches it)\n"
    "  --method M   exact | closed | closed+newton | table (default closed)\n"
    "  --table N    intervals of the table for --method table (default 256)\n\n";

static const char curve_help[] =
    "usage: conifit curve SPRING [--points N] [--method M]\n"
    "Prints the CSV table u_mm,force_N,stiffness_N_per_mm from full stretch (u = -travel)\n"
    "to solid (u = +travel), N points evenly spaced in u (default 201). At +-travel the\n"
    "spring is solid: the force is +-F_C and the stiffness is reported as 0.\n\n"
    "  --points N   number of rows, 2..10000000 (default 201)\n"
    "  --method M   exact | closed | closed+newton | table (default closed)\n"
    "  --table N    intervals of the table for --method table (default 256)\n\n";

static const char info_help[] =
    "usage: conifit info SPRING\n"
    "Prints the derived quantities of a conical spring: type, solid and maximum length,\n"
    "travel, transition and solid loads, linear stiffness, spring index and diameter ratio.\n\n";

typedef struct law_args {
    cf_cli_spring spring;
    const char *spring_file; /* --spring FILE.json[:TYPE], or NULL */
    cf_law_method method;
    long table;
    double u;
    int have_u;
    long points;
} law_args;

/* Parses the options of force/curve/info; `allowed` lists the extra options ("u", "points",
** "method"). Returns -1 when the command should go on, else an exit status. */
static int parse(const char *cmd, const char *help, const char *allowed, int argc, char **argv,
                 law_args *a)
{
    cf_error err = {0};
    memset(a, 0, sizeof *a);
    a->method = CF_LAW_CLOSED;
    a->table = CF_LAW_TABLE_DEFAULT;
    a->points = 201;
    for (int i = 1; i < argc; i++) {
        const char *val;
        int m;
        if (cf_cli_is_help(argv[i])) {
            printf(help, 0.0);
            fputs(cf_cli_spring_help, stdout);
            fputs("  --spring FILE.json[:TYPE]  instead of the six: the spring of a fit file or of\n"
                  "             an exported spring (conifit export --format json); TYPE is\n"
                  "             telescoping or non-telescoping (default: the better fit)\n",
                  stdout);
            return CF_EXIT_OK;
        }
        if ((m = cf_cli_match(argc, argv, &i, "--spring", &val, &err)) != 0) {
            if (m < 0)
                return cf_cli_usage_error(cmd, "%s", err.msg);
            a->spring_file = val;
            continue;
        }
        if ((m = cf_cli_spring_option(&a->spring, argc, argv, &i, &err)) != 0) {
            if (m < 0)
                return cf_cli_usage_error(cmd, "%s", err.msg);
            continue;
        }
        if (strstr(allowed, "u") && (m = cf_cli_match(argc, argv, &i, "--u", &val, &err)) != 0) {
            if (m < 0 || cf_cli_parse_double("--u", val, &a->u, &err) != CF_OK)
                return cf_cli_usage_error(cmd, "%s", err.msg);
            a->have_u = 1;
            continue;
        }
        if (strstr(allowed, "points") &&
            (m = cf_cli_match(argc, argv, &i, "--points", &val, &err)) != 0) {
            if (m < 0 || cf_cli_parse_long("--points", val, 2, 10000000, &a->points, &err))
                return cf_cli_usage_error(cmd, "%s", err.msg);
            continue;
        }
        if (strstr(allowed, "method") &&
            (m = cf_cli_match(argc, argv, &i, "--method", &val, &err)) != 0) {
            if (m < 0 || cf_law_method_parse(val, &a->method, &err) != CF_OK)
                return cf_cli_usage_error(cmd, "%s", err.msg);
            continue;
        }
        if (strstr(allowed, "method") &&
            (m = cf_cli_match(argc, argv, &i, "--table", &val, &err)) != 0) {
            if (m < 0 || cf_cli_parse_long("--table", val, 2, 1 << 26, &a->table, &err))
                return cf_cli_usage_error(cmd, "%s", err.msg);
            continue;
        }
        return cf_cli_usage_error(cmd, "unknown argument '%s'", argv[i]);
    }
    if (a->spring_file) {
        for (int k = 0; k < 6; k++)
            if (a->spring.have[k])
                return cf_cli_usage_error(cmd, "--spring replaces --D1 --D2 --n --d --G --H; "
                                               "give one or the other");
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
        return cf_cli_usage_error("spring", "%s", err.msg);
    if (a->method == CF_LAW_TABLE && cf_law_table_build(law, (size_t)a->table, &err) != CF_OK)
        return cf_cli_fail(&err);
    return -1;
}

int cf_cli_force(int argc, char **argv)
{
    law_args a;
    cf_law law;
    int rc = parse("force", force_help, "u method", argc, argv, &a);
    if (rc >= 0)
        return rc;
    if ((rc = prepare(&a, &law)) >= 0)
        return rc;
    printf("%.17g\n", cf_law_force(&law, a.method, a.u, NULL, NULL));
    cf_law_free(&law);
    return CF_EXIT_OK;
}

int cf_cli_curve(int argc, char **argv)
{
    law_args a;
    cf_law law;
    int rc = parse("curve", curve_help, "points method", argc, argv, &a);
    if (rc >= 0)
        return rc;
    if ((rc = prepare(&a, &law)) >= 0)
        return rc;
    const double s = law.travel_mm;
    printf("u_mm,force_N,stiffness_N_per_mm\n");
    for (long i = 0; i < a.points; i++) {
        /* symmetric sampling: -s + 2 s i/(N-1), with the ends exact */
        double u = (i == a.points - 1) ? s : -s + 2.0 * s * (double)i / (double)(a.points - 1);
        double k;
        double F = cf_law_force(&law, a.method, u, &k, NULL);
        printf("%.17g,%.17g,%.17g\n", u, F, k);
    }
    cf_law_free(&law);
    return fflush(stdout) == 0 ? CF_EXIT_OK : CF_EXIT_CANTCREAT;
}

int cf_cli_info(int argc, char **argv)
{
    law_args a;
    cf_law law;
    int rc = parse("info", info_help, "", argc, argv, &a);
    if (rc >= 0)
        return rc;
    if ((rc = prepare(&a, &law)) >= 0)
        return rc;
    const cf_spring *p = &law.p;
    printf("conical spring, %s\n", cf_spring_type_name(law.type));
    printf("  %-34s %.10g mm\n", "D1 (smallest coil)", p->D1_mm);
    printf("  %-34s %.10g mm\n", "D2 (largest coil)", p->D2_mm);
    printf("  %-34s %.10g\n", "n (active coils)", p->n);
    printf("  %-34s %.10g mm\n", "d (wire)", p->d_mm);
    printf("  %-34s %.10g MPa\n", "G (shear modulus)", p->G_MPa);
    printf("  %-34s %.10g mm\n", "H (free length)", p->H_mm);
    printf("derived\n");
    printf("  %-34s %s ((D2-D1)/2 = %.6g mm %s n d = %.6g mm)\n", "type",
           cf_spring_type_name(law.type), 0.5 * (p->D2_mm - p->D1_mm),
           law.type == CF_TELESCOPING ? ">=" : "<", p->n * p->d_mm);
    printf("  %-34s %.10g\n", "rho = D1/D2", law.rho);
    printf("  %-34s %.10g\n", "spring index c = D1/d", law.index_c);
    printf("  %-34s %.10g mm\n", "L_min (solid length)", law.L_min_mm);
    printf("  %-34s %.10g mm\n", "L_max (full stretch)", law.L_max_mm);
    printf("  %-34s %.10g mm\n", "travel s = H - L_min", law.travel_mm);
    printf("  %-34s %.10g\n", "solid strain s/H", law.travel_mm / p->H_mm);
    printf("  %-34s %.10g N/mm\n", "k0 (linear stiffness)", law.k0_N_per_mm);
    printf("  %-34s %.10g mm\n", "u_T (end of linear region)", law.u_T_mm);
    printf("  %-34s %.10g N\n", "F_T (transition load)", law.F_T_N);
    printf("  %-34s %.10g N\n", "F_C (solid load)", law.F_C_N);
    printf("  %-34s %.10g MPa\n", "F_C/H^2 (stress scale)", law.F_C_N / (p->H_mm * p->H_mm));
    cf_law_free(&law);
    return CF_EXIT_OK;
}
