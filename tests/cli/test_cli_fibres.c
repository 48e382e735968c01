/*
** A body scene with fibres (`"fibres"`, src/notes/simulate.md, "Fibres in a body"): the
** left-ventricular slab, a Gmsh block of 20 x 20 x 5 mm whose fibre angle turns from -60 to +60
** degrees through its thickness (z), held at its bottom and pressed by a flat punch:
**  - `conifit simulate --vtu` runs it; the VTU's cell field "fibre_direction", read back with
**    libxml2, is in every tetrahedron the helix rule's direction at its centroid (1e-9), and the
**    summary names the fibres;
**  - the punch's force exceeds that of the same slab without fibres (the fibres carry load);
**  - its CalculiX export (each tetrahedron's fibre an embedded tension-only spring between two
**    auxiliary nodes tied to the corners by *EQUATION) runs in ccx with the punch force at every
**    step within the deck's stated tolerance and 1e-3 relative of simulate's;
**  - a 3 x 3 x 3 lattice with a fibre along z per cell, pulled along z: its CalculiX export (the
**    fibre tied to the cell's 8 nodes with trilinear weights, the top driven through stiff
**    springs) runs in ccx within the deck's tolerance and 1e-3 of simulate at every step;
**  - bad "fibres" keys exit 65 naming the key and the value; FEBio and SOFA exports refuse a body
**    with fibres (65, naming the format) instead of dropping them.
*/
#include "bodyutil.h"
#include "testutil.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

TU_SCRATCH_GROUP("cli-fibres")

#define PI 3.14159265358979323846
#define FIT "fits/series/muscle_compression_relaxation_fiber30.json"

#define FIBRES                                                                                     \
    "\"fibres\": [{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "      \
    "\"reference\": [1, 0, 0]}, \"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, "          \
    "\"n\": 4, \"d_mm\": 1, \"G_MPa\": 80000, \"H_mm\": 30}}, \"density\": %s}],\n"

static xmlNodePtr child(xmlNodePtr n, const char *name)
{
    for (xmlNodePtr c = n ? n->children : NULL; c; c = c->next)
        if (c->type == XML_ELEMENT_NODE && strcmp((const char *)c->name, name) == 0)
            return c;
    return NULL;
}

/* The numbers of DataArray name under the piece's section, *n of them (new array). */
static double *read_array(xmlDocPtr doc, const char *section, const char *name, size_t *n)
{
    xmlNodePtr sec = child(child(child(xmlDocGetRootElement(doc), "UnstructuredGrid"), "Piece"),
                           section);
    for (xmlNodePtr c = sec ? sec->children : NULL; c; c = c->next) {
        xmlChar *nm = c->type == XML_ELEMENT_NODE ? xmlGetProp(c, (const xmlChar *)"Name") : NULL;
        const int match = nm && (!name || strcmp((const char *)nm, name) == 0);
        xmlFree(nm);
        if (!match && !(name == NULL && c->type == XML_ELEMENT_NODE))
            continue;
        xmlChar *text = xmlNodeGetContent(c);
        size_t cap = 4096, k = 0;
        double *v = malloc(cap * sizeof *v);
        assert_non_null(v);
        const char *p = (const char *)text;
        for (;;) {
            char *e;
            const double x = strtod(p, &e);
            if (e == p)
                break;
            assert_true(isfinite(x));
            if (k == cap)
                assert_non_null(v = realloc(v, (cap *= 2) * sizeof *v));
            v[k++] = x;
            p = e;
        }
        xmlFree(text);
        *n = k;
        return v;
    }
    fail_msg("no %s %s", section, name ? name : "");
    return NULL;
}

/* The slab meshed by Gmsh (element size 2.5 mm) and the scene (fibres of density dens, or none
** when dens is NULL) and the matrix spring (a scene's "spring" entry) at dir/name.json; the CSV's
** last force after `simulate`. */
static double run_slab(const char *spring, const char *name, const char *dens, int vtu, char *out,
                       size_t cap)
{
    char mesh[600], scene[600], csv[600], vdir[600], err[8192];
    snprintf(mesh, sizeof mesh, "%s/slab.msh", dir);
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    snprintf(vdir, sizeof vdir, "%s/%s", dir, name);
    FILE *probe = fopen(mesh, "r");
    if (!probe) {
        const double lo[3] = {0, 0, 0}, hi[3] = {20, 20, 5}, f[3] = {10, 10, 5};
        cf_mesh m;
        cf_error e = {0};
        if (cf_mesh_box(lo, hi, f, 2.5, 2.5, 0, &m, &e) != CF_OK)
            fail_msg("%s", e.msg);
        write_msh(mesh, &m);
    } else
        fclose(probe);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{%s,\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1, \"poisson_ratio\": "
               "0.45},\n", spring, mesh);
    if (dens)
        fprintf(f, FIBRES, dens);
    fprintf(f, " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
               " \"probe\": {\"shape\": \"punch\", \"radius_mm\": 4, \"center_mm\": [10, 10, "
               "5.001], \"direction\": [0, 0, -1], \"depth_mm\": 0.501, \"steps\": 3}}\n");
    fclose(f);
    if (tu_run(out, cap, err, sizeof err, "simulate %s -o %s%s%s", scene, csv,
               vtu ? " --vtu " : "", vtu ? vdir : ""))
        fail_msg("%s", err);
    char *text = tu_slurp(csv);
    assert_non_null(text);
    const char *last = text + strlen(text) - 2;
    while (last > text && *last != '\n')
        last--;
    double d, F;
    assert_int_equal(sscanf(last + 1, "%lf,%lf", &d, &F), 2);
    free(text);
    return F;
}

static void the_fibre_slab_runs_and_shows_its_directions(void **state)
{
    (void)state;
    char out[16384], path[700];
    const double F0 = run_slab(SPRING, "plain", NULL, 0, out, sizeof out);
    const double F1 = run_slab(SPRING, "helix", "2", 1, out, sizeof out);
    print_message("punch 0.5 mm into the 20 x 20 x 5 mm slab: %.6g N without fibres, %.6g N with "
                  "the -60..60 degree helix\n", F0, F1);
    assert_true(F0 > 0 && F1 > 1.001 * F0);
    assert_non_null(strstr(out, "fibres 0: helix from -60 to 60 degrees"));
    snprintf(path, sizeof path, "%s/helix/body_0003.vtu", dir);
    xmlDocPtr doc = xmlReadFile(path, NULL, XML_PARSE_NONET);
    if (!doc)
        fail_msg("libxml2 cannot parse %s", path);
    size_t na, np, nc;
    double *a = read_array(doc, "CellData", "fibre_direction", &na);
    double *x = read_array(doc, "Points", NULL, &np);
    double *u = read_array(doc, "PointData", "displacement", &np);
    double *conn = read_array(doc, "Cells", "connectivity", &nc);
    assert_int_equal(na, 3 * (nc / 4));
    assert_true(nc > 400);
    double worst = 0;
    for (size_t t = 0; t < nc / 4; t++) {
        double zc = 0; /* the reference centroid: current position less displacement */
        for (int k = 0; k < 4; k++) {
            const size_t v = (size_t)conn[4 * t + (size_t)k];
            zc += (x[3 * v + 2] - u[3 * v + 2]) / 4;
        }
        const double th = (-60 + 120 * zc / 5) * PI / 180;
        worst = fmax(worst, fabs(a[3 * t] - cos(th)) + fabs(a[3 * t + 1] - sin(th)) +
                                fabs(a[3 * t + 2]));
    }
    print_message("%zu tetrahedra: fibre_direction within %.3g of the helix rule\n", nc / 4, worst);
    assert_true(worst <= 1e-8); /* the file's 10 digits */
    free(a);
    free(x);
    free(u);
    free(conn);
    xmlFreeDoc(doc);
}

/* A scene with FIBRES' entry replaced by entry; `simulate` must exit 65 with msg in its error. */
static void refused(const char *entry, const char *msg)
{
    char scene[600], mesh[600], out[4096], err[4096];
    snprintf(mesh, sizeof mesh, "%s/slab.msh", dir);
    snprintf(scene, sizeof scene, "%s/bad.json", dir);
    FILE *f = fopen(scene, "w");
    assert_non_null(f);
    fprintf(f, "{" SPRING ",\n \"body\": {\"mesh\": \"%s\", \"unit_mm\": 1},\n \"fibres\": [%s],\n"
               " \"fixed\": {\"below\": {\"axis\": \"z\", \"value_mm\": 0}},\n"
               " \"probe\": {\"shape\": \"punch\", \"radius_mm\": 4, \"center_mm\": [10, 10, "
               "5.001], \"direction\": [0, 0, -1], \"depth_mm\": 0.5}}\n", mesh, entry);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate %s -o -", scene), 65);
    if (!strstr(err, msg))
        fail_msg("expected '%s' in: %s", msg, err);
}

#define P_SPRING "\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, " \
                 "\"G_MPa\": 80000, \"H_mm\": 30}}"

static void bad_fibres_are_refused_by_key_and_value(void **state)
{
    (void)state;
    char out[4096];
    run_slab(SPRING, "mesh", NULL, 0, out, sizeof out); /* writes the slab */
    refused("{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [0, 0, 3]}, " P_SPRING "}",
            "key 'fibres[0].helix.reference' = [0, 0, 3]");
    refused("{\"helix\": {\"normal\": [0, 0, 0], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [1, 0, 0]}, " P_SPRING "}",
            "key 'fibres[0].helix.normal' = [0, 0, 0]");
    refused("{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [1, 0, 0]}, " P_SPRING ", \"density\": -1}",
            "fibres[0]");
    refused("{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [1, 0, 0], \"twist\": 1}, " P_SPRING "}",
            "twist");
    refused("{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [1, 0, 0]}}",
            "key 'fibres[0].spring' is required");
    refused("{\"helix\": {\"normal\": [0, 0, 1], \"from_deg\": -60, \"to_deg\": 60, "
            "\"reference\": [1, 0, 0]}, " P_SPRING ", \"recruitment_strain\": 1.5}",
            "key 'fibres[0].recruitment_strain'");
    /* the formats without a form for the fibres refuse rather than dropping them */
    char scene[600], err[4096];
    snprintf(scene, sizeof scene, "%s/helix.json", dir);
    run_slab(SPRING, "helix", "1", 0, out, sizeof out);
    static const char *const formats[] = {"febio", "sofa"};
    for (int k = 0; k < 2; k++) {
        const int st = tu_run(out, sizeof out, err, sizeof err, "export " FIT " --lattice %s "
                              "--format %s -o %s/x.out", scene, formats[k], dir);
        print_message("%s export of the fibre slab: exit %d: %s", formats[k], st, err);
        assert_int_equal(st, 65);
        char want[64];
        snprintf(want, sizeof want, "%s: key 'fibres': the body's fibre groups", formats[k]);
        if (!strstr(err, want))
            fail_msg("expected '%s' in: %s", want, err);
    }
}

/* The simulate forces of dir/name.csv at steps 1 .. n into F[0 .. n). */
static void csv_forces(const char *name, double *F, int n)
{
    char csv[600], line[256];
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    FILE *c = fopen(csv, "r");
    assert_non_null(c);
    int k = -1;
    double d;
    assert_non_null(fgets(line, sizeof line, c)); /* header */
    while (k < n && fgets(line, sizeof line, c)) {
        double f;
        if (sscanf(line, "%lf,%lf", &d, &f) == 2) {
            if (k >= 0)
                F[k] = f;
            k++;
        }
    }
    fclose(c);
    assert_int_equal(k, n);
}

static void the_fibre_slab_runs_in_ccx(void **state)
{
    (void)state;
    char out[16384], err[16384], path[700];
    const char *fit = "\"spring\": {\"fit\": \"" FIT "\"}";
    const double F0 = run_slab(fit, "ccx0", NULL, 0, out, sizeof out);
    run_slab(fit, "ccx", "2, \"recruitment_strain\": 0.002", 0, out, sizeof out);
    double F[3], G[3];
    csv_forces("ccx", F, 3);
    print_message("the fit's slab at 0.5 mm: %.6g N without fibres, %.6g N with them\n", F0, F[2]);
    assert_true(F[2] > 1.05 * F0); /* the fibres carry a share ccx must reproduce */
    if (tu_run(out, sizeof out, err, sizeof err,
               "export " FIT " --lattice %s/ccx.json --format calculix -o %s/ccx.inp", dir, dir))
        fail_msg("export: %s", err);
    snprintf(path, sizeof path, "%s/ccx.inp", dir);
    char *x = tu_slurp(path);
    assert_non_null(x);
    const double tol = tu_deck_tolerance(x);
    assert_non_null(strstr(x, "*ELEMENT, TYPE=SPRINGA, ELSET=F1\n"));
    assert_non_null(strstr(x, "embedded tension-only springs"));
    free(x);
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    if (bu_ccx_forces(dir, "ccx", G, 3) != 3)
        fail_msg("ccx: not every step in ccx.dat");
    for (int k = 0; k < 3; k++) {
        print_message("fibre slab, step %d: ccx %.7g N, conifit simulate %.7g N (%+.2e; tolerance "
                      "%.3g N)\n", k + 1, G[k], F[k], G[k] / F[k] - 1, tol);
        if (!(fabs(G[k] - F[k]) <= tol) || !(fabs(G[k] - F[k]) <= 1e-3 * F[k]))
            fail_msg("step %d: ccx %.7g N, conifit simulate %.7g N: beyond %.3g N or 1e-3", k + 1,
                     G[k], F[k], tol);
    }
}

/* A 3 x 3 x 3 isotropic lattice of the telescoping fit with fibres (density dens, or none when
** dens is NULL) of that spring along z, recruited at strain 0.03, pulled 10 % along z in 5
** steps, at dir/name. */
static void write_lattice(const char *name, const char *dens)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"fit\": \"fits/telescoping.json\"},\n"
               " \"lattice\": {\"nx\": 3, \"ny\": 3, \"nz\": 3, \"calibration\": "
               "\"isotropic\"},\n");
    if (dens)
        fprintf(f, " \"fibres\": [{\"axis\": [0, 0, 1], \"spring\": {\"fit\": "
                   "\"fits/telescoping.json\"}, \"density\": %s, \"recruitment_strain\": "
                   "0.03}],\n", dens);
    fprintf(f, " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": -0.1, \"duration_s\": 1},\n"
               " \"samples_per_segment\": 5}\n");
    fclose(f);
}

/* simulate's top reaction (N, compressive positive: stress times the 30 x 30 mm top) of
** dir/name at its 5 samples after rest into R. */
static void lattice_reactions(const char *name, double R[5])
{
    char out[8192], err[8192], csv[600], line[512];
    snprintf(csv, sizeof csv, "%s/%s.csv", dir, name);
    if (tu_run(out, sizeof out, err, sizeof err, "simulate %s/%s -o %s", dir, name, csv))
        fail_msg("simulate %s: %s", name, err);
    FILE *c = fopen(csv, "r");
    assert_non_null(c);
    int k = -1;
    assert_non_null(fgets(line, sizeof line, c));
    while (k < 5 && fgets(line, sizeof line, c)) {
        double t, e, sk;
        if (sscanf(line, "%lf,%lf,%lf", &t, &e, &sk) == 3) {
            if (k >= 0)
                R[k] = sk * 1e-3 * 900;
            k++;
        }
    }
    fclose(c);
    assert_int_equal(k, 5);
}

static void a_lattice_fibre_runs_in_ccx(void **state)
{
    (void)state;
    char out[8192], err[8192], path[700];
    double R0[5], R[5];
    write_lattice("lat0.json", NULL);
    write_lattice("lat.json", "1");
    lattice_reactions("lat0.json", R0);
    lattice_reactions("lat.json", R);
    print_message("3^3 lattice pulled 10 %% along z: %.6g N without fibres, %.6g N with a fibre "
                  "along z per cell\n", R0[4], R[4]);
    /* tension: negative; the fibres, slack at the first sample (strain 0.02, below their
    ** recruitment at 0.03), add a share from the second on */
    assert_close(R[0], R0[0], 1e-9 * fabs(R0[0]));
    assert_true(R[1] < R0[1] && R[4] < 1.3 * R0[4]);
    const int st = tu_run(out, sizeof out, err, sizeof err, "export fits/telescoping.json "
                          "--lattice %s/lat.json --format febio -o %s/lat.feb", dir, dir);
    if (st != 65 || !strstr(err, "febio: the lattice's 1 fibre group"))
        fail_msg("febio: exit %d, %s", st, err);
    if (tu_run(out, sizeof out, err, sizeof err, "export fits/telescoping.json --lattice "
               "%s/lat.json --format calculix -o %s/lat.inp", dir, dir))
        fail_msg("export: %s", err);
    snprintf(path, sizeof path, "%s/lat.inp", dir);
    char *x = tu_slurp(path);
    assert_non_null(x);
    const double tol = tu_deck_tolerance(x);
    assert_non_null(strstr(x, "27 embedded tension-only springs (one per cell"));
    free(x);
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    char cmd[1600];
    snprintf(cmd, sizeof cmd, "cd %s && ccx -i lat > lat.log 2>&1", dir);
    if (system(cmd) != 0)
        fail_msg("ccx failed on %s/lat.inp", dir);
    snprintf(path, sizeof path, "%s/lat.dat", dir);
    char *text = tu_slurp(path);
    assert_non_null(text);
    int n = 0;
    const char *key2 = "total force (fx,fy,fz) for set NDRIVE and time";
    for (const char *q = text; (q = strstr(q, key2)); q++) {
        double t, fx, fy, fz;
        if (sscanf(q, "total force (fx,fy,fz) for set NDRIVE and time %lf %lf %lf %lf", &t, &fx,
                   &fy, &fz) != 4)
            continue;
        const int k = (int)floor(t + 0.5);
        assert_true(k == n + 1);
        print_message("fibre lattice, step %d: ccx %.7g N, conifit simulate %.7g N (%+.2e; "
                      "tolerance %.3g N)\n", k, -fz, R[n], -fz / R[n] - 1, tol);
        if (!(fabs(-fz - R[n]) <= tol) || !(fabs(-fz - R[n]) <= 1e-3 * fabs(R[n])))
            fail_msg("step %d: beyond %.3g N or 1e-3", k, tol);
        n++;
    }
    free(text);
    assert_int_equal(n, 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_fibre_slab_runs_and_shows_its_directions),
        cmocka_unit_test(bad_fibres_are_refused_by_key_and_value),
        cmocka_unit_test(the_fibre_slab_runs_in_ccx),
        cmocka_unit_test(a_lattice_fibre_runs_in_ccx),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
