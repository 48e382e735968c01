/*
** Plotting a fit through gnuplot: the measured points, both conical fits, the baselines and (with
** --validate) the lattice curve of each fit on top, the residuals of each model underneath
** (multiplot). gnuplot runs as a child process that reads its script on stdin; it writes a
** temporary file beside the target, which is renamed into place only when gnuplot succeeded, so a
** failed plot leaves no file. The program is `gnuplot`
** on PATH, or the one named by the environment variable CONIFIT_GNUPLOT.
*/
#ifndef CF_PLOT_H
#define CF_PLOT_H

#include "conifit/error.h"
#include "conifit/fit.h"
#include "conifit/report.h"

/* Draws the report's table (x, y in conifit's units: strain or mm, MPa or N; shown in the file's
** units) to path, a .png or .svg file. CF_E_USAGE for another extension, CF_E_INTERNAL when
** gnuplot is missing or fails (message says which), CF_E_CANTWRITE when the file cannot be
** written; `inputs` (NULL-terminated, may be NULL) are refused as targets. */
cf_status cf_plot_write(const cf_fit_report *r, const cf_fit_data *data, const char *path,
                        const char *const *inputs, cf_error *err);

#endif
