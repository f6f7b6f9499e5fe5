/* Running a check suite the same way in every test program. */
#ifndef TS_TEST_RUN_H
#define TS_TEST_RUN_H

#include <check.h>
#include <stdlib.h>

/* Run every test of s, free it, and give main's exit status. */
static inline int test_run_suite(Suite *s)
{
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}

#endif
