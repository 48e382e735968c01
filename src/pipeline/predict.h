/*
** A saved fit's prediction of tables, without refitting (conifit predict FIT.json TABLE...): the
** model the fit file describes -- the single spring's law for a fit to the spring, the lattice's
** homogenised cell for a fit through the lattice, single or joint (its weights, the double-acting
** element's extension spring, the volume term, a tail, as stored) -- evaluated in each table's
** test mode at the table's strains, by the evaluators the fit used (cf_fit_model's law, cell.h's
** cf_cell_curve as lattice_curve.c and the joint fit's verification run it), and compared with
** the measured stress: RMSE, R^2, the measured RMS stress and the joint objective's term
** (cf_joint_table_weights, joint.h: (RMSE / RMS)^2 with unit weights) with its share of the sum.
** A table the fit was fitted to (named in the fit file) gets the fit's own RMSE and term beside
** the prediction's, which reproduce them.
**
**   FIT.json --cf_fitfile_load_model--> model
**   cf_table x N --cf_predict--> cf_predict_result --cf_predict_text / cf_predict_prepare--> report,
**                                                                         CSV, figure
*/
#ifndef CF_PIPELINE_PREDICT_H
#define CF_PIPELINE_PREDICT_H

#include <stddef.h>
#include <stdio.h>

#include "base/atomic.h"
#include "conifit/error.h"
#include "io/fitfile.h"
#include "model/table.h"
#include "pipeline/predict_fibre.h"

/* What the fit's model is. */
typedef enum cf_predict_model {
    CF_PREDICT_SPRING = 0, /* the single spring's law (a fit whose target is the spring) */
    CF_PREDICT_CELL = 1    /* the lattice's homogenised cell (a fit through the lattice) */
} cf_predict_model;

/* One table's prediction. Figures in conifit's units (MPa or N), over the rows the model follows
** (every row unless the note says otherwise); all finite. */
typedef struct cf_predict_table {
    const cf_table *table;
    double *model;          /* the model's stress (MPa) or force (N) at each row; 0 at a row it
                            ** does not follow (owned) */
    unsigned char *follows; /* 1 at each row the model follows (owned) */
    size_t followed;        /* rows followed; ok is 0 when none (the figures are then 0) */
    int ok;
    double rmse, max_abs_error, r2;
    double rms;             /* RMS of the measured stress (or force): the objective's scale */
    double term;            /* the joint objective's term of the table (joint.h) */
    double share;           /* term over the sum of the tables' terms (0 when the sum is 0) */
    int fitted;             /* 1 + the fit file's entry of this table (cf_fitted_model.tab), 0
                            ** when the fit was not fitted to it */
    double fit_rmse;        /* fitted: the fit's own RMSE, MPa or N */
    double fit_term;        /* fitted: the fit's own term, (RMSE / scale)^2 as it records them
                            ** (a single fit records no scale: the table's RMS then) */
    double reach_to;        /* strain (table sign) past which the model cannot follow: the cell's
                            ** first spring at solid, or the single spring's travel; 0 when every
                            ** row is followed */
    int stability_lost;     /* 1: the cell's incremental stiffness loses positive definiteness
                            ** inside the table's range, at strain stable_to (table sign) */
    double stable_to;
    char note[CF_ERROR_MSG_LEN]; /* what the model cannot follow, "" when nothing */
} cf_predict_table;

typedef struct cf_predict_result {
    cf_fitted_model fit;    /* the fit file's model */
    char fit_path[1024];    /* the fit file as named */
    cf_predict_model model;
    size_t n;
    cf_predict_table *tab;  /* n tables (owned) */
    double sum_terms;       /* the sum of the followed tables' terms */
    size_t fitted;          /* how many of the tables the fit was fitted to */
    cf_pf_result fibre;     /* a joint fit's fibre-frame models (its "fibre_lattice" and
                            ** "holzapfel_ogden"), at the tables in the fibre frame; n 0 when
                            ** the file has none (predict_fibre.h) */
} cf_predict_result;

/* Loads the fit of type `type` (NULL: the file's better type) from the fit file at fit_path and
** evaluates it at each of the n tables (which must outlive r) in its test mode. CF_E_NOINPUT when
** the fit file cannot be opened; CF_E_DATA for a fit file cf_fitfile_load_model refuses, and for a
** table the fit's model cannot evaluate, the message naming the table and why: a mode other than
** uniaxial for the single spring's law (only a fit through the lattice has the other modes), a
** force-displacement table against a stress-strain fit or the other way round, a time series.
** Rows the model cannot follow (past a spring's solid length) leave the other rows' figures and a
** note, never a failure. A joint fit file with fibre-frame models (--fibres, a biaxial table) has
** them predicted too, into r->fibre (cf_pf_predict). Release r with cf_predict_free in every case. */
cf_status cf_predict(const char *fit_path, const char *type, const cf_table *const *tables,
                     size_t n, cf_predict_result *r, cf_error *err);

/* Releases the tables' curves. Safe on a zeroed result. */
void cf_predict_free(cf_predict_result *r);

/* The readable report: the model, one row per table with units, the sum of the terms against the
** fit's own objective, and the notes (malloc'd; NULL when memory runs out). */
char *cf_predict_text(const cf_predict_result *r);

/* The CSV of measured against predicted at every row to f (cf_predict_prepare's file): '#' lines
** naming the tables, the header table,mode,row,x,x_unit,measured,predicted,residual,y_unit,followed
** and one line per row, predicted and residual empty where the model does not follow the row. */
void cf_predict_write_csv(const cf_predict_result *r, FILE *f);

/* The CSV of measured against predicted at every row (each table's own units) and the figure
** (one panel per table: the measured points and the prediction), as complete temporaries beside
** their targets (either path NULL: not written; `inputs`, NULL-terminated, refused as targets);
** the caller commits them (cf_atomic_commit). On failure neither is left. */
cf_status cf_predict_prepare(const cf_predict_result *r, const char *csv_path,
                             const char *plot_path, const char *const *inputs,
                             cf_atomic *csv_out, cf_atomic *plot_out, cf_error *err);

#endif
