/*
** The command-line layer: option parsing shared by the subcommands, and the subcommands' entry
** points. Only this layer (files cli*.c and main.c) prints or chooses an exit status; the modules
** below it return a cf_status and a message.
*/
#ifndef CF_CLI_H
#define CF_CLI_H

#include <getopt.h>
#include <stdio.h>

#include "io/budget.h"
#include "conifit/error.h"
#include "model/law_internal.h"
#include "model/table.h"

#include "conifit/version.h"
#include "base/atomic.h"

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

/* Parses a finite double for option `name`; CF_E_USAGE with a message naming the option. */
cf_status cf_cli_parse_double(const char *name, const char *text, double *out, cf_error *err);

/* A size in bytes with an optional K, M or G (binary) suffix; 0 when it is not one. */
double cf_cli_parse_size(const char *text);

/* The budget options shared by simulate and fit: --max-memory SIZE, --max-steps N, --max-work N
** (flag names one of them) into b. 0 when taken, else the usage exit status (message printed). */
int cf_cli_budget_option(const char *cmd, const char *flag, const char *value, cf_budget *b);

/* Parses a whole number in [lo, hi] for option `name`. */
cf_status cf_cli_parse_long(const char *name, const char *text, long lo, long hi, long *out,
                            cf_error *err);

/* ---- option parsing: getopt_long with the options every command shares ---------------------- */

/* Option codes of the shared long options without a short form, and of the spring options
** (--D1 ... --H: CF_CLI_OPT_SPRING + CF_P_D1 ... CF_P_H). Commands number their own from
** CF_CLI_OPT_OWN. */
enum {
    CF_CLI_OPT_PROGRESS = 1000,
    CF_CLI_OPT_NO_PROGRESS,
    CF_CLI_OPT_SPRING = 1100,
    CF_CLI_OPT_OWN = 1200
};

/* Every command takes -h/--help, -o/--output FILE, -q/--quiet and --progress/--no-progress;
** cf_cli_next handles them and returns the command's own options. */
typedef struct cf_cli_parser {
    const char *cmd;               /* "fit", for messages */
    const char *help;              /* the command's help text */
    const char *help_more;         /* printed after it when not NULL */
    void (*help_extra)(FILE *out); /* then called when not NULL (help built from the library) */
    int spring;                    /* 1: the command takes --D1 ... --H */
    int argc;
    char **argv;
    char shortopts[64];
    struct option *longopts;       /* shared + spring + the command's, malloc'd */
    const char *output;            /* -o/--output (NULL if not given; "-" is standard output) */
    int quiet;                     /* -q/--quiet */
    int progress;                  /* --progress 1, --no-progress 0, -1 when not given */
    int status;                    /* exit status once cf_cli_next returned -1 */
} cf_cli_parser;

/* Prepares parsing of argv (argv[0] is the command name). shortopts and longopts (terminated by
** a zeroed entry; may be NULL) are the command's own. Returns 0, or an exit status (70) when
** memory runs out. */
int cf_cli_parser_init(cf_cli_parser *p, const char *cmd, const char *help, int spring,
                       int argc, char **argv, const char *shortopts,
                       const struct option *longopts);

/* The next option of the command: its code (> 0; the value, if any, in optarg), 0 when the
** options are done (the operands are argv[optind] ... argv[argc - 1]), or -1 when the command
** stops with p->status: after --help (0) or a usage error (2, message printed). */
int cf_cli_next(cf_cli_parser *p);

/* Releases the parser. */
void cf_cli_parser_free(cf_cli_parser *p);

/* Runs cf_cli_next to the end, handing each of the command's options to take (which returns 0 to
** go on, else an exit status), and frees the parser (its results stay readable). Returns -1 when
** the command goes on (operands from argv[optind]), else the exit status. */
int cf_cli_parse(cf_cli_parser *p, int (*take)(void *ctx, int c, const char *value), void *ctx);

/* Progress on stderr: as asked, else when stderr is a terminal. */
int cf_cli_progress(const cf_cli_parser *p);

/* ---- output: a file written atomically, or standard output for "-" (or NULL) ---------------- */

typedef struct cf_cli_out {
    FILE *fp;          /* write here */
    int to_stdout;     /* 1: fp is stdout */
    cf_atomic a;       /* the file otherwise */
} cf_cli_out;

/* Opens path (NULL or "-": standard output). `inputs` as for cf_atomic_open. */
cf_status cf_cli_out_open(cf_cli_out *o, const char *path, const char *const *inputs,
                          cf_error *err);

/* Commits the file (or flushes standard output); CF_E_CANTWRITE on failure. */
cf_status cf_cli_out_close(cf_cli_out *o, cf_error *err);

/* Drops an unfinished file (nothing for standard output). Safe after cf_cli_out_close. */
void cf_cli_out_abort(cf_cli_out *o);

/* 1 when path names standard input or output ("-"). */
int cf_cli_is_stdio(const char *path);

/* 1 when path names a folder: it ends in '/' or is an existing directory. */
int cf_cli_is_dir_target(const char *p);

/* ---- the spring options --D1 --D2 --n --d --G --H, and the tail's --n_tail --H_tail (force,
** curve, info, synth) ---------------------------------------------------------------------------- */

typedef struct cf_cli_spring {
    cf_spring p;
    int have[CF_P_ALL]; /* which of D1, D2, n, d, G, H, n_tail, H_tail were given */
} cf_cli_spring;

/* Takes option code c (CF_CLI_OPT_SPRING + k) with value text. Returns 1 when c is a spring
** option it took, 0 when c is another option, -1 on a bad value (message in err). */
int cf_cli_spring_take(cf_cli_spring *s, int c, const char *text, cf_error *err);

/* After parsing: CF_E_USAGE naming the first missing spring option (of the six; the tail's
** two default to 0, no tail). */
cf_status cf_cli_spring_complete(const cf_cli_spring *s, cf_error *err);

/* Prints the spring options' help (from the spring description, spring.h). */
void cf_cli_spring_help(FILE *out);

/* Prints the help of -q, --progress and -h (each command's help states its own -o). */
void cf_cli_common_help(FILE *out);

/* The fit file the scene at scene_path names ('spring.fit'), into out (cap bytes): an input of a
** run that reads the scene, never to be one of its outputs. "" when it names none or cannot be
** read (the run's own reading of the scene then says why). */
void cf_cli_scene_fit(const char *scene_path, char *out, size_t cap);

/* Writes text to f as a terminal may safely show it: line breaks kept, every other control
** character and every byte that is not UTF-8 as \xNN (base/safetext.h). For every message and
** report line that carries text from outside (file names, column names, option values). */
void cf_cli_write_safe(FILE *f, const char *text);

/* The notes the table reader left in m (a skipped preamble, a unit read in another letter case,
** strain that looks like stretch), one "conifit: warning: FILE: NOTE" line each on stderr. */
void cf_cli_table_notes(const cf_table *m);

/* printf into a buffer (8 KiB; longer output is cut), then cf_cli_write_safe. */
void cf_cli_printf_safe(FILE *f, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#endif
