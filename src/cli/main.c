/*
** conifit: conical-spring parameters for mass-spring soft-tissue models.
** The entry point: dispatches to a subcommand and owns the process-wide settings.
*/
#include <errno.h>
#include <locale.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "cli/cli_predict.h"
#include "cli/cli_shard.h"
#include "model/simd.h"

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
    {"predict", cf_cli_predict, "a saved fit's RMSE and objective term at tables, without refitting"},
    {"export", cf_cli_export, "write a fitted spring for CalculiX, Abaqus, FEBio, LS-DYNA, SOFA"},
    {"synth", cf_cli_synth, "write the stress-strain table of a spring (example data)"},
    {"simulate", cf_cli_simulate, "run a scene on a mass-spring lattice of conical springs"},
    {"merge", cf_cli_merge, "merge the summaries of a study fitted in shards (fit --shard K/N)"},
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

/* A fatal signal while outputs are being written: remove their temporaries, then die of it. */
static void on_signal(int sig)
{
    cf_atomic_remove_temporaries();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Everything a command printed must have reached standard output: a full disk or a closed pipe
** is an output that cannot be written (73), never a silent success. */
static int finish(int rc)
{
    int bad = ferror(stdout);
    int e = bad ? EIO : 0;
    if (fflush(stdout) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    if (fclose(stdout) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    if (!bad)
        return rc;
    fprintf(stderr, "conifit: cannot write standard output: %s\n", strerror(e));
    return rc == CF_EXIT_OK ? CF_EXIT_CANTCREAT : rc;
}

static int run(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return CF_EXIT_USAGE;
    }
    if (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        usage(stdout);
        return CF_EXIT_OK;
    }
    const char *simd = getenv("CONIFIT_SIMD");
    if (simd && *simd && cf_simd_parse(simd) < 0) {
        fprintf(stderr, "conifit: environment variable CONIFIT_SIMD is not sse2, avx2 or avx512\n");
        return CF_EXIT_USAGE;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("conifit %s\nvector instructions: %s (processor: %s)\n", CF_VERSION,
               cf_simd_name(cf_simd_level()), cf_simd_name(cf_simd_level_supported()));
        return CF_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    cf_cli_printf_safe(stderr, "conifit: unknown command '%s' (see 'conifit --help')\n", argv[1]);
    return CF_EXIT_USAGE;
}

int main(int argc, char **argv)
{
    /* Numbers are read and written with '.' whatever the user's locale; GSL reports errors by
    ** status, never by aborting. */
    setlocale(LC_ALL, "C");
    gsl_set_error_handler_off();
    /* SIGPIPE (a reader of standard output went away) ends the run as usual, but cleanly. A
    ** signal the parent set to be ignored (nohup: SIGHUP; a shell's background job: SIGINT) stays
    ** ignored: the run was protected from it on purpose. */
    static const int fatal[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
    for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) {
        struct sigaction sa, old;
        if (sigaction(fatal[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(fatal[i], &sa, NULL);
    }
    return finish(run(argc, argv));
}
