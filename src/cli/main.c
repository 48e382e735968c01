/*
** conifit: conical-spring parameters for mass-spring soft-tissue models.
** The entry point: dispatches to a subcommand and owns the process-wide settings.
*/
#include <locale.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "cli/cli.h"

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} command;

static const command commands[] = {
    {"force", cf_cli_force, "force F(u) of one spring at one compression"},
    {"curve", cf_cli_curve, "CSV table of force and stiffness from full stretch to solid"},
    {"info", cf_cli_info, "derived quantities of a spring (type, travel, loads, k0, ...)"},
    {"fit", cf_cli_fit, "fit conical springs (both types) and baselines to measured tables"},
    {"export", cf_cli_export, "write a fitted spring for CalculiX, Abaqus, FEBio, LS-DYNA, SOFA"},
    {"synth", cf_cli_synth, "write the stress-strain table of a spring (example data)"},
    {"simulate", cf_cli_simulate, "run a scene on a mass-spring lattice of conical springs"},
};

static void usage(FILE *out)
{
    fprintf(out, "usage: conifit COMMAND [OPTIONS]   (conifit COMMAND --help for each)\n\n"
                 "Conical-spring parameters for mass-spring soft-tissue simulation.\n\n"
                 "Commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\nExit status: 0 ok, 2 usage, 65 bad data, 66 missing input, "
                 "70 internal error, 73 cannot write output.\n");
}

int main(int argc, char **argv)
{
    /* Numbers are read and written with '.' whatever the user's locale; GSL reports errors by
    ** status, never by aborting. */
    setlocale(LC_ALL, "C");
    gsl_set_error_handler_off();
    if (argc < 2) {
        usage(stderr);
        return CF_EXIT_USAGE;
    }
    if (cf_cli_is_help(argv[1])) {
        usage(stdout);
        return CF_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("conifit %s\n", CF_VERSION);
        return CF_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "conifit: unknown command '%s' (see 'conifit --help')\n", argv[1]);
    return CF_EXIT_USAGE;
}
