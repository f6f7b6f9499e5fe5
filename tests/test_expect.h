/* Assertions shared by the check programs. */
#ifndef TS_TEST_EXPECT_H
#define TS_TEST_EXPECT_H

#include <check.h>
#include <stdio.h>
#include <string.h>

#include "terrashade.h"

/* Assert that `call` refuses its arguments: it returns TS_ERR_ARG and
 * fills *errp (cleared first) with that code and a message, which goes to
 * the log next to the call. */
#define EXPECT_ARG(call, errp)                                                         \
    do {                                                                               \
        memset((errp), 0, sizeof *(errp));                                             \
        ts_status st_ = (call);                                                        \
        ck_assert_msg(st_ == TS_ERR_ARG, "%s returned %d, want TS_ERR_ARG", #call,     \
                      (int)st_);                                                       \
        ck_assert_msg((errp)->code == TS_ERR_ARG && (errp)->message[0] != '\0',        \
                      "%s: no message", #call);                                        \
        printf("%-72.72s -> %s\n", #call, (errp)->message);                            \
    } while (0)

#endif
