/*
** A body's spring groups (body.h, cf_body_set_groups): the springs with both ends in a region take
** a law of their own.
*/
#include "model/body.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/net.h"

/* The laws of the n springs into b->gown (owned) and b->glaw, each of the body law's H. */
static cf_status group_laws(cf_body *b, size_t n, const cf_spring *spring, const char *const *key,
                            size_t table_intervals, cf_error *err)
{
    b->gown = calloc(n, sizeof *b->gown);
    if (!b->gown)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's spring groups");
    b->ngroups = n;
    b->glaw[0] = b->law;
    for (size_t g = 0; g < n; g++) {
        const double H = b->law->p.H_mm;
        if (!(fabs(spring[g].H_mm - H) <= CF_GROUP_H_REL * H))
            return cf_error_set(err, CF_E_DATA,
                                "%s: the group's spring has free length H = %.10g mm; the body's "
                                "springs are calibrated with H = %.10g mm",
                                key[g], spring[g].H_mm, H);
        cf_status st = cf_law_init(&b->gown[g], &spring[g], err);
        if (st == CF_OK && b->method == CF_LAW_TABLE)
            st = cf_law_table_build(&b->gown[g], table_intervals, err);
        if (st != CF_OK)
            return st;
        b->glaw[g + 1] = &b->gown[g];
    }
    return CF_OK;
}

cf_status cf_body_set_groups(cf_body *b, const cf_mesh *m, size_t n, const cf_select *sel,
                             const cf_spring *spring, const char *const *key,
                             size_t table_intervals, cf_error *err)
{
    if (n == 0)
        return CF_OK;
    if (n > CF_BODY_MAX_GROUPS || b->group)
        return cf_error_set(err, CF_E_DATA, "body: %zu spring groups: at most %d, set once", n,
                            CF_BODY_MAX_GROUPS);
    cf_status st = group_laws(b, n, spring, key, table_intervals, err);
    if (st != CF_OK)
        return st;
    b->group = calloc(b->ns ? b->ns : 1, 1);
    uint8_t *mark = malloc(m->nn ? m->nn : 1);
    if (!b->group || !mark) {
        free(mark);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's spring groups");
    }
    for (size_t g = 0; g < n; g++) {
        memset(mark, 0, m->nn);
        cf_mesh_select(m, &sel[g], mark);
        size_t held = 0;
        for (size_t s = 0; s < b->ns; s++) {
            if (!mark[b->si[s]] || !mark[b->sj[s]])
                continue;
            if (b->group[s]) {
                st = cf_error_set(err, CF_E_DATA,
                                  "%s: its region overlaps that of %s (both hold the spring between "
                                  "nodes %u and %u): a spring takes one group's law",
                                  key[g], key[b->group[s] - 1], (unsigned)b->si[s],
                                  (unsigned)b->sj[s]);
                free(mark);
                return st;
            }
            b->group[s] = (uint8_t)(g + 1);
            held++;
        }
        if (held == 0) {
            free(mark);
            return cf_error_set(err, CF_E_DATA,
                                "%s: the group is empty (no spring has both ends in its region "
                                "'%s')",
                                key[g], cf_select_name(sel[g].kind));
        }
    }
    free(mark);
    return CF_OK;
}
