/*
** Runnable models for SOFA (export_model.h).
** What the target reads, as checked against its documentation and source:
** - SOFA: PolynomialSpringsForceField evaluates force = sum a_k |L|^k with L = (l - l0)/l0, times
**   +1 when stretched and, when compressed, -1 if compressible="1" and 0 otherwise
**   (PolynomialSpringsForceField.inl, addForce). No SOFA spring component reads a table, but a
**   piecewise-linear curve is a sum of such springs on the same two nodes: two compressible linear
**   springs give any affine force A + B e, and one one-sided (compressible="0") linear spring of
**   rest length l_j per interior row adds the change of slope there, (s_j - s_j-1)(l - l_j)+. The
**   sum reproduces the table exactly in force. SOFA's tangent of a one-sided spring ignores
**   whether it is engaged (ComputeJacobian uses the polynomial at |L| in both states), so an
**   implicit solver sees the constant stiffness of all springs engaged, the last slope of the
**   table: stable and right at equilibrium, slower to settle than the force alone would be.
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/lattice.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

/* ---- SOFA ------------------------------------------------------------------------------------- */

void cf_sofa_terms_free(cf_sofa_terms *s)
{
    if (!s)
        return;
    free(s->knot_mm), free(s->a_N);
    memset(s, 0, sizeof *s);
}

int cf_sofa_terms_of(const cf_xgroup *g, cf_sofa_terms *s)
{
    memset(s, 0, sizeof *s);
    const size_t R = g->rows;
    if (R < 2)
        return -1;
    s->knot_mm = malloc(R * sizeof *s->knot_mm);
    s->a_N = malloc(R * sizeof *s->a_N);
    if (!s->knot_mm || !s->a_N) {
        cf_sofa_terms_free(s);
        return -1;
    }
    const double L0 = g->L0_mm;
    double prev = (g->T_N[1] - g->T_N[0]) / (g->e_mm[1] - g->e_mm[0]);
    /* affine part: the first segment, extended */
    const double A = g->T_N[0] - prev * g->e_mm[0], B = prev;
    s->a_half_N = A;
    s->a_rest_N = B * L0 - 2.0 * A;
    for (size_t j = 1; j + 1 < R; j++) {
        const double slope = (g->T_N[j + 1] - g->T_N[j]) / (g->e_mm[j + 1] - g->e_mm[j]);
        const double d = slope - prev;
        prev = slope;
        if (d == 0.0)
            continue; /* no kink (the middle of region 1) */
        const double knot = L0 + g->e_mm[j];
        s->knot_mm[s->nknots] = knot;
        s->a_N[s->nknots] = d * knot;
        s->nknots++;
    }
    return 0;
}

/* One PolynomialSpringsForceField of degree-1 springs: `count` node pairs of group g, each with
** rest length l0 and coefficient a. */
static void sofa_field(FILE *out, const cf_xmodel *m, size_t g, const char *name, int compressible,
                       double l0, double a)
{
    const size_t n = m->g[g].count;
    fprintf(out, "\t\t<PolynomialSpringsForceField name=\"%s\" object1=\"@dofs\" object2=\"@dofs\" "
                 "compressible=\"%d\" computeZeroLength=\"0\" firstObjectPoints=\"",
            name, compressible);
    size_t w = 0;
    for (size_t s = 0; s < m->ns; s++)
        if (m->grp[s] == g)
            fprintf(out, "%s%u", w++ ? " " : "", m->si[s]);
    fprintf(out, "\" secondObjectPoints=\"");
    w = 0;
    for (size_t s = 0; s < m->ns; s++)
        if (m->grp[s] == g)
            fprintf(out, "%s%u", w++ ? " " : "", m->sj[s]);
    /* one degree and one coefficient per spring: SOFA applies the first polynomial to all (with a
    ** warning on every step) when the lists are shorter than the springs */
    fprintf(out, "\" polynomialDegree=\"");
    for (size_t i = 0; i < n; i++)
        fprintf(out, "%s1", i ? " " : "");
    fprintf(out, "\" polynomialStiffness=\"");
    for (size_t i = 0; i < n; i++)
        fprintf(out, "%s%.17g", i ? " " : "", a);
    fprintf(out, "\" zeroLength=\"%.17g\"/>\n", l0);
}

int cf_xmodel_write_sofa(FILE *out, const cf_xmodel *m)
{
    cf_sofa_terms *terms = calloc(m->ng ? m->ng : 1, sizeof *terms);
    if (!terms)
        return -1;
    for (size_t g = 0; g < m->ng; g++)
        if (cf_sofa_terms_of(&m->g[g], &terms[g]) != 0) {
            for (size_t h = 0; h < g; h++)
                cf_sofa_terms_free(&terms[h]);
            free(terms);
            return -1;
        }
    fprintf(out, "<?xml version=\"1.0\"?>\n");
    cf_xmodel_header(out, "<!-- ", " -->", m, "SOFA (v24.06 or later)",
                 "runSofa NAME.scn (top reaction: the force on the driven nodes)");
    fprintf(out,
            "<!-- each spring is a sum of degree-1 PolynomialSpringsForceField springs on its two "
            "nodes: two compressible ones (compressible=1, rest lengths L0 and L0/2) give the "
            "first segment of the table extended, one one-sided spring (compressible=0) per "
            "interior row adds that row's change of slope; together they reproduce the table's "
            "piecewise-linear force exactly. SOFA's tangent of a one-sided spring counts it as "
            "engaged in both states, so implicit solvers see the table's last slope: equilibria "
            "are right, settling is slower. Needs the double-precision template Vec3d. -->\n");
    fprintf(out, "<Node name=\"root\" dt=\"1\" gravity=\"0 0 0\">\n");
    fprintf(out, "\t<RequiredPlugin pluginName=\"Sofa.Component.StateContainer "
                 "Sofa.Component.SolidMechanics.Spring Sofa.Component.Constraint.Projective "
                 "Sofa.Component.ODESolver.Backward Sofa.Component.LinearSolver.Direct "
                 "Sofa.Component.Mass\"/>\n");
    fprintf(out, "\t<DefaultAnimationLoop/>\n\t<Node name=\"conifit\">\n");
    fprintf(out, "\t\t<EulerImplicitSolver rayleighStiffness=\"0\" rayleighMass=\"0\"/>\n");
    fprintf(out, "\t\t<SparseLDLSolver template=\"CompressedRowSparseMatrixMat3x3d\"/>\n");
    fprintf(out, "\t\t<MechanicalObject name=\"dofs\" template=\"Vec3d\" position=\"");
    for (size_t i = 0; i < m->nn; i++)
        fprintf(out, "%s%.17g %.17g %.17g", i ? "  " : "", m->X[i], m->Y[i], m->Z[i]);
    fprintf(out, "\"/>\n\t\t<UniformMass totalMass=\"1e-9\"/>\n");
    for (unsigned mask = 1; mask < 8; mask++) {
        size_t w = 0;
        for (size_t i = 0; i < m->nn; i++)
            if ((m->fix[i] & 7u) == mask) {
                if (!w++)
                    fprintf(out,
                            "\t\t<PartialFixedProjectiveConstraint name=\"%s\" "
                            "fixedDirections=\"%d %d %d\" indices=\"",
                            cf_xmodel_mask_name[mask], !!(mask & 1u), !!(mask & 2u), !!(mask & 4u));
                fprintf(out, "%s%zu", w > 1 ? " " : "", i);
            }
        if (w)
            fprintf(out, "\"/>\n");
    }
    /* the drive: the top nodes together, or (a body's probe replayed) each node of it along its
    ** own solved z displacement */
    for (size_t t = 0; t < (m->pp ? m->ntop : 1); t++) {
        fprintf(out, "\t\t<PartialLinearMovementProjectiveConstraint name=\"%s%u\" "
                     "movedDirections=\"0 0 1\" indices=\"",
                m->pp ? "probe" : "drive", m->pp ? m->top[t] : 0u);
        for (size_t q = 0; q < (m->pp ? 1 : m->ntop); q++)
            fprintf(out, "%s%u", q ? " " : "", m->top[m->pp ? t : q]);
        fprintf(out, "\" keyTimes=\"0");
        for (size_t k = 0; k < m->nsteps; k++)
            fprintf(out, " %zu", k + 1);
        fprintf(out, "\" movements=\"0 0 0");
        for (size_t k = 0; k < m->nsteps; k++)
            fprintf(out, "  0 0 %.17g", m->pp ? m->udz_mm[k * m->ntop + t] : m->dz_mm[k]);
        fprintf(out, "\"/>\n");
    }
    for (size_t g = 0; g < m->ng; g++) {
        const cf_sofa_terms s = terms[g];
        char name[64];
        fprintf(out, "\t\t<!-- group %zu: L0 = %.17g mm, weight %.17g, %zu one-sided springs -->\n",
                g + 1, m->g[g].L0_mm, m->g[g].weight, s.nknots);
        snprintf(name, sizeof name, "G%zu_rest", g + 1);
        sofa_field(out, m, g, name, 1, m->g[g].L0_mm, s.a_rest_N);
        snprintf(name, sizeof name, "G%zu_half", g + 1);
        sofa_field(out, m, g, name, 1, 0.5 * m->g[g].L0_mm, s.a_half_N);
        for (size_t j = 0; j < s.nknots; j++) {
            snprintf(name, sizeof name, "G%zu_k%zu", g + 1, j + 1);
            sofa_field(out, m, g, name, 0, s.knot_mm[j], s.a_N[j]);
        }
        cf_sofa_terms_free(&terms[g]);
    }
    free(terms);
    fprintf(out, "\t</Node>\n</Node>\n");
    return 0;
}
