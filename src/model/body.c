/*
** Tissue bodies (body.h): the body of a tetrahedral mesh's net (net.h; its springs on the mesh's
** edges and their calibration are made by net_mesh.c), and the state measured at a body's
** positions. The probe's geometry is in body_probe.c, the tangent and forces in body_assemble.c,
** the static solve in body_solve.c, the haptic loop in body_haptic.c.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"
#include "model/calibration.h"
#include "model/net.h"

double cf_body_kappa_for_nu(double mu_MPa, double nu)
{
    return mu_MPa * (4 * nu - 1) / (1 - 2 * nu);
}


cf_status cf_body_create(cf_body *b, const cf_mesh *m, const cf_law *law, cf_law_method method,
                         double kappa_MPa, cf_error *err)
{
    memset(b, 0, sizeof *b);
    if (!(kappa_MPa >= 0 && kappa_MPa <= CF_KAPPA_MAX_MPA))
        return cf_error_set(err, CF_E_DATA,
                            "body: volume modulus %g MPa: must be >= 0 and at most %g MPa "
                            "(" CF_KAPPA_MAX_WHY ")",
                            kappa_MPa, CF_KAPPA_MAX_MPA);
    /* the mesh's net: the body takes its arrays */
    cf_net net;
    cf_status st = cf_net_mesh(&net, m, law, err);
    if (st != CF_OK)
        return st;
    b->law = law;
    b->method = method;
    b->nn = net.nn;
    b->nt = net.nc;
    b->ns = net.ns;
    b->X = net.X;
    b->fix = net.fix;
    b->tet = net.cell;
    b->si = net.si;
    b->sj = net.sj;
    b->L0 = net.L0_mm;
    b->c = net.w;
    free(net.family);
    b->x = malloc(3 * b->nn * sizeof *b->x);
    b->V0 = malloc(b->nt * sizeof *b->V0);
    if (!b->x || !b->V0) {
        cf_body_free(b);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a body of %zu nodes", m->nn);
    }
    memcpy(b->x, b->X, 3 * b->nn * sizeof *b->x);
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        b->V0[t] = body_vol6(b->X + 3 * v[0], b->X + 3 * v[1], b->X + 3 * v[2], b->X + 3 * v[3]) / 6;
    }
    double Lsum = 0;
    for (size_t s = 0; s < b->ns; s++)
        Lsum += b->L0[s];
    b->mean_edge_mm = Lsum / (double)b->ns;
    const double mu = cf_body_mu_of_law(law);
    b->mu_MPa = mu;
    b->kappa_MPa = kappa_MPa;
    const double lam = mu + kappa_MPa;
    b->E_MPa = mu * (3 * lam + 2 * mu) / (lam + mu);
    b->nu = lam / (2 * (lam + mu));
    return CF_OK;
}

cf_net cf_net_of_body(const cf_body *b)
{
    cf_net n = {0};
    n.nn = b->nn;
    n.X = b->X;
    n.fix = b->fix;
    n.ns = b->ns;
    n.si = b->si;
    n.sj = b->sj;
    n.L0_mm = b->L0;
    n.w = b->c;
    n.cell_kind = CF_NET_TET4;
    n.nc = b->nt;
    n.cell = b->tet;
    return n;
}

double cf_body_measure(const cf_body *b, cf_body_state *st, double *max_u_over_travel)
{
    double umax = 0, minJ = INFINITY;
    for (size_t s = 0; s < b->ns; s++) {
        double n[3], u;
        double L = body_spring_geom(b, b->x, s, n, &u);
        umax = fmax(umax, fabs(u) / cf_law_travel_at(cf_body_spring_law(b, s), u));
        if (st) {
            st->strain[s] = (L - b->L0[s]) / b->L0[s];
            st->solid[s] = fabs(u) >= cf_law_travel_at(cf_body_spring_law(b, s), u);
        }
    }
    for (size_t t = 0; t < b->nt; t++) {
        const uint32_t *v = b->tet + 4 * t;
        double J = body_vol6(b->x + 3 * v[0], b->x + 3 * v[1], b->x + 3 * v[2], b->x + 3 * v[3]) /
                   (6 * b->V0[t]);
        if (st)
            st->J[t] = J;
        minJ = fmin(minJ, J);
    }
    if (b->nfibre)
        umax = fmax(umax, cf_body_fibre_umax(b, b->x));
    if (max_u_over_travel)
        *max_u_over_travel = umax;
    return minJ;
}

void cf_body_free(cf_body *b)
{
    if (!b)
        return;
    cf_body_work_free(b->work);
    free(b->X);
    free(b->x);
    free(b->fix);
    free(b->tet);
    free(b->V0);
    free(b->si);
    free(b->sj);
    free(b->L0);
    free(b->c);
    free(b->f_ext);
    free(b->reaction);
    free(b->contact);
    free(b->group);
    for (size_t g = 0; b->gown && g < b->ngroups; g++)
        cf_law_free(&b->gown[g]);
    free(b->gown);
    for (size_t k = 0; b->flaw && k < b->nfibre; k++)
        cf_law_free(&b->flaw[k]);
    free(b->flaw);
    free(b->fdir);
    free(b->fgrad);
    free(b->elem);
    memset(b, 0, sizeof *b);
}

