/*
** The monotonic clock of the fits (see clock.h).
*/
#include "fit/clock.h"

#include <time.h>

double cf_clock_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
