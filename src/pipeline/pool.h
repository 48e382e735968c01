/*
** A batch of independent tasks on a few threads (private to the layers above; the command line
** fits several tables at a time with it). The pool keeps no state between calls and never prints.
*/
#ifndef CF_PIPELINE_POOL_H
#define CF_PIPELINE_POOL_H

/* Most threads a batch runs on. */
#define CF_POOL_MAX_THREADS 256

/* Runs task(ctx, k) once for every k in 0 .. count-1 on up to nthreads threads, the calling one
** among them (at most count and CF_POOL_MAX_THREADS): each thread takes the next k not yet taken
** until none is left. A thread that cannot be started leaves its share to the others. Returns
** when every task has returned. */
void cf_pool_run(int count, long nthreads, void (*task)(void *ctx, int k), void *ctx);

#endif
