/*
** Work in a child process with a memory and a time limit (isolate.h).
*/
#include "io/isolate.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>

/* The child's last bytes: its status, its message and a mark that the work ended (a child that
** died after writing part of its result has no trailer). */
typedef struct trailer {
    int32_t status;
    char msg[CF_ERROR_MSG_LEN];
    char mark[8];
} trailer;

static const char end_mark[8] = "cf-done";

void cf_isolate_put(cf_isolate_buf *out, const void *p, size_t n)
{
    const unsigned char *c = p;
    while (n > 0 && !out->failed) {
        ssize_t w = write(out->fd, c, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            out->failed = 1;
            return;
        }
        c += w;
        n -= (size_t)w;
    }
}

int cf_isolate_get(cf_isolate_buf *in, void *p, size_t n)
{
    if (n > in->len - in->pos)
        return 0;
    memcpy(p, in->data + in->pos, n);
    in->pos += n;
    return 1;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The bytes the process maps now (its virtual size), 0 when unknown. */
static double mapped_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (!f)
        return 0;
    if (fscanf(f, "%lu", &pages) != 1)
        pages = 0;
    fclose(f);
    return (double)pages * (double)sysconf(_SC_PAGESIZE);
}

static double child_max_bytes; /* in the child: its memory limit, applied by the work */

void cf_isolate_limit_memory(void)
{
#if !defined(__SANITIZE_ADDRESS__) /* AddressSanitizer reserves terabytes of address space */
    if (child_max_bytes > 0 && child_max_bytes < 1e15) {
        struct rlimit r;
        r.rlim_cur = r.rlim_max = (rlim_t)(mapped_bytes() + child_max_bytes);
        setrlimit(RLIMIT_AS, &r);
    }
#else
    (void)mapped_bytes;
#endif
}

/* The child: limits, quiet, default signals; runs the work and writes its trailer. Never
** returns. */
static void child(int fd, pid_t parent, cf_isolate_fn fn, void *arg, double max_bytes,
                  double max_seconds)
{
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent)
        _exit(127);
    for (int s = 1; s < 32; s++)
        if (s != SIGKILL && s != SIGSTOP)
            signal(s, SIG_DFL);
    sigset_t all;
    sigemptyset(&all);
    sigprocmask(SIG_SETMASK, &all, NULL);
    /* no descriptor of the caller but the pipe: another thread's pipe held open here would keep
    ** its reader from seeing the end */
    long maxfd = sysconf(_SC_OPEN_MAX);
    for (long k = 3; k < (maxfd > 0 && maxfd < 65536 ? maxfd : 65536); k++)
        if (k != fd)
            close((int)k);
    int null = open("/dev/null", O_RDWR);
    if (null >= 0) {
        dup2(null, 0);
        dup2(null, 1);
        dup2(null, 2);
    }
    struct rlimit r = {0, 0};
    setrlimit(RLIMIT_CORE, &r);
    if (max_seconds > 0 && max_seconds < 1e7) {
        r.rlim_cur = r.rlim_max = (rlim_t)ceil(max_seconds) + 1;
        setrlimit(RLIMIT_CPU, &r);
    }
    child_max_bytes = max_bytes;
    cf_isolate_buf out = {.fd = fd};
    cf_error e = {0};
    trailer t;
    memset(&t, 0, sizeof t);
    t.status = fn(arg, &out, &e);
    memcpy(t.msg, e.msg, sizeof t.msg);
    memcpy(t.mark, end_mark, sizeof t.mark);
    cf_isolate_put(&out, &t, sizeof t);
    _exit(out.failed ? 3 : 0);
}

/* Reads the child's bytes until the pipe ends (1) or the deadline passes (0); -1 when memory
** runs out. */
static int read_all(int fd, double deadline, cf_isolate_buf *in)
{
    size_t cap = 0;
    for (;;) {
        const double left = deadline - now_s();
        if (left <= 0)
            return 0;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        int r = poll(&p, 1, (int)fmin(left * 1000 + 1, 60000));
        if (r < 0 && errno != EINTR)
            return 0;
        if (r <= 0)
            continue;
        if (in->len == cap) {
            size_t nc = cap ? 2 * cap : 65536;
            unsigned char *q = realloc(in->data, nc);
            if (!q)
                return -1;
            in->data = q;
            cap = nc;
        }
        ssize_t got = read(fd, in->data + in->len, cap - in->len);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            return 1;
        in->len += (size_t)got;
    }
}

/* Waits for the child until the deadline, then kills it; its wait status in *ws, 0 when it had
** to be killed. */
static int reap(pid_t pid, double deadline, int *ws)
{
    for (;;) {
        pid_t w = waitpid(pid, ws, WNOHANG);
        if (w == pid)
            return 1;
        if (w < 0 && errno != EINTR)
            return 1;
        if (now_s() >= deadline) {
            kill(pid, SIGKILL);
            while (waitpid(pid, ws, 0) < 0 && errno == EINTR)
                ;
            return 0;
        }
        struct timespec nap = {0, 2000000};
        nanosleep(&nap, NULL);
    }
}

cf_status cf_isolate_run(const char *what, cf_isolate_fn fn, void *arg, double max_bytes,
                         double max_seconds, cf_isolate_buf *in, cf_error *err)
{
    memset(in, 0, sizeof *in);
    int fd[2];
    if (pipe(fd) != 0)
        return cf_error_set(err, CF_E_INTERNAL, "%s: cannot make a pipe: %s", what,
                            strerror(errno));
    fcntl(fd[0], F_SETFD, FD_CLOEXEC);
    fcntl(fd[1], F_SETFD, FD_CLOEXEC);
    const double start = now_s();
    const double deadline = start + (max_seconds > 0 ? max_seconds : 1e9);
    const pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return cf_error_set(err, CF_E_INTERNAL, "%s: cannot start a process: %s", what,
                            strerror(errno));
    }
    if (pid == 0) {
        close(fd[0]);
        child(fd[1], parent, fn, arg, max_bytes, max_seconds);
    }
    close(fd[1]);
    const int done = read_all(fd[0], deadline, in);
    close(fd[0]);
    int ws = 0;
    const int exited = reap(pid, done == 1 ? deadline : now_s(), &ws);
    trailer t;
    cf_status st = CF_OK;
    if (done < 0) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for its result", what);
    } else if (done == 0 || !exited) {
        st = cf_error_set(err, CF_E_DATA, "%s did not finish within %.3g s: stopped", what,
                          max_seconds);
    } else if (WIFSIGNALED(ws)) {
        const int s = WTERMSIG(ws);
        char lim[120] = "";
        if (max_bytes > 0)
            snprintf(lim, sizeof lim, " (under a memory limit of %.0f MiB: it may need more)",
                     max_bytes / (1024.0 * 1024.0));
        st = cf_error_set(err, CF_E_DATA, "%s failed: its process ended by signal %d (%s)%s",
                          what, s, s == SIGXCPU ? "CPU time limit" : strsignal(s), lim);
    } else if (in->len < sizeof t || !WIFEXITED(ws) || WEXITSTATUS(ws) != 0) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s failed: its process ended with status %d "
                          "before it had written its result", what,
                          WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
    } else {
        memcpy(&t, in->data + in->len - sizeof t, sizeof t);
        in->len -= sizeof t;
        t.msg[sizeof t.msg - 1] = '\0';
        if (memcmp(t.mark, end_mark, sizeof t.mark) != 0)
            st = cf_error_set(err, CF_E_INTERNAL, "%s failed: its result is incomplete", what);
        else if (t.status != CF_OK)
            st = cf_error_set(err, (cf_status)t.status, "%s", t.msg);
    }
    if (st != CF_OK) {
        free(in->data);
        memset(in, 0, sizeof *in);
    }
    return st;
}
