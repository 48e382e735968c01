/*
** A body scene's fibre groups on the body (cli_body.h): each "fibres" entry's helix directions,
** spring and density (cf_body_helix_dirs, cf_body_add_fibres), and their line in the summary;
** and the body's other added term, its element term (body.element_term), with its line.
*/
#include "cli/cli_body.h"

#include <stdio.h>
#include <stdlib.h>

cf_status cf_cli_body_fibres(const cf_scene *sc, cf_body *b, cf_error *err)
{
    if (sc->body_nfibres == 0)
        return CF_OK;
    double *dir = malloc((b->nt ? 3 * b->nt : 1) * sizeof *dir);
    if (!dir)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's fibres");
    cf_status st = CF_OK;
    for (size_t k = 0; k < sc->body_nfibres && st == CF_OK; k++) {
        const cf_scene_body_fibre *f = &sc->body_fibres[k];
        char key[32];
        snprintf(key, sizeof key, "fibres[%zu]", k);
        cf_error e = {0};
        st = cf_body_helix_dirs(b, f->normal, f->reference, f->from_deg, f->to_deg, dir, &e);
        if (st != CF_OK) {
            cf_error_set(err, st, "%s.helix: %s", key, e.msg);
            break;
        }
        if ((st = cf_body_add_fibres(b, &f->spring, f->density, f->slack, dir,
                                     sc->table_intervals, key, &e)) != CF_OK)
            cf_error_set(err, st, "%s", e.msg);
    }
    free(dir);
    return st;
}

void cf_cli_body_fibres_line(FILE *o, const cf_scene *sc, const cf_body *b)
{
    for (size_t k = 0; k < sc->body_nfibres && k < b->nfibre; k++) {
        const cf_scene_body_fibre *f = &sc->body_fibres[k];
        fprintf(o, "fibres %zu: helix from %.6g to %.6g degrees through the thickness along "
                   "(%.6g, %.6g, %.6g), from (%.6g, %.6g, %.6g); spring %s, density %.6g per "
                   "cell of %.6g mm, tension only\n",
                k, f->from_deg, f->to_deg, f->normal[0], f->normal[1], f->normal[2],
                f->reference[0], f->reference[1], f->reference[2], f->source, f->density,
                b->law->p.H_mm);
    }
    cf_cli_body_element_line(o, b);
}

cf_status cf_cli_body_element_term(const cf_scene *sc, cf_body *b, cf_error *err)
{
    if (!sc->body_element_term)
        return CF_OK;
    if (sc->ngroups)
        return cf_error_set(err, CF_E_DATA, "key 'body.element_term' = true: the element term "
                            "takes one spring for the whole body, not the %zu groups of 'groups'",
                            sc->ngroups);
    cf_error e = {0};
    const cf_status st = cf_body_match_elements(b, &e);
    return st == CF_OK ? CF_OK : cf_error_set(err, st, "key 'body.element_term': %s", e.msg);
}

void cf_cli_body_element_line(FILE *o, const cf_body *b)
{
    if (b->elem)
        fprintf(o, "element term: every tetrahedron carries the isotropic tensor (E = %.6g kPa, "
                   "nu = %.6g) less its springs' share (body.element_term)\n",
                b->E_MPa * 1e3, b->nu);
}
