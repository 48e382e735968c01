/*
** `simulate` on a scene with a tissue body (body.h): the probe pressed into the body step by step,
** the depth-force CSV, the ParaView files and the summary.
*/
#ifndef CF_CLI_BODY_H
#define CF_CLI_BODY_H

#include "model/body.h"
#include "io/budget.h"
#include "io/mesh.h"
#include "export/export.h"
#include "io/scene.h"

/* Runs sc (sc->has_body) and writes out (CSV, "-" for standard output) and, when vtu_dir is not
** NULL, vtu_dir/body_NNNN.vtu, springs_NNNN.vtu and body.pvd, and when png is not NULL the
** depth-force plot (cli_probe.h). Returns the exit status. */
int cf_cli_simulate_body(const cf_scene *sc, const char *scene_path, const char *out,
                         const char *vtu_dir, const char *png, const cf_budget *budget, int quiet);

/* Solves sc's body step by step as simulate does and writes it as a model (cf_export_write_body:
** CalculiX) to out, with conifit's force at every step in its header. */
cf_status cf_cli_body_export(const cf_scene *sc, const char *scene_path, const cf_budget *budget,
                             FILE *out, const cf_export_options *opt, cf_export_report *rep,
                             cf_error *err);

/* What every body command builds as simulate does (cli_haptic.c too): the scene's law (with its
** table; a double-acting element's extension spring into *ext, joined to *law: cf_scene_law; free
** both with cf_law_free) and mesh (read and refined, or filled from a closed surface; surface, which may be NULL,
** receives what filling found) under the budget's memory less the law tables
** (cf_budget_law_tables_bytes; CF_E_DATA naming scene_path and 'table_intervals' when they alone
** pass it), node_bytes being what the command will spend per node (refused before Gmsh starts
** when the mesh's estimate passes the limit); the
** body on them with the scene's volume term; the probe checked to start outside it (CF_E_DATA
** naming probe.center_mm and the node). */
cf_status cf_cli_body_load(const cf_scene *sc, const char *scene_path, const cf_budget *budget,
                           double node_bytes, cf_law *law, cf_law *ext, cf_mesh *mesh,
                           cf_mesh_surface_info *surface, cf_error *err);
cf_status cf_cli_body_create(const cf_scene *sc, const cf_law *law, const cf_mesh *mesh,
                             cf_body *b, cf_error *err);
/* cli_body_fibres.c: the scene's fibre groups ("fibres") on b, each entry's helix directions,
** spring and density (nothing without them); the summary's line per group, then the element
** term's (cf_cli_body_element_line). */
cf_status cf_cli_body_fibres(const cf_scene *sc, cf_body *b, cf_error *err);
void cf_cli_body_fibres_line(FILE *o, const cf_scene *sc, const cf_body *b);
/* cli_body_fibres.c too: the element term (body.element_term, cf_body_match_elements) on b when
** the scene asks for it, refused beside spring groups (CF_E_DATA naming the key); its summary
** line (nothing without it). */
cf_status cf_cli_body_element_term(const cf_scene *sc, cf_body *b, cf_error *err);
void cf_cli_body_element_line(FILE *o, const cf_body *b);
cf_status cf_cli_body_probe_outside(const cf_scene *sc, const char *scene_path,
                                    const cf_body *b, const cf_mesh *mesh, const cf_probe *probe,
                                    cf_error *err);

#endif
