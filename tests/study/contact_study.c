/*
** The contact convergence study (src/notes/contact-study.md): a sphere (Hertz) or a flat punch
** (Boussinesq) pressed into a quarter of a block (symmetry planes x = 0 and y = 0, bottom held),
** meshed by Gmsh finer towards the contact; conifit's force against theory and, with --ccx DIR,
** against CalculiX's quadratic tetrahedra (C3D10) on the same tetrahedra with the nodes conifit
** ends with in contact prescribed onto the probe's surface (z only: frictionless).
**
**   contact_study sphere|punch NU REFINE [--ccx DIR]
**
** Prints one line: nodes, contacts, conifit's force over theory, the CPU seconds of the solve
** and, with --ccx, C3D10's force over theory and conifit's over C3D10's. STUDY_ELEM=C3D4 writes
** linear tetrahedra instead; STUDY_CONTACT=1 (sphere) lets CalculiX find its own contact with a
** rigid sphere instead of taking conifit's contact nodes; STUDY_SCALE=S multiplies every
** spring's factor by S (STUDY_MATCH=1 gives the body its element term first); STUDY_W sets the
** block's side, STUDY_H0, STUDY_GROW, STUDY_HMAX its grading (STUDY_RIM=1: about the punch's
** rim, not its centre); STUDY_R, STUDY_D and STUDY_STEPS change the sphere and its steps.
*/
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "io/mesh.h"
#include "model/body.h"
#include "model/body_internal.h"

static double cpu_s(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec +
           (double)u.ru_stime.tv_sec + 1e-6 * (double)u.ru_stime.tv_usec;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* CalculiX's own contact for the sphere (STUDY_CONTACT=1): the block's top faces within 3 contact
** radii of the axis (C3D10 faces; corners 1-2-3, 1-4-2, 2-4-3, 3-4-1 are faces 1 to 4) as the
** slave surface, and as master the lower face of a layer of hexahedra on the sphere's surface
** z = R - sqrt(R^2 - x^2 - y^2) (a = sqrt(R d) thick, 0.08 a apart, from -0.1 a to 3 a: a little
** beyond the symmetry planes), every node of it moved d down (a rigid sphere); face-to-face
** penalty contact of slope 1000 E/a, frictionless. Node numbers from n0, elements from e0; the
** layer's nodes are the set IND. */
static void write_indenter(FILE *f, const cf_body *b, double R, double d, double E, size_t n0,
                           size_t e0)
{
    const double a = sqrt(R * d), lo = -0.1 * a, hi = 3 * a;
    const int N = (int)ceil((hi - lo) / (0.08 * a));
    fprintf(f, "*NODE, NSET=IND\n");
    for (int l = 0; l < 2; l++)
        for (int j = 0; j <= N; j++)
            for (int i = 0; i <= N; i++) {
                const double x = lo + (hi - lo) * i / N, y = lo + (hi - lo) * j / N;
                const size_t n = n0 + (size_t)((l * (N + 1) + j) * (N + 1) + i);
                fprintf(f, "%zu, %.12g, %.12g, %.12g\n", n, x, y,
                        R - sqrt(R * R - x * x - y * y) + 0.5 * l * a);
            }
    fprintf(f, "*ELEMENT, TYPE=C3D8, ELSET=IND\n");
    size_t e = e0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            const size_t c0 = n0 + (size_t)(j * (N + 1) + i), c2 = c0 + (size_t)(N + 1);
            const size_t c[4] = {c0, c0 + 1, c2 + 1, c2};
            const size_t up = (size_t)((N + 1) * (N + 1));
            fprintf(f, "%zu, %zu, %zu, %zu, %zu, %zu, %zu, %zu, %zu\n", e++, c[0], c[1], c[2], c[3],
                    c[0] + up, c[1] + up, c[2] + up, c[3] + up);
        }
    fprintf(f, "*SURFACE, NAME=MASTER, TYPE=ELEMENT\nIND, S1\n"
               "*SURFACE, NAME=SLAVE, TYPE=ELEMENT\n");
    static const int face[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
    for (size_t t = 0; t < b->nt; t++)
        for (int k = 0; k < 4; k++) {
            int top = 1;
            for (int c = 0; c < 3; c++) {
                const double *X = b->X + 3 * b->tet[4 * t + face[k][c]];
                top &= X[2] > -1e-9 && X[0] * X[0] + X[1] * X[1] < 9 * a * a;
            }
            if (top)
                fprintf(f, "%zu, S%d\n", t + 1, k + 1);
        }
    fprintf(f, "*MATERIAL, NAME=RIGID\n*ELASTIC\n%.10g, 0.3\n"
               "*SOLID SECTION, ELSET=IND, MATERIAL=RIGID\n"
               "*SURFACE INTERACTION, NAME=SI\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n"
               "%.10g, %.10g\n*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE\n"
               "SLAVE, MASTER\n",
            1e3 * E, 1e3 * E / a, 3e-5 * E);
}

/* Writes the C3D10 deck of body b (reference positions) with the held nodes of b->fix and node
** i moved by uz[i] along z where load[i]; runs ccx in dir and returns the summed z reaction of
** the loaded nodes (NAN when ccx did not run). */
static double run_ccx(const cf_body *b, const uint8_t *load, const double *uz, const char *dir,
                      const char *job, const double *sph)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s.inp", dir, job);
    FILE *f = fopen(path, "w");
    if (!f)
        return NAN;
    /* with contact the deck's modulus is 1000 MPa, its force scaled back (linear in E, the
    ** penalty taken in proportion): CalculiX's convergence tests use absolute force levels */
    const double Ew = sph ? 1000 : b->E_MPa;
    fprintf(f, "*NODE\n");
    for (size_t i = 0; i < b->nn; i++)
        fprintf(f, "%zu, %.17g, %.17g, %.17g\n", i + 1, b->X[3 * i], b->X[3 * i + 1],
                b->X[3 * i + 2]);
    static const int ends[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    const size_t ne = 6 * b->nt;
    uint64_t *key = malloc(ne * sizeof *key), *sorted = malloc(ne * sizeof *sorted);
    size_t *mid = malloc(ne * sizeof *mid);
    if (!key || !sorted || !mid)
        abort();
    for (size_t t = 0; t < b->nt; t++)
        for (int e = 0; e < 6; e++) {
            uint64_t a = b->tet[4 * t + ends[e][0]], c = b->tet[4 * t + ends[e][1]];
            key[6 * t + e] = a < c ? a << 32 | c : c << 32 | a;
        }
    memcpy(sorted, key, ne * sizeof *key);
    qsort(sorted, ne, sizeof *sorted, cmp_u64);
    size_t nm = 0;
    for (size_t k = 0; k < ne; k++)
        if (k == 0 || sorted[k] != sorted[k - 1])
            sorted[nm++] = sorted[k];
    for (size_t k = 0; k < ne; k++)
        mid[k] = b->nn + 1 + (size_t)((uint64_t *)bsearch(key + k, sorted, nm, sizeof *sorted,
                                                          cmp_u64) - sorted);
    const int quad = !(getenv("STUDY_ELEM") && strcmp(getenv("STUDY_ELEM"), "C3D4") == 0);
    if (!quad)
        nm = 0;
    for (size_t k = 0; k < nm; k++) {
        const size_t a = sorted[k] >> 32, c = sorted[k] & 0xffffffffu;
        fprintf(f, "%zu, %.17g, %.17g, %.17g\n", b->nn + 1 + k, (b->X[3 * a] + b->X[3 * c]) / 2,
                (b->X[3 * a + 1] + b->X[3 * c + 1]) / 2, (b->X[3 * a + 2] + b->X[3 * c + 2]) / 2);
    }
    fprintf(f, "*ELEMENT, TYPE=%s, ELSET=BODY\n", quad ? "C3D10" : "C3D4");
    for (size_t t = 0; t < b->nt; t++) {
        fprintf(f, "%zu, %u, %u, %u, %u", t + 1, b->tet[4 * t] + 1, b->tet[4 * t + 1] + 1,
                b->tet[4 * t + 2] + 1, b->tet[4 * t + 3] + 1);
        for (int e = 0; e < 6 * quad; e++)
            fprintf(f, ",%s %zu", e == 3 ? "\n" : "", mid[6 * t + e]);
        fprintf(f, "\n");
    }
    /* a midpoint takes a component held when both ends hold it; loaded when both are loaded,
    ** by the mean of their displacements */
    for (int a = 0; a < 3; a++) {
        fprintf(f, "*NSET, NSET=FIX%d\n", a + 1);
        int any = 0;
        for (size_t i = 0; i < b->nn; i++)
            if ((b->fix[i] >> a) & 1 && !(a == 2 && load[i]))
                fprintf(f, "%zu\n", i + 1), any = 1;
        for (size_t k = 0; k < nm; k++) {
            const size_t p = sorted[k] >> 32, q = sorted[k] & 0xffffffffu;
            if ((b->fix[p] >> a) & 1 && (b->fix[q] >> a) & 1 && !(a == 2 && load[p] && load[q]))
                fprintf(f, "%zu\n", b->nn + 1 + k), any = 1;
        }
        if (!any)
            abort();
    }
    if (sph)
        write_indenter(f, b, sph[0], sph[1], Ew, b->nn + nm + 1, b->nt + 1);
    fprintf(f, "*NSET, NSET=NTOP%s\n", sph ? "\nIND" : "");
    for (size_t i = 0; i < b->nn; i++)
        if (load[i])
            fprintf(f, "%zu\n", i + 1);
    for (size_t k = 0; k < nm; k++)
        if (load[sorted[k] >> 32] && load[sorted[k] & 0xffffffffu])
            fprintf(f, "%zu\n", b->nn + 1 + k);
    fprintf(f, "*MATERIAL, NAME=TISSUE\n*ELASTIC\n%.17g, %.17g\n"
               "*SOLID SECTION, ELSET=BODY, MATERIAL=TISSUE\n*STEP%s\n*STATIC\n%s*BOUNDARY\n"
               "FIX1, 1, 1\nFIX2, 2, 2\nFIX3, 3, 3\n",
            Ew, b->nu, sph ? ", INC=200" : "", sph ? "1, 1\n" : "");
    if (sph)
        fprintf(f, "IND, 1, 2, 0\nIND, 3, 3, %.12g\n", -sph[1]);
    for (size_t i = 0; i < b->nn; i++)
        if (load[i])
            fprintf(f, "%zu, 3, 3, %.17g\n", i + 1, uz[i]);
    for (size_t k = 0; k < nm; k++) {
        const size_t p = sorted[k] >> 32, q = sorted[k] & 0xffffffffu;
        if (load[p] && load[q])
            fprintf(f, "%zu, 3, 3, %.17g\n", b->nn + 1 + k, (uz[p] + uz[q]) / 2);
    }
    fprintf(f, "*NODE PRINT, NSET=NTOP, TOTALS=ONLY\nRF\n*END STEP\n");
    fclose(f);
    free(key);
    free(sorted);
    free(mid);
    char cmd[2600];
    snprintf(cmd, sizeof cmd, "cd '%s' && OMP_NUM_THREADS=1 ccx -i %s >%s.log 2>&1", dir, job,
             job);
    if (system(cmd) != 0)
        return NAN;
    snprintf(path, sizeof path, "%s/%s.dat", dir, job);
    f = fopen(path, "r");
    if (!f)
        return NAN;
    char line[512];
    double F = NAN;
    int next = 0;
    while (fgets(line, sizeof line, f)) {
        double rx, ry, rz;
        if (next && sscanf(line, " %lg %lg %lg", &rx, &ry, &rz) == 3) {
            F = -rz;
            next = 0;
        }
        if (strstr(line, "total force"))
            next = 1;
    }
    fclose(f);
    return F * b->E_MPa / Ew;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: contact_study sphere|punch NU REFINE [--ccx DIR]\n");
        return 2;
    }
    const int punch = strcmp(argv[1], "punch") == 0;
    const double nu = atof(argv[2]), r = atof(argv[3]);
    const char *ccxdir = argc > 5 && strcmp(argv[4], "--ccx") == 0 ? argv[5] : NULL;
    const char *env;
    /* the block and the probes: a contact radius of about 1 mm in both */
    const double W = (env = getenv("STUDY_W")) ? atof(env) : 30, D = W;
    const double R = punch ? 1 : ((env = getenv("STUDY_R")) ? atof(env) : 40);
    const double d = punch ? 0.01 : ((env = getenv("STUDY_D")) ? atof(env) : 0.025);
    const int steps = (env = getenv("STUDY_STEPS")) ? atoi(env) : 2;
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 70;
    double lo[3] = {0, 0, -D}, hi[3] = {W, W, 0}, focus[3] = {0, 0, 0};
    cf_mesh m;
    /* STUDY_H0, STUDY_GROW, STUDY_HMAX: the element size at the contact point (mm), its growth
    ** (mm per mm) and its largest value (mm), each divided by REFINE; STUDY_W the block's side */
    const double h0 = (env = getenv("STUDY_H0")) ? atof(env) : 0.3;
    const double hg = (env = getenv("STUDY_GROW")) ? atof(env) : 0.4;
    const double hm = (env = getenv("STUDY_HMAX")) ? atof(env) : 8;
    /* STUDY_RIM=1 (punch): graded about the punch's rim instead of its centre */
    const double ring = punch && (env = getenv("STUDY_RIM")) && atoi(env) ? R : 0;
    if (cf_mesh_box_ring(lo, hi, focus, ring, h0 / r, hm / r, hg / r, &m, &err) != CF_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 70;
    }
    cf_body b;
    if (cf_body_create(&b, &m, &law, CF_LAW_CLOSED,
                       cf_body_kappa_for_nu(cf_body_mu_of_law(&law), nu), &err) != CF_OK)
        return 70;
    /* STUDY_MATCH=1: the element term (cf_body_match_elements) */
    if ((env = getenv("STUDY_MATCH")) && atoi(env) && cf_body_match_elements(&b, &err) != CF_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 70;
    }
    /* STUDY_SCALE: every spring's factor times this (the relaxed calibration's experiment) */
    if ((env = getenv("STUDY_SCALE")))
        for (size_t s = 0; s < b.ns; s++)
            b.c[s] *= atof(env);
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        b.fix[i] = (uint8_t)((X[0] < 1e-9) | (X[1] < 1e-9) << 1);
        if (X[2] < -D + 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    }
    cf_probe pr = {0};
    pr.shape = punch ? CF_PROBE_PUNCH : CF_PROBE_SPHERE;
    pr.radius_mm = R;
    pr.dir[2] = -1;
    pr.center_mm[2] = punch ? 0 : R;
    cf_body_step st = {0};
    const double t0 = cpu_s();
    for (int k = 1; k <= steps; k++)
        if (cf_body_solve(&b, &pr, d * k / steps, 0, &st, &err) != CF_OK) {
            fprintf(stderr, "%zu nodes: %s\n", b.nn, err.msg);
            return 70;
        }
    const double cpu = cpu_s() - t0;
    const double Es = b.E_MPa / (1 - b.nu * b.nu);
    const double theory = punch ? 2 * R * d * Es : 4.0 / 3 * Es * sqrt(R) * pow(d, 1.5);
    const double Fc = 4 * st.force_N;
    printf("%s nu %.2f refine %g: %zu nodes, %zu tetrahedra, %d in contact, %d Newton steps, "
           "conifit/theory %.4f, %.2f s CPU",
           punch ? "punch" : "sphere", nu, r, b.nn, b.nt, st.contacts, st.newton_iters,
           Fc / theory, cpu);
    if (ccxdir) {
        /* the nodes in contact at the end, each moved in z onto the probe's surface above its
        ** reference position (a paraboloid for the sphere: small depth) */
        uint8_t *load = calloc(b.nn, 1);
        double *uz = calloc(b.nn, sizeof *uz);
        const double c[3] = {0, 0, pr.center_mm[2] - d};
        for (size_t i = 0; i < b.nn; i++) {
            double nrm[3];
            if (b.fix[i] == CF_BODY_FIX_ALL ||
                !(cf_body_penetration(&pr, c, b.x + 3 * i, nrm, 0) > 0))
                continue;
            const double *X = b.X + 3 * i, q2 = X[0] * X[0] + X[1] * X[1];
            load[i] = 1;
            uz[i] = punch ? -d - X[2] : (c[2] - sqrt(R * R - q2)) - X[2];
        }
        char job[64];
        snprintf(job, sizeof job, "%s_nu%02d_r%g", punch ? "punch" : "sphere",
                 (int)(nu * 100 + 0.5), r);
        const double t1 = cpu_s();
        const double sph[2] = {R, d};
        const int own = !punch && getenv("STUDY_CONTACT") && atoi(getenv("STUDY_CONTACT"));
        if (own)
            memset(load, 0, b.nn);
        const double Fx = 4 * fabs(run_ccx(&b, load, uz, ccxdir, job, own ? sph : NULL));
        struct rusage u;
        getrusage(RUSAGE_CHILDREN, &u);
        const char *el = (env = getenv("STUDY_ELEM")) && strcmp(env, "C3D4") == 0 ? "C3D4"
                         : own                                                ? "C3D10-contact"
                                                                              : "C3D10";
        printf(", %s/theory %.4f, conifit/%s %.4f (ccx %.1f s CPU)", el, Fx / theory, el, Fc / Fx,
               (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec + (cpu_s() - t1));
        free(load);
        free(uz);
    }
    printf("\n");
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    return 0;
}
