/*
** conifit synth: writes the stress-strain table of one conical spring, as a measured table would
** look, optionally with Gaussian noise. One mass-spring cell is a cube of edge H whose axial spring
** carries the stress on a face: stress = F/H^2, strain = u/H (src/model/law.md, "From a spring to
** stress and strain"). Such tables are the project's own examples (data/) and the fitter's recovery
** tests.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "cli/cli.h"
#include "io/measure.h"
#include "io/columns.h"

static const char synth_help[] =
    "usage: conifit synth SPRING [--strain-max E] [--points N] [--noise REL] [--seed S]\n"
    "                     [--stress-unit U] [--tension|--compression] [-o FILE.csv]\n"
    "Writes the stress-strain table of a conical spring: stress = F/H^2, strain = u/H\n"
    "(one cubic cell of edge H), with '#' lines documenting the spring, its type, the\n"
    "derived quantities and the noise, then the header `strain,stress_kPa`.\n\n"
    "  --strain-max E   largest |strain| (dimensionless), below the solid strain s/H\n"
    "                   (default 0.95 of the solid strain)\n"
    "  --points N       rows from strain 0 to E (2..1000000, default 50)\n"
    "  --spacing S      even: evenly spaced in strain (default); solid: geometric in the\n"
    "                   distance to the solid strain, so that rows crowd where the spring\n"
    "                   stiffens (for nearly cylindrical springs, whose nonlinear part is short)\n"
    "  --noise REL      Gaussian noise, standard deviation REL x the largest |stress|\n"
    "                   (dimensionless, default 0: the exact law)\n"
    "  --seed S         seed of the noise generator (GSL mt19937; default 1): the same seed\n"
    "                   gives the same file\n"
    "  --stress-unit U  unit of the stress column: Pa, kPa (default), MPa, GPa, N/mm2, N/m2, mmHg\n"
    "  --tension        strain and stress positive (the default; tension positive)\n"
    "  --compression    strain and stress negative (compression, tension-positive convention)\n"
    "  -o, --output FILE  the table to write (atomically); default, or '-': standard output\n\n";

/* A number written with the fewest digits that read back to the same double. */
static void print_shortest(FILE *fp, double v)
{
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, fp);
}

typedef struct synth_args {
    cf_cli_spring spring;
    double strain_max; /* dimensionless; 0 until given */
    long points;
    int solid_spacing; /* 1: geometric in the distance to solid */
    double noise;      /* relative to the largest |stress| */
    long seed;
    const char *stress_unit;
    int compression;
    const char *out;   /* NULL or "-": standard output */
    int quiet;
    int have_sign;     /* --tension or --compression seen */
} synth_args;

enum {
    OPT_STRAIN_MAX = CF_CLI_OPT_OWN,
    OPT_POINTS,
    OPT_SPACING,
    OPT_NOISE,
    OPT_SEED,
    OPT_STRESS_UNIT,
    OPT_TENSION,
    OPT_COMPRESSION
};

/* One option of synth: 0 to go on, else an exit status. */
static int synth_option(void *ctx, int c, const char *val)
{
    synth_args *a = ctx;
    int *have_sign = &a->have_sign;
    cf_error err = {0};
    int m = cf_cli_spring_take(&a->spring, c, val, &err);
    if (m != 0)
        return m < 0 ? cf_cli_usage_error("synth", "%s", err.msg) : 0;
    switch (c) {
    case OPT_STRAIN_MAX:
        if (cf_cli_parse_double("--strain-max", val, &a->strain_max, &err))
            return cf_cli_usage_error("synth", "%s", err.msg);
        if (!(a->strain_max > 0.0))
            return cf_cli_usage_error("synth", "option --strain-max: '%s' must be > 0", val);
        return 0;
    case OPT_POINTS:
        if (cf_cli_parse_long("--points", val, 2, 1000000, &a->points, &err))
            return cf_cli_usage_error("synth", "%s", err.msg);
        return 0;
    case OPT_SPACING:
        if (strcmp(val, "even") != 0 && strcmp(val, "solid") != 0)
            return cf_cli_usage_error("synth", "option --spacing: '%s' is neither 'even' nor "
                                      "'solid'", val);
        a->solid_spacing = strcmp(val, "solid") == 0;
        return 0;
    case OPT_NOISE:
        if (cf_cli_parse_double("--noise", val, &a->noise, &err))
            return cf_cli_usage_error("synth", "%s", err.msg);
        if (a->noise < 0.0)
            return cf_cli_usage_error("synth", "option --noise: '%s' must be >= 0", val);
        return 0;
    case OPT_SEED:
        if (cf_cli_parse_long("--seed", val, 0, 4294967295L, &a->seed, &err))
            return cf_cli_usage_error("synth", "%s", err.msg);
        return 0;
    case OPT_STRESS_UNIT:
        if (cf_measure_unit(val, NULL) != CF_UNIT_STRESS)
            return cf_cli_usage_error("synth", "option --stress-unit: '%s' is not a stress "
                                      "unit (Pa kPa MPa GPa N/mm2 N/m2 mmHg)", val);
        a->stress_unit = val;
        return 0;
    case OPT_TENSION:
    case OPT_COMPRESSION:
        if (*have_sign && (c == OPT_COMPRESSION) != a->compression)
            return cf_cli_usage_error("synth", "--tension and --compression exclude each other");
        a->compression = c == OPT_COMPRESSION;
        *have_sign = 1;
        return 0;
    default:
        return cf_cli_usage_error("synth", "unexpected option");
    }
}

/* Returns -1 to go on, else an exit status. */
static int parse(int argc, char **argv, synth_args *a)
{
    static const struct option own[] = {
        {"strain-max", required_argument, NULL, OPT_STRAIN_MAX},
        {"points", required_argument, NULL, OPT_POINTS},
        {"spacing", required_argument, NULL, OPT_SPACING},
        {"noise", required_argument, NULL, OPT_NOISE},
        {"seed", required_argument, NULL, OPT_SEED},
        {"stress-unit", required_argument, NULL, OPT_STRESS_UNIT},
        {"tension", no_argument, NULL, OPT_TENSION},
        {"compression", no_argument, NULL, OPT_COMPRESSION},
        {NULL, 0, NULL, 0}};
    cf_error err = {0};
    memset(a, 0, sizeof *a);
    a->points = 50;
    a->seed = 1;
    a->stress_unit = "kPa";
    cf_cli_parser p;
    int rc = cf_cli_parser_init(&p, "synth", synth_help, 1, argc, argv, "", own);
    if (rc || (rc = cf_cli_parse(&p, synth_option, a)) >= 0)
        return rc;
    a->out = p.output;
    a->quiet = p.quiet;
    if (optind < argc)
        return cf_cli_usage_error("synth", "unexpected argument '%s'", argv[optind]);
    if (cf_cli_spring_complete(&a->spring, &err) != CF_OK)
        return cf_cli_usage_error("synth", "%s", err.msg);
    return -1;
}

/* The documenting '#' lines. */
static void write_header(FILE *fp, const synth_args *a, const cf_law *law, double E,
                         double solid_strain, double sd, double to_file, int argc, char **argv)
{
    const cf_spring *p = &law->p;
    const double H2 = p->H_mm * p->H_mm;
    const char *u = a->stress_unit;
    fprintf(fp, "# conifit %s synth: stress-strain table of one conical spring in a cubic cell "
                "of edge H (stress = F/H^2, strain = u/H)\n", CF_VERSION);
    fprintf(fp, "# command: conifit");
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "-o") == 0 || strcmp(argv[i], "--output") == 0) {
            i++;
            continue;
        }
        if (strncmp(argv[i], "-o", 2) == 0 || strncmp(argv[i], "--output=", 9) == 0)
            continue;
        fprintf(fp, " %s", argv[i]);
    }
    fprintf(fp, "\n");
    fprintf(fp, "# spring:");
    for (int k = 0; k < (law->tail ? CF_P_ALL : CF_P_COUNT); k++)
        fprintf(fp, " %s=%.17g", cf_spring_param_info(k)->key, cf_spring_get(p, k));
    fprintf(fp, "\n");
    if (law->tail)
        fprintf(fp, "# tail: cone_travel_mm=%.10g u_C_mm=%.10g k_tail_N_per_mm=%.10g tau=%.10g "
                    "F_solid_N=%.10g tail_compliance=F_C/(k_tail H)=%.10g\n",
                law->cone_travel_mm, law->u_C_mm, law->k_tail_N_per_mm, law->tau, law->F_solid_N,
                law->F_C_N / (law->k_tail_N_per_mm * p->H_mm));
    fprintf(fp, "# type: %s ((D2 - D1)/2 = %.10g mm %s n d = %.10g mm)\n",
            cf_spring_type_name(law->type), 0.5 * (p->D2_mm - p->D1_mm),
            law->type == CF_TELESCOPING ? ">=" : "<", p->n * p->d_mm);
    fprintf(fp, "# derived: rho=%.10g index_c=%.10g L_min_mm=%.10g travel_mm=%.10g "
                "solid_strain=%.10g k0_N_per_mm=%.10g F_T_N=%.10g F_C_N=%.10g\n",
            law->rho, law->index_c, law->L_min_mm, law->travel_mm, solid_strain,
            law->k0_N_per_mm, law->F_T_N, law->F_C_N);
    fprintf(fp, "# derived: transition_strain=%.10g transition_stress_%s=%.10g "
                "solid_stress_%s=%.10g initial_modulus_%s=%.10g\n",
            law->u_T_mm / p->H_mm, u, law->F_T_N / H2 * to_file, u, law->F_C_N / H2 * to_file, u,
            law->k0_N_per_mm / p->H_mm * to_file);
    fprintf(fp, "# identifiable: rho=%.10g solid_strain=%.10g stress_scale_%s=F_C/H^2=%.10g\n",
            law->rho, solid_strain, u, law->F_C_N / H2 * to_file);
    fprintf(fp, "# sampling: %ld rows %s from 0 to %s%.10g (%.6g of the solid strain); "
                "%s\n",
            a->points,
            a->solid_spacing ? "spaced geometrically in the distance to the solid strain"
                             : "evenly spaced in strain",
            a->compression ? "-" : "", E, E / solid_strain,
            a->compression ? "compression: strain and stress negative (tension positive)"
                           : "tension: strain and stress positive");
    if (a->noise > 0.0)
        fprintf(fp, "# noise: Gaussian on stress, sd = %.6g x max|stress| = %.10g %s, GSL mt19937 "
                    "seed %ld\n", a->noise, sd, u, a->seed);
    else
        fprintf(fp, "# noise: none (the exact law, evaluated to the last bits)\n");
    fprintf(fp, "# columns: strain = engineering strain [-], stress = nominal stress [%s]\n", u);
}

/* synth: parse, check the spring and strain range, evaluate the rows, add GSL's Gaussian noise,
** check every value finite, write the table. A straight sequence whose failures all free the
** same three buffers, so kept whole. */
int cf_cli_synth(int argc, char **argv)
{
    synth_args a;
    cf_law law;
    cf_error err = {0};
    int rc = parse(argc, argv, &a);
    if (rc >= 0)
        return rc;
    if (cf_law_init(&law, &a.spring.p, &err) != CF_OK)
        return cf_cli_usage_error("synth", "%s", err.msg);
    const double H = law.p.H_mm;
    const double solid_strain = law.travel_mm / H;
    double E = a.strain_max > 0.0 ? a.strain_max : 0.95 * solid_strain;
    if (!(E < solid_strain)) {
        cf_law_free(&law);
        return cf_cli_usage_error("synth", "option --strain-max: %.10g is not below the solid "
                                  "strain %.10g of this spring", E, solid_strain);
    }
    if (law.index_c < 3.0 && !a.quiet)
        fprintf(stderr, "conifit synth: warning: spring index D1/d = %.6g < 3 is not a practical "
                        "spring (the fitter requires >= 3)\n", law.index_c);
    double to_conifit = 1.0;
    cf_measure_unit(a.stress_unit, &to_conifit);
    const double to_file = 1.0 / to_conifit;

    double *strain = malloc((size_t)a.points * sizeof *strain);
    double *stress = malloc((size_t)a.points * sizeof *stress);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!strain || !stress || !rng) {
        free(strain);
        free(stress);
        if (rng)
            gsl_rng_free(rng);
        cf_law_free(&law);
        cf_error_set(&err, CF_E_INTERNAL, "synth: out of memory for %ld rows", a.points);
        return cf_cli_fail(&err);
    }
    gsl_rng_set(rng, (unsigned long)a.seed);
    const double sign = a.compression ? -1.0 : 1.0;
    double smax = 0.0;
    for (long i = 0; i < a.points; i++) {
        double f = (double)i / (double)(a.points - 1), e;
        if (i == a.points - 1)
            e = E;
        else if (a.solid_spacing) /* solid_strain - e runs geometrically down to solid - E */
            e = solid_strain - solid_strain * pow((solid_strain - E) / solid_strain, f);
        else
            e = E * f;
        double F = cf_law_force(&law, CF_LAW_EXACT, e * H, NULL, NULL);
        strain[i] = sign * e + 0.0; /* + 0.0: no "-0" in the file */
        stress[i] = sign * F / (H * H) * to_file + 0.0;
        if (fabs(stress[i]) > smax)
            smax = fabs(stress[i]);
    }
    const double sd = a.noise * smax;
    if (sd > 0.0)
        for (long i = 0; i < a.points; i++)
            stress[i] += gsl_ran_gaussian(rng, sd);
    int bad = !isfinite(sd);
    for (long i = 0; i < a.points && !bad; i++)
        bad = !isfinite(strain[i]) || !isfinite(stress[i]);
    gsl_rng_free(rng);
    if (bad) {
        free(strain);
        free(stress);
        cf_law_free(&law);
        cf_error_set(&err, CF_E_DATA, "synth: the spring gives a non-finite stress in %s "
                                      "(G_MPa=%.17g H_mm=%.17g)", a.stress_unit, law.p.G_MPa, H);
        return cf_cli_fail(&err);
    }

    cf_cli_out out;
    if (cf_cli_out_open(&out, a.out, NULL, &err) != CF_OK) {
        free(strain);
        free(stress);
        cf_law_free(&law);
        return cf_cli_fail(&err);
    }
    write_header(out.fp, &a, &law, E, solid_strain, sd, to_file, argc, argv);
    fprintf(out.fp, "strain,stress_%s\n", a.stress_unit);
    for (long i = 0; i < a.points; i++) {
        print_shortest(out.fp, strain[i]);
        fputc(',', out.fp);
        print_shortest(out.fp, stress[i]);
        fputc('\n', out.fp);
    }
    free(strain);
    free(stress);
    cf_law_free(&law);
    if (cf_cli_out_close(&out, &err) != CF_OK)
        return cf_cli_fail(&err);
    return CF_EXIT_OK;
}
