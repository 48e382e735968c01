/*
** Bodies from closed surfaces (cf_mesh_from_surface; scene key body.element_size_mm): a cube's
** surface as binary and ASCII STL, either orientation, fills with tetrahedra of its exact volume;
** the shared liver surface (../shared/meshes/liver-smooth.obj, skipped when absent; it crosses
** itself in one small fold, which is smoothed away and reported) fills within a few percent of
** its enclosed volume, closer as the element size falls, with edges of about the size asked for,
** and its body can be probed; an open surface, a Gmsh script, a missing or too small element size
** are refused with exit 65 naming the file or key.
*/
#include "testutil.h"

#include <sys/stat.h>

#include "model/body.h"
#include "io/mesh.h"

TU_SCRATCH_GROUP("cli-surface")

#define SPRING "\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, " \
               "\"G_MPa\": 80000, \"H_mm\": 40}}"

#define LIVER "../shared/meshes/liver-smooth.obj"

/* The 12 outward triangles of the cube [0, 10]^3 (corners numbered by their bits x, y, z). */
static const int cube_tri[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5},
                                    {0, 5, 4}, {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2},
                                    {1, 3, 7}, {1, 7, 5}};

static void corner(int c, float x[3])
{
    for (int a = 0; a < 3; a++)
        x[a] = (c >> a) & 1 ? 10.0f : 0.0f;
}

/* The cube's surface as STL: binary or ASCII, outward or inward, with `drop` triangles left out. */
static void write_cube_stl(const char *path, int binary, int inward, int drop)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    const int n = 12 - drop;
    if (binary) {
        unsigned char head[84] = {0};
        memcpy(head, "cube", 4);
        head[80] = (unsigned char)n;
        fwrite(head, 1, 84, f);
    } else {
        fprintf(f, "solid cube\n");
    }
    for (int t = 0; t < n; t++) {
        int c[3] = {cube_tri[t][0], inward ? cube_tri[t][2] : cube_tri[t][1],
                    inward ? cube_tri[t][1] : cube_tri[t][2]};
        float x[3];
        if (binary) {
            float rec[12] = {0};
            for (int k = 0; k < 3; k++) {
                corner(c[k], x);
                memcpy(rec + 3 + 3 * k, x, sizeof x);
            }
            unsigned char b[50] = {0};
            memcpy(b, rec, 48); /* little-endian floats on x86-64, as STL's */
            fwrite(b, 1, 50, f);
        } else {
            fprintf(f, " facet normal 0 0 0\n  outer loop\n");
            for (int k = 0; k < 3; k++) {
                corner(c[k], x);
                fprintf(f, "   vertex %g %g %g\n", x[0], x[1], x[2]);
            }
            fprintf(f, "  endloop\n endfacet\n");
        }
    }
    if (!binary)
        fprintf(f, "endsolid cube\n");
    fclose(f);
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
              u[2] * (v[0] * w[1] - v[1] * w[0])) /
             6;
    }
    return V;
}

static void a_cube_surface_fills_with_its_volume(void **state)
{
    (void)state;
    for (int k = 0; k < 3; k++) { /* binary outward, ASCII outward, binary inward */
        char path[600];
        snprintf(path, sizeof path, "%s/cube%d.stl", dir, k);
        write_cube_stl(path, k != 1, k == 2, 0);
        cf_mesh m;
        cf_mesh_surface_info info;
        cf_error err = {0};
        if (cf_mesh_from_surface(path, 1, 2, NULL, &m, &info, &err) != CF_OK)
            fail_msg("%s", err.msg);
        const double V = mesh_volume(&m);
        print_message("cube surface %d: %zu vertices, %zu triangles, reversed %d; %zu nodes, %zu "
                      "tetrahedra, volume %.9g mm^3\n",
                      k, info.vertices, info.triangles, info.reversed, m.nn, m.nt, V);
        assert_int_equal(info.vertices, 8);
        assert_int_equal(info.triangles, 12);
        assert_int_equal(info.reversed, k == 2);
        assert_int_equal(info.crossings, 0);
        assert_close(info.enclosed_mm3, 1000, 1e-9);
        assert_close(V, 1000, 1e-6);
        assert_true(m.nt > 200); /* edges of 2 mm in a 10 mm cube: hundreds of tetrahedra */
        cf_mesh_free(&m);
    }
}

/* The volume the OBJ's triangles enclose, read independently of the library. */
static double obj_volume(const char *path)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    static double X[3 * 20000];
    size_t nv = 0;
    double V = 0;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            assert_true(nv < 20000);
            assert_int_equal(sscanf(line + 2, "%lf %lf %lf", &X[3 * nv], &X[3 * nv + 1],
                                    &X[3 * nv + 2]),
                             3);
            nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            long i[3];
            char *p = line + 2;
            for (int k = 0; k < 3; k++) {
                i[k] = strtol(p, &p, 10) - 1;
                while (*p && *p != ' ')
                    p++;
            }
            const double *a = X + 3 * i[0], *b = X + 3 * i[1], *c = X + 3 * i[2];
            V += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0])) /
                 6;
        }
    }
    fclose(f);
    return V;
}

static void the_liver_surface_fills_near_its_volume(void **state)
{
    (void)state;
    struct stat sb;
    if (stat(LIVER, &sb) != 0)
        skip(); /* the shared meshes are absent */
    const double V0 = fabs(obj_volume(LIVER)) * 1000; /* centimetres */
    const double sizes[2] = {6, 3};
    double ratio[2];
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    for (int k = 0; k < 2; k++) {
        cf_mesh m;
        cf_mesh_surface_info info;
        cf_error err = {0};
        if (cf_mesh_from_surface(LIVER, 10, sizes[k], NULL, &m, &info, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_body b;
        assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err), CF_OK);
        ratio[k] = mesh_volume(&m) / V0;
        print_message("liver surface at %g mm: %zu nodes, %zu tetrahedra, mean edge %.3g mm; "
                      "volume %.6g of the surface's %.6g mm^3 (%.4f); %zu crossing edges, %zu "
                      "vertices smoothed by at most %.3g mm\n",
                      sizes[k], m.nn, m.nt, b.mean_edge_mm, mesh_volume(&m), V0, ratio[k],
                      info.crossings, info.smoothed, info.max_move_mm);
        /* the file's own fold (6 edges through other triangles near (-21, 40, -10) mm) is
        ** smoothed by less than a millimetre, which changes the enclosed volume by far less
        ** than the fill's error */
        assert_true(info.crossings > 0 && info.max_move_mm < 1);
        assert_close(info.enclosed_mm3 / V0, 1, 1e-3);
        assert_close(ratio[k], 1, 0.05);
        assert_close(b.mean_edge_mm / sizes[k], 1, 0.3);
        cf_body_free(&b);
        cf_mesh_free(&m);
    }
    assert_true(fabs(ratio[1] - 1) < fabs(ratio[0] - 1)); /* finer is closer */
    cf_law_free(&law);
}

static void the_liver_surface_body_can_be_probed(void **state)
{
    (void)state;
    struct stat sb;
    if (stat(LIVER, &sb) != 0)
        skip();
    char scene[600], csv[600], out[8192], err[8192];
    snprintf(scene, sizeof scene, "%s/liver.json", dir);
    snprintf(csv, sizeof csv, "%s/liver.csv", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    /* a sphere above the surface's highest vertex (-24.66, 15.72, 27.38) mm, held at y <= 10 */
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"" LIVER "\", \"unit_mm\": 10, "
               "\"element_size_mm\": 5, \"poisson_ratio\": 0.45},\n"
               " \"fixed\": {\"below\": {\"axis\": \"y\", \"value_mm\": 10}},\n"
               " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 5, \"center_mm\": [-24.66, "
               "15.72, 32.5], \"direction\": [0, 0, -1], \"depth_mm\": 3, \"steps\": 4}}\n");
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv), 0);
    assert_non_null(strstr(out, "surface: 2194 vertices, 4384 triangles"));
    FILE *c = fopen(csv, "r");
    assert_non_null(c);
    char line[256];
    assert_non_null(fgets(line, sizeof line, c));
    assert_string_equal(line, "depth_mm,force_N\n");
    double d, F, prev = -1;
    int n = 0;
    while (fgets(line, sizeof line, c)) {
        assert_int_equal(sscanf(line, "%lf,%lf", &d, &F), 2);
        assert_true(F > prev || (n == 0 && F == 0));
        prev = F;
        n++;
    }
    fclose(c);
    print_message("liver from its surface (5 mm): sphere force %.6g N at %g mm\n", F, d);
    assert_int_equal(n, 5);
    assert_true(F > 0);
}

static void bad_surfaces_are_refused(void **state)
{
    (void)state;
    char open_stl[600], scene[600], csv[600], out[8192], err[8192], geo[600];
    snprintf(open_stl, sizeof open_stl, "%s/open.stl", dir);
    snprintf(geo, sizeof geo, "%s/shape.geo", dir);
    write_cube_stl(open_stl, 1, 0, 1);
    FILE *g = fopen(geo, "w");
    assert_non_null(g);
    fprintf(g, "Box(1) = {0, 0, 0, 1, 1, 1};\n");
    fclose(g);
    char cube[600];
    snprintf(cube, sizeof cube, "%s/cube0.stl", dir);
    write_cube_stl(cube, 1, 0, 0);
    snprintf(scene, sizeof scene, "%s/bad.json", dir);
    snprintf(csv, sizeof csv, "%s/bad.csv", dir);
    const struct {
        const char *mesh, *extra, *must;
    } cases[] = {
        {open_stl, ", \"element_size_mm\": 2", "not a closed"},
        {geo, "", "a Gmsh script is a program"},
        {cube, "", "missing key 'body.element_size_mm'"},
        {cube, ", \"element_size_mm\": 0.01", "over 5e6"},
        {cube, ", \"element_size_mm\": 2, \"refine\": 1", "'body.refine' goes with a volume mesh"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fprintf(f, "{" SPRING ", \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1%s}, \"fixed\": "
                   "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}}, \"probe\": {\"shape\": "
                   "\"sphere\", \"radius_mm\": 1, \"center_mm\": [5, 5, 12], \"direction\": [0, 0, "
                   "-1], \"depth_mm\": 0.5}}\n",
                cases[k].mesh, cases[k].extra);
        fclose(f);
        int rc = tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s", scene, csv);
        if (rc != 65 || !strstr(err, cases[k].must))
            fail_msg("case %zu: exit %d, expected 65 with \"%s\"; stderr: %s", k, rc,
                     cases[k].must, err);
        struct stat sb;
        assert_true(stat(csv, &sb) != 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_cube_surface_fills_with_its_volume),
        cmocka_unit_test(the_liver_surface_fills_near_its_volume),
        cmocka_unit_test(the_liver_surface_body_can_be_probed),
        cmocka_unit_test(bad_surfaces_are_refused),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
