/*
** `simulate` with a body (cli_body.h). Everything is solved before anything is written; then all
** outputs are opened as temporaries and committed together, so a failed run writes nothing.
*/
#include "cli/cli_body.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/atomic.h"
#include "cli/cli.h"
#include "cli/cli_probe.h"
#include "conifit/body.h"
#include "conifit/mesh.h"
#include "report/vtu.h"

typedef struct run {
    cf_law law;
    cf_mesh mesh;
    cf_body body;
    double *xs;          /* (steps + 1) x 3 nn positions */
    cf_body_step *step;  /* steps + 1 */
    size_t nfixed;
} run;

static void run_free(run *r)
{
    cf_body_free(&r->body);
    cf_mesh_free(&r->mesh);
    cf_law_free(&r->law);
    free(r->xs);
    free(r->step);
}

static cf_status solve(const cf_scene *sc, const char *scene_path, const cf_budget *budget, run *r,
                       cf_error *err)
{
    cf_status st;
    if ((st = cf_law_init(&r->law, &sc->spring, err)) != CF_OK ||
        (sc->method == CF_LAW_TABLE &&
         (st = cf_law_table_build(&r->law, sc->table_intervals, err)) != CF_OK) ||
        (st = cf_mesh_read_refined(sc->body_mesh, sc->body_unit_mm, sc->body_refine, &r->mesh,
                                   err)) != CF_OK)
        return st;
    const size_t steps = (size_t)sc->probe.steps;
    /* memory: the factor of the tangent (about 40 times its 3 x 3 blocks for meshes of organ
    ** size), the matrix, and one copy of the positions per step */
    double bytes = (double)r->mesh.nn * 3 * (81.0 * 16 * 8 + 40.0 * 81 * 8) +
                   (double)(steps + 1) * 3 * (double)r->mesh.nn * 8;
    if (bytes > budget->max_memory_bytes)
        return cf_error_set(err, CF_E_DATA, "%s: the body of %s (%zu nodes, %zu steps) needs "
                            "about %.3g bytes, over the limit %.3g (--max-memory)",
                            scene_path, sc->body_mesh, r->mesh.nn, steps, bytes,
                            budget->max_memory_bytes);
    double kappa = 0, mu = cf_body_mu_of_law(&r->law);
    if (sc->body_volume == 1)
        kappa = sc->body_volume_value;
    else if (sc->body_volume == 2)
        kappa = cf_body_kappa_for_nu(mu, sc->body_volume_value);
    if ((st = cf_body_create(&r->body, &r->mesh, &r->law, sc->method, kappa, err)) != CF_OK)
        return st;
    cf_body *b = &r->body;
    for (size_t i = 0; i < b->nn; i++)
        if (b->X[3 * i + (size_t)sc->fixed_axis] <= sc->fixed_value_mm) {
            b->fix[i] = CF_BODY_FIX_ALL;
            r->nfixed++;
        }
    if (r->nfixed == 0)
        return cf_error_set(err, CF_E_DATA, "%s: key 'fixed.below' (%c <= %g mm) selects no node "
                            "of %s", scene_path, 'x' + sc->fixed_axis, sc->fixed_value_mm,
                            sc->body_mesh);
    long in = cf_body_probe_inside(b, &sc->probe);
    if (in >= 0)
        return cf_error_set(err, CF_E_DATA, "%s: key 'probe.center_mm': the probe starts inside "
                            "the body (node %lu of %s at [%g, %g, %g] mm)",
                            scene_path, (unsigned long)r->mesh.id[in], sc->body_mesh,
                            b->X[3 * in], b->X[3 * in + 1], b->X[3 * in + 2]);
    r->xs = malloc((steps + 1) * 3 * b->nn * sizeof *r->xs);
    r->step = calloc(steps + 1, sizeof *r->step);
    if (!r->xs || !r->step)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps", steps);
    memcpy(r->xs, b->x, 3 * b->nn * sizeof *r->xs);
    r->step[0].min_J = 1;
    for (size_t k = 1; k <= steps; k++) {
        double depth = sc->probe.depth_mm * (double)k / (double)steps;
        if ((st = cf_body_solve(b, &sc->probe, depth, 0, &r->step[k], err)) != CF_OK)
            return st;
        if (!isfinite(r->step[k].force_N))
            return cf_error_set(err, CF_E_INTERNAL, "body: force not finite at depth %g mm", depth);
        memcpy(r->xs + k * 3 * b->nn, b->x, 3 * b->nn * sizeof *r->xs);
    }
    return CF_OK;
}

/* Opens, writes and finishes every output (nothing committed yet). */
static cf_status write_all(const cf_scene *sc, const run *r, const char *out, const char *dir,
                           const char *const *inputs, cf_cli_out *csv, cf_atomic *files,
                           cf_error *err)
{
    const cf_body *b = &r->body;
    const size_t steps = (size_t)sc->probe.steps;
    cf_status st = cf_cli_out_open(csv, out, inputs, err);
    if (st)
        return st;
    fprintf(csv->fp, "depth_mm,force_N\n");
    for (size_t k = 0; k <= steps; k++)
        fprintf(csv->fp, "%.17g,%.17g\n", r->step[k].depth_mm, r->step[k].force_N);
    if (!dir)
        return CF_OK;
    cf_body_state bs;
    bs.strain = malloc(b->ns * sizeof *bs.strain);
    bs.solid = malloc(b->ns);
    bs.J = malloc(b->nt * sizeof *bs.J);
    double *depth = malloc((steps + 1) * sizeof *depth);
    cf_body tmp = *b; /* the body's arrays with each step's positions */
    if (!bs.strain || !bs.solid || !bs.J || !depth) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the VTU files");
        goto end;
    }
    char path[4200];
    for (size_t k = 0; k <= steps && st == CF_OK; k++) {
        tmp.x = r->xs + k * 3 * b->nn;
        cf_body_measure(&tmp, &bs, NULL);
        depth[k] = r->step[k].depth_mm;
        snprintf(path, sizeof path, "%s/body_%04zu.vtu", dir, k);
        if ((st = cf_atomic_open(&files[2 * k], path, inputs, err)) != CF_OK)
            break;
        cf_vtu_body(files[2 * k].fp, b, tmp.x, bs.J);
        if ((st = cf_atomic_finish(&files[2 * k], err)) != CF_OK)
            break;
        snprintf(path, sizeof path, "%s/springs_%04zu.vtu", dir, k);
        if ((st = cf_atomic_open(&files[2 * k + 1], path, inputs, err)) != CF_OK)
            break;
        cf_vtu_springs(files[2 * k + 1].fp, b, tmp.x, bs.strain, bs.solid);
        st = cf_atomic_finish(&files[2 * k + 1], err);
    }
    if (st == CF_OK) {
        snprintf(path, sizeof path, "%s/body.pvd", dir);
        if ((st = cf_atomic_open(&files[2 * steps + 2], path, inputs, err)) == CF_OK) {
            cf_vtu_pvd(files[2 * steps + 2].fp, steps + 1, depth);
            st = cf_atomic_finish(&files[2 * steps + 2], err);
        }
    }
end:
    free(bs.strain);
    free(bs.solid);
    free(bs.J);
    free(depth);
    return st;
}

static void summary(FILE *o, const cf_scene *sc, const run *r)
{
    const cf_body *b = &r->body;
    const size_t steps = (size_t)sc->probe.steps;
    double minJ = 1, umax = 0;
    int iters = 0;
    for (size_t k = 1; k <= steps; k++) {
        minJ = fmin(minJ, r->step[k].min_J);
        umax = fmax(umax, r->step[k].max_u_over_travel);
        iters += r->step[k].newton_iters;
    }
    fprintf(o, "spring: %s; body: %s, %zu nodes, %zu tetrahedra, %zu springs, %zu nodes fixed\n",
            sc->spring_source, sc->body_mesh, b->nn, b->nt, b->ns, r->nfixed);
    fprintf(o, "body: E = %.6g kPa, nu = %.6g (shear modulus %.6g kPa from the spring, volume "
               "modulus %.6g kPa)\n",
            b->E_MPa * 1e3, b->nu, b->mu_MPa * 1e3, b->kappa_MPa * 1e3);
    fprintf(o, "probe: %s of radius %g mm to depth %g mm in %zu steps; Newton iterations: %d\n",
            sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch", sc->probe.radius_mm,
            sc->probe.depth_mm, steps, iters);
    fprintf(o, "end: depth %.6g mm, force %.6g N, %d nodes in contact; smallest J %.6g, largest "
               "spring compression %.4g of travel\n",
            r->step[steps].depth_mm, r->step[steps].force_N, r->step[steps].contacts, minJ, umax);
}

int cf_cli_simulate_body(const cf_scene *sc, const char *scene_path, const char *out,
                         const char *vtu_dir, const char *png, const cf_budget *budget, int quiet)
{
    cf_error err = {0};
    run r;
    memset(&r, 0, sizeof r);
    const char *fit = sc->fit_path[0] ? sc->fit_path : NULL;
    const char *inputs[4] = {scene_path, sc->body_mesh, fit, NULL};
    const size_t nfiles = 2 * ((size_t)sc->probe.steps + 1) + 1;
    cf_atomic *files = NULL;
    cf_cli_out csv = {0};
    cf_atomic plot = {0};
    int rc = CF_EXIT_OK;
    if ((!cf_cli_is_stdio(out) && cf_atomic_check(out, inputs, &err) != CF_OK) ||
        (png && cf_atomic_check(png, inputs, &err) != CF_OK) ||
        solve(sc, scene_path, budget, &r, &err) != CF_OK) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    if (vtu_dir && mkdir(vtu_dir, 0777) != 0 && errno != EEXIST) {
        cf_error_set(&err, CF_E_CANTWRITE, "--vtu %s: cannot create the folder: %s", vtu_dir,
                     strerror(errno));
        rc = cf_cli_fail(&err);
        goto end;
    }
    files = calloc(nfiles, sizeof *files);
    if (!files) {
        cf_error_set(&err, CF_E_INTERNAL, "out of memory");
        rc = cf_cli_fail(&err);
        goto end;
    }
    if (write_all(sc, &r, out, vtu_dir, inputs, &csv, files, &err) != CF_OK ||
        (png && cf_cli_probe_plot(sc, r.step, (size_t)sc->probe.steps + 1, png, inputs, &plot,
                                  &err) != CF_OK)) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    for (size_t k = 0; k < nfiles && vtu_dir; k++)
        if (cf_atomic_commit(&files[k], &err) != CF_OK) {
            rc = cf_cli_fail(&err);
            goto end;
        }
    if (cf_cli_out_close(&csv, &err) != CF_OK || (png && cf_atomic_commit(&plot, &err) != CF_OK)) {
        rc = cf_cli_fail(&err);
        goto end;
    }
    if (!quiet)
        summary(csv.to_stdout ? stderr : stdout, sc, &r);
end:
    cf_cli_out_abort(&csv);
    cf_atomic_abort(&plot);
    for (size_t k = 0; files && k < nfiles; k++)
        cf_atomic_abort(&files[k]);
    free(files);
    run_free(&r);
    return rc;
}

cf_status cf_cli_body_export(const cf_scene *sc, const char *scene_path, const cf_budget *budget,
                             FILE *out, const cf_export_options *opt, cf_export_report *rep,
                             cf_error *err)
{
    run r;
    memset(&r, 0, sizeof r);
    cf_status st = solve(sc, scene_path, budget, &r, err);
    const size_t steps = (size_t)sc->probe.steps;
    double *depth = NULL, *force = NULL;
    if (st == CF_OK) {
        depth = malloc(steps * sizeof *depth);
        force = malloc(steps * sizeof *force);
        if (!depth || !force)
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps", steps);
    }
    if (st == CF_OK) {
        for (size_t k = 0; k < steps; k++) {
            depth[k] = r.step[k + 1].depth_mm;
            force[k] = r.step[k + 1].force_N;
        }
        st = cf_export_write_body(out, &r.body, &sc->probe, steps, depth, force, opt, rep, err);
        if (st != CF_OK)
            snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg), " (%s)",
                     scene_path);
    }
    free(depth);
    free(force);
    run_free(&r);
    return st;
}
