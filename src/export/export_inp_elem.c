/*
** A body's element term for CalculiX (export_model.h, cf_xmodel_inp_elem): every tetrahedron a
** C3D4 element with its own material, the tetrahedron's tensor D_t (cf_body_match_elements) as
** *ELASTIC, TYPE=ANISO. What ccx does with it, from its manual and source: a linear elastic
** material in a step with NLGEOM takes the second Piola-Kirchhoff stress as D : E of the
** Green-Lagrange strain E (a Saint Venant-Kirchhoff material), and C3D4 has one integration
** point with a constant F; so each element stores V0/2 E : D_t : E, conifit's element term
** exactly. ccx's 21 constants are tensor components D_ijkl (sigma_ij = D_ijkl eps_kl); with the
** engineering shear strains of conifit's Voigt form (11, 22, 33, 23, 13, 12), entry (a, b) of
** D_t is the component of the index pairs a and b.
*/
#include "export/export_model.h"

/* ccx's order of the 21 constants, as pairs of conifit's Voigt indices. */
static const int aniso_order[21][2] = {
    {0, 0}, {0, 1}, {1, 1}, {0, 2}, {1, 2}, {2, 2}, {0, 5}, {1, 5}, {2, 5}, {5, 5}, {0, 4},
    {1, 4}, {2, 4}, {5, 4}, {4, 4}, {0, 3}, {1, 3}, {2, 3}, {5, 3}, {4, 3}, {3, 3}};

/* 6 x the signed volume of tetrahedron t of m at rest. */
static double vol6(const cf_xmodel *m, const uint32_t *v)
{
    double a[3][3];
    for (int k = 0; k < 3; k++) {
        a[k][0] = m->X[v[k + 1]] - m->X[v[0]];
        a[k][1] = m->Y[v[k + 1]] - m->Y[v[0]];
        a[k][2] = m->Z[v[k + 1]] - m->Z[v[0]];
    }
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

void cf_xmodel_inp_elem(FILE *out, const cf_xmodel *m, size_t e0)
{
    fprintf(out, "** element term: tetrahedron t is element %zu + t (C3D4, set ET<t>) of material "
                 "ET<t>, its tensor (MPa) as *ELASTIC, TYPE=ANISO, a Saint Venant-Kirchhoff "
                 "material under NLGEOM\n", e0);
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tet + 4 * t;
        /* C3D4 wants nodes 1, 2, 3 turning positively seen from node 4's side */
        const int flip = vol6(m, v) < 0;
        fprintf(out, "*ELEMENT, TYPE=C3D4, ELSET=ET%zu\n%zu, %u, %u, %u, %u\n", t + 1, e0 + t + 1,
                v[0] + 1, v[flip ? 2 : 1] + 1, v[flip ? 1 : 2] + 1, v[3] + 1);
        fprintf(out, "*MATERIAL, NAME=ET%zu\n*ELASTIC, TYPE=ANISO\n", t + 1);
        const double *D = m->elem + 36 * t;
        for (int q = 0; q < 21; q++) {
            char c[32];
            cf_export_inp_real(c, D[6 * aniso_order[q][0] + aniso_order[q][1]]);
            fprintf(out, "%s%s", c, q == 20 || q % 8 == 7 ? "\n" : ", ");
        }
        fprintf(out, "*SOLID SECTION, ELSET=ET%zu, MATERIAL=ET%zu\n", t + 1, t + 1);
    }
}
