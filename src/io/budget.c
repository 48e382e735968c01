/*
** Cost estimates of a scene before it runs (see budget.h).
*/
#include "io/budget.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/calibration.h"
#include "model/linsolve.h"
#include "model/msm_tangent.h"
#include "model/lattice.h"

/* Bytes per node and per spring of the lattice and the solver state (positions, reference
** positions, forces, masses, velocities; spring ends, lengths, weights, tensions, law state), and
** per sample (the sample, its time, the single-spring comparison). Rounded up from the arrays of
** lattice.c and the lattice solvers (msm*.c). */
#define NODE_BYTES 160.0
#define SPRING_BYTES 200.0
#define SAMPLE_BYTES 64.0
/* The static and implicit solvers, with the limits of their cascade (model/linsolve.h): the sparse
** tangent (3 CF_MSM_TANGENT_MAX_ADJ entries a row at most, counted at 64 bytes each), the banded
** factor when it fits in CF_LINSOLVE_BAND_MAX_ENTRIES entries, else a dense LU up to
** CF_LINSOLVE_DENSE_MAX_DOF unknowns, else a GMRES basis of CF_LINSOLVE_GMRES_RESTART vectors. */
#define TANGENT_ROW_BYTES (3.0 * CF_MSM_TANGENT_MAX_ADJ * 64.0)
/* A lattice with spring groups (lattice.h): each spring's place in the groups' order and its
** gathered compression, force and stiffness. */
#define GROUP_SPRING_BYTES 28.0
/* A law table: two values an end and four coefficients an interval (model/law.c). */
#define LAW_TABLE_BYTES 48.0

cf_budget cf_budget_default(void)
{
    cf_budget b = {CF_BUDGET_MAX_MEMORY_DEFAULT, CF_BUDGET_MAX_STEPS_DEFAULT,
                   CF_BUDGET_MAX_WORK_DEFAULT};
    return b;
}

double cf_budget_solve_work(double unknowns)
{
    return CF_BUDGET_SOLVE_WORK_3 * pow(fmax(unknowns, 1.0) / 192.0, 1.5);
}

/* The work of the scene against the limit: CF_E_DATA naming the key, the estimate and what of
** that key would fit. `fit` is the key's value that would fit, `fit_what` how to read it. */
static cf_status check_work(const char *name, const char *key, const cf_scene_cost *c,
                            const cf_lattice *lat, const cf_budget *b, double fit,
                            const char *fit_what, cf_error *err)
{
    if (c->work <= b->max_work)
        return CF_OK;
    char fits[160];
    if (fit > 0 && isfinite(fit))
        snprintf(fits, sizeof fits, "%s %.4g would fit", fit_what, fit);
    else
        snprintf(fits, sizeof fits, "not even one step or sample fits this lattice: reduce "
                                    "'lattice.nx/ny/nz'");
    return cf_error_set(err, CF_E_DATA,
                        "%s: key '%s': the scene needs about %.3g spring-steps of work (%.4g %s "
                        "of a %dx%dx%d lattice, %.3g each), above the limit of %.3g (about 2 to "
                        "6 minutes of one core; raise it with --max-work); %s",
                        name, key, c->work, c->steps, c->steps_kind, lat->cfg.nx, lat->cfg.ny, lat->cfg.nz,
                        c->work_per_step, b->max_work, fits);
}

static double mib(double bytes)
{
    return bytes / (1024.0 * 1024.0);
}

/* Nodes and springs of an nx x ny x nz lattice with the families the scene weights: those of its
** net (cf_net_lattice_size). */
static void lattice_size(const cf_lattice_config *L, double nx, double ny, double nz,
                         double *nodes, double *springs)
{
    cf_lattice_config c = *L;
    c.nx = (int)nx, c.ny = (int)ny, c.nz = (int)nz;
    cf_net_lattice_size(&c, nodes, springs);
}

/* Bytes of the lattice and its solvers for nx x ny x nz cells: the lattice, and for static and
** implicit runs the tangent with the larger of the sparse factor's fill and the fallback's
** workspace (band, dense LU or GMRES basis: used only when the sparse factorisation fails). */
static double lattice_bytes(const cf_scene *sc, double nx, double ny, double nz)
{
    double nodes, springs;
    lattice_size(&sc->cfg.lattice, nx, ny, nz, &nodes, &springs);
    const double dof = 3 * nodes;
    double solver = 0;
    if (!sc->effects.inertia) { /* static and implicit runs factor the tangent */
        const double band = 3 * (nx + 1) * (ny + 1) + 3;
        double fallback;
        if (dof * (band + 1) <= CF_LINSOLVE_BAND_MAX_ENTRIES)
            fallback = 8 * dof * (band + 1);
        else if (dof <= CF_LINSOLVE_DENSE_MAX_DOF)
            fallback = 8 * dof * dof;
        else
            fallback = 8 * dof * (CF_LINSOLVE_GMRES_RESTART + 4.0);
        solver = dof * TANGENT_ROW_BYTES + springs * 36 * 4 +
                 fmax(CF_BUDGET_FILL_BYTES * pow(dof, CF_BUDGET_FILL_EXPONENT), fallback);
    }
    const double grouped = sc->ngroups > 0 ? springs * GROUP_SPRING_BYTES : 0;
    return CF_BUDGET_PROCESS_BYTES + nodes * NODE_BYTES + springs * SPRING_BYTES + solver + grouped;
}

double cf_budget_law_tables_bytes(const cf_scene *sc)
{
    const double laws = 1.0 + (double)sc->ngroups + (double)sc->nfibres +
                        (double)sc->body_nfibres; /* the scene's, each group's, each fibre's */
    return sc->method == CF_LAW_TABLE ? LAW_TABLE_BYTES * ((double)sc->table_intervals + 1) * laws
                                      : 0;
}

/* The largest lattice of the scene's proportions whose bytes fit in `room` (its cell counts into
** n[3]); 0 when not even 1 x 1 x 1 fits. */
static int lattice_that_fits(const cf_scene *sc, double room, int n[3])
{
    const cf_lattice_config *L = &sc->cfg.lattice;
    double lo = 0, hi = 1;
    for (int it = 0; it < 60; it++) {
        const double f = 0.5 * (lo + hi);
        if (lattice_bytes(sc, fmax(1, floor(L->nx * f)), fmax(1, floor(L->ny * f)),
                          fmax(1, floor(L->nz * f))) <= room)
            lo = f;
        else
            hi = f;
    }
    n[0] = (int)fmax(1, floor(L->nx * lo));
    n[1] = (int)fmax(1, floor(L->ny * lo));
    n[2] = (int)fmax(1, floor(L->nz * lo));
    return lattice_bytes(sc, n[0], n[1], n[2]) <= room;
}

/* The memory refusal: the key of the largest part and a value of it that would fit. */
static cf_status memory_refusal(const cf_scene *sc, const char *name, const cf_budget *b,
                                const cf_scene_cost *c, double lattice, double samples,
                                double table, cf_error *err)
{
    const double limit = b->max_memory_bytes;
    const char *key;
    char fits[160];
    if (table >= lattice && table >= samples) {
        key = "table_intervals";
        const double n = floor((limit - lattice - samples) / LAW_TABLE_BYTES) - 1;
        if (n >= 2)
            snprintf(fits, sizeof fits, "at most %.0f intervals would fit", fmin(n, 1e7));
        else
            snprintf(fits, sizeof fits, "leave out 'law_method' (the exact law needs no table)");
    } else if (samples >= lattice) {
        key = "samples_per_segment";
        const double n = floor((limit - lattice - table) / SAMPLE_BYTES);
        if (n >= 2)
            snprintf(fits, sizeof fits, "at most %.0f samples in all would fit", n);
        else
            snprintf(fits, sizeof fits, "not even two samples fit beside the lattice");
    } else {
        key = "lattice.nx/ny/nz";
        int n[3];
        if (lattice_that_fits(sc, limit - samples - table, n))
            snprintf(fits, sizeof fits, "a lattice of at most %dx%dx%d cells would fit", n[0], n[1],
                     n[2]);
        else
            snprintf(fits, sizeof fits, "not even a 1x1x1 lattice fits");
    }
    return cf_error_set(err, CF_E_DATA,
                        "%s: key '%s': the scene needs about %.0f MiB (%zu nodes, %zu springs "
                        "and their solver, %zu samples%s), above the limit of %.0f MiB (raise it "
                        "with --max-memory); %s",
                        name, key, mib(c->memory_bytes), c->nodes, c->springs, sc->nsamples,
                        table > 0 ? ", the law table" : "", mib(limit), fits);
}

cf_status cf_budget_check_size(const cf_scene *sc, const char *name, const cf_budget *b,
                               cf_scene_cost *c, cf_error *err)
{
    memset(c, 0, sizeof *c);
    const cf_lattice_config *L = &sc->cfg.lattice;
    const double nx = L->nx, ny = L->ny, nz = L->nz;
    double nodes, springs;
    lattice_size(L, nx, ny, nz, &nodes, &springs);
    c->nodes = (size_t)nodes;
    c->springs = (size_t)springs;
    c->samples = sc->nsamples;
    const double lattice = lattice_bytes(sc, nx, ny, nz);
    const double samples = (double)sc->nsamples * SAMPLE_BYTES;
    const double table = cf_budget_law_tables_bytes(sc);
    c->memory_bytes = lattice + samples + table;
    if (c->memory_bytes > b->max_memory_bytes)
        return memory_refusal(sc, name, b, c, lattice, samples, table, err);
    return CF_OK;
}

cf_status cf_budget_check_steps(const cf_scene *sc, const char *name, cf_lattice *lat,
                                const cf_budget *b, cf_scene_cost *c, cf_error *err)
{
    const cf_msm_effects *fx = &sc->effects;
    const cf_msm_config *cfg = &sc->cfg;
    const double duration = sc->npath ? sc->path_t_s[sc->npath - 1] - sc->path_t_s[0] : 0;
    const char *key;
    /* what one step costs on this lattice: a pass over the springs, or a solve */
    const double solve = cf_budget_solve_work(3.0 * (double)lat->nn);
    double fit = 0;
    const char *fit_what = "";
    if (fx->inertia) {
        double stable = CF_MSM_DT_SAFETY * cf_msm_stable_step(lat, fx);
        double dt = cfg->dt_s > 0 && cfg->dt_s < stable ? cfg->dt_s : stable;
        c->steps = dt > 0 && isfinite(dt) ? duration / dt : INFINITY;
        c->steps_kind = "explicit steps";
        key = cfg->dt_s > 0 && cfg->dt_s < stable ? "integrator.dt_s"
              : sc->kind == CF_PROTO_RAMP         ? "protocol.duration_s"
              : sc->kind == CF_PROTO_CYCLES       ? "protocol.period_s"
                                                  : "protocol.hold_s";
        c->work_per_step = (double)lat->ns;
        const double share = b->max_work / (c->steps * c->work_per_step);
        if (cfg->dt_s > 0 && cfg->dt_s < stable) {
            fit = cfg->dt_s / share;
            fit_what = "a step dt_s [s] of at least";
        } else {
            fit = duration * share;
            fit_what = "a protocol lasting [s] at most";
        }
    } else if (fx->eta_MPa_s > 0 || fx->maxwell_E_MPa > 0 || fx->prony_count > 0) {
        c->steps_kind = "implicit steps";
        c->work_per_step = solve;
        const double can = b->max_work / solve; /* steps that fit */
        if (cfg->dt_s > 0) {
            c->steps = duration / cfg->dt_s + (double)sc->nsamples;
            key = "integrator.dt_s";
            fit = can > (double)sc->nsamples ? duration / (can - (double)sc->nsamples) : 0;
            fit_what = "a step dt_s [s] of at least";
        } else {
            c->steps = (double)sc->nsamples * (cfg->quasi_substeps > 0 ? cfg->quasi_substeps : 1);
            key = cfg->quasi_substeps > 1 ? "integrator.substeps" : "samples_per_segment";
            fit = cfg->quasi_substeps > 1 ? floor(can / (double)sc->nsamples) : floor(can);
            fit_what = cfg->quasi_substeps > 1 ? "substeps per sample interval: at most"
                                               : "samples in all: at most";
        }
    } else {
        c->steps = (double)sc->nsamples;
        c->steps_kind = "static solves";
        key = "samples_per_segment";
        c->work_per_step = solve;
        fit = floor(b->max_work / solve);
        fit_what = "samples in all: at most";
    }
    c->work = c->steps * c->work_per_step;
    if (!(c->steps <= b->max_steps))
        return cf_error_set(err, CF_E_DATA,
                            "%s: key '%s': the scene needs about %.4g %s, above the limit of %.4g "
                            "(raise it with --max-steps)",
                            name, key, c->steps, c->steps_kind, b->max_steps);
    return check_work(name, key, c, lat, b, fit, fit_what, err);
}

double cf_budget_body_node_bytes(const cf_scene *sc, int keep_forces)
{
    const double factor = 3 * (81.0 * 16 * 8 + 40.0 * 81 * 8); /* tangent and its fill */
    const double groups = sc->ngroups ? 8.0 : 0;                /* a byte a spring, ~7 a node */
    const double fibres = sc->body_nfibres ? 6 * 192.0 : 0;     /* 192 a tetrahedron, ~6 a node */
    return factor + groups + fibres + (sc->body_steps + 1.0) * 3 * 8 * (keep_forces ? 3 : 1) +
           (double)sc->nregions;
}
