/*
** The reports as data, what the files of src/report/ (and the pipeline that fills them) share: one
** table's fit report (report.h: its text and fit file) and a joint fit's (jointreport.h). A header
** of its own, so that the parts of a report (report_words.h, report_baselines.h) depend on these
** types and not on the reports that use them.
*/
#ifndef CF_REPORT_TYPES_H
#define CF_REPORT_TYPES_H

#include "check/validate.h"
#include "conifit/error.h"
#include "fit/baseline.h"
#include "fit/fit.h"
#include "fit/fibre_fit.h"
#include "fit/holzapfel.h"
#include "fit/joint.h"
#include "fit/softening.h"

/* One table and its fits, as the report sees it (cf_pipeline_fit fills it). Values of the fits
** are in conifit's units (MPa or N); table->y_to_file converts them to the file's own unit for
** display and JSON. */
/* The law kinds fitted to one type (cf_fit_options.law conical-tail or auto, or the kinds a
** caller lists in cf_fit_options.kinds): each one's fit and AIC (n ln(RSS_w/n) + 2 k, k the
** kind's number of quantities, lawkind.h, on the weighted residuals), and the one kept in fits[]:
** the feasible one of lowest AIC, the conical law where no other is feasible and lower, or the
** one kind asked for. */
typedef struct cf_law_choice {
    int ran;                                /* 1: more than one kind was fitted */
    int n;                                  /* kinds fitted: cand[0] the conical law, then the
                                            ** others in the order asked */
    cf_fit_result cand[CF_LAW_KINDS_MAX];  /* their fits (cand[chosen] is fits[]'s) */
    double aic[CF_LAW_KINDS_MAX];
    int chosen;                             /* index of the one kept */
    int asked;                              /* 1: kept because it alone was asked for */
} cf_law_choice;

typedef struct cf_fit_report {
    const char *version;        /* conifit version */
    const cf_table *table;      /* the table fitted (not owned; outlives the report) */
    const char *title;          /* the figure's title; NULL: the table's name (its file name
                                ** without folder and extension) */
    cf_fit_options fit_options; /* the options the fits ran with (their limits are reported) */
    double ymax;                /* largest |y| in MPa or N */
    int nfits;                  /* 1 or 2 */
    cf_fit_result fits[2];
    cf_baseline baselines[CF_BASE_COUNT];
    int with_timing;            /* 0: write wall_time_s as 0 (for reproducible files) */
    int validate;               /* 1: each fit was run in the lattice (val[i]) */
    cf_validation val[2];       /* lattice validation of fits[i] (MPa; freed by cf_report_free) */
    int through_msm;            /* 1: each fit was refined through the lattice (thr[i]) */
    cf_through_msm thr[2];      /* what that cost and gained (MPa) */
    cf_softening softening;     /* where the table softens, which the law cannot follow */
    cf_limit_cost limit_cost[2]; /* what the limits holding fits[i] cost (checked when held) */
    cf_law_kind law;          /* the law kind asked for (fit.h) */
    cf_law_choice law_choice[2]; /* for fits[i], both laws (ran = 0 with the conical law alone) */
    /* The verdict on the two types, made once when the fit is made (cf_pipeline_fit) and read by
    ** every part of the report: with two fits cf_fit_compare's; with one, better 0 when its
    ** spring is feasible, else -1 (tie 0). */
    cf_fit_verdict verdict;
} cf_fit_report;

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
    /* The fibre-reinforced lattice (fibre_fit.h) when asked for (fibre_groups not ""): fibre_ran
    ** 1 and fibre[cross] (0: a biaxial table's second direction along s, 1: along n) with the CPU
    ** seconds of each fit, or fibre_why says why not */
    char fibre_groups[CF_FIBRE_MAX + 1];
    int fibre_ran;
    cf_fibre_fit fibre[2];
    double fibre_cpu_s[2];
    char fibre_why[CF_ERROR_MSG_LEN];
} cf_joint_report;

#endif
