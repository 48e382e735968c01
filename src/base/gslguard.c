/*
** The library's GSL error handler and the count of threads inside a guard (see gslguard.h).
*/
#include "base/gslguard.h"

#include <pthread.h>

#include <gsl/gsl_errno.h>

static _Thread_local long depth;         /* guards this thread is inside */
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static long inside;                      /* threads inside a guard (under lock) */
static gsl_error_handler_t *program_handler; /* the handler to put back (under lock) */

static void library_handler(const char *reason, const char *file, int line, int gsl_errno)
{
    if (depth > 0)
        return;
    /* a thread of the program, outside the library, while another thread is inside it */
    pthread_mutex_lock(&lock);
    gsl_error_handler_t *h = program_handler;
    pthread_mutex_unlock(&lock);
    if (h)
        h(reason, file, line, gsl_errno);
}

int cf_gsl_enter(void)
{
    if (depth++ > 0)
        return 0;
    pthread_mutex_lock(&lock);
    inside++;
    gsl_error_handler_t *was = gsl_set_error_handler(library_handler);
    if (was != library_handler) /* the first thread in, or the program set one meanwhile */
        program_handler = was;
    pthread_mutex_unlock(&lock);
    return 1;
}

void cf_gsl_leave(int *token)
{
    (void)token;
    if (--depth > 0)
        return;
    pthread_mutex_lock(&lock);
    if (--inside == 0) {
        gsl_error_handler_t *now = gsl_set_error_handler(program_handler);
        if (now != library_handler) /* the program set another one while we ran: keep it */
            gsl_set_error_handler(now);
        program_handler = NULL;
    }
    pthread_mutex_unlock(&lock);
}
