/*
** The curve of one spring's lattice at the strains of a table, in the table's test mode: what the
** fit through the lattice minimises and what the validation measures. Private to the library.
*/
#ifndef CF_FIT_LATTICE_CURVE_H
#define CF_FIT_LATTICE_CURVE_H

#include "conifit/lattice_fit.h"

/* The curve of spring p at the strains of d in the table's mode: the full lattice (cf_msm_uniaxial)
** when full is set and the mode is uniaxial, else the homogenised cell (cell.h), which equals the
** full lattice wherever the lattice deforms homogeneously and is the only form of the other modes.
** *by_cell (may be NULL) says which ran; law_out (may be NULL) receives the law's own curve. */
cf_status cf_lattice_curve(const cf_spring *p, const cf_validate_setup *s, const cf_table *d,
                           int full, double *out, double *law_out, cf_msm_stats *stats,
                           int *by_cell, cf_error *err);

#endif
