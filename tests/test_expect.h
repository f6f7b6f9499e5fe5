/* Assertions shared by the check programs. */
#ifndef TS_TEST_EXPECT_H
#define TS_TEST_EXPECT_H

#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "terrashade.h"

/* Assert |got - want| <= tol, in double (what: the log's name for it). */
#define CK_NEAR(got, want, tol, what)                                                    \
    ck_assert_msg(fabs((double)(got) - (double)(want)) <= (tol),                         \
                  "%s: got %.10f, want %.10f +/- %g", what, (double)(got), (double)(want), \
                  (double)(tol))

/* Assert that `call` refuses its arguments: it returns TS_ERR_ARG and
 * fills *errp (cleared first) with that code and a message, which goes to
 * the log next to `name` (a string saying what was called). */
#define EXPECT_ARG_NAMED(call, name, errp)                                             \
    do {                                                                               \
        memset((errp), 0, sizeof *(errp));                                             \
        ts_status st_ = (call);                                                        \
        ck_assert_msg(st_ == TS_ERR_ARG, "%s returned %d, want TS_ERR_ARG", (name),    \
                      (int)st_);                                                       \
        ck_assert_msg((errp)->code == TS_ERR_ARG && (errp)->message[0] != '\0',        \
                      "%s: no message", (name));                                       \
        printf("%-72.72s -> %s\n", (name), (errp)->message);                           \
    } while (0)

/* EXPECT_ARG_NAMED with the call's own text as its name. */
#define EXPECT_ARG(call, errp) EXPECT_ARG_NAMED(call, #call, errp)

/* EXPECT_ARG of `fn` (a function of a request and an error) on the request
 * `good` with one field set to `value`, through the request variable `bad`. */
#define EXPECT_ARG_FIELD(fn, bad, good, field, value, errp)                            \
    do {                                                                               \
        (bad) = (good);                                                                \
        (bad).field = (value);                                                         \
        EXPECT_ARG_NAMED(fn(&(bad), (errp)), #fn "(" #field " = " #value ")", (errp));  \
    } while (0)

#endif
