/*
** A body's volume term for CalculiX and Abaqus as conifit takes it, per node (export_model.h,
** cf_xmodel_inp_nodal_volume). conifit's node a stores V0_a (kappa/2)(J_a - 1)^2, J_a = V_a/V0_a
** with V_a, V0_a a quarter of the current and rest volumes of the tetrahedra around it (Bonet &
** Burton 1998). ccx has no element that averages J over a node's tetrahedra: its C3D4 takes J per
** element and locks as nu nears 1/2. So each node gets an auxiliary node whose direction 1 an
** *EQUATION ties to the node's volume change, d_a = (V_a(x) - V0_a)/sqrt(V0_a), and a grounded
** linear spring (SPRING1) of stiffness kappa, whose energy (kappa/2) d_a^2 is the node's term.
** An equation is linear in the displacements (also under NLGEOM) where V_a is cubic in them, so
** V_a is taken to first order about a state: about the state conifit solved at each load step
** (one set of auxiliary nodes, equations and springs per step, the springs of the other steps
** removed by *MODEL CHANGE), which gives the term's value and gradient there exactly; or, for a
** model without solved states, about the rest state. The constant of each equation, V_a(x_k) -
** V0_a - dV_a(x_k) . u_k, rides on one more auxiliary node held at displacement 1.
*/
#include "export/export_model.h"

#include <math.h>
#include <stdlib.h>

/* The rest volumes V0 (nn) of the nodes; with x (3 nn positions, or NULL for the rest state)
** their volumes V (nn) there and every tetrahedron's gradient of its volume grad (12 per
** tetrahedron: d V_t / d x of its four corners). */
static void nodal_volumes(const cf_xmodel *m, const double *x, double *V0, double *V,
                          double *grad)
{
    for (size_t a = 0; a < m->nn; a++)
        V0[a] = V[a] = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *e = m->tet + 4 * t;
        double p[4][3], r[4][3], *g = grad + 12 * t;
        for (int k = 0; k < 4; k++) {
            r[k][0] = m->X[e[k]], r[k][1] = m->Y[e[k]], r[k][2] = m->Z[e[k]];
            for (int c = 0; c < 3; c++)
                p[k][c] = x ? x[3 * e[k] + c] : r[k][c];
        }
        double u[3][3], w[3][3];
        for (int k = 1; k < 4; k++)
            for (int c = 0; c < 3; c++)
                u[k - 1][c] = p[k][c] - p[0][c], w[k - 1][c] = r[k][c] - r[0][c];
        /* dV/dp1 = (p2 - p0) x (p3 - p0) / 6, cyclically; dV/dp0 = -(their sum) */
        for (int k = 0; k < 3; k++) {
            const double *v = u[(k + 1) % 3], *q = u[(k + 2) % 3];
            g[3 * (k + 1) + 0] = (v[1] * q[2] - v[2] * q[1]) / 6;
            g[3 * (k + 1) + 1] = (v[2] * q[0] - v[0] * q[2]) / 6;
            g[3 * (k + 1) + 2] = (v[0] * q[1] - v[1] * q[0]) / 6;
        }
        for (int c = 0; c < 3; c++)
            g[c] = -(g[3 + c] + g[6 + c] + g[9 + c]);
        const double Vt = u[0][0] * g[3] + u[0][1] * g[4] + u[0][2] * g[5];
        const double V0t = (w[0][0] * (w[1][1] * w[2][2] - w[1][2] * w[2][1]) -
                            w[0][1] * (w[1][0] * w[2][2] - w[1][2] * w[2][0]) +
                            w[0][2] * (w[1][0] * w[2][1] - w[1][1] * w[2][0])) / 6;
        for (int k = 0; k < 4; k++) {
            V0[e[k]] += V0t / 4;
            V[e[k]] += Vt / 4;
        }
    }
}

/* The tetrahedra around each node: tl[tp[a] .. tp[a + 1]). */
static void node_tets(const cf_xmodel *m, size_t *tp, uint32_t *tl)
{
    for (size_t a = 0; a <= m->nn; a++)
        tp[a] = 0;
    for (size_t t = 0; t < 4 * m->nt; t++)
        tp[m->tet[t] + 1]++;
    for (size_t a = 0; a < m->nn; a++)
        tp[a + 1] += tp[a];
    for (size_t t = 0; t < m->nt; t++)
        for (int k = 0; k < 4; k++)
            tl[tp[m->tet[4 * t + k]]++] = (uint32_t)t;
    for (size_t a = m->nn; a > 0; a--) /* back to the starts */
        tp[a] = tp[a - 1];
    tp[0] = 0;
}

/* Scratch of one equation: the gradient of V_a over its ring of nodes. */
typedef struct ring {
    double *acc;     /* 3 nn, zero between uses */
    uint32_t *node;  /* the ring's nodes */
    uint8_t *seen;   /* nn, zero between uses */
} ring;

/* The equation of node a's auxiliary node aux: 1 d_aux - dV_a . u / sqrt(V0_a) - c/sqrt(V0_a) u_one
** = 0, with x the positions of the state (NULL: rest) and c its constant. Terms of held
** directions left out. */
static void write_equation(FILE *out, const cf_xmodel *m, size_t a, size_t aux, size_t one,
                           const double *x, const double *V0, const double *V,
                           const double *grad, const size_t *tp, const uint32_t *tl, ring *r)
{
    size_t nr = 0;
    for (size_t q = tp[a]; q < tp[a + 1]; q++) {
        const uint32_t *e = m->tet + 4 * tl[q];
        for (int k = 0; k < 4; k++) {
            if (!r->seen[e[k]])
                r->seen[e[k]] = 1, r->node[nr++] = e[k];
            for (int c = 0; c < 3; c++)
                r->acc[3 * e[k] + c] += grad[12 * tl[q] + 3 * k + c] / 4;
        }
    }
    double cst = V[a] - V0[a]; /* V_a(x) - V0_a - dV_a . u */
    size_t terms = 1 + (x != NULL);
    for (size_t j = 0; j < nr; j++)
        for (int c = 0; c < 3; c++) {
            const uint32_t i = r->node[j];
            if (x)
                cst -= r->acc[3 * i + c] * (x[3 * i + c] - (c == 0 ? m->X : c == 1 ? m->Y : m->Z)[i]);
            terms += !(m->fix[i] & (1u << c)) && r->acc[3 * i + c] != 0;
        }
    const double s = 1 / sqrt(V0[a]);
    char cv[32];
    fprintf(out, "%zu\n%zu, 1, 1.\n", terms, aux);
    for (size_t j = 0; j < nr; j++) {
        const uint32_t i = r->node[j];
        for (int c = 0; c < 3; c++) {
            const double v = r->acc[3 * i + c];
            if (!(m->fix[i] & (1u << c)) && v != 0) {
                cf_export_inp_real(cv, -v * s);
                fprintf(out, "%u, %d, %s\n", i + 1, c + 1, cv);
            }
            r->acc[3 * i + c] = 0;
        }
        r->seen[i] = 0;
    }
    if (x) {
        cf_export_inp_real(cv, -cst * s);
        fprintf(out, "%zu, 1, %s\n", one, cv);
    }
}

size_t cf_xmodel_inp_volume_nodes(const cf_xmodel *m)
{
    if (!(m->nt > 0 && m->kappa_MPa > 0))
        return 0;
    return m->xk_mm ? m->nsteps * m->nn + 1 : m->nn;
}

/* The auxiliary nodes (after the body's), their springs (after the springs' elements, one set
** VOL<k> per state) and held directions are written by the caller's order: nodes and elements
** here, the held directions in cf_xmodel_inp_volume_held. */
int cf_xmodel_inp_nodal_volume(FILE *out, const cf_xmodel *m)
{
    const size_t nn = m->nn, nt = m->nt, S = m->xk_mm ? m->nsteps : 1;
    double *V0 = malloc(nn * sizeof *V0), *V = malloc(nn * sizeof *V);
    double *grad = malloc(12 * (nt ? nt : 1) * sizeof *grad);
    size_t *tp = malloc((nn + 1) * sizeof *tp);
    uint32_t *tl = malloc(4 * (nt ? nt : 1) * sizeof *tl);
    ring r = {calloc(3 * nn, sizeof *r.acc), malloc(nn * sizeof *r.node), calloc(nn, 1)};
    int rc = -1;
    if (!V0 || !V || !grad || !tp || !tl || !r.acc || !r.node || !r.seen)
        goto end;
    node_tets(m, tp, tl);
    const size_t one = nn + S * nn + 1; /* the node held at 1 (per-state equations only) */
    fprintf(out, "** the volume term per node (%s): auxiliary nodes %zu to %zu, d_a = (V_a - "
                 "V0_a)/sqrt(V0_a) to first order by *EQUATION, each a grounded spring of kappa "
                 "= %.17g MPa\n*NODE, NSET=NVOLUME\n",
            m->xk_mm ? "about conifit's solution at each step, one set per step" : "about rest",
            nn + 1, nn + cf_xmodel_inp_volume_nodes(m), m->kappa_MPa);
    for (size_t q = 0; q < cf_xmodel_inp_volume_nodes(m); q++) {
        char x[32], y[32], z[32];
        const size_t a = q % nn;
        cf_export_inp_real(x, m->X[a]);
        cf_export_inp_real(y, m->Y[a]);
        cf_export_inp_real(z, m->Z[a]);
        fprintf(out, "%zu, %s, %s, %s\n", nn + q + 1, x, y, z);
    }
    char kap[32];
    cf_export_inp_real(kap, m->kappa_MPa);
    for (size_t s = 0; s < S; s++) {
        fprintf(out, "*ELEMENT, TYPE=SPRING1, ELSET=VOL%zu\n", s + 1);
        for (size_t a = 0; a < nn; a++)
            fprintf(out, "%zu, %zu\n", m->ns + s * nn + a + 1, nn + s * nn + a + 1);
        fprintf(out, "*SPRING, ELSET=VOL%zu\n1\n%s\n", s + 1, kap);
    }
    if (m->xk_mm) /* the node held at 1 needs an element to have degrees of freedom */
        fprintf(out, "*ELEMENT, TYPE=SPRING1, ELSET=VOLONE\n%zu, %zu\n*SPRING, ELSET=VOLONE\n1\n%s\n",
                m->ns + S * nn + 1, one, kap);
    fprintf(out, "*EQUATION\n");
    for (size_t s = 0; s < S; s++) {
        const double *x = m->xk_mm ? m->xk_mm + 3 * nn * s : NULL;
        nodal_volumes(m, x, V0, V, grad);
        for (size_t a = 0; a < nn; a++)
            if (V0[a] > 0)
                write_equation(out, m, a, nn + s * nn + a + 1, one, x, V0, V, grad, tp, tl, &r);
    }
    rc = 0;
end:
    free(V0), free(V), free(grad), free(tp), free(tl), free(r.acc), free(r.node), free(r.seen);
    return rc;
}

void cf_xmodel_inp_volume_held(FILE *out, const cf_xmodel *m)
{
    const size_t n = cf_xmodel_inp_volume_nodes(m);
    for (size_t q = 0; q < n; q++)
        fprintf(out, "%zu, 2, 3\n", m->nn + q + 1);
    if (m->xk_mm && n)
        fprintf(out, "%zu, 1, 1, 1.\n", m->nn + n);
}

void cf_xmodel_inp_volume_step(FILE *out, const cf_xmodel *m, size_t k)
{
    if (!(m->nt > 0 && m->kappa_MPa > 0) || !m->xk_mm || m->nsteps < 2)
        return;
    fprintf(out, "*MODEL CHANGE, TYPE=ELEMENT, REMOVE\n");
    if (k > 0)
        fprintf(out, "VOL%zu\n*MODEL CHANGE, TYPE=ELEMENT, ADD\nVOL%zu\n", k, k + 1);
    else
        for (size_t s = 1; s < m->nsteps; s++)
            fprintf(out, "VOL%zu\n", s + 1);
}
