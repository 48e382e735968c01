/*
** gnuplot plots of a fit (see plot.h). The data and the model curves go into the script as inline
** data blocks, so gnuplot needs no other file.
*/
#include "out/plot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <strings.h>
#include <unistd.h>

#include "base/atomic.h"

/* Points on each model curve. */
#define CURVE_POINTS 400

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

/* x and the lattice stress (file's unit) of every data point, sorted by x. */
static void lattice_block(FILE *g, const cf_fit_data *d, const double *stress_MPa, double u)
{
    size_t *ord = malloc(sizeof(size_t) * (d->count ? d->count : 1));
    if (!ord)
        return;
    for (size_t i = 0; i < d->count; i++)
        ord[i] = i;
    for (size_t i = 1; i < d->count; i++) /* insertion sort: tables are short and nearly sorted */
        for (size_t j = i; j > 0 && d->x[ord[j - 1]] > d->x[ord[j]]; j--) {
            size_t t = ord[j];
            ord[j] = ord[j - 1];
            ord[j - 1] = t;
        }
    for (size_t i = 0; i < d->count; i++)
        fprintf(g, "%.17g %.17g\n", d->x[ord[i]], stress_MPa[ord[i]] * u);
    free(ord);
}

static void write_script(FILE *g, const cf_fit_report *r, const cf_fit_data *d, const char *out,
                         int svg)
{
    const double u = r->y_to_file;
    double xmin = 0, xmax = 0;
    for (size_t i = 0; i < d->count; i++) {
        xmin = fmin(xmin, d->x[i]);
        xmax = fmax(xmax, d->x[i]);
    }
    cf_law laws[2];
    for (int i = 0; i < r->nfits; i++)
        laws[i] = r->fits[i].law;
    /* data: x, y, then the residual of each model (fits then baselines) */
    fprintf(g, "$DATA << EOD\n");
    for (size_t i = 0; i < d->count; i++) {
        fprintf(g, "%.17g %.17g", d->x[i], d->y[i] * u);
        for (int k = 0; k < r->nfits; k++)
            fprintf(g, " %.17g",
                    (cf_fit_model(&laws[k], r->force_displacement, d->x[i]) - d->y[i]) * u);
        for (int k = 0; k < CF_BASE_COUNT; k++)
            fprintf(g, " %.17g", (cf_baseline_eval(&r->baselines[k], d->x[i]) - d->y[i]) * u);
        fputc('\n', g);
    }
    fprintf(g, "EOD\n$CURVES << EOD\n");
    for (int j = 0; j <= CURVE_POINTS; j++) {
        double x = xmin + (xmax - xmin) * j / CURVE_POINTS;
        fprintf(g, "%.17g", x);
        for (int k = 0; k < r->nfits; k++)
            fprintf(g, " %.17g", cf_fit_model(&laws[k], r->force_displacement, x) * u);
        for (int k = 0; k < CF_BASE_COUNT; k++)
            fprintf(g, " %.17g", cf_baseline_eval(&r->baselines[k], x) * u);
        fputc('\n', g);
    }
    fprintf(g, "EOD\n");
    /* the lattice curve of each validated fit, at the table's strains in increasing order */
    int nlat = 0;
    if (r->validate)
        for (int k = 0; k < r->nfits; k++)
            if (r->val[k].done && r->val[k].count == d->count) {
                fprintf(g, "$LATTICE%d << EOD\n", k);
                lattice_block(g, d, r->val[k].stress_MPa, u);
                fprintf(g, "EOD\n");
                nlat++;
            }
    if (svg)
        fprintf(g, "set terminal svg size 900,800 dynamic enhanced font 'sans,12'\n");
    else
        fprintf(g, "set terminal pngcairo size 900,800 enhanced font 'sans,11'\n");
    fprintf(g, "set output '%s'\n", out);
    const char *xl = r->force_displacement ? "displacement [mm]" : "strain [-]";
    fprintf(g, "set multiplot\nset title \"%s\" noenhanced\n", r->data_file);
    fprintf(g, "set size 1,0.66\nset origin 0,0.34\nset grid\nset key top left box opaque\n");
    fprintf(g, "set xlabel '%s'\nset ylabel '%s [%s]' noenhanced\n", xl, r->y_column, r->y_unit);
    static const char *colors[2] = {"#d62728", "#1f77b4"};
    static const char *bcolors[CF_BASE_COUNT] = {"#7f7f7f", "#2ca02c", "#9467bd"};
    fprintf(g, "plot $DATA using 1:2 with points pt 7 ps 0.6 lc rgb 'black' title 'measured'");
    for (int k = 0; k < r->nfits; k++)
        fprintf(g, ", $CURVES using 1:%d with lines lw %d lc rgb '%s' title 'conical, %s'", 2 + k,
                k == 0 ? 4 : 2, colors[k], cf_spring_type_name(r->fits[k].type));
    for (int k = 0; k < CF_BASE_COUNT; k++)
        fprintf(g, ", $CURVES using 1:%d with lines lw 1 dt 2 lc rgb '%s' title '%s'",
                2 + r->nfits + k, bcolors[k], cf_baseline_name((cf_baseline_kind)k));
    for (int k = 0; nlat > 0 && k < r->nfits; k++)
        if (r->val[k].done && r->val[k].count == d->count)
            fprintf(g, ", $LATTICE%d using 1:2 with linespoints lw 2 dt 4 pt 6 ps 0.5 lc rgb '%s' "
                       "title 'lattice %dx%dx%d, %s'",
                    k, colors[k], r->val[k].setup.cfg.lattice.nx, r->val[k].setup.cfg.lattice.ny,
                    r->val[k].setup.cfg.lattice.nz, cf_spring_type_name(r->fits[k].type));
    fprintf(g, "\nset size 1,0.34\nset origin 0,0\nunset title\nset key off\n");
    fprintf(g, "set ylabel 'residual [%s]' noenhanced\n", r->y_unit);
    fprintf(g, "plot 0 with lines lc rgb 'black' notitle");
    for (int k = 0; k < r->nfits; k++)
        fprintf(g, ", $DATA using 1:%d with linespoints pt 7 ps 0.4 lc rgb '%s'", 3 + k, colors[k]);
    for (int k = 0; k < CF_BASE_COUNT; k++)
        fprintf(g, ", $DATA using 1:%d with lines dt 2 lc rgb '%s'", 3 + r->nfits + k, bcolors[k]);
    fprintf(g, "\nunset multiplot\nset output\n");
}

cf_status cf_plot_write(const cf_fit_report *r, const cf_fit_data *data, const char *path,
                        const char *const *inputs, cf_error *err)
{
    int svg = ends_with(path, ".svg");
    if (!svg && !ends_with(path, ".png"))
        return cf_error_set(err, CF_E_USAGE, "--plot %s: the file must end in .png or .svg", path);
    if (strchr(path, '\'') || strchr(path, '\n'))
        return cf_error_set(err, CF_E_USAGE, "--plot %s: quotes and newlines are not allowed",
                            path);
    /* reserve a temporary name beside the target (atomic.h), let gnuplot write it */
    cf_atomic a;
    cf_status st = cf_atomic_open(&a, path, inputs, err);
    if (st != CF_OK)
        return st;
    fclose(a.fp);
    a.fp = NULL;
    const char *prog = getenv("CONIFIT_GNUPLOT");
    if (!prog || !*prog)
        prog = "gnuplot";
    int fds[2];
    if (pipe(fds) != 0) {
        cf_atomic_abort(&a);
        return cf_error_set(err, CF_E_INTERNAL, "cannot start gnuplot: %s", strerror(errno));
    }
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        cf_atomic_abort(&a);
        return cf_error_set(err, CF_E_INTERNAL, "cannot start gnuplot: %s", strerror(errno));
    }
    if (pid == 0) {
        dup2(fds[0], 0);
        close(fds[0]);
        close(fds[1]);
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        execlp(prog, prog, (char *)NULL);
        _exit(127);
    }
    close(fds[0]);
    FILE *g = fdopen(fds[1], "w");
    if (g) {
        write_script(g, r, data, a.tmp, svg);
        fclose(g);
    } else {
        close(fds[1]);
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == 127) {
        cf_atomic_abort(&a);
        return cf_error_set(err, CF_E_INTERNAL,
                            "cannot run '%s' to draw %s: install gnuplot (Debian package "
                            "gnuplot-nox)",
                            prog, path);
    }
    if (code != 0) {
        cf_atomic_abort(&a);
        return cf_error_set(err, CF_E_INTERNAL, "'%s' failed (status %d) drawing %s", prog, code,
                            path);
    }
    if (rename(a.tmp, a.path) != 0) {
        int e = errno;
        cf_atomic_abort(&a);
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write plot: %s", path, strerror(e));
    }
    a.tmp[0] = '\0';
    return CF_OK;
}
