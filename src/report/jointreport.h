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
#include "conifit/output.h"
#include "io/measure.h"
#include "report/report_types.h"

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
