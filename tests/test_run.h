/* Running a check suite the same way in every test program. */
#ifndef TS_TEST_RUN_H
#define TS_TEST_RUN_H

#include <check.h>
#include <stdlib.h>

/* Run every test of s, reporting as `mode` (CK_NORMAL: the failures,
 * CK_VERBOSE: every test), free it, and give main's exit status. */
static inline int test_run_suite_mode(Suite *s, enum print_output mode)
{
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, mode);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}

/* The same, reporting the failures. */
static inline int test_run_suite(Suite *s)
{
    return test_run_suite_mode(s, CK_NORMAL);
}

#endif
