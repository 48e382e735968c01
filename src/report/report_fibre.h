/*
** How a joint report states its fibre-reinforced lattice (fibre_fit.h; report_types.h's
** fibre_*): in the text, beside the Holzapfel-Ogden baselines, and in the fit file's
** "fibre_lattice". Private to src/report/ (and its tests).
*/
#ifndef CF_REPORT_FIBRE_H
#define CF_REPORT_FIBRE_H

#include <stdio.h>

#include <jansson.h>

#include "report/report_types.h"

/* The fibre lattices (both cross-fibre choices) as text into o; nothing when none was asked. */
void cf_report_fibre_text(FILE *o, const cf_joint_report *r);

/* The same as the fit file's array (NULL when none was fitted or memory runs out). */
json_t *cf_report_fibre_json(const cf_joint_report *r);

#endif
