/*
** The figures conifit draws, all through the one gnuplot runner (gnuplot.h) and its rule: data as
** data blocks of numbers, every piece of text from input as an escaped string literal, the output
** name never shown to gnuplot.
**   - a fit: the measured points, both conical fits, the baselines and (with --validate) the
**     lattice curve of each fit on top, the residuals of each model underneath (multiplot);
**   - a simulation: the lattice's stress-strain curve (with one spring's for comparison), the
**     load-unload loops, or creep / relaxation against time;
**   - a body's probe: its force against depth (or against time in the haptic loop).
** A failed plot leaves no file.
*/
#ifndef CF_PLOT_H
#define CF_PLOT_H

#include <stddef.h>

#include "base/atomic.h"
#include "conifit/error.h"
#include "fit/fit.h"
#include "model/msm.h"
#include "report/report.h"
#include "io/scene.h"

/* CF_OK when path names a format conifit draws (.png, .svg or .pdf, any case); CF_E_DATA otherwise. A
** command checks this before any work, so that a misspelt name costs nothing. */
cf_status cf_plot_check_name(const char *path, cf_error *err);

/* Draws the report's table (x, y in conifit's units: strain or mm, MPa or N; shown in the file's
** units) to path, a .png, .svg or .pdf file, as a temporary file left in *out for the caller to commit
** with its other outputs (cf_atomic_commit) or abort. CF_E_DATA for another extension,
** CF_E_INTERNAL when gnuplot is missing or fails (message says which), CF_E_CANTWRITE when the
** file cannot be written; `inputs` (NULL-terminated, may be NULL) are refused as targets. */
cf_status cf_plot_fit(const cf_fit_report *r, const char *path,
                      const char *const *inputs, cf_atomic *out, cf_error *err);

/* Draws a simulation's samples (n of them; spring_MPa[k]: one spring's F(strain H)/H^2 at the
** sample's strain) as the scene's protocol suggests; same outputs and errors as cf_plot_fit. */
cf_status cf_plot_simulation(const cf_scene *sc, const cf_msm_sample *s, const double *spring_MPa,
                             size_t n, const char *path, const char *const *inputs,
                             cf_atomic *out, cf_error *err);

/* Draws a probe's force (N, positive pushing into the body) against x (the depth in mm, or the
** time in ms of a haptic run: xlabel says which), n points, titled `title` with the curve named
** `series` (both may hold text from input: they reach gnuplot as string literals only); same
** outputs and errors as cf_plot_fit. */
cf_status cf_plot_probe(const char *title, const char *series, const char *xlabel,
                        const double *x, const double *force_N, size_t n, const char *path,
                        const char *const *inputs, cf_atomic *out, cf_error *err);

#endif
