/*
** Benchmark section 2: one explicit step of the mass-spring lattice per spring: conifit's stencil
** step (lattice_step.h) with each evaluator, the edge-list kernel of the statics, and two minimal
** independent linear-spring steps written here (a stencil of the same structure, an edge list), over lattices of about 1e3 to 1e6
** springs; springs per 1 ms at 1e4, 1e5 and 1e6; the machine's triad bandwidth and each kernel's
** distance to the time its memory traffic needs; two threads at 1e6 springs.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "model/lattice.h"
#include "model/lattice_step.h"

/* The spring behind data/telescoping.csv: solid strain 0.6, region 2 from strain 0.24. */
static const cf_spring bench_spring = {8, 20, 2.5, 2, 100, 5};
#define STATE_STRAIN 0.35

typedef struct lvariant {
    const char *name;
    int kind; /* 0 minimal linear edge-list kernel, 1 conifit's step, 2 edge-list kernel
              ** cf_lattice_forces, 3 minimal linear stencil kernel */
    cf_law_method method;
    int lanes; /* conifit's step: the lanes' form it is held to (-2: the one it chooses) */
} lvariant;

static const lvariant lvars[] = {
    {"linear, minimal stencil kernel", 3, CF_LAW_CLOSED, -2},
    {"linear, minimal edge-list kernel", 0, CF_LAW_CLOSED, -2},
    {"exact", 1, CF_LAW_EXACT, -2},
    {"closed", 1, CF_LAW_CLOSED, -2},
    {"closed+newton", 1, CF_LAW_CLOSED_NEWTON, -2},
    {"table 256", 1, CF_LAW_TABLE, -2},
    {"closed, edge-list kernel", 2, CF_LAW_CLOSED, -2},
    {"closed form lanes (no polynomial)", 1, CF_LAW_CLOSED, CF_LANE_CLOSED},
    {"table lanes (no polynomial)", 1, CF_LAW_TABLE, CF_LANE_TABLE},
};
#define NLV (sizeof lvars / sizeof lvars[0])
#define V_LIN 0
#define V_LIN_EDGES 1
#define V_CLOSED 3
#define V_TABLE 5
#define V_EDGES 6

/* A minimal linear-spring step over the edge list, written here independently of conifit's
** kernels: one pass over the springs (gather, length, F = k (L0 - L) a, scatter), one over the
** nodes (symplectic Euler, forces cleared). Same arrays, same order, no law. */
static void linear_step(cf_lattice *lat, const double *const im[3], double *const v[3], double k,
                        double h)
{
    const uint32_t *restrict si = lat->si, *restrict sj = lat->sj;
    double *const xs[3] = {lat->x, lat->y, lat->z};
    double *const fs[3] = {lat->fx, lat->fy, lat->fz};
    for (size_t s = 0; s < lat->ns; s++) {
        const uint32_t i = si[s], j = sj[s];
        const double dx = xs[0][j] - xs[0][i], dy = xs[1][j] - xs[1][i], dz = xs[2][j] - xs[2][i];
        const double L = sqrt(dx * dx + dy * dy + dz * dz);
        const double g = -lat->w[s] * k * (lat->L0_mm[s] - L) * lat->a[s] / L;
        fs[0][i] += g * dx, fs[1][i] += g * dy, fs[2][i] += g * dz;
        fs[0][j] -= g * dx, fs[1][j] -= g * dy, fs[2][j] -= g * dz;
    }
    for (int a = 0; a < 3; a++)
        for (size_t p = 0; p < lat->nn; p++) {
            v[a][p] += h * fs[a][p] * im[a][p];
            xs[a][p] += h * v[a][p];
            fs[a][p] = 0;
        }
}

/* The edge-list kernel the statics and the viscous dynamics use: cf_lattice_forces (three passes
** with per-spring outputs), then a separate node update. */
static void edges_step(cf_lattice *lat, const double *const im[3], double *const v[3], double h)
{
    lat->with_stiffness = 0;
    cf_lattice_forces(lat);
    double *const xs[3] = {lat->x, lat->y, lat->z};
    double *const fs[3] = {lat->fx, lat->fy, lat->fz};
    for (int a = 0; a < 3; a++)
        for (size_t p = 0; p < lat->nn; p++) {
            v[a][p] += h * fs[a][p] * im[a][p];
            xs[a][p] += h * v[a][p];
        }
}

/* A minimal linear-spring step of the stencil's structure, written here independently of
** conifit's step: per layer and per direction (di, dj, dk) of the cell, one run over the layer's
** nodes p with the partner p + D, the spring's weight from a table of the layer built below (0 where
** the partner wraps to another row), the tensions into a buffer while they are added at p, then
** subtracted at p + D; then the node update of linear_step. Same law as linear_step. */
typedef struct stencil_lin {
    int nd;
    long D[13];
    int dk[13];
    double L0[13], a[13], wedge[13]; /* wedge: factor on the bottom and top layers */
    double *w[13];                   /* per direction: weight over a layer's nodes */
    double *t[3];                    /* tension buffer, one layer */
} stencil_lin;

static int stencil_lin_init(stencil_lin *sl, const cf_lattice *lat)
{
    static const int off[13][3] = {{1, 0, 0},   {-1, 1, 0}, {0, 1, 0},  {1, 1, 0}, {-1, -1, 1},
                                   {0, -1, 1},  {1, -1, 1}, {-1, 0, 1}, {0, 0, 1}, {1, 0, 1},
                                   {-1, 1, 1},  {0, 1, 1},  {1, 1, 1}};
    const int nx = lat->cfg.nx, ny = lat->cfg.ny;
    const size_t layer = (size_t)(nx + 1) * (size_t)(ny + 1);
    memset(sl, 0, sizeof *sl);
    for (int a = 0; a < 3; a++)
        if (!(sl->t[a] = malloc(layer * sizeof(double))))
            return -1;
    for (int d = 0; d < 13; d++) {
        const int nzc = (off[d][0] != 0) + (off[d][1] != 0) + (off[d][2] != 0);
        const double fw = lat->cfg.weight[nzc - 1];
        if (fw == 0)
            continue;
        const int e = sl->nd++;
        sl->D[e] = off[d][0] + (long)(nx + 1) * (off[d][1] + (long)(ny + 1) * off[d][2]);
        sl->dk[e] = off[d][2];
        sl->L0[e] = lat->H_mm * sqrt((double)nzc);
        sl->a[e] = 1.0 / sqrt((double)nzc);
        sl->wedge[e] = off[d][2] ? 1.0 : 0.5;
        if (!(sl->w[e] = malloc(layer * sizeof(double))))
            return -1;
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++) {
                const int i2 = i + off[d][0], j2 = j + off[d][1];
                double w = (i2 < 0 || i2 > nx || j2 < 0 || j2 > ny) ? 0.0 : fw;
                if (off[d][0] == 0 && (i == 0 || i == nx))
                    w *= 0.5;
                if (off[d][1] == 0 && (j == 0 || j == ny))
                    w *= 0.5;
                sl->w[e][(size_t)i + (size_t)(nx + 1) * (size_t)j] = w;
            }
    }
    return 0;
}

static void stencil_lin_free(stencil_lin *sl)
{
    for (int a = 0; a < 3; a++)
        free(sl->t[a]);
    for (int d = 0; d < 13; d++)
        free(sl->w[d]);
}

/* Compiled like conifit's step (lattice_step.c), so that the ratios compare like with like: for
** each instruction set of its dispatch, loops vectorised, multiply-adds contracted. */
#ifndef CF_DISPATCH
#if CF_SIMD_MULTI
#define CF_DISPATCH __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define CF_DISPATCH
#endif
#endif
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("fp-contract=fast")
#endif
CF_DISPATCH
static void stencil_linear_step(cf_lattice *lat, const stencil_lin *sl, const double *const im[3],
                                double *const v[3], double k, double h)
{
    const int nz = lat->cfg.nz;
    const size_t layer = (size_t)(lat->cfg.nx + 1) * (size_t)(lat->cfg.ny + 1);
    double *restrict tx = sl->t[0], *restrict ty = sl->t[1], *restrict tz = sl->t[2];
    for (int kz = 0; kz <= nz; kz++)
        for (int e = 0; e < sl->nd; e++) {
            if (sl->dk[e] && kz == nz)
                continue;
            const size_t D = (size_t)sl->D[e];
            /* the layer's nodes whose partner lies within the next layers' arrays (wrapped pairs
            ** have weight 0) */
            const size_t p0 = (size_t)kz * layer, end = (sl->dk[e] ? 2 : 1) * layer - D,
                         n = end < layer ? end : layer;
            const double c = -k * sl->a[e] * (kz == 0 || kz == nz ? sl->wedge[e] : 1.0),
                         L0 = sl->L0[e];
            const double *restrict w = sl->w[e];
            {
                const double *restrict x = lat->x + p0, *restrict y = lat->y + p0,
                                       *restrict z = lat->z + p0;
                double *restrict fx = lat->fx + p0, *restrict fy = lat->fy + p0,
                                 *restrict fz = lat->fz + p0;
#pragma omp simd
                for (size_t i = 0; i < n; i++) {
                    const double dx = x[i + D] - x[i], dy = y[i + D] - y[i], dz = z[i + D] - z[i];
                    const double L = sqrt(dx * dx + dy * dy + dz * dz);
                    const double g = w[i] != 0.0 ? c * w[i] * (L0 - L) / L : 0.0;
                    tx[i] = g * dx, ty[i] = g * dy, tz[i] = g * dz;
                    fx[i] += tx[i], fy[i] += ty[i], fz[i] += tz[i];
                }
            }
            {
                double *restrict fx = lat->fx + p0 + D, *restrict fy = lat->fy + p0 + D,
                                 *restrict fz = lat->fz + p0 + D;
#pragma omp simd
                for (size_t i = 0; i < n; i++)
                    fx[i] -= tx[i], fy[i] -= ty[i], fz[i] -= tz[i];
            }
        }
    double *const xs[3] = {lat->x, lat->y, lat->z};
    double *const fs[3] = {lat->fx, lat->fy, lat->fz};
    for (int a = 0; a < 3; a++) {
        double *restrict x = xs[a], *restrict f = fs[a], *restrict va = v[a];
        const double *restrict m = im[a];
#pragma omp simd
        for (size_t p = 0; p < lat->nn; p++) {
            va[p] += h * f[p] * m[p];
            x[p] += h * va[p];
            f[p] = 0;
        }
    }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif

typedef struct runner {
    cf_lattice *lat;
    cf_lattice_stepper *st;
    const stencil_lin *sl;
    double *v[3];
    double k;
} runner;

static void one_step(runner *r, int kind, double h)
{
    const double *const im[3] = {r->st->inv_mass[0], r->st->inv_mass[1], r->st->inv_mass[2]};
    if (kind == 0)
        linear_step(r->lat, im, r->v, r->k, h);
    else if (kind == 1) {
        cf_lattice_stepper_forces(r->st);
        cf_lattice_stepper_advance(r->st, h, r->v[0], r->v[1], r->v[2]);
    } else if (kind == 2)
        edges_step(r->lat, im, r->v, h);
    else
        stencil_linear_step(r->lat, r->sl, im, r->v, r->k, h);
}

/* Every coordinate scaled by (1 - STATE_STRAIN) about the origin, with a small seeded jitter, so
** that every spring sits in region 2 at a slightly different compression. */
static void deform(cf_lattice *lat)
{
    unsigned long s = 99;
    for (size_t p = 0; p < lat->nn; p++) {
        double *c[3] = {&lat->x[p], &lat->y[p], &lat->z[p]};
        const double R[3] = {lat->X[p], lat->Y[p], lat->Z[p]};
        for (int a = 0; a < 3; a++) {
            s = s * 6364136223846793005UL + 1442695040888963407UL;
            double r = (double)(s >> 11) / 9007199254740992.0 - 0.5;
            *c[a] = R[a] * (1 - STATE_STRAIN) + 0.01 * lat->H_mm * r;
        }
    }
}

/* CPU time of the calling thread, s: on a shared machine the wall time of a single-threaded
** kernel also counts the time it waited for a core, which other work decides. */
static double thread_now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0)
        return bench_now();
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The deformed state of deform() at rest, node forces cleared. */
static void start_state(runner *r)
{
    cf_lattice *lat = r->lat;
    deform(lat);
    for (int a = 0; a < 3; a++)
        memset(r->v[a], 0, lat->nn * sizeof(double));
    memset(lat->fx, 0, lat->nn * sizeof(double));
    memset(lat->fy, 0, lat->nn * sizeof(double));
    memset(lat->fz, 0, lat->nn * sizeof(double));
}

/* Median ns per spring per step of one variant on one lattice (each sample lasts sample_s of
** thread CPU time; wall time when threads run, whose CPU time would add up). */
static bench_stats time_variant(runner *r, int kind, int repeats, double sample_s)
{
    double (*now)(void) = r->st && r->st->threads ? bench_now : thread_now;
    cf_lattice *lat = r->lat;
    start_state(r);
    const double h = 1e-12; /* the state stays where deform() put it */
    double t0 = now();
    one_step(r, kind, h);
    double one = now() - t0;
    long nstep = (long)(sample_s / fmax(one, 1e-9)) + 1;
    double t[16];
    for (int q = 0; q < repeats; q++) {
        t0 = now();
        for (long i = 0; i < nstep; i++)
            one_step(r, kind, h);
        t[q] = (now() - t0) / (double)nstep / (double)lat->ns * 1e9;
    }
    bench_sink += lat->x[lat->nn / 2];
    return bench_summarise(t, repeats);
}

/* Largest relative difference between the node velocities after one step of the two minimal
** linear kernels from the same state (v = h f / m from rest): they must compute the same forces. */
static double linear_kernels_differ(runner *r)
{
    cf_lattice *lat = r->lat;
    const double *const im[3] = {r->st->inv_mass[0], r->st->inv_mass[1], r->st->inv_mass[2]};
    double *v0[3], dmax = 0, vmax = 0;
    for (int a = 0; a < 3; a++)
        if (!(v0[a] = malloc(lat->nn * sizeof(double)))) {
            for (int b = 0; b < a; b++)
                free(v0[b]);
            return NAN;
        }
    for (int kind = 0; kind < 2; kind++) {
        start_state(r);
        if (kind == 0)
            linear_step(lat, im, r->v, r->k, 1e-3);
        else
            stencil_linear_step(lat, r->sl, im, r->v, r->k, 1e-3);
        for (int a = 0; a < 3; a++)
            for (size_t p = 0; p < lat->nn; p++) {
                if (kind == 0)
                    v0[a][p] = r->v[a][p];
                else
                    dmax = fmax(dmax, fabs(r->v[a][p] - v0[a][p]));
                vmax = fmax(vmax, fabs(r->v[a][p]));
            }
    }
    for (int a = 0; a < 3; a++)
        free(v0[a]);
    return vmax > 0 ? dmax / vmax : NAN;
}

/* STREAM-like triad a = b + s c over three arrays far larger than the caches: bytes per second
** counting 24 bytes per element (two reads, one write; the write-allocate read not counted). */
static double triad_bandwidth(int repeats, bench_stats *out)
{
    const size_t n = (size_t)1 << 22; /* 32 MiB per array */
    double *a = malloc(n * sizeof(double)), *b = malloc(n * sizeof(double)),
           *c = malloc(n * sizeof(double));
    if (!a || !b || !c) {
        free(a), free(b), free(c);
        return 0;
    }
    for (size_t i = 0; i < n; i++)
        a[i] = 0, b[i] = (double)i, c[i] = 1.0 / (double)(i + 1);
    double t[16];
    for (int q = 0; q < repeats; q++) {
        double t0 = bench_now();
        const double sc = 1.0 + 1e-3 * q;
        for (size_t i = 0; i < n; i++)
            a[i] = b[i] + sc * c[i];
        t[q] = 24.0 * (double)n / (bench_now() - t0) * 1e-9; /* GB/s */
    }
    bench_sink += a[n / 3];
    free(a), free(b), free(c);
    *out = bench_summarise(t, repeats);
    return out->median;
}

void bench_section_lattice(bench_ctx *ctx)
{
    static const int full[] = {4, 6, 9, 13, 19, 28, 43};
    static const int quick[] = {4, 9, 19};
    const int *sizes = ctx->quick ? quick : full;
    const int nsz = ctx->quick ? 3 : 7;
    const int repeats = ctx->quick ? 3 : 7;
    const double sample_s = ctx->quick ? 0.005 : 0.02;
    cf_law law;
    cf_law_init(&law, &bench_spring, NULL);
    cf_law_table_build(&law, 256, NULL);
    double per[7][NLV]; /* ns per spring per step (median) */
    bench_stats st[7][NLV];
    size_t nsprings[7] = {0}, nnodes[7] = {0};
    bench_stats thr1 = {0}, thr2 = {0};
    int have_thr = 0;
    double lin_differ = 0; /* the two linear kernels' forces, largest relative difference */
    double poly_error = NAN; /* the polynomial's error measured by the closed form's stepper */
    int poly_degree = 0;
    for (int z = 0; z < nsz; z++) {
        cf_lattice lat;
        cf_lattice_config cfg = cf_lattice_default();
        cfg.nx = cfg.ny = cfg.nz = sizes[z];
        if (cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, NULL) != CF_OK)
            continue;
        nsprings[z] = lat.ns;
        nnodes[z] = lat.nn;
        ctx->largest_springs = lat.ns;
        ctx->largest_cells = sizes[z];
        stencil_lin sl;
        if (stencil_lin_init(&sl, &lat) != 0) {
            stencil_lin_free(&sl);
            cf_lattice_free(&lat);
            continue;
        }
        runner r = {&lat, NULL, &sl,
                    {calloc(lat.nn, sizeof(double)), calloc(lat.nn, sizeof(double)),
                     calloc(lat.nn, sizeof(double))},
                    law.k0_N_per_mm};
        /* samples taken round-robin over the variants, so that a change of the machine's load
        ** during the run falls on every variant alike (the ratios below come from one run) */
        cf_lattice_stepper stp[NLV];
        int have[NLV];
        double samp[NLV][16];
        for (size_t e = 0; e < NLV; e++) {
            lat.method = lvars[e].method;
            have[e] = cf_lattice_stepper_init(&stp[e], &lat, NULL, NULL) == CF_OK;
            stp[e].threads = 0; /* one core */
            if (have[e] && lvars[e].lanes != -2)
                stp[e].form = lvars[e].lanes;
        }
        if (have[V_CLOSED]) {
            poly_error = stp[V_CLOSED].poly_error;
            poly_degree = stp[V_CLOSED].lanes.poly_degree;
            r.st = &stp[V_CLOSED];
            lin_differ = fmax(lin_differ, linear_kernels_differ(&r));
        }
        for (int q = 0; q < repeats; q++)
            for (size_t e = 0; e < NLV; e++)
                if (have[e]) {
                    lat.method = lvars[e].method;
                    r.st = &stp[e];
                    samp[e][q] = time_variant(&r, lvars[e].kind, 1, sample_s).median;
                }
        for (size_t e = 0; e < NLV; e++) {
            if (!have[e])
                continue;
            st[z][e] = bench_summarise(samp[e], repeats);
            per[z][e] = st[z][e].median;
            if (e == V_CLOSED && lat.ns >= CF_STEP_THREADS_MIN) {
                lat.method = lvars[e].method;
                r.st = &stp[e];
                thr1 = st[z][e];
                stp[e].threads = 1;
                thr2 = time_variant(&r, 1, repeats, sample_s);
                have_thr = 1;
            }
        }
        for (size_t e = 0; e < NLV; e++)
            if (have[e])
                cf_lattice_stepper_free(&stp[e]);
        for (int a = 0; a < 3; a++)
            free(r.v[a]);
        stencil_lin_free(&sl);
        cf_lattice_free(&lat);
    }
    cf_law_free(&law);

    fprintf(ctx->md,
            "## 2. Lattice step: time per spring\n\n"
            "One explicit step: every spring's force into the node forces, then the symplectic "
            "Euler update of every free node (which also clears the forces). conifit's step is "
            "the stencil over the regular lattice (`model/lattice_step.c`: per layer, chunks of "
            "%d nodes, per cell direction contiguous loads of the positions at p and at p + D, "
            "lengths, the law, tensions added at p and subtracted at p + D in two vectorised "
            "loops; weights from a table of the layer, no node indices and no per-spring "
            "constants; closed form and table through the branch-free lanes of "
            "`model/law_simd.h`, vectorised in every clone, the step with fused multiply-adds "
            "where the processor has them; exact and closed+newton through the scalar law per "
            "chunk). For this spring (ρ = 0.4) \"closed\" and \"table 256\" both run the "
            "spring's polynomial (`model/law_poly.c`: degree %d in √(1−|u|/s) and one "
            "division-free Newton step, measured within %.1e of the closed form when the step "
            "starts); \"closed form lanes\" and \"table lanes\" hold the step to the lanes it "
            "runs for springs the polynomial does not fit, ρ below about 0.03 (the closed form with "
            "its cube root and division; the Hermite table's lookups). \"closed, edge-list "
            "kernel\" is `cf_lattice_forces` (three passes over "
            "the springs' node indices and constants, with per-spring outputs), which the statics "
            "and the viscous dynamics use. Two minimal linear-spring steps (F = k u) are written in "
            "the benchmark, independent of conifit's code: a stencil kernel of the same structure "
            "as conifit's step (the like-for-like reference of the ratios) and an edge-list kernel "
            "(one pass over the springs with gathers and scatters, one over the nodes); their "
            "forces agree to %.1e (largest relative difference of the node velocities after one "
            "step, over every size). Cubic lattices of n³ cells with face and body diagonals, the "
            "spring of `data/telescoping.csv`, every node moved to a compression of %.2f (± 0.5 %% "
            "of H jitter) so that every spring is in region 2. One core; ns per spring per step, "
            "median of %d samples [min–max], taken round-robin over the variants, in CPU time of "
            "the thread (on this shared machine the wall time of a single-threaded kernel also "
            "counts its waits for a core); each sample runs enough steps to last %.0f ms.\n\n",
            CF_STEP_BLOCK, poly_degree, poly_error, lin_differ, STATE_STRAIN, repeats,
            sample_s * 1e3);
    fprintf(ctx->md, "| n | springs |");
    for (size_t e = 0; e < NLV; e++)
        fprintf(ctx->md, " %s |", lvars[e].name);
    fprintf(ctx->md, " closed / linear stencil | table / linear stencil | closed / linear edge list "
                     "| table / linear edge list |\n|---|---|");
    for (size_t e = 0; e < NLV + 4; e++)
        fprintf(ctx->md, "---|");
    fprintf(ctx->md, "\n");
    FILE *dat = bench_open_data(ctx, "lattice_step.dat");
    for (int z = 0; z < nsz; z++) {
        if (!nsprings[z])
            continue;
        fprintf(ctx->md, "| %d | %zu |", sizes[z], nsprings[z]);
        for (size_t e = 0; e < NLV; e++)
            fprintf(ctx->md, " %.2f [%.2f–%.2f] |", st[z][e].median, st[z][e].min, st[z][e].max);
        fprintf(ctx->md, " %.2f | %.2f | %.2f | %.2f |\n", per[z][V_CLOSED] / per[z][V_LIN],
                per[z][V_TABLE] / per[z][V_LIN], per[z][V_CLOSED] / per[z][V_LIN_EDGES],
                per[z][V_TABLE] / per[z][V_LIN_EDGES]);
        if (dat) {
            fprintf(dat, "%zu", nsprings[z]);
            for (size_t e = 0; e < NLV; e++)
                fprintf(dat, " %.6g", per[z][e]);
            fprintf(dat, "\n");
        }
    }
    if (dat)
        fclose(dat);

    /* springs per 1 ms step at the sizes nearest 1e4, 1e5 and 1e6 springs */
    const double want[3] = {1e4, 1e5, 1e6};
    int at[3] = {0, 0, 0};
    for (int q = 0; q < 3; q++)
        for (int z = 0; z < nsz; z++)
            if (nsprings[z] && fabs(log((double)nsprings[z] / want[q])) <
                                   fabs(log((double)nsprings[at[q]] / want[q])))
                at[q] = z;
    fprintf(ctx->md, "\n**Springs per 1 ms step** (one core: 1 ms divided by the time per spring "
                     "measured at that size):\n\n| lattice | springs |");
    for (size_t e = 0; e < NLV; e++)
        fprintf(ctx->md, " %s |", lvars[e].name);
    fprintf(ctx->md, "\n|---|---|");
    for (size_t e = 0; e < NLV; e++)
        fprintf(ctx->md, "---|");
    fprintf(ctx->md, "\n");
    for (int q = 0; q < 3; q++) {
        if (q > 0 && at[q] == at[q - 1])
            continue;
        int z = at[q];
        fprintf(ctx->md, "| %d³ (~%.0e) | %zu |", sizes[z], want[q], nsprings[z]);
        for (size_t e = 0; e < NLV; e++)
            fprintf(ctx->md, " %.3g |", 1e6 / per[z][e]);
        fprintf(ctx->md, "\n");
    }

    /* growth */
    fprintf(ctx->md, "\n**Growth.** Least-squares slope of log(time per step) against "
                     "log(springs) (1 = linear growth).\n\n| variant | slope | per-spring time, "
                     "smallest → largest, ns |\n|---|---|---|\n");
    int last = nsz - 1;
    while (last > 0 && !nsprings[last])
        last--;
    for (size_t e = 0; e < NLV; e++) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        int m = 0;
        for (int z = 0; z < nsz; z++) {
            if (!nsprings[z])
                continue;
            double lx = log((double)nsprings[z]), ly = log(per[z][e] * (double)nsprings[z]);
            sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
            m++;
        }
        double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
        fprintf(ctx->md, "| %s | %.3f | %.2f → %.2f |\n", lvars[e].name, slope, per[0][e],
                per[last][e]);
        if (e == V_CLOSED)
            ctx->slope_closed = slope;
    }

    /* bandwidth floor at the largest size */
    bench_stats bw;
    const double gbs = triad_bandwidth(repeats, &bw);
    const double nodes_per_spring = (double)nnodes[last] / (double)nsprings[last];
    /* bytes that must cross the memory bus per spring and step when nothing stays in cache:
    ** per node and axis the position, velocity and force read and written (3 x 16) and the inverse
    ** mass (8): 152 per node for the minimal kernels (one mass), 168 for conifit's. Stencils: no
    ** spring array (the weight table of a layer stays in cache). Minimal edge list: si, sj (8),
    ** L0, a, w (24) per spring. Edge-list kernel: si, sj, L0, a read and L, u written (40), u read
    ** and F written (16), w, F, L, si, sj read and T written (40); per node the forces cleared
    ** (24), gathered into (48) and read (24), positions and velocities read and written (96), the
    ** mass (8). */
    const double bytes[NLV] = {152 * nodes_per_spring,      32 + 152 * nodes_per_spring,
                               168 * nodes_per_spring,      168 * nodes_per_spring,
                               168 * nodes_per_spring,      168 * nodes_per_spring,
                               96 + 200 * nodes_per_spring, 168 * nodes_per_spring,
                               168 * nodes_per_spring};
    fprintf(ctx->md,
            "\n**Bandwidth floor.** Triad a = b + s·c over three 32 MiB arrays (far beyond the "
            "caches), counting 24 bytes per element: %.1f GB/s [%.1f–%.1f], median of %d. At "
            "the largest lattice (%zu springs, %zu nodes, %.0f MB of spring and node data) each "
            "kernel must move at least the bytes below per spring and step (spring arrays once, "
            "node arrays once, as if nothing stayed in cache; the layout in the source of this "
            "section); the floor is that traffic at the triad bandwidth.\n\n"
            "| variant | bytes per spring | floor, ns per spring | measured, ns per spring | "
            "measured / floor |\n|---|---|---|---|---|\n",
            gbs, bw.min, bw.max, repeats, nsprings[last], nnodes[last],
            (32.0 * (double)nsprings[last] + 104.0 * (double)nnodes[last]) * 1e-6);
    for (size_t e = 0; e < NLV; e++) {
        double floor_ns = gbs > 0 ? bytes[e] / gbs : 0;
        fprintf(ctx->md, "| %s | %.0f | %.2f | %.2f | %.1f |\n", lvars[e].name, bytes[e],
                floor_ns, per[last][e], floor_ns > 0 ? per[last][e] / floor_ns : 0);
    }
    if (have_thr)
        fprintf(ctx->md,
                "\n**Threads** (OpenMP, lattices of %d springs and more): the closed-form "
                "step at %zu springs, %.2f ns per spring on one thread [%.2f–%.2f], %.2f on two "
                "[%.2f–%.2f]: %.2f× with two threads, on a machine whose two cores were shared "
                "with other work while this ran (the load average above).\n\n",
                CF_STEP_THREADS_MIN, nsprings[last], thr1.median, thr1.min, thr1.max, thr2.median,
                thr2.min, thr2.max, thr1.median / thr2.median);
    else
        fprintf(ctx->md, "\n");

    /* targets at the size nearest 1e5 springs */
    const int ref = at[1];
    const double springs_per_ms = 1e6 / per[ref][V_CLOSED];
    const double rc = per[ref][V_CLOSED] / per[ref][V_LIN], rt = per[ref][V_TABLE] / per[ref][V_LIN];
    fprintf(ctx->md,
            "**Targets** (at n = %d, %zu springs, the size nearest 1e5). 1e5 conical springs "
            "per 1 ms step on one core: %s (closed: %.0f springs per ms, i.e. %.2f ms for 1e5; "
            "table: %.0f per ms). Against the linear stencil step (same structure): closed ≤ 2×: "
            "%s (%.2f×); table ≤ 1.3×: %s (%.2f×). Against the minimal linear edge-list step: "
            "closed %.2f×, table %.2f×.\n\n",
            sizes[ref], nsprings[ref], springs_per_ms >= 1e5 ? "**met**" : "**not met**",
            springs_per_ms, per[ref][V_CLOSED] * 0.1, 1e6 / per[ref][V_TABLE],
            rc <= 2 ? "**met**" : "**not met**", rc, rt <= 1.3 ? "**met**" : "**not met**", rt,
            per[ref][V_CLOSED] / per[ref][V_LIN_EDGES], per[ref][V_TABLE] / per[ref][V_LIN_EDGES]);
    bench_target_add(ctx, "lattice step grows linearly with the springs (slope 1 ± 0.1)",
                     fabs(ctx->slope_closed - 1) <= 0.1,
                     "slope %.3f (closed form, %zu to %zu springs)", ctx->slope_closed,
                     nsprings[0], nsprings[last]);
    bench_target_add(ctx, "1e5 conical springs per 1 ms lattice step on one core (closed form)",
                     springs_per_ms >= 1e5, "%.3g springs per ms (%zu-spring lattice)",
                     springs_per_ms, nsprings[ref]);
    bench_target_add(ctx, "lattice step with the closed form ≤ 2× the linear-spring step", rc <= 2,
                     "%.2f× (%.2f against %.2f ns per spring, linear stencil step; %.2f× the "
                     "linear edge-list step)",
                     rc, per[ref][V_CLOSED], per[ref][V_LIN],
                     per[ref][V_CLOSED] / per[ref][V_LIN_EDGES]);
    bench_target_add(ctx, "lattice step with the table ≤ 1.3× the linear-spring step", rt <= 1.3,
                     "%.2f× (%.2f against %.2f ns per spring, linear stencil step; %.2f× the "
                     "linear edge-list step)",
                     rt, per[ref][V_TABLE], per[ref][V_LIN],
                     per[ref][V_TABLE] / per[ref][V_LIN_EDGES]);
    if (bench_gnuplot(ctx, "set terminal pngcairo size 800,500\n"
                           "set output 'lattice_step.png'\n"
                           "set logscale xy\nset grid\nset key outside right\n"
                           "set xlabel 'springs in the lattice'\n"
                           "set ylabel 'time per spring per step [ns]'\n"
                           "set title 'Lattice step: time per spring (flat = linear growth)'\n"
                           "plot for [c=2:10] 'lattice_step.dat' using 1:c with linespoints "
                           "pt 7 title word('linear-stencil linear-edge-list exact closed "
                           "closed+newton table256 closed-edge-list closed-no-polynomial "
                           "table-no-polynomial', c-1)\n") == 0)
        fprintf(ctx->md, "![lattice step: time per spring](lattice_step.png)\n\n");
}
