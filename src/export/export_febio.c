/*
** Runnable models for FEBio 4 (export_model.h).
** What the target reads, as checked against its documentation and source:
** - FEBio 4: discrete_material type "nonlinear spring" with measure "elongation" and a point
**   curve (extend CONSTANT holds the last force), discrete sets in the Mesh section resolved by
**   name when the Discrete section is read (FEBioDiscreteSection25::Parse), after MeshDomains has
**   built the mesh; "zero displacement" and "prescribed displacement" boundary conditions on
**   named node sets, a load controller, a logfile of node data on a node set.
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/lattice.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

char *cf_export_febio_log_name(char *buf, size_t cap, const char *output)
{
    static const char suffix[] = "_top_Rz.txt";
    const char *base = output ? output : "";
    for (const char *c = base; *c; c++) /* the last path component */
        if (*c == '/' || *c == '\\')
            base = c + 1;
    size_t n = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot && dot > base)
        n = (size_t)(dot - base);
    if (n == 0)
        base = "conifit", n = 7;
    size_t w = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < n && i < CF_EXPORT_LOG_STEM_MAX;) {
        const unsigned char *c = (const unsigned char *)base + i;
        size_t len = cf_text_char_length(c, n - i);
        if (len > 1 && i + len > CF_EXPORT_LOG_STEM_MAX)
            break; /* cut before a character that does not fit */
        const char *put = NULL;
        char one[8] = "_";
        switch (len ? *c : 0) {
        case '&': put = "&amp;"; break;
        case '<': put = "&lt;"; break;
        case '>': put = "&gt;"; break;
        case '"': put = "&quot;"; break;
        case '\'': put = "&apos;"; break;
        case '/': case '\\': case ':': case 0: put = "_"; break;
        default:
            memcpy(one, c, len);
            one[len] = '\0';
            put = one;
        }
        const size_t plen = strlen(put);
        if (w + plen + sizeof suffix > cap)
            break;
        memcpy(buf + w, put, plen + 1);
        w += plen;
        i += len ? len : 1;
    }
    if (w + sizeof suffix <= cap)
        memcpy(buf + w, suffix, sizeof suffix);
    return buf;
}


/* ---- FEBio 4 ---------------------------------------------------------------------------------- */

/* Convergence of FEBio's Newton iterations (FESolidSolver2::Quasin in FEBio 4.11; user manual,
** Control section, "Convergence tolerances"). A step converges when every enabled test passes;
** FEBio compares squared norms: |R1|^2 <= rtol |R0|^2 (R0 the step's first residual),
** |du|^2 <= dtol^2 |dU|^2 (du the last correction, dU the step's total increment) and
** |du.R1| <= etol |du0.R0|; a tolerance of 0 disables its test. When the tests fail but
** |R1|^2 < min_residual, FEBio ends the step with the warning "No force acting on the system".
** With max_ups 0 every iteration reforms the stiffness (full Newton, quadratic convergence), so a
** residual that reaches round-off leaves the last correction at about its square: dtol 1e-9 asked
** for a correction below 1e-9 of the step after the residual had already passed under FEBio's
** floor, so the steps ended on the floor with the warning (seen on every step with FEBio 4.11).
** Chosen instead:
** - rtol (1e-2 tol)^2: the force left unbalanced is 1e-2 tol of the step's first residual, which
**   is at most of the order of the step's change of the spring forces, so the reaction it leaves
**   is about 1e-2 of the reaction tolerance (tol F_C times the cut weights); at tol >= 1e-9 this
**   is >= 1e-11 of the residual, above double round-off (~1e-14 of the summed forces).
** - dtol 1e-6: the correction below 1e-6 of the step (squared 1e-12, far above round-off).
** - etol 0: the energy test adds nothing to these two (manual: 0 disables a test).
** - min_residual (1e-12 F)^2, F the force scale of the reaction (the reaction tolerance divided
**   by tol: F_C times the cut weights): the floor about 100 times above the round-off of the
**   summed spring forces, instead of FEBio's absolute 1e-20 N^2, which a small spring's residual
**   reaches before the tests pass. It ends a step that prescribes no change (a hold), whose
**   residual is round-off; should it end a real step first (tol below about 1e-6, or tiny steps),
**   FEBio warns, and the force left is 1e-12 F, far inside the reaction tolerance. */
static void febio_control(FILE *out, const cf_xmodel *m)
{
    const double tol = m->base->tol > 0 ? m->base->tol : CF_EXPORT_TOL_DEFAULT;
    const double rtol = (1e-2 * tol) * (1e-2 * tol);
    const double scale = m->reaction_tol_N / tol;
    const double floor_N = 1e-12 * (scale > 0 ? scale : 1.0);
    fprintf(out, "\t<Control>\n\t\t<analysis>STATIC</analysis>\n\t\t<time_steps>%zu</time_steps>\n"
                 "\t\t<step_size>1</step_size>\n\t\t<solver type=\"solid\">\n"
                 "\t\t\t<max_refs>50</max_refs>\n\t\t\t<dtol>1e-06</dtol>\n"
                 "\t\t\t<etol>0</etol>\n\t\t\t<rtol>%.3g</rtol>\n"
                 "\t\t\t<min_residual>%.3g</min_residual>\n"
                 "\t\t\t<qn_method type=\"BFGS\">\n\t\t\t\t<max_ups>0</max_ups>\n"
                 "\t\t\t</qn_method>\n\t\t</solver>\n\t</Control>\n",
            m->nsteps, rtol, floor_N * floor_N);
}

/* The volume term in FEBio 4: a Mooney-Rivlin material with c1 = c2 = 0 is purely volumetric,
** W = U(J), and pressure_model 2 ("Abaqus") of FEBio's uncoupled materials is U(J) =
** (k/2)(J - 1)^2 (FEUncoupledMaterial::U, case 2, since FEBio 3; user manual, "Uncoupled Elastic
** Solids"): with k = kappa the term of conifit's lattice and body. A body's tetrahedra become tet4
** elements of a ut4 domain with alpha 0 (FEBio's uniform nodal strain tetrahedron, FEUT4Domain:
** the deformation gradient averaged over the tetrahedra around each node, their volumes a quarter
** each; alpha 0 leaves out its element-wise stabilisation), so J per node as conifit takes it; a
** lattice's cells
** hex8 elements, which FEBio gives an uncoupled material's three-field formulation by default
** (FESolidDomainFactory: hex8 with an uncoupled material), whose pressure is U'(v/V) with v/V the
** element's volume ratio, the cell's J of conifit exactly. Nothing written without a volume term. */
static void febio_volume_material(FILE *out, const cf_xmodel *m)
{
    if (!(m->kappa_MPa > 0) || (m->nt == 0 && m->ncells == 0))
        return;
    fprintf(out, "\t<!-- the volume term: (kappa/2)(J - 1)^2 per unit rest volume, kappa = %.17g "
                 "MPa, J per %s: a Mooney-Rivlin solid with c1 = c2 = 0 and pressure_model 2, "
                 "U(J) = (k/2)(J - 1)^2 -->\n",
            m->kappa_MPa, m->nt > 0 ? "node (the ut4 domain's nodal average, alpha 0)"
                                    : "cell (the three-field hex8's volume ratio)");
    fprintf(out, "\t<Material>\n\t\t<material id=\"1\" name=\"volume\" type=\"Mooney-Rivlin\">\n"
                 "\t\t\t<density>1e-09</density>\n\t\t\t<c1>0</c1>\n\t\t\t<c2>0</c2>\n"
                 "\t\t\t<k>%.17g</k>\n\t\t\t<pressure_model>2</pressure_model>\n"
                 "\t\t</material>\n\t</Material>\n",
            m->kappa_MPa);
}

/* The volume elements inside Mesh (see febio_volume_material). */
static void febio_volume_elements(FILE *out, const cf_xmodel *m)
{
    if (!(m->kappa_MPa > 0) || (m->nt == 0 && m->ncells == 0))
        return;
    static const int order[8] = {0, 1, 3, 2, 4, 5, 7, 6}; /* corner di + 2 dj + 4 dk -> hex8 */
    const int tet = m->nt > 0;
    const size_t n = tet ? m->nt : m->ncells;
    fprintf(out, "\t\t<Elements type=\"%s\" name=\"volume\">\n", tet ? "tet4" : "hex8");
    for (size_t e = 0; e < n; e++) {
        fprintf(out, "\t\t\t<elem id=\"%zu\">", e + 1);
        for (int a = 0; a < (tet ? 4 : 8); a++)
            fprintf(out, "%s%u", a ? "," : "",
                    (tet ? m->tet[4 * e + (size_t)a] : m->cell[8 * e + (size_t)order[a]]) + 1);
        fprintf(out, "</elem>\n");
    }
    fprintf(out, "\t\t</Elements>\n");
}

/* The node sets inside Mesh: one per held-direction mask, the top (or every node ever in a body's
** contact set), and a body's contact nodes one by one (p<node>). */
static void febio_node_sets(FILE *out, const cf_xmodel *m)
{
    for (unsigned mask = 1; mask < 8; mask++) {
        size_t cnt = 0;
        for (size_t i = 0; i < m->nn; i++)
            cnt += (m->fix[i] & 7u) == mask;
        if (!cnt)
            continue;
        fprintf(out, "\t\t<NodeSet name=\"%s\">", cf_xmodel_mask_name[mask]);
        size_t w = 0;
        for (size_t i = 0; i < m->nn; i++)
            if ((m->fix[i] & 7u) == mask)
                fprintf(out, "%s%zu", w++ ? "," : "", i + 1);
        fprintf(out, "</NodeSet>\n");
    }
    fprintf(out, "\t\t<NodeSet name=\"top\">");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%s%u", t ? "," : "", m->top[t] + 1);
    fprintf(out, "</NodeSet>\n");
    for (size_t t = 0; m->pp && t < m->ntop; t++)
        fprintf(out, "\t\t<NodeSet name=\"p%u\">%u</NodeSet>\n", m->top[t] + 1, m->top[t] + 1);
}

/* The drive in Boundary: the top nodes together along z (load controller 1), or a body's probe
** replayed, each node of its contact set along z on its own curve (load controller t + 2). */
static void febio_drive(FILE *out, const cf_xmodel *m)
{
    if (m->pp) /* a body's probe replayed: each node its own curve (load controller t + 2) */
        for (size_t t = 0; t < m->ntop; t++)
            fprintf(out, "\t\t<bc name=\"probe%u\" node_set=\"p%u\" type=\"prescribed "
                         "displacement\">\n\t\t\t<dof>z</dof>\n\t\t\t<value lc=\"%zu\">1</value>\n"
                         "\t\t\t<relative>0</relative>\n\t\t</bc>\n",
                    m->top[t] + 1, m->top[t] + 1, t + 2);
    else
        fprintf(out, "\t\t<bc name=\"drive\" node_set=\"top\" type=\"prescribed displacement\">\n"
                     "\t\t\t<dof>z</dof>\n\t\t\t<value lc=\"1\">1</value>\n"
                     "\t\t\t<relative>0</relative>\n\t\t</bc>\n");
}

/* A body's replayed probe: each node's z displacement as conifit solved it at every step (a node
** outside the step's contact set where conifit's equilibrium has it, its reaction zero). */
static void febio_probe_curves(FILE *out, const cf_xmodel *m)
{
    for (size_t t = 0; m->pp && t < m->ntop; t++) {
        fprintf(out, "\t\t<load_controller id=\"%zu\" name=\"probe%u\" type=\"loadcurve\">\n"
                     "\t\t\t<interpolate>LINEAR</interpolate>\n\t\t\t<points>\n"
                     "\t\t\t\t<pt>0,0</pt>\n",
                t + 2, m->top[t] + 1);
        for (size_t k = 0; k < m->nsteps; k++)
            fprintf(out, "\t\t\t\t<pt>%zu,%.17g</pt>\n", k + 1, m->udz_mm[k * m->ntop + t]);
        fprintf(out, "\t\t\t</points>\n\t\t</load_controller>\n");
    }
}

/* An FEBio 4 model, written in the order of its sections (Module, Control, Mesh with nodes,
** node sets and the discrete set, MeshDomains, Boundary, Discrete, LoadData, Output). Long only
** because the file is; each section is a few fprintf calls. */
int cf_xmodel_write_febio(FILE *out, const cf_xmodel *m)
{
    char log[8 * CF_EXPORT_LOG_STEM_MAX];
    cf_export_febio_log_name(log, sizeof log, m->output);
    fprintf(out, "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n");
    cf_xmodel_header(out, "<!-- ", " -->", m, "FEBio 4",
                 "febio4 -i NAME.feb (the top reaction: the sum of Rz in the logfile the Output "
                 "section names, beside NAME.feb)");
    /* FEBio's node data file (FECore DataRecord::Write): per converged step the lines
    ** "*Step  = k", "*Time  = t", "*Data  = Rz", then one line "node,Rz" per node of the set.
    ** Rz is the reaction at a prescribed degree of freedom, the force the constraint applies to
    ** the node (FEBioMechData.cpp FENodeForceZ from FESolidSolver2's m_Fr, which the residual
    ** assembly fills with minus the springs' forces on the node). */
    fprintf(out,
            "<!-- reading the result: the logfile holds, per converged step, the lines '*Step = "
            "k', '*Time = t', '*Data = Rz' and then one line 'node,Rz' per top node; the top "
            "reaction of step k is the sum of Rz over those lines. Rz is the force the "
            "prescribed displacement applies to the node along z: negative under compression, "
            "so conifit's compressive reaction above is minus that sum -->\n");
    fprintf(out, "<febio_spec version=\"4.0\">\n\t<Module type=\"solid\"/>\n");
    febio_control(out, m);
    febio_volume_material(out, m);
    fprintf(out, "\t<Mesh>\n\t\t<Nodes name=\"conifit_nodes\">\n");
    for (size_t i = 0; i < m->nn; i++)
        fprintf(out, "\t\t\t<node id=\"%zu\">%.17g,%.17g,%.17g</node>\n", i + 1, m->X[i], m->Y[i],
                m->Z[i]);
    fprintf(out, "\t\t</Nodes>\n");
    febio_volume_elements(out, m);
    febio_node_sets(out, m);
    for (size_t g = 0; g < m->ng; g++) {
        fprintf(out, "\t\t<DiscreteSet name=\"G%zu\">\n", g + 1);
        for (size_t s = 0; s < m->ns; s++)
            if (m->grp[s] == g)
                fprintf(out, "\t\t\t<delem>%u,%u</delem>\n", m->si[s] + 1, m->sj[s] + 1);
        fprintf(out, "\t\t</DiscreteSet>\n");
    }
    /* FEBio 4 builds the mesh (nodes, sets, degrees of freedom) when it reads MeshDomains
    ** (FEBioMeshDomainsSection4::Parse), even an empty one; without it the discrete and node sets
    ** named below are not found. */
    if (m->kappa_MPa > 0 && m->nt > 0)
        fprintf(out, "\t</Mesh>\n\t<MeshDomains>\n\t\t<SolidDomain name=\"volume\" "
                     "mat=\"volume\" elem_type=\"ut4\">\n\t\t\t<alpha>0</alpha>\n"
                     "\t\t</SolidDomain>\n\t</MeshDomains>\n\t<Boundary>\n");
    else if (m->kappa_MPa > 0 && m->ncells > 0)
        fprintf(out, "\t</Mesh>\n\t<MeshDomains>\n\t\t<SolidDomain name=\"volume\" "
                     "mat=\"volume\"/>\n\t</MeshDomains>\n\t<Boundary>\n");
    else
        fprintf(out, "\t</Mesh>\n\t<MeshDomains/>\n\t<Boundary>\n");
    for (unsigned mask = 1; mask < 8; mask++) {
        size_t cnt = 0;
        for (size_t i = 0; i < m->nn; i++)
            cnt += (m->fix[i] & 7u) == mask;
        if (!cnt)
            continue;
        fprintf(out, "\t\t<bc name=\"%s\" node_set=\"%s\" type=\"zero displacement\">\n"
                     "\t\t\t<x_dof>%d</x_dof>\n\t\t\t<y_dof>%d</y_dof>\n\t\t\t<z_dof>%d</z_dof>\n"
                     "\t\t</bc>\n",
                cf_xmodel_mask_name[mask], cf_xmodel_mask_name[mask], !!(mask & 1u), !!(mask & 2u), !!(mask & 4u));
    }
    febio_drive(out, m);
    fprintf(out, "\t</Boundary>\n");
    fprintf(out, "\t<Discrete>\n");
    for (size_t g = 0; g < m->ng; g++) {
        fprintf(out, "\t\t<discrete_material id=\"%zu\" name=\"G%zu\" type=\"nonlinear spring\">\n"
                     "\t\t\t<scale>1</scale>\n\t\t\t<measure>elongation</measure>\n"
                     "\t\t\t<force type=\"point\">\n\t\t\t\t<interpolate>LINEAR</interpolate>\n"
                     "\t\t\t\t<extend>CONSTANT</extend>\n\t\t\t\t<points>\n",
                g + 1, g + 1);
        for (size_t i = 0; i < m->g[g].rows; i++)
            fprintf(out, "\t\t\t\t\t<pt>%.17g,%.17g</pt>\n", m->g[g].e_mm[i], m->g[g].T_N[i]);
        fprintf(out, "\t\t\t\t</points>\n\t\t\t</force>\n\t\t</discrete_material>\n");
    }
    for (size_t g = 0; g < m->ng; g++)
        fprintf(out, "\t\t<discrete dmat=\"%zu\" discrete_set=\"G%zu\"/>\n", g + 1, g + 1);
    fprintf(out, "\t</Discrete>\n\t<LoadData>\n\t\t<load_controller id=\"1\" name=\"drive\" "
                 "type=\"loadcurve\">\n\t\t\t<interpolate>LINEAR</interpolate>\n"
                 "\t\t\t<points>\n\t\t\t\t<pt>0,0</pt>\n");
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, "\t\t\t\t<pt>%zu,%.17g</pt>\n", k + 1, m->dz_mm[k]);
    fprintf(out, "\t\t\t</points>\n\t\t</load_controller>\n");
    febio_probe_curves(out, m);
    fprintf(out, "\t</LoadData>\n");
    fprintf(out, "\t<Output>\n\t\t<logfile>\n\t\t\t<node_data data=\"Rz\" delim=\",\" "
                 "file=\"%s\" node_set=\"top\"/>\n\t\t</logfile>\n\t</Output>\n", log);
    fprintf(out, "</febio_spec>\n");
    return 0;
}
