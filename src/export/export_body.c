/*
** Export of a tissue body (see export.h, cf_export_write_body), to CalculiX, FEBio or SOFA: every
** edge of the body its own
** spring group (its rest length and its calibration factor as the weight, so its table is the law
** in strain form times that factor, as the lattice export writes its groups), the volume term as
** tetrahedra of a purely volumetric material, the held nodes, and a flat punch pressed along z as
** the prescribed motion of the nodes under its face; CalculiX also takes the element term
** (body.element_term) as an anisotropic tetrahedron each (export_inp_elem.c).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "export/export.h"
#include "base/gslguard.h"
#include "model/body.h"
#include "model/lattice.h"
#include "export/export_internal.h"

/* conifit's contact sets of run into m: top the nodes ever in contact (ascending), with their z
** displacement at every step, and each step's set with its nodes' z displacements. 0, -1 out of
** memory. */
static int replay(const cf_body *b, const cf_probe *pr, const cf_export_body_run *run,
                  cf_xmodel *m)
{
    const size_t nn = b->nn, ns = run->nsteps;
    size_t total = 0;
    m->top = malloc(nn * sizeof *m->top);
    m->pp = malloc((ns + 1) * sizeof *m->pp);
    if (!m->top || !m->pp)
        return -1;
    for (size_t i = 0; i < nn; i++) {
        int ever = 0;
        for (size_t k = 0; k < ns; k++)
            ever |= run->contact[k * nn + i] != 0;
        if (ever)
            m->top[m->ntop++] = (uint32_t)i;
    }
    for (size_t k = 0; k < ns * nn; k++)
        total += run->contact[k] != 0;
    m->pn = malloc((total ? total : 1) * sizeof *m->pn);
    m->pdz_mm = malloc((total ? total : 1) * sizeof *m->pdz_mm);
    m->udz_mm = malloc((ns * m->ntop > 0 ? ns * m->ntop : 1) * sizeof *m->udz_mm);
    m->fdz_mm = malloc((ns * m->ntop > 0 ? ns * m->ntop : 1) * sizeof *m->fdz_mm);
    if (!m->pn || !m->pdz_mm || !m->udz_mm || !m->fdz_mm)
        return -1;
    m->kp_N_per_mm = cf_body_penalty(b);
    size_t w = 0;
    for (size_t k = 0; k < ns; k++) {
        const double *x = run->x_mm + 3 * nn * k;
        m->pp[k] = w;
        for (size_t i = 0; i < nn; i++)
            if (run->contact[k * nn + i]) {
                m->pn[w] = (uint32_t)i;
                m->pdz_mm[w++] = x[3 * i + 2] - b->X[3 * i + 2];
            }
        const double face = pr->center_mm[2] + run->depth_mm[k] * pr->dir[2];
        for (size_t t = 0; t < m->ntop; t++) {
            const size_t i = m->top[t];
            m->udz_mm[k * m->ntop + t] = x[3 * i + 2] - b->X[3 * i + 2];
            m->fdz_mm[k * m->ntop + t] =
                run->contact[k * nn + i] ? face - b->X[3 * i + 2] : m->udz_mm[k * m->ntop + t];
        }
    }
    m->pp[ns] = w;
    return 0;
}

/* What a body's export takes: CalculiX, FEBio or SOFA (SOFA without a volume term), a flat
** punch along z, 1 to CF_EXPORT_MAX_STEPS finite load steps. */
static cf_status check_body(const cf_body *b, const cf_probe *pr, const cf_export_body_run *run,
                            const cf_export_options *opt, cf_error *err)
{
    const size_t nsteps = run->nsteps;
    if (opt->format != CF_EXPORT_CALCULIX && opt->format != CF_EXPORT_FEBIO &&
        opt->format != CF_EXPORT_SOFA)
        return cf_error_set(err, CF_E_DATA, "a body is exported to calculix, febio or sofa, not %s",
                            cf_export_format_name(opt->format));
    if (b->nfibre > 0 && opt->format != CF_EXPORT_CALCULIX)
        return cf_error_set(err, CF_E_DATA,
                            "%s: the body's %zu fibre group%s (embedded tension-only springs tied "
                            "to the tetrahedra by linear constraints) %s no form in this export; "
                            "export it to calculix",
                            cf_export_format_name(opt->format), b->nfibre,
                            b->nfibre == 1 ? "" : "s", b->nfibre == 1 ? "has" : "have");
    if (opt->format == CF_EXPORT_SOFA && b->kappa_MPa > 0)
        return cf_error_set(err, CF_E_DATA,
                            "sofa: the body's volume term (kappa = %g MPa, nu = %g > 0.25) has no "
                            "form among SOFA's springs; export it to calculix, or take "
                            "poisson_ratio 0.25",
                            b->kappa_MPa, b->nu);
    if (b->elem && opt->format != CF_EXPORT_CALCULIX)
        return cf_error_set(err, CF_E_DATA,
                            "%s: the body's element term (body.element_term, an anisotropic "
                            "tensor per tetrahedron) has no form in this export; export it to "
                            "calculix",
                            cf_export_format_name(opt->format));
    if (pr->shape != CF_PROBE_PUNCH || fabs(pr->dir[0]) > 1e-12 || fabs(pr->dir[1]) > 1e-12)
        return cf_error_set(err, CF_E_DATA,
                            "probe: a body's export takes a flat punch moving along z (its contact "
                            "set replayed as prescribed z motions); a sphere pushes its nodes "
                            "along their own normals");
    if (nsteps == 0 || nsteps > CF_EXPORT_MAX_STEPS)
        return cf_error_set(err, CF_E_DATA, "%zu load steps: a body export takes 1 to %d", nsteps,
                            CF_EXPORT_MAX_STEPS);
    for (size_t k = 0; k < nsteps; k++)
        if (!isfinite(run->depth_mm[k]) || !isfinite(run->force_N[k]))
            return cf_error_set(err, CF_E_DATA, "load step %zu: depth or force is not finite",
                                k + 1);
    for (size_t q = 0; q < 3 * b->nn * nsteps; q++)
        if (!isfinite(run->x_mm[q]))
            return cf_error_set(err, CF_E_DATA, "load step %zu: a position is not finite",
                                q / (3 * b->nn) + 1);
    return CF_OK;
}

/* The body's net into m (every edge its own spring group: its rest length and its calibration
** factor as the weight), its height and the reaction tolerance the tables imply. 0, or -1 out of
** memory. */
static int fill_model(const cf_body *b, const cf_export_table *t, const cf_law *law,
                      const cf_export_table *gt, cf_xmodel *m)
{
    const cf_net net = cf_net_of_body(b);
    if (cf_xmodel_of_net(m, &net, CF_XGROUP_EACH) != 0)
        return -1;
    for (size_t s = 0; b->group && s < b->ns; s++) /* spring s is model group s */
        if (b->group[s]) {
            m->g[s].law = b->glaw[b->group[s]];
            m->g[s].table = &gt[b->group[s] - 1];
        }
    double zlo = INFINITY, zhi = -INFINITY;
    for (size_t i = 0; i < b->nn; i++) {
        zlo = fmin(zlo, m->Z[i]);
        zhi = fmax(zhi, m->Z[i]);
    }
    m->height_mm = zhi - zlo;
    /* the tables allow tol F_C per unit weight in each spring a horizontal plane cuts: the plane
    ** halfway up the body */
    const double zmid = (zlo + zhi) / 2;
    double wcut = 0;
    for (size_t s = 0; s < b->ns; s++) {
        const double zi = b->X[3 * b->si[s] + 2], zj = b->X[3 * b->sj[s] + 2];
        if ((zi - zmid) * (zj - zmid) < 0)
            wcut += b->c[s] * fabs(zi - zj) / b->L0[s] *
                    (b->group && b->group[s]
                         ? gt[b->group[s] - 1].tol * b->glaw[b->group[s]]->F_C_N /
                               (t->tol * law->F_C_N)
                         : 1.0); /* a group's spring: its table's tol F_C */
    }
    m->reaction_tol_N = t->tol * law->F_C_N * wcut;
    return 0;
}

cf_status cf_export_write_body(FILE *out, const cf_body *b, const cf_probe *pr,
                               const cf_export_body_run *run, const cf_export_options *opt,
                               cf_export_report *rep, cf_error *err)
{
    CF_GSL_GUARD;
    cf_status st = check_body(b, pr, run, opt, err);
    if (st != CF_OK)
        return st;
    const cf_law *law = b->law;
    cf_export_table t = {0};
    cf_xmodel m = {0};
    cf_export_report r = {0};
    cf_export_table gt[CF_BODY_MAX_GROUPS], ft[CF_FIBRE_MAX];
    memset(gt, 0, sizeof gt);
    memset(ft, 0, sizeof ft);
    if ((st = cf_export_table_for(law, opt, &t, err)) != CF_OK)
        return st;
    for (size_t g = 0; g < b->ngroups; g++) /* each spring group's law its table */
        if ((st = cf_export_table_for(b->glaw[g + 1], opt, &gt[g], err)) != CF_OK)
            goto done;
    for (size_t k = 0; k < b->nfibre; k++) /* each fibre group's law its table */
        if ((st = cf_export_table_for(&b->flaw[k], opt, &ft[k], err)) != CF_OK)
            goto done;
    char title[260];
    snprintf(title, sizeof title,
             "tissue body of %zu nodes, %zu edge springs and %zu tetrahedra (E = %.6g MPa, nu = "
             "%.6g), pressed by a flat punch of radius %.6g mm",
             b->nn, b->ns, b->nt, b->E_MPa, b->nu, pr->radius_mm);
    if (b->nfibre > 0) /* a body without fibres keeps its title */
        snprintf(title + strlen(title), sizeof title - strlen(title),
                 ", with %zu fibre group%s", b->nfibre, b->nfibre == 1 ? "" : "s");
    m.title = title;
    m.source = opt->source;
    m.output = opt->output;
    m.law = law;
    m.base = &t;
    const size_t nsteps = m.nsteps = run->nsteps;
    m.dz_mm = malloc(nsteps * sizeof *m.dz_mm);
    m.ref_N = malloc(nsteps * sizeof *m.ref_N);
    m.strain = malloc(nsteps * sizeof *m.strain);
    if (!m.dz_mm || !m.ref_N || !m.strain || replay(b, pr, run, &m) != 0)
        goto oom;
    if (m.ntop == 0) {
        st = cf_error_set(err, CF_E_DATA,
                          "probe: the punch touches no node of the body at any of the %zu steps "
                          "(its depth reaches %g mm): nothing to export",
                          nsteps, run->depth_mm[nsteps - 1]);
        goto done;
    }
    if (fill_model(b, &t, law, gt, &m) != 0)
        goto oom;
    for (size_t k = 0; k < nsteps; k++) {
        m.dz_mm[k] = run->depth_mm[k] * pr->dir[2];
        m.ref_N[k] = run->force_N[k] * (pr->dir[2] < 0 ? 1 : -1);
        m.strain[k] = run->depth_mm[k] / m.height_mm;
    }
    if (opt->format == CF_EXPORT_CALCULIX || opt->format == CF_EXPORT_FEBIO) {
        m.nt = b->nt;
        m.tet = b->tet;
        m.kappa_MPa = b->kappa_MPa;
        m.xk_mm = run->x_mm;
        m.elem = b->elem;
    }
    if (cf_xmodel_tables(&m) != 0 || cf_xmodel_body_fibres(&m, b, ft) != 0 ||
        cf_xmodel_write(out, &m, opt->format) != 0)
        goto oom;
    r = cf_export_report_of_table(&t, law);
    r.groups = m.ng;
    r.springs = m.ns;
    r.nodes = m.nn;
    r.steps = m.nsteps;
    snprintf(r.warning, sizeof r.warning,
             "the probe is not a contact the %s model detects: conifit's own contact set (%zu "
             "nodes in all) is replayed, %s at every step, so the model reproduces conifit's run "
             "rather than solving the contact itself",
             cf_export_format_name(opt->format), m.ntop,
             opt->format == CF_EXPORT_CALCULIX
                 ? "its nodes pressed by conifit's penalty springs against the punch's face"
                 : "its nodes moved along z as conifit solved them");
    if (ferror(out))
        st = cf_error_set(err, CF_E_CANTWRITE, "cannot write the body's %s model",
                          cf_export_format_name(opt->format));
    goto done;
oom:
    st = cf_error_set(err, CF_E_INTERNAL, "out of memory writing the body's model");
done:
    if (rep)
        *rep = r;
    cf_xmodel_free(&m);
    cf_export_table_free(&t);
    for (size_t g = 0; g < CF_BODY_MAX_GROUPS; g++)
        cf_export_table_free(&gt[g]);
    for (size_t k = 0; k < CF_FIBRE_MAX; k++)
        cf_export_table_free(&ft[k]);
    return st;
}
