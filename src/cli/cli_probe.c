/*
** The depth-force plot of a body's probe (cli_probe.h).
*/
#include "cli/cli_probe.h"

#include <stdio.h>
#include <stdlib.h>

#include "report/plot.h"

cf_status cf_cli_probe_plot(const cf_scene *sc, const cf_body_step *step, size_t n,
                            const char *png, const char *const *inputs, cf_atomic *out,
                            cf_error *err)
{
    double *depth = malloc((n ? n : 1) * sizeof *depth), *force = malloc((n ? n : 1) * sizeof *force);
    if (!depth || !force) {
        free(depth);
        free(force);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the plot");
    }
    for (size_t k = 0; k < n; k++) {
        depth[k] = step[k].depth_mm;
        force[k] = step[k].force_N;
    }
    char title[4300], series[700];
    snprintf(title, sizeof title, "%s of radius %g mm pressed into %s",
             sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch", sc->probe.radius_mm,
             sc->body_mesh);
    snprintf(series, sizeof series, "body (spring: %s)", sc->spring_source);
    cf_status st = cf_plot_probe(title, series, "probe depth (mm)", depth, force, n, png, inputs,
                                 out, err);
    free(depth);
    free(force);
    return st;
}
