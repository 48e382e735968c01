/*
** Atomic output files (see atomic.h).
*/
#define _GNU_SOURCE /* mkostemp, O_CLOEXEC */
#include "base/atomic.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The temporaries this process has open: copies of their names, so that a signal handler can
** remove them. A full list only means that a temporary is not removed on a signal (it is still
** hidden, and swept later). */
#define LIVE_MAX 4096
static char *_Atomic live[LIVE_MAX];
static pthread_mutex_t live_lock = PTHREAD_MUTEX_INITIALIZER;

static int live_add(const char *name)
{
    char *copy = strdup(name);
    if (!copy)
        return 0;
    pthread_mutex_lock(&live_lock);
    for (int i = 0; i < LIVE_MAX; i++)
        if (atomic_load(&live[i]) == NULL) {
            atomic_store(&live[i], copy);
            pthread_mutex_unlock(&live_lock);
            return i + 1;
        }
    pthread_mutex_unlock(&live_lock);
    free(copy);
    return 0;
}

static void live_remove(int slot)
{
    if (slot <= 0 || slot > LIVE_MAX)
        return;
    free(atomic_exchange(&live[slot - 1], NULL));
}

void cf_atomic_remove_temporaries(void)
{
    for (int i = 0; i < LIVE_MAX; i++) {
        char *name = atomic_load(&live[i]);
        if (name)
            unlink(name);
    }
}

int cf_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

static const char *kind_of(mode_t m)
{
    return S_ISLNK(m)    ? "a symbolic link"
           : S_ISFIFO(m) ? "a FIFO"
           : S_ISCHR(m)  ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISSOCK(m) ? "a socket"
           : S_ISDIR(m)  ? "a folder"
                         : "not a regular file";
}

/* CF_OK when nothing is at path or a regular file is. */
static cf_status regular_or_absent(const char *path, cf_error *err)
{
    struct stat s;
    if (lstat(path, &s) != 0) {
        if (errno == ENOENT)
            return CF_OK;
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: %s", path,
                            strerror(errno));
    }
    if (!S_ISREG(s.st_mode))
        return cf_error_set(err, CF_E_CANTWRITE,
                            "%s: is %s; conifit writes only regular files and will not replace "
                            "it",
                            path, kind_of(s.st_mode));
    return CF_OK;
}

/* The folder of path ("." when it has none) into dir; the base name's offset in path. */
static size_t split_dir(const char *path, char *dir, size_t cap)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(dir, cap, ".");
        return 0;
    }
    size_t n = (size_t)(slash - path);
    snprintf(dir, cap, "%.*s", (int)(n ? n : 1), n ? path : "/");
    return n + 1;
}

cf_status cf_atomic_check(const char *path, const char *const *inputs, cf_error *err)
{
    if (!path || !*path)
        return cf_error_set(err, CF_E_CANTWRITE, "empty output file name");
    if (strlen(path) >= sizeof ((cf_atomic *)0)->path)
        return cf_error_set(err, CF_E_CANTWRITE, "%.200s...: output path too long", path);
    size_t plen = strlen(path);
    if (path[plen - 1] == '/')
        return cf_error_set(err, CF_E_CANTWRITE, "%s: names a folder, not a file", path);
    for (size_t i = 0; inputs && inputs[i]; i++)
        if (strcmp(path, inputs[i]) == 0 || cf_same_file(path, inputs[i]))
            return cf_error_set(err, CF_E_CANTWRITE,
                                "%s: refusing to overwrite an input file with output", path);
    cf_status st = regular_or_absent(path, err);
    if (st != CF_OK)
        return st;
    char dir[4096];
    split_dir(path, dir, sizeof dir);
    struct stat s;
    if (stat(dir, &s) != 0 || !S_ISDIR(s.st_mode))
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: folder %s %s",
                            path, dir, errno == ENOENT ? "does not exist" : "is not a folder");
    return CF_OK;
}

/* Is name ".ANYTHING.conifit-PID-XXXXXX"? Then *pid is its PID. */
static int temporary_name(const char *name, long *pid)
{
    if (name[0] != '.')
        return 0;
    const char *tag = NULL;
    for (const char *p = strstr(name, ".conifit-"); p; p = strstr(p + 1, ".conifit-"))
        tag = p;
    if (!tag || tag == name)
        return 0;
    char *end;
    errno = 0;
    long v = strtol(tag + 9, &end, 10);
    if (errno || end == tag + 9 || v <= 0 || *end != '-' || strlen(end + 1) != 6)
        return 0;
    *pid = v;
    return 1;
}

/* Removes the temporaries that processes no longer alive left in dir (killed before they could
** clean up). */
static void sweep(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    long self = (long)getpid();
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        long pid;
        if (!temporary_name(e->d_name, &pid) || pid == self)
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* alive (or not ours to judge) */
        struct stat s;
        if (fstatat(dirfd(d), e->d_name, &s, AT_SYMLINK_NOFOLLOW) == 0 && S_ISREG(s.st_mode))
            unlinkat(dirfd(d), e->d_name, 0);
    }
    closedir(d);
}

cf_status cf_atomic_open(cf_atomic *a, const char *path, const char *const *inputs, cf_error *err)
{
    memset(a, 0, sizeof *a);
    cf_status st = cf_atomic_check(path, inputs, err);
    if (st != CF_OK)
        return st;
    snprintf(a->path, sizeof a->path, "%s", path);
    char dir[4096];
    size_t base = split_dir(path, dir, sizeof dir);
    sweep(dir);
    /* the base name is shortened so that the temporary name stays within NAME_MAX */
    snprintf(a->tmp, sizeof a->tmp, "%.*s.%.200s.conifit-%ld-XXXXXX", (int)base, path,
             path + base, (long)getpid());
    int fd = mkostemp(a->tmp, O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        a->tmp[0] = '\0';
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot create output file: %s", path,
                            strerror(e));
    }
    a->slot = live_add(a->tmp);
    /* an ordinary file's mode (not mkstemp's private one), or the mode of the file it replaces */
    struct stat s;
    fchmod(fd, stat(path, &s) == 0 ? (s.st_mode & 07777) : 0644);
    a->fp = fdopen(fd, "wb");
    if (!a->fp) {
        int e = errno;
        close(fd);
        cf_atomic_abort(a);
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot open output file: %s", path,
                            strerror(e));
    }
    return CF_OK;
}

cf_status cf_atomic_finish(cf_atomic *a, cf_error *err)
{
    if (!a->fp)
        return a->tmp[0] ? CF_OK
                         : cf_error_set(err, CF_E_CANTWRITE, "%s: output file not open", a->path);
    int bad = ferror(a->fp);
    int saved = bad ? EIO : 0;
    if (fflush(a->fp) != 0 && !bad) {
        bad = 1;
        saved = errno;
    }
    if (fclose(a->fp) != 0 && !bad) {
        bad = 1;
        saved = errno;
    }
    a->fp = NULL;
    if (bad) {
        cf_atomic_abort(a);
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: %s", a->path,
                            strerror(saved));
    }
    return CF_OK;
}

cf_status cf_atomic_commit(cf_atomic *a, cf_error *err)
{
    cf_status st = cf_atomic_finish(a, err);
    if (st != CF_OK)
        return st;
    if ((st = regular_or_absent(a->path, err)) != CF_OK) {
        cf_atomic_abort(a);
        return st;
    }
    if (rename(a->tmp, a->path) != 0) {
        int e = errno;
        cf_atomic_abort(a);
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: %s", a->path,
                            strerror(e));
    }
    a->tmp[0] = '\0';
    live_remove(a->slot);
    a->slot = 0;
    return CF_OK;
}

void cf_atomic_abort(cf_atomic *a)
{
    if (a->fp)
        fclose(a->fp);
    a->fp = NULL;
    if (a->tmp[0])
        unlink(a->tmp);
    a->tmp[0] = '\0';
    live_remove(a->slot);
    a->slot = 0;
}
