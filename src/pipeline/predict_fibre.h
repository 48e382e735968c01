/*
** The fibre-frame models of a joint fit file, predicted at tables without refitting (part of
** conifit predict, predict.h): each "fibre_lattice" entry (one per biaxial cross-fibre axis: the
** matrix, the fibre groups, kappa; fibre_fit.h) and each "holzapfel_ogden" entry (full and
** transversely isotropic, per cross axis; holzapfel.h), evaluated at every row of each table
** that lies in the fibre frame (biaxial at any ratio, shear in a named plane: cf_ho_axes) by the
** evaluators the fits used (cf_fibre_row_stress, cf_ho_row_stress), with each table's RMSE and
** its term of the joint objective, (RMSE / RMS stress)^2 (cf_joint_table_weights).
** Fields of the file's entries are read by name; others are ignored.
*/
#ifndef CF_PIPELINE_PREDICT_FIBRE_H
#define CF_PIPELINE_PREDICT_FIBRE_H

#include <stddef.h>
#include <stdio.h>

#include "conifit/error.h"
#include "fit/fibre_fit.h"
#include "fit/holzapfel.h"
#include "model/table.h"

/* Most fibre-frame models of one fit file: a lattice, HO full and HO TI per cross axis. */
#define CF_PF_MAX 6

typedef enum cf_pf_kind { CF_PF_LATTICE = 0, CF_PF_HO = 1, CF_PF_HO_TI = 2 } cf_pf_kind;

/* One model's prediction of the tables. */
typedef struct cf_pf_model {
    cf_pf_kind kind;
    char cross;               /* 'n' or 's' */
    cf_fibre_fit lattice;     /* CF_PF_LATTICE: the quantities as stored */
    double ho[CF_HO_NP];      /* HO: a's in MPa, b's dimensionless (TI: a_s = a_fs = 0) */
    double fit_objective;     /* the objective the fit file records, - */
    double *rmse_MPa;         /* per table (owned); 0 where ok[k] is 0 */
    double *term;             /* per table (owned) */
    size_t *failed_row;       /* per table: 1 + the first row whose state the lattice's cell
                              ** does not reach (its figures then left out), 0 when none (owned) */
    double sum_terms;         /* over the tables it evaluates */
} cf_pf_model;

typedef struct cf_pf_result {
    int n;                    /* models read (0: the file has neither object) */
    cf_pf_model m[CF_PF_MAX];
    size_t ntables;
    unsigned char *ok;        /* per table: 1 when it lies in the fibre frame (owned) */
    double *rms_MPa;          /* per table: RMS of the measured stress (owned) */
} cf_pf_result;

/* Reads the fibre-frame models of the fit file at path and evaluates them at the n tables.
** r->n 0 (and CF_OK) when the file has no "fibre_lattice" and no "holzapfel_ogden". CF_E_NOINPUT
** when the file cannot be opened; CF_E_DATA naming the key for an entry whose quantity is missing
** or not finite, or a cell the quantities do not build; a table without axes is left out
** (ok[k] 0), as is a table at a row of which the lattice's cell finds no state (failed_row),
** never a failure. Release r with cf_pf_free in every case. */
cf_status cf_pf_predict(const char *path, const cf_table *const *tables, size_t n,
                        cf_pf_result *r, cf_error *err);

void cf_pf_free(cf_pf_result *r);

/* The report's section (nothing when r->n is 0): per table the RMSE (table's unit) and the term
** of each model, their sums against the objectives the fit recorded. */
void cf_pf_text(FILE *o, const cf_pf_result *r, const cf_table *const *tables);

#endif
