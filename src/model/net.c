/*
** Spring networks (net.h): the kind table of the volume elements and the release. The generators
** are their users': the cubic lattice's in lattice_net.c (lattice.h), the tetrahedral mesh's in
** net_mesh.c (body.h).
*/
#include "model/net.h"

#include <stdlib.h>
#include <string.h>

/* The kinds of volume element, one row each. */
static const struct {
    const char *name;
    int nodes;
} cell_kinds[] = {
    [CF_NET_TET4] = {"tet4", 4},
    [CF_NET_HEX8] = {"hex8", 8},
};

int cf_net_cell_size(cf_net_cell_kind kind)
{
    return cell_kinds[kind].nodes;
}

const char *cf_net_cell_name(cf_net_cell_kind kind)
{
    return cell_kinds[kind].name;
}

void cf_net_free(cf_net *n)
{
    if (!n)
        return;
    free(n->X);
    free(n->fix);
    free(n->si);
    free(n->sj);
    free(n->L0_mm);
    free(n->w);
    free(n->family);
    free(n->cell);
    memset(n, 0, sizeof *n);
}
