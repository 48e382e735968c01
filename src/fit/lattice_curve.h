/*
** The curve of one spring's lattice at the strains of a table, in the table's test mode: what the
** fit through the lattice minimises and what the validation measures. Private to the library.
*/
#ifndef CF_FIT_LATTICE_CURVE_H
#define CF_FIT_LATTICE_CURVE_H

#include "conifit/error.h"
#include "conifit/law.h"
#include "conifit/spring.h"
#include "fit/fit.h"
#include "model/msm.h"

/* Where the lattice comes from (the validation's lattice and the fits through it). */
typedef struct cf_validate_setup {
    cf_msm_config cfg;          /* lattice and Newton settings */
    cf_law_method method;       /* law evaluator in the lattice */
    size_t table_intervals;     /* table size when method is CF_LAW_TABLE */
} cf_validate_setup;


/* The curve of spring p at the strains of d in the table's mode: the full lattice (cf_msm_uniaxial)
** when full is set and the mode is uniaxial, else the homogenised cell (cell.h), which equals the
** full lattice wherever the lattice deforms homogeneously and is the only form of the other modes.
** *by_cell (may be NULL) says which ran; law_out (may be NULL) receives the law's own curve. */
cf_status cf_lattice_curve(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                           int full, double *out, double *law_out, cf_msm_stats *stats,
                           int *by_cell, cf_error *err);

/* The table the springs see in d's mode: a copy of d (sharing its y) whose x[i] is the largest
** spring strain at row i, with the row's sign, into spring_x (d->count values). In shear the
** springs strain about half the table's strain; in the other modes x is the table's own. */
cf_table cf_lattice_reach(const cf_table *d, double *spring_x);

/* The target's numbers of fit res once the cell's curve g of its spring at d's rows is known:
** res's quality (rss, rmse, max_abs_error, r2, and the weighted objective with weights sw and
** zero-model norm ynorm) become the cell's, the single spring's own figures move to law[0..2]
** (its RMSE, largest |error| and R^2: a uniaxial table; NAN in the other modes). */
void cf_lattice_take_quality(const cf_table *d, const double *g, const double *sw, double ynorm,
                             cf_fit_result *res, double law[3]);

#endif
