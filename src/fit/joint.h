/*
** A joint fit through the lattice: several tables of one tissue, each in its own test mode
** (uniaxial tension, compression, simple shear, ...), fitted by one lattice, i.e. one set of
** identifiable quantities (rho, s/H, F_C/H^2) and, with the calibration `fitted`, the family
** weights too (conifit fit A.csv B.csv C.csv --joint).
**
** Weighting: table k's residuals are divided by its RMS stress s_k = sqrt(mean y^2) and by
** sqrt(n_k), so every table contributes its relative misfit once, whatever its stress scale and
** its number of rows; the objective is sum_k (1/n_k) sum_i ((model_ki - y_ki)/s_k)^2. The stress
** scale is solved in closed form for that weighting; (ln rho, s/H) and, when the weights are
** fitted, ln q (q = diagonal weight / edge weight, face = body; the weights then rescaled so the
** lattice's small-strain modulus is k0/H) by NLopt BOBYQA from a grid of starts, every curve
** through the homogenised cell (cell.h). The spring is placed from the quantities as the ordinary
** fit does, and each uniaxial table is then verified once in the full lattice.
*/
#ifndef CF_JOINT_H
#define CF_JOINT_H

#include <stddef.h>

#include "model/calibration.h"
#include "conifit/error.h"
#include "model/family.h"
#include "fit/fit.h"
#include "fit/lattice_fit.h"
#include "io/measure.h"

/* Most tables in one joint fit. */
#define CF_JOINT_MAX 16
/* A joint fit's lattice must stay stable to this factor times each table's farthest strain: a
** simulator that presses a little further than the test did must not meet a buckled lattice. */
#define CF_JOINT_STABLE_MARGIN 1.05
/* Between two candidates both buildable and stable over every range, one whose cell stays strongly
** elliptic (cf_joint_elliptic) is kept over one whose cell does not only when its weighted
** objective is at most this factor times the other's: within the 1.1x of a reference solid's fit
** the joint fit aims at, the elliptic one meets the same target; further off, the better fit is
** kept and the report says where its cell loses ellipticity. */
#define CF_JOINT_ELLIPTIC_SLACK 1.1
/* A fitted volume modulus is a material's, not a free knob: at most the kappa that gives the
** lattice of the compression spring this small-strain Poisson's ratio along an axis
** (cf_cubic_kappa_of_nu); a stiffer term models no tissue and makes the lattice ill-conditioned. */
#define CF_JOINT_NU_MAX 0.499

typedef struct cf_joint_table {
    cf_mode mode;
    size_t points;
    double scale_MPa;      /* the table's RMS stress s_k (its residual weight is 1/(s_k sqrt n_k)) */
    double cell_rmse;      /* the fitted lattice (homogenised cell) against the table, MPa */
    double lattice_rmse;   /* the full lattice (uniaxial tables; else the cell), MPa */
    int by_cell;           /* 1: lattice_rmse is the cell's (a mode the full lattice lacks) */
    double law_rmse;       /* the lattice against the law's own curve, MPa */
    double aic;            /* the table's AIC at the joint law (its rows, its unit, the law's
                           ** 3 or 4 quantities), as a single fit's report states it */
    double *lattice_MPa;   /* the lattice's stress at each row (owned), MPa */
    /* a double-acting element or a volume term (cell_stability.h, the cell of the placed
    ** springs and kappa): stability checked = 1, stable_in_range 1 when the cell's incremental
    ** stiffness stays positive definite from 0 to the table's farthest strain and, for a
    ** uniaxial table (lattice_checked = 1), the full lattices of 2^3 and 3^3 cells with a
    ** sliding bottom stay stable there too (no negative pivot of their tangent at the
    ** homogeneous state: no column of cells buckles); stable_to the strain up to which all do
    ** (table sign) */
    int stability_checked, stable_in_range, lattice_checked;
    double stable_to;
    /* 1: the lattice is unstable at rest already (stable_to under a thousandth of the range):
    ** never the better type nor the law kept over one that is not */
    int unstable_at_rest;
    /* strong ellipticity of the homogenised cell (cell_elliptic.h) along the table's mode from 0
    ** to the same CF_JOINT_STABLE_MARGIN x its farthest strain: elliptic_checked 1 where scanned,
    ** elliptic_in_range 1 when the acoustic tensor stays positive definite in every direction
    ** throughout; else elliptic_to the last strain where it does (table sign) and elliptic_n the
    ** unit direction (reference configuration) where it is first lost (zero where the mode
    ** cannot go on) */
    int elliptic_checked, elliptic_in_range;
    double elliptic_to;
    double elliptic_n[3];
} cf_joint_table;

typedef struct cf_joint_result {
    cf_fit_result fit;              /* the placed spring (quality fields against the first table) */
    cf_ident ident;                 /* rho, s/H, F_C/H^2 [MPa] the search found (family.h) */
    double weight[CF_FAMILY_COUNT]; /* the lattice's family weights */
    cf_calibration calibration;     /* isotropic, axial or fitted */
    double anisotropy_max;          /* fitted weights: the bound on |Zener ratio - 1| asked (0:
                                    ** none; cf_fit_options.anisotropy_max) */
    size_t ntables;
    cf_joint_table tab[CF_JOINT_MAX];
    double objective;               /* the weighted objective at the optimum, - */
    double aic;                     /* the joint AIC: N ln(objective/N) + 2k over all N rows, k 3
                                    ** (conical) or 4 (conical-tail); what auto compares */
    long evaluations;               /* cell curves computed */
    double wall_time_s;
    /* The double-acting element (law double-acting) and the volume term (joint fits only): */
    int pair;                       /* 1: fit is the compression spring, ext the extension one */
    cf_fit_result ext;              /* the extension spring placed (its ident, ident_se; H = fit's) */
    cf_volume volume;               /* how kappa was set: none, declared, from nu, fitted */
    double volume_modulus_MPa;      /* kappa of the volume term (0: none), MPa */
    double volume_modulus_se;       /* its standard error (fitted), MPa; -1 when not determined
                                    ** or not fitted */
    double nu_compression;          /* the lattice's small-strain nu in uniaxial compression
                                    ** along an axis (the cell at strain -1e-6): a pair's axial
                                    ** springs on their compression side, its lateral ones on
                                    ** their extension side */
    double nu_extension;            /* the same in uniaxial tension (+1e-6) */
    double E_compression_MPa;       /* the lattice's small-strain Young's modulus along an axis,
                                    ** in compression and in tension (MPa, the volume term
                                    ** included); NAN where the cell failed */
    double E_extension_MPa;
    int nparams;                    /* the quantities fitted (3, 4, 6 or 7; the AIC's k) */
    /* A conical-tail fit that is the conical optimum it contains (fit.tail 1, n_tail 0;
    ** cf_joint_fit_tail), or a pair that is the single-sided law's optimum as two equal springs
    ** (cf_joint_fit_pair): the weighted objective of the fit its search ended on (0: it found
    ** none, or the fit is its own); fit.nested_rmse and fit.nested_violated as for one table
    ** (fit.h). */
    double nested_objective;
    /* What the search tried: its starts (grid and space-filling), the ends of those whose lattice
    ** passed the stability check, and the searches restarted under the check (from each stable
    ** end and from the nearest stable point towards the unconstrained optimum). */
    int starts, stable_ends, restarts;
    /* the stable points found by projecting the unstable ends along stabilising directions (the
    ** searches from the best of them count among the restarts) */
    int projected;
} cf_joint_result;

/* Fits the n tables jointly with spring type `type` in the lattice of `lat` (its calibration:
** isotropic or axial as they are; CF_CAL_FITTED fits the weights). One table is a fit of that
** table alone by the same search. CF_E_DATA for no table or more than CF_JOINT_MAX tables, or a
** force-displacement table (its length scale is its own, not
** a strain a lattice shares; the message names the file). */
cf_status cf_joint_fit(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                       const cf_validate_setup *lat, cf_spring_type type, cf_joint_result *r,
                       cf_error *err);

/* The conical-tail law fitted jointly to the same tables as plain, the conical law's joint fit
** (its type, weights and quantities the start): its four quantities (rho, s/H, F_C/H^2, the tail
** tau) searched through the cell as a single table's are (lattice_fit.h, cf_lattice_fit_tail),
** each table weighted as in the conical joint fit, the tailed spring placed in closed form and
** r->fit.tail set. Fitted weights stay where the conical fit left them. The tailed law contains
** the conical one: a search that finds no tailed spring running every table, ends infeasible
** where plain is feasible, or ends with a larger weighted objective at the same feasibility
** returns plain with no tail (fit.tail 1, e_tail 0, n_tail 0; nested_objective says what the
** search ended on). */
cf_status cf_joint_fit_tail(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, const cf_joint_result *plain,
                            cf_joint_result *r, cf_error *err);

/* The double-acting element fitted jointly (opt->law double-acting, or any law with a volume term
** opt->volume): the compression spring's (rho, s/H, F_C/H^2) and, for the pair, the extension
** spring's, with kappa fitted, declared or derived from a declared nu, all through the cell (its
** springs' sides by the sign of their compression, cell.h); each table weighted as in the conical
** joint fit, BOBYQA from plain's quantities (may be NULL) and a grid. Both springs placed as the
** conical law's (the extension spring at the compression spring's H); errors of every quantity
** (kappa too) from the joint residuals' central-difference Jacobian, -1 for those the data do
** not determine (the Jacobian's null space). The pair contains plain (two equal springs, no
** volume term): plain's optimum is a start, and a pair infeasible where plain is feasible is
** plain's optimum as two equal springs (nested_objective what its search ended on). pair 0 fits
** the odd conical law with the volume term. pair 2 fits the pair with a tailed compression spring
** (conical-tail, its tau searched too: 7 quantities, 8 with kappa fitted) from plain, the pair's
** own joint fit (pair 1; CF_E_DATA otherwise), at tau 0.3, 1 and 3; the compression spring placed
** as the tailed law's (fit.tail 1, e_tail and its error); the extension spring stays conical.
** CF_E_DATA (pair 1, 2) when the tables do not determine both springs, the message naming the
** spring left free and why: a table with a loaded axis strains the springs along it directly only
** on its rows' side (positive strain: the extension spring), simple shear fixes about the sum of
** the two laws (determining the pair beside a table of either side, not alone). CF_E_DATA for a
** declared nu below the springs' own (the term only raises it), and for
** a declared nu with the pair (a bimodular lattice has one small-strain nu per side, none to
** declare: declare kappa or fit it). */
cf_status cf_joint_fit_pair(const cf_table *const *tables, size_t n, const cf_fit_options *opt,
                            const cf_validate_setup *lat, cf_spring_type type, int pair,
                            const cf_joint_result *plain, cf_joint_result *r, cf_error *err);

/* Whether the n tables determine both springs of a double-acting element (the check
** cf_joint_fit_pair makes first): CF_OK, or CF_E_DATA with its message. */
cf_status cf_joint_pair_determined(const cf_table *const *tables, size_t n, cf_error *err);

/* 1 unless a table's stability check (cf_joint_table) found the lattice losing stability inside
** that table's range (to CF_JOINT_STABLE_MARGIN times its farthest strain). */
int cf_joint_stable(const cf_joint_result *r);
/* 1 unless a table's check found the lattice unstable at rest (cf_joint_table.unstable_at_rest). */
int cf_joint_stable_at_rest(const cf_joint_result *r);
/* 1 unless a table's scan (cf_joint_table.elliptic_checked) found the homogenised cell losing
** strong ellipticity inside that table's range (to CF_JOINT_STABLE_MARGIN x its farthest strain). */
int cf_joint_elliptic(const cf_joint_result *r);
/* 1 when the candidate r2's ellipticity decides against r1 (both buildable and stable, r2
** elliptic, r1 not, r2's objective within CF_JOINT_ELLIPTIC_SLACK of r1's). */
int cf_joint_elliptic_wins(const cf_joint_result *r2, const cf_joint_result *r1);

/* The joint fit's one stability check, which its search applies to every point it keeps and its
** verification to the placed springs: the lattice of law (a pair through law's extension), family
** weights weight and volume modulus kappa (MPa), in lat's lattice, for each of the n tables the
** homogenised cell's incremental stiffness positive definite and, for a uniaxial table, the full
** lattices of 2^3 and 3^3 cells with a sliding bottom free of negative pivots, at 8 strains
** evenly from 0 to CF_JOINT_STABLE_MARGIN times the table's farthest strain. 1 stable, 0 not, -1
** out of memory. */
int cf_joint_lattice_stable(const cf_law *law, const double weight[CF_FAMILY_COUNT],
                            double kappa_MPa, const cf_validate_setup *lat,
                            const cf_table *const *t, size_t n);

/* The joint objective's weighting of table t, its one definition (the searches' and the
** prediction's, pipeline/predict.h): the table's RMS stress s = sqrt(mean y^2) (MPa) into *scale
** and each row's residual weight sqrt(w_i / n) / s into sw (t->count values; may be NULL), so that
** the table's term of the objective is sum_i (sw_i (model_i - y_i))^2, (RMSE / s)^2 with unit
** weights. Returns 0, or -1 when every stress is zero (no weight; *scale 0). */
int cf_joint_table_weights(const cf_table *t, double *scale, double *sw);

/* Releases the per-table curves. Safe on a zeroed result. */

void cf_joint_free(cf_joint_result *r);

#endif
