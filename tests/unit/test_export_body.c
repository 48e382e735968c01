/*
** The export of a tissue body to FEBio 4 (cf_export_write_body, format febio), read back with
** libxml2 as FEBio reads it: the sections in FEBio's order, every node at its coordinates, every
** tetrahedron of the mesh as a positively oriented tet4 of the purely volumetric material
** (Mooney-Rivlin c1 = c2 = 0, k = kappa, pressure_model 2: U(J) = (k/2)(J - 1)^2), every edge a
** nonlinear spring whose curve is the law times the edge's factor at its rest length (at the
** points and between them, as FEBio interpolates), the held nodes, and the punch as the prescribed
** z displacement of the nodes under its face at every step. FEBio itself is not run here.
*/
#include "testutil.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

#include "model/body.h"
#include "export/export.h"
#include "model/law_internal.h"

static const cf_spring TEL = {10, 30, 4, 1, 80000, 40}; /* telescoping, s = 39 mm */

/* The element children of n, in order (at most cap). */
static size_t children(xmlNodePtr n, xmlNodePtr *out, size_t cap)
{
    size_t k = 0;
    for (xmlNodePtr c = n->children; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && k < cap)
            out[k++] = c;
    return k;
}

/* The first element child of n named name, or NULL. */
static xmlNodePtr child(xmlNodePtr n, const char *name)
{
    for (xmlNodePtr c = n ? n->children : NULL; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && !strcmp((const char *)c->name, name))
            return c;
    return NULL;
}

/* The first element child of n named name whose attribute attr is value, or NULL. */
static xmlNodePtr child_with(xmlNodePtr n, const char *name, const char *attr, const char *value)
{
    for (xmlNodePtr c = n ? n->children : NULL; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE || strcmp((const char *)c->name, name))
            continue;
        xmlChar *v = xmlGetProp(c, (const xmlChar *)attr);
        const int hit = v && !strcmp((const char *)v, value);
        xmlFree(v);
        if (hit)
            return c;
    }
    return NULL;
}

/* The text of n (caller frees with xmlFree). */
static char *text(xmlNodePtr n)
{
    return (char *)xmlNodeGetContent(n);
}

static double number(xmlNodePtr n)
{
    assert_non_null(n);
    char *t = text(n);
    double v;
    assert_int_equal(sscanf(t, "%lf", &v), 1);
    xmlFree(t);
    return v;
}

static int attr_is(xmlNodePtr n, const char *attr, const char *value)
{
    xmlChar *v = xmlGetProp(n, (const xmlChar *)attr);
    const int hit = v && !strcmp((const char *)v, value);
    xmlFree(v);
    return hit;
}

/* The positions and contact sets of block_body's two steps (27 nodes). */
static double xs[2 * 3 * 27];
static uint8_t contact[2 * 27];

/* A 2 x 2 x 2 block of cells over 40 mm (27 nodes, 48 tetrahedra) of TEL's material at nu, held
** at its bottom, and a flat punch of radius 25 mm on the top's centre pressed 1 mm in 2 steps,
** solved as simulate solves it: the depths and forces of the steps. */
static void block_body(cf_law *law, cf_mesh *m, cf_body *b, cf_probe *pr, double nu,
                       double depth[2], double force[2])
{
    cf_error err = {0};
    assert_int_equal(cf_law_init(law, &TEL, &err), CF_OK);
    double g[3] = {0, 20, 40};
    assert_int_equal(cf_mesh_block(m, g, 2, g, 2, g, 2, &err), CF_OK);
    const double mu = cf_body_mu_of_law(law);
    const double kappa = nu > 0.25 ? cf_body_kappa_for_nu(mu, nu) : 0;
    assert_int_equal(cf_body_create(b, m, law, CF_LAW_CLOSED, kappa, &err), CF_OK);
    for (size_t i = 0; i < b->nn; i++)
        if (b->X[3 * i + 2] < 1e-9)
            b->fix[i] = CF_BODY_FIX_ALL;
    *pr = (cf_probe){CF_PROBE_PUNCH, 25, {20, 20, 40}, {0, 0, -1}, 1, 2};
    for (int k = 0; k < 2; k++) {
        cf_body_step st;
        depth[k] = 0.5 * (k + 1);
        if (cf_body_solve(b, pr, depth[k], 0, &st, &err) != CF_OK)
            fail_msg("%s", err.msg);
        force[k] = st.force_N;
        assert_true(force[k] > 0);
        assert_int_equal(b->nn, 27);
        memcpy(xs + 3 * 27 * k, b->x, sizeof xs / 2);
        assert_true(cf_body_contact_set(b, contact + 27 * k) > 0);
    }
}

/* The body's FEBio model as text (caller frees). */
static char *febio_of(const cf_body *b, const cf_probe *pr, const double *depth,
                      const double *force, double tol, cf_export_report *rep)
{
    char *x = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&x, &len);
    assert_non_null(mem);
    cf_export_options opt = cf_export_default_options();
    opt.format = CF_EXPORT_FEBIO;
    opt.tol = tol;
    cf_error err = {0};
    const cf_export_body_run run = {2, depth, force, xs, contact};
    if (cf_export_write_body(mem, b, pr, &run, &opt, rep, &err) != CF_OK)
        fail_msg("%s", err.msg);
    fclose(mem);
    return x;
}

static void a_body_for_febio_holds_its_mesh_springs_volume_and_punch(void **state)
{
    (void)state;
    cf_law law;
    cf_mesh m;
    cf_body b;
    cf_probe pr;
    double depth[2], force[2];
    block_body(&law, &m, &b, &pr, 0.45, depth, force);
    const double tol = 1e-3; /* as the lattice's FEBio test */
    cf_export_report rep;
    char *x = febio_of(&b, &pr, depth, force, tol, &rep);
    assert_int_equal(rep.groups, b.ns);
    assert_int_equal(rep.nodes, b.nn);
    xmlDocPtr doc = xmlReadMemory(x, (int)strlen(x), "body.feb", NULL, XML_PARSE_NONET);
    if (!doc)
        fail_msg("the FEBio model is not well-formed XML");
    xmlNodePtr root = xmlDocGetRootElement(doc);
    assert_string_equal((const char *)root->name, "febio_spec");
    assert_true(attr_is(root, "version", "4.0"));
    /* FEBio 4 reads the material before MeshDomains names it, and builds the mesh there */
    const char *order[] = {"Module", "Control", "Material", "Mesh", "MeshDomains",
                           "Boundary", "Discrete", "LoadData", "Output"};
    xmlNodePtr sec[16];
    assert_int_equal(children(root, sec, 16), 9);
    for (int k = 0; k < 9; k++)
        assert_string_equal((const char *)sec[k]->name, order[k]);
    /* the material: purely volumetric, U(J) = (k/2)(J - 1)^2 with k = kappa */
    xmlNodePtr mat = child(sec[2], "material");
    assert_non_null(mat);
    assert_true(attr_is(mat, "type", "Mooney-Rivlin") && attr_is(mat, "name", "volume"));
    assert_true(number(child(mat, "c1")) == 0 && number(child(mat, "c2")) == 0);
    assert_true(number(child(mat, "k")) == b.kappa_MPa);
    assert_true(b.kappa_MPa > 0);
    assert_true(number(child(mat, "pressure_model")) == 2);
    /* the nodes, exactly */
    xmlNodePtr mesh = sec[3], nodes = child(mesh, "Nodes"), nl[64];
    assert_int_equal(children(nodes, nl, 64), b.nn);
    double *X = malloc(3 * b.nn * sizeof *X);
    assert_non_null(X);
    for (size_t i = 0; i < b.nn; i++) {
        char id[32];
        snprintf(id, sizeof id, "%zu", i + 1);
        assert_true(attr_is(nl[i], "id", id));
        char *t = text(nl[i]);
        assert_int_equal(sscanf(t, "%lf,%lf,%lf", &X[3 * i], &X[3 * i + 1], &X[3 * i + 2]), 3);
        xmlFree(t);
        for (int a = 0; a < 3; a++)
            assert_true(X[3 * i + a] == b.X[3 * i + a]);
    }
    /* the tetrahedra, each the mesh's, positively oriented (FEBio's tet4 refuses a negative
    ** Jacobian) */
    xmlNodePtr els = child_with(mesh, "Elements", "type", "tet4"), el[128];
    assert_non_null(els);
    assert_true(attr_is(els, "name", "volume"));
    assert_int_equal(children(els, el, 128), b.nt);
    for (size_t t = 0; t < b.nt; t++) {
        char *s = text(el[t]);
        unsigned n[4];
        assert_int_equal(sscanf(s, "%u,%u,%u,%u", &n[0], &n[1], &n[2], &n[3]), 4);
        xmlFree(s);
        double e[3][3];
        for (int a = 0; a < 4; a++)
            assert_int_equal(n[a], b.tet[4 * t + (size_t)a] + 1);
        for (int a = 1; a < 4; a++)
            for (int c = 0; c < 3; c++)
                e[a - 1][c] = X[3 * (n[a] - 1) + (size_t)c] - X[3 * (n[0] - 1) + (size_t)c];
        const double vol = (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                            e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                            e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6;
        assert_close(vol, b.V0[t], 1e-9 * b.V0[t]);
        assert_true(vol > 0);
    }
    xmlNodePtr dom = child(sec[4], "SolidDomain");
    assert_non_null(dom);
    assert_true(attr_is(dom, "name", "volume") && attr_is(dom, "mat", "volume"));
    /* J per node as conifit takes it: FEBio's node-averaged tetrahedron without its element-wise
    ** stabilisation */
    assert_true(attr_is(dom, "elem_type", "ut4"));
    assert_true(number(child(dom, "alpha")) == 0);
    /* the held nodes: all of the bottom, in all three directions */
    xmlNodePtr held = child_with(mesh, "NodeSet", "name", "fix_xyz");
    assert_non_null(held);
    char *hs = text(held);
    size_t nheld = 0;
    for (const char *p = hs; *p;) {
        char *end;
        const unsigned long id = strtoul(p, &end, 10);
        assert_true(end > p && id >= 1 && id <= b.nn);
        assert_int_equal(b.fix[id - 1], CF_BODY_FIX_ALL);
        nheld++;
        p = *end == ',' ? end + 1 : end;
    }
    xmlFree(hs);
    assert_int_equal(nheld, 9);
    xmlNodePtr zero = child_with(sec[5], "bc", "node_set", "fix_xyz");
    assert_true(zero && attr_is(zero, "type", "zero displacement"));
    /* the punch: conifit's contact set, the 5 nodes its face rests on, each moved along z as
    ** conifit solved it at each step (its own load curve) */
    xmlNodePtr top = child_with(mesh, "NodeSet", "name", "top");
    assert_non_null(top);
    char *ts = text(top);
    size_t ntop = 0;
    for (const char *p = ts; *p;) {
        char *end;
        const unsigned long id = strtoul(p, &end, 10);
        assert_true(end > p && id >= 1 && id <= b.nn);
        const double *P = b.X + 3 * (id - 1);
        assert_true(P[2] == 40 && hypot(P[0] - 20, P[1] - 20) < 25);
        char set[32];
        snprintf(set, sizeof set, "p%lu", id);
        xmlNodePtr bc = child_with(sec[5], "bc", "node_set", set);
        assert_true(bc && attr_is(bc, "type", "prescribed displacement"));
        char *d = text(child(bc, "dof"));
        assert_string_equal(d, "z");
        xmlFree(d);
        char *lcid = (char *)xmlGetProp(child(bc, "value"), (const xmlChar *)"lc");
        assert_non_null(lcid);
        xmlNodePtr c = child_with(sec[7], "load_controller", "id", lcid);
        xmlFree(lcid);
        assert_non_null(c);
        xmlNodePtr q[4];
        assert_int_equal(children(child(c, "points"), q, 4), 3);
        for (int k = 1; k < 3; k++) {
            char *qs = text(q[k]);
            double t, z;
            assert_int_equal(sscanf(qs, "%lf,%lf", &t, &z), 2);
            xmlFree(qs);
            assert_true(t == k && z == xs[3 * 27 * (k - 1) + 3 * (id - 1) + 2] - P[2]);
            assert_true(z < 0 && z > -depth[k - 1] - 1e-3);
        }
        ntop++;
        p = *end == ',' ? end + 1 : end;
    }
    xmlFree(ts);
    assert_int_equal(ntop, 5);
    assert_null(child_with(sec[5], "bc", "node_set", "top")); /* no longer one drive for all */
    xmlNodePtr lc = child(child(sec[7], "load_controller"), "points"), pts[8];
    assert_int_equal(children(lc, pts, 8), 3);
    for (int k = 0; k < 3; k++) {
        char *s = text(pts[k]);
        double t, z;
        assert_int_equal(sscanf(s, "%lf,%lf", &t, &z), 2);
        xmlFree(s);
        assert_true(t == k && z == (k ? -depth[k - 1] : 0));
    }
    /* conifit's force at each step in the header */
    for (int k = 0; k < 2; k++) {
        char want[96];
        snprintf(want, sizeof want, "conifit reaction %.17g N", force[k]);
        assert_non_null(strstr(x, want));
    }
    /* every edge: its own discrete set and curve, the law times its factor at its rest length,
    ** at the points and halfway between them (FEBio interpolates LINEAR) */
    const double H = TEL.H_mm;
    double worst = 0;
    size_t checked = 0;
    for (size_t s = 0; s < b.ns; s++) {
        char name[32], pair[48];
        snprintf(name, sizeof name, "G%zu", s + 1);
        xmlNodePtr set = child_with(mesh, "DiscreteSet", "name", name), de[4];
        assert_non_null(set);
        assert_int_equal(children(set, de, 4), 1);
        char *d = text(de[0]);
        snprintf(pair, sizeof pair, "%u,%u", b.si[s] + 1, b.sj[s] + 1);
        assert_string_equal(d, pair);
        xmlFree(d);
        xmlNodePtr dm = child_with(sec[6], "discrete_material", "name", name);
        assert_true(dm && attr_is(dm, "type", "nonlinear spring"));
        char *meas = text(child(dm, "measure"));
        assert_string_equal(meas, "elongation");
        xmlFree(meas);
        xmlNodePtr curve = child(child(dm, "force"), "points"), cp[512];
        const size_t n = children(curve, cp, 512);
        assert_true(n > 10 && n < 512);
        double e[512], T[512];
        for (size_t i = 0; i < n; i++) {
            char *t = text(cp[i]);
            assert_int_equal(sscanf(t, "%lf,%lf", &e[i], &T[i]), 2);
            xmlFree(t);
            if (i)
                assert_true(e[i] > e[i - 1]);
        }
        const double L0 = b.L0[s], c = b.c[s];
        /* the table's whole range, from near solid in compression to full stretch */
        assert_true(-e[0] * H / L0 > 0.99 * law.travel_mm);
        assert_close(-e[0] * H / L0, rep.u_hi_mm, 1e-9 * law.travel_mm);
        assert_close(-e[n - 1] * H / L0, rep.u_lo_mm, 1e-9 * law.travel_mm);
        assert_true(rep.u_lo_mm < 0);
        for (size_t i = 0; i < n; i++)
            for (int h = 0; h < (i + 1 < n ? 2 : 1); h++) {
                const double at = h ? 0.5 * (e[i] + e[i + 1]) : e[i];
                const double Tf = h ? 0.5 * (T[i] + T[i + 1]) : T[i];
                const double want = -c * cf_law_force(&law, CF_LAW_EXACT, -at * H / L0, NULL, NULL);
                const double off = fabs(Tf - want) / (c * law.F_C_N);
                worst = fmax(worst, off);
                if (!(off <= 1.01 * tol))
                    fail_msg("spring %zu: %g N at elongation %g mm, the law %g N", s + 1, Tf, at,
                             want);
                checked++;
            }
        char dis[32];
        snprintf(dis, sizeof dis, "%zu", s + 1);
        assert_non_null(child_with(sec[6], "discrete", "dmat", dis));
    }
    print_message("body for FEBio: %zu nodes, %zu springs, %zu tet4, kappa %.6g MPa; curves "
                  "within %.3g of c F_C at %zu points and midpoints\n",
                  b.nn, b.ns, b.nt, b.kappa_MPa, worst, checked);
    assert_true(worst > 1e-7); /* the comparison sees the tables, not a copy of the law */
    assert_non_null(child(child(sec[8], "logfile"), "node_data"));
    free(X);
    xmlFreeDoc(doc);
    free(x);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

/* At nu = 1/4 the body has no volume term: no material, no solid elements, an empty MeshDomains
** (FEBio 4 still needs it to build the mesh); a sphere probe is refused naming the probe. */
static void a_body_without_volume_term_writes_springs_only_and_a_sphere_is_refused(void **state)
{
    (void)state;
    cf_law law;
    cf_mesh m;
    cf_body b;
    cf_probe pr;
    double depth[2], force[2];
    block_body(&law, &m, &b, &pr, 0.25, depth, force);
    assert_true(b.kappa_MPa == 0);
    cf_export_report rep;
    char *x = febio_of(&b, &pr, depth, force, 1e-4, &rep);
    xmlDocPtr doc = xmlReadMemory(x, (int)strlen(x), "body.feb", NULL, XML_PARSE_NONET);
    assert_non_null(doc);
    xmlNodePtr root = xmlDocGetRootElement(doc);
    assert_null(child(root, "Material"));
    assert_null(child(child(root, "Mesh"), "Elements"));
    xmlNodePtr md = child(root, "MeshDomains");
    assert_non_null(md);
    assert_null(md->children);
    assert_non_null(child_with(child(root, "Mesh"), "DiscreteSet", "name", "G1"));
    xmlFreeDoc(doc);
    free(x);
    pr.shape = CF_PROBE_SPHERE;
    cf_export_options opt = cf_export_default_options();
    opt.format = CF_EXPORT_FEBIO;
    cf_error err = {0};
    FILE *null = fopen("/dev/null", "w");
    assert_non_null(null);
    const cf_export_body_run run = {2, depth, force, xs, contact};
    assert_int_equal(cf_export_write_body(null, &b, &pr, &run, &opt, &rep, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "probe"));
    /* a run whose probe touches nothing has no contact to carry: refused, saying so */
    pr.shape = CF_PROBE_PUNCH;
    static const uint8_t none[2 * 27];
    const cf_export_body_run untouched = {2, depth, force, xs, none};
    assert_int_equal(cf_export_write_body(null, &b, &pr, &untouched, &opt, &rep, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "touches no node"));
    fclose(null);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

int main(void)
{
    xmlInitParser();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_body_for_febio_holds_its_mesh_springs_volume_and_punch),
        cmocka_unit_test(a_body_without_volume_term_writes_springs_only_and_a_sphere_is_refused),
    };
    const int rc = cmocka_run_group_tests(tests, NULL, NULL);
    xmlCleanupParser();
    return rc;
}
