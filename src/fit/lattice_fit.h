/*
** The fit through the lattice (conifit fit --target lattice): the lattice's curve, not the single
** spring's, is the objective. It optimises the three identifiable quantities (rho, solid strain
** s/H, stress scale F_C/H^2; the lattice's stress depends on the design parameters only through
** them, as the single spring's does) through the homogenised cell (cell.h), then places the design
** parameters as the ordinary fit does (cf_fit_place). The verification of the placed spring in
** the full lattice is a measurement and belongs to the validation (validate.h,
** cf_validate_lattice_fit).
**
** Stress-strain tables only: a force-displacement table is a single spring's curve, not a block
** of tissue, and its free length H is not determined by the data.
*/
#ifndef CF_LATTICE_FIT_H
#define CF_LATTICE_FIT_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/family.h"
#include "fit/fit.h"
#include "model/law_internal.h"
#include "io/measure.h"
#include "model/msm.h"
#include "fit/lattice_curve.h"

/* What the fit through the lattice did (the verification fields are filled by
** cf_validate_lattice_fit, validate.h). */
typedef struct cf_through_msm {
    int done;                   /* 1: run */
    int improved;               /* 1: the spring was replaced (the lattice fits better) */
    double rmse_before;         /* RMSE of the ordinary fit in the lattice (homogenised cell),
                                ** MPa */
    double cell_rmse;           /* RMSE of the reported spring through the cell: the fit's, MPa
                                ** (the fit's rmse, r2, ... are the cell's once done) */
    double law_rmse;            /* the single spring's own law against the table (a uniaxial
                                ** table; NAN in the other modes, where the law has no curve), MPa */
    double law_max_abs_error;   /* the same, largest |error|, MPa */
    double law_r2;              /* the same, R^2 */
    long uncertainty_curves;    /* cell curves of the errors and profiles (in evaluations) */
    double rmse_after;          /* validation RMSE of the reported spring (full lattice), MPa */
    int verified;               /* 1: the full lattice ran (uniaxial); 0: the mode is the cell's */
    double verify_max_abs;      /* largest |full lattice - cell| at the table's strains, MPa */
    cf_ident ident_before;      /* rho, s/H, F_C/H^2 [MPa] of the ordinary fit (family.h) */
    cf_ident ident_after;       /* the same after the lattice objective */
    double wall_time_s;         /* s, the optimisation, the placement and the verification */
    long evaluations;           /* cell curves computed */
    size_t search_rows;         /* rows the searches ran on: a subsample of a table longer than
                                ** CF_LATTICE_FIT_FULL_ROWS (subsample.h), else every row */
    char note[CF_ERROR_MSG_LEN]; /* why it did not run (done = 0), else empty */
} cf_through_msm;

/* Tables up to this many rows are searched on every row; longer ones on a subsample of
** CF_SUBSAMPLE_ROWS rows (the stress scale and the placement then on every row), so that the fit
** through the lattice costs about what a 2000-row table does (a 65 000-row table took 430 s of
** CPU on every row). */
#define CF_LATTICE_FIT_FULL_ROWS 2000

/* The fit through the lattice for one fitted spring res (in: the ordinary fit; out: the spring
** placed from the identifiable quantities that make the homogenised cell reproduce the table in
** its mode, when that lowers the cell's RMSE). Local searches (NLopt BOBYQA over log rho and s/H,
** the stress scale in closed form) from the ordinary fit and a coarse grid. t->done = 1 when it
** ran; CF_E_DATA for a force-displacement table or a table no spring reaches, CF_E_INTERNAL when
** memory runs out. Deterministic. Once done, res's quality (rss, rmse, max_abs_error, r2,
** objective) and uncertainty (ident_se, corr, intervals, held) are the cell's, the target's: the
** single spring's own figures move to t->law_*. cf_validate_lattice_fit (validate.h) then verifies res. */
cf_status cf_lattice_fit(const cf_table *d, const cf_fit_options *opt, const cf_validate_setup *s,
                         cf_fit_result *res, cf_through_msm *t, cf_error *err);

/* The conical-tail law (fit.h) through the lattice for the type of plain (the conical law's fit
** through the lattice of the same table, done: its quantities start the search and its cell RMSE
** is t->rmse_before): the four identifiable quantities (rho, s/H, F_C/H^2 and the tail's share)
** searched through the homogenised cell (NLopt BOBYQA over three, the stress scale in closed
** form), their standard errors through the cell, and the tailed spring placed in closed form
** (src/fit/lattice_tail.c). res's quality is the cell's, as cf_lattice_fit's; no profile
** intervals. Errors as cf_lattice_fit's. Deterministic. */
cf_status cf_lattice_fit_tail(const cf_table *d, const cf_fit_options *opt,
                              const cf_validate_setup *s, const cf_fit_result *plain,
                              cf_fit_result *res, cf_through_msm *t, cf_error *err);

#endif
