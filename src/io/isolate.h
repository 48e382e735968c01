/*
** A piece of work run in a child process (isolate.c): a library that may loop for ever, exhaust
** memory or abort (Gmsh's meshing) runs where none of that can reach the caller. The child gets
** a memory limit (its address space) and is killed at a wall-time limit; it dies with the thread
** that started it (a caller ended by a signal leaves no child behind); its standard output and
** error go nowhere (the library prints nothing). Its result comes back through a pipe as bytes.
** Private to the io layer.
*/
#ifndef CF_IO_ISOLATE_H
#define CF_IO_ISOLATE_H

#include <stddef.h>

#include "conifit/error.h"

/* The child's side: bytes written to the pipe. The parent's side: the bytes read, and a cursor. */
typedef struct cf_isolate_buf {
    int fd;               /* child: the pipe's writing end */
    int failed;           /* child: a write failed */
    unsigned char *data;  /* parent: what the child wrote */
    size_t len, pos;
} cf_isolate_buf;

/* The work: runs in the child, writes its result with cf_isolate_put, returns its status (its
** message in err comes back to the caller as it is). */
typedef cf_status (*cf_isolate_fn)(void *arg, cf_isolate_buf *out, cf_error *err);

/* In the child: its memory limit (max_bytes beyond what it maps now) takes effect; the work calls
** it once its libraries are loaded. */
void cf_isolate_limit_memory(void);

void cf_isolate_put(cf_isolate_buf *out, const void *p, size_t n);
/* n bytes of the result into p; 0 when fewer are left. */
int cf_isolate_get(cf_isolate_buf *in, void *p, size_t n);

/* Runs fn(arg) in a child with an address space of max_bytes beyond what it maps when fn calls
** cf_isolate_limit_memory (0: no limit) for at most max_seconds of wall time. On CF_OK, *in holds the bytes
** the child wrote (free in->data). Otherwise the child's own status and message, or CF_E_DATA when
** it ran out of time ("did not finish within"), CF_E_DATA when it died of a signal under the
** memory limit (the signal named), CF_E_INTERNAL when no child could be started. `what` names the
** work in messages ("Gmsh meshing s.obj"). */
cf_status cf_isolate_run(const char *what, cf_isolate_fn fn, void *arg, double max_bytes,
                         double max_seconds, cf_isolate_buf *in, cf_error *err);

#endif
