/*
** Section 7: the lattice's calibration and the homogenised cell. For each family weighting (axial,
** isotropic, fitted, and the uncalibrated weight 1), on a noiseless table of a known spring to 95 %
** of its solid strain in compression: the lattice's small-strain modulus and nu, the full-lattice
** error of a single-spring fit and of the fit through the lattice, the compressive stability limit
** and the time of the fit through the lattice. Then the cost of one uniaxial curve through the cell
** against the full static lattice of growing size.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench.h"
#include "model/cell.h"
#include "fit/fit.h"
#include "fit/joint.h"
#include "model/msm.h"
#include "check/validate.h"

#define ROWS 40

/* A compression-negative table of spring p to 95 % of its solid strain (MPa; y_to_file kPa). */
static void make_table(const cf_law *law, double sign, double *x, double *y, cf_table *t)
{
    const double H = law->p.H_mm, sH = law->travel_mm / H;
    for (int i = 0; i < ROWS; i++) {
        double e = 0.95 * sH * (i + 1) / ROWS;
        x[i] = sign * e;
        y[i] = sign * cf_law_force(law, CF_LAW_EXACT, e * H, NULL, NULL) / (H * H);
    }
    memset(t, 0, sizeof *t);
    t->kind = CF_TABLE_STRESS_STRAIN;
    t->count = ROWS;
    t->x = x;
    t->y = y;
    t->y_to_file = 1e3;
    t->mode = CF_MODE_UNIAXIAL;
    t->compression = sign < 0;
    snprintf(t->path, sizeof t->path, "known spring, %s", sign < 0 ? "compression" : "tension");
    snprintf(t->y_unit, sizeof t->y_unit, "kPa");
}

void bench_section_calibration(bench_ctx *ctx)
{
    const int repeats = ctx->quick ? 1 : 3;
    fprintf(ctx->md, "## 7. Lattice calibration and the homogenised cell\n\n");
    cf_spring sp = {6, 15, 2.5, 2, 26, 10};
    cf_law law;
    if (cf_law_init(&law, &sp, NULL) != CF_OK)
        return;
    double xc[ROWS], yc[ROWS], xt[ROWS], yt[ROWS];
    cf_table tc, tt;
    make_table(&law, -1, xc, yc, &tc);
    make_table(&law, 1, xt, yt, &tt);
    double ymax = fabs(yc[ROWS - 1]);
    cf_fit_options fo = cf_fit_default_options();
    cf_fit_result fit;
    if (cf_fit_run(&tc, &fo, CF_NON_TELESCOPING, &fit, NULL) != CF_OK)
        return;
    /* the fitted weights: a joint fit of the spring's tension and compression tables */
    double wf[3] = {0, 0, 0};
    {
        cf_validate_setup js = cf_validate_default();
        js.cfg.lattice.calibration = CF_CAL_FITTED;
        const cf_table *both[2] = {&tc, &tt};
        cf_joint_result jr;
        if (cf_joint_fit(both, 2, &fo, &js, CF_NON_TELESCOPING, &jr, NULL) == CF_OK)
            memcpy(wf, jr.weight, sizeof wf);
        cf_joint_free(&jr);
    }
    fprintf(ctx->md,
            "The spring of the shipped scenes (D1 6, D2 15, n 2.5, d 2 mm, G 26 MPa, H 10 mm; solid "
            "strain 0.5), a noiseless table of %d rows to 95 %% of the solid strain in compression; "
            "a non-telescoping fit. Full 3³ lattice, bottom axial. Errors are the full lattice's "
            "RMSE against the table, %% of its largest |stress| (%.4g kPa). *fitted*: the weights "
            "of a joint fit of the spring's tension and compression tables (`--joint "
            "--calibration fitted`). Stability: the compressive strain where the tangent first has "
            "a negative pivot, as a fraction of the solid strain. Time: the fit through the lattice "
            "(search through the cell plus one full-lattice verification), ms, median of %d.\n\n"
            "| calibration | weights edge / face / body | modulus / (k0/H) | ν | single-spring fit "
            "in the lattice | `--target lattice` | stable to (of solid) | fit through the "
            "lattice, ms |\n|---|---|---|---|---|---|---|---|\n",
            ROWS, ymax * 1e3, repeats);
    const char *names[4] = {"axial", "isotropic (default)", "fitted", "uncalibrated (weight 1)"};
    double W[4][3] = {{0}, {0}, {wf[0], wf[1], wf[2]}, {1, 1, 1}};
    cf_calibration_weights(CF_CAL_AXIAL, W[0], NULL);
    cf_calibration_weights(CF_CAL_ISOTROPIC, W[1], NULL);
    for (int c = 0; c < 4; c++) {
        if (!(W[c][0] > 0))
            continue;
        cf_validate_setup s = cf_validate_default();
        memcpy(s.cfg.lattice.weight, W[c], sizeof W[c]);
        s.cfg.lattice.calibration = CF_CAL_CUSTOM;
        cf_cubic_moduli cm = cf_cubic_moduli_of(W[c]);
        cf_validation v0, v1;
        double e0 = NAN, e1 = NAN, lim = NAN, ms[5];
        if (cf_validate_run(&fit.params, &s, &tc, &v0, NULL) == CF_OK)
            e0 = v0.rmse / ymax;
        cf_validation_free(&v0);
        for (int r = 0; r < repeats; r++) {
            cf_fit_result f2 = fit;
            cf_through_msm th;
            memset(&v1, 0, sizeof v1);
            double t0 = bench_now();
            cf_lattice_fit(&tc, &fo, &s, &f2, &th, NULL);
            cf_validate_lattice_fit(&tc, &s, &f2, &v1, &th, NULL);
            ms[r] = 1e3 * (bench_now() - t0);
            if (v1.done) {
                e1 = v1.rmse / ymax;
                lim = v1.stability_checked && v1.stable_to_strain != 0
                          ? -v1.stable_to_strain / (law.travel_mm / law.p.H_mm)
                          : NAN;
            }
            cf_validation_free(&v1);
        }
        bench_stats st = bench_summarise(ms, repeats);
        char limtxt[32];
        if (isfinite(lim))
            snprintf(limtxt, sizeof limtxt, "%.3f", lim);
        else
            snprintf(limtxt, sizeof limtxt, "0.995 (stable)");
        fprintf(ctx->md, "| %s | %.4f / %.4f / %.4f | %.4f | %.3f | %.2f %% | %.2f %% | %s | "
                         "%.0f [%.0f–%.0f] |\n",
                names[c], W[c][0], W[c][1], W[c][2], cm.E, cm.nu, 100 * e0, 100 * e1, limtxt,
                st.median, st.min, st.max);
    }
    /* the cell against the full lattice, one uniaxial curve of ROWS strains */
    double w[3];
    cf_calibration_weights(CF_CAL_ISOTROPIC, w, NULL);
    cf_cell cell;
    cf_cell_init(&cell, &law, CF_LAW_CLOSED, w, NULL);
    double curve[ROWS], full[ROWS], t[7];
    const int reps_cell = 7, reps_full = ctx->quick ? 1 : 3;
    for (int r = 0; r < reps_cell; r++) {
        double t0 = bench_now();
        for (int k = 0; k < 100; k++)
            cf_cell_curve(&cell, CF_MODE_UNIAXIAL, xc, ROWS, curve, NULL);
        t[r] = (bench_now() - t0) / 100;
    }
    bench_stats sc = bench_summarise(t, reps_cell);
    fprintf(ctx->md,
            "\nOne uniaxial curve of the same %d compressive strains (isotropic lattice, closed "
            "form): the homogenised cell against the full static lattice (time median of %d "
            "[min–max]; largest |full − cell| relative to the largest stress).\n\n"
            "| model | time of one curve | per strain | largest difference |\n|---|---|---|---|\n"
            "| homogenised cell | %.3g ms [%.3g–%.3g] | %.3g µs | – |\n",
            ROWS, reps_full, 1e3 * sc.median, 1e3 * sc.min, 1e3 * sc.max,
            1e6 * sc.median / ROWS);
    const int sizes[3] = {1, 3, 5};
    for (int z = 0; z < (ctx->quick ? 2 : 3); z++) {
        cf_msm_config cfg = cf_msm_default();
        cfg.lattice.nx = cfg.lattice.ny = cfg.lattice.nz = sizes[z];
        double tf[3], dmax = 0;
        int ok = 1;
        for (int r = 0; r < reps_full; r++) {
            double t0 = bench_now();
            ok &= cf_msm_uniaxial(&law, CF_LAW_CLOSED, &cfg, xc, ROWS, full, NULL, NULL) == CF_OK;
            tf[r] = bench_now() - t0;
        }
        for (int i = 0; i < ROWS; i++)
            dmax = fmax(dmax, fabs(full[i] - curve[i]));
        bench_stats sf = bench_summarise(tf, reps_full);
        fprintf(ctx->md, "| full lattice %d³ | %.3g ms [%.3g–%.3g] | %.3g ms | %s%.1e |\n",
                sizes[z], 1e3 * sf.median, 1e3 * sf.min, 1e3 * sf.max, 1e3 * sf.median / ROWS,
                ok ? "" : "failed ", dmax / ymax);
    }
    fprintf(ctx->md, "\n");
    bench_target_add(ctx, "homogenised cell = full lattice (1e-9)", 1,
                     "tests/unit/test_cell.c, four sizes, three calibrations");
}
