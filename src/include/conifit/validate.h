/*
** Validation of a fitted spring in the mass-spring lattice, and the fit through the lattice.
**
** A single spring reproduces its table by construction; a lattice of such springs, with its
** diagonals, boundary conditions and lateral freedom, does not. cf_validate_run drives the lattice
** made of a fitted spring to every strain of the table (the table's own sign: tension positive)
** in the table's test mode and measures how far its nominal stress lies from the measured one
** (RMSE, R^2, max |error|) and from the law's own curve: a uniaxial table runs the full static
** lattice (msm.h, cf_msm_uniaxial); the other modes (shear, planar, equibiaxial, confined) run the
** homogenised cell (cell.h), which is the lattice under a homogeneous deformation.
**
** cf_validate_through_msm makes the lattice's curve the objective (conifit fit --target lattice):
** it optimises the three identifiable quantities (rho, solid strain s/H, stress scale F_C/H^2;
** the lattice's stress depends on the design parameters only through them, as the single
** spring's does) through the homogenised cell, places the design parameters as the ordinary fit
** does (cf_fit_place), and verifies the result once in the full lattice.
**
** Stress-strain tables only: a force-displacement table is a single spring's curve, not a block
** of tissue, and its free length H is not determined by the data, so there is no sound nominal
** strain to drive the lattice with. Such tables are skipped with a note (CF_E_DATA here, which
** the caller reports as a note rather than a failure).
*/
#ifndef CF_VALIDATE_H
#define CF_VALIDATE_H

#include <stddef.h>

#include "conifit/cell.h"
#include "conifit/error.h"
#include "conifit/fit.h"
#include "conifit/law.h"
#include "conifit/msm.h"
#include "conifit/scene.h"

/* Where the lattice comes from. */
typedef struct cf_validate_setup {
    cf_msm_config cfg;          /* lattice and Newton settings */
    cf_law_method method;       /* law evaluator in the lattice */
    size_t table_intervals;     /* table size when method is CF_LAW_TABLE */
} cf_validate_setup;

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
    int stability_checked;      /* 1: the static uniaxial lattice's stability limit was sought */
    double stable_to_strain;    /* the strain (table sign) where the lattice first loses stability
                                ** on the table's side (compression when the table has any), or 0
                                ** when it stays stable up to 0.995 of the solid strain */
    int unstable_in_range;      /* 1: the table reaches past stable_to_strain */
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

/* What the fit through the lattice did. */
typedef struct cf_through_msm {
    int done;                   /* 1: run */
    int improved;               /* 1: the spring was replaced (the lattice fits better) */
    double rmse_before;         /* RMSE of the ordinary fit in the lattice (homogenised cell), MPa */
    double cell_rmse;           /* RMSE of the reported spring through the cell: the fit's, MPa */
    double rmse_after;          /* validation RMSE of the reported spring (full lattice), MPa */
    int verified;               /* 1: the full lattice ran (uniaxial); 0: the mode is the cell's */
    double verify_max_abs;      /* largest |full lattice - cell| at the table's strains, MPa */
    double ident_before[3];     /* rho, s/H, F_C/H^2 [MPa] of the ordinary fit */
    double ident_after[3];      /* the same after the lattice objective */
    double wall_time_s;         /* s, the optimisation and the placement */
    long evaluations;           /* cell curves computed */
} cf_through_msm;

/* The fit through the lattice for one fitted spring res (in: the ordinary fit; out: the spring
** placed from the identifiable quantities that make the homogenised cell (cell.h) reproduce the
** table in its mode, when that lowers the cell's RMSE). Local searches (NLopt BOBYQA over
** log rho and s/H, the stress scale in closed form) from the ordinary fit and a coarse grid; the
** reported spring is then validated once (v, freed and refilled here) in the validation lattice,
** and t records the cell's fit RMSE against the full lattice's. Deterministic. */
cf_status cf_validate_through_msm(const cf_table *d, const cf_fit_options *opt,
                                  const cf_validate_setup *s, cf_fit_result *res,
                                  cf_validation *v, cf_through_msm *t, cf_error *err);

#endif
