/*
** Bench section: a static contact solve on the finest mesh of the contact study
** (src/notes/contact-study.md): a sphere of 40 mm pressed 0.025 mm (two steps) into a graded
** quarter block of 8,657 nodes, at nu 0.25 and 0.45; CPU time of the solve and the force over
** Hertz's. Target: each under 2 minutes of CPU, within 3 % of Hertz.
*/
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bench.h"
#include "io/mesh.h"
#include "model/body.h"

/* One run at refinement r (the study's): 1 with *cpu_s, *ratio and *nodes filled, 0 on failure. */
static int hertz_run(double nu, double r, double *cpu_s, double *ratio, size_t *nodes)
{
    cf_spring p = {10, 30, 4, 1, 8e4, 40}; /* the tests' telescoping cone */
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 0;
    const double W = 30, R = 40, d = 0.025;
    double lo[3] = {0, 0, -W}, hi[3] = {W, W, 0}, focus[3] = {0, 0, 0};
    cf_mesh m;
    cf_body b;
    cf_error err = {0};
    int ok = 0;
    if (cf_mesh_box(lo, hi, focus, 0.3 / r, 8 / r, 0.4 / r, &m, &err) != CF_OK)
        goto law;
    if (cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                       cf_body_kappa_for_nu(cf_body_mu_of_law(&law), nu), &err) != CF_OK)
        goto mesh;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] = (uint8_t)((X[0] < 1e-9) | (X[1] < 1e-9) << 1);
        if (X[2] < -W + 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    }
    cf_probe pr = {CF_PROBE_SPHERE, R, {0, 0, R}, {0, 0, -1}, d, 2};
    cf_body_step st = {0};
    const double t0 = bench_cpu_now();
    ok = cf_body_solve(&b, &pr, d / 2, 0, &st, &err) == CF_OK &&
         cf_body_solve(&b, &pr, d, 0, &st, &err) == CF_OK;
    *cpu_s = bench_cpu_now() - t0;
    const double Es = b.E_MPa / (1 - b.nu * b.nu);
    *ratio = 4 * st.force_N / (4.0 / 3 * Es * sqrt(R) * pow(d, 1.5));
    *nodes = b.nn;
    cf_body_free(&b);
mesh:
    cf_mesh_free(&m);
law:
    cf_law_free(&law);
    return ok;
}

void bench_section_contact(bench_ctx *ctx)
{
    FILE *md = ctx->md;
    const double r = ctx->quick ? 3 : 4.6;
    fprintf(md, "## Tissue bodies: Hertz on the contact study's finest mesh\n\n"
                "A sphere of 40 mm pressed 0.025 mm in two static solves into a quarter block "
                "30 mm deep, meshed by Gmsh finer towards the contact (refinement %g of "
                "src/notes/contact-study.md), the tests' spring; CPU time of the two solves "
                "(after meshing), one run.\n\n"
                "| nu | nodes | CPU | force / Hertz |\n|---|---|---|---|\n",
            r);
    int met = 1;
    char what[96] = "";
    for (int k = 0; k < 2; k++) {
        const double nu = k ? 0.45 : 0.25;
        double cpu = 0, ratio = 0;
        size_t nodes = 0;
        if (!hertz_run(nu, r, &cpu, &ratio, &nodes)) {
            fprintf(md, "| %.2f | %zu | failed | |\n", nu, nodes);
            met = 0;
            continue;
        }
        fprintf(md, "| %.2f | %zu | %.1f s | %.4f |\n", nu, nodes, cpu, ratio);
        met &= cpu < 120 && fabs(ratio - 1) <= 0.03;
        snprintf(what + strlen(what), sizeof what - strlen(what), "%snu %.2f: %.1f s, %.4f",
                 k ? "; " : "", nu, cpu, ratio);
    }
    fprintf(md, "\n");
    bench_target_add(ctx, "Hertz on 8,657 nodes: under 2 min CPU, within 3 %", met, "%s", what);
}
