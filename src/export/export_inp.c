/*
** Runnable models for CalculiX and Abaqus (export_model.h).
** What the target reads, as checked against its documentation and source:
** - CalculiX ccx: SPRINGA elements with *SPRING, NONLINEAR take (force, elongation) pairs; ccx
**   holds the force constant past the last pair, and copies the curve into a fixed array of 200
**   pairs (materialdata_sp.f, plconloc(802)), hence the 200-row limit. *NODE PRINT with TOTALS
**   prints the summed reaction of a node set for every increment.
** - Abaqus/Standard reads the same *SPRING layout (ccx took its input language from it).
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/lattice.h"
#include "model/lattice_hourglass.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

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
    cf_export_inp_real(d1, 2.0 / m->kappa_MPa);
    fprintf(out, "*MATERIAL, NAME=CONIFIT_VOLUME\n*HYPERELASTIC, NEO HOOKE\n0., %s\n", d1);
    fprintf(out, "*SOLID SECTION, ELSET=CELLS, MATERIAL=CONIFIT_VOLUME\n");
}

/* The held components (after *BOUNDARY or *BOUNDARY, OP=NEW), and with a nodal volume term the
** unused directions 2 and 3 of its auxiliary nodes. */
static void write_inp_held_lines(FILE *out, const cf_xmodel *m)
{
    for (size_t i = 0; i < m->nn; i++)
        for (int a = 0; a < 3; a++)
            if (m->fix[i] & (1u << a))
                fprintf(out, "%zu, %d, %d\n", i + 1, a + 1, a + 1);
    cf_xmodel_inp_volume_held(out, m);
}

static void write_inp_held(FILE *out, const cf_xmodel *m)
{
    fprintf(out, "*BOUNDARY\n");
    write_inp_held_lines(out, m);
}

/* A body's probe as conifit's penalty contact with its contact set replayed: each node ever in
** contact (top) is tied along z by a SPRING2 of conifit's penalty stiffness to a node of the
** punch's face (numbered after the body's nodes and the volume term's auxiliary ones, x and y
** held); one *STEP per load step moves each face node to the face at that depth when its body
** node is in conifit's contact set, and to where the spring is slack (the node's solved z) when
** it is not. The reaction is summed over the face nodes (NFACE): the springs' forces, the probe
** force however the body carries it (the volume term's equations included, whose forces ccx
** leaves out of a body node's RF). */
static void write_inp_probe_steps(FILE *out, const cf_xmodel *m, int abaqus)
{
    const size_t f0 = m->nn + cf_xmodel_inp_volume_nodes(m); /* face node t: f0 + t + 1 */
    fprintf(out, "** the punch's face: node %zu + t tied to the t-th node of NTOP along z by a "
                 "spring of conifit's penalty stiffness; the probe force of a step is minus the z "
                 "total of the reaction of set NFACE ('total force ... for set NFACE' in "
                 "NAME.dat)\n*NODE, NSET=NFACE\n", f0 + 1);
    for (size_t t = 0; t < m->ntop; t++) {
        char x[32], y[32], z[32];
        cf_export_inp_real(x, m->X[m->top[t]]);
        cf_export_inp_real(y, m->Y[m->top[t]]);
        cf_export_inp_real(z, m->Z[m->top[t]]);
        fprintf(out, "%zu, %s, %s, %s\n", f0 + t + 1, x, y, z);
    }
    const size_t e0 = m->ns + cf_xmodel_inp_volume_nodes(m);
    fprintf(out, "*ELEMENT, TYPE=SPRING2, ELSET=PROBE\n");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%zu, %u, %zu\n", e0 + t + 1, m->top[t] + 1, f0 + t + 1);
    char kp[32];
    cf_export_inp_real(kp, m->kp_N_per_mm);
    fprintf(out, "*SPRING, ELSET=PROBE\n3, 3\n%s\n", kp);
    cf_xmodel_inp_fibres(out, m, f0 + m->ntop, e0 + m->ntop);
    write_inp_held(out, m);
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%zu, 1, 2\n", f0 + t + 1);
    for (size_t k = 0; k < m->nsteps; k++) {
        fprintf(out, "*STEP, NLGEOM%s, INC=1000\n*STATIC\n1., 1.\n", abaqus ? "=YES" : "");
        fprintf(out, "*CONTROLS, PARAMETERS=FIELD%s\n%s", abaqus ? ", FIELD=DISPLACEMENT" : "",
                inp_controls);
        cf_xmodel_inp_volume_step(out, m, k);
        fprintf(out, "** step %zu: %zu nodes in conifit's contact set (NC%zu); the face nodes of "
                     "the others where their springs are slack\n*BOUNDARY\n",
                k + 1, m->pp[k + 1] - m->pp[k], k + 1);
        for (size_t t = 0; t < m->ntop; t++) {
            char dz[32];
            cf_export_inp_real(dz, m->fdz_mm[k * m->ntop + t]);
            fprintf(out, "%zu, 3, 3, %s\n", f0 + t + 1, dz);
        }
        fprintf(out, "*NODE PRINT, NSET=NFACE, TOTALS=ONLY\nRF\n*END STEP\n");
    }
}

/* The node sets of a replayed probe: NC<k> the contact set of step k (steps without contact have
** none). */
static void write_inp_probe_sets(FILE *out, const cf_xmodel *m)
{
    for (size_t k = 0; m->pp && k < m->nsteps; k++) {
        const size_t n = m->pp[k + 1] - m->pp[k];
        if (!n)
            continue;
        fprintf(out, "*NSET, NSET=NC%zu\n", k + 1);
        for (size_t q = 0; q < n; q++)
            fprintf(out, "%u%s", m->pn[m->pp[k] + q] + 1, (q % 16 == 15 || q + 1 == n) ? "\n" : ", ");
    }
}

/* The hourglass control (lattice_hourglass.h): per cell and mode i an extra node (numbers after
** the lattice's, at the cell's first corner) whose displacement along each axis *EQUATION sets to
** q_i = sum_a h_i(a)/8 u_a (q_i is F sum gamma X + sum gamma c = 0 for affine motion, and
** sum_a gamma_a X_a = 0, so it is the same in displacements as in positions), held by a grounded
** SPRING1 of stiffness k_h on each axis (element numbers after the springs' and the cells'): the
** energy (k_h/2) sum_i |q_i|^2, exactly. */
static void write_inp_hourglass(FILE *out, const cf_xmodel *m)
{
    const size_t n0 = m->nn, e0 = m->ns + (m->kappa_MPa > 0 ? m->ncells : 0);
    fprintf(out, "** hourglass control: k_h = %.17g N/mm on each of the 4 modes of every cell\n",
            m->hg_k_N_per_mm);
    fprintf(out, "*NODE, NSET=NHOURGLASS\n");
    for (size_t c = 0; c < m->ncells; c++)
        for (int i = 0; i < 4; i++) {
            char x[32], y[32], z[32];
            const uint32_t p = m->cell[8 * c];
            cf_export_inp_real(x, m->X[p]);
            cf_export_inp_real(y, m->Y[p]);
            cf_export_inp_real(z, m->Z[p]);
            fprintf(out, "%zu, %s, %s, %s\n", n0 + 4 * c + (size_t)i + 1, x, y, z);
        }
    fprintf(out, "*EQUATION\n");
    for (size_t c = 0; c < m->ncells; c++)
        for (int i = 0; i < 4; i++)
            for (int d = 1; d <= 3; d++) {
                fprintf(out, "9\n%zu, %d, -1.", n0 + 4 * c + (size_t)i + 1, d);
                for (int a = 0; a < 8; a++)
                    fprintf(out, "%s%u, %d, %s", a % 4 == 3 ? "\n" : ", ", m->cell[8 * c + a] + 1,
                            d, cf_hourglass_pattern(i, a) > 0 ? "0.125" : "-0.125");
                fputc('\n', out);
            }
    char k[32];
    cf_export_inp_real(k, m->hg_k_N_per_mm);
    for (int d = 1; d <= 3; d++) {
        fprintf(out, "*ELEMENT, TYPE=SPRING1, ELSET=HOURGLASS%d\n", d);
        for (size_t h = 0; h < 4 * m->ncells; h++)
            fprintf(out, "%zu, %zu\n", e0 + (size_t)(d - 1) * 4 * m->ncells + h + 1, n0 + h + 1);
        fprintf(out, "*SPRING, ELSET=HOURGLASS%d\n%d\n%s\n", d, d, k);
    }
}

/* A lattice with fibres: the fibres (after the hourglass nodes and springs), and the top driven
** through stiff springs. ccx leaves the forces an *EQUATION carries to a node out of its RF, and
** the fibres' equations reach the top nodes; so each top node is tied along z by a SPRING2 of
** stiffness k_d to a driver node (set NDRIVE, x and y held) that the steps move, and the reaction
** is summed over the drivers. k_d is 1e7 times the lattice's largest secant stiffness
** max |R_k / dz_k|, so that a top node lags its driver by at most 1e-7 of the step's travel. */
static void write_inp_lattice_fibres(FILE *out, const cf_xmodel *m, int abaqus)
{
    const size_t hg = m->hg_k_N_per_mm > 0 ? 4 * m->ncells : 0;
    const size_t n0 = m->nn + hg + 2 * m->nfib;
    const size_t e0 = m->ns + (m->kappa_MPa > 0 ? m->ncells : 0) + 3 * hg + m->nfib;
    cf_xmodel_inp_fibres(out, m, m->nn + hg, e0 - m->nfib);
    double kd = 0;
    for (size_t k = 0; k < m->nsteps; k++)
        if (m->dz_mm[k] != 0)
            kd = fmax(kd, 1e7 * fabs(m->ref_N[k] / m->dz_mm[k]));
    if (!(kd > 0))
        kd = 1e7;
    fprintf(out, "** the top driven through springs of %.6g N/mm along z (the fibres' equations "
                 "reach the top nodes, and ccx leaves an equation's forces out of a node's RF): the "
                 "reaction of a step is the z total of set NDRIVE ('total force ... for set "
                 "NDRIVE' in NAME.dat)\n*NODE, NSET=NDRIVE\n", kd);
    for (size_t t = 0; t < m->ntop; t++) {
        char x[32], y[32], z[32];
        cf_export_inp_real(x, m->X[m->top[t]]);
        cf_export_inp_real(y, m->Y[m->top[t]]);
        cf_export_inp_real(z, m->Z[m->top[t]]);
        fprintf(out, "%zu, %s, %s, %s\n", n0 + t + 1, x, y, z);
    }
    fprintf(out, "*ELEMENT, TYPE=SPRING2, ELSET=DRIVE\n");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%zu, %u, %zu\n", e0 + t + 1, m->top[t] + 1, n0 + t + 1);
    char k[32];
    cf_export_inp_real(k, kd);
    fprintf(out, "*SPRING, ELSET=DRIVE\n3, 3\n%s\n", k);
    write_inp_held(out, m);
    fprintf(out, "NDRIVE, 1, 2\n");
    for (size_t s = 0; s < m->nsteps; s++) {
        fprintf(out, "*STEP, NLGEOM%s, INC=1000\n*STATIC\n1., 1.\n", abaqus ? "=YES" : "");
        fprintf(out, "*CONTROLS, PARAMETERS=FIELD%s\n%s", abaqus ? ", FIELD=DISPLACEMENT" : "",
                inp_controls);
        char dz[32];
        cf_export_inp_real(dz, m->dz_mm[s]);
        fprintf(out, "*BOUNDARY\nNDRIVE, 3, 3, %s\n", dz);
        fprintf(out, "*NODE PRINT, NSET=NDRIVE, TOTALS=ONLY\nRF\n*END STEP\n");
    }
}

static int write_inp(FILE *out, const cf_xmodel *m, int abaqus)
{
    const char *target = abaqus ? "Abaqus/Standard" : "CalculiX (ccx)";
    cf_xmodel_header(out, "** ", "", m, target,
                 abaqus ? "abaqus job=NAME (summed top reaction RF3 in NAME.dat per increment)"
                        : "ccx -i NAME (summed top reaction in NAME.dat, 'total force' lines)");
    fprintf(out, "*NODE, NSET=NALL\n");
    for (size_t i = 0; i < m->nn; i++) {
        char x[32], y[32], z[32];
        cf_export_inp_real(x, m->X[i]);
        cf_export_inp_real(y, m->Y[i]);
        cf_export_inp_real(z, m->Z[i]);
        fprintf(out, "%zu, %s, %s, %s\n", i + 1, x, y, z);
    }
    fprintf(out, "*NSET, NSET=NTOP\n");
    for (size_t t = 0; t < m->ntop; t++)
        fprintf(out, "%u%s", m->top[t] + 1, (t % 16 == 15 || t + 1 == m->ntop) ? "\n" : ", ");
    write_inp_probe_sets(out, m);
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
    if (m->nt > 0 && m->kappa_MPa > 0) { /* a body's nodal volume term */
        if (cf_xmodel_inp_nodal_volume(out, m) != 0)
            return -1;
    }
    else if (m->kappa_MPa > 0) /* a lattice's cells */
        write_inp_volume(out, m);
    if (m->nt == 0 && m->hg_k_N_per_mm > 0)
        write_inp_hourglass(out, m);
    if (m->nt > 0 && m->elem) /* after the springs', the volume term's, the probe's and fibres' */
        cf_xmodel_inp_elem(out, m, m->ns + cf_xmodel_inp_volume_nodes(m) + m->ntop + m->nfib);
    if (m->nt == 0 && m->nfib > 0) { /* a lattice's fibres: after the hourglass nodes and springs */
        write_inp_lattice_fibres(out, m, abaqus);
        return 0;
    }
    if (m->pp) {
        write_inp_probe_steps(out, m, abaqus);
        return 0;
    }
    write_inp_held(out, m);
    for (size_t k = 0; k < m->nsteps; k++) {
        fprintf(out, "*STEP, NLGEOM%s, INC=1000\n*STATIC\n1., 1.\n", abaqus ? "=YES" : "");
        fprintf(out, "*CONTROLS, PARAMETERS=FIELD%s\n%s", abaqus ? ", FIELD=DISPLACEMENT" : "",
                inp_controls);
        char dz[32];
        cf_export_inp_real(dz, m->dz_mm[k]);
        fprintf(out, "*BOUNDARY\nNTOP, 3, 3, %s\n", dz);
        fprintf(out, "*NODE PRINT, NSET=NTOP, TOTALS=ONLY\nRF\n*END STEP\n");
    }
    return 0;
}

int cf_xmodel_write_calculix(FILE *out, const cf_xmodel *m)
{
    return write_inp(out, m, 0);
}

int cf_xmodel_write_abaqus(FILE *out, const cf_xmodel *m)
{
    return write_inp(out, m, 1);
}
