/*
** The mass-spring lattice (see lattice.h): its net (net.h: nodes, springs, weights and the bottom's
** fixity, made by cf_net_lattice) copied into structures of arrays with the nodes' masses and the
** top face, and the force kernel the solvers call on every step.
*/
#include "model/lattice.h"
#include "model/lattice_cells.h"
#include "base/gslguard.h"

#include "model/cell.h"
#include "model/lattice_hourglass.h"
#include "model/net.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>

#include <gsl/gsl_integration.h>

cf_lattice_config cf_lattice_default(void)
{
    cf_lattice_config c;
    c.nx = c.ny = c.nz = 3;
    c.calibration = CF_CAL_ISOTROPIC;
    cf_calibration_weights(c.calibration, c.weight, NULL);
    c.density_t_per_mm3 = 1e-9;
    c.bottom = CF_BOTTOM_AXIAL;
    c.volume_modulus_MPa = 0;
    c.hourglass = CF_HOURGLASS_AUTO;
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        c.group_law[f] = NULL;
    c.fibre = NULL;
    c.nfibre = 0;
    return c;
}

/* Largest lattice accepted: keeps node indices in uint32 and memory bounded (about 2e7 springs). */
#define CF_LATTICE_MAX_NODES 1500000.0

void cf_lattice_free(cf_lattice *lat)
{
    if (!lat)
        return;
    double **d[] = {&lat->x, &lat->y, &lat->z, &lat->X, &lat->Y, &lat->Z, &lat->mass_t, &lat->fx,
                    &lat->fy, &lat->fz, &lat->L0_mm, &lat->a, &lat->w, &lat->L_mm, &lat->u_mm,
                    &lat->F_N, &lat->k_N_per_mm, &lat->T_N, &lat->top_share};
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) {
        free(*d[i]);
        *d[i] = NULL;
    }
    free(lat->gidx), free(lat->gu), free(lat->gF), free(lat->gk);
    lat->gidx = NULL;
    lat->gu = lat->gF = lat->gk = NULL;
    free(lat->fix);
    free(lat->family);
    lat->family = NULL;
    free(lat->si);
    free(lat->sj);
    free(lat->top);
    lat->fix = NULL;
    lat->si = lat->sj = lat->top = NULL;
}

static size_t node_id(const cf_lattice_config *c, int i, int j, int k)
{
    return (size_t)i + (size_t)(c->nx + 1) * ((size_t)j + (size_t)(c->ny + 1) * (size_t)k);
}

/* The configuration is one a lattice can be built from: CF_E_DATA naming what is not. */
static cf_status check_config(const cf_lattice_config *cfg, cf_error *err)
{
    cf_status st = cf_net_lattice_check_cells(cfg, err);
    if (st != CF_OK)
        return st;
    if ((double)(cfg->nx + 1) * (cfg->ny + 1) * (cfg->nz + 1) > CF_LATTICE_MAX_NODES)
        return cf_error_set(err, CF_E_DATA,
                            "lattice %d x %d x %d cells: more than %.0f nodes", cfg->nx, cfg->ny,
                            cfg->nz, CF_LATTICE_MAX_NODES);
    if (!(cfg->density_t_per_mm3 > 0) || !isfinite(cfg->density_t_per_mm3))
        return cf_error_set(err, CF_E_DATA, "density_t_per_mm3 = %g: must be finite and > 0",
                            cfg->density_t_per_mm3);
    if (!(cfg->volume_modulus_MPa >= 0 && cfg->volume_modulus_MPa <= CF_KAPPA_MAX_MPA))
        return cf_error_set(err, CF_E_DATA,
                            "lattice volume_modulus_MPa = %g: must be >= 0 and at most %g MPa "
                            "(" CF_KAPPA_MAX_WHY ")",
                            cfg->volume_modulus_MPa, CF_KAPPA_MAX_MPA);
    if (!(cfg->hourglass == CF_HOURGLASS_AUTO || (cfg->hourglass >= 0 && cfg->hourglass <= 1000)))
        return cf_error_set(err, CF_E_DATA, "lattice hourglass = %g: must be from 0 to 1000 (the "
                                            "fraction of the cell's shear stiffness)",
                            cfg->hourglass);
    if (cfg->nfibre < 0 || cfg->nfibre > CF_FIBRE_MAX || (cfg->nfibre > 0 && !cfg->fibre))
        return cf_error_set(err, CF_E_DATA, "lattice fibre groups: %d, must be 0 to %d (and "
                            "given)", cfg->nfibre, CF_FIBRE_MAX);
    for (int k = 0; k < cfg->nfibre; k++) {
        cf_status sf = cf_fibre_check(&cfg->fibre[k], err);
        if (sf != CF_OK)
            return sf;
    }
    return cf_calibration_check(cfg->weight, err);
}

/* The arrays of nn nodes, at most cap springs and ntop top nodes, zeroed: 0, or -1 when memory
** runs out (what was allocated is left for cf_lattice_free). */
static int lattice_alloc(cf_lattice *lat, size_t nn, size_t cap, size_t ntop)
{
    double **nd[] = {&lat->x, &lat->y, &lat->z, &lat->X, &lat->Y, &lat->Z,
                     &lat->mass_t, &lat->fx, &lat->fy, &lat->fz};
    for (size_t i = 0; i < sizeof nd / sizeof nd[0]; i++)
        if (!(*nd[i] = calloc(nn, sizeof(double))))
            return -1;
    double **sd[] = {&lat->L0_mm, &lat->a, &lat->w, &lat->L_mm, &lat->u_mm,
                     &lat->F_N, &lat->k_N_per_mm, &lat->T_N};
    for (size_t i = 0; i < sizeof sd / sizeof sd[0]; i++)
        if (!(*sd[i] = calloc(cap ? cap : 1, sizeof(double))))
            return -1;
    lat->fix = calloc(nn, 1);
    lat->family = calloc(cap ? cap : 1, 1);
    lat->si = calloc(cap ? cap : 1, sizeof(uint32_t));
    lat->sj = calloc(cap ? cap : 1, sizeof(uint32_t));
    lat->top = calloc(ntop, sizeof(uint32_t));
    lat->top_share = calloc(ntop, sizeof(double));
    return lat->fix && lat->family && lat->si && lat->sj && lat->top && lat->top_share ? 0 : -1;
}

/* The nodes of net at their places, each with its share of the cells' mass, its fixity and its
** springs, copied into the lattice's arrays (allocated for net->ns springs). */
static void copy_net(cf_lattice *lat, const cf_net *net)
{
    const cf_lattice_config *cfg = &lat->cfg;
    const double H = lat->H_mm;
    const double cell_mass = cfg->density_t_per_mm3 * H * H * H;
    lat->m_min_t = INFINITY;
    for (int k = 0; k <= cfg->nz; k++)
        for (int j = 0; j <= cfg->ny; j++)
            for (int i = 0; i <= cfg->nx; i++) {
                size_t p = node_id(cfg, i, j, k);
                lat->X[p] = lat->x[p] = net->X[3 * p];
                lat->Y[p] = lat->y[p] = net->X[3 * p + 1];
                lat->Z[p] = lat->z[p] = net->X[3 * p + 2];
                /* the node's share of the 1 to 8 cells around it */
                lat->mass_t[p] = cell_mass * cf_lattice_axis_share(i, 0, cfg->nx) *
                                 cf_lattice_axis_share(j, 0, cfg->ny) *
                                 cf_lattice_axis_share(k, 0, cfg->nz);
                if (lat->mass_t[p] < lat->m_min_t)
                    lat->m_min_t = lat->mass_t[p];
            }
    memcpy(lat->fix, net->fix, lat->nn);
    lat->ns = net->ns;
    memcpy(lat->si, net->si, net->ns * sizeof *lat->si);
    memcpy(lat->sj, net->sj, net->ns * sizeof *lat->sj);
    memcpy(lat->L0_mm, net->L0_mm, net->ns * sizeof *lat->L0_mm);
    memcpy(lat->w, net->w, net->ns * sizeof *lat->w);
    memcpy(lat->family, net->family, net->ns);
    for (size_t s = 0; s < net->ns; s++)
        lat->a[s] = H / net->L0_mm[s];
}

/* The most springs meeting at one node of the lattice: 0, or -1 when memory runs out. */
static int set_max_degree(cf_lattice *lat)
{
    int *degree = calloc(lat->nn, sizeof(int));
    if (!degree)
        return -1;
    for (size_t s = 0; s < lat->ns; s++) {
        degree[lat->si[s]]++;
        degree[lat->sj[s]]++;
    }
    lat->max_degree = 0;
    for (size_t p = 0; p < lat->nn; p++)
        if (degree[p] > lat->max_degree)
            lat->max_degree = degree[p];
    free(degree);
    return 0;
}

/* The top nodes, with their shares of the top face. */
static void set_top(cf_lattice *lat)
{
    const cf_lattice_config *cfg = &lat->cfg;
    size_t t = 0;
    for (int j = 0; j <= cfg->ny; j++)
        for (int i = 0; i <= cfg->nx; i++) {
            lat->top[t] = (uint32_t)node_id(cfg, i, j, cfg->nz);
            lat->top_share[t] =
                cf_lattice_axis_share(i, 0, cfg->nx) * cf_lattice_axis_share(j, 0, cfg->ny);
            t++;
        }
}

/* The groups' laws of cfg resolved into lat->glaw (the lattice's law where NULL): CF_E_DATA for a
** group law of another free length. */
static cf_status resolve_groups(cf_lattice *lat, const cf_law *law, const cf_lattice_config *cfg,
                                cf_error *err)
{
    static const char *const names[CF_FAMILY_COUNT] = {"edge", "face", "body"};
    lat->grouped = 0;
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        const cf_law *g = cfg->group_law[f] ? cfg->group_law[f] : law;
        if (!(fabs(g->p.H_mm - law->p.H_mm) <= CF_GROUP_H_REL * law->p.H_mm))
            return cf_error_set(err, CF_E_DATA,
                                "lattice group '%s': its law's free length H = %.10g mm differs "
                                "from the lattice's %.10g mm (every group of a lattice shares H, "
                                "to %g relative)",
                                names[f], g->p.H_mm, law->p.H_mm, CF_GROUP_H_REL);
        lat->glaw[f] = g;
        if (g != law && cfg->weight[f] > 0)
            lat->grouped = 1;
    }
    return CF_OK;
}

/* The grouped kernel's order of the springs (by group, each in spring order) and its buffers: 0,
** or -1 when memory runs out. Nothing without groups. */
static int group_index(cf_lattice *lat)
{
    if (!lat->grouped)
        return 0;
    const size_t ns = lat->ns ? lat->ns : 1;
    lat->gidx = malloc(ns * sizeof *lat->gidx);
    lat->gu = malloc(ns * sizeof *lat->gu);
    lat->gF = malloc(ns * sizeof *lat->gF);
    lat->gk = malloc(ns * sizeof *lat->gk);
    if (!lat->gidx || !lat->gu || !lat->gF || !lat->gk)
        return -1;
    size_t n = 0;
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        lat->gstart[f] = n;
        for (size_t s = 0; s < lat->ns; s++)
            if (lat->family[s] == f)
                lat->gidx[n++] = (uint32_t)s;
    }
    lat->gstart[CF_FAMILY_COUNT] = n;
    return 0;
}

double cf_lattice_travel_at(const cf_lattice *lat, double u)
{
    double t = cf_law_travel_at(lat->law, u);
    for (int f = 0; lat->grouped && f < CF_FAMILY_COUNT; f++)
        if (lat->cfg.weight[f] > 0)
            t = fmin(t, cf_law_travel_at(lat->glaw[f], u));
    return t;
}

/* The family weights the small-strain constants see (the hourglass stiffness): each group's
** weight times its law's k0 over the lattice law's (the weights themselves without groups). */
static void stiffness_weights(const cf_lattice *lat, double w[CF_FAMILY_COUNT])
{
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        w[f] = lat->grouped ? lat->cfg.weight[f] * lat->glaw[f]->k0_N_per_mm /
                                  lat->law->k0_N_per_mm
                            : lat->cfg.weight[f];
}

cf_status cf_lattice_create(cf_lattice *lat, const cf_law *law, cf_law_method method,
                            const cf_lattice_config *cfg, cf_error *err)
{
    memset(lat, 0, sizeof *lat);
    cf_status st = check_config(cfg, err);
    if (st != CF_OK)
        return st;
    lat->cfg = *cfg;
    lat->law = law;
    lat->method = method;
    lat->with_stiffness = 1;
    lat->H_mm = law->p.H_mm;
    if ((st = resolve_groups(lat, law, cfg, err)) != CF_OK)
        return st;
    lat->travel_mm = cf_law_travel_min(law); /* a pair: the side that closes first */
    for (int f = 0; lat->grouped && f < CF_FAMILY_COUNT; f++)
        if (cfg->weight[f] > 0)
            lat->travel_mm = fmin(lat->travel_mm, cf_law_travel_min(lat->glaw[f]));
    /* the net of the lattice (its nodes, springs, weights and fixity), copied into the structures
    ** of arrays the kernels run on */
    cf_net net;
    if ((st = cf_net_lattice(&net, cfg, lat->H_mm, err)) != CF_OK)
        return st;
    lat->nn = net.nn;
    lat->ntop = (size_t)(cfg->nx + 1) * (cfg->ny + 1);
    if (lattice_alloc(lat, lat->nn, net.ns, lat->ntop) != 0) {
        cf_net_free(&net);
        cf_lattice_free(lat);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a %d x %d x %d lattice",
                            cfg->nx, cfg->ny, cfg->nz);
    }
    copy_net(lat, &net);
    cf_net_free(&net);
    if (set_max_degree(lat) != 0 || group_index(lat) != 0) {
        cf_lattice_free(lat);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a %d x %d x %d lattice",
                            cfg->nx, cfg->ny, cfg->nz);
    }
    set_top(lat);
    lat->area_mm2 = (double)cfg->nx * cfg->ny * lat->H_mm * lat->H_mm;
    lat->height_mm = cfg->nz * lat->H_mm;
    double wk[CF_FAMILY_COUNT];
    stiffness_weights(lat, wk);
    lat->hg_k_N_per_mm =
        cf_hourglass_stiffness(wk, cfg->volume_modulus_MPa, cfg->hourglass, law);
    return CF_OK;
}

void cf_lattice_reset(cf_lattice *lat)
{
    memcpy(lat->x, lat->X, lat->nn * sizeof(double));
    memcpy(lat->y, lat->Y, lat->nn * sizeof(double));
    memcpy(lat->z, lat->Z, lat->nn * sizeof(double));
}

/* Gauss points of [0, 1] (two, weight 1/2 each) and the trilinear shape functions' derivatives
** there: dN[g][a][j] = dN_a/dxi_j at point g (of 8), corner a = di + 2 dj + 4 dk. */
static double dN_table[8][8][3];
static once_flag dN_once = ONCE_FLAG_INIT;

static void shape_derivatives(void)
{
    double (*dN)[8][3] = dN_table;
    const double q[2] = {0.5 - 0.5 / 1.7320508075688772935, 0.5 + 0.5 / 1.7320508075688772935};
    for (int g = 0; g < 8; g++) {
        const double xi[3] = {q[g & 1], q[(g >> 1) & 1], q[(g >> 2) & 1]};
        for (int a = 0; a < 8; a++) {
            const int d[3] = {a & 1, (a >> 1) & 1, (a >> 2) & 1};
            double f[3], df[3];
            for (int j = 0; j < 3; j++) {
                f[j] = d[j] ? xi[j] : 1 - xi[j];
                df[j] = d[j] ? 1.0 : -1.0;
            }
            dN[g][a][0] = df[0] * f[1] * f[2];
            dN[g][a][1] = f[0] * df[1] * f[2];
            dN[g][a][2] = f[0] * f[1] * df[2];
        }
    }
}

void cf_lattice_cell_nodes(const cf_lattice *lat, size_t c, uint32_t node[8])
{
    const cf_lattice_config *cfg = &lat->cfg;
    const size_t nx = (size_t)cfg->nx, ny = (size_t)cfg->ny;
    const int ci = (int)(c % nx), cj = (int)((c / nx) % ny), ck = (int)(c / (nx * ny));
    for (int a = 0; a < 8; a++)
        node[a] = (uint32_t)node_id(cfg, ci + (a & 1), cj + ((a >> 1) & 1), ck + ((a >> 2) & 1));
}

double cf_lattice_cell_volume(const cf_lattice *lat, size_t c, uint32_t node[8], double g[8][3],
                              double (*hess)[8][3][3])
{
    double X[8][3];
    call_once(&dN_once, shape_derivatives); /* the same at every cell: computed once */
    const double (*dN)[8][3] = (const double (*)[8][3])dN_table;
    cf_lattice_cell_nodes(lat, c, node);
    for (int a = 0; a < 8; a++)
        X[a][0] = lat->x[node[a]], X[a][1] = lat->y[node[a]], X[a][2] = lat->z[node[a]];
    memset(g, 0, 8 * 3 * sizeof(double));
    if (hess)
        memset(hess, 0, 8 * 8 * 3 * 3 * sizeof(double));
    double V = 0;
    for (int p = 0; p < 8; p++) {
        double M[3][3] = {{0}}; /* dx_i/dxi_j */
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    M[i][j] += X[a][i] * dN[p][a][j];
        double C[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
                C[i][j] = M[i1][j1] * M[i2][j2] - M[i1][j2] * M[i2][j1];
            }
        V += 0.125 * (M[0][0] * C[0][0] + M[0][1] * C[0][1] + M[0][2] * C[0][2]);
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++)
                g[a][i] += 0.125 * (C[i][0] * dN[p][a][0] + C[i][1] * dN[p][a][1] +
                                    C[i][2] * dN[p][a][2]);
        if (!hess)
            continue;
        /* d2 det/(dM_ij dM_kl) = sum_mn eps_ikm eps_jln M_mn, so the Gauss point adds to
        ** hess[a][b][i][k] (i != k, m the third index) eps_ikm M_m . (dN_a x dN_b) / 8, where
        ** M_m is row m of M: one cross product and three dot products per pair of nodes (a node
        ** with itself adds nothing, and the pair (b, a) adds the transposed block) */
        for (int a = 0; a < 8; a++)
            for (int b = a + 1; b < 8; b++) {
                const double *u = dN[p][a], *v = dN[p][b];
                const double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                     u[0] * v[1] - u[1] * v[0]};
                double t[3];
                for (int m = 0; m < 3; m++)
                    t[m] = 0.125 * (M[m][0] * w[0] + M[m][1] * w[1] + M[m][2] * w[2]);
                /* eps_ikm = +1 for (i, k, m) a cyclic order of (0, 1, 2), -1 otherwise */
                hess[a][b][0][1] += t[2], hess[a][b][1][0] -= t[2];
                hess[a][b][1][2] += t[0], hess[a][b][2][1] -= t[0];
                hess[a][b][2][0] += t[1], hess[a][b][0][2] -= t[1];
                hess[b][a][1][0] += t[2], hess[b][a][0][1] -= t[2];
                hess[b][a][2][1] += t[0], hess[b][a][1][2] -= t[0];
                hess[b][a][0][2] += t[1], hess[b][a][2][0] -= t[1];
            }
    }
    const double H = lat->H_mm;
    return V / (H * H * H);
}

/* The cells' node forces, the volume term's -kappa (J - 1) dV/dx and the hourglass control's,
** added to fx, fy, fz. */
static void cell_forces(cf_lattice *lat);
static double fibre_forces(cf_lattice *lat);

int cf_lattice_has_cells(const cf_lattice *lat)
{
    return lat->cfg.volume_modulus_MPa != 0 || lat->hg_k_N_per_mm != 0;
}

void cf_lattice_add_volume_forces(cf_lattice *lat)
{
    if (cf_lattice_has_cells(lat))
        cell_forces(lat);
    if (lat->cfg.nfibre > 0)
        fibre_forces(lat);
}

/* The corner positions of cell c into x (and its nodes into node). */
static void cell_positions(const cf_lattice *lat, size_t c, uint32_t node[8], double x[8][3])
{
    cf_lattice_cell_nodes(lat, c, node);
    for (int a = 0; a < 8; a++)
        x[a][0] = lat->x[node[a]], x[a][1] = lat->y[node[a]], x[a][2] = lat->z[node[a]];
}

double cf_lattice_volume_row_bound(const cf_lattice *lat)
{
    const double kappa = lat->cfg.volume_modulus_MPa, H = lat->H_mm;
    /* the hourglass control's rows: k_h sum_b |coef(a, b)| = k_h (1/16 + 3/32 + 1/32) = 3 k_h / 16
    ** per cell, at most 8 cells a node, whatever the positions */
    const double hg = 8 * 0.1875 * lat->hg_k_N_per_mm;
    if (!(kappa > 0))
        return hg;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    double *row = calloc(3 * lat->nn, sizeof *row);
    if (!row) /* no memory for the exact bound: the rest state's, 12 kappa H, doubled */
        return 24.0 * kappa * H + hg;
    for (size_t c = 0; c < nc; c++) {
        uint32_t node[8];
        double g[8][3], hess[8][8][3][3];
        const double J = cf_lattice_cell_volume(lat, c, node, g, hess);
        const double a1 = kappa / (H * H * H), a2 = kappa * (J - 1);
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++) {
                double r = 0;
                for (int b = 0; b < 8; b++)
                    for (int k = 0; k < 3; k++)
                        r += fabs(a1 * g[a][i] * g[b][k] + a2 * hess[a][b][i][k]);
                row[3 * node[a] + i] += r;
            }
    }
    double worst = 0;
    for (size_t q = 0; q < 3 * lat->nn; q++)
        worst = fmax(worst, row[q]);
    free(row);
    return worst + hg;
}

/* The fibre groups' forces of every cell: F = sum_a x_a g_a^T with g_a the mean gradient of
** corner a's shape function, (2 xi_a - 1)/(4 H) per axis (xi_a in {0, 1}^3 its corner), and the
** force -H^3 P g_a on corner a. Returns the largest compression over travel of a fibre spring
** (a spring past solid gives no force and returns at least 1). */
static double fibre_forces(cf_lattice *lat)
{
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    const double H = lat->H_mm, H3 = H * H * H;
    double rmax = 0;
    for (size_t c = 0; c < nc; c++) {
        uint32_t node[8];
        double x[8][3], g[8][3], F[9] = {0}, P[3][3] = {{0}};
        cell_positions(lat, c, node, x);
        for (int a = 0; a < 8; a++)
            for (int j = 0; j < 3; j++)
                g[a][j] = (2.0 * ((a >> j) & 1) - 1) / (4 * H);
        for (int a = 0; a < 8; a++)
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    F[3 * i + j] += x[a][i] * g[a][j];
        for (int k = 0; k < lat->cfg.nfibre; k++) {
            double T, r = 0;
            if (cf_fibre_add_stress(&lat->cfg.fibre[k], H, F, P, &T, &r, NULL) != CF_OK)
                r = fmax(r, 1.0);
            rmax = fmax(rmax, r);
        }
        for (int a = 0; a < 8; a++) {
            double f[3];
            for (int i = 0; i < 3; i++)
                f[i] = -H3 * (P[i][0] * g[a][0] + P[i][1] * g[a][1] + P[i][2] * g[a][2]);
            lat->fx[node[a]] += f[0];
            lat->fy[node[a]] += f[1];
            lat->fz[node[a]] += f[2];
        }
    }
    return rmax;
}

static void cell_forces(cf_lattice *lat)
{
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    const double kappa = lat->cfg.volume_modulus_MPa, kh = lat->hg_k_N_per_mm;
    for (size_t c = 0; c < nc; c++) {
        uint32_t node[8];
        if (kappa != 0) {
            double g[8][3];
            const double J = cf_lattice_cell_volume(lat, c, node, g, NULL), f = -kappa * (J - 1);
            for (int a = 0; a < 8; a++) {
                lat->fx[node[a]] += f * g[a][0];
                lat->fy[node[a]] += f * g[a][1];
                lat->fz[node[a]] += f * g[a][2];
            }
        }
        if (kh != 0) {
            double x[8][3], q[4][3], f[8][3];
            cell_positions(lat, c, node, x);
            cf_hourglass_modes(x, q);
            cf_hourglass_forces(q, kh, f);
            for (int a = 0; a < 8; a++) {
                lat->fx[node[a]] += f[a][0];
                lat->fy[node[a]] += f[a][1];
                lat->fz[node[a]] += f[a][2];
            }
        }
    }
}

/* The grouped kernel's law: each group's springs gathered, its law's batch over them, the forces
** and stiffnesses scattered back. Returns the largest |u| / travel over the springs, each group's
** travel on its side. */
static double group_forces(cf_lattice *lat)
{
    const int wk = lat->with_stiffness;
    double r = 0;
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        const size_t b = lat->gstart[f], n = lat->gstart[f + 1] - b;
        const uint32_t *idx = lat->gidx + b;
        const cf_law *g = lat->glaw[f];
        for (size_t k = 0; k < n; k++) {
            const double u = lat->u_mm[idx[k]];
            lat->gu[b + k] = u;
            r = fmax(r, fabs(u) / cf_law_travel_at(g, u));
        }
        if (n == 0)
            continue;
        cf_law_force_many(g, lat->method, n, lat->gu + b, lat->gF + b, wk ? lat->gk + b : NULL);
        for (size_t k = 0; k < n; k++) {
            lat->F_N[idx[k]] = lat->gF[b + k];
            if (wk)
                lat->k_N_per_mm[idx[k]] = lat->gk[b + k];
        }
    }
    return r;
}

double cf_lattice_forces(cf_lattice *lat)
{
    const size_t ns = lat->ns, nn = lat->nn;
    const uint32_t *restrict si = lat->si, *restrict sj = lat->sj;
    const double *restrict x = lat->x, *restrict y = lat->y, *restrict z = lat->z;
    const double *restrict L0 = lat->L0_mm, *restrict a = lat->a, *restrict w = lat->w;
    double *restrict L = lat->L_mm, *restrict u = lat->u_mm, *restrict T = lat->T_N;
    double *restrict fx = lat->fx, *restrict fy = lat->fy, *restrict fz = lat->fz;
    const double *restrict F = lat->F_N;
    double umax = 0;
    /* 1: geometry (gathers, no branches). */
    for (size_t s = 0; s < ns; s++) {
        double dx = x[sj[s]] - x[si[s]], dy = y[sj[s]] - y[si[s]], dz = z[sj[s]] - z[si[s]];
        double l = sqrt(dx * dx + dy * dy + dz * dz);
        L[s] = l;
        u[s] = (L0[s] - l) * a[s];
        double au = fabs(u[s]);
        umax = au > umax ? au : umax;
    }
    /* 2: the law, one dispatch for all springs (or one per group). */
    if (lat->grouped)
        umax = group_forces(lat) * lat->travel_mm;
    else
        cf_law_force_many(lat->law, lat->method, ns, lat->u_mm, lat->F_N,
                          lat->with_stiffness ? lat->k_N_per_mm : NULL);
    /* 3: tensions and equal and opposite node forces. */
    memset(fx, 0, nn * sizeof(double));
    memset(fy, 0, nn * sizeof(double));
    memset(fz, 0, nn * sizeof(double));
    for (size_t s = 0; s < ns; s++) {
        double t = -w[s] * F[s];
        T[s] = t;
        double g = t / L[s];
        uint32_t i = si[s], j = sj[s];
        double gx = g * (x[j] - x[i]), gy = g * (y[j] - y[i]), gz = g * (z[j] - z[i]);
        fx[i] += gx;
        fy[i] += gy;
        fz[i] += gz;
        fx[j] -= gx;
        fy[j] -= gy;
        fz[j] -= gz;
    }
    if (cf_lattice_has_cells(lat))
        cell_forces(lat);
    if (lat->cfg.nfibre > 0)
        umax = fmax(umax, fibre_forces(lat) * lat->travel_mm);
    return umax / lat->travel_mm;
}

void cf_lattice_add_tensions(cf_lattice *lat, const double *Textra_N)
{
    const uint32_t *si = lat->si, *sj = lat->sj;
    for (size_t s = 0; s < lat->ns; s++) {
        uint32_t i = si[s], j = sj[s];
        double g = Textra_N[s] / lat->L_mm[s];
        double gx = g * (lat->x[j] - lat->x[i]), gy = g * (lat->y[j] - lat->y[i]),
               gz = g * (lat->z[j] - lat->z[i]);
        lat->fx[i] += gx;
        lat->fy[i] += gy;
        lat->fz[i] += gz;
        lat->fx[j] -= gx;
        lat->fy[j] -= gy;
        lat->fz[j] -= gz;
        lat->T_N[s] += Textra_N[s];
    }
}

typedef struct law_at_ctx {
    const cf_law *law;
    cf_law_method method;
} law_at_ctx;

static double law_at(double v, void *p)
{
    const law_at_ctx *c = p;
    return cf_law_force(c->law, c->method, v, NULL, NULL);
}

/* Work done compressing one unweighted spring of the law from 0 to u: int_0^u F(v) dv, N mm.
** Region 1 exactly; region 2 by 8-point Gauss-Legendre quadrature (GSL's glfixed) on
** [u_T, min(|u|, u_C)] (the law is smooth there apart from the square-root stiffening at the
** cone's solid; with a tail on four equal panels: one left 1.3e-7 relative at 0.97 of the
** travel, four are within the 1e-9 that tests/unit/test_lattice.c asks); a tail's region 3,
** linear from F_C with the tail's stiffness, exactly; past solid the solid force times the
** further compression. Without a tail u_C is the travel and the solid force F_C. */
static double law_work(const cf_law *law, cf_law_method m, double u,
                       const gsl_integration_glfixed_table *gl)
{
    if (u < 0 && law->extension) /* a pair's extension side: its own spring compressed by -u */
        law = law->extension, u = -u;
    if (law->mech) { /* a law kind (lawmech.h): its force on the side of u, held past its travel */
        law_at_ctx c = {law, m};
        gsl_function f = {law_at, &c};
        const double s = cf_law_travel_at(law, u), b = u < 0 ? fmax(u, -s) : fmin(u, s);
        return gsl_integration_glfixed(&f, 0.0, b, gl) +
               (u - b) * cf_law_force(law, m, b, NULL, NULL);
    }
    double au = fabs(u), uT = law->u_T_mm, uC = law->u_C_mm, s = law->travel_mm;
    double e = 0.5 * law->k0_N_per_mm * fmin(au, uT) * fmin(au, uT);
    if (au > uT) {
        law_at_ctx c = {law, m};
        gsl_function f = {law_at, &c};
        const double b = fmin(au, uC);
        if (law->tail) { /* the stiffness climbs to the tail's near u_C: four panels */
            for (int k = 0; k < 4; k++)
                e += gsl_integration_glfixed(&f, uT + (b - uT) * k / 4.0,
                                             k == 3 ? b : uT + (b - uT) * (k + 1) / 4.0, gl);
        } else {
            e += gsl_integration_glfixed(&f, uT, b, gl);
        }
        if (law->tail && au > uC) {
            const double x = fmin(au, s) - uC;
            e += x * (law->F_C_N + 0.5 * law->k_tail_N_per_mm * x);
        }
        if (au > s)
            e += law->F_solid_N * (au - s);
    }
    return e;
}

double cf_lattice_elastic_energy(const cf_lattice *lat)
{
    CF_GSL_GUARD;
    /* GSL keeps the 8-point nodes precomputed: the table is a small allocation, no computation */
    gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc(8);
    if (!gl)
        return NAN; /* out of memory: not a number, which the energy-drift statistic (fmax) skips */
    double e = 0;
    for (size_t s = 0; s < lat->ns; s++) {
        double dx = lat->x[lat->sj[s]] - lat->x[lat->si[s]];
        double dy = lat->y[lat->sj[s]] - lat->y[lat->si[s]];
        double dz = lat->z[lat->sj[s]] - lat->z[lat->si[s]];
        double u = (lat->L0_mm[s] - sqrt(dx * dx + dy * dy + dz * dz)) * lat->a[s];
        e += lat->w[s] / lat->a[s] * law_work(cf_lattice_spring_law(lat, s), lat->method, u, gl);
    }
    gsl_integration_glfixed_table_free(gl);
    const double kappa = lat->cfg.volume_modulus_MPa, H = lat->H_mm;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    for (size_t c = 0; kappa != 0 && c < nc; c++) { /* the volume term, (kappa/2)(J - 1)^2 H^3 */
        uint32_t node[8];
        double g[8][3];
        const double J = cf_lattice_cell_volume(lat, c, node, g, NULL);
        e += 0.5 * kappa * (J - 1) * (J - 1) * H * H * H;
    }
    return e + cf_lattice_hourglass_energy(lat);
}

double cf_lattice_hourglass_energy(const cf_lattice *lat)
{
    const double kh = lat->hg_k_N_per_mm;
    const size_t nc = (size_t)lat->cfg.nx * (size_t)lat->cfg.ny * (size_t)lat->cfg.nz;
    double e = 0;
    for (size_t c = 0; kh != 0 && c < nc; c++) { /* (k_h/2) sum_i |q_i|^2 */
        uint32_t node[8];
        double x[8][3], q[4][3];
        cell_positions(lat, c, node, x);
        cf_hourglass_modes(x, q);
        for (int i = 0; i < 4; i++)
            e += 0.5 * kh * (q[i][0] * q[i][0] + q[i][1] * q[i][1] + q[i][2] * q[i][2]);
    }
    return e;
}

double cf_lattice_lateral_stretch(const cf_lattice *lat)
{
    const double W = lat->cfg.nx * lat->H_mm;
    double hi = 0, lo = 0;
    size_t nhi = 0, nlo = 0;
    for (size_t p = 0; p < lat->nn; p++) {
        if (lat->X[p] == W)
            hi += lat->x[p], nhi++;
        else if (lat->X[p] == 0)
            lo += lat->x[p], nlo++;
    }
    return (hi / (double)nhi - lo / (double)nlo) / W;
}

double cf_lattice_top_strain(const cf_lattice *lat)
{
    double sum = 0, wsum = 0;
    for (size_t t = 0; t < lat->ntop; t++) {
        uint32_t p = lat->top[t];
        sum += lat->top_share[t] * (lat->Z[p] - lat->z[p]);
        wsum += lat->top_share[t];
    }
    return sum / wsum / lat->height_mm;
}
