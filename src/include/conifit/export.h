/*
** Export of a fitted conical spring to other simulators: the law sampled into an adaptive
** force-displacement table (or fitted by a polynomial in strain), written in each target's own
** conventions and units.
**
** The table. Rows run from full stretch to just before solid, u in [-u_end, +u_end] (mm), with
** rows always at 0, +-u_T and +-u_end. Rows are placed by bisection until linear interpolation
** between two rows stays within the tolerance of the law, measured as
**     |F_table(u) - F(u)| <= tol * max(|F(u)|, CF_EXPORT_FLOOR * F_C)
** i.e. relative to the local force, with an absolute floor of tol * 1e-3 * F_C where the force
** itself is tiny (around u = 0; region 1 is linear, so the table is exact there anyway).
** Near solid the stiffness grows like (s - u)^(-1/2), so the table stops a hair before solid,
** at u_end = the compression where the law carries F_C (1 - tol): past u_end, a simulator that
** holds the last force constant is within tol * F_C of the law up to solid (where the law clamps
** at F_C), and one that extrapolates the last slope behaves as a stiff solid stop.
** The achieved error is measured afterwards on a dense grid independent of the rows (uniform in
** u, and uniform in sqrt(1 - |u|/s), which crowds towards solid) with the exact evaluator.
**
** Sign conventions: conifit's u > 0 compresses and F has the sign of u. CalculiX, Abaqus,
** FEBio, LS-DYNA and SOFA take tension positive, so their tables hold elongation = -u (mm) and
** force = -F(u) (N), ascending in elongation.
*/
#ifndef CF_EXPORT_H
#define CF_EXPORT_H

#include <stddef.h>
#include <stdio.h>

#include "conifit/error.h"
#include "conifit/fitfile.h"
#include "conifit/law.h"

/* Absolute floor of the table tolerance, as a fraction of F_C (see above). */
#define CF_EXPORT_FLOOR 1e-3
/* Default relative tolerance of the table, and the range accepted. Below 1e-9 the rows near
** solid would have to be closer than the spacing of doubles allows. */
#define CF_EXPORT_TOL_DEFAULT 1e-4
#define CF_EXPORT_TOL_MIN 1e-9
#define CF_EXPORT_TOL_MAX 0.1
/* CalculiX 2.20 keeps at most 200 (force, elongation) pairs of a nonlinear *SPRING and silently
** ignores the rest (found by running ccx on longer tables), so its export refuses larger tables. */
#define CF_EXPORT_CALCULIX_MAX_ROWS 200
/* Default and largest degree of the SOFA polynomial. */
#define CF_EXPORT_DEGREE_DEFAULT 7
#define CF_EXPORT_DEGREE_MAX 15

typedef enum cf_export_format {
    CF_EXPORT_JSON = 0,
    CF_EXPORT_CSV,
    CF_EXPORT_CALCULIX,
    CF_EXPORT_ABAQUS,
    CF_EXPORT_FEBIO,
    CF_EXPORT_LSDYNA,
    CF_EXPORT_SOFA
} cf_export_format;

/* A force-displacement table of the law, rows ascending in u. */
typedef struct cf_export_table {
    size_t rows;
    double *u_mm;        /* compression of each row, mm (ascending, odd-symmetric) */
    double *F_N;         /* force of the law at u, N */
    double *k_N_per_mm;  /* tangent stiffness of the law at u, N/mm */
    double tol;          /* requested relative tolerance */
    double u_end_mm;     /* last row: where the law carries F_C (1 - tol), mm */
    double max_err_rel;  /* achieved maximum of |F_table - F| / max(|F|, FLOOR F_C) */
    double max_err_N;    /* |F_table - F| at that point, N */
    double max_err_u_mm; /* where it occurs, mm */
} cf_export_table;

/* Samples the law into t (see the top of this file). CF_E_DATA for a tolerance outside
** [CF_EXPORT_TOL_MIN, CF_EXPORT_TOL_MAX], CF_E_INTERNAL when memory runs out. */
cf_status cf_export_table_build(const cf_law *law, double tol, cf_export_table *t, cf_error *err);

/* Releases the rows of t; safe on a zeroed table. */
void cf_export_table_free(cf_export_table *t);

/* Linear interpolation of the table at u (mm), N; the end rows' forces outside the table. */
double cf_export_table_eval(const cf_export_table *t, double u_mm);

/* A least-squares polynomial in strain for SOFA: tension force (N) = sum_k a[k-1] L^k, k = 1..
** degree, L = elongation / H = -u/H, fitted on a grid uniform in u over [-u_end, u_end]. */
typedef struct cf_export_poly {
    int degree;
    double a_N[CF_EXPORT_DEGREE_MAX]; /* coefficient of L^(k), N, k = 1..degree */
    double max_err_N;                 /* maximum |poly - law| on the check grid, N */
    double max_err_rel_FC;            /* the same relative to F_C */
} cf_export_poly;

cf_status cf_export_poly_fit(const cf_law *law, const cf_export_table *t, int degree,
                             cf_export_poly *poly, cf_error *err);

/* The polynomial's tension force (N) at strain L (elongation / H). */
double cf_export_poly_eval(const cf_export_poly *poly, double L);

/* What to write. Build with cf_export_default_options, then change fields. */
typedef struct cf_export_options {
    cf_export_format format;
    double tol;          /* relative tolerance of the table */
    int degree;          /* SOFA polynomial degree */
    int example;         /* calculix/abaqus: a complete one-spring .inp instead of the block */
    const char *source;  /* name of the fit file, for provenance ("" or NULL if none) */
    int auto_tol;        /* calculix: loosen tol (x2, x2.5, x2 ...) until the table fits
                         ** CF_EXPORT_CALCULIX_MAX_ROWS rows, instead of refusing */
} cf_export_options;

cf_export_options cf_export_default_options(void);

/* What was written: row count and achieved error, for the user. */
typedef struct cf_export_report {
    size_t rows;          /* rows of the table written (0 for json) */
    double max_err_rel;   /* achieved maximum error (table: relative, see above; sofa: / F_C) */
    double max_err_N;     /* the same in N */
    double u_end_mm;      /* last row of the table, mm */
    double tol;           /* tolerance the table was built with */
} cf_export_report;

/* Writes the spring in the chosen format to out. Never writes NaN or Inf. */
cf_status cf_export_write(FILE *out, const cf_fitted_spring *fs, const cf_export_options *opt,
                          cf_export_report *rep, cf_error *err);

/* Parses json | csv | calculix | abaqus | febio | lsdyna | sofa; CF_E_DATA otherwise. */
cf_status cf_export_format_parse(const char *name, cf_export_format *format, cf_error *err);
const char *cf_export_format_name(cf_export_format format);

#endif
