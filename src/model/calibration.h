/*
** Calibration of the cubic mass-spring lattice: how much of the fitted law each spring family
** carries, so that the lattice as a material behaves like the tissue the law was fitted to.
**
** A cubic cell of edge H holds, per cell, one spring along each of the 3 edge directions, one
** along each of the 6 face-diagonal directions and one along each of the 4 body diagonals. Every
** family evaluates the same law in strain form (a spring of rest length L0 at the compression
** u = (L0 - L) H / L0) and carries it times its family weight w. The axial stiffness dF/dL of a
** spring at small strain is therefore k_e = w_e k0 (edge), k_f = w_f k0 / sqrt 2 (face diagonal)
** and k_b = w_b k0 / sqrt 3 (body diagonal), k0 the law's linear stiffness.
**
** Affine (Cauchy-Born) homogenisation of the cell gives the small-strain elastic constants
**     C11 = (k_e + 2 k_f + 4 k_b / 3) / H,    C12 = C44 = (k_f + 4 k_b / 3) / H
** (C12 = C44 is the Cauchy relation of central springs). The lattice is isotropic when
** C11 - C12 = 2 C44, i.e. k_e = k_f + 8 k_b / 3, and then nu = 1/4 whatever the weights: the
** best a lattice of central springs can do (Kot et al. 2015; Golec et al. 2020). Its Young's
** modulus along a cube axis is E = (C11 - C12)(C11 + 2 C12) / (C11 + C12).
**
** Calibrations:
**   isotropic  face and body weights equal, k_e = k_f + 8 k_b / 3 (isotropic, nu = 1/4), scaled
**              so that E = k0 / H, the law's own small-strain modulus: about 0.6085 for the
**              edges and 0.2708 for each diagonal. The default.
**   axial      every family the same weight (the shape of the uncalibrated lattice), scaled so
**              that E = k0 / H along the axes; nu = 0.317 and the lattice is anisotropic.
**   fitted     weights found by a fit through the lattice (a joint fit of several test modes);
**              they cannot be derived here.
**   custom     weights given by hand.
** References: San-Vicente, Aguinaga & Celiguieta 2012; Lloyd, Szekely & Harders 2007; Baudet et
** al. 2009; Kot et al. 2015; Golec et al. 2020.
*/
#ifndef CF_CALIBRATION_H
#define CF_CALIBRATION_H

#include "conifit/error.h"

/* The spring families of the cubic cell, as indices of a weight[3] array. */
enum { CF_FAMILY_EDGE = 0, CF_FAMILY_FACE = 1, CF_FAMILY_BODY = 2, CF_FAMILY_COUNT = 3 };

typedef enum cf_calibration {
    CF_CAL_ISOTROPIC = 0,
    CF_CAL_AXIAL = 1,
    CF_CAL_FITTED = 2,
    CF_CAL_CUSTOM = 3
} cf_calibration;

/* Small-strain elastic constants of the cubic lattice, in units of the law's k0 / H (so E = 1
** means the lattice's modulus along an axis equals the single spring's). */
typedef struct cf_cubic_moduli {
    double C11, C12, C44; /* cubic elastic constants, k0/H */
    double E;             /* Young's modulus along a cube axis, k0/H */
    double nu;            /* Poisson's ratio for a load along a cube axis, - */
    double zener;         /* anisotropy ratio 2 C44 / (C11 - C12); 1 when isotropic, - */
} cf_cubic_moduli;

/* The moduli of a lattice with family weights w (each finite and >= 0). */
cf_cubic_moduli cf_cubic_moduli_of(const double w[CF_FAMILY_COUNT]);

/* The diagonal-to-edge weight ratio q of a lattice of weights {1, q, q} (face = body) whose Zener
** ratio 2 C44/(C11 - C12) is zener (> 0, below 2 sqrt 2 (1/sqrt 2 + 4/(3 sqrt 3)), the ratio's
** limit as q grows); the ratio rises with q, 1 at the isotropic calibration's. NAN out of range. */
double cf_cubic_q_of_zener(double zener);

/* The volume term (cell.h) adds kappa to C11 and C12 (Lame's lambda), nothing to C44: the
** volume modulus kappa (MPa) that gives a lattice of weights w and small-strain modulus scale
** k0/H (MPa) the Poisson's ratio nu along an axis, kappa = (nu (C11 + C12) - C12)/(1 - 2 nu) k0/H
** from nu = (C12 + kappa)/(C11 + C12 + 2 kappa) (negative when nu is below the springs' own; the
** isotropic lattice: kappa = mu (4 nu - 1)/(1 - 2 nu)); and the inverse. */
/* The largest volume modulus kappa (MPa) a lattice or a body takes, from any source (a scene's
** 'lattice.volume_modulus_MPa' or 'body.volume_modulus_MPa', a fit file, conifit fit
** --volume-modulus, the library's configurations): 1e6 MPa = 1 TPa, above the bulk modulus of
** any solid (diamond's is 0.44 TPa; water's 2.2 GPa, what nearly incompressible tissue
** approaches). The springs' stiffness k0/H of soft tissue is of order 1e-3 to 1 MPa, so at the
** bound the volume term outweighs them 1e6 to 1e9 times and a solve in double precision (unit
** roundoff 1.1e-16) still carries their forces to about 1e-7 of their size; from about 1e14 MPa
** the springs vanish in the rounding and a lattice run's stresses changed sign (measured: -1.5e12
** kPa at kappa 1e25), which no check downstream catches. CF_KAPPA_MAX_WHY says it in a message.
** Where the spring is known as kappa is declared (a scene's keys), kappa is also held to
** CF_KAPPA_MAX_RATIO times the spring's k0/H: the lattice's stability check reads the signs of
** its tangent's pivots, which the springs' share must still reach. Measured on the shipped
** uniaxial scene (k0/H 1.5e-3 MPa): the loss of stability found at strain 0.36-0.38 for kappa up
** to 1e4 MPa (6.6e6 k0/H), at 0.30 for 1e5 and at 0.01 (false) for 1e6, with the stresses still
** right. 1e6 k0/H is a Poisson's ratio of 0.4999998 in the isotropic lattice, beyond any
** measured tissue's; a body's 'poisson_ratio' (at most 0.4999) stays 500 times below it. */
#define CF_KAPPA_MAX_MPA 1e6
#define CF_KAPPA_MAX_WHY                                                                           \
    "1 TPa, above any solid's bulk modulus; beyond it the springs' forces are lost in the "       \
    "solve's rounding"
#define CF_KAPPA_MAX_RATIO 1e6
#define CF_KAPPA_RATIO_WHY                                                                         \
    "beyond it the springs' share of the tangent is lost to the precision its stability check "   \
    "needs"

double cf_cubic_kappa_of_nu(const double w[CF_FAMILY_COUNT], double k0_over_H, double nu);
double cf_cubic_nu_of_kappa(const double w[CF_FAMILY_COUNT], double k0_over_H, double kappa);

/* The family weights of calibration c (isotropic or axial, derived from the formulas above).
** CF_E_DATA for fitted or custom, which carry their own weights. */
cf_status cf_calibration_weights(cf_calibration c, double w[CF_FAMILY_COUNT], cf_error *err);

/* Checks family weights: each finite and >= 0, and a lattice that carries load along every axis
** (the edges or the diagonals not all zero). CF_E_DATA naming the family and value. */
cf_status cf_calibration_check(const double w[CF_FAMILY_COUNT], cf_error *err);

/* "isotropic", "axial", "fitted", "custom"; and the parser of the first three (the names a scene
** may give). */
const char *cf_calibration_name(cf_calibration c);
cf_status cf_calibration_parse(const char *name, cf_calibration *c, cf_error *err);

/* "edge", "face", "body". */
const char *cf_family_name(int family);

#endif
