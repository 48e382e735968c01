/*
** Tests of the spring network (model/net.h): the cubic lattice's generator against the lattice
** (cf_lattice_create's arrays, cf_lattice_cell_nodes) and against what a lattice of cells must hold
** (counts, the order of the springs by their first node, rest lengths equal to the distances of the
** end nodes, each family's total weight), and the tetrahedral mesh's generator against the body
** (cf_body_create's arrays) and against its mesh (every edge once, sorted, its calibration scaled
** to the law's shear modulus), on a generated block and on the liver when ../shared is present.
*/
#include "testutil.h"

#include <math.h>

#include "model/body.h"
#include "model/calibration.h"
#include "model/cell.h"
#include "model/lattice.h"
#include "io/mesh.h"
#include "model/lattice_cells.h"
#include "model/net.h"

/* The spring of the tests: a telescoping cone. */
static cf_law test_law(void)
{
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, NULL), CF_OK);
    return law;
}

/* The net of cfg matches the lattice cf_lattice_create builds of it and the lattice's geometry. */
static void check_lattice(const cf_lattice_config *cfg)
{
    cf_law law = test_law();
    const double H = law.p.H_mm;
    cf_net n;
    cf_lattice lat;
    cf_error err = {0};
    assert_int_equal(cf_net_lattice(&n, cfg, H, &err), CF_OK);
    assert_int_equal(cf_lattice_create(&lat, &law, CF_LAW_CLOSED, cfg, &err), CF_OK);
    const size_t nx = (size_t)cfg->nx, ny = (size_t)cfg->ny, nz = (size_t)cfg->nz;
    assert_int_equal(n.nn, (nx + 1) * (ny + 1) * (nz + 1));
    assert_int_equal(n.nn, lat.nn);
    assert_int_equal(n.ns, lat.ns);
    assert_int_equal(n.cell_kind, CF_NET_HEX8);
    assert_int_equal(cf_net_cell_size(n.cell_kind), 8);
    assert_string_equal(cf_net_cell_name(n.cell_kind), "hex8");
    assert_int_equal(n.nc, nx * ny * nz);
    double nodes, springs; /* the count the budgets take, without making the net */
    cf_net_lattice_size(cfg, &nodes, &springs);
    assert_true(nodes == (double)n.nn && springs == (double)n.ns);
    /* springs per family: a cell direction with offsets o has prod (n_a + 1 - |o_a|) springs */
    size_t expect[CF_FAMILY_COUNT] = {0}, count[CF_FAMILY_COUNT] = {0};
    double wsum[CF_FAMILY_COUNT] = {0};
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int o[3], fam;
        cf_cell_direction(d, o, &fam);
        if (cfg->weight[fam] != 0)
            expect[fam] += (nx + 1 - (size_t)abs(o[0])) * (ny + 1 - (size_t)abs(o[1])) *
                           (nz + 1 - (size_t)abs(o[2]));
    }
    for (size_t p = 0; p < n.nn; p++) {
        assert_true(n.X[3 * p] == lat.X[p] && n.X[3 * p + 1] == lat.Y[p] &&
                    n.X[3 * p + 2] == lat.Z[p]);
        assert_int_equal(n.fix[p], lat.fix[p]);
        /* the bottom face is held along z, and nothing above it is held */
        assert_int_equal((n.fix[p] & CF_FIX_Z) != 0, n.X[3 * p + 2] == 0.0);
        if (cfg->bottom == CF_BOTTOM_CLAMPED)
            assert_int_equal(n.fix[p], n.X[3 * p + 2] == 0.0 ? CF_FIX_X | CF_FIX_Y | CF_FIX_Z : 0);
    }
    size_t prev_first = 0;
    for (size_t s = 0; s < n.ns; s++) {
        assert_int_equal(n.si[s], lat.si[s]);
        assert_int_equal(n.sj[s], lat.sj[s]);
        assert_true(n.L0_mm[s] == lat.L0_mm[s] && n.w[s] == lat.w[s]);
        assert_int_equal(n.family[s], lat.family[s]);
        assert_true(n.si[s] < n.sj[s]);
        const double *a = n.X + 3 * n.si[s], *b = n.X + 3 * n.sj[s];
        const double L = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
                              (b[2] - a[2]) * (b[2] - a[2]));
        assert_close(n.L0_mm[s], L, 1e-12 * H);
        assert_close(n.L0_mm[s], H * sqrt(n.family[s] + 1.0), 1e-12 * H);
        assert_close(lat.a[s], H / n.L0_mm[s], 1e-15);
        count[n.family[s]]++;
        wsum[n.family[s]] += n.w[s];
        /* the springs run by the node they start from (the end from which the other is one
        ** of the cell's directions), whose index never decreases */
        int o[3];
        for (int k = 0; k < 3; k++)
            o[k] = (int)lround((b[k] - a[k]) / H);
        size_t first = n.sj[s];
        for (int d = 0; d < CF_CELL_DIRS; d++) {
            int od[3], fam;
            cf_cell_direction(d, od, &fam);
            if (od[0] == o[0] && od[1] == o[1] && od[2] == o[2])
                first = n.si[s];
        }
        assert_true(first >= prev_first);
        prev_first = first;
    }
    /* each cell holds 3 edges', 6 face diagonals' and 4 body diagonals' worth of springs */
    const double per_cell[CF_FAMILY_COUNT] = {3, 6, 4};
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        assert_int_equal(count[f], expect[f]);
        assert_close(wsum[f], per_cell[f] * cfg->weight[f] * (double)n.nc,
                            1e-12 * per_cell[f] * (double)n.nc);
    }
    /* the cells: the lattice's corner order, and each a cube of edge H */
    for (size_t c = 0; c < n.nc; c++) {
        uint32_t node[8];
        cf_lattice_cell_nodes(&lat, c, node);
        for (int a = 0; a < 8; a++) {
            assert_int_equal(n.cell[8 * c + a], node[a]);
            const double *x0 = n.X + 3 * n.cell[8 * c], *xa = n.X + 3 * n.cell[8 * c + a];
            assert_close(xa[0] - x0[0], H * (a & 1), 1e-12 * H);
            assert_close(xa[1] - x0[1], H * ((a >> 1) & 1), 1e-12 * H);
            assert_close(xa[2] - x0[2], H * ((a >> 2) & 1), 1e-12 * H);
        }
    }
    cf_lattice_free(&lat);
    cf_net_free(&n);
    cf_law_free(&law);
}

static void the_lattice_generator_gives_the_lattice(void **state)
{
    (void)state;
    cf_lattice_config cfg = cf_lattice_default();
    check_lattice(&cfg); /* 3 x 3 x 3, isotropic, sliding bottom */
    cfg.nx = 4, cfg.ny = 2, cfg.nz = 5;
    cfg.bottom = CF_BOTTOM_CLAMPED;
    check_lattice(&cfg);
    cfg.weight[CF_FAMILY_FACE] = 0; /* a family of weight 0 has no springs */
    cfg.weight[CF_FAMILY_BODY] = 0.3;
    cfg.nx = 1;
    check_lattice(&cfg);
}

static void a_bad_lattice_is_refused_naming_the_field(void **state)
{
    (void)state;
    cf_lattice_config cfg = cf_lattice_default();
    cfg.ny = 0;
    cf_net n;
    cf_error err = {0};
    assert_int_equal(cf_net_lattice(&n, &cfg, 10, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "lattice.ny = 0"));
    cfg.ny = 3;
    assert_int_equal(cf_net_lattice(&n, &cfg, -1, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "-1 mm"));
    cf_net_free(&n); /* safe on the zeroed net a refusal leaves */
}

/* The net of mesh m matches the body cf_body_create builds of it, every edge of the mesh once. */
static void check_mesh(const cf_mesh *m)
{
    cf_law law = test_law();
    cf_net n;
    cf_body b;
    cf_error err = {0};
    assert_int_equal(cf_net_mesh(&n, m, &law, &err), CF_OK);
    assert_int_equal(cf_body_create(&b, m, &law, CF_LAW_CLOSED, 0.0, &err), CF_OK);
    assert_int_equal(n.nn, m->nn);
    assert_int_equal(n.nn, b.nn);
    assert_int_equal(n.ns, b.ns);
    assert_int_equal(n.nc, m->nt);
    assert_int_equal(n.cell_kind, CF_NET_TET4);
    assert_int_equal(cf_net_cell_size(n.cell_kind), 4);
    assert_string_equal(cf_net_cell_name(n.cell_kind), "tet4");
    assert_null(n.family);
    assert_memory_equal(n.X, m->X, 3 * m->nn * sizeof *n.X);
    assert_memory_equal(n.X, b.X, 3 * m->nn * sizeof *n.X);
    assert_memory_equal(n.cell, m->tet, 4 * m->nt * sizeof *n.cell);
    for (size_t i = 0; i < n.nn; i++)
        assert_int_equal(n.fix[i], 0);
    /* the springs: sorted by their ends, each an edge of the mesh, rest length its length */
    double trace = 0;
    for (size_t s = 0; s < n.ns; s++) {
        assert_int_equal(n.si[s], b.si[s]);
        assert_int_equal(n.sj[s], b.sj[s]);
        assert_true(n.L0_mm[s] == b.L0[s] && n.w[s] == b.c[s]);
        assert_true(n.si[s] < n.sj[s]);
        if (s > 0)
            assert_true(n.si[s - 1] < n.si[s] || (n.si[s - 1] == n.si[s] && n.sj[s - 1] < n.sj[s]));
        const double *p = n.X + 3 * n.si[s], *q = n.X + 3 * n.sj[s];
        const double L = sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                              (q[2] - p[2]) * (q[2] - p[2]));
        assert_close(n.L0_mm[s], L, 1e-12 * L);
        assert_true(n.w[s] >= 0);
        /* k = w k0 H / L0: the network's tensor trace sum k L0^2 */
        trace += n.w[s] * law.k0_N_per_mm * law.p.H_mm / n.L0_mm[s] * n.L0_mm[s] * n.L0_mm[s];
    }
    /* every edge of every tetrahedron is a spring (found by bisection in the sorted list), and
    ** the tetrahedra's volume */
    static const int edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    double V = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tet + 4 * t;
        for (int e = 0; e < 6; e++) {
            uint32_t i = v[edge[e][0]], j = v[edge[e][1]];
            if (i > j) {
                uint32_t k = i;
                i = j, j = k;
            }
            size_t lo = 0, hi = n.ns;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (n.si[mid] < i || (n.si[mid] == i && n.sj[mid] < j))
                    lo = mid + 1;
                else
                    hi = mid;
            }
            assert_true(lo < n.ns && n.si[lo] == i && n.sj[lo] == j);
        }
        V += b.V0[t];
    }
    /* the isotropic part of the network's tensor has the law's shear modulus */
    assert_close(trace / (15 * V), cf_body_mu_of_law(&law), 1e-10 * cf_body_mu_of_law(&law));
    /* the body's view is the net */
    const cf_net view = cf_net_of_body(&b);
    assert_true(view.nn == n.nn && view.ns == n.ns && view.nc == n.nc);
    assert_true(view.X == b.X && view.w == b.c && view.cell == b.tet && view.fix == b.fix);
    cf_body_free(&b);
    cf_net_free(&n);
    cf_law_free(&law);
}

static void the_mesh_generator_gives_the_body_of_a_block(void **state)
{
    (void)state;
    double g[5] = {0, 2, 5, 6, 10};
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, g, 4, g, 3, g, 2, NULL), CF_OK);
    check_mesh(&m);
    cf_mesh_free(&m);
}

static void the_mesh_generator_gives_the_body_of_the_liver(void **state)
{
    (void)state;
    FILE *f = fopen("../shared/meshes/liver2.msh", "r");
    if (!f)
        skip(); /* ../shared/meshes absent: nothing to read */
    fclose(f);
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_read("../shared/meshes/liver2.msh", 100, &m, &err), CF_OK);
    check_mesh(&m);
    cf_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_lattice_generator_gives_the_lattice),
        cmocka_unit_test(a_bad_lattice_is_refused_naming_the_field),
        cmocka_unit_test(the_mesh_generator_gives_the_body_of_a_block),
        cmocka_unit_test(the_mesh_generator_gives_the_body_of_the_liver),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
