/*
** The fibre-reinforced lattice in a joint report (report_fibre.h).
*/
#include "report/report_fibre.h"

#include <stdio.h>

#include "conifit/spring.h"
#include "fit/fit.h"
#include "io/fitfile_json.h"

/* One family (rho, s/H, F_C/H^2) and its placed springs as text, the stress in the first
** table's unit; `per` is what the springs are counted per ("cell", "lattice edge"). */
static void family_text(FILE *o, const cf_joint_report *r, const char *what, const cf_ident *q,
                        const cf_fibre_spring *s, const char *per)
{
    const cf_table *t0 = r->tables[0];
    char sp[256];
    fprintf(o, "      %s: rho %.4g, s/H %.4g, F_C/H^2 %.4g %s\n        built as %d %s spring%s "
               "per %s in parallel, each %s, index D1/d %.3g: %s",
            what, q->rho, q->solid, q->scale * t0->y_to_file, t0->y_unit, s->count,
            cf_spring_type_name(s->type), s->count == 1 ? "" : "s", per,
            cf_spring_text(&s->spring, 4, 0, sp, sizeof sp), s->spring.D1_mm / s->spring.d_mm,
            s->buildable ? "buildable" : "NOT buildable (breaks");
    for (unsigned b = 1; !s->buildable && b < (1u << CF_C_COUNT); b <<= 1)
        if (s->violated & b)
            fprintf(o, " %s", cf_fit_constraint_name(b));
    fprintf(o, "%s\n", s->buildable ? "" : ")");
}

static void fit_text(FILE *o, const cf_joint_report *r, int c)
{
    const cf_fibre_fit *f = &r->fibre[c];
    const cf_table *t0 = r->tables[0];
    const cf_ho_fit *h = &r->ho[CF_HO_FULL][c];
    fprintf(o, "    second direction along %s: weighted objective %.4g", c ? "n" : "s",
            f->objective);
    if (r->ho_ran)
        fprintf(o, " (Holzapfel-Ogden full %.4g: %s)", h->objective,
                f->objective <= h->objective ? "at or below" : "above");
    fprintf(o, ", %d parameters, %.2f s CPU\n", f->nparams, r->fibre_cpu_s[c]);
    family_text(o, r, "matrix", &f->matrix, &f->matrix_spring, "lattice edge");
    fprintf(o, "        family weights edge %.4g, face %.4g, body %.4g (each family's springs carry "
               "its weight times the spring's force)\n", f->family[0], f->family[1], f->family[2]);
    for (int g = 0; g < f->ngroups; g++) {
        char what[64];
        snprintf(what, sizeof what, "group %c (taut from strain %.4g)", f->groups[g],
                 f->slack[g]);
        family_text(o, r, what, &f->fibre[g], &f->fibre_spring[g], "cell");
    }
    fprintf(o, "      lattice %s; the cell of these springs gives the fitted stress to %.2g of "
               "each table's largest\n",
            f->buildable ? "buildable: every spring within the design limits"
                         : "NOT buildable: a spring breaks the design limits",
            f->placed_error);
    fprintf(o, "      volume modulus kappa %.4g %s; %s (smallest stiffness of the cell %.4g %s "
               "along every table to 1.05x its strain)\n      RMSE:",
            f->kappa_MPa * t0->y_to_file, t0->y_unit, f->stable ? "stable" : "NOT stable",
            f->min_stiffness_MPa * t0->y_to_file, t0->y_unit);
    for (size_t k = 0; k < f->ntables; k++) {
        char name[128];
        cf_table_name(r->tables[k], name, sizeof name);
        fprintf(o, "%s %s %.4g %s (%.3g)", k ? "," : "", name,
                f->rmse_MPa[k] * r->tables[k]->y_to_file, r->tables[k]->y_unit, f->term[k]);
    }
    fprintf(o, "\n");
}

void cf_report_fibre_text(FILE *o, const cf_joint_report *r)
{
    if (!r->fibre_groups[0])
        return;
    fprintf(o, "\nFibre-reinforced lattice (groups %s: a conical spring per cell along each axis "
               "of the fibre frame, slack in compression, on the isotropic lattice with its "
               "volume term; homogenised cell, fitted jointly with the weighted objective)",
            r->fibre_groups);
    if (!r->fibre_ran) {
        fprintf(o, ": not fitted: %s\n", r->fibre_why);
        return;
    }
    fprintf(o, ":\n");
    fit_text(o, r, 1);
    fit_text(o, r, 0);
}

/* The placed spring of a family as the fit file's "spring" object. */
static json_t *spring_json(const cf_fibre_spring *s)
{
    json_t *e = json_object(), *v = json_array();
    if (!e || !v) {
        json_decref(e);
        json_decref(v);
        return NULL;
    }
    for (int k = 0; k < CF_P_COUNT; k++)
        json_object_set_new(e, cf_spring_param_info(k)->key,
                            cf_json_number(cf_spring_get(&s->spring, k)));
    json_object_set_new(e, "type", json_string(cf_spring_type_name(s->type)));
    json_object_set_new(e, "count", json_integer(s->count));
    json_object_set_new(e, "index", cf_json_number(s->spring.D1_mm / s->spring.d_mm));
    json_object_set_new(e, "reach_strain", cf_json_number(s->reach));
    json_object_set_new(e, "buildable", json_boolean(s->buildable));
    for (unsigned b = 1; b < (1u << CF_C_COUNT); b <<= 1)
        if (s->violated & b)
            json_array_append_new(v, json_string(cf_fit_constraint_name(b)));
    json_object_set_new(e, "violated", v);
    return e;
}

static json_t *family_json(const cf_ident *q, const cf_fibre_spring *s, char axis, double slack)
{
    json_t *e = json_object();
    if (!e)
        return NULL;
    if (axis) {
        json_object_set_new(e, "axis", json_stringn(&axis, 1));
        json_object_set_new(e, "recruitment_strain", cf_json_number(slack));
    }
    json_object_set_new(e, "rho", cf_json_number(q->rho));
    json_object_set_new(e, "solid_strain", cf_json_number(q->solid));
    json_object_set_new(e, "stress_scale_kPa", cf_json_number(q->scale * 1e3));
    json_object_set_new(e, "spring", spring_json(s));
    return e;
}

json_t *cf_report_fibre_json(const cf_joint_report *r)
{
    if (!r->fibre_ran)
        return NULL;
    json_t *a = json_array();
    for (int c = 0; a && c < 2; c++) {
        const cf_fibre_fit *f = &r->fibre[c];
        json_t *e = json_object(), *gs = json_array(), *rm = json_array();
        if (!e || !gs || !rm || json_array_append_new(a, e) != 0) {
            json_decref(e);
            json_decref(gs);
            json_decref(rm);
            json_decref(a);
            return NULL;
        }
        for (int g = 0; g < f->ngroups; g++)
            json_array_append_new(gs, family_json(&f->fibre[g], &f->fibre_spring[g], f->groups[g],
                                                   f->slack[g]));
        for (size_t k = 0; k < f->ntables; k++)
            json_array_append_new(rm, cf_json_number(f->rmse_MPa[k] * 1e3));
        json_object_set_new(e, "model", json_string("fibre-lattice"));
        json_object_set_new(e, "cross_axis", json_string(c ? "n" : "s"));
        json_object_set_new(e, "matrix", family_json(&f->matrix, &f->matrix_spring, 0, 0));
        json_object_set_new(e, "fibre_groups", gs);
        json_t *fw = json_array();
        for (int k = 0; k < CF_FAMILY_COUNT && fw; k++)
            json_array_append_new(fw, cf_json_number(f->family[k]));
        json_object_set_new(e, "family_weights", fw);
        json_object_set_new(e, "volume_modulus_kPa", cf_json_number(f->kappa_MPa * 1e3));
        json_object_set_new(e, "objective", cf_json_number(f->objective));
        json_object_set_new(e, "stable", json_boolean(f->stable));
        json_object_set_new(e, "buildable", json_boolean(f->buildable));
        json_object_set_new(e, "placed_stress_error", cf_json_number(f->placed_error));
        json_object_set_new(e, "rmse_kPa", rm);
        json_object_set_new(e, "cpu_s", cf_json_number(r->fibre_cpu_s[c]));
    }
    return a;
}
