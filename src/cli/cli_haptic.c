/*
** `simulate --haptic` (cli_probe.h): the probe moved along the scene's "haptic" path, one update of
** the haptic loop (cf_body_haptic_step) per millisecond of simulated time, the force of each
** update written as t_ms,depth_mm,force_N; the summary gives the wall time per update and, at
** the path's last depth, the force of a static solve of the same body for comparison.
**
** The body is built as the static probe run builds it (cli_body.c, solve): the same law, mesh,
** volume term, held nodes and checks, with the same messages.
*/
#include "cli/cli_probe.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "cli/cli_body.h"
#include "io/mesh.h"
#include "report/plot.h"

typedef struct haptic_run {
    cf_law law;
    cf_law ext; /* unused: the scene refuses a double-acting element with a haptic loop */
    cf_mesh mesh;
    cf_body body, still;  /* the haptic loop's body, and one solved statically for comparison */
    size_t nfixed;
    size_t n;             /* updates, one per ms from 0 */
    double *t_ms, *depth_mm, *force_N, *wall_ms;
    double min_J, max_u;  /* over the run */
    int max_contacts;
    cf_body_step rest;    /* the static solve at the last depth */
} haptic_run;

static void haptic_free(haptic_run *r)
{
    cf_body_free(&r->body);
    cf_body_free(&r->still);
    cf_mesh_free(&r->mesh);
    cf_law_free(&r->law);
    cf_law_free(&r->ext);
    free(r->t_ms);
    free(r->depth_mm);
    free(r->force_N);
    free(r->wall_ms);
}

/* The depth of the path at t (linear between its vertices, held after the last). */
static double path_depth(const cf_scene *sc, double t)
{
    const size_t n = sc->haptic_n;
    if (t >= sc->haptic_t_ms[n - 1])
        return sc->haptic_depth_mm[n - 1];
    size_t i = 1;
    while (sc->haptic_t_ms[i] < t)
        i++;
    const double t0 = sc->haptic_t_ms[i - 1], t1 = sc->haptic_t_ms[i];
    const double a = (t - t0) / (t1 - t0);
    return sc->haptic_depth_mm[i - 1] + a * (sc->haptic_depth_mm[i] - sc->haptic_depth_mm[i - 1]);
}

/* Builds b on r's mesh and law as the static run does (cli_body.h): volume term, the fixed
** regions' nodes held, probe outside. A region that displaces or loads is refused: the loop holds
** its supports still. */
static cf_status make_body(const cf_scene *sc, const char *scene_path, haptic_run *r, cf_body *b,
                           cf_error *err)
{
    cf_status st = cf_cli_body_create(sc, &r->law, &r->mesh, b, err);
    if (st != CF_OK)
        return st;
    uint8_t *mark = malloc(b->nn ? b->nn : 1);
    if (!mark)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the regions");
    r->nfixed = 0;
    for (size_t k = 0; k < sc->nregions && st == CF_OK; k++) {
        const cf_scene_region *g = &sc->regions[k];
        if (g->use != CF_REGION_FIXED) {
            st = cf_error_set(err, CF_E_DATA, "%s: key '%s': the haptic loop holds its supports "
                              "still ('fixed' regions only); run the scene without --haptic",
                              scene_path, g->key);
            break;
        }
        memset(mark, 0, b->nn);
        if (cf_mesh_select(&r->mesh, &g->sel, mark) == 0) {
            st = cf_error_set(err, CF_E_DATA, "%s: key '%s.%s' selects no node of %s",
                              scene_path, g->key, cf_select_name(g->sel.kind), sc->body_mesh);
            break;
        }
        for (size_t i = 0; i < b->nn; i++)
            if (mark[i])
                b->fix[i] = CF_BODY_FIX_ALL;
    }
    free(mark);
    for (size_t i = 0; st == CF_OK && i < b->nn; i++)
        r->nfixed += b->fix[i] != 0;
    if (st == CF_OK && r->nfixed == 0)
        st = cf_error_set(err, CF_E_DATA, "%s: no node of %s is held: the haptic loop needs a "
                          "'fixed' region", scene_path, sc->body_mesh);
    return st != CF_OK ? st
                       : cf_cli_body_probe_outside(sc, scene_path, b, &r->mesh, &sc->probe, err);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* Runs the loop over the path, then the static solve at its last depth. */
static cf_status run(const cf_scene *sc, const char *scene_path, const cf_budget *budget,
                     haptic_run *r, cf_error *err)
{
    cf_status st;
    const double T = sc->haptic_t_ms[sc->haptic_n - 1];
    r->n = (size_t)floor(T) + 1;
    if ((double)r->n > budget->max_steps)
        return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.path' asks for %zu updates (one per "
                            "ms to %g ms), over the limit %.3g (--max-steps)",
                            scene_path, r->n, T, budget->max_steps);
    /* per node: two bodies as the static run counts one, and the kept columns (below) */
    const double node_bytes = 2 * 3 * (81.0 * 16 * 8 + 40.0 * 81 * 8) + 9 * 1000 * 8;
    if ((st = cf_cli_body_load(sc, scene_path, budget, node_bytes, &r->law, &r->ext, &r->mesh,
                               NULL, err)) != CF_OK)
        return st;
    /* memory: two bodies (the loop's and the static one) as the static run estimates one, the
    ** loop's kept columns of the inverse (9 nn per node that touches the probe, at most all of
    ** them near the probe: counted as 1000 nodes) and four numbers per update */
    const double nn = (double)r->mesh.nn;
    const double bytes = 2 * nn * 3 * (81.0 * 16 * 8 + 40.0 * 81 * 8) +
                         9 * nn * fmin(nn, 1000) * 8 + 4 * (double)r->n * 8;
    if (bytes > budget->max_memory_bytes)
        return cf_error_set(err, CF_E_DATA, "%s: the haptic loop on %s (%zu nodes, %zu updates) "
                            "needs about %.3g bytes, over the limit %.3g (--max-memory)",
                            scene_path, sc->body_mesh, r->mesh.nn, r->n, bytes,
                            budget->max_memory_bytes);
    if ((st = make_body(sc, scene_path, r, &r->body, err)) != CF_OK ||
        (st = make_body(sc, scene_path, r, &r->still, err)) != CF_OK)
        return st;
    r->t_ms = malloc(r->n * sizeof *r->t_ms);
    r->depth_mm = malloc(r->n * sizeof *r->depth_mm);
    r->force_N = malloc(r->n * sizeof *r->force_N);
    r->wall_ms = malloc(r->n * sizeof *r->wall_ms);
    if (!r->t_ms || !r->depth_mm || !r->force_N || !r->wall_ms)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu updates", r->n);
    r->min_J = 1;
    r->max_u = 0;
    for (size_t k = 0; k < r->n; k++) {
        cf_body_step s;
        r->t_ms[k] = (double)k;
        r->depth_mm[k] = path_depth(sc, (double)k);
        const double t0 = now_ms();
        st = cf_body_haptic_step(&r->body, &sc->probe, r->depth_mm[k], 0, sc->haptic_iterations,
                                 &s, err);
        r->wall_ms[k] = now_ms() - t0;
        if (st != CF_OK)
            return st;
        if (!isfinite(s.force_N))
            return cf_error_set(err, CF_E_INTERNAL, "haptic loop: force not finite at %zu ms "
                                "(depth %g mm)", k, r->depth_mm[k]);
        r->force_N[k] = s.force_N;
        r->min_J = fmin(r->min_J, s.min_J);
        r->max_u = fmax(r->max_u, s.max_u_over_travel);
        if (s.contacts > r->max_contacts)
            r->max_contacts = s.contacts;
    }
    /* the static answer at the last depth, in the scene's steps from the rest state */
    const double last = r->depth_mm[r->n - 1];
    const int steps = sc->probe.steps > 0 ? sc->probe.steps : 10;
    for (int k = 1; k <= steps; k++)
        if ((st = cf_body_solve(&r->still, &sc->probe, last * k / steps, 0, &r->rest, err)) !=
            CF_OK)
            return st;
    return CF_OK;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void summary(FILE *o, const cf_scene *sc, const haptic_run *r)
{
    const cf_body *b = &r->body;
    double *w = malloc(r->n * sizeof *w);
    double median = NAN, p99 = NAN, worst = NAN, mean = 0;
    if (w) {
        memcpy(w, r->wall_ms, r->n * sizeof *w);
        qsort(w, r->n, sizeof *w, cmp_double);
        median = w[r->n / 2];
        p99 = w[(size_t)floor(0.99 * (double)(r->n - 1))];
        worst = w[r->n - 1];
        for (size_t k = 0; k < r->n; k++)
            mean += w[k] / (double)r->n;
        free(w);
    }
    fprintf(o, "spring: %s; body: %s, %zu nodes, %zu tetrahedra, %zu springs, %zu nodes fixed\n",
            sc->spring_source, sc->body_mesh, b->nn, b->nt, b->ns, r->nfixed);
    fprintf(o, "body: E = %.6g kPa, nu = %.6g\n", b->E_MPa * 1e3, b->nu);
    fprintf(o, "haptic: %zu updates, one per ms of simulated time (0 to %zu ms), at most %d chord "
               "iterations each; %s of radius %g mm, at most %d nodes in contact\n",
            r->n, r->n - 1, sc->haptic_iterations,
            sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch", sc->probe.radius_mm,
            r->max_contacts);
    fprintf(o, "wall time per update: median %.4g ms, mean %.4g ms, 99th percentile %.4g ms, "
               "largest %.4g ms (the first factors the tangent); 1 kHz %s\n",
            median, mean, p99, worst, median <= 1 ? "held (median <= 1 ms)" : "not held");
    const double fh = r->force_N[r->n - 1], fs = r->rest.force_N;
    fprintf(o, "at the last depth %.6g mm: haptic force %.6g N, static solve %.6g N", 
            r->depth_mm[r->n - 1], fh, fs);
    if (fs != 0)
        fprintf(o, " (ratio %.5f)", fh / fs);
    fprintf(o, "\nstable: smallest J %.6g, largest spring compression %.4g of travel, every force "
               "finite\n",
            r->min_J, r->max_u);
}

int cf_cli_simulate_haptic(const cf_scene *sc, const char *scene_path, const char *out,
                           const char *png, const cf_budget *budget, int quiet)
{
    cf_error err = {0};
    if (sc->haptic_n == 0) {
        cf_error_set(&err, CF_E_DATA, "%s: --haptic needs the key 'haptic': {\"path\": [[t_ms, "
                     "depth_mm], ...]}", scene_path);
        return cf_cli_fail(&err);
    }
    haptic_run r;
    memset(&r, 0, sizeof r);
    const char *fit = sc->fit_path[0] ? sc->fit_path : NULL;
    const char *inputs[4] = {scene_path, sc->body_mesh, fit, NULL};
    cf_cli_out csv = {0};
    cf_atomic plot = {0};
    int rc = CF_EXIT_OK;
    if ((!cf_cli_is_stdio(out) && cf_atomic_check(out, inputs, &err) != CF_OK) ||
        (png && cf_atomic_check(png, inputs, &err) != CF_OK) ||
        run(sc, scene_path, budget, &r, &err) != CF_OK ||
        cf_cli_out_open(&csv, out, inputs, &err) != CF_OK) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    fprintf(csv.fp, "t_ms,depth_mm,force_N\n");
    for (size_t k = 0; k < r.n; k++)
        fprintf(csv.fp, "%.17g,%.17g,%.17g\n", r.t_ms[k], r.depth_mm[k], r.force_N[k]);
    char title[4300], series[700];
    snprintf(title, sizeof title, "haptic loop: %s of radius %g mm on %s",
             sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch", sc->probe.radius_mm,
             sc->body_mesh);
    snprintf(series, sizeof series, "body (spring: %s), one update per ms", sc->spring_source);
    if ((png && cf_plot_probe(title, series, "simulated time (ms)", r.t_ms, r.force_N, r.n, png,
                              inputs, &plot, &err) != CF_OK) ||
        cf_cli_out_close(&csv, &err) != CF_OK || (png && cf_atomic_commit(&plot, &err) != CF_OK)) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    if (!quiet)
        summary(csv.to_stdout ? stderr : stdout, sc, &r);
end:
    cf_cli_out_abort(&csv);
    cf_atomic_abort(&plot);
    haptic_free(&r);
    return rc;
}
