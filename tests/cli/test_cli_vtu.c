/*
** The fields of `conifit simulate --vtu DIR`, read back from the files with libxml2: a Gmsh cube
** on rollers compressed 0.1 % at its top (free to expand sideways) holds, averaged over its
** tetrahedra, sigma_zz = E eps_zz within 1 % (E the body's calibrated Young's modulus, from the
** summary; eps_zz the tetrahedra's Green-Lagrange strain), no lateral stress, and the support
** force over the area; a sphere pressed into a block: the contact forces and the supports'
** reactions balance, the probe's force of the file's field data is the CSV's, every spring has a
** force, and the PVD's times are the load factor (the depth in each file's field data).
*/
#include "bodyutil.h"
#include "testutil.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

TU_SCRATCH_GROUP("cli-vtu")

/* The element child of n named name, or NULL. */
static xmlNodePtr child(xmlNodePtr n, const char *name)
{
    for (xmlNodePtr c = n ? n->children : NULL; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && strcmp((const char *)c->name, name) == 0)
            return c;
    return NULL;
}

/* The numbers of the DataArray named name (NULL: the first) under section (PointData, CellData,
** Points, Cells, FieldData) of the file's piece (of the grid for FieldData), as a new array of
** *n numbers; fails the test when it is missing or holds anything but numbers. */
static double *read_array(xmlDocPtr doc, const char *section, const char *name, size_t *n)
{
    xmlNodePtr grid = child(xmlDocGetRootElement(doc), "UnstructuredGrid");
    xmlNodePtr sec = strcmp(section, "FieldData") == 0 ? child(grid, section)
                                                        : child(child(grid, "Piece"), section);
    if (!sec)
        fail_msg("no %s", section);
    for (xmlNodePtr c = sec->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE)
            continue;
        xmlChar *nm = xmlGetProp(c, (const xmlChar *)"Name");
        const int match = !name || (nm && strcmp((const char *)nm, name) == 0);
        xmlFree(nm);
        if (!match)
            continue;
        xmlChar *text = xmlNodeGetContent(c);
        size_t cap = 1024, k = 0;
        double *v = malloc(cap * sizeof *v);
        assert_non_null(v);
        const char *p = (const char *)text;
        for (;;) {
            char *e;
            const double x = strtod(p, &e);
            if (e == p)
                break;
            assert_true(isfinite(x));
            if (k == cap) {
                cap *= 2;
                v = realloc(v, cap * sizeof *v);
                assert_non_null(v);
            }
            v[k++] = x;
            p = e;
        }
        while (*p == ' ' || *p == '\n')
            p++;
        assert_int_equal(*p, 0); /* numbers only */
        xmlFree(text);
        *n = k;
        return v;
    }
    fail_msg("no %s %s", section, name ? name : "");
    return NULL;
}

static xmlDocPtr parse(const char *path)
{
    xmlDocPtr doc = xmlReadFile(path, NULL, XML_PARSE_NONET);
    if (!doc)
        fail_msg("libxml2 cannot parse %s", path);
    return doc;
}

/* Six times the volume of the tetrahedron of points a, b, c, d. */
static double vol6(const double *a, const double *b, const double *c, const double *d)
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/* The summary's "body: E = X kPa". */
static double summary_E_kPa(const char *out)
{
    const char *s = strstr(out, "body: E = ");
    double E = 0;
    if (!s || sscanf(s, "body: E = %lf kPa", &E) != 1)
        fail_msg("no E in: %s", out);
    return E;
}

/* The bottom on rollers (z held), x and y of the corner at the origin and y of the corner at
** x = 10 held: the cube is free to expand sideways. */
#define ROLLERS                                                                                    \
    "{\"below\": {\"axis\": \"z\", \"value_mm\": 0}, \"by_mm\": [null, null, 0]},\n"             \
    "{\"box\": {\"min_mm\": [0, 0, 0], \"max_mm\": [0, 0, 0]}, \"by_mm\": [0, 0, null]},\n"      \
    "{\"box\": {\"min_mm\": [10, 0, 0], \"max_mm\": [10, 0, 0]}, \"by_mm\": [null, 0, null]}"

static void a_compressed_cube_holds_sigma_equal_E_eps(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], vtu[600], out[8192], err[8192], path[700];
    snprintf(mesh, sizeof mesh, "%s/cube.msh", dir);
    snprintf(scene, sizeof scene, "%s/cube.json", dir);
    snprintf(csv, sizeof csv, "%s/cube.csv", dir);
    snprintf(vtu, sizeof vtu, "%s/cube", dir);
    write_cube(mesh, 1);
    const double eps = -1e-3;
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"steps\": 2, "
            "\"poisson_ratio\": 0.25},\n \"displaced\": [" ROLLERS ",\n"
            "  {\"above\": {\"axis\": \"z\", \"value_mm\": 10}, \"by_mm\": [null, null, %g]}]}\n",
            mesh, eps * 10);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s --vtu %s", scene, csv, vtu))
        fail_msg("%s", err);
    const double E = summary_E_kPa(out);
    snprintf(path, sizeof path, "%s/body_0002.vtu", vtu);
    xmlDocPtr doc = parse(path);
    size_t np, nc, ns, ne, nr, nt;
    double *X = read_array(doc, "Points", NULL, &np);
    double *conn = read_array(doc, "Cells", "connectivity", &nc);
    double *sig = read_array(doc, "CellData", "stress_kPa", &ns);
    double *gl = read_array(doc, "CellData", "strain_green_lagrange", &ne);
    double *R = read_array(doc, "PointData", "reaction_N", &nr);
    double *tv = read_array(doc, "FieldData", "TimeValue", &nt);
    assert_int_equal(nc % 4, 0);
    assert_int_equal(ns, 6 * (nc / 4));
    assert_int_equal(ne, ns);
    assert_int_equal(nr, np);
    assert_int_equal(nt, 1);
    assert_close(tv[0], 1, 0); /* the last of the static steps: load factor 1 */
    double V = 0, szz = 0, sxx = 0, syy = 0, ezz = 0, Fz = 0, lo = INFINITY, hi = -INFINITY;
    for (size_t t = 0; t < nc / 4; t++) {
        const double *c = conn + 4 * t;
        const double v = vol6(X + 3 * (size_t)c[0], X + 3 * (size_t)c[1], X + 3 * (size_t)c[2],
                              X + 3 * (size_t)c[3]) / 6;
        assert_true(v > 0);
        V += v;
        szz += v * sig[6 * t + 2];
        sxx += v * sig[6 * t];
        syy += v * sig[6 * t + 1];
        ezz += v * gl[6 * t + 2];
        lo = fmin(lo, sig[6 * t + 2]);
        hi = fmax(hi, sig[6 * t + 2]);
    }
    szz /= V;
    sxx /= V;
    syy /= V;
    ezz /= V;
    for (size_t i = 0; i < np / 3; i++)
        if (X[3 * i + 2] > 10 * (1 + eps) - 1e-6)
            Fz += R[3 * i + 2]; /* the top's supports push it down: negative */
    const double area = V / (10 * (1 + eps)); /* the current cross-section */
    print_message("cube (Gmsh, h 1 mm, nu 0.25) at %g strain: mean sigma_zz %.6g kPa, E eps_zz "
                  "%.6g kPa (ratio %.5f), top's support force over area %.6g kPa, lateral "
                  "%.3g %.3g kPa; single tetrahedra %.4g .. %.4g kPa\n",
                  eps, szz, E * ezz, szz / (E * ezz), Fz / area * 1e3, sxx, syy, lo, hi);
    assert_close(ezz, eps + eps * eps / 2, 1e-3 * fabs(eps)); /* Green-Lagrange of the stretch */
    assert_close(szz / (E * ezz), 1, 0.01);
    assert_close(szz, Fz / area * 1e3, 1e-4 * fabs(szz)); /* the virial of the boundary's forces */
    assert_true(fabs(sxx) < 0.01 * fabs(szz) && fabs(syy) < 0.01 * fabs(szz));
    free(X);
    free(conn);
    free(sig);
    free(gl);
    free(R);
    free(tv);
    xmlFreeDoc(doc);
}

static void the_probe_force_balances_the_reactions(void **state)
{
    (void)state;
    char mesh[600], scene[600], csv[600], vtu[600], out[8192], err[8192], path[700];
    snprintf(mesh, sizeof mesh, "%s/block.msh", dir);
    snprintf(scene, sizeof scene, "%s/probe.json", dir);
    snprintf(csv, sizeof csv, "%s/probe.csv", dir);
    snprintf(vtu, sizeof vtu, "%s/probe", dir);
    write_block(mesh);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f,
            "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": 0.45},\n"
            " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
            " \"probe\": {\"shape\": \"sphere\", \"radius_mm\": 5, \"center_mm\": [15, 15, 20], "
            "\"direction\": [0, 0, -1], \"depth_mm\": 1, \"steps\": 4}}\n",
            mesh);
    fclose(f);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s -o %s --vtu %s", scene, csv, vtu))
        fail_msg("%s", err);
    /* the CSV's last force */
    char *text = tu_slurp(csv);
    assert_non_null(text);
    const char *last = text + strlen(text) - 2;
    while (last > text && *last != '\n')
        last--;
    double d_csv, F_csv;
    assert_int_equal(sscanf(last + 1, "%lf,%lf", &d_csv, &F_csv), 2);
    free(text);
    assert_true(F_csv > 0);
    for (int k = 0; k <= 4; k++) {
        snprintf(path, sizeof path, "%s/body_%04d.vtu", vtu, k);
        xmlDocPtr doc = parse(path);
        size_t n1, n2, n3, n4, n5;
        double *C = read_array(doc, "PointData", "contact_force_N", &n1);
        double *R = read_array(doc, "PointData", "reaction_N", &n2);
        double *Fp = read_array(doc, "FieldData", "probe_force_N", &n3);
        double *dp = read_array(doc, "FieldData", "probe_depth_mm", &n4);
        double *tv = read_array(doc, "FieldData", "TimeValue", &n5);
        assert_int_equal(n1, n2);
        double sc[3] = {0, 0, 0}, sr[3] = {0, 0, 0};
        for (size_t i = 0; i < n1; i++) {
            sc[i % 3] += C[i];
            sr[i % 3] += R[i];
        }
        print_message("step %d (time %g, depth %g mm): probe %.9g N, contact forces [%.3g %.3g "
                      "%.9g] N, reactions [%.3g %.3g %.9g] N\n",
                      k, tv[0], dp[0], Fp[0], sc[0], sc[1], sc[2], sr[0], sr[1], sr[2]);
        assert_close(tv[0], k / 4.0, 1e-15);
        assert_close(dp[0], k / 4.0, 1e-12);
        assert_close(-sc[2], Fp[0], 1e-9 * F_csv);    /* the probe pushes down (-z) */
        for (int a = 0; a < 3; a++)                  /* the supports hold the probe's force */
            assert_close(sc[a] + sr[a], 0, 1e-6 * F_csv);
        if (k == 4)
            assert_close(Fp[0], F_csv, 1e-12 * F_csv);
        free(C);
        free(R);
        free(Fp);
        free(dp);
        free(tv);
        xmlFreeDoc(doc);
    }
    /* the springs: a force for each, some in tension and some in compression */
    snprintf(path, sizeof path, "%s/springs_0004.vtu", vtu);
    xmlDocPtr doc = parse(path);
    size_t nf, nc;
    double *F = read_array(doc, "CellData", "force_N", &nf);
    double *conn = read_array(doc, "Cells", "connectivity", &nc);
    assert_int_equal(2 * nf, nc);
    double fmin_ = INFINITY, fmax_ = -INFINITY;
    for (size_t s = 0; s < nf; s++) {
        fmin_ = fmin(fmin_, F[s]);
        fmax_ = fmax(fmax_, F[s]);
    }
    assert_true(fmin_ < 0 && fmax_ > 0);
    free(F);
    free(conn);
    xmlFreeDoc(doc);
    /* the PVD: the load factor as its time, said in a comment */
    snprintf(path, sizeof path, "%s/body.pvd", vtu);
    text = tu_slurp(path);
    assert_non_null(text);
    assert_non_null(strstr(text, "timestep=\"0.5\" group=\"\" part=\"0\" file=\"body_0002.vtu\""));
    assert_non_null(strstr(text, "<!-- timestep: the load factor"));
    free(text);
    doc = parse(path); /* well-formed */
    xmlFreeDoc(doc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_compressed_cube_holds_sigma_equal_E_eps),
        cmocka_unit_test(the_probe_force_balances_the_reactions),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
