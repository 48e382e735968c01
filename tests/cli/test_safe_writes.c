/*
** Writes that leave nothing wrong behind, through the program: targets that are not regular files
** are refused and left as they were; a standard output that cannot be written is exit 73 with a
** message; a failed plot replaces nothing; a batch writes each finished table and nothing of a
** failed one; two outputs of one run never share a name; a run stopped by SIGTERM removes its temporaries, and those of a run killed
** outright are hidden and swept by the next run.
*/
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>

#include "testutil.h"

static char out[1 << 16], errb[1 << 14];
TU_SCRATCH_GROUP("writes")

static const char spring[] = "--D1 8 --D2 20 --n 2.5 --d 2 --G 100 --H 5";

static void path_of(char *p, size_t cap, const char *name)
{
    snprintf(p, cap, "%s/%s", dir, name);
}

static void write_text(const char *name, const char *text)
{
    char p[512];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static const char *read_text(const char *name)
{
    static char buf[1 << 16];
    char p[512];
    path_of(p, sizeof p, name);
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static int exists(const char *name)
{
    char p[512];
    struct stat s;
    path_of(p, sizeof p, name);
    return lstat(p, &s) == 0;
}

/* Number of conifit temporaries (".NAME.conifit-TAG-PID-XXXXXX") in the folder. */
static int temporaries(void)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (e->d_name[0] == '.' && strstr(e->d_name, ".conifit-"))
            n++;
    closedir(d);
    return n;
}

/* A symbolic link, a FIFO and a character device given as the output of each writing command:
** refused with 73 (no hang on the FIFO), each left exactly as it was. */
static void non_regular_targets_are_refused(void **state)
{
    (void)state;
    char p[512], q[512];
    write_text("target.txt", "keep me\n");
    path_of(p, sizeof p, "link.json");
    assert_int_equal(symlink("target.txt", p), 0);
    path_of(p, sizeof p, "fifo.json");
    assert_int_equal(mkfifo(p, 0644), 0);
    const char *targets[] = {"link.json", "fifo.json", "/dev/null"};
    for (size_t t = 0; t < 3; t++) {
        if (targets[t][0] == '/')
            snprintf(q, sizeof q, "%s", targets[t]);
        else
            path_of(q, sizeof q, targets[t]);
        const char *cmds[] = {
            "fit data/telescoping.csv --quiet -o %s",
            "fit data/telescoping.csv --quiet --plot %s.png",
            "simulate data/scenes/uniaxial.json -o %s",
            "synth --D1 8 --D2 20 --n 2.5 --d 2 --G 100 --H 5 -o %s",
            "export fits/telescoping.json --format json -o %s",
        };
        for (size_t c = 0; c < sizeof cmds / sizeof cmds[0]; c++) {
            if (strstr(cmds[c], "%s.png") && t == 2)
                continue; /* no device with a .png name */
            char args[1024];
            snprintf(args, sizeof args, cmds[c], q);
            if (strstr(cmds[c], "%s.png")) {
                /* the plot target: a link named *.png */
                char l[512];
                path_of(l, sizeof l, t == 0 ? "link.json.png" : "fifo.json.png");
                if (t == 0)
                    symlink("target.txt", l);
                else
                    mkfifo(l, 0644);
            }
            int st = tu_run(out, sizeof out, errb, sizeof errb, "%s", args);
            if (st != 73)
                fail_msg("%s: exit %d, expected 73 (%s)", args, st, errb);
            assert_non_null(strstr(errb, "regular file"));
        }
    }
    struct stat s;
    path_of(p, sizeof p, "link.json");
    assert_int_equal(lstat(p, &s), 0);
    assert_true(S_ISLNK(s.st_mode));
    path_of(p, sizeof p, "fifo.json");
    assert_int_equal(lstat(p, &s), 0);
    assert_true(S_ISFIFO(s.st_mode));
    assert_int_equal(stat("/dev/null", &s), 0);
    assert_true(S_ISCHR(s.st_mode));
    assert_string_equal(read_text("target.txt"), "keep me\n");
    assert_int_equal(temporaries(), 0);
}

/* Every command whose standard output is a full disk ends with 73 and says so. */
static void stdout_errors_are_exit_73(void **state)
{
    (void)state;
    struct stat s;
    if (stat("/dev/full", &s) != 0)
        skip();
    char args[2][256];
    snprintf(args[0], sizeof args[0], "force %s --u 1", spring);
    snprintf(args[1], sizeof args[1], "info %s", spring);
    char curve[256];
    snprintf(curve, sizeof curve, "curve %s", spring);
    char sim[512];
    snprintf(sim, sizeof sim, "simulate data/scenes/uniaxial.json -o %s/sim.csv", dir);
    const char *cmds[] = {args[0],  args[1],     curve,       "fit data/telescoping.csv",
                          sim,      "--help",    "--version", "fit --help",
                          "simulate --help", "export fits/telescoping.json --format json"};
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
        char cmd[1024];
        snprintf(cmd, sizeof cmd, "%s %s >/dev/full 2>%s/err", tu_conifit(), cmds[i], dir);
        int st = system(cmd);
        st = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
        if (st != 73)
            fail_msg("'conifit %s' into a full disk: exit %d, expected 73", cmds[i], st);
        if (!strstr(read_text("err"), "standard output"))
            fail_msg("'conifit %s': no message about standard output: %s", cmds[i],
                     read_text("err"));
    }
}

/* A plot that fails replaces nothing: the existing fit file keeps its content, no plot, no
** temporary. */
static void failed_plot_replaces_nothing(void **state)
{
    (void)state;
    write_text("keep.json", "{\"old\": true}\n");
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=/bin/false %s fit data/telescoping.csv -o %s/keep.json --plot "
             "%s/p.png --quiet 2>/dev/null",
             tu_conifit(), dir, dir);
    int st = system(cmd);
    assert_int_equal(WEXITSTATUS(st), 70);
    assert_string_equal(read_text("keep.json"), "{\"old\": true}\n");
    assert_false(exists("p.png"));
    assert_int_equal(temporaries(), 0);
    /* the same for simulate: neither the CSV nor the plot */
    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=/bin/false %s simulate data/scenes/uniaxial.json -o %s/keep.json "
             "--plot %s/p.png >/dev/null 2>&1",
             tu_conifit(), dir, dir);
    st = system(cmd);
    assert_int_equal(WEXITSTATUS(st), 70);
    assert_string_equal(read_text("keep.json"), "{\"old\": true}\n");
    assert_false(exists("p.png"));
    assert_int_equal(temporaries(), 0);
    char keep[512];
    path_of(keep, sizeof keep, "keep.json");
    remove(keep);
}

/* A batch writes each table's files as soon as that table is done, and none of a table that
** failed: a bad table fails alone (exit 65, the good table's files written); a table whose plot
** fails (gnuplot missing) has neither its plot nor its fit file. Two tables with one base name are
** refused before anything runs. */
static void batches_write_each_finished_table(void **state)
{
    (void)state;
    char sub[512];
    path_of(sub, sizeof sub, "out");
    assert_int_equal(mkdir(sub, 0755), 0);
    write_text("bad.csv", "strain,stress_kPa\n0,0\n0.1,x\n");
    int st = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit data/telescoping.csv %s/bad.csv -o %s/out/ --plot %s/out/", dir, dir, dir);
    assert_int_equal(st, 65);
    assert_non_null(strstr(errb, "bad.csv:3"));
    assert_non_null(strstr(errb, "1 of 2 tables failed"));
    assert_true(exists("out/telescoping.json"));
    assert_true(exists("out/telescoping.png"));
    assert_false(exists("out/bad.json"));
    assert_false(exists("out/bad.png"));
    assert_int_equal(temporaries(), 0);
    char rm[600];
    snprintf(rm, sizeof rm, "rm -f %s/out/*", dir);
    assert_int_equal(system(rm), 0);
    /* every table fits, but plotting fails: neither file of a table is written */
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=/bin/false %s fit data/telescoping.csv data/non_telescoping.csv "
             "-o %s/out/ --plot %s/out/ -j 2 --quiet 2>%s/err",
             tu_conifit(), dir, dir, dir);
    st = system(cmd);
    assert_int_equal(WEXITSTATUS(st), 70);
    assert_non_null(strstr(read_text("err"), "2 of 2 tables failed"));
    assert_false(exists("out/telescoping.json"));
    assert_false(exists("out/non_telescoping.json"));
    assert_int_equal(temporaries(), 0);
    /* duplicate base names */
    char sub2[512];
    path_of(sub2, sizeof sub2, "other");
    assert_int_equal(mkdir(sub2, 0755), 0);
    snprintf(cmd, sizeof cmd, "cp data/telescoping.csv %s/other/telescoping.csv", dir);
    assert_int_equal(system(cmd), 0);
    st = tu_run(out, sizeof out, errb, sizeof errb,
                "fit data/telescoping.csv %s/other/telescoping.csv -o %s/out/ --quiet", dir, dir);
    assert_int_equal(st, 2);
    assert_non_null(strstr(errb, "both be written"));
    assert_false(exists("out/telescoping.json"));
    /* one name for two outputs of one table */
    st = tu_run(out, sizeof out, errb, sizeof errb,
                "simulate data/scenes/uniaxial.json -o %s/x.png --plot %s/x.png", dir, dir);
    assert_int_equal(st, 2);
    assert_false(exists("x.png"));
    assert_int_equal(temporaries(), 0);
}

/* A stand-in gnuplot signals conifit while its outputs exist only as temporaries. SIGTERM: the
** temporaries are removed and nothing is written. SIGKILL: they stay, hidden, and the next run
** in the folder sweeps them. */
static void signals_leave_nothing_visible(void **state)
{
    (void)state;
    write_text("term.sh", "#!/bin/sh\nkill -TERM $PPID\nsleep 2\nexit 1\n");
    write_text("kill.sh", "#!/bin/sh\nkill -KILL $PPID\nexit 1\n");
    char p[512];
    path_of(p, sizeof p, "term.sh");
    assert_int_equal(chmod(p, 0755), 0);
    path_of(p, sizeof p, "kill.sh");
    assert_int_equal(chmod(p, 0755), 0);
    char sub[512];
    path_of(sub, sizeof sub, "sig");
    assert_int_equal(mkdir(sub, 0755), 0);
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=%s/term.sh %s fit data/telescoping.csv -o %s/sig/a.json --plot "
             "%s/sig/a.png --quiet 2>/dev/null",
             dir, tu_conifit(), dir, dir);
    int st = system(cmd);
    /* the shell reports a child killed by SIGTERM as 128 + 15 */
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 128 + SIGTERM);
    DIR *d = opendir(sub);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        n += e->d_name[0] != '.' || strstr(e->d_name, ".conifit-") != NULL;
    closedir(d);
    assert_int_equal(n, 0); /* no temporary, no output */

    snprintf(cmd, sizeof cmd,
             "CONIFIT_GNUPLOT=%s/kill.sh %s fit data/telescoping.csv -o %s/sig/a.json --plot "
             "%s/sig/a.png --quiet 2>/dev/null",
             dir, tu_conifit(), dir, dir);
    st = system(cmd);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 128 + SIGKILL);
    int hidden = 0, visible = 0;
    d = opendir(sub);
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (e->d_name[0] == '.' && strstr(e->d_name, ".conifit-"))
            hidden++;
        else
            visible++;
    }
    closedir(d);
    assert_int_equal(visible, 0);
    assert_true(hidden >= 1); /* the fit file's temporary at least */
    /* the next run into the folder sweeps them */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv -o %s/sig/b.json --quiet", dir),
                     0);
    d = opendir(sub);
    n = 0;
    while ((e = readdir(d)) != NULL)
        n += e->d_name[0] == '.' && strstr(e->d_name, ".conifit-") != NULL;
    closedir(d);
    assert_int_equal(n, 0);
}

/* The fit file a scene names is an input of every run that reads the scene: `export --lattice
** SCENE -o` and `fit --validate SCENE -o` naming it are refused with 73 and leave it as it was. */
static void a_scenes_fit_file_is_never_an_output(void **state)
{
    (void)state;
    char *fit = tu_slurp("fits/telescoping.json");
    assert_non_null(fit);
    write_text("own.json", fit);
    free(fit);
    char scene[600];
    snprintf(scene, sizeof scene,
             "{\"spring\": {\"fit\": \"%s/own.json\"},\n"
             " \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, \"calibration\": \"isotropic\"},\n"
             " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.2, \"duration_s\": 1},\n"
             " \"samples_per_segment\": 4}\n",
             dir);
    write_text("scene.json", scene);
    const char *before = read_text("own.json");
    char keep[1 << 16];
    snprintf(keep, sizeof keep, "%s", before);
    /* the scene is good: the same runs with another output succeed */
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "export fits/telescoping.json --lattice %s/scene.json --format "
                            "calculix -o %s/lat.inp --quiet",
                            dir, dir),
                     0);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "export fits/telescoping.json --lattice %s/scene.json --format "
                            "calculix -o %s/own.json --quiet",
                            dir, dir),
                     73);
    assert_non_null(strstr(errb, "input"));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit data/telescoping.csv --validate %s/scene.json -o %s/own.json "
                            "--quiet",
                            dir, dir),
                     73);
    assert_non_null(strstr(errb, "input"));
    assert_string_equal(read_text("own.json"), keep);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(non_regular_targets_are_refused),
        cmocka_unit_test(stdout_errors_are_exit_73),
        cmocka_unit_test(failed_plot_replaces_nothing),
        cmocka_unit_test(batches_write_each_finished_table),
        cmocka_unit_test(signals_leave_nothing_visible),
        cmocka_unit_test(a_scenes_fit_file_is_never_an_output),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
