/*
** The homogenised cell: the stress of the cubic mass-spring lattice (lattice.h) under a homogeneous
** deformation, from one cell (affine, Cauchy-Born), with the free stretches of a test mode solved
** for zero stress. It costs microseconds per strain instead of a lattice solve.
**
** Why one cell is enough: under a homogeneous deformation every node of the lattice is a centre of
** symmetry of its springs (interior forces cancel pair by pair), and a free side face is in
** equilibrium exactly when the cell's nominal stress has no traction on it. So wherever the full
** lattice's static solution is homogeneous (free sides, lubricated platens: bottom 'axial'), it
** equals the cell's, for any number of cells (tests: 1e-9 relative).
**
** The cell of edge H holds one spring along each of 13 directions N (integer offsets: 3 edges,
** 6 face diagonals, 4 body diagonals; reference vector X = H N, rest length L0 = H |N|). Under a
** deformation gradient F a spring has length L = |F X|, stretch L/L0 and the law's compression
** u = H (1 - L/L0) (the strain form of lattice.h); its tension is T = -w F_law(u) + extra (w its
** family's weight, extra an optional viscous term). The nominal (first Piola-Kirchhoff) stress is
**     P = (1/H^3) sum_d T_d (F X_d) (X_d)^T / L_d,        MPa, tension positive.
**
** Test modes (table strain e, tension positive; stretch 1 + e; loading axis as stated):
**   uniaxial     F = diag(a, a, 1 + e), a free with P_xx = P_yy = 0 (free sides); stress P_zz
**   shear        F = I + e (x along z): simple shear of amount e, other stretches held; stress P_xz
**   planar       F = diag(1 + e, 1, c), c free with P_zz = 0 (pure shear); stress P_xx
**   equibiaxial  F = diag(1 + e, 1 + e, c), c free with P_zz = 0; stress P_xx
**   confined     F = diag(1, 1, 1 + e), lateral stretches held; stress P_zz
**   biaxial      F = diag(1 + e, 1 + k e, c), c free with P_zz = 0; stress P_xx, k the cell's
**                biaxial_k (the other in-plane strain per unit of this one; 1 is equibiaxial).
**                The cubic cell is the same along x and y, so either direction of a biaxial
**                test is its x: a table's rows of the second direction take k = 1 / ratio.
** Only uniaxial is a mode of the full lattice (cf_msm_uniaxial); the others are the cell's.
**
** The volume term (Golec et al. 2020, The Visual Computer 36:809-825): with volume_modulus_MPa =
** kappa > 0 the cell also stores W = (kappa/2)(J - 1)^2 per unit reference volume, J = det F,
** whose nominal stress kappa (J - 1) cof F (cof F = J F^-T) adds to the springs'. At small strain
** it adds kappa to Lame's lambda and nothing to mu: the isotropic lattice (lambda = mu) gets
** nu = (mu + kappa)/(2 (2 mu + kappa)). Simple shear keeps J = 1 and does not feel it. kappa = 0
** (cf_cell_init's value) leaves every result of the springs alone, bit for bit.
** Spring groups: each family's directions may take a law of their own (family_law, the groups of
** the lattice's cfg.group_law); the homogenised cell then equals the full lattice with those
** groups as it does with one law.
** A double-acting law (law.h, law->extension) enters through the law alone: each spring's side
** (and the travel to solid on that side) follows the sign of its compression.
**
** For time-dependent models the cell takes, per direction, an extra tension affine in the
** spring's length, T_extra = T0 + k (L - Lref): a backward-Euler dashpot or the exponential update
** of a Maxwell branch over one step has that form. A strain history is then a loop of
** cf_cell_mode calls, updating the extra terms from the returned spring lengths. The weights of
** calibration.h scale the extras as they scale the law (give them already weighted).
*/
#ifndef CF_CELL_H
#define CF_CELL_H

#include <stddef.h>

#include "model/calibration.h"
#include "model/fibre.h"
#include "conifit/error.h"
#include "model/law_internal.h"
#include "model/mode.h"

/* Spring directions of the cell. */
#define CF_CELL_DIRS 13

/* Integer offset N[3] of direction d (0 <= d < CF_CELL_DIRS) and its family (CF_FAMILY_*). */
void cf_cell_direction(int d, int N[3], int *family);

typedef struct cf_cell {
    const cf_law *law;               /* not owned; with CF_LAW_TABLE its table must be built */
    cf_law_method method;            /* evaluator */
    double weight[CF_FAMILY_COUNT];  /* family weights (calibration.h) */
    double law_scale;                /* factor on every law force and tangent (1 by cf_cell_init):
                                     ** an implicit step of quasi-linear viscoelasticity scales the
                                     ** law by 1 - sum g_i (1 - b_i) and adds an affine extra */
    double law_scale_strain;         /* its growth with strain (0 by cf_cell_init): the factor on
                                     ** a spring at law compression u is law_scale +
                                     ** law_scale_strain |u| / H (relaxation that grows with strain) */
    double stretch_hint;             /* first guess of a mode's free stretch (0 by cf_cell_init:
                                     ** from the small-strain constants); a history passes the
                                     ** last step's */
    double volume_modulus_MPa;       /* kappa of the volume term, MPa (0 by cf_cell_init: none) */
    double biaxial_k;                /* the biaxial mode's strain along y per unit strain along x
                                     ** (1 by cf_cell_init; other modes ignore it) */
    const cf_law *family_law[CF_FAMILY_COUNT]; /* a law per spring group (the family of each
                                     ** direction, as the lattice's cfg.group_law), not owned; NULL
                                     ** (cf_cell_init's): law. Same free length H as law */
    const cf_fibre_group *fibre;     /* fibre groups (fibre.h), not owned; NULL by cf_cell_init */
    int nfibre;                      /* their count, 0 .. CF_FIBRE_MAX (0 by cf_cell_init: the
                                     ** cell of the node-to-node springs alone, bit for bit) */
    double frame[9];                 /* the fibre frame, rows f, s, n as unit vectors in the
                                     ** lattice frame (the identity by cf_cell_init): the axes of
                                     ** cf_cell_load's modes */
    int linear_finish;               /* 1: a free-stretch solve whose last Newton step is too small
                                     ** for its second-order term to reach rounding takes that step
                                     ** by the cell's linearisation instead of evaluating the cell
                                     ** again (0 by cf_cell_init: every state evaluated) */
} cf_cell;

/* Checks the weights (cf_calibration_check) and fills c (law_scale 1, law_scale_strain 0, stretch_hint 0,
** linear_finish 0, biaxial_k 1, every family with law). */
cf_status cf_cell_init(cf_cell *c, const cf_law *law, cf_law_method method,
                       const double weight[CF_FAMILY_COUNT], cf_error *err);

/* Extra tension per direction, T = T0_N[d] + k_N_per_mm[d] (L - Lref_mm[d]), N (tension
** positive), already multiplied by the family weight. */
typedef struct cf_cell_extra {
    double T0_N[CF_CELL_DIRS];
    double k_N_per_mm[CF_CELL_DIRS];
    double Lref_mm[CF_CELL_DIRS];
} cf_cell_extra;

/* The cell at one deformation. */
typedef struct cf_cell_state {
    double F[9];                     /* deformation gradient, row-major (F[3 i + j] = F_ij), - */
    double L_mm[CF_CELL_DIRS];       /* spring lengths, mm */
    double T_N[CF_CELL_DIRS];        /* spring tensions (law and extra, weighted), N */
    double P_MPa[3][3];              /* nominal stress, MPa, tension positive */
    double stress_MPa;               /* the mode's stress component (cf_cell_mode), MPa */
    double free_stretch;             /* the solved free stretch (1 when the mode has none), - */
    double max_u_over_travel;        /* largest |u| / travel over the springs, - */
} cf_cell_state;

/* The state at deformation gradient F (row-major, F[3 i + j] = F_ij; extra may be NULL). CF_E_DATA when a spring would reach
** or pass solid (message: the direction and its stretch) or F is not finite. */
cf_status cf_cell_stress(const cf_cell *c, const double F[9], const cf_cell_extra *extra,
                         cf_cell_state *s, cf_error *err);

/* The state at F (as cf_cell_stress) and the cell's full tangent A = dP/dF, MPa:
** A[27 i + 9 j + 3 k + l] = dP_ij / dF_kl (symmetric under (ij) <-> (kl): the second derivative
** of the cell's stored energy per volume). Same failures as cf_cell_stress. */
cf_status cf_cell_tangent(const cf_cell *c, const double F[9], const cf_cell_extra *extra,
                          cf_cell_state *s, double A[81], cf_error *err);

/* The state of test mode m at table strain e (tension positive), the free stretch solved to
** rounding (safeguarded Newton inside a bracket). CF_E_DATA when e is not finite or the mode
** cannot reach it (a spring at solid), CF_E_NOCONV when no free stretch gives zero stress. */
cf_status cf_cell_mode(const cf_cell *c, cf_mode m, double e, const cf_cell_extra *extra,
                       cf_cell_state *s, cf_error *err);

/* A test mode placed on the axes of the fibre frame (c->frame; 0 f, 1 s, 2 n), p = axis[0],
** q = axis[1], r the third; the stretches of F in the fibre frame (F' = R F R^T, R the frame):
**   uniaxial     F'_pp = 1 + e, F'_qq and F'_rr free (each zeroes its own P'), stress P'_pp
**   planar       F'_pp = 1 + e, F'_qq = 1, F'_rr free; stress P'_pp
**   equibiaxial  F'_pp = F'_qq = 1 + e, F'_rr free; stress P'_pp
**   biaxial      F'_pp = 1 + e, F'_qq = 1 + k e, F'_rr free; stress P'_pp (a table's row of
**                either direction: p its own axis, k the other's strain per unit of its own)
**   confined     F'_pp = 1 + e, the others 1; stress P'_pp
**   shear        F' = I + e e_q e_p^T (the face of normal p moved along q, Sommer et al. 2015's
**                mode (pq)); stress P'_qp, the shear traction on that face
** With fibres, cf_cell_mode places its mode this way on the lattice's own axes (the old modes'
** axes: uniaxial and confined along z, planar, equibiaxial and biaxial along x with y second,
** shear with z the normal and x the direction), each free stretch solved on its own. */
typedef struct cf_cell_load {
    cf_mode mode;
    int axis[2];
    double k;
} cf_cell_load;

/* The state of load ld at table strain e in the fibre frame (c->frame), every free stretch solved
** (Newton on the analytic tangent, steps halved where a spring would reach solid) until it moves
** by less than 1e-15; s->free_stretch is the first free stretch, s->F the lattice-frame F,
** s->P_MPa the lattice-frame P. Failures as cf_cell_mode's; CF_E_DATA for axes that are not two
** different axes of 0 .. 2. */
cf_status cf_cell_load_state(const cf_cell *c, const cf_cell_load *ld, double e,
                             cf_cell_state *s, cf_error *err);

/* The largest |L/L0 - 1| over the cell's springs at table strain e of mode m with the free
** stretches held at 1: how far the springs travel (in strain) when the table reaches e. For
** uniaxial, planar, equibiaxial and confined it is |e| (the loaded edge); for simple shear about
** |e|/2 (a face diagonal). Lets a fit bound the springs' solid strain by what they reach. */
double cf_cell_spring_strain(cf_mode m, double e);

/* The table strain of mode m (side < 0: compression) at which the first spring of the cell
** reaches solid, the free stretches solved (not held): past it the mode cannot go. To 1e-12
** relative. CF_E_DATA when no spring reaches solid up to |e| = 1000. */
cf_status cf_cell_solid_strain(const cf_cell *c, cf_mode m, int side, double *e_solid,
                               cf_error *err);

/* The mode's stress (MPa, table sign) at each of count strains. Stops at the first failure. */
cf_status cf_cell_curve(const cf_cell *c, cf_mode m, const double *strain, size_t count,
                        double *stress_MPa, cf_error *err);

#endif
