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
#include "model/body.h"
#include "io/budget.h"
#include "io/mesh.h"
#include "report/vtu.h"

typedef struct run {
    cf_law law;
    cf_law ext;          /* a double-acting element's extension spring (law.extension) */
    cf_mesh mesh;
    cf_body body;
    size_t steps;
    double *xs;          /* (steps + 1) x 3 nn positions */
    cf_body_step *step;  /* steps + 1 */
    size_t nfixed;       /* nodes with a held component */
    cf_mesh_surface_info surface; /* a surface filled with tetrahedra: what was found and done */
    double *presc;       /* 3 nn: each held component's displacement at the last step, mm */
    double *fload;       /* 3 nn: the loads at the last step, N (NULL: none) */
    uint8_t *mark;       /* nregions x nn: the nodes of each region */
    size_t *nsel;        /* nregions: how many */
    double *time;        /* steps + 1: a probe path's times, s */
    double *rv;          /* (steps + 1) x nregions x 3: a held region's support force (N), a loaded
                         ** one's mean displacement (mm) */
    cf_body_motion motion; /* a dynamic run's masses and state */
    int keep_forces;     /* keep each step's contact and support forces (for --vtu) */
    double *contact;     /* (steps + 1) x 3 nn: the probe's force on each node, N */
    double *reaction;    /* (steps + 1) x 3 nn: the supports' force at each held component, N */
    uint8_t *contact_set; /* (steps + 1) x nn: each static step's contact set (for the export) */
} run;

static void run_free(run *r)
{
    cf_body_free(&r->body);
    cf_mesh_free(&r->mesh);
    cf_law_free(&r->law);
    cf_law_free(&r->ext);
    free(r->xs);
    free(r->step);
    free(r->presc);
    free(r->fload);
    free(r->mark);
    free(r->nsel);
    free(r->rv);
    free(r->time);
    free(r->contact);
    free(r->contact_set);
    free(r->reaction);
    cf_body_motion_free(&r->motion);
}

cf_status cf_cli_body_load(const cf_scene *sc, const char *scene_path, const cf_budget *budget,
                           double node_bytes, cf_law *law, cf_law *ext, cf_mesh *mesh,
                           cf_mesh_surface_info *surface, cf_error *err)
{
    cf_status st;
    cf_mesh_surface_info unused;
    /* the law as a lattice scene's (with its table, and a double-acting element's extension
    ** spring joined to it) */
    if ((st = cf_scene_law(sc, law, ext, err)) != CF_OK)
        return st;
    const double tables = cf_budget_law_tables_bytes(sc);
    if (tables >= budget->max_memory_bytes)
        return cf_error_set(err, CF_E_DATA, "%s: key 'table_intervals' = %zu: the law tables need "
                            "%.3g bytes, over the limit %.3g (--max-memory)", scene_path,
                            sc->table_intervals, tables, budget->max_memory_bytes);
    cf_mesh_limits lim = cf_mesh_limits_default();
    lim.max_bytes = budget->max_memory_bytes - tables; /* what the mesh and its solve may take */
    lim.node_bytes = node_bytes;
    st = sc->body_element_size_mm > 0
             ? cf_mesh_from_surface(sc->body_mesh, sc->body_unit_mm, sc->body_element_size_mm,
                                    &lim, mesh, surface ? surface : &unused, err)
             : cf_mesh_read_refined(sc->body_mesh, sc->body_unit_mm, sc->body_refine, &lim, mesh,
                                    err);
    if (st == CF_E_DATA && err && strstr(err->msg, "over the memory limit")) {
        const size_t n = strlen(err->msg);
        snprintf(err->msg + n, sizeof err->msg - n, " (raise it with --max-memory)");
    }
    return st;
}

cf_status cf_cli_body_create(const cf_scene *sc, const cf_law *law, const cf_mesh *mesh,
                             cf_body *b, cf_error *err)
{
    double kappa = 0, mu = cf_body_mu_of_law(law);
    if (sc->body_volume == 1 || sc->body_volume == 3) /* 3: the fit's lattice's, the same kappa */
        kappa = sc->body_volume_value;
    else if (sc->body_volume == 2)
        kappa = cf_body_kappa_for_nu(mu, sc->body_volume_value);
    cf_status st = cf_body_create(b, mesh, law, sc->method, kappa, err);
    if (st != CF_OK || (st = cf_cli_body_fibres(sc, b, err)) != CF_OK ||
        (st = cf_cli_body_element_term(sc, b, err)) != CF_OK || sc->ngroups == 0)
        return st;
    /* the scene's spring groups by region */
    cf_select sel[CF_SCENE_MAX_GROUPS];
    cf_spring spring[CF_SCENE_MAX_GROUPS];
    char keys[CF_SCENE_MAX_GROUPS][32];
    const char *key[CF_SCENE_MAX_GROUPS];
    for (size_t g = 0; g < sc->ngroups; g++) {
        sel[g] = sc->groups[g].sel;
        spring[g] = sc->groups[g].spring;
        snprintf(keys[g], sizeof keys[g], "groups[%zu]", g);
        key[g] = keys[g];
    }
    cf_error e = {0};
    if ((st = cf_body_set_groups(b, mesh, sc->ngroups, sel, spring, key, sc->table_intervals,
                                 &e)) != CF_OK)
        cf_error_set(err, st, "%s", e.msg);
    return st;
}

cf_status cf_cli_body_probe_outside(const cf_scene *sc, const char *scene_path,
                                    const cf_body *b, const cf_mesh *mesh, const cf_probe *probe,
                                    cf_error *err)
{
    long in = cf_body_probe_inside(b, probe);
    if (in >= 0)
        return cf_error_set(err, CF_E_DATA, "%s: key 'probe.center_mm': the probe starts inside "
                            "the body (node %lu of %s at [%g, %g, %g] mm)",
                            scene_path, (unsigned long)mesh->id[in], sc->body_mesh,
                            b->X[3 * in], b->X[3 * in + 1], b->X[3 * in + 2]);
    return CF_OK;
}

/* The regions of sc on the body: held components and their displacements, the loads. A region
** that selects nothing, and a component two regions hold at different displacements, are
** refused. */
static cf_status regions(const cf_scene *sc, const char *scene_path, run *r, cf_error *err)
{
    cf_body *b = &r->body;
    const size_t nn = b->nn, nr = sc->nregions;
    uint8_t *owner = calloc(3 * nn, 1); /* 1 + the region that holds a component */
    r->presc = calloc(3 * nn, sizeof *r->presc);
    r->mark = calloc(nr * nn + 1, 1);
    r->nsel = calloc(nr + 1, sizeof *r->nsel);
    r->rv = calloc((r->steps + 1) * nr * 3 + 1, sizeof *r->rv);
    b->reaction = calloc(3 * nn, sizeof *b->reaction);
    cf_status st = CF_OK;
    if (!owner || !r->presc || !r->mark || !r->nsel || !r->rv || !b->reaction) {
        free(owner);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the regions");
    }
    for (size_t k = 0; k < nr && st == CF_OK; k++) {
        const cf_scene_region *g = &sc->regions[k];
        uint8_t *m = r->mark + k * nn;
        r->nsel[k] = cf_mesh_select(&r->mesh, &g->sel, m);
        if (r->nsel[k] == 0) {
            st = cf_error_set(err, CF_E_DATA, "%s: key '%s.%s' selects no node of %s",
                              scene_path, g->key, cf_select_name(g->sel.kind), sc->body_mesh);
            break;
        }
        if (g->use == CF_REGION_LOADED) {
            if (!r->fload && !(r->fload = calloc(3 * nn, sizeof *r->fload)))
                st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the loads");
            else if (cf_body_spread_force(b, m, g->vec, r->fload) == 0)
                st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the loads");
            continue;
        }
        for (size_t i = 0; i < nn && st == CF_OK; i++)
            for (int a = 0; m[i] && a < 3; a++) {
                if (!((g->comps >> a) & 1))
                    continue;
                const size_t q = 3 * i + (size_t)a;
                if (owner[q] && r->presc[q] != g->vec[a]) {
                    st = cf_error_set(err, CF_E_DATA, "%s: keys '%s' and '%s' hold the %c "
                                      "component of node %lu of %s at different displacements "
                                      "(%g and %g mm)", scene_path, sc->regions[owner[q] - 1].key,
                                      g->key, 'x' + a, (unsigned long)r->mesh.id[i],
                                      sc->body_mesh, r->presc[q], g->vec[a]);
                    break;
                }
                owner[q] = (uint8_t)(k + 1);
                r->presc[q] = g->vec[a];
                b->fix[i] |= (uint8_t)(1u << a);
            }
    }
    free(owner);
    for (size_t i = 0; i < nn; i++)
        r->nfixed += b->fix[i] != 0;
    return st;
}

/* The regions' numbers at step k: support forces of held regions (at the components they hold),
** mean displacements of loaded ones. */
static void region_values(const cf_scene *sc, run *r, size_t k)
{
    const cf_body *b = &r->body;
    const size_t nn = b->nn, nr = sc->nregions;
    for (size_t g = 0; g < nr; g++) {
        double *v = r->rv + (k * nr + g) * 3;
        const uint8_t *m = r->mark + g * nn;
        v[0] = v[1] = v[2] = 0;
        const unsigned comps = sc->regions[g].use == CF_REGION_LOADED ? 7 : sc->regions[g].comps;
        for (size_t i = 0; i < nn; i++)
            for (int a = 0; m[i] && a < 3; a++)
                if ((comps >> a) & 1)
                    v[a] += sc->regions[g].use == CF_REGION_LOADED
                            ? (b->x[3 * i + (size_t)a] - b->X[3 * i + (size_t)a]) /
                                  (double)r->nsel[g]
                            : b->reaction[3 * i + (size_t)a];
    }
}

/* A dynamic run's steps and their work (an implicit step costs about a static solve of the same
** unknowns, cf_budget_solve_work) against --max-steps and --max-work, before anything runs. */
static cf_status dynamic_budget(const cf_scene *sc, const char *scene_path,
                                const cf_budget *budget, size_t nn, cf_error *err)
{
    const double steps = sc->body_steps, each = cf_budget_solve_work(3.0 * (double)nn);
    if (steps <= budget->max_steps && steps * each <= budget->max_work)
        return CF_OK;
    const double fits = fmin(budget->max_steps, floor(budget->max_work / each));
    return cf_error_set(err, CF_E_DATA, "%s: key 'integrator.dt_s' = %g: %.0f implicit steps of "
                        "the body of %s (%zu nodes, about %.3g spring-steps each) are over the "
                        "limits %.3g steps (--max-steps) or %.3g spring-steps (--max-work); "
                        "at most %.0f steps fit, a step of at least %.3g s",
                        scene_path, sc->cfg.dt_s, steps, sc->body_mesh, nn, each,
                        budget->max_steps, budget->max_work, fits,
                        fits >= 1 ? sc->body_duration_s / fits : INFINITY);
}

/* The fraction of the scene's loads, displacements and probe depth at step k of `steps`: k/steps
** in a static run; in a dynamic one, the time k dt over body.ramp_s, 1 after it (and from the
** first step when ramp_s is 0). */
static double load_factor(const cf_scene *sc, size_t k, size_t steps)
{
    if (!sc->body_dynamic)
        return (double)k / (double)steps;
    const double t = (double)k * sc->body_dt_s;
    return sc->body_ramp_s > 0 ? fmin(1, t / sc->body_ramp_s) : (k > 0);
}

/* A probe on a path at the fraction lam of its time: its reference point into *moved, its travel
** along the direction from the path's start into *travel; returns the time. */
static double path_probe(const cf_scene *sc, double lam, cf_probe *moved, double *travel)
{
    const size_t np = sc->probe_npath;
    const double *ts = sc->probe_path_t_s;
    const double t = ts[0] + lam * (ts[np - 1] - ts[0]);
    size_t j = 0;
    while (j + 2 < np && ts[j + 1] < t)
        j++;
    const double w = fmin(1, fmax(0, (t - ts[j]) / (ts[j + 1] - ts[j])));
    *travel = 0;
    for (int a = 0; a < 3; a++) {
        moved->center_mm[a] = (1 - w) * sc->probe_path_mm[j][a] + w * sc->probe_path_mm[j + 1][a];
        *travel += (moved->center_mm[a] - sc->probe.center_mm[a]) * sc->probe.dir[a];
    }
    return t;
}

/* With r->keep_forces: at k = 0 the arrays of every step's contact and support forces (step 0's
** zero) and the body's contact forces; at k > 0 step k's copied from the body. */
static cf_status keep_forces(run *r, size_t k, cf_error *err)
{
    cf_body *b = &r->body;
    const size_t n = 3 * b->nn;
    if (!r->keep_forces)
        return CF_OK;
    if (k > 0) {
        memcpy(r->contact + k * n, b->contact, n * sizeof *r->contact);
        memcpy(r->reaction + k * n, b->reaction, n * sizeof *r->reaction);
        return CF_OK;
    }
    r->contact = calloc((r->steps + 1) * n, sizeof *r->contact);
    r->reaction = calloc((r->steps + 1) * n, sizeof *r->reaction);
    b->contact = calloc(n, sizeof *b->contact);
    if (!r->contact || !r->reaction || !b->contact)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps' forces", r->steps);
    return CF_OK;
}

static cf_status solve(const cf_scene *sc, const char *scene_path, const cf_budget *budget, run *r,
                       cf_error *err)
{
    cf_status st;
    if ((st = cf_cli_body_load(sc, scene_path, budget, cf_budget_body_node_bytes(sc, r->keep_forces),
                               &r->law, &r->ext, &r->mesh, &r->surface, err)) != CF_OK)
        return st;
    const size_t steps = r->steps = (size_t)sc->body_steps;
    if (sc->body_dynamic && (st = dynamic_budget(sc, scene_path, budget, r->mesh.nn, err)))
        return st;
    /* memory: per node (cf_budget_body_node_bytes) and the law tables */
    double bytes = r->mesh.nn * cf_budget_body_node_bytes(sc, r->keep_forces) +
                   cf_budget_law_tables_bytes(sc);
    if (bytes > budget->max_memory_bytes)
        return cf_error_set(err, CF_E_DATA, "%s: the body of %s (%zu nodes, %zu steps) needs "
                            "about %.3g bytes, over the limit %.3g (--max-memory)",
                            scene_path, sc->body_mesh, r->mesh.nn, steps, bytes,
                            budget->max_memory_bytes);
    if ((st = cf_cli_body_create(sc, &r->law, &r->mesh, &r->body, err)) != CF_OK)
        return st;
    cf_body *b = &r->body;
    if ((st = regions(sc, scene_path, r, err)) != CF_OK)
        return st;
    cf_probe none = {.shape = CF_PROBE_SPHERE, .dir = {0, 0, 1}}; /* radius 0: touches nothing */
    const cf_probe *probe = sc->has_probe ? &sc->probe : &none;
    if ((st = cf_cli_body_probe_outside(sc, scene_path, b, &r->mesh, probe, err)) != CF_OK)
        return st;
    r->xs = malloc((steps + 1) * 3 * b->nn * sizeof *r->xs);
    r->step = calloc(steps + 1, sizeof *r->step);
    r->time = calloc(steps + 1, sizeof *r->time);
    r->contact_set = calloc((steps + 1) * b->nn, 1);
    if (!r->time || !r->contact_set)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps", steps);
    if (sc->probe_npath)
        r->time[0] = sc->probe_path_t_s[0];
    if (r->fload && !(b->f_ext = calloc(3 * b->nn, sizeof *b->f_ext)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the loads");
    if (!r->xs || !r->step)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps", steps);
    if ((st = keep_forces(r, 0, err)) != CF_OK)
        return st;
    memcpy(r->xs, b->x, 3 * b->nn * sizeof *r->xs);
    r->step[0].min_J = 1;
    if (sc->body_dynamic &&
        (st = cf_body_motion_init(b, sc->cfg.lattice.density_t_per_mm3, sc->body_damping_per_s,
                                  &r->motion, err)) != CF_OK)
        return st;
    r->motion.gamma = sc->body_newmark_gamma;
    double fdepth = 0; /* a force-driven probe's depth, found step by step */
    for (size_t k = 1; k <= steps; k++) {
        const double lam = load_factor(sc, k, steps);
        const double depth = sc->has_probe ? sc->probe.depth_mm * lam : 0;
        for (size_t q = 0; q < 3 * b->nn; q++) {
            if ((b->fix[q / 3] >> (q % 3)) & 1)
                b->x[q] = b->X[q] + lam * r->presc[q];
            if (r->fload)
                b->f_ext[q] = lam * r->fload[q];
        }
        cf_probe moved = sc->probe; /* a probe on a path: its reference point at this time */
        const cf_probe *pk = probe;
        double dk = depth, travel = 0;
        if (sc->probe_npath) {
            r->time[k] = path_probe(sc, lam, &moved, &travel);
            pk = &moved;
            dk = 0;
        }
        if (sc->body_dynamic)
            r->time[k] = (double)k * sc->body_dt_s;
        if ((st = sc->body_dynamic
                      ? cf_body_dynamic_step(b, &r->motion, pk, dk, sc->body_dt_s, 0, &r->step[k],
                                             err)
                  : sc->has_probe && sc->probe.force_N > 0
                      ? cf_body_solve_force(b, pk, sc->probe.force_N * lam, &fdepth, 0,
                                            &r->step[k], err)
                      : cf_body_solve(b, pk, dk, 0, &r->step[k], err)) != CF_OK) {
            if (err && st == CF_E_DATA && sc->probe.force_N > 0) { /* the scene's key */
                char why[sizeof err->msg];
                snprintf(why, sizeof why, "%s", err->msg);
                snprintf(err->msg, sizeof err->msg, "%s: key 'probe.force_N' = %g: %.400s",
                         scene_path, sc->probe.force_N, why);
            }
            if (err) /* which step: without a probe the depth says nothing */
                snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg),
                         " (step %zu of %zu, loads at %g of the scene's)", k, steps, lam);
            return st;
        }
        if (!sc->has_probe)
            r->step[k].depth_mm = lam; /* the load factor stands for the depth */
        if (sc->probe_npath)
            r->step[k].depth_mm = travel; /* along the direction, from the path's start */
        if (!isfinite(r->step[k].force_N))
            return cf_error_set(err, CF_E_INTERNAL, "body: force not finite at step %zu", k);
        region_values(sc, r, k);
        memcpy(r->xs + k * 3 * b->nn, b->x, 3 * b->nn * sizeof *r->xs);
        keep_forces(r, k, err);
        if (!sc->body_dynamic)
            cf_body_contact_set(b, r->contact_set + k * b->nn);
    }
    return CF_OK;
}

/* The CSV's column names of region k (a held region's support force, a loaded one's mean
** displacement), or 0 for a fixed region (no columns). */
static int region_columns(const cf_scene_region *g, FILE *f)
{
    if (g->use == CF_REGION_FIXED)
        return 0;
    char name[48];
    size_t n = 0;
    for (const char *p = g->key; *p && n + 1 < sizeof name; p++) /* "displaced[1]" -> displaced1 */
        if (*p != '[' && *p != ']')
            name[n++] = *p;
    name[n] = 0;
    for (int a = 0; a < 3; a++)
        fprintf(f, g->use == CF_REGION_LOADED ? ",%s_u%c_mm" : ",%s_F%c_N", name, 'x' + a);
    return 1;
}

/* The ParaView files of every step into dir (nothing committed yet): the PVD's time is the
** run's time (s) when it has one, else the load factor k/steps (the pseudo time of a static
** run, 0 to 1); the probe's depth and force are each file's field data. */
static cf_status write_vtu(const cf_scene *sc, const run *r, const char *dir, int timed,
                           const char *const *inputs, cf_atomic *files, cf_error *err)
{
    const cf_body *b = &r->body;
    const size_t steps = r->steps;
    cf_status st = CF_OK;
    cf_body_state bs;
    bs.strain = malloc(b->ns * sizeof *bs.strain);
    bs.solid = malloc(b->ns);
    bs.J = malloc(b->nt * sizeof *bs.J);
    cf_body_fields q;
    q.node_stress = malloc(6 * b->nn * sizeof *q.node_stress);
    q.stress = malloc(6 * b->nt * sizeof *q.stress);
    q.strain = malloc(6 * b->nt * sizeof *q.strain);
    q.mises = malloc(b->nt * sizeof *q.mises);
    q.force = malloc(b->ns * sizeof *q.force);
    double *time = malloc((steps + 1) * sizeof *time);
    cf_body tmp = *b; /* the body's arrays with each step's positions */
    if (!bs.strain || !bs.solid || !bs.J || !time || !q.node_stress || !q.stress || !q.strain ||
        !q.mises || !q.force) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the VTU files");
        goto end;
    }
    char path[4200];
    for (size_t k = 0; k <= steps && st == CF_OK; k++) {
        tmp.x = r->xs + k * 3 * b->nn;
        cf_body_measure(&tmp, &bs, NULL);
        if ((st = cf_body_fields_at(b, tmp.x, &q, err)) != CF_OK)
            break;
        time[k] = timed ? r->time[k] : (double)k / (double)steps;
        const cf_vtu_state vs = {tmp.x, bs.J, &q, r->contact + k * 3 * b->nn,
                                 r->reaction + k * 3 * b->nn, bs.strain, bs.solid, time[k], k,
                                 sc->has_probe, r->step[k].depth_mm, r->step[k].force_N};
        snprintf(path, sizeof path, "%s/body_%04zu.vtu", dir, k);
        if ((st = cf_atomic_open(&files[2 * k], path, inputs, err)) != CF_OK)
            break;
        cf_vtu_body(files[2 * k].fp, b, &vs);
        if ((st = cf_atomic_finish(&files[2 * k], err)) != CF_OK)
            break;
        snprintf(path, sizeof path, "%s/springs_%04zu.vtu", dir, k);
        if ((st = cf_atomic_open(&files[2 * k + 1], path, inputs, err)) != CF_OK)
            break;
        cf_vtu_springs(files[2 * k + 1].fp, b, &vs);
        st = cf_atomic_finish(&files[2 * k + 1], err);
    }
    if (st == CF_OK) {
        snprintf(path, sizeof path, "%s/body.pvd", dir);
        if ((st = cf_atomic_open(&files[2 * steps + 2], path, inputs, err)) == CF_OK) {
            cf_vtu_pvd(files[2 * steps + 2].fp, steps + 1, time,
                       timed ? "the run's time in s"
                             : "the load factor, step k of n at k/n (static equilibria); "
                               "field data probe_depth_mm holds the depth");
            st = cf_atomic_finish(&files[2 * steps + 2], err);
        }
    }
end:
    free(bs.strain);
    free(bs.solid);
    free(bs.J);
    free(q.node_stress);
    free(q.stress);
    free(q.strain);
    free(q.mises);
    free(q.force);
    free(time);
    return st;
}

/* Opens, writes and finishes every output (nothing committed yet). */
static cf_status write_all(const cf_scene *sc, const run *r, const char *out, const char *dir,
                           const char *const *inputs, cf_cli_out *csv, cf_atomic *files,
                           cf_error *err)
{
    const size_t steps = r->steps;
    cf_status st = cf_cli_out_open(csv, out, inputs, err);
    if (st)
        return st;
    const int timed = sc->probe_npath || sc->body_dynamic; /* a time column */
    if (timed)
        fprintf(csv->fp, "time_s,");
    fprintf(csv->fp, !sc->has_probe ? "load_factor" : "depth_mm,force_N");
    for (size_t g = 0; g < sc->nregions; g++)
        region_columns(&sc->regions[g], csv->fp);
    fprintf(csv->fp, "\n");
    for (size_t k = 0; k <= steps; k++) {
        if (timed)
            fprintf(csv->fp, "%.17g,", r->time[k]);
        fprintf(csv->fp, "%.17g", r->step[k].depth_mm);
        if (sc->has_probe)
            fprintf(csv->fp, ",%.17g", r->step[k].force_N);
        for (size_t g = 0; g < sc->nregions; g++)
            if (sc->regions[g].use != CF_REGION_FIXED)
                for (int a = 0; a < 3; a++)
                    fprintf(csv->fp, ",%.17g", r->rv[(k * sc->nregions + g) * 3 + (size_t)a]);
        fprintf(csv->fp, "\n");
    }
    if (!dir)
        return CF_OK;
    return write_vtu(sc, r, dir, timed, inputs, files, err);
}

static double total_mass(const run *r)
{
    double m = 0;
    for (size_t i = 0; r->motion.mass && i < r->body.nn; i++)
        m += r->motion.mass[i];
    return m;
}

/* A static run's stability: each step's equilibrium stable when the last stiffness matrix its
** solve factored has no negative eigenvalue (cf_body_step.neg_pivots). A dynamic step's matrix
** holds the masses, so it says nothing of the equilibrium: no line. */
static void stability(FILE *o, const cf_scene *sc, const run *r)
{
    if (sc->body_dynamic)
        return;
    size_t stable = 0, unknown = 0, first = 0;
    for (size_t k = 1; k <= r->steps; k++) {
        const long neg = r->step[k].neg_pivots;
        stable += neg == 0;
        unknown += neg < 0;
        if (neg > 0 && !first)
            first = k;
    }
    fprintf(o, "stability: %zu of %zu steps a stable equilibrium (no negative eigenvalue of the "
               "stiffness matrix)", stable, r->steps);
    if (first)
        fprintf(o, "; unstable from step %zu (%s %g%s): %ld negative eigenvalues, the body can "
                   "buckle or snap through there",
                first, sc->has_probe ? "depth" : "load factor", r->step[first].depth_mm,
                sc->has_probe ? " mm" : "", r->step[first].neg_pivots);
    if (unknown)
        fprintf(o, "; %zu steps not checked (no stiffness matrix factored)", unknown);
    fprintf(o, "\n");
}

/* The body's spring groups (scene "groups"): each region's springs and the law they take (the
** body's E and nu above are of the scene spring's law). */
static void groups_line(FILE *o, const cf_scene *sc, const cf_body *b)
{
    for (size_t g = 0; g < sc->ngroups && b->group; g++) {
        size_t n = 0;
        for (size_t s = 0; s < b->ns; s++)
            n += b->group[s] == g + 1;
        fprintf(o, "group %zu (region '%s'): %zu springs take the law of spring %s (shear modulus "
                   "%.6g kPa)\n",
                g, cf_select_name(sc->groups[g].sel.kind), n, sc->groups[g].source,
                cf_body_mu_of_law(b->glaw[g + 1]) * 1e3);
    }
}

/* A double-acting element: which spring each side takes, and the shear modulus the extension
** spring gives (the body's E and nu are the compression spring's, cf_body_mu_of_law). */
static void pair_line(FILE *o, const run *r)
{
    const cf_law *law = &r->law, *ext = law->extension;
    if (!ext)
        return;
    fprintf(o, "double-acting element: edges in compression take the spring (k0 %.6g N/mm), "
               "edges in extension the extension spring (k0 %.6g N/mm, shear modulus %.6g kPa "
               "in extension; E and nu above are in compression)\n",
            law->k0_N_per_mm, ext->k0_N_per_mm,
            r->body.mu_MPa * ext->k0_N_per_mm / law->k0_N_per_mm * 1e3);
}

static void summary(FILE *o, const cf_scene *sc, const run *r)
{
    const cf_body *b = &r->body;
    const size_t steps = r->steps;
    double minJ = 1, umax = 0;
    int iters = 0;
    for (size_t k = 1; k <= steps; k++) {
        minJ = fmin(minJ, r->step[k].min_J);
        umax = fmax(umax, r->step[k].max_u_over_travel);
        iters += r->step[k].newton_iters;
    }
    fprintf(o, "spring: %s; body: %s, %zu nodes, %zu tetrahedra, %zu springs, %zu nodes held\n",
            sc->spring_source, sc->body_mesh, b->nn, b->nt, b->ns, r->nfixed);
    fprintf(o, "body: E = %.6g kPa, nu = %.6g (shear modulus %.6g kPa from the spring, volume "
               "modulus %.6g kPa)\n",
            b->E_MPa * 1e3, b->nu, b->mu_MPa * 1e3, b->kappa_MPa * 1e3);
    if (sc->body_volume == 3)
        fprintf(o, "volume term: the fit's lattice's, kappa = %.6g kPa taken whole (the isotropic "
                   "lattice and the body share mu = k0/(2.5 H) and lambda = mu + kappa, so the "
                   "body has the lattice's small-strain E = %.6g kPa and nu = %.6g)\n",
                b->kappa_MPa * 1e3, b->E_MPa * 1e3, b->nu);
    groups_line(o, sc, b);
    cf_cli_body_fibres_line(o, sc, b);
    pair_line(o, r);
    if (sc->body_element_size_mm > 0) {
        const cf_mesh_surface_info *si = &r->surface;
        double V = 0;
        for (size_t t = 0; t < b->nt; t++)
            V += b->V0[t];
        fprintf(o, "surface: %zu vertices, %zu triangles%s, enclosing %.6g mm^3; filled with "
                   "tetrahedra of %g mm: %.6g mm^3 (%.4f of it)\n",
                si->vertices, si->triangles, si->reversed ? " (turned outward)" : "",
                si->enclosed_mm3, sc->body_element_size_mm, V, V / si->enclosed_mm3);
        if (si->crossings)
            fprintf(o, "surface: %zu edges crossed the surface elsewhere; %zu vertices smoothed "
                       "(moved at most %.3g mm) to undo it\n",
                    si->crossings, si->smoothed, si->max_move_mm);
    }
    for (size_t g = 0; g < sc->nregions; g++) {
        const cf_scene_region *rg = &sc->regions[g];
        const double *v = r->rv + (steps * sc->nregions + g) * 3;
        fprintf(o, "region %s.%s: %zu nodes; at the end %s [%.6g, %.6g, %.6g] %s\n", rg->key,
                cf_select_name(rg->sel.kind), r->nsel[g],
                rg->use == CF_REGION_LOADED ? "mean displacement" : "support force", v[0], v[1],
                v[2], rg->use == CF_REGION_LOADED ? "mm" : "N");
    }
    if (sc->body_dynamic)
        fprintf(o, "dynamic: %zu implicit steps (Newmark, gamma %g) of %g s to %g s, "
                   "loads ramped over %g s, density %g t/mm^3, damping %g 1/s, mass %.6g t\n",
                steps, sc->body_newmark_gamma, sc->body_dt_s, sc->body_duration_s, sc->body_ramp_s,
                sc->cfg.lattice.density_t_per_mm3, sc->body_damping_per_s, total_mass(r));
    if (!sc->has_probe) {
        fprintf(o, "no probe: loads ramped in %zu steps; Newton iterations: %d; smallest J %.6g, "
                   "largest spring compression %.4g of travel\n",
                steps, iters, minJ, umax);
        return;
    }
    if (sc->probe_npath)
        fprintf(o, "probe: %s of radius %g mm along a path of %zu points over %g s in %zu steps; "
                   "Newton iterations: %d\n",
                sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch",
                sc->probe.radius_mm, sc->probe_npath,
                sc->probe_path_t_s[sc->probe_npath - 1] - sc->probe_path_t_s[0], steps, iters);
    else if (sc->probe.force_N > 0)
        fprintf(o, "probe: %s of radius %g mm pressed to %g N in %zu steps; Newton iterations: "
                   "%d\n",
                sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch",
                sc->probe.radius_mm, sc->probe.force_N, steps, iters);
    else
        fprintf(o, "probe: %s of radius %g mm to depth %g mm in %zu steps; Newton iterations: "
                   "%d\n",
                sc->probe.shape == CF_PROBE_SPHERE ? "sphere" : "flat punch",
                sc->probe.radius_mm, sc->probe.depth_mm, steps, iters);
    fprintf(o, "end: depth %.6g mm, force %.6g N, %d nodes in contact; smallest J %.6g, largest "
               "spring compression %.4g of travel\n",
            r->step[steps].depth_mm, r->step[steps].force_N, r->step[steps].contacts, minJ, umax);
}

/* 1 when path names one of the files --vtu dir writes for a run of steps steps: dir/body.pvd,
** dir/body_NNNN.vtu or dir/springs_NNNN.vtu with NNNN from 0000 to the last step. */
static int vtu_file(const char *path, const char *dir, size_t steps)
{
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path;
    const char *num = strncmp(base, "body_", 5) == 0      ? base + 5
                      : strncmp(base, "springs_", 8) == 0 ? base + 8
                                                          : NULL;
    if (strcmp(base, "body.pvd") != 0) {
        if (!num)
            return 0;
        char *end;
        errno = 0;
        unsigned long long k = strtoull(num, &end, 10);
        char again[32];
        snprintf(again, sizeof again, "%04llu", k);
        if (errno || end == num || strcmp(end, ".vtu") != 0 || k > steps ||
            strncmp(again, num, (size_t)(end - num)) != 0 || strlen(again) != (size_t)(end - num))
            return 0;
    }
    char mine[4200];
    snprintf(mine, sizeof mine, "%s/%s", dir, base);
    return cf_same_target(path, mine);
}

int cf_cli_simulate_body(const cf_scene *sc, const char *scene_path, const char *out,
                         const char *vtu_dir, const char *png, const cf_budget *budget, int quiet)
{
    cf_error err = {0};
    run r;
    memset(&r, 0, sizeof r);
    const char *fit = sc->fit_path[0] ? sc->fit_path : NULL;
    const char *inputs[4] = {scene_path, sc->body_mesh, fit, NULL};
    const size_t nfiles = 2 * ((size_t)sc->body_steps + 1) + 1;
    cf_atomic *files = NULL;
    cf_cli_out csv = {0};
    cf_atomic plot = {0};
    int rc = CF_EXIT_OK;
    /* the CSV must not replace a ParaView file (a plot's name ends in .png, .svg or .pdf) */
    if (vtu_dir && !cf_cli_is_stdio(out) && vtu_file(out, vtu_dir, (size_t)sc->body_steps))
        return cf_cli_usage_error("simulate",
                                  "-o %s is one of the files --vtu %s writes (body.pvd, "
                                  "body_NNNN.vtu and springs_NNNN.vtu for steps 0 to %d); name "
                                  "another",
                                  out, vtu_dir, sc->body_steps);
    r.keep_forces = vtu_dir != NULL;
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
        (png && cf_cli_probe_plot(sc, r.step, r.steps + 1, png, inputs, &plot,
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
    if (!quiet) {
        summary(csv.to_stdout ? stderr : stdout, sc, &r);
        stability(csv.to_stdout ? stderr : stdout, sc, &r);
    }
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
    for (size_t g = 0; g < sc->nregions; g++) /* the export holds fixed nodes and moves a probe */
        if (sc->regions[g].use != CF_REGION_FIXED)
            return cf_error_set(err, CF_E_DATA, "%s: key '%s': the export of a body takes "
                                "fixed regions and a probe only", scene_path,
                                sc->regions[g].key);
    if (!sc->has_probe)
        return cf_error_set(err, CF_E_DATA, "%s: missing key 'probe': the export of a body "
                            "moves a probe", scene_path);
    if (sc->probe_npath)
        return cf_error_set(err, CF_E_DATA, "%s: key 'probe.path': the export of a body moves "
                            "the probe along its direction only", scene_path);
    if (sc->body_dynamic)
        return cf_error_set(err, CF_E_DATA, "%s: key 'effects.inertia': the export of a body "
                            "takes a static run", scene_path);
    cf_status st = solve(sc, scene_path, budget, &r, err);
    const size_t steps = r.steps;
    double *depth = NULL, *force = NULL;
    if (st == CF_OK) {
        depth = malloc(steps * sizeof *depth);
        force = malloc(steps * sizeof *force);
        if (!depth || !force)
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory for %zu steps", steps);
    }
    /* the CalculiX model takes the volume term about every step's state: about 1 kB per node and
    ** step (the liver probe's 507 nodes and 16 steps: 7 MB of its 23), held in memory whole */
    const double deck = 1e3 * (double)r.body.nn * (double)steps;
    if (st == CF_OK && opt->format == CF_EXPORT_CALCULIX && r.body.kappa_MPa > 0 &&
        deck > budget->max_memory_bytes)
        st = cf_error_set(err, CF_E_DATA, "%s: the CalculiX model of the body (%zu nodes, %zu "
                          "steps, its volume term taken at every step) needs about %.3g bytes, "
                          "over the limit %.3g (--max-memory); take fewer probe.steps",
                          scene_path, r.body.nn, steps, deck, budget->max_memory_bytes);
    if (st == CF_OK) {
        for (size_t k = 0; k < steps; k++) {
            depth[k] = r.step[k + 1].depth_mm;
            force[k] = r.step[k + 1].force_N;
        }
        const cf_export_body_run er = {steps, depth, force, r.xs + 3 * r.body.nn,
                                       r.contact_set + r.body.nn};
        st = cf_export_write_body(out, &r.body, &sc->probe, &er, opt, rep, err);
        if (st != CF_OK)
            snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg), " (%s)",
                     scene_path);
    }
    free(depth);
    free(force);
    run_free(&r);
    return st;
}
