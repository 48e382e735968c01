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

#endif
