/*
** What a scene will cost, estimated before anything runs: nodes, springs, samples, memory and
** time steps (or static solves). A scene above the limits is refused with a message naming the
** scene key that drives the estimate and the estimate itself, so that every accepted scene either
** finishes or is refused before it starts. The limits are the defaults below or the caller's
** (`conifit simulate --max-memory`, `--max-steps`).
**
** The estimates are of the present solvers: memory is the program, the lattice, the samples, the
** law table (`table_intervals`) and the workspace of the linear solvers a static or implicit run
** uses (the sparse tangent and the larger of its factorisation's fill, measured below, and the
** fallback's banded factor, dense LU or GMRES basis); steps are static solves (one per sample), implicit steps, or explicit
** steps at the stable step of the unloaded lattice (stiffening springs can only add sub-steps).
** Work is what those steps cost on the scene's lattice, in spring-steps (one spring through one
** explicit step, 13 to 35 ns on one core of the machine the model was measured on): an explicit
** step costs one per spring, a static solve or an implicit step (Newton, a sparse factorisation
** of the tangent) CF_BUDGET_SOLVE_WORK_3 for the 3 x 3 x 3 lattice (192 unknowns), growing as the
** unknowns to the power 1.5 (measured 1.0 ms, 15 ms and 113 ms per solve at 3^3, 6^3, 10^3).
*/
#ifndef CF_BUDGET_H
#define CF_BUDGET_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/lattice.h"
#include "io/scene.h"

#define CF_BUDGET_MAX_MEMORY_DEFAULT (2.0 * 1024 * 1024 * 1024) /* bytes: 2 GiB */
#define CF_BUDGET_MAX_STEPS_DEFAULT 1e7                         /* steps or solves */
#define CF_BUDGET_MAX_WORK_DEFAULT 1e10 /* spring-steps: about 2 to 6 minutes on one core */
#define CF_BUDGET_SOLVE_WORK_3 3e4      /* spring-steps per solve of the 3^3 lattice (1 ms) */
/* The program itself, its libraries and the inputs it holds (10 MiB peak for a 4^3 scene, with
** room for other C libraries and thread stacks). */
#define CF_BUDGET_PROCESS_BYTES (16.0 * 1024 * 1024)
/* The sparse factorisation's fill, as bytes = CF_BUDGET_FILL_BYTES * unknowns^CF_BUDGET_FILL_EXPONENT
** beside the tangent. Measured on static cubic lattices (two samples, peak resident memory):
** CHOLMOD's factor holds lnz = 1.9e4, 3.6e5, 1.8e6, 5.6e6 entries at 322, 2022, 6250, 14158
** free unknowns (4^3 to 16^3, about 7.8 n^1.41), and at 13.5 bytes an entry of its workspace; the
** peak beyond the lattice and the tangent is 97 to 91 unknowns^1.45 bytes from 16^3 to 43^3
** (196 MiB, 432 MiB, 836 MiB at 16^3, 20^3, 24^3, and 8.0 GB reported for 43^3). 110 keeps the
** estimate 11 to 18 % above each. */
#define CF_BUDGET_FILL_BYTES 110.0
#define CF_BUDGET_FILL_EXPONENT 1.45

typedef struct cf_budget {
    double max_memory_bytes;
    double max_steps;
    double max_work; /* spring-steps (see above) */
} cf_budget;

/* The default limits. */
cf_budget cf_budget_default(void);

typedef struct cf_scene_cost {
    size_t nodes, springs, samples;
    double memory_bytes;       /* estimate, bytes */
    double steps;              /* estimate: explicit or implicit time steps, or static solves */
    const char *steps_kind;    /* "explicit steps", "implicit steps" or "static solves" */
    double work_per_step;      /* spring-steps per step or solve on this lattice */
    double work;               /* steps * work_per_step */
} cf_scene_cost;

/* `name` (the scene's file) starts each message. Nodes, springs, samples and memory of the scene, checked against the memory limit before the
** lattice is built. CF_E_DATA naming the key (lattice.nx/ny/nz or samples_per_segment) and the
** estimate when it is above. */
cf_status cf_budget_check_size(const cf_scene *sc, const char *name, const cf_budget *b,
                               cf_scene_cost *c, cf_error *err);

/* The steps of the scene on its built lattice (for the explicit stable step) and their work,
** checked against the step and the work limits. CF_E_DATA naming the key (protocol duration,
** integrator.dt_s, integrator.substeps or samples_per_segment), the estimate and, for the work,
** the value of that key that would fit, when it is above. */
cf_status cf_budget_check_steps(const cf_scene *sc, const char *name, cf_lattice *lat,
                                const cf_budget *b, cf_scene_cost *c, cf_error *err);

/* Spring-steps of one static solve or implicit step of a lattice with this many unknowns. */
double cf_budget_solve_work(double unknowns);

/* The bytes of the scene's law tables when it evaluates its laws by table (`law_method` "table":
** values and slopes at the ends, four cubic coefficients per interval of `table_intervals`): the
** scene spring's, each spring group's and each fibre group's (lattice or body); 0 otherwise. */
double cf_budget_law_tables_bytes(const cf_scene *sc);

/* What a tissue body's static or dynamic run spends per node: the tangent and its factor's fill
** (about 40 times its 3 x 3 blocks for meshes of organ size), one copy of the positions per step
** (three with the forces kept), a byte a node per region, a spring group's index a spring and a
** fibre group's directions and shape gradients per tetrahedron; the law tables come once on top
** (cf_budget_law_tables_bytes). */
double cf_budget_body_node_bytes(const cf_scene *sc, int keep_forces);

#endif
