/*
** Runnable models for other simulators (see export_model.h): one writer per target, each
** writing nodes, one spring group per (rest length, weight) with its own table, the boundary
** conditions, the load steps and the output requests in that code's own syntax.
**
** What each target reads, as checked against its documentation and source:
** - CalculiX ccx: SPRINGA elements with *SPRING, NONLINEAR take (force, elongation) pairs; ccx
**   holds the force constant past the last pair, and copies the curve into a fixed array of 200
**   pairs (materialdata_sp.f, plconloc(802)), hence the 200-row limit. *NODE PRINT with TOTALS
**   prints the summed reaction of a node set for every increment.
** - Abaqus/Standard reads the same *SPRING layout (ccx took its input language from it).
** - FEBio 4: discrete_material type "nonlinear spring" with measure "elongation" and a point
**   curve (extend CONSTANT holds the last force), discrete sets in the Mesh section resolved by
**   name when the Discrete section is read (FEBioDiscreteSection25::Parse), after MeshDomains has
**   built the mesh; "zero displacement" and "prescribed displacement" boundary conditions on
**   named node sets, a load controller, a logfile of node data on a node set.
** - LS-DYNA: *MAT_SPRING_NONLINEAR_ELASTIC (MAT_S04) on *ELEMENT_DISCRETE; every *DEFINE_CURVE is
**   rediscretized to LCINT equally spaced points between its first and last abscissa, 100 unless
**   the curve's own LCINT (field 8 of its first card, since 2015) or *CONTROL_SOLUTION says
**   otherwise (LSTC FAQ "discretization of curves"; *DEFINE_CURVE remark 1). An adaptive table
**   with LCINT = rows is still resampled: its rows crowd towards solid, the even points do not
**   (measured on the shipped fits: 8 to 26 % of F_C off near solid, all but the nearly
**   cylindrical one). So the curves are evenly spaced with LCINT = rows, which the
**   rediscretization gives back (export_table.c, cf_export_table_build_even), over the range
**   where CF_EXPORT_LSDYNA_MAX_ROWS rows meet the tolerance. Past a curve's ends LS-DYNA
**   continues its end segments' slope (as d3view's note "Modeling symmetric/unsymmetric
**   nonlinear discrete springs", 2006, describes), not the law's stop at solid.
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

#include "conifit/lattice.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

void cf_xmodel_free(cf_xmodel *m)
{
    if (!m)
        return;
    free(m->X), free(m->Y), free(m->Z), free(m->fix);
    free(m->si), free(m->sj), free(m->grp), free(m->top);
    free(m->dz_mm), free(m->ref_N), free(m->strain), free(m->cell);
    for (size_t g = 0; g < m->ng && m->g; g++)
        free(m->g[g].e_mm), free(m->g[g].T_N);
    free(m->g);
    memset(m, 0, sizeof *m);
}

int cf_xmodel_tables(cf_xmodel *m)
{
    const cf_export_table *t = m->base;
    const double H = m->law->p.H_mm;
    for (size_t g = 0; g < m->ng; g++) {
        cf_xgroup *G = &m->g[g];
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

/* A real for CalculiX/Abaqus input: at most 20 characters (ccx reads a number from a field of
** 20 characters), always with a decimal point, with as many significant digits as fit (17, or 14
** for a negative number with an exponent). */
static void inp_real(char buf[32], double x)
{
    if (x == 0.0)
        x = 0.0; /* no "-0" */
    for (int p = 17; p >= 8; p--) {
        char t[40];
        snprintf(t, sizeof t, "%.*g", p, x);
        char *e = strpbrk(t, "eE");
        if (!strchr(t, '.')) { /* 40 -> 40.  1e-05 -> 1.e-05 */
            char tail[40];
            snprintf(tail, sizeof tail, "%s", e ? e : "");
            if (e)
                *e = '\0';
            strcat(t, ".");
            strcat(t, tail);
        }
        if (strlen(t) <= 20) {
            memcpy(buf, t, strlen(t) + 1);
            return;
        }
    }
    snprintf(buf, 32, "%.8e", x);
}

void cf_export_inp_pair(FILE *out, double force_N, double elongation_mm)
{
    char a[32], b[32];
    inp_real(a, force_N);
    inp_real(b, elongation_mm);
    fprintf(out, "%s, %s\n", a, b);
}

/* ---- comments shared by the writers ---------------------------------------------------------- */

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

static void model_header(FILE *out, const char *lead, const char *tail, const cf_xmodel *m,
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
    for (size_t g = 0; g < m->ng; g++)
        fprintf(out, "%s  group %zu: L0 = %.17g mm, weight = %.17g, %zu springs, %zu rows%s\n",
                lead, g + 1, m->g[g].L0_mm, m->g[g].weight, m->g[g].count, m->g[g].rows, tail);
    fprintf(out,
            "%sloading: the %zu top nodes move along z together (x, y free unless fixed); at each "
            "step, conifit's compressive top reaction (N) for comparison:%s\n",
            lead, m->ntop, tail);
    fprintf(out,
            "%sreaction tolerance implied by the tables: %.6g N (tol F_C times the weights of "
            "the springs a horizontal plane cuts, projected on z)%s\n",
            lead, m->reaction_tol_N, tail);
    if (m->kappa_MPa > 0)
        fprintf(out,
                "%svolume term: each of the %zu %s stores (kappa/2)(J - 1)^2 of its rest "
                "volume, kappa = %.17g MPa, J its volume over its rest volume%s\n",
                lead, m->nt > 0 ? m->nt : m->ncells, m->nt > 0 ? "tetrahedra" : "cells",
                m->kappa_MPa, tail);
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, "%s  step %zu: top z displacement %.17g mm (strain %.10g), conifit reaction "
                     "%.17g N%s\n",
                lead, k + 1, m->dz_mm[k], m->strain[k], m->ref_N[k], tail);
}

/* ---- CalculiX and Abaqus ---------------------------------------------------------------------- */

/* Convergence: the residual force criterion R_n tightened from its default 0.005 of the mean force
** so that the reaction is converged far below the table's tolerance; the other entries are the
** defaults of the *CONTROLS, PARAMETERS=FIELD line. */
static const char inp_controls[] = "1.e-9,1.e-6,0.01,,0.02,1.e-5,1.e-3,1.e-8\n";

/* The volume term as one C3D8 hexahedron per cell (element numbers after the springs') of a
** neo-Hookean material with no shear term: W = C10 (I1bar - 3) + (1/D1)(J - 1)^2 with C10 = 0
** and D1 = 2/kappa is (kappa/2)(J - 1)^2 (CalculiX and Abaqus manuals, *HYPERELASTIC). The
** element integrates it at its 2 x 2 x 2 Gauss points, conifit over the cell's volume from its
** eight nodes: the same wherever J is uniform over a cell (the homogeneous loading of the
** export). */
static void write_inp_volume(FILE *out, const cf_xmodel *m)
{
    static const int order[8] = {0, 1, 3, 2, 4, 5, 7, 6}; /* corner di + 2 dj + 4 dk -> C3D8 */
    fprintf(out, "** volume term: kappa = %.17g MPa on every cell\n", m->kappa_MPa);
    fprintf(out, "*ELEMENT, TYPE=C3D8, ELSET=CELLS\n");
    for (size_t c = 0; c < m->ncells; c++) {
        fprintf(out, "%zu", m->ns + c + 1);
        for (int a = 0; a < 8; a++)
            fprintf(out, ", %u", m->cell[8 * c + order[a]] + 1);
        fputc('\n', out);
    }
    char d1[32];
    inp_real(d1, 2.0 / m->kappa_MPa);
    fprintf(out, "*MATERIAL, NAME=CONIFIT_VOLUME\n*HYPERELASTIC, NEO HOOKE\n0., %s\n", d1);
    fprintf(out, "*SOLID SECTION, ELSET=CELLS, MATERIAL=CONIFIT_VOLUME\n");
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

static void write_inp(FILE *out, const cf_xmodel *m, int abaqus)
{
    const char *target = abaqus ? "Abaqus/Standard" : "CalculiX (ccx)";
    model_header(out, "** ", "", m, target,
                 abaqus ? "abaqus job=NAME (summed top reaction RF3 in NAME.dat per increment)"
                        : "ccx -i NAME (summed top reaction in NAME.dat, 'total force' lines)");
    fprintf(out, "*NODE, NSET=NALL\n");
    for (size_t i = 0; i < m->nn; i++) {
        char x[32], y[32], z[32];
        inp_real(x, m->X[i]);
        inp_real(y, m->Y[i]);
        inp_real(z, m->Z[i]);
        fprintf(out, "%zu, %s, %s, %s\n", i + 1, x, y, z);
    }
    fprintf(out, "*NSET, NSET=NTOP\n");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%u%s", m->top[t] + 1, (t % 16 == 15 || t + 1 == m->ntop) ? "\n" : ", ");
    for (size_t g = 0; g < m->ng; g++) {
        fprintf(out, "*ELEMENT, TYPE=SPRINGA, ELSET=G%zu\n", g + 1);
        for (size_t s = 0; s < m->ns; s++)
            if (m->grp[s] == g)
                fprintf(out, "%zu, %u, %u\n", s + 1, m->si[s] + 1, m->sj[s] + 1);
        fprintf(out, "** group %zu: L0 = %.17g mm, weight %.17g; force (N), elongation (mm)\n",
                g + 1, m->g[g].L0_mm, m->g[g].weight);
        fprintf(out, "*SPRING, ELSET=G%zu, NONLINEAR\n\n", g + 1);
        for (size_t i = 0; i < m->g[g].rows; i++)
            cf_export_inp_pair(out, m->g[g].T_N[i], m->g[g].e_mm[i]);
    }
    if (m->nt > 0 && m->kappa_MPa > 0) { /* a body's tetrahedra */
        /* W = C10 (I1bar - 3) + (J - 1)^2 / D1: with C10 = 0 and D1 = 2/kappa the volume term */
        fprintf(out, "** the volume term: a purely volumetric material, (kappa/2)(J - 1)^2 per unit "
                     "volume, kappa = %.17g MPa, J per tetrahedron\n",
                m->kappa_MPa);
        fprintf(out, "*ELEMENT, TYPE=C3D4, ELSET=VOLUME\n");
        for (size_t t = 0; t < m->nt; t++)
            fprintf(out, "%zu, %u, %u, %u, %u\n", m->ns + t + 1, m->tet[4 * t] + 1,
                    m->tet[4 * t + 1] + 1, m->tet[4 * t + 2] + 1, m->tet[4 * t + 3] + 1);
        char d1[32];
        inp_real(d1, 2 / m->kappa_MPa);
        fprintf(out, "*MATERIAL, NAME=VOLUME\n*HYPERELASTIC, NEO HOOKE\n0., %s\n"
                     "*SOLID SECTION, ELSET=VOLUME, MATERIAL=VOLUME\n",
                d1);
    }
    else if (m->kappa_MPa > 0) /* a lattice's cells */
        write_inp_volume(out, m);
    fprintf(out, "*BOUNDARY\n");
    for (size_t i = 0; i < m->nn; i++)
        for (int a = 0; a < 3; a++)
            if (m->fix[i] & (1u << a))
                fprintf(out, "%zu, %d, %d\n", i + 1, a + 1, a + 1);
    for (size_t k = 0; k < m->nsteps; k++) {
        fprintf(out, "*STEP, NLGEOM%s, INC=1000\n*STATIC\n1., 1.\n", abaqus ? "=YES" : "");
        fprintf(out, "*CONTROLS, PARAMETERS=FIELD%s\n%s", abaqus ? ", FIELD=DISPLACEMENT" : "",
                inp_controls);
        char dz[32];
        inp_real(dz, m->dz_mm[k]);
        fprintf(out, "*BOUNDARY\nNTOP, 3, 3, %s\n", dz);
        fprintf(out, "*NODE PRINT, NSET=NTOP, TOTALS=ONLY\nRF\n*END STEP\n");
    }
}

int cf_xmodel_write_calculix(FILE *out, const cf_xmodel *m)
{
    write_inp(out, m, 0);
    return 0;
}

int cf_xmodel_write_abaqus(FILE *out, const cf_xmodel *m)
{
    write_inp(out, m, 1);
    return 0;
}

/* ---- FEBio 4 ---------------------------------------------------------------------------------- */

/* The fixed-direction masks that occur, in a fixed order, with FEBio set names. */
static const char *const mask_name[8] = {"", "fix_x", "fix_y", "fix_xy",
                                         "fix_z", "fix_xz", "fix_yz", "fix_xyz"};

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
** elements (J per tetrahedron, as in CalculiX's C3D4; conifit takes J per node); a lattice's cells
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
            m->kappa_MPa, m->nt > 0 ? "tetrahedron (conifit's body takes J per node)"
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

/* An FEBio 4 model, written in the order of its sections (Module, Control, Mesh with nodes,
** node sets and the discrete set, MeshDomains, Boundary, Discrete, LoadData, Output). Long only
** because the file is; each section is a few fprintf calls. */
int cf_xmodel_write_febio(FILE *out, const cf_xmodel *m)
{
    char log[8 * CF_EXPORT_LOG_STEM_MAX];
    cf_export_febio_log_name(log, sizeof log, m->output);
    fprintf(out, "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n");
    model_header(out, "<!-- ", " -->", m, "FEBio 4",
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
    for (unsigned mask = 1; mask < 8; mask++) {
        size_t cnt = 0;
        for (size_t i = 0; i < m->nn; i++)
            cnt += (m->fix[i] & 7u) == mask;
        if (!cnt)
            continue;
        fprintf(out, "\t\t<NodeSet name=\"%s\">", mask_name[mask]);
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
    if (m->kappa_MPa > 0 && (m->nt > 0 || m->ncells > 0))
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
                mask_name[mask], mask_name[mask], !!(mask & 1u), !!(mask & 2u), !!(mask & 4u));
    }
    fprintf(out, "\t\t<bc name=\"drive\" node_set=\"top\" type=\"prescribed displacement\">\n"
                 "\t\t\t<dof>z</dof>\n\t\t\t<value lc=\"1\">1</value>\n"
                 "\t\t\t<relative>0</relative>\n\t\t</bc>\n\t</Boundary>\n");
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
    fprintf(out, "\t\t\t</points>\n\t\t</load_controller>\n\t</LoadData>\n");
    fprintf(out, "\t<Output>\n\t\t<logfile>\n\t\t\t<node_data data=\"Rz\" delim=\",\" "
                 "file=\"%s\" node_set=\"top\"/>\n\t\t</logfile>\n\t</Output>\n", log);
    fprintf(out, "</febio_spec>\n");
    return 0;
}

/* ---- LS-DYNA ---------------------------------------------------------------------------------- */

/* LS-DYNA's translational constraint code of *NODE (TC) for a fixed-direction mask. */
static int dyna_tc(unsigned mask)
{
    static const int tc[8] = {0, 1, 2, 4, 3, 6, 5, 7};
    return tc[mask & 7u];
}

int cf_xmodel_write_lsdyna(FILE *out, const cf_xmodel *m)
{
    model_header(out, "$ ", "", m, "LS-DYNA (implicit static)",
                 "ls-dyna i=NAME.k (top reaction: spcforc / bndout of the prescribed motion)");
    cf_export_comment_even(out, "$ ", "", m->base, m->law);
    fprintf(out, "*KEYWORD\n*TITLE\nconifit %s\n", m->title);
    fprintf(out, "*CONTROL_TERMINATION\n$#  endtim\n%10.1f\n", (double)m->nsteps);
    fprintf(out, "*CONTROL_IMPLICIT_GENERAL\n$#  imflag       dt0\n%10d%10.1f\n", 1, 1.0);
    fprintf(out, "*CONTROL_IMPLICIT_SOLUTION\n$#  nsolvr    ilimit    maxref     dctol     ectol"
                 "     rctol\n%10d%10d%10d%10.1e%10.1e%10.1e\n",
            12, 11, 50, 1e-9, 1e-12, 1e-12);
    fprintf(out, "*DATABASE_BNDOUT\n$#      dt\n%10.1f\n", 1.0);
    fprintf(out, "*DATABASE_SPCFORC\n$#      dt\n%10.1f\n", 1.0);
    fprintf(out, "*NODE\n$#   nid               x               y               z      tc      "
                 "rc\n");
    for (size_t i = 0; i < m->nn; i++)
        fprintf(out, "%8zu%16.9e%16.9e%16.9e%8d%8d\n", i + 1, m->X[i], m->Y[i], m->Z[i],
                dyna_tc(m->fix[i]), 7);
    fprintf(out, "*SECTION_DISCRETE\n$#   secid       dro\n%10d%10d\n", 1, 0);
    for (size_t g = 0; g < m->ng; g++) {
        const cf_xgroup *G = &m->g[g];
        fprintf(out, "$ group %zu: L0 = %.17g mm, weight %.17g\n", g + 1, G->L0_mm, G->weight);
        fprintf(out, "*PART\ngroup %zu\n$#     pid     secid       mid\n%10zu%10d%10zu\n", g + 1,
                g + 1, 1, g + 1);
        fprintf(out, "*MAT_SPRING_NONLINEAR_ELASTIC\n$#     mid       lcd       lcr\n%10zu%10zu%10d\n",
                g + 1, g + 1, 0);
        fprintf(out, "*DEFINE_CURVE\n$#    lcid      sidr       sfa       sfo      offa      offo"
                     "    dattyp     lcint\n");
        fprintf(out, "%10zu%10d%10.1f%10.1f%10.1f%10.1f%10d%10zu\n", g + 1, 0, 1.0, 1.0, 0.0, 0.0,
                0, G->rows);
        fprintf(out, "$#                a1                  o1\n");
        for (size_t i = 0; i < G->rows; i++)
            fprintf(out, "%20.12e%20.12e\n", G->e_mm[i], G->T_N[i]);
    }
    fprintf(out, "*ELEMENT_DISCRETE\n$#   eid     pid      n1      n2\n");
    for (size_t s = 0; s < m->ns; s++)
        fprintf(out, "%8zu%8u%8u%8u\n", s + 1, m->grp[s] + 1, m->si[s] + 1, m->sj[s] + 1);
    fprintf(out, "*SET_NODE_LIST\n$#     sid\n%10d\n", 1);
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%10u%s", m->top[t] + 1, (t % 8 == 7 || t + 1 == m->ntop) ? "\n" : "");
    const size_t lc_drive = m->ng + 1;
    fprintf(out, "*BOUNDARY_PRESCRIBED_MOTION_SET\n$#    nsid       dof       vad      lcid        "
                 "sf\n%10d%10d%10d%10zu%10.1f\n",
            1, 3, 2, lc_drive, 1.0);
    fprintf(out, "*DEFINE_CURVE\n$#    lcid      sidr       sfa       sfo      offa      offo    "
                 "dattyp     lcint\n%10zu%10d%10.1f%10.1f%10.1f%10.1f%10d%10zu\n",
            lc_drive, 0, 1.0, 1.0, 0.0, 0.0, 0, m->nsteps + 1);
    fprintf(out, "%20.12e%20.12e\n", 0.0, 0.0);
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, "%20.12e%20.12e\n", (double)(k + 1), m->dz_mm[k]);
    fprintf(out, "*END\n");
    return 0;
}

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
    model_header(out, "<!-- ", " -->", m, "SOFA (v24.06 or later)",
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
                            mask_name[mask], !!(mask & 1u), !!(mask & 2u), !!(mask & 4u));
                fprintf(out, "%s%zu", w > 1 ? " " : "", i);
            }
        if (w)
            fprintf(out, "\"/>\n");
    }
    fprintf(out, "\t\t<PartialLinearMovementProjectiveConstraint name=\"drive\" "
                 "movedDirections=\"0 0 1\" indices=\"");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%s%u", t ? " " : "", m->top[t]);
    fprintf(out, "\" keyTimes=\"0");
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, " %zu", k + 1);
    fprintf(out, "\" movements=\"0 0 0");
    for (size_t k = 0; k < m->nsteps; k++)
        fprintf(out, "  0 0 %.17g", m->dz_mm[k]);
    fprintf(out, "\"/>\n");
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
