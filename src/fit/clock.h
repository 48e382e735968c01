/*
** The clock the fits and the validation time themselves with. Private to the library.
*/
#ifndef CF_FIT_CLOCK_H
#define CF_FIT_CLOCK_H

/* Seconds on the monotonic clock (an arbitrary origin: only differences mean anything). */
double cf_clock_s(void);

#endif
