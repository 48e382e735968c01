/*
** `conifit fit`: fit conical springs (both types by default) to one or more measured tables,
** print a readable report, and write one JSON fit file (and optionally a plot) per table.
** Several tables run in parallel with -j N (one thread per table at a time; the fitter keeps no
** global state). This file names the outputs, runs the fits and prints; the arguments are parsed
** in cli_fit_args.c.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic.h"
#include "model/calibration.h"
#include "model/mode.h"
#include "cli/cli.h"
#include "cli/cli_fit.h"
#include "cli/cli_shard.h"
#include "fit/baseline.h"
#include "io/fitfile.h"
#include "fit/joint.h"
#include "report/jointreport.h"
#include "pipeline/pipeline.h"
#include "pipeline/pipeline_joint.h"
#include "pipeline/pipeline_series.h"
#include "pipeline/pool.h"

typedef struct fit_job {
    const fit_args *args;
    const char *file;
    cf_table m;
    cf_fit_report rep;
    cf_visco_report vrep;        /* a time series (m.t not NULL) */
    char json_path[4096];        /* "" when not written */
    char plot_path[4096];
    cf_atomic json_out, plot_out; /* both complete, put in place as soon as the job succeeds */
    const cf_shard *shard;       /* --shard: its fit file is stamped with the study's options */
    char *text;
    const char *const *inputs;   /* every input of the run: never an output */
    cf_error err;
    cf_status st;
} fit_job;

/* Named warnings on stderr: a family that cannot be placed inside the limits, a law that goes
** solid close past the data. */
static void fit_warnings(const char *file, const cf_fit_report *r, const cf_fit_result *f)
{
    const char *type = cf_spring_type_name(f->type);
    for (int b = 0; b < CF_C_COUNT; b++) {
        unsigned bit = 1u << b;
        if (f->violated & bit)
            cf_cli_printf_safe(stderr,
                    "conifit: warning: %s: no %s spring of this table meets the limit %s "
                    "(feasible: false); to widen it: %s\n",
                    file, type, cf_fit_constraint_name(bit),
                    cf_fit_constraint_flag_for(bit, cf_table_is_force(r->table)));
    }
    if (f->feasible && f->solid_ratio < CF_FIT_SOLID_RATIO_WARN)
        cf_cli_printf_safe(stderr,
                "conifit: warning: %s: the %s law goes solid at %s %.4g%s%s, %.3g times the "
                "table's largest (below %.1f): it stiffens without bound just past the data\n",
                file, type, cf_table_is_force(r->table) ? "displacement [mm]" : "strain",
                f->solid_table_strain > 0 ? f->solid_table_strain : f->ident.solid,
                cf_table_is_force(r->table) ? "" : " in ",
                cf_table_is_force(r->table) ? "" : cf_mode_name(r->table->mode), f->solid_ratio,
                CF_FIT_SOLID_RATIO_WARN);
}

/* What the model cannot follow in the table (cf_report_warnings), on stderr. */
static void report_warnings(const char *file, const cf_fit_report *r)
{
    char w[CF_REPORT_WARNINGS_MAX][CF_REPORT_WARNING_LEN];
    int n = cf_report_warnings(r, w, CF_REPORT_WARNINGS_MAX);
    for (int k = 0; k < n; k++)
        cf_cli_printf_safe(stderr, "conifit: warning: %s: %s\n", file, w[k]);
}

/* Through-the-lattice work and each type of a joint fit take seconds: say so on a terminal. */
static void show_progress(void *ctx, const char *table, const char *what)
{
    (void)ctx;
    if (!table)
        cf_cli_printf_safe(stderr, "conifit fit: %s\n", what);
    else if (strstr(what, "through the lattice") || strstr(what, "viscoelastic"))
        cf_cli_printf_safe(stderr, "conifit: %s: %s...\n", table, what);
}

static void fit_one(fit_job *j);

/* Puts a job's outputs in place, the plot first: a fit file in place means a finished table
** (what a resumed shard looks for). On failure nothing of the job's is left but what was in
** place already. */
static void put_in_place(fit_job *j)
{
    if (j->st == CF_OK && j->shard && j->json_path[0])
        j->st = cf_cli_shard_stamp(j->shard, j->file, &j->json_out, &j->err);
    if (j->st == CF_OK && j->plot_path[0])
        j->st = cf_atomic_commit(&j->plot_out, &j->err);
    if (j->st == CF_OK && j->json_path[0])
        j->st = cf_atomic_commit(&j->json_out, &j->err);
    cf_atomic_abort(&j->json_out);
    cf_atomic_abort(&j->plot_out);
    if (j->st != CF_OK)
        j->json_path[0] = j->plot_path[0] = '\0'; /* not written (by this run) */
}

/* Fits one loaded table and writes its outputs as soon as they are complete, so that a batch
** stopped part way keeps every table it finished. */
static void run_job(fit_job *j)
{
    if (j->st != CF_OK) /* its table could not be read */
        return;
    fit_one(j);
    put_in_place(j);
}

/* Fits one table and prepares its outputs as complete temporaries. */
static void fit_one(fit_job *j)
{
    const fit_args *a = j->args;
    if (j->m.t) { /* a time series: the viscoelastic fit */
        j->st = cf_pipeline_fit_series(&j->m, &a->popt, &a->vopt, &j->vrep, &j->err);
        if (j->st == CF_OK)
            j->st = cf_pipeline_series_prepare(&j->vrep, j->json_path[0] ? j->json_path : NULL,
                                               j->plot_path[0] ? j->plot_path : NULL, j->inputs,
                                               &j->json_out, &j->plot_out, &j->err);
        if (j->st == CF_OK && !a->quiet)
            j->text = cf_visco_report_text(&j->vrep);
        return;
    }
    j->st = cf_pipeline_fit(&j->m, &a->popt, &j->rep, &j->err);
    if (j->st != CF_OK)
        return;
    /* both outputs as temporaries, put in place by run_job */
    j->st = cf_pipeline_prepare(&j->rep, j->json_path[0] ? j->json_path : NULL,
                                j->plot_path[0] ? j->plot_path : NULL, j->inputs, &j->json_out,
                                &j->plot_out, &j->err);
    if (j->st != CF_OK)
        return;
    if (!a->quiet)
        j->text = cf_report_text(&j->rep);
}

/* Names every output of the run before anything is read or fitted, and refuses the run when two
** outputs share a name (two tables with one base name in a batch, -o and --plot alike) or an
** output cannot be written (an input, a non-regular file, a missing folder). */
static int plan_outputs(const fit_args *a, fit_job *jobs, const char *const *inputs)
{
    cf_error err = {0};
    for (int i = 0; i < a->nfiles; i++) {
        fit_job *j = &jobs[i];
        j->inputs = inputs;
        if (cf_cli_is_stdio(a->out))
            ; /* the fit file goes to standard output, written by cf_cli_fit */
        else if (a->out && cf_cli_is_dir_target(a->out))
            cf_cli_path_in_dir(j->json_path, sizeof j->json_path, a->out, a->files[i], ".json");
        else if (a->out)
            snprintf(j->json_path, sizeof j->json_path, "%s", a->out);
        if (a->plot && (a->nfiles > 1 || cf_cli_is_dir_target(a->plot)))
            cf_cli_path_in_dir(j->plot_path, sizeof j->plot_path, a->plot, a->files[i], ".png");
        else if (a->plot)
            snprintf(j->plot_path, sizeof j->plot_path, "%s", a->plot);
        const char *mine[2] = {j->json_path, j->plot_path};
        for (int k = 0; k < 2; k++) {
            if (!mine[k][0])
                continue;
            if (cf_atomic_check(mine[k], inputs, &err) != CF_OK)
                return cf_cli_fail(&err);
            /* against every output named so far, this table's included */
            for (int i2 = 0; i2 <= i; i2++)
                for (int k2 = 0; k2 < 2; k2++) {
                    const char *other = k2 == 0 ? jobs[i2].json_path : jobs[i2].plot_path;
                    if ((i2 == i && k2 >= k) || !other[0] || strcmp(other, mine[k]) != 0)
                        continue;
                    if (i2 == i)
                        return cf_cli_usage_error("fit", "-o and --plot both name %s", mine[k]);
                    return cf_cli_usage_error("fit", "tables %s and %s would both be written "
                                              "to %s; give them different names",
                                              a->files[i2], a->files[i], mine[k]);
                }
        }
    }
    return -1;
}

/* --joint: one lattice fitted to every table (pipeline_joint.h), each spring type asked for;
** the outputs checked before, put in place and printed after. */
static int run_joint(const fit_args *a, fit_job *jobs, const char *const *inputs)
{
    cf_error err = {0};
    const char *outs[2] = {a->out, a->plot};
    for (int k = 0; k < 2; k++)
        if (outs[k] && cf_atomic_check(outs[k], inputs, &err) != CF_OK)
            return cf_cli_fail(&err);
    if (a->out && a->plot && strcmp(a->out, a->plot) == 0)
        return cf_cli_usage_error("fit", "-o and --plot both name %s", a->out);
    const cf_table *tabs[CF_JOINT_MAX];
    if (a->nfiles > CF_JOINT_MAX)
        return cf_cli_usage_error("fit", "--joint takes at most %d tables", CF_JOINT_MAX);
    for (int i = 0; i < a->nfiles; i++)
        tabs[i] = &jobs[i].m;
    cf_joint_report r;
    int rc = CF_EXIT_OK;
    /* a declared kappa is in the tables' stress unit (the first table's) */
    cf_pipeline_options popt = a->popt;
    if (popt.fit.volume == CF_VOLUME_MODULUS) {
        popt.fit.volume_value /= tabs[0]->y_to_file;
        if (!(popt.fit.volume_value <= CF_KAPPA_MAX_MPA))
            return cf_cli_usage_error("fit",
                                      "--volume-modulus %g %s (%s's stress unit) is %g MPa: kappa "
                                      "must be at most %g MPa (" CF_KAPPA_MAX_WHY ")",
                                      a->popt.fit.volume_value, tabs[0]->y_unit, tabs[0]->path,
                                      popt.fit.volume_value, CF_KAPPA_MAX_MPA);
    }
    if (cf_pipeline_fit_joint(tabs, (size_t)a->nfiles, &popt, &r, &err) != CF_OK)
        rc = cf_cli_fail(&err);
    cf_atomic jo = {0}, po = {0};
    if (rc == CF_EXIT_OK &&
        cf_joint_prepare(&r, a->out, a->plot, inputs, &jo, &po, &err) != CF_OK)
        rc = cf_cli_fail(&err);
    if (rc == CF_EXIT_OK && ((a->out && cf_atomic_commit(&jo, &err) != CF_OK) ||
                             (a->plot && cf_atomic_commit(&po, &err) != CF_OK)))
        rc = cf_cli_fail(&err);
    if (rc == CF_EXIT_OK && !a->quiet) {
        char *text = cf_joint_text(&r);
        if (text)
            cf_cli_write_safe(stdout, text);
        free(text);
        if (a->out)
            cf_cli_printf_safe(stdout, "Fit file: %s\n", a->out);
        if (a->plot)
            cf_cli_printf_safe(stdout, "Plot: %s\n", a->plot);
    }
    cf_joint_report_free(&r);
    return rc;
}

/* Reads every table (one that cannot be read is a failed table of the batch, as one that
** cannot be fitted: the others go on), the scene, and the elastic fit a series is held to, and
** checks the options against the tables read. -1 to go on, else an exit status. */
static int load_inputs(fit_args *a, fit_job *jobs, int *nseries)
{
    int rc = -1, nread = 0;
    for (int i = 0; i < a->nfiles; i++) {
        jobs[i].args = a;
        jobs[i].file = a->files[i];
        jobs[i].st = cf_measure_load(a->files[i], &a->mopt, &jobs[i].m, &jobs[i].err);
        if (jobs[i].st == CF_OK) {
            cf_cli_table_notes(&jobs[i].m);
            nread++;
        }
    }
    if (rc < 0 && a->scene) {
        cf_error err = {0};
        if (cf_pipeline_use_scene(&a->popt, a->scene, &err) != CF_OK)
            rc = cf_cli_fail(&err);
    }
    *nseries = 0;
    for (int i = 0; i < a->nfiles && rc < 0; i++)
        *nseries += jobs[i].st == CF_OK && jobs[i].m.t != NULL;
    /* as the series' options in a batch with stress-strain tables, these apply to the tables
    ** they concern; refused when every table read is a series */
    if (rc < 0 && *nseries > 0 && *nseries == nread &&
        (a->popt.validate || a->popt.target == CF_TARGET_LATTICE))
        rc = cf_cli_usage_error("fit", "--validate and --target lattice apply to stress-strain "
                                       "tables; a time series is fitted through the lattice "
                                       "already");
    /* the single spring has no shear, planar, equibiaxial or confined curve: its law against such
    ** a table would be the law at a uniaxial strain equal to the table's */
    for (int i = 0; i < a->nfiles && rc < 0 && a->popt.target == CF_TARGET_SPRING && !a->joint;
         i++)
        if (jobs[i].st == CF_OK && !jobs[i].m.t && !cf_table_is_force(&jobs[i].m) &&
            !cf_mode_row_of(jobs[i].m.mode)->spring_curve)
            rc = cf_cli_usage_error("fit", "--target spring: the table's mode is %s, which a "
                                           "single spring has no curve of; fit it through the "
                                           "lattice (the default in that mode) or give "
                                           "--mode uniaxial",
                                    cf_mode_name(jobs[i].m.mode));
    /* the tailed law: the spring itself or through the lattice (one table or several jointly),
    ** as the conical law; not with fixed parameters, and a time series' elastic part is fitted as
    ** the conical law (a tailed one is held, --elastic with a tailed fit) */
    const cf_law_kind law = a->popt.fit.law;
    int nfixed = 0;
    for (int k = 0; k < CF_P_COUNT; k++)
        nfixed += a->popt.fit.fixed[k] != 0;
    if (rc < 0 && law != CF_KIND_CONICAL) {
        const char *lname = cf_law_kind_name(law);
        if (*nseries)
            rc = cf_cli_usage_error("fit", "--law %s: a time series' elastic part is fitted as "
                                           "the conical law (use --law conical; a tailed spring "
                                           "is held with --elastic of a tailed fit)", lname);
        else if (nfixed)
            rc = cf_cli_usage_error("fit", "--law %s places its spring in closed form and holds "
                                           "no parameter fixed (drop --fix)", lname);
    }
    if (rc < 0 && *nseries == 0 && nread > 0 && a->series_only)
        rc = cf_cli_usage_error("fit", "--branches, --dashpot, --relaxation, --elastic and "
                                       "--max-evaluations apply to time "
                                       "series "
                                       "(a table with a time column) only");
    if (rc < 0 && a->elastic) {
        cf_fitted_spring fs;
        cf_error err = {0};
        if (cf_fitfile_load_spec(a->elastic, &fs, &err) != CF_OK) {
            rc = cf_cli_fail(&err);
        } else {
            /* a tailed spring is held with its fourth quantity, the tail's compliance
            ** e_t = F_C/(k_t H) = (s/H) n_tail/n: the model runs the tailed law */
            a->vopt.elastic = cf_ident_of(&fs.params, 0);
            a->vopt.elastic_e_tail = cf_spring_has_tail(&fs.params)
                                         ? a->vopt.elastic.solid * fs.params.n_tail / fs.params.n
                                         : 0.0;
            a->vopt.hold_elastic = 1;
        }
    }
    return rc;
}

/* The pool's task k: job k of the array ctx. */
static void run_job_k(void *ctx, int k)
{
    run_job(&((fit_job *)ctx)[k]);
}

/* What one job prints: its error, or the fit file on standard output (-o -), its report, where
** its files went, and its warnings. Returns its exit status. */
static int report_job(const fit_args *a, fit_job *j)
{
    if (j->st != CF_OK)
        return cf_cli_fail(&j->err);
    int rc = CF_EXIT_OK;
    if (cf_cli_is_stdio(a->out)) {
        char *json = cf_report_json_string(&j->rep);
        if (!json || fputs(json, stdout) < 0 || fflush(stdout) != 0) {
            cf_error e = {0};
            cf_error_set(&e, json ? CF_E_CANTWRITE : CF_E_INTERNAL,
                         "cannot write the fit file to standard output");
            rc = cf_cli_fail(&e);
        }
        free(json);
    }
    if (j->text) {
        cf_cli_write_safe(stdout, j->text);
        if (j->json_path[0])
            cf_cli_printf_safe(stdout, "Fit file: %s\n", j->json_path);
        if (j->plot_path[0])
            cf_cli_printf_safe(stdout, "Plot: %s\n", j->plot_path);
        if (a->nfiles > 1)
            fputc('\n', stdout);
    }
    report_warnings(j->file, &j->rep);
    if (j->m.t && j->vrep.fit.evaluation_bound_reached)
        cf_cli_printf_safe(stderr,
                           "conifit: warning: %s: the time-series fit stopped after %ld model "
                           "runs, at its bound of %ld (--max-evaluations), with candidates or "
                           "starts left unfitted: the model kept is the best of those fitted\n",
                           j->file, j->vrep.fit.evaluations,
                           a->vopt.max_evaluations > 0 ? a->vopt.max_evaluations
                                                       : CF_VISCO_EVAL_MAX);
    for (int k = 0; k < j->rep.nfits; k++) {
        fit_warnings(j->file, &j->rep, &j->rep.fits[k]);
        const cf_validation *v = &j->rep.val[k];
        if (j->rep.validate && v->done && v->unstable_in_range)
            cf_cli_printf_safe(stderr,
                    "conifit: warning: %s: the %s spring's %s loses stability at strain "
                    "%.4g (%s), inside the table's range\n",
                    j->file, cf_spring_type_name(j->rep.fits[k].type),
                    v->by_cell ? "cell" : "lattice", v->stable_to_strain, cf_mode_name(v->mode));
        const cf_through_msm *t = &j->rep.thr[k];
        if (j->rep.through_msm && t->done && t->search_rows < j->rep.table->count)
            cf_cli_printf_safe(stderr,
                    "conifit: note: %s: the %s fit through the lattice searched on a %zu-row "
                    "subsample of the %zu rows (tables above %d rows; the stress scale, the "
                    "placement and the RMSE on every row)\n",
                    j->file, cf_spring_type_name(j->rep.fits[k].type), t->search_rows,
                    j->rep.table->count, CF_LATTICE_FIT_FULL_ROWS);
    }
    return rc;
}

/* One row of the summary of several tables. */
static void summary_row(const fit_args *a, const fit_job *j, int wname)
{
    if (j->st != CF_OK) {
        cf_cli_printf_safe(stdout, "  %-*s failed\n", wname, j->file);
        return;
    }
    if (j->m.t) {
        cf_cli_printf_safe(stdout, "  %-*s time series: %d Prony term%s, RMSE %.4g %s\n", wname, j->file,
               j->vrep.fit.p.nbranch, j->vrep.fit.p.nbranch == 1 ? "" : "s",
               j->vrep.fit.rmse * j->m.y_to_file, j->m.y_unit);
        return;
    }
    char cell[2][32] = {"-", "-"};
    for (int k = 0; k < j->rep.nfits; k++)
        snprintf(cell[j->rep.fits[k].type], sizeof cell[0], "%.4g %s%s",
                 j->rep.fits[k].rmse * j->m.y_to_file, j->m.y_unit,
                 j->rep.fits[k].feasible ? "" : " (!)");
    int bb = CF_BASE_LINEAR; /* always fitted; a baseline not fitted has no RMSE to compare */
    for (int k = 0; k < CF_BASE_COUNT; k++)
        if (j->rep.baselines[k].fitted && j->rep.baselines[k].rmse < j->rep.baselines[bb].rmse)
            bb = k;
    char bcell[48];
    snprintf(bcell, sizeof bcell, "%s %.4g %s", cf_baseline_name((cf_baseline_kind)bb),
             j->rep.baselines[bb].rmse * j->m.y_to_file, j->m.y_unit);
    int b = cf_report_better(&j->rep);
    char vcell[48] = "";
    if (a->popt.validate && b >= 0 && j->rep.val[b].done)
        snprintf(vcell, sizeof vcell, " %.4g %s", j->rep.val[b].rmse * j->m.y_to_file,
                 j->m.y_unit);
    else if (a->popt.validate)
        snprintf(vcell, sizeof vcell, " skipped");
    cf_cli_printf_safe(stdout, "  %-*s %-18s %-18s %-22s %-16s%s\n", wname, j->file, cell[0], cell[1], bcell,
           b < 0                          ? "none feasible"
           : cf_report_types_tie(&j->rep) ? "tie"
                                          : cf_spring_type_name(j->rep.fits[b].type),
           vcell);
}

/* The summary of several tables: one row each. */
static void print_summary(const fit_args *a, const fit_job *jobs)
{
    int wname = 5;
    for (int i = 0; i < a->nfiles; i++)
        if ((int)strlen(jobs[i].file) > wname)
            wname = (int)strlen(jobs[i].file);
    printf("Summary (RMSE in each table's unit):\n");
    printf("  %-*s %-18s %-18s %-22s %-16s%s\n", wname, "table", "telescoping", "non-telescoping",
           "best baseline", "better type", a->popt.validate ? " lattice RMSE (better type)" : "");
    for (int i = 0; i < a->nfiles; i++)
        summary_row(a, &jobs[i], wname);
}

/* Fits the jobs (each puts its outputs in place when it succeeds), prints each report and the
** summary. Returns the exit status: the first failure's, else 0. */
static int fit_all(const fit_args *a, fit_job *jobs)
{
    cf_pool_run(a->nfiles, a->jobs, run_job_k, jobs);
    int rc = CF_EXIT_OK, failed = 0;
    for (int i = 0; i < a->nfiles; i++)
        failed += jobs[i].st != CF_OK;
    for (int i = 0; i < a->nfiles; i++) {
        const int e = report_job(a, &jobs[i]);
        if (jobs[i].st != CF_OK) /* the first failed table's status stands */
            rc = rc == CF_EXIT_OK ? e : rc;
        else if (e != CF_EXIT_OK) /* a fit file that standard output refused */
            rc = e;
    }
    if (failed && a->nfiles > 1 && (a->out || a->plot))
        cf_cli_printf_safe(stderr, "conifit: %d of %d tables failed and have no output file; "
                           "the others' are written\n", failed, a->nfiles);
    if (a->nfiles > 1 && !a->quiet)
        print_summary(a, jobs);
    return rc;
}

/* fit: parse, name every output, read every input, then fit them all (fit_all) or jointly
** (run_joint). */
int cf_cli_fit(int argc, char **argv)
{
    fit_args a;
    cf_shard sh;
    int rc = cf_cli_shard_take(&argc, argv, &sh);
    if (rc < 0)
        rc = cf_cli_fit_parse(argc, argv, &a);
    if (rc < 0 && sh.given)
        rc = a.joint ? cf_cli_usage_error("fit", "--shard fits tables one by one, not --joint")
                     : cf_cli_shard_select(&sh, a.out, a.options ? a.options : "-", &a.files,
                                           &a.nfiles);
    if (rc >= 0) {
        cf_cli_shard_free(&sh);
        free(a.options);
        return rc;
    }
    if (sh.given)
        a.popt.with_timing = 0; /* fit files that depend on the table alone */
    fit_job *jobs = calloc((size_t)a.nfiles + 1, sizeof *jobs);
    /* every input of the run, never to be an output */
    const char **inputs = calloc((size_t)a.nfiles + 4, sizeof *inputs);
    if (!jobs || !inputs) {
        free(jobs);
        free(inputs);
        fprintf(stderr, "conifit: out of memory\n");
        return CF_EXIT_SOFTWARE;
    }
    for (int i = 0; i < a.nfiles; i++)
        inputs[i] = a.files[i];
    /* the scene, the fit file it names, the elastic fit (the list ends at the first absent) */
    char scene_fit[4096];
    size_t n = (size_t)a.nfiles;
    if (a.scene) {
        inputs[n++] = a.scene;
        cf_cli_scene_fit(a.scene, scene_fit, sizeof scene_fit);
        if (scene_fit[0])
            inputs[n++] = scene_fit;
    }
    inputs[n] = a.elastic;
    if (!a.joint)
        rc = plan_outputs(&a, jobs, inputs);
    for (int i = 0; i < a.nfiles; i++)
        jobs[i].shard = sh.given ? &sh : NULL;
    int nseries = 0;
    if (rc < 0 && a.nfiles == 0) /* a shard with nothing (left) to fit: its summary only */
        rc = CF_EXIT_OK;
    if (rc < 0)
        rc = load_inputs(&a, jobs, &nseries);
    for (int i = 0; i < a.nfiles && rc < 0 && a.joint; i++)
        if (jobs[i].st != CF_OK) /* one lattice for every table: each must be read */
            rc = cf_cli_fail(&jobs[i].err);
    if (a.progress)
        a.popt.progress = show_progress;
    if (rc < 0 && a.joint)
        rc = nseries ? cf_cli_usage_error("fit", "--joint fits stress-strain tables; a time "
                                                 "series is fitted on its own")
                     : run_joint(&a, jobs, inputs);
    int fitted = rc < 0;
    if (rc < 0)
        rc = fit_all(&a, jobs);
    if (sh.given && (fitted || rc == CF_EXIT_OK)) {
        /* a failed table is a row of the summary, written all the same */
        for (int i = 0; i < a.nfiles; i++)
            if (jobs[i].st != CF_OK)
                cf_cli_shard_failed(&sh, jobs[i].file, jobs[i].err.msg);
        const int src = cf_cli_shard_summary(&sh, a.out);
        rc = rc == CF_EXIT_OK ? src : rc;
    }
    for (int i = 0; i < a.nfiles; i++) {
        cf_table_free(&jobs[i].m);
        free(jobs[i].text);
        cf_report_free(&jobs[i].rep);
        cf_visco_report_free(&jobs[i].vrep);
    }
    free(jobs);
    free(inputs);
    if (sh.given)
        free((void *)a.files); /* the shard's list, cf_cli_shard_select's */
    cf_cli_shard_free(&sh);
    free(a.options);
    return rc;
}
