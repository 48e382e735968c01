/*
** Export of a fitted spring (see export.h): the blocks to paste into a model (CSV table,
** CalculiX/Abaqus *SPRING, FEBio discrete material, LS-DYNA material and curve), the JSON spring,
** and the runnable models (export_model.c) of one spring (--example) or of the whole lattice.
*/
#include "export/export.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <jansson.h>

#include "model/lattice.h"
#include "conifit/version.h"
#include "base/safetext.h"
#include "io/fitfile_json.h"
#include "export/export_internal.h"

cf_export_options cf_export_default_options(void)
{
    cf_export_options o;
    memset(&o, 0, sizeof o);
    o.format = CF_EXPORT_JSON;
    o.tol = CF_EXPORT_TOL_DEFAULT;
    return o;
}

/* 1 when a Prony term of the fit changes with strain (g_per_strain). */
static int strain_moduli(const cf_fitted_spring *fs)
{
    for (int i = 0; i < fs->prony_count; i++)
        if (fs->prony_k[i] != 0)
            return 1;
    return 0;
}

/* The Prony terms and dashpot of a viscoelastic fit, as comment lines: the time-dependent part of
** the tissue that the simulator formats' spring elements have no place for (src/notes/export.md). */
static void prony_comment(FILE *out, const char *lead, const char *tail,
                          const cf_fitted_spring *fs, const char *why)
{
    if (!fs || !fs->viscoelastic)
        return;
    double ginf = 1;
    for (int i = 0; i < fs->prony_count; i++)
        ginf -= fs->prony_g[i];
    const int strain = strain_moduli(fs);
    fprintf(out, "%sviscoelastic fit: %s on every spring, force = the law convolved with G(t) = "
                 "g_inf + sum g_i exp(-t/tau_i), g_inf = %.17g%s%s\n",
            lead, strain ? "relaxation depending on strain" : "quasi-linear viscoelasticity", ginf,
            strain ? " at zero strain" : "", tail);
    for (int i = 0; i < fs->prony_count; i++) {
        fprintf(out, "%sprony term %d: g = %.17g, tau_s = %.17g", lead, i + 1, fs->prony_g[i],
                fs->prony_tau_s[i]);
        if (fs->prony_k[i] != 0) /* relaxation depending on strain */
            fprintf(out, ", g_per_strain = %.17g (g at strain e: g + g_per_strain |e|)",
                    fs->prony_k[i]);
        fprintf(out, "%s\n", tail);
    }
    if (fs->eta_MPa_s > 0)
        fprintf(out, "%sdashpot beside every spring: eta = %.17g kPa s%s\n", lead,
                fs->eta_MPa_s * 1e3, tail);
    fprintf(out, "%s%s%s\n", lead, why, tail);
}

/* The fit's lattice volume term, as a comment line: a property of the lattice's cells, which a
** table of one spring has no place for (export --lattice carries it where the format can). */
static void volume_comment(FILE *out, const char *lead, const char *tail,
                           const cf_fitted_spring *fs)
{
    if (fs && fs->volume_modulus_MPa > 0)
        fprintf(out,
                "%sthe fit's lattice also has a volume term, not in this table: every cell stores "
                "(kappa/2)(J - 1)^2 of its rest volume, kappa = %.17g MPa (export --lattice "
                "writes it as volume elements for calculix and abaqus)%s\n",
                lead, fs->volume_modulus_MPa, tail);
}

/* Comment lines shared by the blocks: what, units, sign, source, spring and table. */
static void block_header(FILE *out, const char *lead, const char *tail, const char *what,
                         const cf_law *law, const cf_export_table *t,
                         const cf_export_options *opt, const cf_fitted_spring *fs)
{
    fprintf(out, "%sconifit %s: %s%s\n", lead, CF_VERSION, what, tail);
    fprintf(out, "%sunits: mm, N, s, tonne (force in N, elongation in mm)%s\n", lead, tail);
    fprintf(out, "%ssign: tension positive; elongation = -u (conifit compresses for u > 0)%s\n",
            lead, tail);
    cf_export_comment_source(out, lead, tail, opt->source);
    cf_export_comment_spring(out, lead, tail, law);
    cf_export_comment_table(out, lead, tail, t, law);
    volume_comment(out, lead, tail, fs);
}

/* What a block writer writes from: the fitted spring, its law, the table of the law (none for
** formats without a table) and the options. */
typedef struct block_job {
    const cf_fitted_spring *fs;
    const cf_law *law;
    const cf_export_table *t;
    const cf_export_options *opt;
} block_job;

static cf_status write_json(FILE *out, const block_job *j, cf_error *err)
{
    const cf_fitted_spring *fs = j->fs;
    const cf_export_options *opt = j->opt;
    json_t *root = json_pack("{s:s, s:s}", "schema", CF_SPRINGFILE_SCHEMA, "conifit_version",
                             CF_VERSION);
    json_t *spring = cf_fitfile_spring_json(j->law);
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
    if (j->law->extension) { /* the keys of a fit file's double-acting element (fitfile.h) */
        json_t *es = cf_fitfile_spring_json(j->law->extension);
        if (!es) {
            json_decref(root);
            json_decref(units);
            json_decref(prov);
            return cf_error_set(err, CF_E_INTERNAL, "out of memory building the JSON spring");
        }
        json_object_set(root, "params_extension", json_object_get(es, "params"));
        json_object_set(root, "derived_extension", json_object_get(es, "derived"));
        json_decref(es);
    }
    if (fs->volume_modulus_MPa > 0)
        json_object_set_new(root, "lattice",
                            json_pack("{s:o}", "volume_modulus_MPa",
                                      cf_json_number(fs->volume_modulus_MPa)));
    json_object_set_new(units, "length", json_string("mm"));
    json_object_set_new(units, "force", json_string("N"));
    json_object_set_new(units, "modulus", json_string("MPa"));
    json_object_set_new(units, "stiffness", json_string("N/mm"));
    json_object_set_new(units, "sign",
                        json_string("u > 0 compresses the spring; F has the sign of u"));
    json_object_set_new(root, "units", units);
    char source[CF_EXPORT_SOURCE_MAX]; /* text from outside: valid UTF-8 for JSON */
    const char *src = opt->source ? opt->source : "";
    json_object_set_new(prov, "fit_file", json_string(cf_safe_text(source, sizeof source, src,
                                                                   strlen(src))));
    json_object_set_new(prov, "data_file", json_string(fs->data_file));
    if (isfinite(fs->rmse)) {
        json_object_set_new(prov, "rmse", cf_json_number(fs->rmse));
        json_object_set_new(prov, "rmse_unit", json_string(fs->y_unit));
    }
    json_object_set_new(prov, "fit_version", json_string(fs->version));
    json_object_set_new(root, "provenance", prov);
    if (fs->viscoelastic) { /* the keys of the fit file, which cf_fitfile_load reads back */
        json_t *pr = json_array();
        double ginf = 1;
        for (int i = 0; pr && i < fs->prony_count; i++) {
            json_t *t = json_pack("{s:o, s:o}", "g", cf_json_number(fs->prony_g[i]), "tau_s",
                                  cf_json_number(fs->prony_tau_s[i]));
            if (t && fs->prony_k[i] != 0)
                json_object_set_new(t, "g_per_strain", cf_json_number(fs->prony_k[i]));
            json_array_append_new(pr, t);
            ginf -= fs->prony_g[i];
        }
        json_object_set_new(root, "prony", pr);
        json_object_set_new(root, "g_inf", cf_json_number(ginf));
        if (fs->eta_MPa_s > 0)
            json_object_set_new(root, "dashpot",
                                json_pack("{s:o}", "eta_kPa_s", cf_json_number(fs->eta_MPa_s * 1e3)));
        const int strain = strain_moduli(fs);
        json_object_set_new(
            root, "viscoelasticity",
            json_string(strain ? "relaxation depending on strain: term i's modulus at the "
                                 "spring's strain e is g + g_per_strain |e|, its branch relaxing "
                                 "that share of the law force"
                               : "quasi-linear (Fung): the spring's force is its law convolved "
                                 "with G(t) = g_inf + sum g_i exp(-t/tau_i)"));
    }
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


static cf_status write_csv(FILE *out, const block_job *j, cf_error *err)
{
    (void)err;
    const cf_export_table *t = j->t;
    prony_comment(out, "# ", "", j->fs,
                  "the table below is the instantaneous (elastic) law; G(t) scales its response "
                  "in time");
    if (j->law->extension) {
        fprintf(out, "# double-acting element: u >= 0 the compression spring, u < 0 its own "
                     "extension spring (the same free length H)\n");
        cf_export_comment_spring(out, "# ", "", j->law);
    }
    volume_comment(out, "# ", "", j->fs);
    fprintf(out, "u_mm,force_N,stiffness_N_per_mm\n");
    for (size_t i = 0; i < t->rows; i++)
        fprintf(out, "%.17g,%.17g,%.17g\n", t->u_mm[i], t->F_N[i], t->k_N_per_mm[i]);
    return CF_OK;
}

/* CalculiX and Abaqus share the *SPRING layout: force first, then elongation, ascending in
** elongation; tension positive, so each row is (-F(u), -u) read from the top of the table. */
static void write_inp_block(FILE *out, const block_job *j, const char *what)
{
    const cf_export_table *t = j->t;
    block_header(out, "** ", "", what, j->law, t, j->opt, j->fs);
    prony_comment(out, "** ", "", j->fs,
                  "not written as keywords: *VISCOELASTIC, TIME=PRONY belongs to a *MATERIAL of "
                  "continuum elements; SPRINGA elements take *SPRING alone, elastic");
    fprintf(out, "** CalculiX holds the force of the last pair beyond the table (constant force)\n");
    fprintf(out, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR\n\n");
    for (size_t i = t->rows; i-- > 0;)
        cf_export_inp_pair(out, -t->F_N[i], -t->u_mm[i]);
}

static cf_status write_calculix(FILE *out, const block_job *j, cf_error *err)
{
    (void)err;
    write_inp_block(out, j, "conical spring as a nonlinear CalculiX SPRINGA table");
    return CF_OK;
}

static cf_status write_abaqus(FILE *out, const block_job *j, cf_error *err)
{
    (void)err;
    write_inp_block(out, j, "conical spring as a nonlinear Abaqus SPRINGA table");
    return CF_OK;
}

static cf_status write_febio(FILE *out, const block_job *j, cf_error *err)
{
    (void)err;
    const cf_law *law = j->law;
    const cf_export_table *t = j->t;
    fprintf(out, "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n");
    block_header(out, "<!-- ", " -->", "conical spring for FEBio 4 as a nonlinear spring", law, t,
                 j->opt, j->fs);
    prony_comment(out, "<!-- ", " -->", j->fs,
                  "not written as material: FEBio's viscoelastic material (g1..g6, t1..t6) wraps a "
                  "solid's elastic material; a discrete nonlinear spring has no relaxation");
    fprintf(out, "<!-- beyond the table the force is held constant (extend CONSTANT); for a "
                 "model that runs as it is use the example or the lattice export -->\n");
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
        fprintf(out, "\t\t\t\t\t<pt>%.17g,%.17g</pt>\n", t->u_mm[i] == 0.0 ? 0.0 : -t->u_mm[i],
                t->F_N[i] == 0.0 ? 0.0 : -t->F_N[i]);
    fprintf(out, "\t\t\t\t</points>\n\t\t\t</force>\n\t\t</discrete_material>\n");
    fprintf(out, "\t\t<discrete dmat=\"1\" discrete_set=\"conifit_springs\"/>\n");
    fprintf(out, "\t</Discrete>\n</febio_spec>\n");
    return CF_OK;
}

/* LS-DYNA keyword cards: 10-character fields; the curve's points in two 20-character fields.
** The table is evenly spaced and LCINT (field 8 of the curve's first card) is its row count:
** LS-DYNA rediscretizes every curve to LCINT equally spaced points (100 by default), which are
** then the rows themselves (see CF_EXPORT_LSDYNA_MAX_ROWS). */
static cf_status write_lsdyna(FILE *out, const block_job *j, cf_error *err)
{
    (void)err;
    const cf_export_table *t = j->t;
    block_header(out, "$ ", "",
                 "conical spring for LS-DYNA as *MAT_SPRING_NONLINEAR_ELASTIC (MAT_S04)", j->law,
                 t, j->opt, j->fs);
    prony_comment(out, "$ ", "", j->fs,
                  "not written as cards: the viscoelastic materials with G_i, BETA_i are for "
                  "solids; *MAT_SPRING_MAXWELL holds one linear term, not a series on a curve");
    cf_export_comment_even(out, "$ ", "", t, j->law);
    fprintf(out, "*KEYWORD\n*MAT_SPRING_NONLINEAR_ELASTIC\n");
    fprintf(out, "$#     mid       lcd       lcr\n");
    fprintf(out, "%10d%10d%10d\n", 1, 1, 0);
    fprintf(out, "*DEFINE_CURVE\n");
    fprintf(out, "$#    lcid      sidr       sfa       sfo      offa      offo    dattyp     lcint\n");
    fprintf(out, "%10d%10d%10.1f%10.1f%10.1f%10.1f%10d%10zu\n", 1, 0, 1.0, 1.0, 0.0, 0.0, 0,
            t->rows);
    fprintf(out, "$#                a1                  o1\n");
    for (size_t i = t->rows; i-- > 0;)
        fprintf(out, "%20.12e%20.12e\n", -t->u_mm[i], -t->F_N[i]);
    fprintf(out, "*END\n");
    return CF_OK;
}

/* ---- the registry of formats ------------------------------------------------------------------ */

/* One format: what callers see, the writer of its block (NULL: the block is the one-spring model)
** and the writer of its models (NULL: no models), and, for a format whose target reads tables of at
** most info.max_rows rows, whose limit that is (for the message). */
typedef struct format_def {
    cf_export_format_info info;
    cf_status (*block)(FILE *out, const block_job *j, cf_error *err);
    int (*model)(FILE *out, const cf_xmodel *m);
    const char *limited_by;
} format_def;

/* Indexed by cf_export_format; each entry: {format, name, extension, description, model, table,
** max_rows, even}, block writer, model writer, limited_by. */
static const format_def formats[CF_EXPORT_FORMAT_COUNT] = {
    [CF_EXPORT_JSON] = {{CF_EXPORT_JSON, "json", ".json",
      "the spring itself (schema " CF_SPRINGFILE_SCHEMA "), for any tool", 0, 0, 0},
     write_json, NULL, NULL},
    [CF_EXPORT_CSV] = {{CF_EXPORT_CSV, "csv", ".csv",
      "the law's table: u_mm,force_N,stiffness_N_per_mm, for any tool", 0, 1, 0},
     write_csv, NULL, NULL},
    [CF_EXPORT_CALCULIX] = {{CF_EXPORT_CALCULIX, "calculix", ".inp",
      "CalculiX ccx 2.20+: a *SPRING table for SPRINGA elements", 1, 1,
      CF_EXPORT_CALCULIX_MAX_ROWS},
     write_calculix, cf_xmodel_write_calculix, "CalculiX"},
    [CF_EXPORT_ABAQUS] = {{CF_EXPORT_ABAQUS, "abaqus", ".inp",
      "Abaqus/Standard: the same *SPRING table (kept to CalculiX's 200 rows)", 1, 1,
      CF_EXPORT_CALCULIX_MAX_ROWS},
     write_abaqus, cf_xmodel_write_abaqus, "CalculiX"},
    [CF_EXPORT_FEBIO] = {{CF_EXPORT_FEBIO, "febio", ".feb",
      "FEBio 4: a nonlinear-spring discrete material", 1, 1, 0},
     write_febio, cf_xmodel_write_febio, NULL},
    [CF_EXPORT_LSDYNA] = {{CF_EXPORT_LSDYNA, "lsdyna", ".k",
      "LS-DYNA: *MAT_SPRING_NONLINEAR_ELASTIC, an evenly spaced *DEFINE_CURVE", 1, 1,
      CF_EXPORT_LSDYNA_MAX_ROWS, 1},
     write_lsdyna, cf_xmodel_write_lsdyna, NULL},
    [CF_EXPORT_SOFA] = {{CF_EXPORT_SOFA, "sofa", ".scn",
      "SOFA v24.06+: always a scene (springs as sums of polynomial springs)", 1, 1, 0},
     NULL, cf_xmodel_write_sofa, NULL},
};

static const format_def *format_def_of(cf_export_format f)
{
    return (unsigned)f < CF_EXPORT_FORMAT_COUNT ? &formats[f] : NULL;
}

const cf_export_format_info *cf_export_format_get(cf_export_format format)
{
    const format_def *d = format_def_of(format);
    return d ? &d->info : NULL;
}

const char *cf_export_format_name(cf_export_format format)
{
    const format_def *d = format_def_of(format);
    return d ? d->info.name : "?";
}

const char *cf_export_format_list(char *buf, size_t cap, int models_only)
{
    size_t n = 0, k = 0, len = 0;
    for (size_t i = 0; i < CF_EXPORT_FORMAT_COUNT; i++)
        n += !models_only || formats[i].info.model;
    if (cap)
        buf[0] = '\0';
    for (size_t i = 0; i < CF_EXPORT_FORMAT_COUNT && len < cap; i++) {
        if (models_only && !formats[i].info.model)
            continue;
        const char *sep = k == 0 ? "" : k + 1 == n ? " or " : ", ";
        int w = snprintf(buf + len, cap - len, "%s%s", sep, formats[i].info.name);
        len += w > 0 ? (size_t)w : 0;
        k++;
    }
    return buf;
}

cf_status cf_export_format_parse(const char *name, cf_export_format *format, cf_error *err)
{
    for (size_t i = 0; i < CF_EXPORT_FORMAT_COUNT; i++)
        if (name && strcmp(name, formats[i].info.name) == 0) {
            *format = formats[i].info.format;
            return CF_OK;
        }
    char list[256];
    return cf_error_set(err, CF_E_DATA, "unknown export format '%s' (expected %s)",
                        name ? name : "(null)", cf_export_format_list(list, sizeof list, 0));
}

cf_status cf_export_format_of_path(const char *path, cf_export_format *format, cf_error *err)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    size_t found = 0;
    char names[256] = "";
    if (dot && (!slash || dot > slash))
        for (size_t i = 0; i < CF_EXPORT_FORMAT_COUNT; i++)
            if (strcasecmp(dot, formats[i].info.extension) == 0) {
                if (found++ == 0)
                    *format = formats[i].info.format;
                const size_t len = strlen(names);
                snprintf(names + len, sizeof names - len, "%s%s", len ? " or " : "",
                         formats[i].info.name);
            }
    if (found == 1)
        return CF_OK;
    if (found > 1)
        return cf_error_set(err, CF_E_DATA, "'%s' could be %s: name the format", path, names);
    return cf_error_set(err, CF_E_DATA, "no export format writes files named like '%s'",
                        path ? path : "(null)");
}

int cf_xmodel_write(FILE *out, const cf_xmodel *m, cf_export_format f)
{
    const format_def *d = format_def_of(f);
    return d && d->model ? d->model(out, m) : -1;
}

/* ---- the table of a format -------------------------------------------------------------------- */

/* Builds the table for opt (range, tolerance, CalculiX's row limit): CF_E_DATA with the tolerance
** that would fit when the table is too long for CalculiX/Abaqus and the tolerance was given. */
cf_status cf_export_table_for(const cf_law *law, const cf_export_options *opt,
                              cf_export_table *t, cf_error *err)
{
    const format_def *d = format_def_of(opt->format);
    const size_t max_rows = d ? d->info.max_rows : 0;
    double tol = opt->tol;
    if (d && d->info.even) { /* evenly spaced: the range, not the tolerance, gives way */
        double lo = opt->u_lo_mm, hi = opt->u_hi_mm;
        if (!opt->have_range) {
            hi = cf_export_table_end(law, tol);
            lo = -cf_export_table_end(law->extension ? law->extension : law, tol);
        }
        return cf_export_table_build_even(law, tol, lo, hi, max_rows, t, err);
    }
    for (int step = 0;; step++) {
        cf_status st;
        if (opt->have_range)
            st = cf_export_table_build_range(law, tol, opt->u_lo_mm, opt->u_hi_mm, t, err);
        else
            st = cf_export_table_build(law, tol, t, err);
        if (st != CF_OK)
            return st;
        if (!max_rows || t->rows <= max_rows)
            return CF_OK;
        const size_t rows = t->rows;
        cf_export_table_free(t);
        if (!opt->auto_tol || tol >= CF_EXPORT_TOL_MAX) {
            /* rows grow like tol^(-1/2): find the tolerance that fits, to report it */
            double need = tol * pow((double)rows / (double)max_rows, 2.0);
            for (int k = 0; k < 20 && need <= CF_EXPORT_TOL_MAX; k++, need *= 1.1) {
                cf_export_table probe;
                cf_error e2 = {0};
                cf_status s2 =
                    opt->have_range
                        ? cf_export_table_build_range(law, need, opt->u_lo_mm, opt->u_hi_mm,
                                                      &probe, &e2)
                        : cf_export_table_build(law, need, &probe, &e2);
                const int fits = s2 == CF_OK && probe.rows <= max_rows;
                cf_export_table_free(&probe);
                if (fits)
                    break;
            }
            return cf_error_set(err, CF_E_DATA,
                                "%s reads at most %zu (force, elongation) pairs per spring, "
                                "but tolerance %g of F_C needs %zu rows for this spring (rho = "
                                "%.4g); tolerance %.2g fits%s",
                                d->limited_by, max_rows, tol, rows, law->rho, need,
                                opt->have_range ? "" : ", or a narrower range");
        }
        tol = fmin(CF_EXPORT_TOL_MAX, (step % 3 == 1) ? tol * 2.5 : tol * 2.0);
    }
}

cf_export_report cf_export_report_of_table(const cf_export_table *t, const cf_law *law)
{
    cf_export_report r = {0};
    r.rows = t->rows;
    r.tol = t->tol;
    r.max_err_rel = t->max_err_rel;
    r.max_err_N = t->max_err_N;
    r.u_lo_mm = t->u_lo_mm;
    r.u_hi_mm = t->u_hi_mm;
    r.even = t->even;
    r.req_lo_mm = t->req_lo_mm;
    r.req_hi_mm = t->req_hi_mm;
    if (t->rows)
        r.end_force_rel = fmax(fabs(t->F_N[0]), fabs(t->F_N[t->rows - 1])) / law->F_C_N;
    r.solid_force_rel = law->F_solid_N / law->F_C_N;
    return r;
}

/* ---- models ----------------------------------------------------------------------------------- */

/* The one-spring model: node 1 at the origin held, node 2 at (0, 0, H) free along z only; the
** spring is pushed and pulled to 0.5, 0.9 and 0.99 of the table's ends. */
static int single_model(cf_xmodel *m, const cf_law *law, const cf_export_table *t)
{
    static const double frac[6] = {0.5, 0.9, 0.99, -0.5, -0.9, -0.99};
    m->title = "one conical spring along z, pushed and pulled";
    m->nn = 2;
    m->ns = 1;
    m->ng = 1;
    m->ntop = 1;
    m->nsteps = 6;
    m->X = calloc(2, sizeof *m->X);
    m->Y = calloc(2, sizeof *m->Y);
    m->Z = calloc(2, sizeof *m->Z);
    m->fix = calloc(2, 1);
    m->si = calloc(1, sizeof *m->si);
    m->sj = calloc(1, sizeof *m->sj);
    m->grp = calloc(1, sizeof *m->grp);
    m->top = calloc(1, sizeof *m->top);
    m->g = calloc(1, sizeof *m->g);
    m->dz_mm = calloc(6, sizeof *m->dz_mm);
    m->ref_N = calloc(6, sizeof *m->ref_N);
    m->strain = calloc(6, sizeof *m->strain);
    if (!m->X || !m->Y || !m->Z || !m->fix || !m->si || !m->sj || !m->grp || !m->top || !m->g ||
        !m->dz_mm || !m->ref_N || !m->strain)
        return -1;
    const double H = law->p.H_mm;
    m->Z[1] = H;
    m->fix[0] = CF_FIX_X | CF_FIX_Y | CF_FIX_Z;
    m->fix[1] = CF_FIX_X | CF_FIX_Y;
    m->sj[0] = 1;
    m->top[0] = 1;
    m->g[0].L0_mm = H;
    m->g[0].weight = 1.0;
    m->g[0].count = 1;
    m->area_mm2 = H * H;
    m->reaction_tol_N = t->tol * law->F_C_N;
    m->height_mm = H;
    for (int k = 0; k < 6; k++) {
        const double u = frac[k] > 0 ? frac[k] * t->u_hi_mm : -frac[k] * t->u_lo_mm;
        m->dz_mm[k] = -u;
        m->strain[k] = u / H;
        m->ref_N[k] = cf_law_force(law, CF_LAW_EXACT, u, NULL, NULL);
    }
    return cf_xmodel_tables(m);
}

cf_status cf_export_write(FILE *out, const cf_fitted_spring *fs, const cf_export_options *opt,
                          cf_export_report *rep, cf_error *err)
{
    const format_def *d = format_def_of(opt->format);
    if (!d)
        return cf_error_set(err, CF_E_INTERNAL, "unknown export format %d", (int)opt->format);
    if (opt->example && !d->model)
        return cf_error_set(err, CF_E_DATA, "format %s writes no model", d->info.name);
    if (opt->example && fs->volume_modulus_MPa > 0)
        return cf_error_set(err, CF_E_DATA,
                            "the fit's lattice has a volume term (kappa = %g MPa), which the "
                            "one-spring example has no cells for: export the lattice (--lattice) "
                            "to calculix or abaqus",
                            fs->volume_modulus_MPa);
    cf_law law, ext;
    cf_export_table t = {0};
    cf_export_report r = {0};
    cf_xmodel m = {0};
    memset(&ext, 0, sizeof ext);
    cf_status st = cf_fitted_law(fs, &law, err);
    if (st != CF_OK)
        return st;
    if (fs->has_extension && ((st = cf_law_init(&ext, &fs->extension, err)) != CF_OK ||
                              (st = cf_law_pair(&law, &ext, err)) != CF_OK))
        goto done;
    if (d->info.table) {
        if ((st = cf_export_table_for(&law, opt, &t, err)) != CF_OK)
            goto done;
        r = cf_export_report_of_table(&t, &law);
    }
    if (d->block && !opt->example) {
        const block_job j = {fs, &law, &t, opt};
        if ((st = d->block(out, &j, err)) != CF_OK)
            goto done;
    } else {
        m.law = &law;
        m.base = &t;
        m.source = opt->source;
        m.output = opt->output;
        if (single_model(&m, &law, &t) != 0 || d->model(out, &m) != 0) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory writing the model");
            goto done;
        }
    }
    if (ferror(out))
        st = cf_error_set(err, CF_E_CANTWRITE, "cannot write the %s export", d->info.name);
done:
    if (rep)
        *rep = r;
    cf_xmodel_free(&m);
    cf_export_table_free(&t);
    cf_law_free(&law);
    cf_law_free(&ext);
    return st;
}
