/*
** Gmsh bounded and isolated (io/isolate.h, cf_mesh_limits): a closed tetrahedron's surface fills
** (Gmsh's classification of its four triangles never ended: the test runs it in a process it kills
** after 120 s); Gmsh past its time limit is stopped with an error, and a caller ended by SIGTERM
** takes Gmsh's process with it; the search for a surface's crossings is near-linear in its
** triangles (a 40,000-triangle cylinder of long triangles, counted in edge-triangle tests) and comes
** after the cheap size check; a refinement and a fill over --max-memory are refused before Gmsh
** starts; a solid within a solid (two nested shells facing outward) is refused, a cavity filled;
** two nodes of a mesh file at one point are refused naming both, a node defined twice naming its
** lines.
*/
#include "testutil.h"

#include <errno.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "model/body.h"
#include "io/mesh.h"
#include "io/surface.h"

TU_SCRATCH_GROUP("mesh-guard")

#define SPRING "\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, " \
               "\"G_MPa\": 80000, \"H_mm\": 40}}"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double mesh_volume(const cf_mesh *m)
{
    double V = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const double *a = m->X + 3 * m->tet[4 * t], *b = m->X + 3 * m->tet[4 * t + 1],
                     *c = m->X + 3 * m->tet[4 * t + 2], *d = m->X + 3 * m->tet[4 * t + 3];
        double u[3], v[3], w[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
            w[k] = d[k] - a[k];
        }
        V += (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
              u[2] * (v[0] * w[1] - v[1] * w[0])) / 6;
    }
    return V;
}

/* The cube [lo, hi]^3 as OBJ vertices from number `base` + 1 and its six faces (as quads), facing
** outward or inward. */
static void obj_cube(FILE *f, double lo, double hi, int base, int inward)
{
    for (int c = 0; c < 8; c++)
        fprintf(f, "v %g %g %g\n", c & 1 ? hi : lo, c & 2 ? hi : lo, c & 4 ? hi : lo);
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int k = 0; k < 6; k++) {
        int v[4];
        for (int j = 0; j < 4; j++)
            v[j] = base + 1 + q[k][inward ? 3 - j : j];
        fprintf(f, "f %d %d %d %d\n", v[0], v[1], v[2], v[3]);
    }
}

static void write_cube(const char *path, double hi)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    obj_cube(f, 0, hi, 0, 0);
    fclose(f);
}

/* Runs the fill of `path` at size h in a child process that this test kills after `limit` s;
** returns the child's exit status (0: filled with the volume V0 within 1e-6), or -1 when it had to
** be killed. */
static int fill_in_child(const char *path, double h, double V0, double limit)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cf_mesh m;
        cf_error err = {0};
        cf_status st = cf_mesh_from_surface(path, 1, h, NULL, &m, NULL, &err);
        if (st != CF_OK) {
            fprintf(stderr, "%s\n", err.msg);
            _exit(1);
        }
        const double V = mesh_volume(&m);
        fprintf(stderr, "%s at %g mm: %zu tetrahedra, volume %.9g mm^3\n", path, h, m.nt, V);
        _exit(fabs(V - V0) <= 1e-6 * V0 && m.nt >= 4 ? 0 : 2);
    }
    const double end = now_s() + limit;
    int ws = 0;
    while (waitpid(pid, &ws, WNOHANG) == 0) {
        if (now_s() > end) {
            kill(pid, SIGKILL);
            waitpid(pid, &ws, 0);
            return -1;
        }
        usleep(20000);
    }
    return WIFEXITED(ws) ? WEXITSTATUS(ws) : 100 + WTERMSIG(ws);
}

static void a_tetrahedron_surface_fills(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/tet.obj", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    fclose(f);
    const double sizes[2] = {2.5, 20};
    for (int k = 0; k < 2; k++)
        assert_int_equal(fill_in_child(path, sizes[k], 1000.0 / 6, 120), 0);
}

static void gmsh_past_its_time_is_stopped(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/cube.obj", dir);
    write_cube(path, 10);
    cf_mesh_limits lim = cf_mesh_limits_default();
    lim.max_seconds = 1;
    cf_mesh m;
    cf_error err = {0};
    const double t0 = now_s();
    /* about 180,000 tetrahedra: some 25 s of Gmsh */
    assert_int_equal(cf_mesh_from_surface(path, 1, 0.3, &lim, &m, NULL, &err), CF_E_DATA);
    const double took = now_s() - t0;
    print_message("stopped after %.2f s: %s\n", took, err.msg);
    assert_non_null(strstr(err.msg, "did not finish within 1 s"));
    assert_true(took < 20); /* a bound on the stop, not a speed target */
}

/* The children of process pid (Linux: /proc/PID/task/PID/children), the first into *child. */
static int first_child(pid_t pid, pid_t *child)
{
    char p[64];
    snprintf(p, sizeof p, "/proc/%d/task/%d/children", (int)pid, (int)pid);
    FILE *f = fopen(p, "r");
    int c = 0, ok = f && fscanf(f, "%d", &c) == 1;
    if (f)
        fclose(f);
    *child = (pid_t)c;
    return ok;
}

/* 1 while process pid runs (not ended, not a zombie). */
static int running(pid_t pid)
{
    char p[64], st = 'X';
    snprintf(p, sizeof p, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(p, "r");
    if (!f)
        return 0;
    int ok = fscanf(f, "%*d (%*[^)]) %c", &st) == 1;
    fclose(f);
    return ok && st != 'Z' && st != 'X';
}

static void a_terminated_caller_takes_gmsh_with_it(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/cube-term.obj", dir);
    write_cube(path, 10);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cf_mesh m;
        cf_mesh_from_surface(path, 1, 0.3, NULL, &m, NULL, NULL);
        _exit(0);
    }
    pid_t gmsh = 0;
    const double end = now_s() + 30;
    while (!first_child(pid, &gmsh) && now_s() < end)
        usleep(20000);
    assert_true(gmsh > 0); /* Gmsh runs in a process of its own */
    usleep(300000);
    kill(pid, SIGTERM);
    int ws = 0;
    waitpid(pid, &ws, 0);
    assert_true(WIFSIGNALED(ws) && WTERMSIG(ws) == SIGTERM);
    const double gone = now_s() + 10;
    while (running(gmsh) && now_s() < gone)
        usleep(20000);
    assert_false(running(gmsh));
}

/* A cylinder along x (length 100 mm, radius 5 mm) of n long side triangles around and two caps of
** n thin triangles each, as binary STL: 4 n triangles in all. */
static void write_cylinder(const char *path, int n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    unsigned char head[84] = {0};
    const uint32_t nt = 4 * (uint32_t)n;
    memcpy(head + 80, &nt, 4);
    fwrite(head, 1, 84, f);
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < n; k++) {
        const double a0 = 2 * pi * k / n, a1 = 2 * pi * ((k + 1) % n) / n;
        const float y0 = (float)(5 * cos(a0)), z0 = (float)(5 * sin(a0)), y1 = (float)(5 * cos(a1)),
                    z1 = (float)(5 * sin(a1));
        const float tri[4][9] = {{0, y0, z0, 100, y0, z0, 100, y1, z1},
                                 {0, y0, z0, 100, y1, z1, 0, y1, z1},
                                 {0, 0, 0, 0, y0, z0, 0, y1, z1},
                                 {100, 0, 0, 100, y1, z1, 100, y0, z0}};
        for (int t = 0; t < 4; t++) {
            unsigned char rec[50] = {0};
            memcpy(rec + 12, tri[t], 36);
            fwrite(rec, 1, 50, f);
        }
    }
    fclose(f);
}

static void crossings_are_sought_in_near_linear_work(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/cylinder.stl", dir);
    write_cylinder(path, 10000);
    cf_surface s;
    cf_mesh_surface_info info;
    cf_error err = {0};
    assert_int_equal(cf_surface_read(path, &s, &err), CF_OK);
    assert_int_equal(s.nf, 40000);
    if (cf_surface_prepare(&s, path, 1, 2, &info, &err) != CF_OK)
        fail_msg("%s", err.msg);
    print_message("cylinder of %zu triangles: %zu edge-triangle tests, %zu crossings, %zu "
                  "shells\n", info.triangles, info.pair_tests, info.crossings, info.shells);
    assert_int_equal(info.crossings, 0);
    assert_int_equal(info.shells, 1);
    assert_true(info.pair_tests > 0);
    /* a sweep along the axis tests every edge against every side triangle: 1e9 */
    assert_true(info.pair_tests < 50 * info.triangles);
    cf_surface_free(&s);
    /* at 0.05 mm the fill is refused before any crossing is sought */
    assert_int_equal(cf_surface_read(path, &s, &err), CF_OK);
    assert_int_equal(cf_surface_prepare(&s, path, 1, 0.05, &info, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "over 5e6"));
    assert_int_equal(info.pair_tests, 0);
    cf_surface_free(&s);
}

/* The block [0, 10]^3 in n^3 cells of six tetrahedra as a Gmsh 2.2 ASCII mesh. */
static void write_block_msh(const char *path, int n)
{
    double g[64];
    for (int i = 0; i <= n; i++)
        g[i] = 10.0 * i / n;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_block(&m, g, n, g, n, g, n, &err), CF_OK);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", m.nn);
    for (size_t i = 0; i < m.nn; i++)
        fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, m.X[3 * i], m.X[3 * i + 1], m.X[3 * i + 2]);
    fprintf(f, "$EndNodes\n$Elements\n%zu\n", m.nt);
    for (size_t t = 0; t < m.nt; t++)
        fprintf(f, "%zu 4 2 0 1 %u %u %u %u\n", t + 1, m.tet[4 * t] + 1, m.tet[4 * t + 1] + 1,
                m.tet[4 * t + 2] + 1, m.tet[4 * t + 3] + 1);
    fprintf(f, "$EndElements\n");
    fclose(f);
    cf_mesh_free(&m);
}

/* `conifit simulate` of a probed body on `mesh` with the body's extra keys; its exit status, its
** stderr in err. */
static int simulate_body(const char *mesh, const char *extra, const char *opts, char *err,
                         size_t cap)
{
    char scene[600], csv[600], out[4096];
    snprintf(scene, sizeof scene, "%s/body.json", dir);
    snprintf(csv, sizeof csv, "%s/body.csv", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{" SPRING ", \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1%s}, \"fixed\": "
               "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"probe\": {\"shape\": "
               "\"sphere\", \"radius_mm\": 1, \"center_mm\": [5, 5, 12], \"direction\": [0, 0, "
               "-1], \"depth_mm\": 0.5}}\n", mesh, extra);
    fclose(f);
    unlink(csv);
    int rc = tu_run(out, sizeof out, err, cap, "simulate %s -o %s %s", scene, csv, opts);
    struct stat sb;
    if (rc != 0)
        assert_true(stat(csv, &sb) != 0);
    return rc;
}

static void meshes_over_the_memory_limit_are_refused_before_gmsh(void **state)
{
    (void)state;
    char msh[600], cube[600], err[8192];
    snprintf(msh, sizeof msh, "%s/block.msh", dir);
    write_block_msh(msh, 4); /* 384 tetrahedra: refined 4 times, 1.6e6 */
    int rc = simulate_body(msh, ", \"refine\": 4", "--max-memory 300M", err, sizeof err);
    print_message("refine 4: exit %d: %s", rc, err);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(err, "refining its 384 tetrahedra 4 times"));
    assert_non_null(strstr(err, "refused before meshing"));
    assert_non_null(strstr(err, "--max-memory"));
    snprintf(cube, sizeof cube, "%s/cube-small.obj", dir);
    write_cube(cube, 10);
    rc = simulate_body(cube, ", \"element_size_mm\": 0.4", "--max-memory 1G", err, sizeof err);
    print_message("fill at 0.4 mm: exit %d: %s", rc, err);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(err, "filling it at an element size of 0.4 mm"));
    assert_non_null(strstr(err, "refused before meshing"));
    /* the same block unrefined runs */
    assert_int_equal(simulate_body(msh, "", "", err, sizeof err), 0);
}

static void a_solid_within_a_solid_is_refused(void **state)
{
    (void)state;
    char nested[600], hollow[600], err[8192];
    snprintf(nested, sizeof nested, "%s/nested.obj", dir);
    snprintf(hollow, sizeof hollow, "%s/hollow.obj", dir);
    for (int inward = 0; inward < 2; inward++) {
        FILE *f = fopen(inward ? hollow : nested, "w");
        assert_non_null(f);
        obj_cube(f, 0, 10, 0, 0);
        obj_cube(f, 3, 7, 8, inward);
        fclose(f);
    }
    int rc = simulate_body(nested, ", \"element_size_mm\": 2", "", err, sizeof err);
    print_message("nested outward shells: exit %d: %s", rc, err);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(err, "a solid within a solid"));
    assert_non_null(strstr(err, "vertex 9"));
    /* a cavity (its shell facing into it) is filled around */
    cf_mesh m;
    cf_mesh_surface_info info;
    cf_error e = {0};
    if (cf_mesh_from_surface(hollow, 1, 2, NULL, &m, &info, &e) != CF_OK)
        fail_msg("%s", e.msg);
    assert_int_equal(info.shells, 2);
    assert_close(mesh_volume(&m), 1000 - 64, 1e-6);
    cf_mesh_free(&m);
}

static void coincident_nodes_of_a_mesh_file_are_refused(void **state)
{
    (void)state;
    char path[600];
    snprintf(path, sizeof path, "%s/crack.msh", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
               "4 0 0 1\n5 0 0 0\n6 1 0 0\n7 0 1 0\n8 0 0 -1\n$EndNodes\n$Elements\n2\n"
               "1 4 2 0 1 1 2 3 4\n2 4 2 0 1 5 7 6 8\n$EndElements\n");
    fclose(f);
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_read(path, 1, &m, &err), CF_E_DATA);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "crack.msh: nodes 1 and 5 are at the same point"));
    /* a node defined twice (Gmsh keeps the last), in a version 2 and a version 4.1 file */
    snprintf(path, sizeof path, "%s/twice.msh", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
               "4 0 0 1\n4 0 0 2\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n");
    fclose(f);
    assert_int_equal(cf_mesh_read(path, 1, &m, &err), CF_E_DATA);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "twice.msh:10: node 4 is defined a second time (first at "
                                    "line 9)"));
    snprintf(path, sizeof path, "%s/twice4.msh", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n2 5 1 4\n3 1 0 4\n1\n2\n3\n4\n"
               "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 1 0 1\n4\n0 0 2\n$EndNodes\n$Elements\n"
               "1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n");
    fclose(f);
    assert_int_equal(cf_mesh_read(path, 1, &m, &err), CF_E_DATA);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "twice4.msh:16: node 4 is defined a second time"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_tetrahedron_surface_fills),
        cmocka_unit_test(gmsh_past_its_time_is_stopped),
        cmocka_unit_test(a_terminated_caller_takes_gmsh_with_it),
        cmocka_unit_test(crossings_are_sought_in_near_linear_work),
        cmocka_unit_test(meshes_over_the_memory_limit_are_refused_before_gmsh),
        cmocka_unit_test(a_solid_within_a_solid_is_refused),
        cmocka_unit_test(coincident_nodes_of_a_mesh_file_are_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
