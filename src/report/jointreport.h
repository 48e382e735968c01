/*
** What a joint fit reports (joint.h): the readable text, the fit file (JSON: the spring of each
** type in `fits[]` as in every fit file, so export and scenes read it, and `tables[]` with each
** table's mode, points, RMSE of the fit and of the lattice) and the figure (every table with its
** lattice curve, one panel per table).
*/
#ifndef CF_JOINTREPORT_H
#define CF_JOINTREPORT_H

#include <stddef.h>

#include "conifit/error.h"
#include "fit/holzapfel.h"
#include "fit/joint.h"
#include "io/measure.h"
#include "conifit/output.h"

/* Both laws of one type's joint fit (--law conical-tail or auto): the law not kept. */
typedef struct cf_joint_law_choice {
    int ran;                /* 1: the tailed law was fitted beside the conical one */
    int chose_tail;         /* 1: fits[] holds the tailed law, other the conical one */
    cf_joint_result other;  /* the other law's joint fit (its curves owned) */
    int pair_ran;           /* 1: the double-acting element was fitted too (double-acting, auto) */
    int chose_pair;         /* 1: fits[] holds the pair, pair_other the single-sided law it beat */
    cf_joint_result pair_other; /* the pair when not kept, else the law it displaced (owned) */
    char pair_refused[CF_ERROR_MSG_LEN]; /* auto: why the pair was not fitted ("" when it was,
                                         ** or the reason is a declared nu) */
    /* the pair with a tailed compression spring (cf_joint_fit_pair, pair 2) against the pair
    ** with a conical one: the one kept is the pair above, the other summarised here */
    int pair_tail_ran;          /* 1: the tailed pair was fitted (from the conical pair) */
    int pair_tail_kept;         /* 1: the pair above has the tailed compression spring */
    double alt_aic, alt_objective; /* the pair not kept: its joint AIC and weighted objective */
    int alt_feasible, alt_stable, alt_nparams;
} cf_joint_law_choice;

/* One joint fit per spring type over the same tables. */
typedef struct cf_joint_report {
    const cf_table *const *tables;
    size_t ntables;
    int nfits;
    cf_joint_result fits[2];
    cf_joint_law_choice law_choice[2];
    cf_law_kind law;          /* the law asked for (--law) */
    int with_timing;            /* 0: wall times written as 0 */
    /* The Holzapfel-Ogden baselines (holzapfel.h), fitted when a table is biaxial: ho_ran 1 and
    ** ho[form][cross] (form CF_HO_FULL, CF_HO_TI; cross 0: a biaxial table's second direction
    ** along s, 1: along n, where its plane does not say), or ho_why says why not ("" when no
    ** table is biaxial: nothing is said) */
    int ho_ran;
    cf_ho_fit ho[2][2];
    char ho_why[CF_ERROR_MSG_LEN];
} cf_joint_report;

/* Releases every fit's curves, the law not kept's too. Safe on a zeroed report. */
void cf_joint_report_free(cf_joint_report *r);

/* Index of the better fit (a lattice stable at rest first (cf_joint_stable_at_rest), then a
** feasible spring, then one stable over every table's range (cf_joint_stable), then one whose
** cell stays strongly elliptic within CF_JOINT_ELLIPTIC_SLACK of the other's objective
** (cf_joint_elliptic_wins), then the lower weighted objective), -1 when none. */
int cf_joint_better(const cf_joint_report *r);

/* The readable report (malloc'd; NULL when memory runs out). */
char *cf_joint_text(const cf_joint_report *r);

/* The fit file and the figure as complete temporaries beside their targets (either path NULL:
** not written); the caller commits them (cf_output_commit). On failure neither is left. */
cf_status cf_joint_prepare(const cf_joint_report *r, const char *json_path, const char *plot_path,
                           const char *const *inputs, cf_output *json_out,
                           cf_output *plot_out, cf_error *err);

#endif
