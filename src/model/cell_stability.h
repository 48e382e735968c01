/*
** Stability of the homogenised cell (cell.h) along a test mode: the lattice's analogue of
** Drucker's check. At a deformation F the cell's incremental stiffness is its full tangent
** A = dP/dF (cf_cell_tangent) taken over every strain increment dF = D F, D symmetric (the six
** independent strain components, whatever the mode loads; rigid rotations, which change no
** spring length, are left out). The state is stable while that 6 x 6 quadratic form is positive
** definite: its smallest eigenvalue (GSL's symmetric eigen solver) is the stiffness of the
** softest strain increment. The lattice's hourglass control (lattice_hourglass.h) has no part
** here: it is zero, with its forces and stiffness along every affine motion, for every
** homogeneous deformation; it acts on the node-scale modes the full lattice's check sees.
*/
#ifndef CF_CELL_STABILITY_H
#define CF_CELL_STABILITY_H

#include "model/cell.h"
#include "conifit/error.h"

/* The smallest eigenvalue (MPa) of the cell's incremental stiffness at F. CF_E_DATA as
** cf_cell_stress, CF_E_INTERNAL when memory runs out. */
cf_status cf_cell_min_stiffness(const cf_cell *c, const double F[9], double *lambda_MPa,
                                cf_error *err);

/* Follows mode m from strain 0 to `reach` (table sign, tension positive) and returns in *limit
** the largest |strain| (with reach's sign) up to which the smallest eigenvalue stays positive:
** reach itself when it does all the way (*lost = 0), else the strain where it first reaches zero
** to 1e-6 of reach (*lost = 1). A strain the mode cannot reach (a spring at solid) ends the scan
** as a loss, at the last strain reached. */
cf_status cf_cell_stable_to(const cf_cell *c, cf_mode m, double reach, double *limit, int *lost,
                            cf_error *err);

#endif
