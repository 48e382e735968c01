/*
** The predicted response of a fitted viscoelastic model to two stated loads: a load-unload cycle
** (hysteresis) and a creep test (see viscofit.h, cf_visco_predict).
*/
#include "fit/viscofit.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/msm.h"
#include "fit/viscofit_ctx.h"

enum { PRED_PER = 200 }; /* samples per half of a predicted history */

/* One load-unload cycle to the series' largest strain at its loading rate: loop area and loading
** work. */
static void predict_cycle(const cf_visco_params *p, const cf_visco_setup *s, double xpeak,
                          double tload, cf_visco_predict *out)
{
    double ts[2 * PRED_PER + 1];
    cf_msm_sample smp[2 * PRED_PER + 1];
    cf_error e = {0};
    double pt[3] = {0, tload, 2 * tload}, pv[3] = {0, fabs(xpeak), 0};
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, 3, pt, pv};
    for (int k = 0; k <= 2 * PRED_PER; k++)
        ts[k] = 2 * tload * k / (2.0 * PRED_PER);
    if (cf_visco_run(p, s, &path, ts, 2 * PRED_PER + 1, smp, &e) != CF_OK) {
        snprintf(out->note, sizeof out->note, "hysteresis: %.480s", e.msg);
        return;
    }
    double area = 0, work = 0;
    for (int k = 1; k <= 2 * PRED_PER; k++) {
        double dA = 0.5 * (smp[k].stress_MPa + smp[k - 1].stress_MPa) *
                    (smp[k].strain - smp[k - 1].strain);
        area += dA;
        if (k <= PRED_PER)
            work += dA;
    }
    out->hysteresis_done = 1;
    out->cycle_strain = xpeak;
    out->cycle_period_s = 2 * tload;
    out->loop_area_MPa = area;
    out->loading_work_MPa = work;
}

/* Creep under the stress sc (MPa, magnitude) applied in tload and held for thold; sgn is the
** table's sign of the loading. */
static void predict_creep(const cf_visco_params *p, const cf_visco_setup *s, double sc,
                          double sgn, double tload, double thold, cf_visco_predict *out)
{
    double ts[2 * PRED_PER + 1];
    cf_msm_sample smp[2 * PRED_PER + 1];
    double pt[3] = {0, tload, tload + thold}, pv[3] = {0, sc, sc};
    cf_msm_path path = {CF_DRIVE_FORCE, 3, pt, pv};
    for (int k = 0; k <= 2 * PRED_PER; k++)
        ts[k] = k <= PRED_PER ? tload * k / PRED_PER : tload + thold * (k - PRED_PER) / PRED_PER;
    cf_error ce = {0};
    if (sc > 0 && cf_visco_run(p, s, &path, ts, 2 * PRED_PER + 1, smp, &ce) == CF_OK) {
        out->creep_done = 1;
        out->creep_stress_MPa = sgn * sc;
        out->creep_ramp_s = tload;
        out->creep_hold_s = thold;
        out->creep_strain_ramp = sgn * smp[PRED_PER].strain;
        out->creep_strain_end = sgn * smp[2 * PRED_PER].strain;
    } else {
        /* after the cycle's reason, if any: each skipped prediction finds its own */
        size_t n = strlen(out->note);
        snprintf(out->note + n, sizeof out->note - n, "%screep: %.240s", n ? "; " : "",
                 sc > 0 ? (ce.msg[0] ? ce.msg : "the run failed") : "the series ends at zero stress");
    }
}

void cf_visco_predictions(const cf_visco_params *p, const cf_visco_setup *s,
                          const cf_visco_data *d, cf_visco_predict *out)
{
    CF_GSL_GUARD;
    memset(out, 0, sizeof *out);
    const size_t n = d->count;
    /* the largest strain, when it is first reached, and the loading time from the last zero */
    size_t kp = 0;
    for (size_t k = 0; k < n; k++)
        if (fabs(d->x[k]) > fabs(d->x[kp]))
            kp = k;
    size_t k0 = 0;
    for (size_t k = 0; k < kp; k++)
        if (d->x[k] == 0)
            k0 = k;
    double tload = d->t_s[kp] - d->t_s[k0];
    double thold = d->t_s[n - 1] - d->t_s[kp];
    if (!(tload > 0))
        tload = 1;
    if (!(thold > 0))
        thold = tload;
    predict_cycle(p, s, d->x[kp], tload, out);
    predict_creep(p, s, fabs(d->y[n - 1]), d->x[kp] < 0 ? -1.0 : 1.0, tload, thold, out);
}
