/*
** The joint fit of a fibre-reinforced lattice (model/fibre.h) to tables that lie in a fibre frame
** (biaxial tables, both directions, and simple-shear tables with a plane, table.h): the matrix's
** conical law (rho, s/H, F_C/H^2: the isotropic lattice of node-to-node springs, family weights
** equal, scaled so that its small-strain modulus along an axis is the law's k0/H), one fibre
** group per named axis of the frame (f, s or n), each a conical law acting in fibre tension only
** (its own rho, s/H and F_C/H^2, one spring per cell of edge H = its free length), and the
** volume modulus kappa. The frame is the lattice's own (f = x, s = y, n = z); a biaxial table's
** second direction is n or s (`cross`) where its plane does not say, as the Holzapfel-Ogden
** baseline reads it (holzapfel.h). Every row is the homogenised cell in its own mode
** (cf_cell_load_state): a biaxial row along its own axis with the other loaded at k times its
** strain and the third free, a shear row (ij) with the face of normal i moved along j.
** Objective: the joint fit's (each table (RMSE / RMS stress)^2, a biaxial table's two directions
** one table), the Holzapfel-Ogden fit's. Levenberg-Marquardt in bounded coordinates (logits of
** rho in (rho_min 0.05, 1), of s/H above the farthest strain each family's springs reach at
** 1.05 x the tables' strains, of kappa in (0, CF_KAPPA_MAX_MPA); logs of the scales) from a grid
** of eight starts. Private to the library.
*/
#ifndef CF_FIT_FIBRE_FIT_H
#define CF_FIT_FIBRE_FIT_H

#include <stddef.h>

#include "conifit/error.h"
#include "fit/holzapfel.h"
#include "model/family.h"
#include "model/fibre.h"
#include "model/table.h"

/* The fitted lattice. */
typedef struct cf_fibre_fit {
    char groups[CF_FIBRE_MAX + 1]; /* the groups' axes, e.g. "f", "fs", "fn" */
    int ngroups;
    char cross;                    /* 'n' or 's' (see above) */
    cf_ident matrix;               /* rho, s/H (-), F_C/H^2 (MPa) of the matrix springs */
    cf_ident fibre[CF_FIBRE_MAX];  /* the same of each group's spring */
    double kappa_MPa;              /* volume modulus, MPa */
    double objective;              /* sum over tables of (RMSE / RMS stress)^2, - */
    size_t ntables;
    double rmse_MPa[CF_HO_MAX_TABLES]; /* each table's RMSE, MPa */
    double term[CF_HO_MAX_TABLES];     /* each table's (RMSE / RMS)^2, - */
    int nparams, starts;
    int stable;                    /* 1: the cell's incremental stiffness positive at every row
                                   ** and to 1.05 x each table's farthest strain */
    double min_stiffness_MPa;      /* its smallest eigenvalue over those states, MPa */
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

/* The nominal stress (MPa, table sign) of row i of t in the model's cell, axes from cf_ho_axes. */
cf_status cf_fibre_row_stress(const cf_fibre_model *m, const cf_table *t, size_t i,
                              const int axes[2], double *stress_MPa, cf_error *err);

/* Fits the lattice with groups (one to CF_FIBRE_MAX of the letters f, s, n, each once) jointly
** to the n tables (cross as above). CF_E_DATA for bad groups or a table without axes (naming it),
** CF_E_NOCONV when no start gives a finite objective. */
cf_status cf_fibre_fit_joint(const cf_table *const *t, size_t n, const char *groups, char cross,
                             cf_fibre_fit *r, cf_error *err);

#endif
