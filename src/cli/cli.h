/*
** The command-line layer: option parsing shared by the subcommands, and the subcommands' entry
** points. Only this layer (files cli*.c and main.c) prints or chooses an exit status; the modules
** below it return a cf_status and a message.
*/
#ifndef CF_CLI_H
#define CF_CLI_H

#include <stdio.h>

#include "conifit/error.h"
#include "conifit/law.h"

#include "conifit/version.h"

/* Each subcommand: parses its own arguments (argv[0] is the subcommand name) and returns an exit
** status (0, 2, 65, 66, 70, 73). */
int cf_cli_force(int argc, char **argv);
int cf_cli_curve(int argc, char **argv);
int cf_cli_info(int argc, char **argv);
int cf_cli_fit(int argc, char **argv);
int cf_cli_simulate(int argc, char **argv);
int cf_cli_export(int argc, char **argv);
int cf_cli_synth(int argc, char **argv);

/* Prints "conifit: MESSAGE" on stderr for err and returns its exit status. */
int cf_cli_fail(const cf_error *err);

/* Prints "conifit CMD: MESSAGE (see conifit CMD --help)" on stderr and returns 2. */
int cf_cli_usage_error(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Option scanning: `--name VALUE` or `--name=VALUE`. cf_cli_match returns 1 and sets *value when
** argv[*i] is option `name` (advancing *i past a separate value), 0 when it is another argument,
** and -1 when the option lacks its value (a message is in err). */
int cf_cli_match(int argc, char **argv, int *i, const char *name, const char **value,
                 cf_error *err);

/* Parses a finite double for option `name`; CF_E_USAGE with a message naming the option. */
cf_status cf_cli_parse_double(const char *name, const char *text, double *out, cf_error *err);

/* Parses a whole number in [lo, hi] for option `name`. */
cf_status cf_cli_parse_long(const char *name, const char *text, long lo, long hi, long *out,
                            cf_error *err);

/* True when argv[i] is -h or --help. */
int cf_cli_is_help(const char *arg);

/* Spring arguments shared by force, curve and info: --D1 --D2 --n --d --G --H (all required). */
typedef struct cf_cli_spring {
    cf_spring p;
    int have[6];     /* which of D1, D2, n, d, G, H were given */
} cf_cli_spring;

/* Tries argv[*i] as one of the spring options; returns 1 if consumed, 0 if not one, -1 on error. */
int cf_cli_spring_option(cf_cli_spring *s, int argc, char **argv, int *i, cf_error *err);

/* After parsing: CF_E_USAGE naming the first missing spring option. */
cf_status cf_cli_spring_complete(const cf_cli_spring *s, cf_error *err);

/* Text describing the spring options, for --help. */
extern const char cf_cli_spring_help[];

#endif
