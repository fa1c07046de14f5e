/* Tiny assertion helpers shared by the example/test programs. */
#ifndef PLEAT_TEST_UTIL_H
#define PLEAT_TEST_UTIL_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "pleat.h"

static int g_failures = 0;
static int g_checks = 0;

#define CHECK(cond)                                                            \
    do {                                                                       \
        g_checks++;                                                            \
        if (!(cond)) {                                                         \
            g_failures++;                                                      \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__,   \
                    #cond);                                                    \
        }                                                                      \
    } while (0)

/* Checks that `call` returns `expected` and, on failure, that a message was set. */
#define CHECK_STATUS(call, expected)                                           \
    do {                                                                       \
        PleatStatus st_ = (call);                                              \
        g_checks++;                                                            \
        if (st_ != (expected)) {                                               \
            g_failures++;                                                      \
            fprintf(stderr, "%s:%d: %s returned %d, expected %d (%s)\n",       \
                    __FILE__, __LINE__, #call, (int)st_, (int)(expected),      \
                    pleat_last_error());                                       \
        } else if ((expected) != PLEAT_STATUS_OK &&                            \
                   strlen(pleat_last_error()) == 0) {                          \
            g_failures++;                                                      \
            fprintf(stderr, "%s:%d: %s failed without a message\n", __FILE__,  \
                    __LINE__, #call);                                          \
        } else if ((expected) != PLEAT_STATUS_OK) {                            \
            printf("  ok: %-60.60s -> %s\n", #call, pleat_last_error());       \
        }                                                                      \
    } while (0)

static int finish(const char *name) {
    printf("%s: %d passed, %d failed\n", name, g_checks - g_failures, g_failures);
    return g_failures == 0 ? 0 : 1;
}
#endif
