/*
** Export of a fitted spring (see export.h): adaptive tables of the law, the SOFA polynomial, and
** the writers of each target format.
*/
#include "conifit/export.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>
#include <jansson.h>

#include "conifit/version.h"
#include "io/fitfile_json.h"

/* Rows are accepted when the interpolation error at the probes is within this fraction of the
** tolerance, so that the error between probes (checked afterwards on the dense grid) stays
** within the tolerance itself. */
#define CF_EXPORT_SAFETY 0.8
/* Points of each half of the independent check grid (uniform in u, and uniform in
** w = sqrt(1 - |u|/s), which crowds towards solid). */
#define CF_EXPORT_CHECK_POINTS 20000
/* Points of the least-squares grid of the SOFA polynomial. */
#define CF_EXPORT_POLY_POINTS 4001

/* ---- the adaptive table ----------------------------------------------------------------------- */

typedef struct rowbuf {
    size_t n, cap;
    double *u, *F, *k;
} rowbuf;

static int rowbuf_push(rowbuf *b, double u, double F, double k)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        double *nu = realloc(b->u, cap * sizeof *nu);
        if (!nu)
            return -1;
        b->u = nu;
        double *nF = realloc(b->F, cap * sizeof *nF);
        if (!nF)
            return -1;
        b->F = nF;
        double *nk = realloc(b->k, cap * sizeof *nk);
        if (!nk)
            return -1;
        b->k = nk;
        b->cap = cap;
    }
    b->u[b->n] = u;
    b->F[b->n] = F;
    b->k[b->n] = k;
    b->n++;
    return 0;
}

static double allowed_error(const cf_law *law, double tol, double F)
{
    return tol * fmax(fabs(F), CF_EXPORT_FLOOR * law->F_C_N);
}

/* True when linear interpolation between the rows at a and b stays within the tolerance (times
** the safety factor) at seven probes inside the interval. */
static int interval_ok(const cf_law *law, double tol, double a, double Fa, double b, double Fb)
{
    for (int i = 1; i < 8; i++) {
        double f = i / 8.0;
        double F = cf_law_force(law, CF_LAW_EXACT, a + f * (b - a), NULL, NULL);
        if (fabs(Fa + (Fb - Fa) * f - F) > CF_EXPORT_SAFETY * allowed_error(law, tol, F))
            return 0;
    }
    return 1;
}

/* Appends the rows of (a, end] on the compression side, marching from a: each next row is the
** farthest one (found by doubling, then bisection) whose interval still meets the tolerance.
** This nearly equidistributes the error, so the row count stays close to the least possible. */
static int march(const cf_law *law, double tol, double a, double end, rowbuf *rows)
{
    /* Intervals narrower than this are not refined: their ends would differ by a few ulps. */
    const double min_width = 64.0 * DBL_EPSILON * law->travel_mm;
    double Fa = cf_law_force(law, CF_LAW_EXACT, a, NULL, NULL);
    double h = (end - a) / 64.0;
    while (a < end) {
        double good = 0.0, bad = 0.0;
        double w = fmin(h, end - a);
        /* grow while the interval is good, shrink while it is bad */
        for (int it = 0; it < 200; it++) {
            double b = (w >= end - a) ? end : a + w;
            double Fb = cf_law_force(law, CF_LAW_EXACT, b, NULL, NULL);
            if (w <= min_width || interval_ok(law, tol, a, Fa, b, Fb)) {
                good = w;
                if (b == end || bad != 0.0)
                    break;
                w *= 2.0;
            } else {
                bad = w;
                if (good != 0.0)
                    break;
                w *= 0.5;
            }
        }
        /* refine between the good and the bad width */
        for (int it = 0; it < 12 && bad != 0.0 && a + good < end; it++) {
            double m = 0.5 * (good + bad);
            double Fb = cf_law_force(law, CF_LAW_EXACT, a + m, NULL, NULL);
            if (interval_ok(law, tol, a, Fa, a + m, Fb))
                good = m;
            else
                bad = m;
        }
        double b = (a + good >= end) ? end : a + good;
        double kb;
        double Fb = cf_law_force(law, CF_LAW_EXACT, b, &kb, NULL);
        if (rowbuf_push(rows, b, Fb, kb) != 0)
            return -1;
        h = good;
        a = b;
        Fa = Fb;
    }
    return 0;
}

/* The i-th point (0 <= i < 2 CHECK_POINTS) of the dense check grid over [-u_end, u_end]. */
static double check_point(const cf_law *law, double u_end, size_t i)
{
    const size_t N = CF_EXPORT_CHECK_POINTS;
    if (i < N)
        return -u_end + 2.0 * u_end * ((double)i + 0.5) / (double)N;
    i -= N;
    /* w from w_end (at u_end) to 1 (at u = 0), both signs alternately */
    const double s = law->travel_mm;
    const double w_end = sqrt(fmax(0.0, 1.0 - u_end / s));
    const size_t half = N / 2;
    const size_t j = i % half;
    const double w = w_end + (1.0 - w_end) * ((double)j + 0.5) / (double)half;
    double u = fmin(s * (1.0 - w * w), u_end);
    return (i < half) ? u : -u;
}

double cf_export_table_eval(const cf_export_table *t, double u_mm)
{
    if (t->rows == 0)
        return 0.0;
    if (!(u_mm > t->u_mm[0]))
        return t->F_N[0];
    if (u_mm >= t->u_mm[t->rows - 1])
        return t->F_N[t->rows - 1];
    size_t lo = 0, hi = t->rows - 1; /* u[lo] < u <= u[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->u_mm[mid] < u_mm)
            lo = mid;
        else
            hi = mid;
    }
    const double f = (u_mm - t->u_mm[lo]) / (t->u_mm[hi] - t->u_mm[lo]);
    return t->F_N[lo] + f * (t->F_N[hi] - t->F_N[lo]);
}

void cf_export_table_free(cf_export_table *t)
{
    if (!t)
        return;
    free(t->u_mm);
    free(t->F_N);
    free(t->k_N_per_mm);
    memset(t, 0, sizeof *t);
}

cf_status cf_export_table_build(const cf_law *law, double tol, cf_export_table *t, cf_error *err)
{
    memset(t, 0, sizeof *t);
    if (!isfinite(tol) || tol < CF_EXPORT_TOL_MIN || tol > CF_EXPORT_TOL_MAX)
        return cf_error_set(err, CF_E_DATA, "tolerance %g is outside [%g, %g]", tol,
                            CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX);
    const double u_end = cf_law_deflection(law, law->F_C_N * (1.0 - tol));
    rowbuf half = {0};
    int bad = 0;
    double k0;
    double F0 = cf_law_force(law, CF_LAW_EXACT, 0.0, &k0, NULL);
    bad |= rowbuf_push(&half, 0.0, F0, k0);
    double a = 0.0;
    if (law->u_T_mm < u_end) { /* region 1 is linear: one interval */
        double kT;
        double FT = cf_law_force(law, CF_LAW_EXACT, law->u_T_mm, &kT, NULL);
        bad |= rowbuf_push(&half, law->u_T_mm, FT, kT);
        a = law->u_T_mm;
    }
    if (!bad)
        bad |= march(law, tol, a, u_end, &half);
    if (bad) {
        free(half.u), free(half.F), free(half.k);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory building the export table");
    }
    /* mirror: the law is odd, so the stretch half is the compression half negated */
    const size_t n = 2 * half.n - 1;
    t->u_mm = malloc(n * sizeof *t->u_mm);
    t->F_N = malloc(n * sizeof *t->F_N);
    t->k_N_per_mm = malloc(n * sizeof *t->k_N_per_mm);
    if (!t->u_mm || !t->F_N || !t->k_N_per_mm) {
        free(half.u), free(half.F), free(half.k);
        cf_export_table_free(t);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory building the export table");
    }
    for (size_t i = 0; i < half.n; i++) {
        size_t up = half.n - 1 + i, down = half.n - 1 - i;
        t->u_mm[up] = half.u[i];
        t->F_N[up] = half.F[i];
        t->k_N_per_mm[up] = half.k[i];
        t->u_mm[down] = -half.u[i];
        t->F_N[down] = -half.F[i];
        t->k_N_per_mm[down] = half.k[i];
    }
    free(half.u), free(half.F), free(half.k);
    t->rows = n;
    t->tol = tol;
    t->u_end_mm = u_end;
    /* the achieved error, on a grid that knows nothing of the rows */
    for (size_t i = 0; i < 2 * (size_t)CF_EXPORT_CHECK_POINTS; i++) {
        double u = check_point(law, u_end, i);
        double F = cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL);
        double e = fabs(cf_export_table_eval(t, u) - F);
        double rel = e / fmax(fabs(F), CF_EXPORT_FLOOR * law->F_C_N);
        if (rel > t->max_err_rel) {
            t->max_err_rel = rel;
            t->max_err_N = e;
            t->max_err_u_mm = u;
        }
    }
    for (size_t i = 0; i < n; i++)
        if (!isfinite(t->u_mm[i]) || !isfinite(t->F_N[i]) || !isfinite(t->k_N_per_mm[i])) {
            cf_export_table_free(t);
            return cf_error_set(err, CF_E_INTERNAL, "export table row %zu is not finite", i);
        }
    return CF_OK;
}

/* ---- the SOFA polynomial ---------------------------------------------------------------------- */

double cf_export_poly_eval(const cf_export_poly *poly, double L)
{
    double acc = 0.0;
    for (int k = poly->degree; k >= 1; k--)
        acc = (acc + poly->a_N[k - 1]) * L;
    return acc;
}

cf_status cf_export_poly_fit(const cf_law *law, const cf_export_table *t, int degree,
                             cf_export_poly *poly, cf_error *err)
{
    memset(poly, 0, sizeof *poly);
    if (degree < 1 || degree > CF_EXPORT_DEGREE_MAX)
        return cf_error_set(err, CF_E_DATA, "polynomial degree %d is outside [1, %d]", degree,
                            CF_EXPORT_DEGREE_MAX);
    const size_t N = CF_EXPORT_POLY_POINTS;
    const double H = law->p.H_mm, u_end = t->u_end_mm;
    gsl_matrix *X = gsl_matrix_alloc(N, (size_t)degree);
    gsl_vector *y = gsl_vector_alloc(N), *c = gsl_vector_alloc((size_t)degree);
    gsl_matrix *cov = gsl_matrix_alloc((size_t)degree, (size_t)degree);
    gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc(N, (size_t)degree);
    cf_status st = CF_OK;
    if (!X || !y || !c || !cov || !w) {
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory fitting the SOFA polynomial");
        goto done;
    }
    /* Columns are scaled by the largest strain so that the normal equations stay conditioned. */
    const double Lmax = u_end / H;
    for (size_t i = 0; i < N; i++) {
        double u = -u_end + 2.0 * u_end * (double)i / (double)(N - 1);
        double L = -u / H, x = L / Lmax, p = 1.0;
        for (int k = 0; k < degree; k++) {
            p *= x;
            gsl_matrix_set(X, i, (size_t)k, p);
        }
        gsl_vector_set(y, i, -cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL));
    }
    double chisq;
    if (gsl_multifit_linear(X, y, c, cov, &chisq, w) != GSL_SUCCESS) {
        st = cf_error_set(err, CF_E_INTERNAL, "the least-squares fit of degree %d failed",
                          degree);
        goto done;
    }
    poly->degree = degree;
    for (int k = 0; k < degree; k++) {
        poly->a_N[k] = gsl_vector_get(c, (size_t)k) / pow(Lmax, k + 1);
        if (!isfinite(poly->a_N[k])) {
            st = cf_error_set(err, CF_E_INTERNAL, "polynomial coefficient a%d is not finite",
                              k + 1);
            goto done;
        }
    }
    for (size_t i = 0; i < 2 * (size_t)CF_EXPORT_CHECK_POINTS; i++) {
        double u = check_point(law, u_end, i);
        double e = fabs(cf_export_poly_eval(poly, -u / H) +
                        cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL));
        if (e > poly->max_err_N)
            poly->max_err_N = e;
    }
    poly->max_err_rel_FC = poly->max_err_N / law->F_C_N;
done:
    gsl_multifit_linear_free(w);
    gsl_matrix_free(cov);
    gsl_vector_free(c);
    gsl_vector_free(y);
    gsl_matrix_free(X);
    return st;
}

/* ---- formats ---------------------------------------------------------------------------------- */

static const char *const format_names[] = {"json",  "csv",    "calculix", "abaqus",
                                           "febio", "lsdyna", "sofa"};

cf_status cf_export_format_parse(const char *name, cf_export_format *format, cf_error *err)
{
    for (size_t i = 0; i < sizeof format_names / sizeof format_names[0]; i++)
        if (name && strcmp(name, format_names[i]) == 0) {
            *format = (cf_export_format)i;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA,
                        "unknown export format '%s' (expected json, csv, calculix, abaqus, "
                        "febio, lsdyna or sofa)",
                        name ? name : "(null)");
}

const char *cf_export_format_name(cf_export_format format)
{
    size_t i = (size_t)format;
    return i < sizeof format_names / sizeof format_names[0] ? format_names[i] : "?";
}

cf_export_options cf_export_default_options(void)
{
    cf_export_options o;
    memset(&o, 0, sizeof o);
    o.format = CF_EXPORT_JSON;
    o.tol = CF_EXPORT_TOL_DEFAULT;
    o.degree = CF_EXPORT_DEGREE_DEFAULT;
    return o;
}

static const char *src_name(const cf_export_options *opt)
{
    return (opt->source && *opt->source) ? opt->source : "(none)";
}

/* A spring's design parameters on one line, for comments. */
/* Comment lines: each starts with lead and ends with tail (XML comments must close on each line
** so that no "--" appears inside one). */
static void params_line(FILE *out, const char *lead, const char *tail, const cf_law *law)
{
    fprintf(out, "%sspring (%s):", lead, cf_spring_type_name(law->type));
    for (int k = 0; k < CF_P_COUNT; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        fprintf(out, "%s %s = %.17g%s%s", k ? "," : "", sp->name, cf_spring_get(&law->p, k),
                strcmp(sp->unit, "-") ? " " : "", strcmp(sp->unit, "-") ? sp->unit : "");
    }
    fprintf(out, "%s\n", tail);
    fprintf(out, "%stravel s = %.17g mm, F_T = %.17g N, F_C = %.17g N, k0 = %.17g N/mm%s\n", lead,
            law->travel_mm, law->F_T_N, law->F_C_N, law->k0_N_per_mm, tail);
}

static void table_comment(FILE *out, const char *lead, const char *tail,
                          const cf_export_table *t, const cf_law *law)
{
    fprintf(out, "%srows %zu; linear interpolation is within %.3g of the law (relative to the "
                 "force, floor %g F_C); achieved %.3g (%.3g N at u = %.6g mm)%s\n",
            lead, t->rows, t->tol, CF_EXPORT_FLOOR, t->max_err_rel, t->max_err_N,
            t->max_err_u_mm, tail);
    fprintf(out,
            "%sthe table ends a hair before solid, at |elongation| = %.17g mm where |F| = "
            "F_C (1 - tol) = %.17g N;%s\n%sthe law is solid at %.17g mm and clamps there at "
            "F_C.%s\n",
            lead, t->u_end_mm, law->F_C_N * (1.0 - t->tol), tail, lead, law->travel_mm, tail);
}

static cf_status write_json(FILE *out, const cf_fitted_spring *fs, const cf_law *law,
                            const cf_export_options *opt, cf_error *err)
{
    json_t *root = json_pack("{s:s, s:s}", "schema", CF_SPRINGFILE_SCHEMA, "conifit_version",
                             CF_VERSION);
    json_t *spring = cf_fitfile_spring_json(law);
    json_t *units = json_object(), *prov = json_object();
    if (!root || !spring || !units || !prov) {
        json_decref(root);
        json_decref(spring);
        json_decref(units);
        json_decref(prov);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory building the JSON spring");
    }
    json_object_update(root, spring);
    json_decref(spring);
    json_object_set_new(units, "length", json_string("mm"));
    json_object_set_new(units, "force", json_string("N"));
    json_object_set_new(units, "modulus", json_string("MPa"));
    json_object_set_new(units, "stiffness", json_string("N/mm"));
    json_object_set_new(units, "sign",
                        json_string("u > 0 compresses the spring; F has the sign of u"));
    json_object_set_new(root, "units", units);
    json_object_set_new(prov, "fit_file", json_string(opt->source ? opt->source : ""));
    json_object_set_new(prov, "data_file", json_string(fs->data_file));
    if (isfinite(fs->rmse)) {
        json_object_set_new(prov, "rmse", cf_json_number(fs->rmse));
        json_object_set_new(prov, "rmse_unit", json_string(fs->y_unit));
    }
    json_object_set_new(prov, "fit_version", json_string(fs->version));
    json_object_set_new(root, "provenance", prov);
    char *text = cf_fitfile_dumps(root);
    json_decref(root);
    if (!text)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory writing the JSON spring");
    int rc = fputs(text, out);
    free(text);
    if (rc < 0)
        return cf_error_set(err, CF_E_CANTWRITE, "cannot write the JSON spring");
    return CF_OK;
}

static void write_csv(FILE *out, const cf_export_table *t)
{
    fprintf(out, "u_mm,force_N,stiffness_N_per_mm\n");
    for (size_t i = 0; i < t->rows; i++)
        fprintf(out, "%.17g,%.17g,%.17g\n", t->u_mm[i], t->F_N[i], t->k_N_per_mm[i]);
}

/* CalculiX and Abaqus share the *SPRING layout: force first, then elongation, ascending in
** elongation; tension positive, so each row is (-F(u), -u) read from the top of the table. */
static void write_inp(FILE *out, const cf_law *law, const cf_export_table *t,
                      const cf_export_options *opt)
{
    const char *target = opt->format == CF_EXPORT_ABAQUS ? "Abaqus" : "CalculiX";
    fprintf(out, "** conifit %s: conical spring as a nonlinear %s SPRINGA table\n", CF_VERSION,
            target);
    fprintf(out, "** units: mm, N, s, tonne (force in N, elongation in mm)\n");
    fprintf(out, "** sign: tension positive; elongation = -u (conifit compresses for u > 0)\n");
    fprintf(out, "** source: %s\n", src_name(opt));
    params_line(out, "** ", "", law);
    table_comment(out, "** ", "", t, law);
    const double H = law->p.H_mm;
    if (opt->example) {
        fprintf(out, "** one spring along x from node 1 (fixed) to node 2; prescribe node 2's "
                     "x-displacement (mm)\n");
        fprintf(out, "*NODE, NSET=NALL\n1, 0., 0., 0.\n2, %.17g, 0., 0.\n", H);
        fprintf(out, "*NSET, NSET=NFIX\n1\n*NSET, NSET=NPULL\n2\n");
        fprintf(out, "*ELEMENT, TYPE=SPRINGA, ELSET=CONIFIT_SPRING\n1, 1, 2\n");
    }
    fprintf(out, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR\n\n");
    for (size_t i = t->rows; i-- > 0;)
        fprintf(out, "%.17g, %.17g\n", -t->F_N[i], -t->u_mm[i]);
    if (opt->example) {
        fprintf(out, "*BOUNDARY\nNFIX, 1, 3\nNPULL, 2, 3\n");
        const double frac[4] = {0.5, -0.5, 0.99, -0.99};
        for (int i = 0; i < 4; i++) {
            fprintf(out, "*STEP\n*STATIC\n*BOUNDARY\nNPULL, 1, 1, %.17g\n", frac[i] * t->u_end_mm);
            fprintf(out, "*NODE PRINT, NSET=NPULL\nU, RF\n*END STEP\n");
        }
    }
}

static void write_febio(FILE *out, const cf_law *law, const cf_export_table *t,
                        const cf_export_options *opt)
{
    fprintf(out, "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n");
    fprintf(out, "<!-- conifit %s: conical spring for FEBio 4 as a nonlinear spring -->\n",
            CF_VERSION);
    fprintf(out, "<!-- units: mm, N, s, tonne (force in N, elongation in mm) -->\n");
    fprintf(out, "<!-- sign: tension positive; elongation = -u (conifit compresses for u > 0) "
                 "-->\n");
    fprintf(out, "<!-- source: %s -->\n", src_name(opt));
    params_line(out, "<!-- ", " -->", law);
    table_comment(out, "<!-- ", " -->", t, law);
    fprintf(out, "<!-- beyond the table the force is held constant (extend CONSTANT) -->\n");
    fprintf(out, "<febio_spec version=\"4.0\">\n");
    fprintf(out, "\t<Mesh>\n\t\t<!-- replace 1,2 by the node pairs of your springs -->\n");
    fprintf(out, "\t\t<DiscreteSet name=\"conifit_springs\">\n\t\t\t<delem>1,2</delem>\n");
    fprintf(out, "\t\t</DiscreteSet>\n\t</Mesh>\n");
    fprintf(out, "\t<Discrete>\n");
    fprintf(out, "\t\t<discrete_material id=\"1\" name=\"conifit_%s\" type=\"nonlinear spring\">\n",
            law->type == CF_TELESCOPING ? "telescoping" : "non_telescoping");
    fprintf(out, "\t\t\t<scale>1</scale>\n\t\t\t<measure>elongation</measure>\n");
    fprintf(out, "\t\t\t<force type=\"point\">\n\t\t\t\t<interpolate>LINEAR</interpolate>\n");
    fprintf(out, "\t\t\t\t<extend>CONSTANT</extend>\n\t\t\t\t<points>\n");
    for (size_t i = t->rows; i-- > 0;)
        fprintf(out, "\t\t\t\t\t<pt>%.17g,%.17g</pt>\n", -t->u_mm[i], -t->F_N[i]);
    fprintf(out, "\t\t\t\t</points>\n\t\t\t</force>\n\t\t</discrete_material>\n");
    fprintf(out, "\t\t<discrete dmat=\"1\" discrete_set=\"conifit_springs\"/>\n");
    fprintf(out, "\t</Discrete>\n</febio_spec>\n");
}

/* LS-DYNA keyword cards: 10-character fields; the curve's points in two 20-character fields. */
static void write_lsdyna(FILE *out, const cf_law *law, const cf_export_table *t,
                         const cf_export_options *opt)
{
    fprintf(out, "$ conifit %s: conical spring for LS-DYNA as *MAT_SPRING_NONLINEAR_ELASTIC "
                 "(MAT_S04)\n",
            CF_VERSION);
    fprintf(out, "$ units: mm, N, s, tonne (force in N, displacement in mm)\n");
    fprintf(out, "$ sign: tension positive; displacement = elongation = -u (conifit compresses "
                 "for u > 0)\n");
    fprintf(out, "$ source: %s\n", src_name(opt));
    params_line(out, "$ ", "", law);
    table_comment(out, "$ ", "", t, law);
    fprintf(out, "$ LS-DYNA extrapolates past the last point with the last slope (a stiff stop)\n");
    fprintf(out, "*KEYWORD\n*MAT_SPRING_NONLINEAR_ELASTIC\n");
    fprintf(out, "$#     mid       lcd       lcr\n");
    fprintf(out, "%10d%10d%10d\n", 1, 1, 0);
    fprintf(out, "*DEFINE_CURVE\n");
    fprintf(out, "$#    lcid      sidr       sfa       sfo      offa      offo    dattyp\n");
    fprintf(out, "%10d%10d%10.1f%10.1f%10.1f%10.1f%10d\n", 1, 0, 1.0, 1.0, 0.0, 0.0, 0);
    fprintf(out, "$#                a1                  o1\n");
    for (size_t i = t->rows; i-- > 0;)
        fprintf(out, "%20.12e%20.12e\n", -t->u_mm[i], -t->F_N[i]);
    fprintf(out, "*END\n");
}

static void write_sofa(FILE *out, const cf_law *law, const cf_export_poly *poly,
                       const cf_export_options *opt)
{
    fprintf(out, "<!-- conifit %s: conical spring for SOFA (v23.06 or later) as a "
                 "PolynomialSpringsForceField -->\n",
            CF_VERSION);
    fprintf(out, "<!-- units: mm, N, s, tonne (SOFA is unit-agnostic: use this system in the "
                 "whole scene) -->\n");
    fprintf(out, "<!-- force (N, tension positive) = sum_k a_k L^k, L = (l - l0)/l0 the strain "
                 "of the spring, l0 = H -->\n");
    fprintf(out, "<!-- source: %s -->\n", src_name(opt));
    params_line(out, "<!-- ", " -->", law);
    fprintf(out, "<!-- least-squares polynomial of degree %d over |L| <= %.17g; maximum error "
                 "against the law %.17g N = %.3g F_C -->\n",
            poly->degree, law->travel_mm / law->p.H_mm, poly->max_err_N, poly->max_err_rel_FC);
    fprintf(out, "<PolynomialSpringsForceField name=\"conifit_spring\" polynomialDegree=\"%d\" "
                 "polynomialStiffness=\"",
            poly->degree);
    for (int k = 0; k < poly->degree; k++)
        fprintf(out, "%s%.17g", k ? " " : "", poly->a_N[k]);
    fprintf(out, "\" computeZeroLength=\"0\" zeroLength=\"%.17g\" object1=\"@OBJECT1\" "
                 "firstObjectPoints=\"0\" object2=\"@OBJECT2\" secondObjectPoints=\"0\"/>\n",
            law->p.H_mm);
}

cf_status cf_export_write(FILE *out, const cf_fitted_spring *fs, const cf_export_options *opt,
                          cf_export_report *rep, cf_error *err)
{
    cf_law law;
    cf_export_table t = {0};
    cf_export_report r = {0};
    cf_status st = cf_law_init(&law, &fs->params, err);
    if (st != CF_OK)
        return st;
    if (opt->format == CF_EXPORT_JSON) {
        st = write_json(out, fs, &law, opt, err);
        goto done;
    }
    double tol = opt->tol;
    for (int step = 0;; step++) {
        if ((st = cf_export_table_build(&law, tol, &t, err)) != CF_OK)
            goto done;
        if (opt->format != CF_EXPORT_CALCULIX || t.rows <= CF_EXPORT_CALCULIX_MAX_ROWS)
            break;
        /* rows grow like tol^(-1/2): the tolerance that would fit, for the message */
        double need = tol * pow((double)t.rows / CF_EXPORT_CALCULIX_MAX_ROWS, 2.0);
        if (!opt->auto_tol || tol >= CF_EXPORT_TOL_MAX) {
            st = cf_error_set(err, CF_E_DATA,
                              "CalculiX reads at most %d (force, elongation) pairs per spring, "
                              "but --tol %g needs %zu rows; use --tol %.2g or larger",
                              CF_EXPORT_CALCULIX_MAX_ROWS, tol, t.rows, need * 1.2);
            goto done;
        }
        cf_export_table_free(&t);
        tol = fmin(CF_EXPORT_TOL_MAX, (step % 3 == 1) ? tol * 2.5 : tol * 2.0);
    }
    r.tol = tol;
    r.rows = t.rows;
    r.max_err_rel = t.max_err_rel;
    r.max_err_N = t.max_err_N;
    r.u_end_mm = t.u_end_mm;
    switch (opt->format) {
    case CF_EXPORT_CSV:
        write_csv(out, &t);
        break;
    case CF_EXPORT_CALCULIX:
    case CF_EXPORT_ABAQUS:
        write_inp(out, &law, &t, opt);
        break;
    case CF_EXPORT_FEBIO:
        write_febio(out, &law, &t, opt);
        break;
    case CF_EXPORT_LSDYNA:
        write_lsdyna(out, &law, &t, opt);
        break;
    case CF_EXPORT_SOFA: {
        cf_export_poly poly;
        if ((st = cf_export_poly_fit(&law, &t, opt->degree, &poly, err)) != CF_OK)
            goto done;
        write_sofa(out, &law, &poly, opt);
        r.rows = 0;
        r.max_err_N = poly.max_err_N;
        r.max_err_rel = poly.max_err_rel_FC;
        break;
    }
    default:
        st = cf_error_set(err, CF_E_INTERNAL, "unknown export format %d", (int)opt->format);
        goto done;
    }
    if (ferror(out))
        st = cf_error_set(err, CF_E_CANTWRITE, "cannot write the %s export",
                          cf_export_format_name(opt->format));
done:
    if (rep)
        *rep = r;
    cf_export_table_free(&t);
    cf_law_free(&law);
    return st;
}
