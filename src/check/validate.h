/*
** Validation of a fitted spring in the mass-spring lattice.
**
** A single spring reproduces its table by construction; a lattice of such springs, with its
** diagonals, boundary conditions and lateral freedom, does not. cf_validate_run drives the lattice
** made of a fitted spring to every strain of the table (the table's own sign: tension positive)
** in the table's test mode and measures how far its nominal stress lies from the measured one
** (RMSE, R^2, max |error|) and from the law's own curve: a uniaxial table runs the full static
** lattice (msm.h, cf_msm_uniaxial); the other modes (shear, planar, equibiaxial, confined) run the
** homogenised cell (cell.h), which is the lattice under a homogeneous deformation.
**
** The fit through the lattice (lattice_fit.h) makes the lattice's curve the objective;
** cf_validate_lattice_fit verifies its result once in the full lattice.
**
** Stress-strain tables only: a force-displacement table is a single spring's curve, not a block
** of tissue, and its free length H is not determined by the data, so there is no sound nominal
** strain to drive the lattice with. Such tables are skipped with a note (CF_E_DATA here, which
** the caller reports as a note rather than a failure).
*/
#ifndef CF_VALIDATE_H
#define CF_VALIDATE_H

#include <stddef.h>

#include "model/cell.h"
#include "conifit/error.h"
#include "fit/fit.h"
#include "fit/lattice_fit.h"
#include "model/law_internal.h"
#include "model/msm.h"
#include "io/scene.h"

/* cf_msm_default() (3 x 3 x 3 cells, face and body diagonals, bottom axial) with the fitter's own
** evaluator, CF_LAW_CLOSED. */
cf_validate_setup cf_validate_default(void);

/* The setup of a scene, which must be a static uniaxial one: protocol kind "ramp" under a
** displacement drive ('to_strain') and no time-dependent effect. The scene's spring is not used
** (each fitted spring replaces it). CF_E_DATA naming the offending key otherwise. */
cf_status cf_validate_from_scene(const cf_scene *sc, const char *name, cf_validate_setup *s,
                                 cf_error *err);

/* The outcome of one validation. */
typedef struct cf_validation {
    int done;                   /* 1: run; 0: skipped (see note) */
    char note[CF_ERROR_MSG_LEN]; /* why it was skipped, empty when done */
    cf_validate_setup setup;    /* the lattice it ran */
    double rmse;                /* lattice stress against the table, MPa */
    double max_abs_error;       /* largest |lattice - table|, MPa */
    double r2;                  /* coefficient of determination of the lattice curve, - */
    double wall_time_s;         /* s */
    size_t solves;              /* static solves */
    size_t newton_iters;        /* Newton iterations in all */
    cf_mode mode;               /* the table's test mode */
    int by_cell;                /* 1: run by the homogenised cell (a mode the full lattice has no
                                ** boundary conditions for); 0: the full lattice */
    double law_rmse;            /* RMSE of the lattice against the law's own curve F(eH)/H^2:
                                ** what the lattice adds to the spring, MPa; NaN for
                                ** the other modes (the law's curve is a uniaxial one) */
    int stability_checked;      /* 1: the stability in the table's mode was sought (the full
                                ** lattice's negative pivots in uniaxial, the cell's tangent in
                                ** the other modes) */
    double stable_to_strain;    /* the largest strain (table sign) of the table's range up to which
                                ** it stays stable, on the table's side (compression when the table
                                ** has any): the table's reach when stable all the way */
    int unstable_in_range;      /* 1: the table reaches past stable_to_strain */
    int cell_stability_checked; /* 1: the cell's incremental stiffness was followed (every mode) */
    double cell_stable_to_strain; /* as stable_to_strain, for the cell's stiffness (cell_stability.h) */
    int cell_unstable_in_range; /* 1: the cell's stiffness stops being positive definite in range */
    char stability_note[CF_ERROR_MSG_LEN]; /* why the stability is not checked, else empty */
    size_t count;               /* points of stress_MPa */
    double *stress_MPa;         /* lattice stress at each table strain, MPa (owned; NULL if skipped) */
} cf_validation;

/* Runs the lattice made of spring p at the strains of d and fills v (v->stress_MPa malloc'd).
** CF_E_DATA for a force-displacement table or a strain at or past the spring's solid strain,
** CF_E_NOCONV when a static solve does not converge, CF_E_INTERNAL when memory runs out; on
** failure v->done = 0 and v->note holds the message. */
cf_status cf_validate_run(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                          cf_validation *v, cf_error *err);

/* Releases v->stress_MPa. Safe on a zeroed validation. */
void cf_validation_free(cf_validation *v);

/* The verification of a fit through the lattice (lattice_fit.h, cf_lattice_fit, which filled
** t and res): the reported spring res once in the validation lattice (v, freed and refilled here),
** t recording the validation RMSE and the largest difference between the full lattice and the
** cell the fit ran on. A force-displacement table is recorded as skipped (v->note, CF_E_DATA); a
** fit that did not run (t->done = 0) leaves v empty and err untouched. */
cf_status cf_validate_lattice_fit(const cf_table *d, const cf_validate_setup *s,
                                  const cf_fit_result *res, cf_validation *v, cf_through_msm *t,
                                  cf_error *err);

#endif
