/* The C test's platform on QEMU mps2-an386: reset handler (copy .data,
   zero .bss, enable the FPU), HardFault exit, semihosting output and exit,
   and stack painting. No C library. The image does not define the panic
   hook auvnav_panic: it links only if the static library has no panic
   path left (the link-time proof of scripts/c-test.sh). */
#include <stdint.h>

int main(void);
extern uint32_t __data_start, __data_end, __data_load, __bss_start, __bss_end, __stack_top;

static int semihost(int op, const void *arg) {
  register int r0 __asm__("r0") = op;
  register const void *r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void test_write(const char *s) { semihost(0x04, s); /* SYS_WRITE0 */ }

void test_exit(int status) {
  /* SYS_EXIT: ADP_Stopped_ApplicationExit (0) or RunTimeErrorUnknown (1). */
  semihost(0x18, (const void *)(uintptr_t)(status == 0 ? 0x20026u : 0x20023u));
  for (;;) {}
}

#define PAINT 0x5a5aa5a5u
#define PAINT_BYTES (256u * 1024u)
static uint32_t *paint_low, *paint_high;

static uint32_t *stack_pointer(void) {
  uint32_t *sp;
  __asm__ volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

/* Paints the 256 KiB below the caller's frame. */
void test_stack_begin(void) {
  uint32_t *p;
  paint_high = stack_pointer() - 16;
  paint_low = paint_high - PAINT_BYTES / 4u;
  for (p = paint_low; p < paint_high; p++) *(volatile uint32_t *)p = PAINT;
}

/* Bytes of stack used below the painted top since test_stack_begin. */
uint32_t test_stack_end(void) {
  uint32_t *p = paint_low;
  while (p < paint_high && *(volatile uint32_t *)p == PAINT) p++;
  return (uint32_t)((paint_high - p) * 4);
}

void reset_handler(void) {
  uint32_t *s = &__data_load, *d = &__data_start;
  while (d < &__data_end) *d++ = *s++;
  for (d = &__bss_start; d < &__bss_end; d++) *d = 0;
  /* CPACR: full access to CP10 and CP11 (the FPU). */
  *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
  __asm__ volatile("dsb\n isb" ::: "memory");
  test_exit(main());
}

static void fault(void) {
  test_write("HardFault\n");
  test_exit(1);
}

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
  (void (*)(void))&__stack_top, reset_handler, fault, fault, fault, fault, fault, 0, 0, 0, 0, fault, fault, 0, fault, fault,
};
