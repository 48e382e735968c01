/*
** Atomic output files (see atomic.h).
*/
#include "base/atomic.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int cf_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

cf_status cf_atomic_open(cf_atomic *a, const char *path, const char *const *inputs, cf_error *err)
{
    memset(a, 0, sizeof *a);
    if (!path || !*path)
        return cf_error_set(err, CF_E_CANTWRITE, "empty output file name");
    for (size_t i = 0; inputs && inputs[i]; i++)
        if (cf_same_file(path, inputs[i]))
            return cf_error_set(err, CF_E_CANTWRITE,
                                "%s: refusing to overwrite an input file with output", path);
    if (strlen(path) >= sizeof a->path)
        return cf_error_set(err, CF_E_CANTWRITE, "%s: output path too long", path);
    snprintf(a->path, sizeof a->path, "%s", path);
    snprintf(a->tmp, sizeof a->tmp, "%s.XXXXXX", path);
    int fd = mkstemp(a->tmp);
    if (fd < 0) {
        a->tmp[0] = '\0';
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot create output file: %s", path,
                            strerror(errno));
    }
    fchmod(fd, 0644);
    a->fp = fdopen(fd, "wb");
    if (!a->fp) {
        close(fd);
        remove(a->tmp);
        a->tmp[0] = '\0';
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot open output file: %s", path,
                            strerror(errno));
    }
    return CF_OK;
}

cf_status cf_atomic_commit(cf_atomic *a, cf_error *err)
{
    int bad = !a->fp || ferror(a->fp);
    int saved = errno;
    if (a->fp && fflush(a->fp) != 0) {
        bad = 1;
        saved = errno;
    }
    if (a->fp && fclose(a->fp) != 0 && !bad) {
        bad = 1;
        saved = errno;
    }
    a->fp = NULL;
    if (!bad && rename(a->tmp, a->path) != 0) {
        bad = 1;
        saved = errno;
    }
    if (bad) {
        if (a->tmp[0])
            remove(a->tmp);
        a->tmp[0] = '\0';
        return cf_error_set(err, CF_E_CANTWRITE, "%s: cannot write output file: %s", a->path,
                            strerror(saved ? saved : EIO));
    }
    a->tmp[0] = '\0';
    return CF_OK;
}

void cf_atomic_abort(cf_atomic *a)
{
    if (a->fp)
        fclose(a->fp);
    a->fp = NULL;
    if (a->tmp[0])
        remove(a->tmp);
    a->tmp[0] = '\0';
}
