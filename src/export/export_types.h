/*
** The export formats as a type, and the largest tables their targets read: what the registry
** (export.c, export.h) and the model writers (export_model.h) share. A header of its own, so that
** the writers depend on the type and not on the registry that calls them.
*/
#ifndef CF_EXPORT_TYPES_H
#define CF_EXPORT_TYPES_H

/* CalculiX copies a nonlinear spring's curve into a fixed local array of 200 (elongation, force)
** pairs with the pair count stored right after it (plconloc(802) in ccx's materialdata_sp.f);
** a longer table is read without a message and corrupts that count, which perturbs the whole
** curve. Exports for CalculiX (and Abaqus, so that the same file runs in both) keep to 200. */
#define CF_EXPORT_CALCULIX_MAX_ROWS 200
/* LS-DYNA rediscretizes every *DEFINE_CURVE to LCINT equally spaced points, 100 unless the
** curve's LCINT says otherwise (LSTC FAQ "discretization of curves"; *DEFINE_CURVE, remark 1), so
** its curves are written evenly spaced with LCINT = rows: the rediscretization then returns the
** rows themselves. An even table cannot follow the law's stiffening near solid with few rows
** (its curvature grows like (1 - F/F_C)^-3), so it has at most this many rows and its range stops
** where they meet the tolerance. */
#define CF_EXPORT_LSDYNA_MAX_ROWS 10000

/* The export formats. What each is and what writes it is held in one registry (export.c): a new
** format is a value here and an entry there; the command line builds its help, its --format check
** and its messages from the registry. */
typedef enum cf_export_format {
    CF_EXPORT_JSON = 0,
    CF_EXPORT_CSV,
    CF_EXPORT_CALCULIX,
    CF_EXPORT_ABAQUS,
    CF_EXPORT_FEBIO,
    CF_EXPORT_LSDYNA,
    CF_EXPORT_SOFA,
    CF_EXPORT_FORMAT_COUNT
} cf_export_format;

#endif
