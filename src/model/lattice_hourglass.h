/*
** Hourglass control of the lattice's cells (Flanagan & Belytschko 1981, "A uniform strain
** hexahedron and quadrilateral with orthogonal hourglass control", Int J Numer Meth Eng
** 17:679-706). A cell's eight nodes have 24 motions; 12 are affine (x = F X + c), 12 are its
** hourglass modes: along each axis the four patterns h_i(a) = xi eta, eta zeta, zeta xi,
** xi eta zeta of the corner signs (xi, eta, zeta) = (2 di - 1, 2 dj - 1, 2 dk - 1). For the cubic
** cell those patterns are orthogonal to the affine field already (sum_a h_i(a) = 0 and
** sum_a h_i(a) X_a = 0), so the Flanagan-Belytschko vectors are gamma_i = h_i / 8 and the mode
** amplitudes q_i = sum_a gamma_i(a) x_a (a vector each) vanish for every affine motion of the
** cell. Every cell stores W = (k_h / 2) sum_i |q_i|^2: zero for a homogeneous deformation, so the
** homogenised cell (cell.h), every fit through it and every homogeneous lattice state keep their
** stresses; it resists only the node-scale modes. W is quadratic in the positions, invariant under
** translation and rotation (|R q| = |q|), and its Hessian is constant:
** d2W/dx_a dx_b = k_h sum_i gamma_i(a) gamma_i(b) I (cf_hourglass_coef).
** k_h = 4 f mu H: f (cf_lattice_config.hourglass) times the stiffness that makes an hourglass mode
** cost what a simple shear of the cell with the same node motion (the same sum of squared node
** displacements) costs, mu = C44 (k0_c + k0_e) / (2 H) the cell's small-strain shear modulus
** (calibration.h; a double-acting element's diagonals work half on each side in simple shear).
*/
#ifndef CF_MODEL_LATTICE_HOURGLASS_H
#define CF_MODEL_LATTICE_HOURGLASS_H

#include "model/calibration.h"
#include "model/law_internal.h"

/* The hourglass fraction of a lattice with a volume term when none is given (lattice.h's
** CF_HOURGLASS_AUTO). */
#define CF_HOURGLASS_DEFAULT 0.5

/* h_i(a) (+1 or -1) of mode i (0..3) at corner a (0..7, a = di + 2 dj + 4 dk). */
int cf_hourglass_pattern(int i, int a);

/* d2W/(dx_a dx_b) / k_h for corners a and b (0..7, a = di + 2 dj + 4 dk): 1/16 for a == b,
** -1/32 along an edge, 0 across a face, +1/32 across the body. */
double cf_hourglass_coef(int a, int b);

/* The four mode amplitudes q[i] (mm, a vector each) of a cell's corner positions x[a]. */
void cf_hourglass_modes(double x[8][3], double q[4][3]);

/* The forces -dW/dx_a (N) on the corners of a cell with mode amplitudes q and stiffness k_h. */
void cf_hourglass_forces(double q[4][3], double k_h, double f[8][3]);

/* The hourglass stiffness k_h (N/mm) of a lattice with family weights w, volume modulus kappa
** (MPa) and hourglass fraction `fraction` (CF_HOURGLASS_AUTO or >= 0) built from law (and its
** extension spring when it has one). 0 when there is none. */
double cf_hourglass_stiffness(const double w[CF_FAMILY_COUNT], double kappa_MPa, double fraction,
                              const cf_law *law);

#endif
