/* The command line's single-process cluster (app/cli/cluster/
 * cluster_single.c, what a build without MPI uses), tested in every build:
 * started as one of several processes it refuses with exit status 6, and
 * otherwise it is the one process of its job. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"

#include "cli.h"
#include "cluster.h"

static char last_error[1024];

/* The command line's cli_error, which the module reports through. */
void cli_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(last_error, sizeof last_error, fmt, ap);
    va_end(ap);
}

static void test_alone(void **state)
{
    (void)state;
    unsetenv("OMPI_COMM_WORLD_SIZE");
    unsetenv("PMI_SIZE");
    unsetenv("PMIX_SIZE");
    int argc = 1;
    char *args[] = {"zonetrace", NULL}, **argv = args;
    assert_int_equal(cluster_start(&argc, &argv), EXIT_OK);
    assert_int_equal(cluster_rank(), 0);
    assert_int_equal(cluster_ranks(), 1);
    assert_null(cluster_share());
    assert_int_equal(cluster_agree(EXIT_UNWRITABLE), EXIT_UNWRITABLE);
    char mine[5] = "abcd", all[5] = "";
    assert_int_equal(cluster_gather(mine, 5, all), 0);
    assert_string_equal(all, "abcd");
    /* a launcher's one-process job is one process too */
    setenv("OMPI_COMM_WORLD_SIZE", "1", 1);
    assert_int_equal(cluster_start(&argc, &argv), EXIT_OK);
}

static void test_refuses_several(void **state)
{
    (void)state;
    const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
    for (int i = 0; i < 3; i++) {
        unsetenv("OMPI_COMM_WORLD_SIZE");
        unsetenv("PMI_SIZE");
        unsetenv("PMIX_SIZE");
        setenv(vars[i], "4", 1);
        int argc = 1;
        char *args[] = {"zonetrace", NULL}, **argv = args;
        last_error[0] = '\0';
        assert_int_equal(cluster_start(&argc, &argv), EXIT_UNSUPPORTED);
        assert_non_null(strstr(last_error, "built without MPI"));
        assert_non_null(strstr(last_error, "one of 4 processes"));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alone),
        cmocka_unit_test(test_refuses_several),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
