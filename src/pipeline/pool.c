/*
** The batch pool (see pool.h): threads that take the next task under one lock.
*/
#include "pipeline/pool.h"
#include "base/gslguard.h"

#include <pthread.h>

typedef struct pool {
    void (*task)(void *ctx, int k);
    void *ctx;
    int count;
    int next;
    pthread_mutex_t lock;
} pool;

static void *worker(void *arg)
{
    CF_GSL_GUARD;
    pool *p = arg;
    for (;;) {
        pthread_mutex_lock(&p->lock);
        int k = p->next++;
        pthread_mutex_unlock(&p->lock);
        if (k >= p->count)
            return NULL;
        p->task(p->ctx, k);
    }
}

void cf_pool_run(int count, long nthreads, void (*task)(void *ctx, int k), void *ctx)
{
    pool p = {task, ctx, count, 0, PTHREAD_MUTEX_INITIALIZER};
    int nt = (int)(nthreads < count ? nthreads : count);
    if (nt > CF_POOL_MAX_THREADS)
        nt = CF_POOL_MAX_THREADS;
    pthread_t th[CF_POOL_MAX_THREADS];
    int started = 0;
    for (int t = 1; t < nt; t++)
        if (pthread_create(&th[started], NULL, worker, &p) == 0)
            started++;
    worker(&p);
    for (int t = 0; t < started; t++)
        pthread_join(th[t], NULL);
}
