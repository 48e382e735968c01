/*
** GSL's error handler while the library runs.
**
** GSL reports an error (a matrix that is not positive definite, an inverse CDF that does not
** converge, memory that runs out) by calling one process-wide handler before it returns the error
** code; the default handler prints and calls abort(). The library checks every code GSL returns
** and never wants that handler: CF_GSL_GUARD, at the top of a function, makes GSL errors raised on
** this thread return their codes quietly until the function returns, whatever handler the calling
** program set (or left at GSL's default).
**
** How: while at least one thread runs inside a guard, GSL's handler is the library's own, which
** does nothing for a thread inside a guard and passes the error on to the handler the program had
** set for any other thread (with GSL's default handler left in place, such an error returns its
** code, as with gsl_set_error_handler_off: the library never aborts). When the last thread leaves,
** the program's handler is put back (unless the program set another one meanwhile: that one
** stays). Guards nest at the cost of a thread-local counter; the outermost one on a thread takes
** a lock twice. The batch pool's threads run their tasks inside a guard.
**
** Every public function that can reach GSL has a guard (its first statement), except the law's
** force evaluations, called once a point, which take it around the one GSL call they can make.
** tests/check_gsl_guard.sh (part of make test) checks this on the objects' call graph: no path
** from a public function to GSL may avoid a function that enters a guard.
*/
#ifndef CF_GSLGUARD_H
#define CF_GSLGUARD_H

/* Enters a guarded region of this thread; returns a token for cf_gsl_leave. */
int cf_gsl_enter(void);

/* Leaves the region cf_gsl_enter entered (token: its return value, by address). */
void cf_gsl_leave(int *token);

/* A guard for the rest of the enclosing block (left on every return, by the compiler's cleanup
** attribute, which GCC and Clang provide). */
#define CF_GSL_GUARD                                                                               \
    __attribute__((cleanup(cf_gsl_leave), unused)) int cf_gsl_guard_token_ = cf_gsl_enter()

#endif
