/*
** Atomic output files (see atomic.h).
*/
#define _GNU_SOURCE /* O_CLOEXEC, O_NOFOLLOW */
#include "base/atomic.h"
#include "base/input.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The temporaries this process has open: copies of their names, so that a signal handler can
** remove them. A list of chunks of entries that only grows (a new chunk when every entry is in
** use) and whose entries are reused: it holds as many temporaries as are ever open at once, with
** no bound, and a handler can walk it at any moment (chunks are never freed or moved, and each
** entry's state is read atomically). An entry is FREE, CLAIMED (its name being written) or LIVE. */
enum { LIVE_FREE, LIVE_CLAIMED, LIVE_IN_USE };
#define LIVE_CHUNK 32
typedef struct live_chunk {
    struct live_chunk *_Atomic next;
    struct {
        atomic_int state;
        char name[sizeof ((cf_atomic *)0)->tmp];
    } entry[LIVE_CHUNK];
} live_chunk;
static live_chunk live_first;
static pthread_mutex_t live_grow = PTHREAD_MUTEX_INITIALIZER; /* appends a chunk */

/* Claims a free entry for name (a new chunk when none is free): 1 + its index, or 0 when memory
** ran out (the temporary is then not removed on a signal: still hidden, and swept later). */
static int live_add(const char *name)
{
    const size_t n = strlen(name);
    if (n >= sizeof live_first.entry[0].name)
        return 0;
    int index = 0;
    for (live_chunk *c = &live_first; c;) {
        for (int i = 0; i < LIVE_CHUNK; i++, index++) {
            int expect = LIVE_FREE;
            if (atomic_compare_exchange_strong(&c->entry[i].state, &expect, LIVE_CLAIMED)) {
                memcpy(c->entry[i].name, name, n + 1);
                atomic_store(&c->entry[i].state, LIVE_IN_USE);
                return index + 1;
            }
        }
        live_chunk *next = atomic_load(&c->next);
        if (!next) {
            pthread_mutex_lock(&live_grow);
            next = atomic_load(&c->next);
            if (!next && (next = calloc(1, sizeof *next)) != NULL)
                atomic_store(&c->next, next);
            pthread_mutex_unlock(&live_grow);
        }
        c = next;
    }
    return 0;
}

static void live_remove(int slot)
{
    if (slot <= 0)
        return;
    live_chunk *c = &live_first;
    for (int k = (slot - 1) / LIVE_CHUNK; k > 0 && c; k--)
        c = atomic_load(&c->next);
    if (c)
        atomic_store(&c->entry[(slot - 1) % LIVE_CHUNK].state, LIVE_FREE);
}

void cf_atomic_remove_temporaries(void)
{
    for (live_chunk *c = &live_first; c; c = atomic_load(&c->next))
        for (int i = 0; i < LIVE_CHUNK; i++)
            if (atomic_load(&c->entry[i].state) == LIVE_IN_USE)
                unlink(c->entry[i].name);
}

int cf_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
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
                            path, cf_file_kind(s.st_mode));
    if ((s.st_mode & 0222) == 0)
        return cf_error_set(err, CF_E_CANTWRITE,
                            "%s: is write-protected (mode %04o); conifit will not replace it",
                            path, (unsigned)(s.st_mode & 07777));
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

/* This machine's PID space, as 16 hex digits: a hash of the host name, the kernel's boot id and the
** PID namespace (device and inode of /proc/self/ns/pid). Two runs with the same tag see the same
** processes under the same PIDs, so one may judge whether the other is alive; a run in another
** container or on another host sharing the folder has another tag. Computed once. */
static char host_tag[17];
static pthread_once_t host_tag_once = PTHREAD_ONCE_INIT;

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 0x100000001b3ULL;
    return h;
}

static void host_tag_init(void)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    char buf[256] = {0};
    if (gethostname(buf, sizeof buf - 1) == 0)
        h = fnv1a(h, buf, strlen(buf));
    int fd = open("/proc/sys/kernel/random/boot_id", O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
        ssize_t n = read(fd, buf, sizeof buf);
        if (n > 0)
            h = fnv1a(h, buf, (size_t)n);
        close(fd);
    }
    struct stat s;
    if (stat("/proc/self/ns/pid", &s) == 0) {
        h = fnv1a(h, &s.st_dev, sizeof s.st_dev);
        h = fnv1a(h, &s.st_ino, sizeof s.st_ino);
    }
    snprintf(host_tag, sizeof host_tag, "%016llx", (unsigned long long)h);
}

static const char *tag_of_host(void)
{
    pthread_once(&host_tag_once, host_tag_init);
    return host_tag;
}

/* Is name ".ANYTHING.conifit-TAG-PID-XXXXXX" with this machine's TAG? Then *pid is its PID.
** Temporaries of other PID spaces (and of the older form without a tag) are never judged. */
static int temporary_name(const char *name, long *pid)
{
    if (name[0] != '.')
        return 0;
    const char *tag = NULL;
    for (const char *p = strstr(name, ".conifit-"); p; p = strstr(p + 1, ".conifit-"))
        tag = p;
    if (!tag || tag == name)
        return 0;
    const char *mine = tag_of_host();
    const size_t tl = strlen(mine);
    if (strncmp(tag + 9, mine, tl) != 0 || tag[9 + tl] != '-')
        return 0;
    const char *digits = tag + 9 + tl + 1;
    char *end;
    errno = 0;
    long v = strtol(digits, &end, 10);
    if (errno || end == digits || v <= 0 || *end != '-' || strlen(end + 1) != 6)
        return 0;
    *pid = v;
    return 1;
}

/* Removes the temporaries that processes of this PID space no longer alive left in dir (killed
** before they could clean up). */
static void sweep_now(const char *dir)
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

/* The folders swept lately (device, inode, a hash of the name given, when): a folder is swept on the first open in it and
** again only once SWEEP_AGAIN_S seconds have passed, so that a run writing n files into one
** folder (a body's VTU series: thousands of steps) reads the folder once, not n times (which cost
** O(n^2): a 6,000-step series spent 35-43 s there against 1.3 s of solving). A process living
** long (a program linked with the library) still sweeps a folder now and then. The name's hash
** keeps a folder removed and made again elsewhere, which may get the old one's inode, from
** passing for it (another spelling of one folder only sweeps it once more). The list is a
** small ring: a folder that falls out of it is swept again, which is only extra work. */
#define SWEPT_SLOTS 64
#define SWEEP_AGAIN_S 600.0
static struct {
    dev_t dev;
    ino_t ino;
    uint64_t name;
    double when;
} swept[SWEPT_SLOTS];
static size_t nswept, swept_next;
static unsigned long sweeps_done;
static pthread_mutex_t swept_lock = PTHREAD_MUTEX_INITIALIZER;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void sweep(const char *dir)
{
    struct stat s;
    if (stat(dir, &s) != 0)
        return;
    const double t = now_s();
    const uint64_t name = fnv1a(0xcbf29ce484222325ULL, dir, strlen(dir));
    pthread_mutex_lock(&swept_lock);
    size_t k = 0;
    while (k < nswept &&
           !(swept[k].dev == s.st_dev && swept[k].ino == s.st_ino && swept[k].name == name))
        k++;
    const int due = k == nswept || t - swept[k].when >= SWEEP_AGAIN_S;
    if (due) {
        if (k == nswept) { /* a new entry, or the oldest one's place */
            k = nswept < SWEPT_SLOTS ? nswept++ : swept_next;
            swept_next = (k + 1) % SWEPT_SLOTS;
        }
        swept[k].dev = s.st_dev;
        swept[k].ino = s.st_ino;
        swept[k].name = name;
        swept[k].when = t;
        sweeps_done++;
    }
    pthread_mutex_unlock(&swept_lock);
    if (due)
        sweep_now(dir);
}

unsigned long cf_atomic_sweeps(void)
{
    pthread_mutex_lock(&swept_lock);
    unsigned long n = sweeps_done;
    pthread_mutex_unlock(&swept_lock);
    return n;
}

/* Creates the file named by tmpl, whose last six characters are replaced by random letters and
** digits until the name is new, with mode 0666 less the umask (as any new file of the user's);
** the descriptor, or -1 with errno. */
static int create_temporary(char *tmpl)
{
    static const char letters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    const size_t n = strlen(tmpl);
    if (n < 6) {
        errno = EINVAL;
        return -1;
    }
    for (int attempt = 0; attempt < 100; attempt++) {
        unsigned char r[6];
        if (getrandom(r, sizeof r, 0) != (ssize_t)sizeof r)
            return -1;
        for (int i = 0; i < 6; i++)
            tmpl[n - 6 + i] = letters[r[i] % (sizeof letters - 1)];
        int fd = open(tmpl, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0666);
        if (fd >= 0 || errno != EEXIST)
            return fd;
    }
    errno = EEXIST;
    return -1;
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
    snprintf(a->tmp, sizeof a->tmp, "%.*s.%.200s.conifit-%s-%ld-XXXXXX", (int)base, path,
             path + base, tag_of_host(), (long)getpid());
    int fd = create_temporary(a->tmp);
    if (fd < 0) {
        int e = errno;
        a->tmp[0] = '\0';
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot create output file: %s", path,
                            strerror(e));
    }
    a->slot = live_add(a->tmp);
    /* a new file has the umask's permissions (create_temporary); one that replaces a file takes
    ** that file's permissions, without set-user-ID, set-group-ID or sticky bits */
    struct stat s;
    if (stat(path, &s) == 0)
        fchmod(fd, s.st_mode & 0777);
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
    if (!a)
        return;
    if (a->fp)
        fclose(a->fp);
    a->fp = NULL;
    if (a->tmp[0])
        unlink(a->tmp);
    a->tmp[0] = '\0';
    live_remove(a->slot);
    a->slot = 0;
}
