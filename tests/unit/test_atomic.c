/*
** Tests of the atomic output files (src/base/atomic.c): the permissions of what they write (the
** umask for a new file, no special bits on a replaced one), write-protected targets refused and
** left alone, the sweep of dead runs' temporaries, which judges only temporaries of its own
** PID space and reads a folder once for many files, and the removal on a signal of every
** temporary open, however many (more than the 4096 an earlier fixed list held).
*/
#include "testutil.h"

#include <dirent.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "base/atomic.h"

/* Writes text to path through cf_atomic; the status of the commit (or of the open). */
static cf_status write_atomic(const char *path, const char *text, cf_error *err)
{
    cf_atomic a;
    cf_status st = cf_atomic_open(&a, path, NULL, err);
    if (st != CF_OK)
        return st;
    fputs(text, a.fp);
    return cf_atomic_commit(&a, err);
}

static mode_t mode_of(const char *path)
{
    struct stat s;
    assert_int_equal(stat(path, &s), 0);
    return s.st_mode & 07777;
}

static void new_file_has_the_umask_permissions(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-atomic-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    const mode_t masks[] = {027, 077, 0};
    for (size_t k = 0; k < sizeof masks / sizeof masks[0]; k++) {
        snprintf(path, sizeof path, "%s/new%zu.csv", dir, k);
        mode_t old = umask(masks[k]);
        cf_error err = {0};
        cf_status st = write_atomic(path, "x\n", &err);
        umask(old);
        assert_int_equal(st, CF_OK);
        assert_int_equal(mode_of(path), 0666 & ~masks[k]);
        unlink(path);
    }
    rmdir(dir);
}

static void replaced_file_keeps_its_permissions_without_special_bits(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-atomic-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/old.csv", dir);
    cf_error err = {0};
    assert_int_equal(write_atomic(path, "old\n", &err), CF_OK);
    assert_int_equal(chmod(path, 06751), 0);
    assert_int_equal(mode_of(path), 06751);
    assert_int_equal(write_atomic(path, "new\n", &err), CF_OK);
    assert_int_equal(mode_of(path), 0751);
    char *text = tu_slurp(path);
    assert_string_equal(text, "new\n");
    free(text);
    unlink(path);
    rmdir(dir);
}

static void write_protected_target_is_refused_and_kept(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-atomic-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/kept.csv", dir);
    cf_error err = {0};
    assert_int_equal(write_atomic(path, "kept\n", &err), CF_OK);
    assert_int_equal(chmod(path, 0444), 0);
    assert_int_equal(write_atomic(path, "lost\n", &err), CF_E_CANTWRITE);
    assert_non_null(strstr(err.msg, "write-protected"));
    assert_non_null(strstr(err.msg, "kept.csv"));
    char *text = tu_slurp(path);
    assert_string_equal(text, "kept\n");
    free(text);
    /* nothing left behind: the folder holds the one file */
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    assert_int_equal(n, 1);
    unlink(path);
    rmdir(dir);
}

static int exists_in(const char *dir, const char *name)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return access(p, F_OK) == 0;
}

static void touch_in(const char *dir, const char *name)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fclose(f);
}

static void sweep_removes_only_dead_temporaries_of_its_own_pid_space(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-atomic-XXXXXX", other[] = "/tmp/conifit-atomic-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    assert_non_null(mkdtemp(other));
    /* this run's tag, from the name of one of its temporaries (in another folder: the first
    ** open in dir must be the one that sweeps it) */
    snprintf(path, sizeof path, "%s/probe.csv", other);
    cf_atomic a;
    cf_error err = {0};
    assert_int_equal(cf_atomic_open(&a, path, NULL, &err), CF_OK);
    const char *t = strstr(a.tmp, ".conifit-");
    assert_non_null(t);
    char tag[64];
    assert_int_equal(sscanf(t + 9, "%63[0-9a-f]", tag), 1);
    assert_int_equal(strlen(tag), 16);
    cf_atomic_abort(&a);
    assert_int_equal(rmdir(other), 0);
    /* a PID that was this PID space's and is dead now */
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0)
        _exit(0);
    assert_int_equal(waitpid(child, NULL, 0), child);
    char dead_mine[200], dead_other[200], dead_untagged[200], live_mine[200];
    snprintf(dead_mine, sizeof dead_mine, ".a.csv.conifit-%s-%ld-Ab12Cd", tag, (long)child);
    snprintf(dead_other, sizeof dead_other, ".b.csv.conifit-0123456789abcdef-%ld-Ab12Cd",
             (long)child);
    snprintf(dead_untagged, sizeof dead_untagged, ".c.csv.conifit-%ld-Ab12Cd", (long)child);
    snprintf(live_mine, sizeof live_mine, ".d.csv.conifit-%s-1-Ab12Cd", tag); /* init lives */
    const char *all[] = {dead_mine, dead_other, dead_untagged, live_mine};
    for (size_t k = 0; k < 4; k++)
        touch_in(dir, all[k]);
    snprintf(path, sizeof path, "%s/out.csv", dir);
    assert_int_equal(write_atomic(path, "x\n", &err), CF_OK); /* sweeps the folder */
    assert_false(exists_in(dir, dead_mine));
    assert_true(exists_in(dir, dead_other));    /* another container's or host's: maybe alive */
    assert_true(exists_in(dir, dead_untagged)); /* cannot be told: left alone */
    assert_true(exists_in(dir, live_mine));
    for (size_t k = 1; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, all[k]);
        unlink(path);
    }
    snprintf(path, sizeof path, "%s/out.csv", dir);
    unlink(path);
    assert_int_equal(rmdir(dir), 0);
}

/* A run writing many files into one folder (a body's VTU series) sweeps it once, not once per
** file: the sweep reads the whole folder, so n files would cost O(n^2). Another folder is swept
** on its own first open. */
static void a_folder_is_swept_once_for_many_files(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-atomic-XXXXXX", other[] = "/tmp/conifit-atomic-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    assert_non_null(mkdtemp(other));
    cf_error err = {0};
    const unsigned long before = cf_atomic_sweeps();
    for (int i = 0; i < 200; i++) {
        snprintf(path, sizeof path, "%s/body_%04d.vtu", dir, i);
        assert_int_equal(write_atomic(path, "<VTKFile/>\n", &err), CF_OK);
    }
    assert_int_equal(cf_atomic_sweeps() - before, 1);
    snprintf(path, sizeof path, "%s/body.pvd", other);
    assert_int_equal(write_atomic(path, "<VTKFile/>\n", &err), CF_OK);
    assert_int_equal(cf_atomic_sweeps() - before, 2);
    for (int i = 0; i < 200; i++) {
        snprintf(path, sizeof path, "%s/body_%04d.vtu", dir, i);
        assert_int_equal(unlink(path), 0);
    }
    snprintf(path, sizeof path, "%s/body.pvd", other);
    assert_int_equal(unlink(path), 0);
    assert_int_equal(rmdir(dir), 0);
    assert_int_equal(rmdir(other), 0);
}

/* Files in dir whose name starts with a dot (temporaries). */
static int hidden_in(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        n += e->d_name[0] == '.' && strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

/* 5000 temporaries open at once (finished, so no descriptor stays open), in 50 folders: the
** signal handler's cf_atomic_remove_temporaries removes every one; the entries are then reused,
** and an aborted handle frees its own. */
static void every_open_temporary_is_removed_on_a_signal(void **state)
{
    (void)state;
    enum { NDIR = 50, PER = 100 };
    char root[] = "/tmp/conifit-atomic-XXXXXX", dir[NDIR][320], path[400];
    assert_non_null(mkdtemp(root));
    static cf_atomic a[NDIR * PER];
    cf_error err = {0};
    for (int d = 0; d < NDIR; d++) {
        snprintf(dir[d], sizeof dir[d], "%s/d%02d", root, d);
        assert_int_equal(mkdir(dir[d], 0700), 0);
        for (int i = 0; i < PER; i++) {
            snprintf(path, sizeof path, "%.300s/f%03d.json", dir[d], i);
            assert_int_equal(cf_atomic_open(&a[d * PER + i], path, NULL, &err), CF_OK);
            fputs("{}\n", a[d * PER + i].fp);
            assert_int_equal(cf_atomic_finish(&a[d * PER + i], &err), CF_OK);
        }
    }
    int left = 0;
    for (int d = 0; d < NDIR; d++)
        left += hidden_in(dir[d]);
    assert_int_equal(left, NDIR * PER);
    cf_atomic_remove_temporaries();
    left = 0;
    for (int d = 0; d < NDIR; d++)
        left += hidden_in(dir[d]);
    assert_int_equal(left, 0);
    for (int k = 0; k < NDIR * PER; k++) {
        a[k].tmp[0] = '\0'; /* removed already */
        cf_atomic_abort(&a[k]);
    }
    /* the entries are free again: a new temporary is removed as well, a committed one is not */
    snprintf(path, sizeof path, "%.300s/again.json", dir[0]);
    cf_atomic b, c;
    assert_int_equal(cf_atomic_open(&b, path, NULL, &err), CF_OK);
    assert_int_equal(cf_atomic_finish(&b, &err), CF_OK);
    snprintf(path, sizeof path, "%.300s/kept.json", dir[0]);
    assert_int_equal(cf_atomic_open(&c, path, NULL, &err), CF_OK);
    assert_int_equal(cf_atomic_commit(&c, &err), CF_OK);
    assert_int_equal(b.slot, 1);
    cf_atomic_remove_temporaries();
    assert_int_equal(hidden_in(dir[0]), 0);
    assert_int_equal(access(path, F_OK), 0);
    b.tmp[0] = '\0';
    cf_atomic_abort(&b);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(new_file_has_the_umask_permissions),
        cmocka_unit_test(replaced_file_keeps_its_permissions_without_special_bits),
        cmocka_unit_test(write_protected_target_is_refused_and_kept),
        cmocka_unit_test(sweep_removes_only_dead_temporaries_of_its_own_pid_space),
        cmocka_unit_test(every_open_temporary_is_removed_on_a_signal),
        cmocka_unit_test(a_folder_is_swept_once_for_many_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
