/*
** Benchmark section: a tissue body's static solve against CalculiX on the same mesh. The block
** 40 x 40 x 20 mm meshed by Gmsh (cf_mesh_box, one element size), held at its bottom; a linear
** spring (D1 = D2) with nu 0.45; a flat punch of radius 8 mm pressed 0.2 mm into the top's centre
** in 4 load steps. conifit: cf_body_solve at each step (penalty contact, the nodal volume term)
** in a forked child; CalculiX (ccx, when installed): linear C3D4 tetrahedra of the same nodes
** with the body's E and nu, the top nodes under the punch moved 0.2 mm down in 4 increments.
** Reported: wall time and peak resident set (ru_maxrss) of each, and their ratio; the target is
** conifit's memory within 1.5 times CalculiX's.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"
#include "io/mesh.h"
#include "model/body.h"

#define DEPTH_MM 0.2
#define RADIUS_MM 8.0
#define STEPS 4

typedef struct body_run {
    const cf_mesh *m;
    const cf_law *law;
} body_run;

/* The child's work: the body, its four load steps; exits 1 when a solve fails. */
static void run_body(void *arg)
{
    const body_run *r = arg;
    cf_body b;
    cf_error err = {0};
    const double kappa = cf_body_kappa_for_nu(cf_body_mu_of_law(r->law), 0.45);
    if (cf_body_create(&b, r->m, r->law, CF_LAW_CLOSED, kappa, &err) != CF_OK)
        _exit(1);
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] <= 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    const cf_probe pr = {CF_PROBE_PUNCH, RADIUS_MM, {20, 20, 20.001}, {0, 0, -1}, DEPTH_MM + 0.001,
                         STEPS, 0};
    for (int k = 1; k <= STEPS; k++) {
        cf_body_step st = {0};
        if (cf_body_solve(&b, &pr, pr.depth_mm * k / STEPS, 0, &st, &err) != CF_OK)
            _exit(1);
        bench_sink += st.force_N;
    }
    cf_body_free(&b);
}

/* The CalculiX deck of mesh m (C3D4, E and nu) at path; 0 when it cannot be written. */
static int write_deck(const char *path, const cf_mesh *m, double E, double nu)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    fprintf(f, "*NODE, NSET=NALL\n");
    for (size_t i = 0; i < m->nn; i++)
        fprintf(f, "%zu, %.17g, %.17g, %.17g\n", i + 1, m->X[3 * i], m->X[3 * i + 1],
                m->X[3 * i + 2]);
    fprintf(f, "*ELEMENT, TYPE=C3D4, ELSET=BODY\n");
    for (size_t t = 0; t < m->nt; t++)
        fprintf(f, "%zu, %u, %u, %u, %u\n", t + 1, m->tet[4 * t] + 1, m->tet[4 * t + 1] + 1,
                m->tet[4 * t + 2] + 1, m->tet[4 * t + 3] + 1);
    fprintf(f, "*MATERIAL, NAME=TISSUE\n*ELASTIC\n%.17g, %.17g\n"
               "*SOLID SECTION, ELSET=BODY, MATERIAL=TISSUE\n*BOUNDARY\n",
            E, nu);
    for (size_t i = 0; i < m->nn; i++)
        if (m->X[3 * i + 2] <= 1e-9)
            fprintf(f, "%zu, 1, 3\n", i + 1);
    fprintf(f, "*STEP\n*STATIC\n%g, 1.0, %g, %g\n*BOUNDARY\n", 1.0 / STEPS, 1.0 / STEPS,
            1.0 / STEPS);
    for (size_t i = 0; i < m->nn; i++) {
        const double *x = m->X + 3 * i;
        if (x[2] >= 20 - 1e-9 && hypot(x[0] - 20, x[1] - 20) < RADIUS_MM)
            fprintf(f, "%zu, 3, 3, %.17g\n", i + 1, -DEPTH_MM);
    }
    fprintf(f, "*NODE FILE\nU\n*END STEP\n");
    return fclose(f) == 0;
}

/* ccx on the deck of m in a scratch folder: 0 and its wall time, CPU time (user + system, s) and
** peak RSS when it ran. */
static int run_ccx(const cf_mesh *m, double E, double nu, double *wall, double *cpu, long *kb)
{
    char dir[] = "/tmp/conifit-bench-ccx-XXXXXX", path[80], run[120], cmd[160];
    if (!mkdtemp(dir))
        return -1;
    snprintf(path, sizeof path, "%s/block.inp", dir);
    /* in the scratch folder: ccx writes its solver's files (spooles.out) where it runs; exec, so
    ** that the resources are ccx's own */
    snprintf(run, sizeof run, "cd '%s' && exec /usr/bin/ccx -i block", dir);
    int rc = -1;
    if (write_deck(path, m, E, nu)) {
        char *argv[] = {"/bin/sh", "-c", run, NULL};
        struct rusage ru;
        const double t0 = bench_now();
        rc = bench_exec(argv, &ru);
        *wall = bench_now() - t0;
        *cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
               (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
        *kb = ru.ru_maxrss;
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        rc = -1;
    return rc;
}

void bench_section_body_ccx(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    fprintf(md, "## Tissue bodies: a static solve against CalculiX on the same mesh\n\n"
                "The block 40 x 40 x 20 mm meshed by Gmsh, held at its bottom, nu 0.45, a linear "
                "spring; a flat punch of radius %g mm pressed %g mm into the top in %d steps. "
                "conifit: cf_body_solve per step (the nodal volume term in its augmented form, "
                "MUMPS's L D L^T); CalculiX: linear C3D4 of the same tetrahedra with the body's E "
                "and nu, the nodes under the punch moved. Peak resident set of each process "
                "(ru_maxrss).\n\n"
                "| element size | nodes | conifit wall | conifit memory | ccx wall | ccx memory | "
                "memory ratio |\n|---|---|---|---|---|---|---|\n",
                RADIUS_MM, DEPTH_MM, STEPS);
    const int have_ccx = access("/usr/bin/ccx", X_OK) == 0;
    cf_spring p = {0};
    const double v[CF_P_COUNT] = {10, 10, 4, 1, 80000, 40};
    for (int k = 0; k < CF_P_COUNT; k++)
        cf_spring_set(&p, k, v[k]);
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return;
    const double mu = cf_body_mu_of_law(&law), kappa = cf_body_kappa_for_nu(mu, 0.45);
    const double lam = mu + kappa, E = mu * (3 * lam + 2 * mu) / (lam + mu); /* body.c's */
    const double sizes[2] = {1.64, 1.15};
    double worst = -1;
    char worst_at[64] = "not measured";
    for (int s = 0; s < (ctx->quick ? 1 : 2); s++) {
        const double lo[3] = {0, 0, 0}, hi[3] = {40, 40, 20}, focus[3] = {20, 20, 20};
        cf_mesh m;
        cf_error err = {0};
        if (cf_mesh_box(lo, hi, focus, sizes[s], sizes[s], 0, &m, &err) != CF_OK) {
            fprintf(md, "| %g mm | Gmsh failed: %s | | | | | |\n", sizes[s], err.msg);
            continue;
        }
        body_run r = {&m, &law};
        const double t0 = bench_now();
        const long kb = bench_child_maxrss_kb(run_body, &r);
        const double wall = bench_now() - t0;
        double cw = 0, ccpu = 0;
        long ckb = -1;
        const int cok = have_ccx && run_ccx(&m, E, 0.45, &cw, &ccpu, &ckb) == 0;
        const double ratio = kb > 0 && cok && ckb > 0 ? (double)kb / (double)ckb : -1;
        fprintf(md, "| %g mm | %zu | %s%.3g s | %.0f MiB | %s%.3g s | %.0f MiB | %.2f |\n", sizes[s],
                m.nn, kb > 0 ? "" : "failed ", wall, kb / 1024.0, cok ? "" : "not run ", cw,
                ckb / 1024.0, ratio);
        if (ratio > worst) {
            worst = ratio;
            snprintf(worst_at, sizeof worst_at, "%.2f at %zu nodes", ratio, m.nn);
        }
        cf_mesh_free(&m);
    }
    fprintf(md, "\n");
    bench_target_add(ctx, "body static solve's memory within 1.5x CalculiX C3D4 on the same mesh",
                     worst < 0 ? -1 : worst <= 1.5, "%s", worst_at);
}

/* The child's work as run_body, timed: fn's CPU time (user + system of the child, s) and peak
** resident set (KiB) through wait4; -1 in *kb when the child failed. */
static void child_cpu(void (*fn)(void *), void *arg, double *cpu, long *kb)
{
    fflush(NULL);
    *kb = -1;
    *cpu = 0;
    pid_t pid = fork();
    if (pid < 0)
        return;
    if (pid == 0) {
        fn(arg);
        _exit(0);
    }
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return;
    *cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    *kb = ru.ru_maxrss;
}

/* The organ-scale row: the same block and probe meshed at 0.82 mm (about 50,000 nodes),
** conifit's CPU time against the target of a minute, and CalculiX on the same mesh. */
void bench_section_body_large(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    const double h = ctx->quick ? 1.64 : 0.82;
    fprintf(md, "## Tissue bodies at organ scale: about 50,000 nodes\n\n"
                "The block and probe of the section above meshed at %g mm; conifit's CPU time "
                "(user + system of the solving process) and peak resident set, CalculiX's on the "
                "same mesh. The target: under a minute of CPU.\n\n"
                "| element size | nodes | tetrahedra | conifit CPU | conifit wall | conifit memory "
                "| ccx CPU | ccx wall | ccx memory |\n|---|---|---|---|---|---|---|---|---|\n", h);
    cf_spring p = {0};
    const double v[CF_P_COUNT] = {10, 10, 4, 1, 80000, 40};
    for (int k = 0; k < CF_P_COUNT; k++)
        cf_spring_set(&p, k, v[k]);
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return;
    const double mu = cf_body_mu_of_law(&law), kappa = cf_body_kappa_for_nu(mu, 0.45);
    const double lam = mu + kappa, E = mu * (3 * lam + 2 * mu) / (lam + mu);
    const double lo[3] = {0, 0, 0}, hi[3] = {40, 40, 20}, focus[3] = {20, 20, 20};
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, focus, h, h, 0, &m, &err) != CF_OK) {
        fprintf(md, "| %g mm | Gmsh failed: %s | | | | | | | |\n\n", h, err.msg);
        bench_target_add(ctx, "a 50,000-node body probed in under a minute of CPU", -1,
                         "not measured");
        return;
    }
    body_run r = {&m, &law};
    double cpu, ccpu = 0, cw = 0;
    long kb, ckb = -1;
    const double t0 = bench_now();
    child_cpu(run_body, &r, &cpu, &kb);
    const double wall = bench_now() - t0;
    const int cok = access("/usr/bin/ccx", X_OK) == 0 && run_ccx(&m, E, 0.45, &cw, &ccpu, &ckb) == 0;
    fprintf(md, "| %g mm | %zu | %zu | %s%.3g s | %.3g s | %.0f MiB | %s%.3g s | %.3g s | %.0f MiB |\n\n",
            h, m.nn, m.nt, kb > 0 ? "" : "failed ", cpu, wall, kb / 1024.0, cok ? "" : "not run ",
            ccpu, cw, ckb / 1024.0);
    bench_target_add(ctx, "a 50,000-node body probed in under a minute of CPU",
                     kb > 0 ? cpu <= 60 : -1, "%zu nodes: %.3g s of CPU, %.0f MiB", m.nn, cpu,
                     kb / 1024.0);
    cf_mesh_free(&m);
}
