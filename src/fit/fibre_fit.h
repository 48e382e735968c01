/*
** The joint fit of a fibre-reinforced lattice (model/fibre.h) to tables that lie in a fibre frame
** (biaxial tables, both directions, and simple-shear tables with a plane, table.h): the matrix's
** conical law (rho, s/H, F_C/H^2: the isotropic lattice of node-to-node springs, family weights
** equal, scaled so that its small-strain modulus along an axis is the law's k0/H), one fibre
** group per named axis of the frame (f, s or n), each a conical law acting in fibre tension only
** (its own rho, s/H and F_C/H^2, one spring per cell of edge H = its free length) from its own
** recruitment strain on (slack below it, model/fibre.h; fitted in (0, 0.2)), and the volume
** modulus kappa (at most the one of Poisson's ratio CF_JOINT_NU_MAX along an axis of the
** matrix). The frame is the lattice's own (f = x, s = y, n = z); a biaxial table's
** second direction is n or s (`cross`) where its plane does not say, as the Holzapfel-Ogden
** baseline reads it (holzapfel.h). Every row is the homogenised cell in its own mode
** (cf_cell_load_state): a biaxial row along its own axis with the other loaded at k times its
** strain and the third free, a shear row (ij) with the face of normal i moved along j.
** Objective: the joint fit's (each table (RMSE / RMS stress)^2, a biaxial table's two directions
** one table), the Holzapfel-Ogden fit's. Levenberg-Marquardt in bounded coordinates (logits of
** rho in (rho_min 0.05, 1), of s/H above the farthest strain each family's springs reach at
** 1.05 x the tables' strains, of kappa in (0, its bound), of each recruitment strain; logs of the
** scales) from a grid
** of eight starts. Private to the library.
*/
#ifndef CF_FIT_FIBRE_FIT_H
#define CF_FIT_FIBRE_FIT_H

#include <stddef.h>

#include "conifit/error.h"
#include "fit/fit.h"
#include "fit/holzapfel.h"
#include "model/family.h"
#include "model/fibre.h"
#include "model/table.h"

/* A family of the fitted lattice placed as buildable springs (fibre_place.c): the spring fit's
** placement (cf_fit_place, its default design limits) of the family with its stress scale shared
** by `count` equal springs in parallel, each of F_C/H^2 = scale / count (the cell's stress of a
** family is count x its spring's, so the lattice is the fitted one), every spring of the lattice
** at the matrix spring's free length H, the cell's edge. */
typedef struct cf_fibre_spring {
    cf_spring spring;      /* one spring: D1, D2, n, d (mm), G (MPa), H (mm) */
    cf_spring_type type;   /* its type */
    int count;             /* springs in parallel: per cell along a group's axis, per lattice
                           ** edge (each of the 13 node-to-node springs) for the matrix */
    int buildable;         /* 1: the spring meets every design limit */
    unsigned violated;     /* CF_C_* bits it breaks (0 when buildable) */
    double reach;          /* the farthest strain its travel must take (the tables' own), - */
} cf_fibre_spring;

/* Most springs in parallel a placement gives a family before it calls it not buildable. */
#define CF_FIBRE_COUNT_MAX 1000

/* The fitted lattice. */
typedef struct cf_fibre_fit {
    char groups[CF_FIBRE_MAX + 1]; /* the groups' axes, e.g. "f", "fs", "fn" */
    int ngroups;
    char cross;                    /* 'n' or 's' (see above) */
    cf_ident matrix;               /* rho, s/H (-), F_C/H^2 (MPa) of the matrix springs */
    cf_ident fibre[CF_FIBRE_MAX];  /* the same of each group's spring */
    double slack[CF_FIBRE_MAX];    /* each group's recruitment strain (fibre.h), - */
    double family[CF_FAMILY_COUNT]; /* the matrix's relative family weights (edge 1, face and body
                                    ** fitted in (0, 20); all 0: 1, 1, 1), each family's weight in
                                    ** the cell that over the lattice's E of them */
    double kappa_MPa;              /* volume modulus, MPa */
    double objective;              /* sum over tables of (RMSE / RMS stress)^2, - */
    size_t ntables;
    double rmse_MPa[CF_HO_MAX_TABLES]; /* each table's RMSE, MPa */
    double term[CF_HO_MAX_TABLES];     /* each table's (RMSE / RMS)^2, - */
    int nparams, starts;
    int stable;                    /* 1: the cell's incremental stiffness positive at every row
                                   ** and to 1.05 x each table's farthest strain */
    double min_stiffness_MPa;      /* its smallest eigenvalue over those states, MPa */
    /* The lattice built: each family placed (cf_fibre_spring), buildable when all are, and the
    ** largest difference between the placed lattice's stress and the fitted one's over every
    ** row, relative to the row's table's largest |stress| (-1: the placed lattice did not run). */
    cf_fibre_spring matrix_spring, fibre_spring[CF_FIBRE_MAX];
    int buildable;
    double placed_error;
} cf_fibre_fit;

/* The cell of a fitted lattice (laws owned here; free with cf_fibre_model_free). */
typedef struct cf_fibre_model {
    cf_law matrix, law[CF_FIBRE_MAX];
    cf_fibre_group group[CF_FIBRE_MAX];
    cf_cell cell;
    int nlaws;
} cf_fibre_model;

/* Builds the cell of f (the laws of its families' members). CF_E_DATA when a member is not a
** valid spring (its message). */
cf_status cf_fibre_model_init(cf_fibre_model *m, const cf_fibre_fit *f, cf_error *err);
void cf_fibre_model_free(cf_fibre_model *m);

/* Builds the cell of f's placed springs (matrix_spring, fibre_spring): the matrix's law of its
** spring with the family weights times its count, each group's law of its spring with density
** its count. CF_E_DATA when a spring is not valid (its message). */
cf_status cf_fibre_model_init_placed(cf_fibre_model *m, const cf_fibre_fit *f, cf_error *err);

/* Places family q, whose springs must travel to strain reach, as buildable springs under the
** design limits of opt: for each spring type where the family can be placed at all
** (cf_fit_ident_limit), the fewest springs in parallel whose share of the stress scale lies
** within the largest one spring of the type carries there, then cf_fit_place of that share;
** the buildable placement with the fewest springs (non-telescoping first on a tie). H_mm > 0
** scales the spring to that free length (its family unchanged) and checks it again. Where no
** type places it, out is the non-telescoping placement of one spring, buildable 0, with the
** limits it breaks. CF_E_INTERNAL when memory runs out. */
cf_status cf_fibre_place(const cf_ident *q, double reach, const cf_fit_options *opt, double H_mm,
                         cf_fibre_spring *out, cf_error *err);

/* The nominal stress (MPa, table sign) of row i of t in the model's cell, axes from cf_ho_axes. */
cf_status cf_fibre_row_stress(const cf_fibre_model *m, const cf_table *t, size_t i,
                              const int axes[2], double *stress_MPa, cf_error *err);

/* Fits the lattice with groups (one to CF_FIBRE_MAX of the letters f, s, n, each once) jointly
** to the n tables (cross as above). CF_E_DATA for bad groups or a table without axes (naming it),
** CF_E_NOCONV when no start gives a finite objective. */
cf_status cf_fibre_fit_joint(const cf_table *const *t, size_t n, const char *groups, char cross,
                             cf_fibre_fit *r, cf_error *err);

#endif
