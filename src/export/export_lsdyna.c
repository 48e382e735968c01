/*
** Runnable models for LS-DYNA (export_model.h).
** What the target reads, as checked against its documentation and source:
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
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/lattice.h"
#include "conifit/spring.h"
#include "conifit/version.h"
#include "base/safetext.h"

/* ---- LS-DYNA ---------------------------------------------------------------------------------- */

/* LS-DYNA's translational constraint code of *NODE (TC) for a fixed-direction mask. */
static int dyna_tc(unsigned mask)
{
    static const int tc[8] = {0, 1, 2, 4, 3, 6, 5, 7};
    return tc[mask & 7u];
}

int cf_xmodel_write_lsdyna(FILE *out, const cf_xmodel *m)
{
    cf_xmodel_header(out, "$ ", "", m, "LS-DYNA (implicit static)",
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
