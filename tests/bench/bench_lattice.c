/*
** Benchmark section 2: one explicit step of the mass-spring lattice (force kernel plus the
** symplectic update of the nodes) per spring, for a linear spring (the floor: the same kernel with
** the law replaced by F = k u) and for the conical law with each evaluator, over lattices of about
** 1e3 to 1e6 springs.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "conifit/lattice.h"

/* The spring behind data/telescoping.csv: solid strain 0.6, region 2 from strain 0.24. */
static const cf_spring bench_spring = {8, 20, 2.5, 2, 100, 5};
#define STATE_STRAIN 0.35

typedef struct lvariant {
    const char *name;
    int linear;
    cf_law_method method;
} lvariant;

static const lvariant lvars[] = {
    {"linear (floor)", 1, CF_LAW_CLOSED}, {"exact", 0, CF_LAW_EXACT},
    {"closed", 0, CF_LAW_CLOSED},         {"closed+newton", 0, CF_LAW_CLOSED_NEWTON},
    {"table 256", 0, CF_LAW_TABLE},
};
#define NLV (sizeof lvars / sizeof lvars[0])

/* The lattice kernel with F = k u in place of the law (same passes, same memory traffic; forces
** only, as in an explicit step). */
static void linear_forces(cf_lattice *lat, double k)
{
    const size_t ns = lat->ns, nn = lat->nn;
    const uint32_t *restrict si = lat->si, *restrict sj = lat->sj;
    const double *restrict x = lat->x, *restrict y = lat->y, *restrict z = lat->z;
    const double *restrict L0 = lat->L0_mm, *restrict a = lat->a, *restrict w = lat->w;
    double *restrict L = lat->L_mm, *restrict u = lat->u_mm, *restrict T = lat->T_N;
    double *restrict F = lat->F_N;
    double *restrict fx = lat->fx, *restrict fy = lat->fy, *restrict fz = lat->fz;
    for (size_t s = 0; s < ns; s++) {
        double dx = x[sj[s]] - x[si[s]], dy = y[sj[s]] - y[si[s]], dz = z[sj[s]] - z[si[s]];
        double l = sqrt(dx * dx + dy * dy + dz * dz);
        L[s] = l;
        u[s] = (L0[s] - l) * a[s];
    }
    for (size_t s = 0; s < ns; s++)
        F[s] = k * u[s];
    memset(fx, 0, nn * sizeof(double));
    memset(fy, 0, nn * sizeof(double));
    memset(fz, 0, nn * sizeof(double));
    for (size_t s = 0; s < ns; s++) {
        double t = -w[s] * F[s];
        T[s] = t;
        double g = t / L[s];
        uint32_t i = si[s], j = sj[s];
        double gx = g * (x[j] - x[i]), gy = g * (y[j] - y[i]), gz = g * (z[j] - z[i]);
        fx[i] += gx;
        fy[i] += gy;
        fz[i] += gz;
        fx[j] -= gx;
        fy[j] -= gy;
        fz[j] -= gz;
    }
}

typedef struct vel {
    double *vx, *vy, *vz;
} vel;

/* One symplectic Euler step: forces, then v += h f/m and x += h v on the free degrees. */
static void step(cf_lattice *lat, vel *v, int linear, double k, double h)
{
    if (linear)
        linear_forces(lat, k);
    else {
        lat->with_stiffness = 0; /* an explicit step needs forces only */
        cf_lattice_forces(lat);
    }
    for (size_t p = 0; p < lat->nn; p++) {
        const double im = h / lat->mass_t[p];
        const uint8_t f = lat->fix[p];
        if (!(f & CF_FIX_X)) {
            v->vx[p] += im * lat->fx[p];
            lat->x[p] += h * v->vx[p];
        }
        if (!(f & CF_FIX_Y)) {
            v->vy[p] += im * lat->fy[p];
            lat->y[p] += h * v->vy[p];
        }
        if (!(f & CF_FIX_Z)) {
            v->vz[p] += im * lat->fz[p];
            lat->z[p] += h * v->vz[p];
        }
    }
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

void bench_section_lattice(bench_ctx *ctx)
{
    static const int full[] = {4, 6, 9, 13, 19, 28, 42};
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
    size_t nsprings[7];
    int ref = 0; /* index of the size nearest 1e5 springs */
    for (int z = 0; z < nsz; z++) {
        cf_lattice lat;
        cf_lattice_config cfg = cf_lattice_default();
        cfg.nx = cfg.ny = cfg.nz = sizes[z];
        if (cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, NULL) != CF_OK) {
            nsprings[z] = 0;
            continue;
        }
        nsprings[z] = lat.ns;
        if (fabs(log((double)lat.ns / 1e5)) < fabs(log((double)nsprings[ref] / 1e5)))
            ref = z;
        ctx->largest_springs = lat.ns;
        ctx->largest_cells = sizes[z];
        vel v = {calloc(lat.nn, sizeof(double)), calloc(lat.nn, sizeof(double)),
                 calloc(lat.nn, sizeof(double))};
        for (size_t e = 0; e < NLV; e++) {
            lat.method = lvars[e].method;
            deform(&lat);
            memset(v.vx, 0, lat.nn * sizeof(double));
            memset(v.vy, 0, lat.nn * sizeof(double));
            memset(v.vz, 0, lat.nn * sizeof(double));
            /* a step of 1e-12 s: the state stays where deform() put it */
            const double h = 1e-12;
            double t0 = bench_now();
            step(&lat, &v, lvars[e].linear, law.k0_N_per_mm, h);
            double one = bench_now() - t0;
            long nstep = (long)(sample_s / fmax(one, 1e-9)) + 1;
            double t[16];
            for (int r = 0; r < repeats; r++) {
                t0 = bench_now();
                for (long i = 0; i < nstep; i++)
                    step(&lat, &v, lvars[e].linear, law.k0_N_per_mm, h);
                t[r] = (bench_now() - t0) / (double)nstep / (double)lat.ns * 1e9;
            }
            bench_sink += lat.fz[lat.nn / 2];
            st[z][e] = bench_summarise(t, repeats);
            per[z][e] = st[z][e].median;
        }
        free(v.vx);
        free(v.vy);
        free(v.vz);
        cf_lattice_free(&lat);
    }
    cf_law_free(&law);

    fprintf(ctx->md,
            "## 2. Lattice step: time per spring\n\n"
            "One explicit step = the force kernel `cf_lattice_forces` (lengths, law, tensions, node "
            "forces) plus the symplectic Euler update of every free node. Cubic lattices of n³ "
            "cells with face and body diagonals (the default), the spring of "
            "`data/telescoping.csv`, every node moved to a compression of %.2f (± 0.5 %% of H "
            "jitter) so that every spring is in region 2. The linear floor is the same kernel "
            "with the law replaced by F = k u. ns per spring per step, median of %d samples "
            "[min–max]; each sample runs enough steps to last %.0f ms.\n\n",
            STATE_STRAIN, repeats, sample_s * 1e3);
    fprintf(ctx->md, "| n | springs |");
    for (size_t e = 0; e < NLV; e++)
        fprintf(ctx->md, " %s |", lvars[e].name);
    fprintf(ctx->md, " closed / linear | table / linear |\n|---|---|");
    for (size_t e = 0; e < NLV + 2; e++)
        fprintf(ctx->md, "---|");
    fprintf(ctx->md, "\n");
    FILE *dat = bench_open_data(ctx, "lattice_step.dat");
    for (int z = 0; z < nsz; z++) {
        if (!nsprings[z])
            continue;
        fprintf(ctx->md, "| %d | %zu |", sizes[z], nsprings[z]);
        for (size_t e = 0; e < NLV; e++)
            fprintf(ctx->md, " %.2f [%.2f–%.2f] |", st[z][e].median, st[z][e].min, st[z][e].max);
        fprintf(ctx->md, " %.2f | %.2f |\n", per[z][2] / per[z][0], per[z][4] / per[z][0]);
        if (dat) {
            fprintf(dat, "%zu", nsprings[z]);
            for (size_t e = 0; e < NLV; e++)
                fprintf(dat, " %.6g", per[z][e]);
            fprintf(dat, "\n");
        }
    }
    if (dat)
        fclose(dat);
    /* growth: least-squares slope of log(step time) against log(springs) */
    fprintf(ctx->md,
            "\n**Growth.** Least-squares slope of log(time per step) against log(springs) "
            "(1 = linear growth), and the largest lattice that keeps a 1 kHz step on one core: "
            "the largest measured size whose step fits in 1 ms, and 1 ms divided by the time per "
            "spring measured at the largest size (cache misses included).\n\n"
            "| evaluator | slope | per-spring time, smallest → largest, ns | largest measured "
            "size within 1 ms | springs per 1 ms step (at the largest size) |\n"
            "|---|---|---|---|---|\n");
    int last = nsz - 1;
    while (last > 0 && !nsprings[last])
        last--;
    for (size_t e = 0; e < NLV; e++) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        int m = 0;
        size_t fits = 0;
        for (int z = 0; z < nsz; z++) {
            if (!nsprings[z])
                continue;
            double lx = log((double)nsprings[z]);
            double ly = log(per[z][e] * (double)nsprings[z]);
            sx += lx;
            sy += ly;
            sxx += lx * lx;
            sxy += lx * ly;
            m++;
            if (per[z][e] * (double)nsprings[z] <= 1e6)
                fits = nsprings[z];
        }
        double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
        fprintf(ctx->md, "| %s | %.3f | %.2f → %.2f | %zu | %.3g |\n", lvars[e].name, slope,
                per[0][e], per[last][e], fits, 1e6 / per[last][e]);
        if (e == 2)
            ctx->slope_closed = slope;
    }
    const double closed_ms = per[ref][2] * 1e5 * 1e-6; /* ms for 1e5 springs at the ref size */
    const double springs_per_ms = 1e6 / per[ref][2];
    const double rc = per[ref][2] / per[ref][0], rt = per[ref][4] / per[ref][0];
    fprintf(ctx->md,
            "\n**Targets** (at n = %d, %zu springs, the size nearest 1e5). 1e5 conical springs "
            "per 1 ms step on one core: %s (closed: %.0f springs per ms, i.e. %.2f ms for 1e5; "
            "table: %.0f per ms). Closed ≤ 2× linear: %s (%.2f×). Table ≤ 1.3× linear: %s "
            "(%.2f×).\n\n",
            sizes[ref], nsprings[ref], springs_per_ms >= 1e5 ? "**met**" : "**not met**",
            springs_per_ms, closed_ms, 1e6 / per[ref][4], rc <= 2 ? "**met**" : "**not met**", rc,
            rt <= 1.3 ? "**met**" : "**not met**", rt);
    bench_target_add(ctx, "lattice step grows linearly with the springs (slope 1 ± 0.1)",
                     fabs(ctx->slope_closed - 1) <= 0.1, "slope %.3f (closed form, %zu to %zu springs)",
                     ctx->slope_closed, nsprings[0], nsprings[last]);
    bench_target_add(ctx, "1e5 conical springs per 1 ms lattice step on one core (closed form)",
                     springs_per_ms >= 1e5, "%.3g springs per ms (%zu-spring lattice)",
                     springs_per_ms, nsprings[ref]);
    bench_target_add(ctx, "lattice step with the closed form ≤ 2× the linear-spring lattice",
                     rc <= 2, "%.2f× (%.2f against %.2f ns per spring)", rc, per[ref][2],
                     per[ref][0]);
    bench_target_add(ctx, "lattice step with the table ≤ 1.3× the linear-spring lattice", rt <= 1.3,
                     "%.2f× (%.2f against %.2f ns per spring)", rt, per[ref][4], per[ref][0]);
    if (bench_gnuplot(ctx, "set terminal pngcairo size 800,500\n"
                           "set output 'lattice_step.png'\n"
                           "set logscale xy\nset grid\nset key outside right\n"
                           "set xlabel 'springs in the lattice'\n"
                           "set ylabel 'time per spring per step [ns]'\n"
                           "set title 'Lattice step: time per spring (flat = linear growth)'\n"
                           "plot for [c=2:6] 'lattice_step.dat' using 1:c with linespoints "
                           "pt 7 title word('linear exact closed closed+newton table256', c-1)\n") ==
        0)
        fprintf(ctx->md, "![lattice step: time per spring](lattice_step.png)\n\n");
}
