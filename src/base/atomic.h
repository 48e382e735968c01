/*
** Writing output files so that nothing is ever half-written and nothing but a regular file is
** ever replaced.
**
** A file is written under a hidden temporary name in its own folder, `.NAME.conifit-TAG-PID-XXXXXX`,
** and renamed over the target only when it is complete (and, for a command with several outputs,
** only when all of them are: open them all, then commit them all). Rules:
**   - the target must not be one of the run's inputs;
**   - an existing target must be a regular file that is not write-protected (no write permission
**     for anyone): a symbolic link, FIFO, character or block device, socket or folder is refused
**     (conifit never writes into such a thing, nor replaces it);
**   - a new file gets 0666 less the umask; a replaced file keeps its permissions but never a
**     set-user-ID, set-group-ID or sticky bit;
**   - a failed or aborted write leaves no file at all;
**   - temporaries still open when the process is stopped by a signal are removed by
**     cf_atomic_remove_temporaries (main calls it on SIGINT, SIGTERM, SIGHUP, SIGPIPE); those of a
**     process killed outright (SIGKILL) stay hidden (dot names) and are swept by a later
**     cf_atomic_open in the same folder, once no process of that PID is alive: the first open
**     of a process in a folder sweeps it, later ones only after ten minutes (so n files in one
**     folder cost one reading of it, not n). TAG names the PID
**     space (host, boot and PID namespace): only temporaries of this one are judged, so a run in
**     another container or on another host sharing the folder is never swept while it writes.
** The list of live temporaries is the one process-wide state of the library; it is thread-safe.
*/
#ifndef CF_ATOMIC_H
#define CF_ATOMIC_H

#include <stdio.h>

#include "conifit/error.h"

/* The public cf_output (conifit/output.h) is this structure; inside the library it is used as a
** value (a job holds its outputs) under the name cf_atomic. */
typedef struct cf_output {
    FILE *fp;          /* write here (NULL once the file is finished) */
    char path[4096];   /* final name */
    char tmp[4200];    /* temporary name in the same folder ("" when none) */
    int slot;          /* 1 + its entry in the list of live temporaries, 0 when none */
} cf_atomic;

/* Whether path may be written: CF_E_CANTWRITE (message names the path and the reason) when it is
** one of `inputs` (NULL-terminated, may be NULL), exists and is not a regular file or is
** write-protected, or its folder does not exist. Lets a command refuse a bad target before any
** work. */
cf_status cf_atomic_check(const char *path, const char *const *inputs, cf_error *err);

/* Checks path (cf_atomic_check) and opens a temporary file beside it. CF_E_CANTWRITE when it
** cannot be created. */
cf_status cf_atomic_open(cf_atomic *a, const char *path, const char *const *inputs, cf_error *err);

/* Finishes the temporary file (flush, close), checking every write; the file is complete but not
** in place, and no descriptor stays open. On failure the temporary is removed, CF_E_CANTWRITE. */
cf_status cf_atomic_finish(cf_atomic *a, cf_error *err);

/* Finishes the file if needed and renames it to its final name, after checking again that the
** target is not (by now) something other than a regular file. On any failure the temporary file
** is removed and CF_E_CANTWRITE returned. */
cf_status cf_atomic_commit(cf_atomic *a, cf_error *err);

/* Closes and removes the temporary file (safe to call twice, after a commit, on a zeroed
** cf_atomic, or with NULL). */
void cf_atomic_abort(cf_atomic *a);

/* The argument checks of a call named `call` that prepares up to two outputs of report r:
** CF_E_USAGE when r is NULL, a path is given without its handle, a handle given still holds
** an uncommitted file, or both paths are given with one handle or name one file (the second
** output would replace the first). Then empties the handles given (either may be NULL), so that the call may
** abort both on failure. Handles held by value must start zeroed. */
cf_status cf_atomic_begin(const char *call, const void *r, const char *path1, cf_atomic *out1,
                          const char *path2, cf_atomic *out2, cf_error *err);

/* The same for a call that prepares one output: the path must be given too. */
cf_status cf_atomic_begin_one(const char *call, const void *r, const char *path, cf_atomic *out,
                              cf_error *err);

/* Removes every temporary file still open in this process. Async-signal-safe: for a handler of a
** fatal signal. */
void cf_atomic_remove_temporaries(void);

/* How many times this process has swept a folder for dead runs' temporaries (for tests). */
unsigned long cf_atomic_sweeps(void);

/* 1 when paths a and b name one file: the same text, one existing file (same device and inode),
** or, for files not there yet, the same name in the same folder (the folders resolved). */
int cf_same_target(const char *a, const char *b);

/* True when a and b name the same existing file (same device and inode). */
int cf_same_file(const char *a, const char *b);

#endif
