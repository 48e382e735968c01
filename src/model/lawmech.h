/*
** A law kind's mechanics as a row of functions (as GSL's gsl_multifit_nlinear_type): what the
** lattice, the body, the exports and the fit file need of a law that is not the conical spring's.
** A law of such a kind (law_internal.h, cf_law_init_kind) holds its row and its quantities; law.h's
** entry points dispatch to the row, so no consumer names a kind.
**
** The quantities are those of the kind's fit to a stress-strain table (src/fit/lawkind.h: the
** row's quantities, in conifit's units, MPa and dimensionless): a kind describes a family of
** similar springs, and the one of free length H carries F(u) = H^2 sigma(q, u/H). The functions
** take H for that reason.
**
** A registry of kinds by name lets a fit file naming a kind the library does not define be read
** when its caller registered the kind (cf_law_mech_register); the library's own conical kinds are
** not rows: their laws keep the conical fast paths of law.c bit for bit.
*/
#ifndef CF_MODEL_LAWMECH_H
#define CF_MODEL_LAWMECH_H

#include <stddef.h>

#include "conifit/error.h"
#include "conifit/spring.h"

#define CF_LAW_Q_MAX 8 /* quantities of a kind's law, at most (as CF_Q_MAX of a fit) */

typedef struct cf_law_mech {
    const char *name;            /* the kind's name: the fit file's "law" */
    int nq;                      /* its quantities, at most CF_LAW_Q_MAX */
    const char *key[CF_LAW_Q_MAX]; /* each quantity's fit-file key (with its unit) under the
                                 ** fit's "law_params" */
    /* Force (N, with the sign of u) at compression u (mm; u < 0 stretches) of the spring of free
    ** length H (mm), and its tangent stiffness dF/du (N/mm, >= 0) in *k when k is not NULL. Past
    ** a side's travel the force stays at its value there and the stiffness is 0 (as the conical
    ** law's solid). Required. */
    double (*force)(const double *q, double H_mm, double u_mm, double *k);
    /* The same over count displacements (F, and k when not NULL); optional: NULL evaluates force
    ** point by point (the scalar fallback the lattice's step uses for such a kind). */
    void (*force_many)(const double *q, double H_mm, size_t count, const double *u_mm,
                       double *F_N, double *k_N_per_mm);
    /* The travel to solid on each side (side +1 compression, -1 stretch), mm, in (0, H].
    ** Required. */
    double (*travel)(const double *q, double H_mm, int side);
    /* The displacements (mm, increasing, in (0, U]) of the rows of a piecewise-linear table of the
    ** side of sign (+1 or -1; U the table's reach on that side, positive), at most max of them;
    ** returns their number (0: none, the export spaces them evenly). Optional. */
    size_t (*samples)(const double *q, double H_mm, int sign, double U_mm, size_t max,
                      double *u_mm);
    /* Its buildable spring at free length H (the design parameters the exports and reports
    ** give, checked by cf_law_init). Required. */
    cf_spring (*spring)(const double *q, double H_mm);
} cf_law_mech;

/* Registers kind mech by its name so that a fit file naming it can be read (io/fitfile.c). Not
** thread-safe: register before the threads that read fit files start. CF_E_DATA when the row
** lacks a required function, has nq outside [1, CF_LAW_Q_MAX] or a key missing, or names one of the
** library's kinds or another registered row; registering the same row twice is a no-op;
** CF_E_INTERNAL when the registry (CF_LAW_MECH_MAX rows) is full. */
#define CF_LAW_MECH_MAX 16
cf_status cf_law_mech_register(const cf_law_mech *mech, cf_error *err);

/* The registered kind of that name, or NULL. */
const cf_law_mech *cf_law_mech_find(const char *name);

#endif
