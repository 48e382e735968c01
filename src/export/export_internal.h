/*
** What the export registry (export.c) gives the exports of runnable models (export_lattice.c,
** export_body.c): a model written through its format's writer, and the law's table and its report
** for the options. Private to the export layer.
*/
#ifndef CF_EXPORT_INTERNAL_H
#define CF_EXPORT_INTERNAL_H

#include <stdio.h>

#include "conifit/error.h"
#include "export/export.h"
#include "export/export_model.h"

/* A body's fibre groups into m (export_fibres.c): one embedded spring per tetrahedron and group
** with its ends' equations, and tables of the groups' laws (ft[k] group k's table) by weight;
** adds their tables' share to m->reaction_tol_N along the solved states m->xk_mm (m->dz_mm and
** m->nsteps set). 0, or -1 out of memory. */
int cf_xmodel_body_fibres(cf_xmodel *m, const cf_body *b, const cf_export_table *ft);

/* A lattice's fibre groups (lat->cfg.fibre) into m, one embedded spring per cell and group tied to
** the cell's 8 nodes (m->cell) with trilinear weights, each group's table from ft[k]; adds their
** share to m->reaction_tol_N. 0, or -1 out of memory. */
int cf_xmodel_lattice_fibres(cf_xmodel *m, const cf_lattice *lat, const cf_export_table *ft);

/* Writes m in format f through the format's model writer (export.c's registry): 0, or -1 for a
** format without models or when memory runs out. */
int cf_xmodel_write(FILE *out, const cf_xmodel *m, cf_export_format f);

/* The table of the law for opt: its range and tolerance, kept to CalculiX's 200 pairs for
** calculix and abaqus (loosening the tolerance when opt->auto_tol, else CF_E_DATA naming the
** tolerance that fits). */
cf_status cf_export_table_for(const cf_law *law, const cf_export_options *opt,
                              cf_export_table *t, cf_error *err);

/* The report of a table of law: its rows, tolerance, achieved error, range and force at its ends
** (the rest zero). */
cf_export_report cf_export_report_of_table(const cf_export_table *t, const cf_law *law);

#endif
