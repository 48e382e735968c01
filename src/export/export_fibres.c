/*
** A body's fibre groups for CalculiX (export_internal.h, cf_xmodel_body_fibres; export_model.h,
** cf_xmodel_inp_fibres). conifit stores in tetrahedron t, for group k of direction a and law of
** free length Hf, the energy V0 (density / H^3) E(lambda) with lambda = |F a| and dE/dlambda =
** Hf T(Hf (lambda - 1)), T the law's force in tension only (body_fibres.c, fibre.h). ccx writes
** the same term as one embedded SPRINGA per tetrahedron and group: its two ends are auxiliary
** nodes at the tetrahedron's centre c -+ (Hf/2) a, and each end's three displacements are tied by
** *EQUATION to the four corners' with the linear shape functions' values there,
** N_m(p) = 1/4 + grad N_m . (p - c) (the ends may lie outside the tetrahedron: the linear field
** extends exactly). A linear tetrahedron deforms affinely, so the ends' separation is F (Hf a)
** and the spring's elongation is Hf (|F a| - 1) exactly; a spring of weight w = V0 density / H^3
** on the tension-only table (elongation e = u, tension w F(u) for u >= 0, 0 for u <= 0) stores
** w Hf integral T dlambda, conifit's term. Tetrahedra of one group and the same weight (to the
** last bit) share one table.
** ccx reads an equation's first term as its dependent degree of freedom, which must be no other
** equation's dependent one nor held (ccx manual, *EQUATION): each auxiliary node's directions are
** dependent in exactly one equation and appear in no other.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "export/export_internal.h"
#include "model/body.h"
#include "model/lattice.h"

/* Index of the table of group k with weight w among m->fg[0 .. m->nfg) (fk the group of each),
** appended when new. */
static size_t table_of(cf_xmodel *m, uint32_t *fk, uint32_t k, double w, double Hf,
                       double slack, const cf_law *law, const cf_export_table *t)
{
    for (size_t g = 0; g < m->nfg; g++)
        if (fk[g] == k && m->fg[g].weight == w)
            return g;
    cf_xgroup *G = &m->fg[m->nfg];
    memset(G, 0, sizeof *G);
    G->L0_mm = Hf;
    G->slack_mm = slack * Hf;
    G->weight = w;
    G->law = law;
    G->table = t;
    fk[m->nfg] = k;
    return m->nfg++;
}

/* Group G's rows from its law's table: one slack row at e = -Hf, then the rows of u >= 0 (the
** first of them at u = 0, force 0) at e = u + the group's slack elongation (a recruited fibre is
** slack up to it, fibre.h). 0, or -1 out of memory. */
static int fibre_rows(cf_xgroup *G)
{
    const cf_export_table *t = G->table;
    size_t i0 = 0;
    while (i0 < t->rows && t->u_mm[i0] < 0)
        i0++;
    G->rows = t->rows - i0 + 1;
    G->e_mm = malloc(G->rows * sizeof *G->e_mm);
    G->T_N = malloc(G->rows * sizeof *G->T_N);
    if (!G->e_mm || !G->T_N)
        return -1;
    G->e_mm[0] = -G->L0_mm;
    G->T_N[0] = 0.0;
    for (size_t i = i0; i < t->rows; i++) {
        G->e_mm[i - i0 + 1] = t->u_mm[i] + G->slack_mm;
        G->T_N[i - i0 + 1] = t->u_mm[i] > 0 ? G->weight * t->F_N[i] : 0.0;
    }
    return 0;
}

/* Compression Hf (|F a| - 1 - slack) of group k's fibre spring in tetrahedron t at positions x,
** F = sum_m x_m (grad N_m)^T; 0 when it is slack. */
static double stretched(const cf_body *b, const double *x, size_t t, size_t k)
{
    const uint32_t *v = b->tet + 4 * t;
    const double *a = b->fdir + 3 * (CF_FIBRE_MAX * t + k), *G = b->fgrad + 12 * t;
    double Fa[3] = {0, 0, 0};
    for (int c4 = 0; c4 < 4; c4++) {
        const double ga = G[3 * c4] * a[0] + G[3 * c4 + 1] * a[1] + G[3 * c4 + 2] * a[2];
        for (int i = 0; i < 3; i++)
            Fa[i] += x[3 * v[c4] + (size_t)i] * ga;
    }
    const cf_fibre_group g = {.law = &b->flaw[k], .slack = b->fslack[k]};
    return cf_fibre_compression(&g, sqrt(Fa[0] * Fa[0] + Fa[1] * Fa[1] + Fa[2] * Fa[2]));
}

/* What the fibre tables allow in the probe force: the reaction is the derivative of the energy
** along conifit's equilibrium path, so a table error dT (at most tol F_C in each law's table,
** times the spring's weight w) changes it by sum w dT de/dd to first order (the re-equilibration
** is of second order); de/dd taken between consecutive steps (from the rest state), its largest
** sum over the steps. Slack fibres carry no error (their rows are exactly 0). */
static double path_tol(const cf_xmodel *m, const cf_body *b, const cf_export_table *ft)
{
    double worst = 0;
    for (size_t s = 0; m->xk_mm && s < m->nsteps; s++) {
        const double *x1 = m->xk_mm + 3 * b->nn * s, *x0 = s ? x1 - 3 * b->nn : b->X;
        const double dd = fabs(m->dz_mm[s] - (s ? m->dz_mm[s - 1] : 0));
        if (!(dd > 0))
            continue;
        double sum = 0;
        for (size_t q = 0; q < m->nfib; q++) {
            const size_t t = q / b->nfibre, k = q % b->nfibre;
            sum += m->fg[m->fgrp[q]].weight * ft[k].tol * b->flaw[k].F_C_N *
                   fabs(stretched(b, x1, t, k) - stretched(b, x0, t, k));
        }
        worst = fmax(worst, sum / dd);
    }
    return worst;
}

int cf_xmodel_body_fibres(cf_xmodel *m, const cf_body *b, const cf_export_table *ft)
{
    const size_t n = b->nt * b->nfibre;
    if (n == 0)
        return 0;
    const double H = b->law->p.H_mm;
    m->fnc = 4;
    m->fcorner = malloc(4 * n * sizeof *m->fcorner);
    m->fgrp = malloc(n * sizeof *m->fgrp);
    m->fx_mm = malloc(6 * n * sizeof *m->fx_mm);
    m->fwt = malloc(8 * n * sizeof *m->fwt);
    m->fg = malloc(n * sizeof *m->fg);
    uint32_t *fk = malloc(n * sizeof *fk);
    if (!m->fcorner || !m->fgrp || !m->fx_mm || !m->fwt || !m->fg || !fk) {
        free(fk);
        return -1;
    }
    for (size_t t = 0; t < b->nt; t++)
        for (size_t k = 0; k < b->nfibre; k++) {
            const size_t q = m->nfib++;
            const uint32_t *v = b->tet + 4 * t;
            const double *a = b->fdir + 3 * (CF_FIBRE_MAX * t + k), *G = b->fgrad + 12 * t;
            const double Hf = b->flaw[k].p.H_mm, w = b->V0[t] * b->fdensity[k] / (H * H * H);
            for (int i = 0; i < 3; i++) {
                double c = 0;
                for (int c4 = 0; c4 < 4; c4++)
                    c += b->X[3 * v[c4] + (size_t)i] / 4;
                m->fx_mm[6 * q + (size_t)i] = c - Hf / 2 * a[i];
                m->fx_mm[6 * q + 3 + (size_t)i] = c + Hf / 2 * a[i];
            }
            for (int c4 = 0; c4 < 4; c4++) {
                const double ga = G[3 * c4] * a[0] + G[3 * c4 + 1] * a[1] + G[3 * c4 + 2] * a[2];
                m->fcorner[4 * q + (size_t)c4] = v[c4];
                m->fwt[8 * q + (size_t)c4] = 0.25 - Hf / 2 * ga;
                m->fwt[8 * q + 4 + (size_t)c4] = 0.25 + Hf / 2 * ga;
            }
            m->fgrp[q] = (uint32_t)table_of(m, fk, (uint32_t)k, w, Hf, b->fslack[k], &b->flaw[k],
                                              &ft[k]);
        }
    free(fk);
    for (size_t g = 0; g < m->nfg; g++)
        if (fibre_rows(&m->fg[g]) != 0)
            return -1;
    m->fib_tol_N = path_tol(m, b, ft);
    m->reaction_tol_N += m->fib_tol_N;
    return 0;
}

/* The equations of end e (0, 1) of fibre q, node number nd: u(nd) - sum_m N_m u(corner m) = 0
** in each direction, terms of weight 0 left out, four terms a line. */
static void write_equations(FILE *out, const cf_xmodel *m, size_t q, int e, size_t nd)
{
    const size_t nc = m->fnc;
    const double *w = m->fwt + 2 * nc * q + nc * (size_t)e;
    int terms = 1;
    for (size_t c = 0; c < nc; c++)
        terms += w[c] != 0;
    for (int d = 1; d <= 3; d++) {
        fprintf(out, "%d\n%zu, %d, -1.", terms, nd, d);
        int on_line = 1;
        for (size_t c = 0; c < nc; c++) {
            if (w[c] == 0)
                continue;
            char x[32];
            cf_export_inp_real(x, w[c]);
            fprintf(out, "%s%u, %d, %s", on_line == 4 ? "\n" : ", ", m->fcorner[nc * q + c] + 1,
                    d, x);
            on_line = on_line == 4 ? 1 : on_line + 1;
        }
        fputc('\n', out);
    }
}

void cf_xmodel_inp_fibres(FILE *out, const cf_xmodel *m, size_t node0, size_t elem0)
{
    if (m->nfib == 0)
        return;
    if (m->fnc == 4)
        fprintf(out, "** fibres: %zu embedded tension-only springs (one per tetrahedron and fibre "
                     "group), each between two auxiliary nodes at the tetrahedron's centre -+ "
                     "(Hf/2) a tied to its corners by *EQUATION (linear shape functions: the "
                     "elongation is Hf (|F a| - 1) exactly); %zu tables; their share of the "
                     "reaction tolerance %.6g N (tol F_C times the sum of each spring's weight "
                     "times the rate of its elongation per unit probe travel along conifit's "
                     "path, its largest over the steps)\n", m->nfib, m->nfg, m->fib_tol_N);
    else
        fprintf(out, "** fibres: %zu embedded tension-only springs (one per cell and fibre group), "
                     "each between two auxiliary nodes at the cell's centre -+ (Hf/2) a tied to "
                     "its 8 nodes by *EQUATION (trilinear weights: the elongation is Hf (|F a| - "
                     "1) with conifit's cell F exactly when a has a zero component or the cell "
                     "deforms affinely; else the ends' separation adds (Hf^3 a1 a2 a3 / 4 H^3) "
                     "times the cell's twist mode sum_a s1 s2 s3 x_a); %zu tables; their share of "
                     "the reaction tolerance %.6g N (tol F_C times cells times density Hf / "
                     "height: a fibre's stretch moves at most as fast as the strain)\n",
                m->nfib, m->nfg, m->fib_tol_N);
    fprintf(out, "*NODE, NSET=NFIBRE\n");
    for (size_t q = 0; q < 2 * m->nfib; q++) {
        char x[32], y[32], z[32];
        cf_export_inp_real(x, m->fx_mm[3 * q]);
        cf_export_inp_real(y, m->fx_mm[3 * q + 1]);
        cf_export_inp_real(z, m->fx_mm[3 * q + 2]);
        fprintf(out, "%zu, %s, %s, %s\n", node0 + q + 1, x, y, z);
    }
    fprintf(out, "*EQUATION\n");
    for (size_t q = 0; q < m->nfib; q++)
        for (int e = 0; e < 2; e++)
            write_equations(out, m, q, e, node0 + 2 * q + (size_t)e + 1);
    for (size_t g = 0; g < m->nfg; g++) {
        const cf_xgroup *G = &m->fg[g];
        fprintf(out, "*ELEMENT, TYPE=SPRINGA, ELSET=F%zu\n", g + 1);
        for (size_t q = 0; q < m->nfib; q++)
            if (m->fgrp[q] == g)
                fprintf(out, "%zu, %zu, %zu\n", elem0 + q + 1, node0 + 2 * q + 1,
                        node0 + 2 * q + 2);
        fprintf(out, "** fibre table %zu: Hf = %.17g mm, weight %.17g (%s); "
                     "tension (N), elongation (mm), slack below %.17g mm\n",
                g + 1, G->L0_mm, G->weight, m->fnc == 4 ? "V0 density / H^3" : "density",
                G->slack_mm);
        fprintf(out, "*SPRING, ELSET=F%zu, NONLINEAR\n\n", g + 1);
        for (size_t i = 0; i < G->rows; i++)
            cf_export_inp_pair(out, G->T_N[i], G->e_mm[i]);
    }
}

int cf_xmodel_lattice_fibres(cf_xmodel *m, const cf_lattice *lat, const cf_export_table *ft)
{
    const cf_lattice_config *lc = &lat->cfg;
    const size_t nk = (size_t)lc->nfibre, n = m->ncells * nk;
    if (n == 0)
        return 0;
    const double H = lat->H_mm;
    m->fnc = 8;
    m->fcorner = malloc(8 * n * sizeof *m->fcorner);
    m->fgrp = malloc(n * sizeof *m->fgrp);
    m->fx_mm = malloc(6 * n * sizeof *m->fx_mm);
    m->fwt = malloc(16 * n * sizeof *m->fwt);
    m->fg = calloc(nk, sizeof *m->fg);
    if (!m->fcorner || !m->fgrp || !m->fx_mm || !m->fwt || !m->fg)
        return -1;
    m->nfg = nk;
    for (size_t k = 0; k < nk; k++) {
        const cf_fibre_group *g = &lc->fibre[k];
        m->fg[k] = (cf_xgroup){.L0_mm = g->law->p.H_mm, .weight = g->density,
                               .slack_mm = g->slack * g->law->p.H_mm, .law = g->law,
                               .table = &ft[k]};
        if (fibre_rows(&m->fg[k]) != 0)
            return -1;
        m->fib_tol_N += (double)m->ncells * g->density * g->law->p.H_mm * ft[k].tol *
                        g->law->F_C_N / m->height_mm;
    }
    for (size_t c = 0; c < m->ncells; c++)
        for (size_t k = 0; k < nk; k++) {
            const size_t q = m->nfib++;
            const uint32_t *v = m->cell + 8 * c;
            const double *a = lc->fibre[k].dir, Hf = lc->fibre[k].law->p.H_mm;
            const double X0[3] = {m->X[v[0]], m->Y[v[0]], m->Z[v[0]]};
            for (int e = 0; e < 2; e++) {
                double s[3]; /* the end's coordinates in the cell, 0 .. 1 inside */
                for (int i = 0; i < 3; i++) {
                    const double p = X0[i] + H / 2 + (e ? 1 : -1) * Hf / 2 * a[i];
                    m->fx_mm[6 * q + 3 * (size_t)e + (size_t)i] = p;
                    s[i] = (p - X0[i]) / H;
                }
                for (int b = 0; b < 8; b++) /* corner b = di + 2 dj + 4 dk */
                    m->fwt[16 * q + 8 * (size_t)e + (size_t)b] =
                        ((b & 1) ? s[0] : 1 - s[0]) * ((b & 2) ? s[1] : 1 - s[1]) *
                        ((b & 4) ? s[2] : 1 - s[2]);
            }
            memcpy(m->fcorner + 8 * q, v, 8 * sizeof *v);
            m->fgrp[q] = (uint32_t)k;
        }
    m->reaction_tol_N += m->fib_tol_N;
    return 0;
}
