/*
** The joint fit of a fibre-reinforced lattice (fibre_fit.h).
*/
#include "fit/fibre_fit.h"

#include <math.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>

#include "fit/fit.h"
#include "fit/joint.h"
#include "fit/lm.h"
#include "model/calibration.h"
#include "model/cell_stability.h"

/* The bounded coordinates: rho in (rho_min, 1) with the spring fit's default rho_min (a largest
** coil at most 20 times the smallest: fit.h), s/H in (0.02, 0.99). */
#define RHO_LO CF_FIT_RHO_MIN_DEFAULT
#define B_LO 0.02
#define B_HI 0.99
/* The largest recruitment strain a group is fitted with (fibre.h). */
#define SLACK_HI 0.2
/* The largest face or body family weight of the matrix, relative to the edge family's 1. */
#define FAMILY_HI 20.0

static double logistic(double t, double lo, double hi)
{
    return lo + (hi - lo) / (1 + exp(-t));
}

static double logit(double v, double lo, double hi)
{
    const double z = (v - lo) / (hi - lo);
    return log(z / (1 - z));
}

static int axis_of(char c)
{
    return c == 'f' ? 0 : c == 's' ? 1 : c == 'n' ? 2 : -1;
}

/* The matrix's family weights in the cell: each of f's relative weights (1, 1, 1 when f has
** none) over the lattice's axial modulus E of them, so that the matrix's modulus along an axis is
** its springs' k0/H. */
static void matrix_weights(const cf_fibre_fit *f, double w[CF_FAMILY_COUNT])
{
    const int none = !(f->family[0] > 0 || f->family[1] > 0 || f->family[2] > 0);
    double u[CF_FAMILY_COUNT];
    for (int k = 0; k < CF_FAMILY_COUNT; k++)
        u[k] = none ? 1 : f->family[k];
    const double E = cf_cubic_moduli_of(u).E;
    for (int k = 0; k < CF_FAMILY_COUNT; k++)
        w[k] = u[k] / E;
}

/* The cell of f's families built of the springs sp (matrix first, then each group's), the
** matrix's family weights and each group's density times count (one of each per family). */
static cf_status model_build(cf_fibre_model *m, const cf_fibre_fit *f, const cf_spring *sp,
                             const int *count, cf_error *err)
{
    memset(m, 0, sizeof *m);
    cf_status st = cf_law_init(&m->matrix, &sp[0], err);
    if (st != CF_OK)
        return st;
    m->nlaws = 0;
    for (int k = 0; k < f->ngroups; k++) {
        if ((st = cf_law_init(&m->law[k], &sp[1 + k], err)) != CF_OK) {
            cf_fibre_model_free(m);
            return st;
        }
        m->nlaws = k + 1;
    }
    double w[CF_FAMILY_COUNT];
    matrix_weights(f, w);
    for (int k = 0; k < CF_FAMILY_COUNT; k++)
        w[k] *= count[0];
    if ((st = cf_cell_init(&m->cell, &m->matrix, CF_LAW_CLOSED, w, err)) != CF_OK) {
        cf_fibre_model_free(m);
        return st;
    }
    m->cell.volume_modulus_MPa = f->kappa_MPa;
    for (int k = 0; k < f->ngroups; k++) {
        const int a = axis_of(f->groups[k]);
        m->group[k] = (cf_fibre_group){&m->law[k], CF_LAW_CLOSED, {a == 0, a == 1, a == 2},
                                       (double)count[1 + k], f->slack[k]};
    }
    m->cell.fibre = m->group;
    m->cell.nfibre = f->ngroups;
    return CF_OK;
}

cf_status cf_fibre_model_init(cf_fibre_model *m, const cf_fibre_fit *f, cf_error *err)
{
    cf_spring sp[1 + CF_FIBRE_MAX];
    int count[1 + CF_FIBRE_MAX];
    sp[0] = cf_ident_member(&f->matrix);
    count[0] = 1;
    for (int k = 0; k < f->ngroups; k++) {
        sp[1 + k] = cf_ident_member(&f->fibre[k]);
        count[1 + k] = 1;
    }
    return model_build(m, f, sp, count, err);
}

cf_status cf_fibre_model_init_placed(cf_fibre_model *m, const cf_fibre_fit *f, cf_error *err)
{
    cf_spring sp[1 + CF_FIBRE_MAX];
    int count[1 + CF_FIBRE_MAX];
    sp[0] = f->matrix_spring.spring;
    count[0] = f->matrix_spring.count;
    for (int k = 0; k < f->ngroups; k++) {
        sp[1 + k] = f->fibre_spring[k].spring;
        count[1 + k] = f->fibre_spring[k].count;
    }
    return model_build(m, f, sp, count, err);
}

void cf_fibre_model_free(cf_fibre_model *m)
{
    cf_law_free(&m->matrix);
    for (int k = 0; k < m->nlaws; k++)
        cf_law_free(&m->law[k]);
    m->nlaws = 0;
}

/* The load of row i of t (axes as cf_ho_axes gives them). */
static cf_cell_load row_load(const cf_table *t, size_t i, const int axes[2])
{
    if (t->mode == CF_MODE_SHEAR)
        return (cf_cell_load){CF_MODE_SHEAR, {axes[0], axes[1]}, 0};
    const int d = i < t->second ? 0 : 1;
    return (cf_cell_load){CF_MODE_BIAXIAL, {axes[d], axes[1 - d]}, cf_table_biaxial_k(t, i)};
}

cf_status cf_fibre_row_stress(const cf_fibre_model *m, const cf_table *t, size_t i,
                              const int axes[2], double *stress_MPa, cf_error *err)
{
    const cf_cell_load ld = row_load(t, i, axes);
    cf_cell_state s;
    cf_status st = cf_cell_load_state(&m->cell, &ld, t->x[i], &s, err);
    *stress_MPa = st == CF_OK ? s.stress_MPa : 0;
    return st;
}

/* ---- the fit ------------------------------------------------------------------------------ */

typedef struct ff_ctx {
    const cf_table *const *t;
    size_t n, rows;
    int axes[CF_HO_MAX_TABLES][2];
    double scale[CF_HO_MAX_TABLES]; /* 1 / (RMS stress sqrt(rows)) */
    cf_fibre_fit shape;             /* groups, cross */
    double b_lo[CF_FIBRE_MAX];      /* each group's least s/H: its farthest stretch to 1.05 x
                                    ** the tables' strains, so that no spring reaches solid there */
    double b_lo_matrix;             /* the same of the matrix springs */
    int np;
} ff_ctx;

/* The largest kappa (MPa) of f's matrix: Poisson's ratio CF_JOINT_NU_MAX along an axis of its
** lattice (matrix_weights, its springs' k0/H), at most CF_KAPPA_MAX_MPA; 0 when its member is not
** a spring. */
static double kappa_max(const cf_fibre_fit *f)
{
    double w[CF_FAMILY_COUNT];
    matrix_weights(f, w);
    const cf_spring p = cf_ident_member(&f->matrix);
    cf_law law;
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 0;
    const double k0H = law.k0_N_per_mm / law.p.H_mm;
    cf_law_free(&law);
    const double k = cf_cubic_kappa_of_nu(w, k0H, CF_JOINT_NU_MAX);
    return isfinite(k) && k > 0 ? fmin(k, CF_KAPPA_MAX_MPA) : 0;
}

/* The lattice of the coordinates th: 3 for the matrix, 3 per group, 1 for kappa, 1 per group
** for its recruitment strain, then the matrix's face and body family weights. */
static void fit_of(const ff_ctx *c, const double *th, cf_fibre_fit *f)
{
    *f = c->shape;
    cf_ident *q[1 + CF_FIBRE_MAX] = {&f->matrix};
    for (int k = 0; k < f->ngroups; k++)
        q[1 + k] = &f->fibre[k];
    for (int k = 0; k <= f->ngroups; k++) {
        const double *x = th + 3 * k;
        q[k]->rho = logistic(x[0], RHO_LO, 1);
        q[k]->solid = logistic(x[1], k ? c->b_lo[k - 1] : c->b_lo_matrix, B_HI);
        q[k]->scale = exp(fmin(fmax(x[2], -40.0), 20.0));
    }
    /* the matrix's face and body family weights over the edge's, each in (0, FAMILY_HI) */
    const double *x = th + 3 * (f->ngroups + 1) + 1 + f->ngroups;
    f->family[0] = 1;
    f->family[1] = logistic(x[0], 0, FAMILY_HI);
    f->family[2] = logistic(x[1], 0, FAMILY_HI);
    /* kappa in (0, kappa_max): at most the one of Poisson's ratio CF_JOINT_NU_MAX along an axis
    ** of the matrix lattice (its weights, its springs' k0/H), as the joint fit's; within
    ** CF_KAPPA_MAX_MPA, the most a lattice takes (calibration.h) */
    f->kappa_MPa = kappa_max(f) / (1 + exp(-fmax(th[3 * (f->ngroups + 1)], -700.0)));
    for (int k = 0; k < f->ngroups; k++)
        f->slack[k] = SLACK_HI / (1 + exp(-fmax(th[3 * (f->ngroups + 1) + 1 + k], -700.0)));
}

static int residuals(const gsl_vector *x, void *arg, gsl_vector *r)
{
    const ff_ctx *c = arg;
    cf_fibre_fit f;
    cf_fibre_model m;
    fit_of(c, x->data, &f);
    const int ok = cf_fibre_model_init(&m, &f, NULL) == CF_OK;
    size_t row = 0;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        for (size_t i = 0; i < t->count; i++) {
            double y = 0;
            const double w = sqrt(t->w ? t->w[i] : 1.0) * c->scale[k];
            const int good = ok && cf_fibre_row_stress(&m, t, i, c->axes[k], &y, NULL) == CF_OK;
            const double v = w * (y - t->y[i]);
            gsl_vector_set(r, row++, good && isfinite(v) ? v : 1e10);
        }
    }
    if (ok)
        cf_fibre_model_free(&m);
    return GSL_SUCCESS;
}

static double run_lm(ff_ctx *c, double *th)
{
    const cf_lm_stop stop = {.max_iter = 300, .xtol = 1e-15, .gtol = 1e-15, .ftol = 0,
                             .stall = 20, .stall_rel = 1e-14, .floor = 1e-28};
    return cf_lm_minimise(residuals, c, c->rows, (size_t)c->np, th, &stop);
}

static double reach_of(const ff_ctx *c, int a, double over);
static double matrix_reach(const ff_ctx *c, double over);

/* The tables' axes and weights and the groups into c; *amp the largest RMS stress. */
static cf_status setup(ff_ctx *c, const cf_table *const *t, size_t n, const char *groups,
                       char cross, double *amp, cf_error *err)
{
    if (n < 1 || n > CF_HO_MAX_TABLES)
        return cf_error_set(err, CF_E_DATA, "a fibre-lattice fit takes 1 to %d tables, not %zu",
                            CF_HO_MAX_TABLES, n);
    const size_t ng = groups ? strlen(groups) : 0;
    int seen = 0;
    for (size_t k = 0; k < ng && ng <= 3; k++) {
        const int a = axis_of(groups[k]);
        seen = a < 0 || (seen & (1 << a)) ? -1 : seen | (1 << a);
        if (seen < 0)
            break;
    }
    if (ng < 1 || ng > 3 || seen < 0)
        return cf_error_set(err, CF_E_DATA, "fibre groups '%.16s': one to three of the axes f, "
                            "s and n, each once", groups ? groups : "");
    if (cross != 'n' && cross != 's')
        return cf_error_set(err, CF_E_DATA, "cross-fibre axis '%c': n or s", cross);
    memset(c, 0, sizeof *c);
    c->t = t;
    c->n = n;
    memcpy(c->shape.groups, groups, ng);
    c->shape.ngroups = (int)ng;
    c->shape.cross = cross;
    c->np = 3 * ((int)ng + 1) + 1 + (int)ng + 2;
    *amp = 0;
    for (size_t k = 0; k < n; k++) {
        char why[CF_ERROR_MSG_LEN];
        if (cf_ho_axes(t[k], cross, c->axes[k]) != 0) {
            cf_ho_unfit(t + k, 1, why, sizeof why);
            return cf_error_set(err, CF_E_DATA, "%s", why);
        }
        double ss = 0;
        for (size_t i = 0; i < t[k]->count; i++)
            ss += t[k]->y[i] * t[k]->y[i];
        const double rms = sqrt(ss / (double)t[k]->count);
        if (!(rms > 0))
            return cf_error_set(err, CF_E_DATA, "%s: every stress is zero: no scale to weigh "
                                "its residuals by", t[k]->path);
        c->scale[k] = 1 / (rms * sqrt((double)t[k]->count));
        c->rows += t[k]->count;
        *amp = fmax(*amp, rms);
    }
    for (size_t k = 0; k < ng; k++)
        c->b_lo[k] = fmax(B_LO, 1.001 * reach_of(c, axis_of(groups[k]), 1.05));
    c->b_lo_matrix = fmax(B_LO, 1.001 * matrix_reach(c, 1.05));
    return CF_OK;
}

/* The farthest fibre strain lambda - 1 of a group along axis a over the tables at `over` times
** their strains: a loaded biaxial axis stretches by its strain, the normal of a sheared face by
** sqrt(1 + gamma^2) (the free axis of a biaxial row shortens and leaves the fibre slack). */
static double reach_of(const ff_ctx *c, int a, double over)
{
    double r = 0;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        for (size_t i = 0; i < t->count; i++) {
            const double e = over * t->x[i];
            if (t->mode == CF_MODE_SHEAR && c->axes[k][0] == a)
                r = fmax(r, sqrt(1 + e * e) - 1);
            else if (t->mode == CF_MODE_BIAXIAL) {
                const cf_cell_load ld = row_load(t, i, c->axes[k]);
                if (ld.axis[0] == a)
                    r = fmax(r, e);
                else if (ld.axis[1] == a)
                    r = fmax(r, ld.k * e);
            }
        }
    }
    return r;
}

/* The farthest strain |L/L0 - 1| of a matrix spring over the tables at `over` times their strains:
** simple shear's from the cell's geometry (cf_cell_spring_strain), a biaxial row's by the
** shortening of its free axis were the cell incompressible, 1 - 1 / ((1 + e)(1 + k e)), which
** the compressible cell does not exceed (its volume grows under tension). */
static double matrix_reach(const ff_ctx *c, double over)
{
    double r = 0;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        for (size_t i = 0; i < t->count; i++) {
            const double e = over * t->x[i];
            if (t->mode == CF_MODE_SHEAR)
                r = fmax(r, cf_cell_spring_strain(CF_MODE_SHEAR, e));
            else {
                const double kk = cf_table_biaxial_k(t, i);
                r = fmax(r, fmax(fabs(e), 1 - 1 / ((1 + e) * (1 + kk * e))));
            }
        }
    }
    return r;
}

/* The smallest eigenvalue of the cell's incremental stiffness over every row's state of the
** tables and each table's path to 1.05 x its farthest strain (both directions of a biaxial one);
** -INFINITY when a state cannot be reached. */
static double min_stiffness(const ff_ctx *c, const cf_fibre_model *m)
{
    double lo = INFINITY;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        double far[2] = {0, 0};
        size_t at[2] = {0, 0};
        for (size_t i = 0; i <= t->count + 1; i++) {
            const size_t row = i < t->count ? i : at[i - t->count];
            const int d = row < t->second ? 0 : 1;
            cf_cell_load ld = row_load(t, row, c->axes[k]);
            const double e = i < t->count ? t->x[row] : 1.05 * far[i - t->count];
            if (i < t->count && fabs(e) > fabs(far[d]))
                far[d] = e, at[d] = row;
            if (i >= t->count && far[i - t->count] == 0)
                continue;
            cf_cell_state s;
            double l;
            if (cf_cell_load_state(&m->cell, &ld, e, &s, NULL) != CF_OK ||
                cf_cell_min_stiffness(&m->cell, s.F, &l, NULL) != CF_OK)
                return -INFINITY;
            lo = fmin(lo, l);
        }
    }
    return lo;
}

/* The start s of the grid: the matrix near the isotropic lattice of these scales, each group's
** rho, s/H and scale on a 2 x 2 x 2 grid (rho 0.3 or 0.8, s/H 0.14 or 0.25, scale 1 or 5 x amp;
** the groups after the first at 0.3 of the first's scale), kappa at 1 % of its bound, each
** group recruited at strain 0.01. */
static void start(const ff_ctx *c, int s, double amp, double *th)
{
    th[0] = logit(0.6, RHO_LO, 1);
    th[1] = logit(fmax(0.3, 1.1 * c->b_lo_matrix), c->b_lo_matrix, B_HI);
    th[2] = log(amp);
    for (int k = 0; k < c->shape.ngroups; k++) {
        double *x = th + 3 * (k + 1);
        x[0] = logit(s & 1 ? 0.8 : 0.3, RHO_LO, 1);
        x[1] = logit(fmax(s & 2 ? 0.25 : 0.14, 1.1 * c->b_lo[k]), c->b_lo[k], B_HI);
        x[2] = log((s & 4 ? 5.0 : 1.0) * amp * (k ? 0.3 : 1.0));
    }
    const int nk = 3 * (c->shape.ngroups + 1);
    th[nk] = log(0.01 / 0.99); /* kappa 1 % of its bound */
    for (int k = 0; k < c->shape.ngroups; k++)
        th[nk + 1 + k] = logit(0.01, 0, SLACK_HI);
    th[nk + 1 + c->shape.ngroups] = th[nk + 2 + c->shape.ngroups] = logit(1, 0, FAMILY_HI);
}

/* Each table's RMSE and term, the stability, into r (the model of r). */
static void finish(const ff_ctx *c, cf_fibre_fit *r)
{
    cf_fibre_model m;
    r->stable = 0;
    r->min_stiffness_MPa = -INFINITY;
    if (cf_fibre_model_init(&m, r, NULL) != CF_OK)
        return;
    r->objective = 0;
    for (size_t k = 0; k < c->n; k++) {
        const cf_table *t = c->t[k];
        double ss = 0, sw = 0;
        for (size_t i = 0; i < t->count; i++) {
            double y = 0;
            cf_fibre_row_stress(&m, t, i, c->axes[k], &y, NULL);
            ss += (y - t->y[i]) * (y - t->y[i]);
            sw += (t->w ? t->w[i] : 1.0) * (y - t->y[i]) * (y - t->y[i]);
        }
        r->rmse_MPa[k] = sqrt(ss / (double)t->count);
        r->term[k] = sw * c->scale[k] * c->scale[k];
        r->objective += r->term[k];
    }
    r->min_stiffness_MPa = min_stiffness(c, &m);
    r->stable = r->min_stiffness_MPa > 0;
    cf_fibre_model_free(&m);
}

/* The largest difference between the placed lattice's stress and the fitted one's over every
** row, relative to its table's largest |stress|; -1 when either does not run. */
static double placed_error(const ff_ctx *c, const cf_fibre_fit *r)
{
    cf_fibre_model fitted, placed;
    if (cf_fibre_model_init(&fitted, r, NULL) != CF_OK)
        return -1;
    if (cf_fibre_model_init_placed(&placed, r, NULL) != CF_OK) {
        cf_fibre_model_free(&fitted);
        return -1;
    }
    double worst = 0;
    for (size_t k = 0; k < c->n && worst >= 0; k++) {
        const cf_table *t = c->t[k];
        double ymax = 0;
        for (size_t i = 0; i < t->count; i++)
            ymax = fmax(ymax, fabs(t->y[i]));
        for (size_t i = 0; i < t->count && worst >= 0; i++) {
            double a = 0, b = 0;
            if (cf_fibre_row_stress(&fitted, t, i, c->axes[k], &a, NULL) != CF_OK ||
                cf_fibre_row_stress(&placed, t, i, c->axes[k], &b, NULL) != CF_OK)
                worst = -1;
            else
                worst = fmax(worst, fabs(a - b) / ymax);
        }
    }
    cf_fibre_model_free(&fitted);
    cf_fibre_model_free(&placed);
    return worst;
}

/* Each family of r placed as buildable springs (cf_fibre_place, the spring fit's default design
** limits), the groups at the matrix spring's free length, the cell's edge; their travel to the
** tables' own farthest strains (a group no table stretches still gets a travel, 1e-3). */
static cf_status place_all(const ff_ctx *c, cf_fibre_fit *r, cf_error *err)
{
    const cf_fit_options opt = cf_fit_default_options();
    cf_status st = cf_fibre_place(&r->matrix, fmax(matrix_reach(c, 1.0), 1e-3), &opt, 0,
                                  &r->matrix_spring, err);
    if (st != CF_OK)
        return st;
    r->buildable = r->matrix_spring.buildable;
    const double H = r->matrix_spring.spring.H_mm;
    for (int k = 0; k < r->ngroups; k++) {
        const double reach = fmax(reach_of(c, axis_of(r->groups[k]), 1.0), 1e-3);
        if ((st = cf_fibre_place(&r->fibre[k], reach, &opt, H, &r->fibre_spring[k], err)) !=
            CF_OK)
            return st;
        r->buildable = r->buildable && r->fibre_spring[k].buildable;
    }
    r->placed_error = placed_error(c, r);
    return CF_OK;
}

cf_status cf_fibre_fit_joint(const cf_table *const *t, size_t n, const char *groups, char cross,
                             cf_fibre_fit *r, cf_error *err)
{
    ff_ctx c;
    double amp = 0, best = INFINITY, th_best[4 * CF_FIBRE_MAX + 6] = {0};
    cf_status st = setup(&c, t, n, groups, cross, &amp, err);
    if (st != CF_OK)
        return st;
    memset(r, 0, sizeof *r);
    for (int s = 0; s < 8; s++) {
        double th[4 * CF_FIBRE_MAX + 6];
        start(&c, s, amp, th);
        const double ss = run_lm(&c, th);
        r->starts++;
        if (ss < best) {
            best = ss;
            memcpy(th_best, th, sizeof th_best);
        }
    }
    if (!(best < 1e19))
        return cf_error_set(err, CF_E_NOCONV, "the fibre-lattice fit found no lattice with a "
                            "finite objective on the %zu tables", n);
    const int starts = r->starts;
    fit_of(&c, th_best, r);
    r->starts = starts;
    r->nparams = c.np;
    r->ntables = n;
    finish(&c, r);
    return place_all(&c, r, err);
}
