/*
** The law as a force-displacement table (export_table.c), what every export writes.
**
** Rows run over a range of compressions u (mm), by default from full stretch to just before solid, with rows always at 0, +-u_T and the two ends. The
** tolerance is a fraction of the solid load: everywhere in the range
**     |F_table(u) - F(u)| <= tol * F_C.
** Nodes are placed by equidistributing the interpolation error (density ~ |F''|^(1/2)), interior
** values are moved by half the local interpolation error (a best approximation rather than the
** interpolant), and the achieved error is measured on a dense grid that knows nothing of the rows
** (uniform in u, and uniform in sqrt(1 - |u|/s), which crowds towards solid). Near solid the
** stiffness grows like (s - u)^(-1/2), so the full range stops at u_end, where the law carries
** F_C (1 - tol): a simulator that holds the last force beyond it (CalculiX, FEBio CONSTANT) is
** within tol F_C of the law up to solid.
**
** Private to the export layer (export.h includes it for its callers).
*/
#ifndef CF_EXPORT_TABLE_H
#define CF_EXPORT_TABLE_H

#include <stddef.h>

#include "conifit/error.h"
#include "model/law_internal.h"

/* Default tolerance of the table (fraction of F_C), and the range accepted. Below 1e-9 the rows
** near solid would have to be closer than the spacing of doubles allows. */
#define CF_EXPORT_TOL_DEFAULT 1e-4
#define CF_EXPORT_TOL_MIN 1e-9
#define CF_EXPORT_TOL_MAX 0.1

/* A force-displacement table of the law, rows ascending in u. */
typedef struct cf_export_table {
    size_t rows;
    double *u_mm;        /* compression of each row, mm (ascending) */
    double *F_N;         /* force of the table at u, N (within tol F_C of the law) */
    double *k_N_per_mm;  /* tangent stiffness of the law at u, N/mm */
    double tol;          /* requested tolerance, fraction of F_C */
    double u_lo_mm;      /* first row (<= 0: the largest stretch), mm */
    double u_hi_mm;      /* last row (>= 0: the largest compression), mm */
    double max_err_rel;  /* achieved maximum |F_table - F| / F_C over [u_lo, u_hi] */
    double max_err_N;    /* the same in N */
    double max_err_u_mm; /* where it occurs, mm */
    int even;            /* 1: rows evenly spaced in u (cf_export_table_build_even) */
    double req_lo_mm, req_hi_mm; /* the range asked for, mm; an even table's [u_lo, u_hi] may be
                         ** shorter (where its rows meet the tolerance) */
} cf_export_table;

/* Where the full-range table ends: the compression (mm) at which the law carries F_C (1 - tol);
** with a cylindrical tail F_solid - tol F_C, in the tail's straight region 3. */
double cf_export_table_end(const cf_law *law, double tol);

/* Samples the law into t over [-u_end, u_end] (see the top of this file). CF_E_DATA for a
** tolerance outside [CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX] or a spring whose table does not reach
** the tolerance (the message gives the achieved error), CF_E_INTERNAL when memory runs out. */
cf_status cf_export_table_build(const cf_law *law, double tol, cf_export_table *t, cf_error *err);

/* The same over [u_lo, u_hi] (mm, u_lo <= 0 <= u_hi): CF_E_DATA naming the limit when the range
** passes the end of the travel (|u| > u_end) or does not contain the rest state. */
cf_status cf_export_table_build_range(const cf_law *law, double tol, double u_lo_mm,
                                      double u_hi_mm, cf_export_table *t, cf_error *err);

/* An evenly spaced table of the law (rows on the law) over [u_lo, u_hi], or over the part of it
** where at most max_rows (>= 2) evenly spaced rows meet the tolerance: the fewest rows that meet
** it over the whole range; else max_rows rows over the range cut at |u| <= U, the largest U for
** which they do (the error measured on the check grid of the adaptive table). t->req_lo_mm and
** t->req_hi_mm keep the range asked for. Errors as cf_export_table_build_range. */
cf_status cf_export_table_build_even(const cf_law *law, double tol, double u_lo_mm,
                                     double u_hi_mm, size_t max_rows, cf_export_table *t,
                                     cf_error *err);

/* Releases the rows of t; safe on a zeroed table. */
void cf_export_table_free(cf_export_table *t);

/* Linear interpolation of the table at u (mm), N; the end rows' forces outside the table. */
double cf_export_table_eval(const cf_export_table *t, double u_mm);

#endif
