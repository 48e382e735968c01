/*
** Opening input files (see input.h).
*/
#define _GNU_SOURCE /* O_CLOEXEC */
#include "base/input.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

const char *cf_file_kind(mode_t m)
{
    return S_ISLNK(m)    ? "a symbolic link"
           : S_ISFIFO(m) ? "a FIFO"
           : S_ISCHR(m)  ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISSOCK(m) ? "a socket"
           : S_ISDIR(m)  ? "a folder"
                         : "not a regular file";
}

FILE *cf_input_open(const char *path, const char *what, cf_error *err)
{
    /* O_NONBLOCK: a FIFO without a writer opens at once instead of waiting for one */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        cf_error_set(err, CF_E_NOINPUT, "%s: cannot open %s: %s", path, what, strerror(errno));
        return NULL;
    }
    struct stat s;
    if (fstat(fd, &s) != 0) {
        cf_error_set(err, CF_E_NOINPUT, "%s: cannot read %s: %s", path, what, strerror(errno));
        close(fd);
        return NULL;
    }
    if (!S_ISREG(s.st_mode)) {
        cf_error_set(err, CF_E_NOINPUT, "%s: cannot read %s: it is %s, not a regular file", path,
                     what, cf_file_kind(s.st_mode));
        close(fd);
        return NULL;
    }
    const int flags = fcntl(fd, F_GETFL);
    FILE *f = flags >= 0 && fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        cf_error_set(err, CF_E_NOINPUT, "%s: cannot read %s: %s", path, what, strerror(errno));
        close(fd);
    }
    return f;
}
