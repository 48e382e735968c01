/*
** Fibre groups of the cubic lattice and its homogenised cell: embedded springs along a material
** direction (the mean fibre direction f, optionally the sheet direction s), one per lattice cell,
** on top of the cell's 13 node-to-node springs and its volume term.
**
** A group's spring lies along the reference unit vector a (lattice frame) through the cell. Under
** the cell's deformation gradient F it has stretch lambda = |F a| (the same F the volume term
** uses: under a homogeneous deformation it is the lattice's own, so the cell stays exact). Its law
** is a conical spring of free length Hf (the law's H) acting in tension only, the fibre law: at
** stretch lambda > 1 the spring is compressed by u = Hf (lambda - 1) (mounted in a pull-to-push
** cage, it closes its coils as the fibre is stretched, stiffening as crimped collagen
** straightens) and carries T = F_law(u); at lambda <= 1 it is slack, T = 0. Its energy per cell
** is density E(lambda), dE/dlambda = Hf T, stored in the cell's volume H^3, so its nominal stress
** and tangent are
**   P_ij    = phi (F a)_i a_j / lambda,                     phi = density Hf T / H^3,
**   A_ijkl  = dP_ij/dF_kl = c1 (F a)_i a_j (F a)_k a_l + phi delta_ik a_j a_l / lambda,
**             c1 = density Hf (Hf k lambda - T) / (H^3 lambda^3),  k = dF_law/du.
** With Hf = H and X_a = H a: P = (1/H^3) T (F X_a) X_a^T / |F X_a|, a node-to-node spring's form.
** Density is a number of springs per cell (the fit's stress scale of the group); a buildable
** member is the law's spring. Private to the library.
*/
#ifndef CF_MODEL_FIBRE_H
#define CF_MODEL_FIBRE_H

#include "conifit/error.h"
#include "model/law_internal.h"

/* Most fibre groups of one cell (fibre and sheet, and room for a cross-fibre family). */
#define CF_FIBRE_MAX 4

typedef struct cf_fibre_group {
    const cf_law *law;      /* not owned: the conical law acting in fibre tension */
    cf_law_method method;   /* its evaluator */
    double dir[3];          /* reference unit direction a, lattice frame */
    double density;         /* springs per cell, > 0 */
    double slack;           /* recruitment strain, >= 0: the fibre is slack up to stretch
                            ** 1 + slack (crimped collagen straightening), 0 for taut at rest */
} cf_fibre_group;

/* Checks g: a finite direction of unit length (1e-12), a finite density > 0, a law. CF_E_DATA
** naming the value. */
cf_status cf_fibre_check(const cf_fibre_group *g, cf_error *err);

/* The group's stretch lambda = |F a| at F (row-major), F a into Fa. */
double cf_fibre_stretch(const cf_fibre_group *g, const double F[9], double Fa[3]);

/* The compression u = Hf (lambda - 1 - slack) (mm) of the group's spring at stretch lambda; 0
** while the fibre is slack (lambda <= 1 + slack, or lambda not a number). */
double cf_fibre_compression(const cf_fibre_group *g, double lambda);

/* Adds the group's nominal stress at F to P (MPa) in a cell of edge H_mm; *tension_N gets T and
** *r its compression over the travel. CF_E_DATA when the spring reaches solid (message: the
** direction and the stretch). */
cf_status cf_fibre_add_stress(const cf_fibre_group *g, double H_mm, const double F[9],
                              double P[3][3], double *tension_N, double *r, cf_error *err);

/* Adds the group's tangent dP_ij/dF_kl at F to A[27 i + 9 j + 3 k + l] (MPa). Same failure. */
cf_status cf_fibre_add_tangent(const cf_fibre_group *g, double H_mm, const double F[9],
                               double A[81], cf_error *err);

#endif
