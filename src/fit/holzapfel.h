/*
** The Holzapfel-Ogden law of passive myocardium (Holzapfel & Ogden 2009, Phil. Trans. R. Soc. A
** 367:3445-3475) as a baseline of joint fits on tables that lie in a fibre frame (f fibre,
** s sheet, n sheet-normal): biaxial tables and simple-shear tables with a plane (table.h).
** Incompressible (the homogeneous tests need no volumetric penalty: the pressure is the
** traction-free condition's), strain energy per reference volume
**   W = a/(2b) (exp(b (I1 - 3)) - 1)
**     + sum_{i = f, s} a_i/(2 b_i) (exp(b_i (I4i - 1)^2) - 1)       (only while I4i > 1)
**     + a_fs/(2 b_fs) (exp(b_fs I8fs^2) - 1),
** I1 = tr C, I4f = f0.C f0, I4s = s0.C s0, I8fs = f0.C s0 (C = F^T F). The Cauchy stress is
** sigma = -p I + 2 W1 B + 2 W4f f f + 2 W4s s s + W8 (f s + s f), f = F f0, s = F s0.
**   biaxial  F = diag in the table's two axes (1 + e, 1 + k e) and 1/((1 + e)(1 + k e)) in the
**            third, traction-free; a row's stress P = sigma_pp / lambda_p along its own axis p.
**   shear    (ij): F = I + gamma e_j e_i (the face of normal i moved along j); the stress is
**            sigma_ij = P_ji (the sheared face keeps its area and normal).
** The transversely isotropic reduction keeps a, b, a_f, b_f (a_s = a_fs = 0). Both are fitted by
** the joint objective of the lattice's joint fit (joint.h): each table's residuals divided by its
** RMS stress and the square root of its row count (a biaxial table's two directions one table).
** Private to the library.
*/
#ifndef CF_FIT_HOLZAPFEL_H
#define CF_FIT_HOLZAPFEL_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/table.h"

/* Parameters: a, b, a_f, b_f, a_s, b_s, a_fs, b_fs (the a's in MPa, the b's dimensionless). */
#define CF_HO_NP 8
/* Most tables of one fit (as joint.h's CF_JOINT_MAX). */
#define CF_HO_MAX_TABLES 16

typedef enum cf_ho_form {
    CF_HO_FULL = 0, /* all eight */
    CF_HO_TI = 1    /* transversely isotropic: a, b, a_f, b_f */
} cf_ho_form;

/* W at F (row-major, fibre-frame components: index 0 f, 1 s, 2 n), MPa. */
double cf_ho_energy(const double p[CF_HO_NP], const double F[9]);

/* The Cauchy stress without its pressure, 2 W1 B + ..., at F (row-major), MPa. */
void cf_ho_sigma_bar(const double p[CF_HO_NP], const double F[9], double s[9]);

/* The fibre-frame axes of table t (0 f, 1 s, 2 n): a shear table's (i, j) and a biaxial table's
** (first, second direction) from its plane; a biaxial table without one has its first direction
** along f and its second along `cross` ('s' or 'n'). -1 when t has no axes (another mode, or a
** shear table without a plane). */
int cf_ho_axes(const cf_table *t, char cross, int axes[2]);

/* The nominal stress of row i of t (axes from cf_ho_axes), MPa, in the table's sign. */
double cf_ho_row_stress(const double p[CF_HO_NP], const cf_table *t, size_t i,
                        const int axes[2]);

typedef struct cf_ho_fit {
    cf_ho_form form;
    char cross;              /* 's' or 'n': the axis of a biaxial table's second direction
                             ** where its plane does not say */
    double p[CF_HO_NP];      /* a, b, a_f, b_f, a_s, b_s, a_fs, b_fs (TI: a_s = a_fs = 0) */
    double objective;        /* sum over tables of (RMSE / RMS stress)^2, - */
    size_t ntables;
    double rmse_MPa[CF_HO_MAX_TABLES];  /* each table's RMSE, MPa */
    int nparams;             /* 8 or 4 */
    int starts;              /* starts of the search */
} cf_ho_fit;

/* Fits the law of form `form` jointly to the n tables (each with axes: cf_ho_axes with cross),
** LM in the logs of the parameters from a grid of starts (and from `from`, a fit to the same
** tables, when not NULL). CF_E_DATA naming the table for one without axes or n out of 1 ..
** CF_HO_MAX_TABLES; CF_E_NOCONV when no start gives a finite objective. */
cf_status cf_ho_fit_joint(const cf_table *const *t, size_t n, cf_ho_form form, char cross,
                          const cf_ho_fit *from, cf_ho_fit *r, cf_error *err);

/* Why the n tables cannot take a Holzapfel-Ogden fit (a sentence naming the first table
** without axes, into buf), or 0 with buf "" when they can. */
int cf_ho_unfit(const cf_table *const *t, size_t n, char *buf, size_t cap);

#endif
