/*
** What the tests of tissue bodies share: a block mesh written as a Gmsh file, and a spring.
*/
#ifndef CF_TESTS_BODYUTIL_H
#define CF_TESTS_BODYUTIL_H

#include <stdio.h>

#include "model/body.h"
#include "io/mesh.h"
#include "testutil.h"

#define SPRING "\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, " \
               "\"G_MPa\": 80000, \"H_mm\": 40}}"

/* Mesh m as a Gmsh 2.2 file at path (tetrahedra, node numbers from 1); m is freed. */
static inline void write_msh(const char *path, cf_mesh *m)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", m->nn);
    for (size_t i = 0; i < m->nn; i++)
        fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, m->X[3 * i], m->X[3 * i + 1],
                m->X[3 * i + 2]);
    fprintf(f, "$EndNodes\n$Elements\n%zu\n", m->nt);
    for (size_t t = 0; t < m->nt; t++)
        fprintf(f, "%zu 4 2 0 1 %u %u %u %u\n", t + 1, m->tet[4 * t] + 1, m->tet[4 * t + 1] + 1,
                m->tet[4 * t + 2] + 1, m->tet[4 * t + 3] + 1);
    fprintf(f, "$EndElements\n");
    fclose(f);
    cf_mesh_free(m);
}

/* The block of 6 x 6 x 3 cells over 30 x 30 x 15 mm (the block generator's) into m. */
static inline void make_block(cf_mesh *m)
{
    double xs[7], zs[4];
    for (int i = 0; i <= 6; i++)
        xs[i] = 5.0 * i;
    for (int i = 0; i <= 3; i++)
        zs[i] = 5.0 * i;
    assert_int_equal(cf_mesh_block(m, xs, 6, xs, 6, zs, 3, NULL), CF_OK);
}

/* That block as a Gmsh 2.2 file. */
static inline void write_block(const char *path)
{
    cf_mesh m;
    make_block(&m);
    write_msh(path, &m);
}

/* The 10 mm cube meshed by Gmsh (Delaunay, element size h), as a Gmsh 2.2 file. */
static inline void write_cube(const char *path, double h)
{
    double lo[3] = {0, 0, 0}, hi[3] = {10, 10, 10}, f[3] = {5, 5, 5};
    cf_mesh m;
    cf_error err = {0};
    if (cf_mesh_box(lo, hi, f, h, h, 0, &m, &err) != CF_OK)
        fail_msg("%s", err.msg);
    write_msh(path, &m);
}

/* Runs ccx on dir/job.inp (dir and job plain names the test made) and reads the probe force of
** every step (minus the z total of the face nodes' reaction, set NFACE) into F[0 .. n); returns
** how many steps it found. */
static inline int bu_ccx_forces(const char *dir, const char *job, double *F, int n)
{
    char cmd[1600], dat[700];
    snprintf(cmd, sizeof cmd, "cd %s && ccx -i %s > %s.log 2>&1", dir, job, job);
    if (system(cmd) != 0)
        fail_msg("ccx failed on %s/%s.inp", dir, job);
    snprintf(dat, sizeof dat, "%s/%s.dat", dir, job);
    char *text = tu_slurp(dat);
    assert_non_null(text);
    int found = 0;
    for (const char *p = text; (p = strstr(p, "total force (fx,fy,fz) for set NFACE and time")); p++) {
        double t, fx, fy, fz;
        if (sscanf(p, "total force (fx,fy,fz) for set NFACE and time %lf %lf %lf %lf", &t, &fx,
                   &fy, &fz) != 4)
            continue;
        const int k = (int)floor(t + 0.5);
        if (fabs(t - k) > 1e-9 || k < 1 || k > n)
            continue;
        F[k - 1] = -fz;
        found++;
    }
    free(text);
    return found;
}

/* Exports fit with the body scene (conifit export FIT --lattice SCENE --format calculix) to
** dir/job.inp, checks that the deck's header states simulate's force F[1 .. steps] at every step
** (1e-9) and, when ccx is installed, that ccx's probe force is within rel_tol of it; label names
** the case in the printed lines. dir and job are plain names the test made. */
static inline void bu_export_matches_simulate(const char *dir, const char *fit, const char *scene,
                                              const char *job, const double *F, int steps,
                                              const char *label, double rel_tol)
{
    char inp[700], out[8192], err[8192];
    snprintf(inp, sizeof inp, "%s/%s.inp", dir, job);
    if (tu_run(out, sizeof out, err, sizeof err, "export %s --lattice %s --format calculix -o %s",
               fit, scene, inp) != 0)
        fail_msg("export: %s", err);
    char *deck = tu_slurp(inp);
    assert_non_null(deck);
    assert_non_null(strstr(deck, "extension spring"));
    /* conifit's forces in the deck's header are simulate's */
    int n = 0;
    for (const char *q = deck; n < steps && (q = strstr(q, "conifit reaction ")); q++) {
        double ref;
        if (sscanf(q, "conifit reaction %lf", &ref) == 1) {
            assert_true(fabs(ref - F[n + 1]) <= 1e-9 * fabs(F[n + 1]));
            n++;
        }
    }
    free(deck);
    assert_int_equal(n, steps);
    if (system("command -v ccx >/dev/null 2>&1") != 0) {
        print_message("ccx not installed: the deck is checked, not run\n");
        return;
    }
    double *G = calloc((size_t)steps, sizeof *G);
    assert_non_null(G);
    if (bu_ccx_forces(dir, job, G, steps) != steps)
        fail_msg("ccx: not every step in %s.dat", job);
    for (int k = 1; k <= steps; k++) {
        print_message("%s export, step %d: ccx %.7g N, conifit simulate %.7g N (%+.2e)\n", label, k,
                      G[k - 1], F[k], G[k - 1] / F[k] - 1);
        if (!(fabs(G[k - 1] - F[k]) <= rel_tol * F[k]))
            fail_msg("step %d: ccx %.7g N, conifit %.7g N: beyond %g", k, G[k - 1], F[k], rel_tol);
    }
    free(G);
}

#endif
