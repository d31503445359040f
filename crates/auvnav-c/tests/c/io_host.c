/* The C test's platform functions on the host: stdio, exit. The stack is
   not measured here. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

void test_write(const char *s) { fputs(s, stdout); }
void test_exit(int status) { fflush(stdout); exit(status); }
void test_stack_begin(void) {}
uint32_t test_stack_end(void) { return 0; }
