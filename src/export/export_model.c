/*
** Runnable models for other simulators (see export_model.h): one writer per target, each
** writing nodes, one spring group per (rest length, weight) with its own table, the boundary
** conditions, the load steps and the output requests in that code's own syntax.
**
** The writers for each target are in export_inp.c, export_febio.c, export_lsdyna.c and
** export_sofa.c; this file holds what they share.
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/lattice.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

/* Two springs belong to one shared group when their rest lengths and weights agree to this relative
** difference (they are computed by the same formulas, so they agree to rounding). */
#define GROUP_REL 1e-12

static int same(double a, double b)
{
    return fabs(a - b) <= GROUP_REL * fmax(fabs(a), fabs(b));
}

int cf_xmodel_of_net(cf_xmodel *m, const cf_net *n, cf_xgrouping grouping)
{
    m->nn = n->nn;
    m->ns = n->ns;
    m->ng = 0;
    m->X = malloc(n->nn * sizeof *m->X);
    m->Y = malloc(n->nn * sizeof *m->Y);
    m->Z = malloc(n->nn * sizeof *m->Z);
    m->fix = malloc(n->nn ? n->nn : 1);
    m->si = malloc(n->ns * sizeof *m->si);
    m->sj = malloc(n->ns * sizeof *m->sj);
    m->grp = malloc(n->ns * sizeof *m->grp);
    m->g = calloc(n->ns, sizeof *m->g); /* at most one group per spring */
    if (!m->X || !m->Y || !m->Z || !m->fix || !m->si || !m->sj || !m->grp || !m->g)
        return -1;
    for (size_t i = 0; i < n->nn; i++) {
        m->X[i] = n->X[3 * i];
        m->Y[i] = n->X[3 * i + 1];
        m->Z[i] = n->X[3 * i + 2];
        m->fix[i] = n->fix[i] & (CF_FIX_X | CF_FIX_Y | CF_FIX_Z);
    }
    memcpy(m->si, n->si, n->ns * sizeof *m->si);
    memcpy(m->sj, n->sj, n->ns * sizeof *m->sj);
    for (size_t s = 0; s < n->ns; s++) {
        size_t g = grouping == CF_XGROUP_EACH ? m->ng : 0;
        while (g < m->ng && !(same(m->g[g].L0_mm, n->L0_mm[s]) && same(m->g[g].weight, n->w[s])))
            g++;
        if (g == m->ng) {
            m->g[g].L0_mm = n->L0_mm[s];
            m->g[g].weight = n->w[s];
            m->ng++;
        }
        m->g[g].count++;
        m->grp[s] = (uint32_t)g;
    }
    return 0;
}

void cf_xmodel_free(cf_xmodel *m)
{
    if (!m)
        return;
    free(m->X), free(m->Y), free(m->Z), free(m->fix);
    free(m->si), free(m->sj), free(m->grp), free(m->top);
    free(m->dz_mm), free(m->ref_N), free(m->strain), free(m->cell);
    free(m->pp), free(m->pn), free(m->pdz_mm), free(m->udz_mm), free(m->fdz_mm);
    for (size_t g = 0; g < m->ng && m->g; g++)
        free(m->g[g].e_mm), free(m->g[g].T_N);
    free(m->g);
    for (size_t g = 0; g < m->nfg && m->fg; g++)
        free(m->fg[g].e_mm), free(m->fg[g].T_N);
    free(m->fg), free(m->fcorner), free(m->fgrp), free(m->fx_mm), free(m->fwt);
    memset(m, 0, sizeof *m);
}

int cf_xmodel_tables(cf_xmodel *m)
{
    const double H = m->law->p.H_mm;
    for (size_t g = 0; g < m->ng; g++) {
        cf_xgroup *G = &m->g[g];
        const cf_export_table *t = G->table ? G->table : m->base;
        G->rows = t->rows;
        G->e_mm = malloc(t->rows * sizeof *G->e_mm);
        G->T_N = malloc(t->rows * sizeof *G->T_N);
        if (!G->e_mm || !G->T_N)
            return -1;
        /* ascending elongation: the table read from its compression end */
        for (size_t i = 0; i < t->rows; i++) {
            size_t r = t->rows - 1 - i;
            G->e_mm[i] = -t->u_mm[r] * (G->L0_mm / H);
            G->T_N[i] = -G->weight * t->F_N[r];
            if (G->e_mm[i] == 0.0)
                G->e_mm[i] = 0.0; /* no "-0" in files */
            if (G->T_N[i] == 0.0)
                G->T_N[i] = 0.0;
        }
    }
    return 0;
}

/* ---- comments shared by the writers ---------------------------------------------------------- */

/* Most distinct group laws a header states (a body has at most CF_BODY_MAX_GROUPS, a lattice
** three). */
#define CF_XMODEL_LAWS_SAID 16

/* Group G's (index g) own law and table at the first group taking it (said[k] the laws stated,
** first[k] their groups), a reference to that group after. */
static void comment_group_law(FILE *out, const char *lead, const char *tail, const cf_xgroup *G,
                              size_t g, const cf_law *said[CF_XMODEL_LAWS_SAID],
                              size_t first[CF_XMODEL_LAWS_SAID])
{
    int k = 0;
    while (k < CF_XMODEL_LAWS_SAID && said[k] && said[k] != G->law)
        k++;
    if (k < CF_XMODEL_LAWS_SAID && said[k] == G->law) {
        fprintf(out, "%s    group %zu: the law and table of group %zu%s\n", lead, g + 1,
                first[k] + 1, tail);
        return;
    }
    if (k < CF_XMODEL_LAWS_SAID)
        said[k] = G->law, first[k] = g;
    char gl[96];
    snprintf(gl, sizeof gl, "%s    group %zu: ", lead, g + 1);
    cf_export_comment_spring(out, gl, tail, G->law);
    cf_export_comment_table(out, gl, tail, G->table, G->law);
}

void cf_export_comment_source(FILE *out, const char *lead, const char *tail, const char *source)
{
    char safe[CF_EXPORT_SOURCE_MAX];
    cf_safe_text(safe, CF_EXPORT_SOURCE_MAX, source && *source ? source : "(none)",
                 source && *source ? strlen(source) : 6);
    /* an XML comment may not hold "--" (nor end in '-'): every '-' after a '-', and a last one,
    ** is written as its escape */
    const int xml = strstr(tail, "-->") != NULL;
    fprintf(out, "%ssource: ", lead);
    for (const char *c = safe; *c; c++) {
        if (xml && *c == '-' && ((c > safe && c[-1] == '-') || c[1] == '\0'))
            fputs("\\x2D", out);
        else
            fputc(*c, out);
    }
    fprintf(out, "%s\n", tail);
}

static void comment_one_spring(FILE *out, const char *lead, const char *tail, const cf_law *law,
                               const char *what);

void cf_export_comment_spring(FILE *out, const char *lead, const char *tail, const cf_law *law)
{
    comment_one_spring(out, lead, tail, law, law->extension ? "compression spring" : "spring");
    if (!law->extension)
        return;
    fprintf(out,
            "%sdouble-acting element: the compression spring for u > 0, its own extension "
            "spring for u < 0 (the same free length H); every table below holds both sides%s\n",
            lead, tail);
    comment_one_spring(out, lead, tail, law->extension, "extension spring");
}

static void comment_one_spring(FILE *out, const char *lead, const char *tail, const cf_law *law,
                               const char *what)
{
    fprintf(out, "%s%s (%s):", lead, what, cf_spring_type_name(law->type));
    for (int k = 0; k < (law->tail ? CF_P_ALL : CF_P_COUNT); k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        fprintf(out, "%s %s = %.17g%s%s", k ? "," : "", sp->name, cf_spring_get(&law->p, k),
                strcmp(sp->unit, "-") ? " " : "", strcmp(sp->unit, "-") ? sp->unit : "");
    }
    fprintf(out, "%s\n", tail);
    fprintf(out, "%stravel s = %.17g mm, F_T = %.17g N, F_C = %.17g N, k0 = %.17g N/mm%s\n", lead,
            law->travel_mm, law->F_T_N, law->F_C_N, law->k0_N_per_mm, tail);
    if (law->tail)
        fprintf(out,
                "%scylindrical tail in series: k_tail = %.17g N/mm; the cone closes at u_C = "
                "%.17g mm (F_C), then the force rises linearly to F_solid = %.17g N at solid "
                "(travel s above is the whole spring's)%s\n",
                lead, law->k_tail_N_per_mm, law->u_C_mm, law->F_solid_N, tail);
}

void cf_export_comment_table(FILE *out, const char *lead, const char *tail,
                             const cf_export_table *t, const cf_law *law)
{
    fprintf(out,
            "%stable: %zu rows over u in [%.10g, %.10g] mm (compression positive); within %.3g "
            "F_C of the law, achieved %.3g F_C (%.3g N at u = %.6g mm)%s\n",
            lead, t->rows, t->u_lo_mm, t->u_hi_mm, t->tol, t->max_err_rel, t->max_err_N,
            t->max_err_u_mm, tail);
    if (law->extension) {
        fprintf(out,
                "%sthe law is solid at u = %.17g mm (F_C) and at u = -%.17g mm (the extension "
                "spring's F_C); past the table's ends a simulator that holds the last force is "
                "within %.3g of that side's F_C of the law up to solid when the table runs to "
                "its full range%s\n",
                lead, law->travel_mm, law->extension->travel_mm, t->tol, tail);
        return;
    }
    fprintf(out,
            "%sthe law is solid at |u| = %.17g mm (force %s); past the table's ends a simulator "
            "that holds the last force is within %.3g F_C of the law up to solid when the table "
            "runs to its full range%s\n",
            lead, law->travel_mm, law->tail ? "F_solid" : "F_C", t->tol, tail);
}

void cf_export_comment_even(FILE *out, const char *lead, const char *tail,
                            const cf_export_table *t, const cf_law *law)
{
    if (!t->even || t->rows < 2)
        return;
    const double h = (t->u_hi_mm - t->u_lo_mm) / (double)(t->rows - 1);
    fprintf(out,
            "%scurve: %zu rows evenly spaced, every %.10g mm of u (in a group of rest length L0, "
            "every %.10g L0/H mm of elongation); LCINT = %zu, so LS-DYNA's rediscretization of "
            "each curve to LCINT equally spaced points (LSTC FAQ 'discretization of curves'; "
            "*DEFINE_CURVE remark 1) gives back these rows%s\n",
            lead, t->rows, h, h, t->rows, tail);
    const int cut = t->u_lo_mm != t->req_lo_mm || t->u_hi_mm != t->req_hi_mm;
    const double F_lo = cf_law_force(law, CF_LAW_EXACT, t->u_lo_mm, NULL, NULL);
    const double F_hi = cf_law_force(law, CF_LAW_EXACT, t->u_hi_mm, NULL, NULL);
    if (cut)
        fprintf(out,
                "%srange: u in [%.10g, %.10g] mm, shortened from [%.10g, %.10g] mm: at most %zu "
                "evenly spaced rows meet the tolerance only there (the law's curvature grows "
                "like (1 - F/F_C)^-3 towards solid)%s\n",
                lead, t->u_lo_mm, t->u_hi_mm, t->req_lo_mm, t->req_hi_mm, t->rows, tail);
    fprintf(out,
            "%sat the curve's ends the law carries %.6g and %.6g of F_C; past them LS-DYNA "
            "extrapolates the curve along its end segments (a straight line), while the law "
            "stiffens to %s at solid (|u| = %.10g mm): keep the springs' compression within "
            "the curve%s\n",
            lead, F_lo / law->F_C_N, F_hi / law->F_C_N, law->tail ? "F_solid" : "F_C",
            law->travel_mm, tail);
}

void cf_xmodel_header(FILE *out, const char *lead, const char *tail, const cf_xmodel *m,
                      const char *target, const char *how)
{
    fprintf(out, "%sconifit %s: %s for %s%s\n", lead, CF_VERSION, m->title, target, tail);
    fprintf(out, "%srun: %s%s\n", lead, how, tail);
    fprintf(out, "%sunits: mm, N, s, tonne (force in N, lengths in mm)%s\n", lead, tail);
    fprintf(out,
            "%ssign: tension positive; each spring table holds elongation L - L0 (mm) and "
            "tension (N)%s\n",
            lead, tail);
    cf_export_comment_source(out, lead, tail, m->source);
    cf_export_comment_spring(out, lead, tail, m->law);
    cf_export_comment_table(out, lead, tail, m->base, m->law);
    fprintf(out,
            "%s%zu nodes, %zu springs in %zu groups; group k is the law at rest length L0 (in "
            "strain form u = -(L - L0) H/L0) times its weight:%s\n",
            lead, m->nn, m->ns, m->ng, tail);
    const cf_law *said[CF_XMODEL_LAWS_SAID] = {0}; /* group laws already stated */
    size_t first[CF_XMODEL_LAWS_SAID] = {0};
    for (size_t g = 0; g < m->ng; g++) {
        fprintf(out, "%s  group %zu: L0 = %.17g mm, weight = %.17g, %zu springs, %zu rows%s\n",
                lead, g + 1, m->g[g].L0_mm, m->g[g].weight, m->g[g].count, m->g[g].rows, tail);
        if (m->g[g].law) /* a spring group's own law and table (at the first group taking it) */
            comment_group_law(out, lead, tail, &m->g[g], g, said, first);
    }
    if (m->pp)
        fprintf(out,
                "%sloading: conifit's probe replayed (a contact this format solves would not give "
                "conifit's penalty contact): at each step the nodes of conifit's contact set have "
                "their z displacement prescribed as conifit solved it (x, y free: frictionless), "
                "%zu nodes in all; the reaction is summed over them. The header's reaction is "
                "conifit's probe force, the 'top z displacement' the probe's travel%s\n",
                lead, m->ntop, tail);
    else
        fprintf(out,
                "%sloading: the %zu top nodes move along z together (x, y free unless fixed); at "
                "each step, conifit's compressive top reaction (N) for comparison:%s\n",
                lead, m->ntop, tail);
    if (m->note && m->note[0])
        fprintf(out, "%snote: %s%s\n", lead, m->note, tail);
    if (m->ncells > 0 && m->nt == 0) /* a lattice's cells: export_lattice.c, propagated_tol */
        fprintf(out,
                "%sreaction tolerance implied by the tables: %.6g N (tol F_C times the largest, "
                "over the steps, sum of every spring's weight times the rate of its length per "
                "unit top displacement along conifit's equilibrium path: the tables' error "
                "carried through the equilibrium with the cells, to first order; at least that of "
                "the springs a horizontal plane cuts)%s\n",
                lead, m->reaction_tol_N, tail);
    else
        fprintf(out,
                "%sreaction tolerance implied by the tables: %.6g N (tol F_C times the weights of "
                "the springs a horizontal plane cuts, projected on z)%s\n",
                lead, m->reaction_tol_N, tail);
    for (size_t g = 0; g < m->ng; g++)
        if (m->g[g].law) { /* spring groups: the tolerance covers each */
            fprintf(out,
                    "%sspring groups: each group's table has its own law and tolerance; the tol "
                    "F_C above is at least each spring's group's own, so the tolerance covers "
                    "every group%s\n",
                    lead, tail);
            break;
        }
    if (m->kappa_MPa > 0)
        fprintf(out,
                "%svolume term: each of the %zu %s stores (kappa/2)(J - 1)^2 of its rest "
                "volume, kappa = %.17g MPa, J its volume over its rest volume%s\n",
                lead, m->nt > 0 ? m->nn : m->ncells,
                m->nt > 0 ? "nodes (a quarter of each tetrahedron around it)" : "cells",
                m->kappa_MPa, tail);
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, "%s  step %zu: top z displacement %.17g mm (strain %.10g), conifit reaction "
                     "%.17g N%s\n",
                lead, k + 1, m->dz_mm[k], m->strain[k], m->ref_N[k], tail);
}

/* The fixed-direction masks that occur, in a fixed order, with FEBio set names. */
const char *const cf_xmodel_mask_name[8] = {"", "fix_x", "fix_y", "fix_xy",
                                         "fix_z", "fix_xz", "fix_yz", "fix_xyz"};

int cf_xmodel_carries_hourglass(cf_export_format f)
{
    return f == CF_EXPORT_CALCULIX || f == CF_EXPORT_ABAQUS;
}

const char *cf_xmodel_volume_refusal(const cf_xmodel *m, cf_export_format f)
{
    if (!(m->kappa_MPa > 0))
        return NULL;
    switch (f) {
    case CF_EXPORT_CALCULIX:
    case CF_EXPORT_ABAQUS:
    case CF_EXPORT_FEBIO:
        return NULL;
    case CF_EXPORT_LSDYNA:
        return "this export writes LS-DYNA's discrete springs only, and none of the solid "
               "materials it writes has exactly the lattice's (kappa/2)(J - 1)^2 and no shear; "
               "export calculix or abaqus";
    case CF_EXPORT_SOFA:
        return "SOFA's spring force fields have no volume term and this export writes no FEM "
               "force field; export calculix or abaqus";
    default:
        return "the format writes no volume elements";
    }
}
