/*
** Law kinds as a table. A law kind is what a fit can put between a table and a spring: the
** conical spring's law, the conical spring with a cylindrical tail, the double-acting pair, or a
** kind a caller defines. Its row says everything the rest of the library needs to carry its fit:
** the number of identifiable quantities and, for each, its fit-file key, report label and unit in
** a stress-strain and in a force-displacement table; and how it is fitted: by a fitter of its own
** (the conical kinds, whose design constraints need one), or by the generic fit of this module
** (cf_law_kind_fit) from an evaluator y(q, x), a start and range of its quantities from the table,
** and the buildable spring of a set of quantities (its member).
**
** The fit, its profile intervals and errors, the law choice by AIC (k = nq), the report's rows
** and the fit file's keys read the row and never a literal count: a new kind is a row and its
** evaluators (tests/unit/test_lawkind.c adds a linear spring this way).
**
** The table lives in fit/ rather than model/ because a row names its fitter. Private to the
** library (the public headers name a kind by cf_law_kind, fit.h).
*/
#ifndef CF_FIT_LAWKIND_H
#define CF_FIT_LAWKIND_H

#include "conifit/error.h"
#include "model/family.h"
#include "fit/fit.h"
#include "fit/lattice_fit.h"
#include "io/measure.h"

/* One identifiable quantity. unit "y" is the table's stress or force unit (the report converts
** to the file's own); "" is dimensionless. The _force variants are a force-displacement table's. */
typedef struct cf_law_quantity {
    const char *key, *key_force;     /* fit-file keys */
    const char *label, *label_force; /* the report's row label */
    const char *name, *name_force;   /* the quantity in a sentence ("solid strain") */
    const char *unit, *unit_force;   /* "", "y" or a unit ("mm") */
    const char *zero_text;           /* NULL, or what the report shows when the value is exactly
                                     ** 0 (the tail's "none: conical") */
} cf_law_quantity;

typedef struct cf_law_row {
    const char *name;   /* its --law name and fit-file "law" */
    const char *title;  /* in a sentence: "the <title> (<nq> quantities)" */
    const char *adds;   /* what it adds to the kind it is compared with ("the tail"), or NULL */
    const char *spring; /* its spring in a sentence ("the tailed spring") */
    int nq;             /* identifiable quantities, at most CF_Q_MAX */
    int cone;           /* 1: its first three quantities are the cone's family (family.h), as
                        ** the conical kinds'; 0: its spring's family comes from its member */
    int ncorr;          /* the first ncorr of them have a correlation matrix (0: all nq); the
                        ** tailed law's is its cone's three */
    cf_law_quantity q[CF_Q_MAX];
    /* Its own fitter to one spring type (NULL: the generic fit below); plain is the conical
    ** fit of the same table and type, a start it may use. */
    cf_status (*fit)(const cf_table *t, const cf_fit_options *opt, cf_spring_type type,
                     const cf_fit_result *plain, cf_fit_result *res, cf_error *err);
    /* Its fitter through the lattice (NULL: the kind is fitted to the single spring only);
    ** plain and plain_thr are the conical law's fit through it. */
    cf_status (*fit_lattice)(const cf_table *t, const cf_fit_options *opt,
                             const cf_validate_setup *s, const cf_fit_result *plain,
                             const cf_through_msm *plain_thr, cf_fit_result *res,
                             cf_through_msm *thr, cf_error *err);
    /* For the generic fit: y (MPa or N) at x (strain or mm) of quantities q, all positive; the
    ** start and range of each quantity from the table (0 < lo <= start <= hi); the spring of q
    ** (free length 1 mm for a stress-strain table), checked against the design limits. */
    double (*eval)(const double *q, int force, double x);
    void (*range)(const cf_table *t, double *start, double *lo, double *hi);
    cf_spring (*member)(const double *q, int force, cf_spring_type type);
    /* Its mechanics (model/lawmech.h), so that its fitted law is its own in the lattice, the
    ** body, the exports and the fit file: the fit of a stress-strain table makes the law of its
    ** quantities (cf_law_init_kind, at its member's free length). NULL: its fit's law is the
    ** conical law of its member (so too a force-displacement fit, whose quantities are not the
    ** stress-strain family's). */
    const cf_law_mech *mech;
} cf_law_row;

/* The library's rows: the conical law and the conical law with a tail. (The double-acting pair
** is fitted jointly, joint.h; its row names its quantities.) */
extern const cf_law_row cf_law_conical_row, cf_law_tail_row, cf_law_double_row;

/* The row of a kind (NULL for CF_KIND_AUTO). */
const cf_law_row *cf_law_row_of(cf_law_kind kind);

/* Quantity k's key, label, sentence name and unit in table t's kind. */
const char *cf_law_q_key(const cf_law_row *row, int k, const cf_table *t);
const char *cf_law_q_label(const cf_law_row *row, int k, const cf_table *t);
const char *cf_law_q_name(const cf_law_row *row, int k, const cf_table *t);
const char *cf_law_q_unit(const cf_law_row *row, int k, const cf_table *t);

/* The kind of fit f: its kind, or (a fit made before kinds were recorded) the conical law or the
** tailed one by f->tail. */
const cf_law_row *cf_fit_kind_of(const cf_fit_result *f);

/* Where one fitted law kind stands in a law choice. */
typedef struct cf_law_standing {
    int feasible; /* its spring (or pair) is buildable within the limits */
    int stable;   /* its lattice is stable over every table's range (1 where not checked) */
    double aic;   /* its AIC (k its number of quantities) */
} cf_law_standing;

/* The one law choice of every fit (single, joint, pair): the index of the kind kept among the n
** fitted, s[0] the incumbent (the conical law, or the single-sided law a pair is compared with).
** asked >= 0: that one, asked for by name. Otherwise a kind replaces the one kept so far only
** when it is feasible, has a lower AIC, and is stable or the one kept is not either. */
int cf_law_pick(const cf_law_standing *s, int n, int asked);

/* The cone family (family.h) of fit f's spring: its first three quantities for the conical
** kinds, which are that family; for a kind of other quantities, its member's family. */
cf_ident cf_fit_family(const cf_fit_result *f, int force_displacement);

/* Fits kind row to table t for spring type `type`: the row's own fitter, or the generic fit
** (weighted least squares over log q within the row's range, NLopt BOBYQA then its errors
** s^2 (J^T W J)^-1 and profile intervals where a quantity sits on its range or is not
** determined; its spring is the row's member, checked against opt's design limits). res->kind is
** row. CF_E_DATA for a table it cannot fit, CF_E_INTERNAL when memory runs out. */
cf_status cf_law_kind_fit(const cf_law_row *row, const cf_table *t, const cf_fit_options *opt,
                          cf_spring_type type, const cf_fit_result *plain, cf_fit_result *res,
                          cf_error *err);

#endif
