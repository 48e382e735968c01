/*
** Benchmark section: tissue bodies and the probe loop at haptic rate. The liver meshes of
** ../shared/meshes (section skipped without them), with the fitted muscle spring of
** fits/series/ and nu = 0.45: a sphere of radius 10 mm pressed into the liver's top at 5 mm/s,
** one static equilibrium per 1 ms of simulated time (5 um of travel per update), each solve
** starting from the last, and the haptic loop's update (cf_body_haptic_step). Reported: the wall
** and CPU time per update (median and 99th percentile over the updates after the first contact),
** by mesh size (liver2.msh as read and refined once by Gmsh), the haptic force against the static
** solve's along the ramp and at rest, whether an update fits in 1 ms (1 kHz: median <= 1 ms, 99th
** percentile <= 2 ms), and CalculiX (ccx) on the same mesh, per increment. First, the search for a
** surface's crossings on cylinders of long triangles, by triangle count.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "model/body.h"
#include "io/fitfile.h"
#include "io/mesh.h"
#include "io/surface.h"

#define UPDATES 200
#define HAPTIC_ITERS 3
#define CCX_INCREMENTS 20

/* haptic = 0: a static solve per update; else cf_body_haptic_step with at most `haptic` chord
** iterations per update, then held at the last depth for UPDATES more updates, and its force
** there over the static solve's. */
/* What loop() measures: medians and 99th percentiles per update (after first contact), the force
** after every update of the ramp (fk[UPDATES]), the last, and at rest the haptic force over the
** static solve's. */
typedef struct loop_result {
    double wall_ms, cpu_ms, wall_p99, cpu_p99;
    double fk[UPDATES];
    double force, rest_ratio;
    size_t nodes;
} loop_result;

/* The 99th percentile of the sorted x[n] (the value below which 99 % of them lie). */
static double p99(const double *x, int n)
{
    int k = (int)ceil(0.99 * n) - 1;
    return x[k < 0 ? 0 : k];
}

static int loop(const char *path, int refine, const cf_law *law, int haptic, loop_result *res)
{
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_read_refined(path, 100, refine, NULL, &m, &err) != CF_OK)
        return 0;
    cf_body b;
    if (cf_body_create(&b, &m, law, CF_LAW_CLOSED,
                       cf_body_kappa_for_nu(cf_body_mu_of_law(law), 0.45), &err) != CF_OK) {
        cf_mesh_free(&m);
        return 0;
    }
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] <= -60)
            b.fix[i] = CF_BODY_FIX_ALL;
    /* the sphere just above the liver's highest node */
    size_t top = 0;
    for (size_t i = 1; i < b.nn; i++)
        if (b.X[3 * i + 2] > b.X[3 * top + 2])
            top = i;
    cf_probe pr = {CF_PROBE_SPHERE, 10, {b.X[3 * top], b.X[3 * top + 1], b.X[3 * top + 2] + 10.001},
                   {0, 0, -1}, 0, UPDATES};
    double w[UPDATES], c[UPDATES];
    int n = 0, ok = 1;
    cf_body_step st = {0};
    for (int k = 1; k <= UPDATES && ok; k++) {
        double t0 = bench_now(), c0 = bench_cpu_now();
        ok = (haptic ? cf_body_haptic_step(&b, &pr, 0.005 * k, 0, haptic, &st, &err)
                     : cf_body_solve(&b, &pr, 0.005 * k, 0, &st, &err)) == CF_OK;
        res->fk[k - 1] = st.force_N;
        if (st.contacts > 0) {
            w[n] = (bench_now() - t0) * 1e3;
            c[n] = (bench_cpu_now() - c0) * 1e3;
            n++;
        }
    }
    res->nodes = b.nn;
    res->force = st.force_N;
    res->rest_ratio = 1;
    if (haptic && ok) {
        for (int k = 0; k < UPDATES && ok; k++)
            ok = cf_body_haptic_step(&b, &pr, 0.005 * UPDATES, 0, haptic, &st, &err) == CF_OK;
        cf_body_step sst;
        ok = ok && cf_body_solve(&b, &pr, 0.005 * UPDATES, 0, &sst, &err) == CF_OK;
        res->rest_ratio = ok ? st.force_N / sst.force_N : 0;
    }
    cf_body_free(&b);
    cf_mesh_free(&m);
    if (!ok || n == 0)
        return 0;
    res->wall_ms = bench_summarise(w, n).median;
    res->cpu_ms = bench_summarise(c, n).median;
    res->wall_p99 = p99(w, n); /* bench_summarise sorted them */
    res->cpu_p99 = p99(c, n);
    return 1;
}

/* A cylinder along x (length 100 mm, radius 5 mm) of n long side triangles pairs and two fan
** caps: 4 n triangles, in memory. */
static int cylinder(int n, cf_surface *s)
{
    s->nv = 2 * (size_t)n + 2;
    s->nf = 4 * (size_t)n;
    s->X = malloc(3 * s->nv * sizeof *s->X);
    s->tri = malloc(3 * s->nf * sizeof *s->tri);
    if (!s->X || !s->tri) {
        cf_surface_free(s);
        return 0;
    }
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < n; k++)
        for (int e = 0; e < 2; e++) {
            double *x = s->X + 3 * (size_t)(2 * k + e);
            x[0] = 100.0 * e;
            x[1] = 5 * cos(2 * pi * k / n);
            x[2] = 5 * sin(2 * pi * k / n);
        }
    const uint32_t c0 = 2 * (uint32_t)n, c1 = c0 + 1;
    memset(s->X + 3 * (size_t)c0, 0, 6 * sizeof *s->X);
    s->X[3 * (size_t)c1] = 100;
    for (uint32_t k = 0; k < (uint32_t)n; k++) {
        const uint32_t a0 = 2 * k, a1 = 2 * k + 1, b0 = 2 * ((k + 1) % (uint32_t)n), b1 = b0 + 1;
        const uint32_t t[4][3] = {{a0, a1, b1}, {a0, b1, b0}, {c0, a0, b0}, {c1, b1, a1}};
        memcpy(s->tri + 12 * (size_t)k, t, sizeof t);
    }
    return 1;
}

/* The search for a surface's crossings (cf_surface_prepare) on cylinders of long triangles and
** fan caps, the shape a sweep along one axis made quadratic (60.8 s at 40,000 triangles). */
static void surface_crossings(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    fprintf(md, "## Tissue bodies: a surface's checks on long triangles\n\n"
                "cf_surface_prepare (closedness, shells, crossings) on a cylinder 100 mm long, "
                "5 mm in radius, of long side triangles and fan caps.\n\n"
                "| triangles | edge-triangle tests | wall |\n|---|---|---|\n");
    double t40 = -1;
    for (int n = 2500; n <= 40000; n *= 2) {
        cf_surface s;
        cf_mesh_surface_info info;
        cf_error err = {0};
        if (!cylinder(n, &s))
            break;
        const double t0 = bench_now();
        const cf_status st = cf_surface_prepare(&s, "cylinder", 1, 2, &info, &err);
        const double t = bench_now() - t0;
        cf_surface_free(&s);
        if (st != CF_OK) {
            fprintf(md, "| %d | failed: %s | |\n", 4 * n, err.msg);
            continue;
        }
        if (4 * n == 40000)
            t40 = t;
        fprintf(md, "| %d | %zu | %.3g s |\n", 4 * n, info.pair_tests, t);
    }
    fprintf(md, "\n");
    bench_target_add(ctx, "crossing check of a 40,000-triangle cylinder within 2 s",
                     t40 >= 0 && t40 < 2, "%.3g s", t40);
}

/* CalculiX on the liver mesh (refined `refine` times): the same tetrahedra as linear C3D4, linear
** elastic with the body's E and nu, held below z = -60 mm, the highest node pushed 1 mm down in
** CCX_INCREMENTS fixed increments with NLGEOM; one row of the table: wall time of the ccx run
** per increment and its reaction at the pushed node. Skipped (a row saying why) without ccx. */
static void ccx_row(bench_ctx *ctx, int refine, const char *mesh, const cf_law *law)
{
    FILE *md = ctx->md;
    const char *what = "CalculiX C3D4, linear elastic";
    if (system("command -v ccx >/dev/null 2>&1") != 0) {
        fprintf(md, "| %s | %s | | not measured: no ccx | | | | | |\n", mesh, what);
        return;
    }
    cf_mesh m;
    cf_body b;
    cf_error err = {0};
    if (cf_mesh_read_refined("../shared/meshes/liver2.msh", 100, refine, NULL, &m, &err) != CF_OK)
        return;
    if (cf_body_create(&b, &m, law, CF_LAW_CLOSED,
                       cf_body_kappa_for_nu(cf_body_mu_of_law(law), 0.45), &err) != CF_OK) {
        cf_mesh_free(&m);
        return;
    }
    char path[900], cmd[2000];
    snprintf(path, sizeof path, "%s/haptic_ccx%d.inp", ctx->dir, refine);
    FILE *f = fopen(path, "w");
    size_t top = 0;
    for (size_t i = 1; i < b.nn; i++)
        if (b.X[3 * i + 2] > b.X[3 * top + 2])
            top = i;
    if (f) {
        fprintf(f, "*NODE\n");
        for (size_t i = 0; i < b.nn; i++)
            fprintf(f, "%zu, %.17g, %.17g, %.17g\n", i + 1, b.X[3 * i], b.X[3 * i + 1],
                    b.X[3 * i + 2]);
        fprintf(f, "*ELEMENT, TYPE=C3D4, ELSET=BODY\n");
        for (size_t t = 0; t < b.nt; t++)
            fprintf(f, "%zu, %u, %u, %u, %u\n", t + 1, b.tet[4 * t] + 1, b.tet[4 * t + 1] + 1,
                    b.tet[4 * t + 2] + 1, b.tet[4 * t + 3] + 1);
        fprintf(f, "*NSET, NSET=FIX\n");
        for (size_t i = 0; i < b.nn; i++)
            if (b.X[3 * i + 2] <= -60)
                fprintf(f, "%zu\n", i + 1);
        fprintf(f, "*NSET, NSET=NTOP\n%zu\n*MATERIAL, NAME=TISSUE\n*ELASTIC\n%.17g, %.17g\n"
                   "*SOLID SECTION, ELSET=BODY, MATERIAL=TISSUE\n"
                   "*STEP, NLGEOM, INC=1000\n*STATIC, DIRECT\n%.17g, 1\n*BOUNDARY\nFIX, 1, 3\n"
                   "NTOP, 3, 3, -1\n*NODE PRINT, NSET=NTOP, TOTALS=ONLY\nRF\n*END STEP\n",
                top + 1, b.E_MPa, b.nu, 1.0 / CCX_INCREMENTS);
        fclose(f);
    }
    const size_t nodes = b.nn;
    cf_body_free(&b);
    cf_mesh_free(&m);
    snprintf(cmd, sizeof cmd, "cd %s && OMP_NUM_THREADS=1 ccx -i haptic_ccx%d > haptic_ccx%d.log 2>&1",
             ctx->dir, refine, refine);
    const double t0 = bench_now();
    const int rc = f ? system(cmd) : -1;
    const double t = bench_now() - t0;
    double fz = NAN, tt, fx, fy, fzk;
    snprintf(path, sizeof path, "%s/haptic_ccx%d.dat", ctx->dir, refine);
    FILE *dat = rc == 0 ? fopen(path, "r") : NULL;
    static char text[1 << 16];
    const size_t len = dat ? fread(text, 1, sizeof text - 1, dat) : 0;
    text[len] = 0;
    if (dat)
        fclose(dat);
    const char *key = "total force (fx,fy,fz) for set NTOP and time";
    for (const char *q = text; (q = strstr(q, key)); q++) /* the last increment's */
        if (sscanf(q + strlen(key), "%lf %lf %lf %lf", &tt, &fx, &fy, &fzk) == 4)
            fz = fzk;
    if (rc != 0 || !isfinite(fz)) {
        fprintf(md, "| %s | %s | %zu | ccx failed (see haptic_ccx%d.log) | | | | | |\n", mesh, what,
                nodes, refine);
        return;
    }
    fprintf(md, "| %s | %s, %d increments | %zu | %.3g ms per increment | - | %.4g N | - | - | %s |\n",
            mesh, what, CCX_INCREMENTS, nodes, 1e3 * t / CCX_INCREMENTS, -fz,
            1e3 * t / CCX_INCREMENTS <= 1 ? "yes" : "no");
}

void bench_section_body(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    surface_crossings(ctx);
    bench_section_body_ccx(ctx);
    fprintf(md, "## Tissue bodies: the probe loop at haptic rate\n\n");
    FILE *f = fopen("../shared/meshes/liver2.msh", "r");
    if (!f) {
        fprintf(md, "Not measured: ../shared/meshes is absent.\n\n");
        bench_target_add(ctx, "probe update on liver2.msh within 1 ms (1 kHz)", -1, "no mesh");
        return;
    }
    fclose(f);
    cf_fitted_spring fs;
    cf_law law;
    cf_error err = {0};
    if (cf_fitfile_load("fits/series/muscle_compression_relaxation_fiber30.json", NULL, &fs,
                        &err) != CF_OK ||
        cf_law_init(&law, &fs.params, &err) != CF_OK) {
        fprintf(md, "Not measured: %s\n\n", err.msg);
        return;
    }
    fprintf(md, "The fitted muscle spring (fits/series/muscle_compression_relaxation_fiber30.json) "
                "on every edge of the liver mesh (unit 100 mm), nu = 0.45, held below z = -60 mm; "
                "a sphere of radius 10 mm pressed down into the top at 5 mm/s, one static "
                "equilibrium (Newton on the sparse tangent, warm-started from the last) per 1 ms "
                "update, %d updates; median and 99th percentile per update after first contact "
                "(the first factorisation among them), one core. "
                "The haptic update (cf_body_haptic_step): at most %d chord iterations (and 1) with "
                "the exact residual and the contact-free tangent factored once, contact by "
                "Woodbury's identity, the force taken from the body's side after the last step; "
                "the 1 kHz target on the refined mesh is judged on the 1-iteration row; "
                "'ramp' is its largest relative difference from the static solve's "
                "force at the same depth over the updates in contact; then held %d updates at "
                "the last depth, its force over the static solve's there ('at rest'). 1 kHz: "
                "median wall <= 1 ms and 99th percentile <= 2 ms. CalculiX: ccx (OMP_NUM_THREADS=1) "
                "on the same tetrahedra as linear C3D4, linear elastic with the body's E and nu, "
                "held alike, the top node pushed 1 mm down in %d fixed increments (NLGEOM), wall "
                "time of the whole run per increment (its start-up included).\n\n"
                "| mesh | update | nodes | wall per update (median / p99) | CPU (median / p99) | "
                "force at %.2f mm | ramp | at rest / static | 1 kHz |\n"
                "|---|---|---|---|---|---|---|---|---|\n",
            UPDATES, HAPTIC_ITERS, UPDATES, CCX_INCREMENTS, 0.005 * UPDATES);
    double liver_wall = -1, refined_wall = -1, refined_p99 = -1, refined_worst = -1;
    static loop_result rs, rh; /* the static solve's and the haptic loop's, per mesh */
    static const int iters[3] = {0, HAPTIC_ITERS, 1}; /* static solve, haptic, haptic 1 iteration */
    for (int refine = 0; refine <= (ctx->quick ? 0 : 1); refine++) {
        const char *mesh = refine ? "liver2.msh refined once" : "liver2.msh";
        for (int v = 0; v < 3; v++) {
            const int haptic = iters[v];
            loop_result *r = haptic ? &rh : &rs;
            char kind[64];
            snprintf(kind, sizeof kind, haptic ? "haptic, %d iteration%s" : "static solve", haptic,
                     haptic == 1 ? "" : "s");
            r->nodes = 0;
            if (!loop("../shared/meshes/liver2.msh", refine, &law, haptic, r)) {
                fprintf(md, "| %s | %s | %zu | failed | | | | | |\n", mesh, kind, r->nodes);
                continue;
            }
            char at_rest[32] = "-", ramp[32] = "-";
            double worst = 0;
            if (haptic) {
                for (int k = 0; k < UPDATES; k++)
                    if (rs.fk[k] > 0)
                        worst = fmax(worst, fabs(rh.fk[k] / rs.fk[k] - 1));
                snprintf(at_rest, sizeof at_rest, "%.7f", r->rest_ratio);
                snprintf(ramp, sizeof ramp, "%.2g", worst);
            }
            const int khz = r->wall_ms <= 1 && r->wall_p99 <= 2;
            fprintf(md, "| %s | %s | %zu | %.3g / %.3g ms | %.3g / %.3g ms | %.4g N | %s | %s | %s |\n",
                    mesh, kind, r->nodes, r->wall_ms, r->wall_p99, r->cpu_ms, r->cpu_p99, r->force,
                    ramp, at_rest, khz ? "yes" : "no");
            if (refine == 0 && haptic == HAPTIC_ITERS)
                liver_wall = r->wall_ms;
            if (refine == 1 && haptic == 1)
                refined_wall = r->wall_ms, refined_p99 = r->wall_p99, refined_worst = worst;
        }
        ccx_row(ctx, refine, mesh, &law);
    }
    fprintf(md, "\n");
    bench_target_add(ctx, "probe update on liver2.msh within 1 ms (1 kHz)",
                     liver_wall < 0 ? -1 : liver_wall <= 1, "%.3g ms wall per update (haptic update)",
                     liver_wall);
    bench_target_add(ctx, "haptic update on liver2.msh refined once: median <= 1 ms, p99 <= 2 ms",
                     refined_wall < 0 ? -1 : refined_wall <= 1 && refined_p99 <= 2,
                     "median %.3g ms, p99 %.3g ms wall (1 iteration per update; ramp within %.2g "
                     "of the static force)",
                     refined_wall, refined_p99, refined_worst);
    cf_law_free(&law);
}
