/*
** The cubic lattice's spring network (declared in lattice.h with the lattice, whose config it
** reads): nodes, springs of the families with their cell shares, the bottom face's fixity, the
** cells as hexahedra.
*/
#include "model/lattice.h"

#include "model/calibration.h"
#include "model/cell.h"
#include "model/net.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double cf_lattice_axis_share(int p, int o, int n)
{
    if (o != 0)
        return p + o >= 0 && p + o <= n ? 1.0 : 0.0;
    return p == 0 || p == n ? 0.5 : 1.0;
}

static size_t node_id(const cf_lattice_config *c, int i, int j, int k)
{
    return (size_t)i + (size_t)(c->nx + 1) * ((size_t)j + (size_t)(c->ny + 1) * (size_t)k);
}

/* The springs from node (i, j, k) along the noff cell directions off, each with its rest length
** and its weight (the family's, times the share of the cells that hold it); appended at n->ns. */
static void add_springs(cf_net *n, const cf_lattice_config *cfg, double H, const int (*off)[3],
                        int noff, int i, int j, int k)
{
    const size_t p = node_id(cfg, i, j, k);
    for (int o = 0; o < noff; o++) {
        int i2 = i + off[o][0], j2 = j + off[o][1], k2 = k + off[o][2];
        if (i2 < 0 || i2 > cfg->nx || j2 < 0 || j2 > cfg->ny || k2 < 0 || k2 > cfg->nz)
            continue;
        double share = cf_lattice_axis_share(i, off[o][0], cfg->nx) *
                       cf_lattice_axis_share(j, off[o][1], cfg->ny) *
                       cf_lattice_axis_share(k, off[o][2], cfg->nz); /* 1/4, 1/2 or 1 */
        int nzc = (off[o][0] != 0) + (off[o][1] != 0) + (off[o][2] != 0);
        size_t q = node_id(cfg, i2, j2, k2), ns = n->ns;
        n->si[ns] = (uint32_t)(p < q ? p : q);
        n->sj[ns] = (uint32_t)(p < q ? q : p);
        n->L0_mm[ns] = H * sqrt((double)nzc);
        n->w[ns] = share * cfg->weight[nzc - 1];
        n->family[ns] = (uint8_t)(nzc - 1);
        n->ns = ns + 1;
    }
}

/* The spring directions of the lattice of cfg into off (each unordered pair of neighbours once,
** those of the families of non-zero weight, in the order of cell.h): how many. */
static int lattice_dirs(const cf_lattice_config *cfg, int off[CF_CELL_DIRS][3])
{
    int noff = 0;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int fam;
        cf_cell_direction(d, off[noff], &fam);
        if (cfg->weight[fam] != 0)
            noff++;
    }
    return noff;
}

void cf_net_lattice_size(const cf_lattice_config *cfg, double *nodes, double *springs)
{
    int off[CF_CELL_DIRS][3];
    const int noff = lattice_dirs(cfg, off);
    const double dim[3] = {cfg->nx, cfg->ny, cfg->nz};
    *nodes = (dim[0] + 1) * (dim[1] + 1) * (dim[2] + 1);
    /* a direction of offsets o has prod (n_a + 1 - |o_a|) springs: the nodes whose far end is in */
    *springs = 0;
    for (int o = 0; o < noff; o++) {
        double c = 1;
        for (int a = 0; a < 3; a++)
            c *= dim[a] + 1 - abs(off[o][a]);
        *springs += c;
    }
}

/* The bottom face's fixity of cfg->bottom and the lattice's cells (x fastest). */
static void lattice_boundary_cells(cf_net *n, const cf_lattice_config *cfg)
{
    for (int j = 0; j <= cfg->ny; j++)
        for (int i = 0; i <= cfg->nx; i++) {
            size_t p = node_id(cfg, i, j, 0);
            n->fix[p] = CF_FIX_Z;
            if (cfg->bottom == CF_BOTTOM_CLAMPED)
                n->fix[p] |= CF_FIX_X | CF_FIX_Y;
        }
    if (cfg->bottom == CF_BOTTOM_AXIAL) {
        n->fix[node_id(cfg, 0, 0, 0)] |= CF_FIX_X | CF_FIX_Y;
        n->fix[node_id(cfg, cfg->nx, 0, 0)] |= CF_FIX_Y;
    }
    uint32_t *c = n->cell;
    for (int k = 0; k < cfg->nz; k++)
        for (int j = 0; j < cfg->ny; j++)
            for (int i = 0; i < cfg->nx; i++)
                for (int a = 0; a < 8; a++)
                    *c++ = (uint32_t)node_id(cfg, i + (a & 1), j + ((a >> 1) & 1),
                                             k + ((a >> 2) & 1));
}

cf_status cf_net_lattice_check_cells(const cf_lattice_config *cfg, cf_error *err)
{
    const int dims[3] = {cfg->nx, cfg->ny, cfg->nz};
    const char *names[3] = {"nx", "ny", "nz"};
    for (int a = 0; a < 3; a++)
        if (dims[a] < 1 || dims[a] > 10000)
            return cf_error_set(err, CF_E_DATA, "lattice.%s = %d: must be between 1 and 10000",
                                names[a], dims[a]);
    return CF_OK;
}

cf_status cf_net_lattice(cf_net *n, const cf_lattice_config *cfg, double H_mm, cf_error *err)
{
    memset(n, 0, sizeof *n);
    cf_status st = cf_net_lattice_check_cells(cfg, err);
    if (st != CF_OK)
        return st;
    if ((double)(cfg->nx + 1) * (cfg->ny + 1) * (cfg->nz + 1) > (double)UINT32_MAX)
        return cf_error_set(err, CF_E_DATA, "lattice %d x %d x %d cells: too many nodes to number",
                            cfg->nx, cfg->ny, cfg->nz);
    if (!(H_mm > 0) || !isfinite(H_mm))
        return cf_error_set(err, CF_E_DATA, "lattice cell edge %g mm: must be finite and > 0",
                            H_mm);
    int off[CF_CELL_DIRS][3];
    const int noff = lattice_dirs(cfg, off);
    n->nn = (size_t)(cfg->nx + 1) * (cfg->ny + 1) * (cfg->nz + 1);
    n->nc = (size_t)cfg->nx * cfg->ny * cfg->nz;
    n->cell_kind = CF_NET_HEX8;
    double nodes, springs;
    cf_net_lattice_size(cfg, &nodes, &springs);
    const size_t cap = (size_t)springs;
    n->X = malloc(3 * n->nn * sizeof *n->X);
    n->fix = calloc(n->nn, 1);
    n->si = malloc((cap ? cap : 1) * sizeof *n->si);
    n->sj = malloc((cap ? cap : 1) * sizeof *n->sj);
    n->L0_mm = malloc((cap ? cap : 1) * sizeof *n->L0_mm);
    n->w = malloc((cap ? cap : 1) * sizeof *n->w);
    n->family = malloc(cap ? cap : 1);
    n->cell = malloc(8 * n->nc * sizeof *n->cell);
    if (!n->X || !n->fix || !n->si || !n->sj || !n->L0_mm || !n->w || !n->family || !n->cell) {
        cf_net_free(n);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a %d x %d x %d lattice",
                            cfg->nx, cfg->ny, cfg->nz);
    }
    for (int k = 0; k <= cfg->nz; k++)
        for (int j = 0; j <= cfg->ny; j++)
            for (int i = 0; i <= cfg->nx; i++) {
                double *X = n->X + 3 * node_id(cfg, i, j, k);
                X[0] = i * H_mm;
                X[1] = j * H_mm;
                X[2] = k * H_mm;
                add_springs(n, cfg, H_mm, (const int (*)[3])off, noff, i, j, k);
            }
    lattice_boundary_cells(n, cfg);
    return CF_OK;
}
