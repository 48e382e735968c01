/*
** Strong ellipticity of the homogenised cell (cell.h) along a test mode: a material-level
** condition, distinct from the cell's stability (cell_stability.h). At a homogeneous deformation F
** the acoustic tensor of the cell's incremental modulus A = dP/dF (cf_cell_tangent) for a unit
** direction n of the reference configuration is
**     Q_ik(n) = A_ijkl n_j n_l,
** the stiffness a plane wave (or a band of localised strain) of normal n meets. The material is
** strongly elliptic at F while Q(n) is positive definite for every n; where it is not, a laminate
** of two homogeneous states with interface normal n costs no energy to first order and the bulk
** material may localise there, whatever a finite lattice with held ends does (Knowles & Sternberg
** 1977, J Elasticity 8:329-379; Ogden, Non-linear Elastic Deformations, 1984, sec. 6.2.7).
** The smallest eigenvalue of Q(n) over the unit sphere is found on a Fibonacci sphere of
** CF_ACOUSTIC_DIRECTIONS directions, refined from its best few by a pattern search on the sphere.
*/
#ifndef CF_CELL_ELLIPTIC_H
#define CF_CELL_ELLIPTIC_H

#include "model/cell.h"
#include "conifit/error.h"

/* Directions sampled on the sphere before the local refinement. */
#define CF_ACOUSTIC_DIRECTIONS 400

/* The smallest eigenvalue (MPa) over unit n of Q(n)_ik = A[27 i + 9 j + 3 k + l] n_j n_l (A a
** first elasticity tensor as cf_cell_tangent gives it, major-symmetric), and the n where it is
** reached (unit, its largest component positive, components under 1e-9 zero; Q(n) = Q(-n)).
** CF_E_DATA when A is not finite. */
cf_status cf_acoustic_min(const double A[81], double *q_min_MPa, double n[3], cf_error *err);

/* Follows mode m from strain 0 to `reach` (table sign, tension positive) and returns in *limit
** the largest |strain| (with reach's sign) up to which the cell stays strongly elliptic (the
** smallest eigenvalue of its acoustic tensor positive for every direction): reach itself when it
** does all the way (*lost = 0), else the strain where it is first lost, to 1e-6 of reach (*lost
** = 1, n the direction where the acoustic tensor is softest there; 0 when lost at rest). A strain
** the mode cannot reach (a spring at solid) ends the scan as a loss, at the last strain reached,
** n then zero. CF_E_DATA when reach is not finite. */
cf_status cf_cell_elliptic_to(const cf_cell *c, cf_mode m, double reach, double *limit, int *lost,
                              double n[3], cf_error *err);

#endif
