/* crash_at_exit.c: a library whose destructor aborts the process that loaded it when that process
 * exits, as pythonfmu's export library can at interpreter shutdown (tests/test_distributed.py). */
#include <stdlib.h>

__attribute__((destructor)) static void crash_at_exit(void) { abort(); }
