/*
** The one way conifit runs gnuplot. Every figure is a script built with this module and drawn by
** cf_gp_render; nothing else in conifit starts gnuplot.
**
** The rule that keeps input from becoming code: a script line is a constant format whose only
** text conversion is %q. %q turns any text (a column name, a unit, a file name, a scene string)
** into a gnuplot double-quoted string in which every byte other than letters, digits, space and
** . , _ + - / : = ( ) [ ] # is written as an octal escape (\047 for a quote, \140 for a backtick,
** \100 for @, \012 for a newline). Such a literal cannot end early, cannot start a command
** substitution or a macro, and is only ever a string value. %s is refused. Numbers go in with %d,
** %zu and the floating conversions; data go in as data blocks of numbers written by this module.
** gnuplot never sees an output file name either: it draws to its standard output, which is a
** temporary file beside the target (atomic.h).
**
** The program is `gnuplot` on PATH, or the one named by the environment variable CONIFIT_GNUPLOT
** (run directly, never through a shell).
*/
#ifndef CF_OUT_GNUPLOT_H
#define CF_OUT_GNUPLOT_H

#include <stddef.h>

#include "base/atomic.h"
#include "conifit/error.h"

/* A script being built. Errors are sticky: the first one is kept and reported by cf_gp_render. */
typedef struct cf_gp {
    char *buf;
    size_t len, cap;
    int in_block;
    cf_status st;
    char msg[160];
} cf_gp;

/* CF_OK for a path conifit can draw to: .png (cairo PNG), .svg or .pdf (cairo PDF) (any case); CF_E_DATA naming the
** path otherwise. */
cf_status cf_gp_check_name(const char *path, cf_error *err);

void cf_gp_init(cf_gp *g);
void cf_gp_free(cf_gp *g);

/* Sets the terminal for path's format (cf_gp_check_name) at width x height pixels; another name
** makes the script invalid. */
void cf_gp_terminal(cf_gp *g, const char *path, int width, int height);

/* Appends one script line (a newline is added). fmt must be a constant; conversions: %d, %zu,
** %g %e %f with flags, width and precision (double), %q (text, as a safe string literal), %%.
** Any other conversion, a non-finite number, or a newline in fmt makes the script invalid. */
void cf_gp_cmd(cf_gp *g, const char *fmt, ...);

/* A data block `$NAME << EOD` (NAME: letters, digits, '_'), rows of finite numbers, then `EOD`.
** A non-finite value makes the script invalid. */
void cf_gp_block_begin(cf_gp *g, const char *name);
void cf_gp_block_row(cf_gp *g, size_t n, const double *values);
void cf_gp_block_end(cf_gp *g);

/* Runs gnuplot on the script with its standard output on a temporary file beside path (refused
** when path is one of `inputs`, NULL-terminated, may be NULL), and checks that it succeeded and
** drew something. On CF_OK the drawing is in *out, not yet in place: the caller commits it
** (cf_atomic_commit) with its other outputs, or aborts it. Errors: CF_E_INTERNAL for an invalid
** script, a missing gnuplot (message names the Debian package) or a failed one (message quotes its
** first error line); CF_E_CANTWRITE when the temporary file cannot be made. */
cf_status cf_gp_render(cf_gp *g, const char *path, const char *const *inputs, cf_atomic *out,
                       cf_error *err);

#endif
