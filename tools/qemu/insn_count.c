/* QEMU TCG plugin: counts the guest instructions executed between two
 * marker functions, exactly and repeatably (BENCHMARKS.md).
 *
 *   qemu-system-arm ... -plugin libinsn_count.so
 *
 * Every translated instruction adds 1 to a counter when it executes
 * (inline, no callback). A translation block that starts at the marker
 * `auvnav_bench_start` (found by its ELF symbol, which QEMU loaded with the
 * kernel) snapshots the counter when it executes; one that starts at
 * `auvnav_bench_stop` prints `QEMU-BENCH <count>` on stdout, where count is
 * the instructions executed from the entry of the start marker up to, not
 * including, the stop marker. The firmware prints what it measures (on
 * stdout too, through semihosting) before it calls the start marker, so
 * the two interleave in order. Single vCPU (Cortex-M). At exit it prints
 * `QEMU-TOTAL <count>`, all instructions executed.
 *
 * With the argument `profile=N` (`-plugin libinsn_count.so,profile=20`) it
 * also prints, at exit, the N functions (ELF symbols) that executed the
 * most instructions over the whole run, as `QEMU-PROFILE <count> <symbol>`
 * (mangled; pipe through `c++filt`): where the time goes. The profile
 * counts whole translation blocks, so it is approximate where a block ends
 * early (an exception); the marker counts are exact. With `hot=N` it
 * prints the N hottest translation blocks instead, as
 * `QEMU-HOT <count> <address> <executions> x <size> <symbol>`: where inside
 * a function the instructions go (tools/qemu/profile.sh --hot).
 *
 * Instructions, not cycles: QEMU does not model the Cortex-M pipeline,
 * flash wait states or FPU latencies. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "qemu-plugin-api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

static uint64_t executed;  /* instructions executed so far */
static uint64_t started;   /* `executed` at the last start marker */
static int running;

/* Profile: one record per translated block. */
struct block {
    const char *sym;
    uint64_t vaddr;
    uint64_t insns;
    uint64_t execs;
};
static struct block **blocks;
static size_t n_blocks, cap_blocks;
static int profile_top; /* 0: no profile */
static int per_block;   /* count=block: add a block's size when it starts */
static int hot_top;     /* hot=N: the N hottest translation blocks */

static void say(const char *s)
{
    /* Straight to fd 1, unbuffered, like QEMU's semihosting writes. */
    size_t n = strlen(s);
    while (n > 0) {
        ssize_t w = write(1, s, n);
        if (w <= 0) {
            return;
        }
        s += w;
        n -= (size_t)w;
    }
}

static void on_start(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    (void)udata;
    started = executed;
    running = 1;
}

static void on_stop(unsigned int vcpu, void *udata)
{
    char line[64];
    (void)vcpu;
    (void)udata;
    if (!running) {
        say("QEMU-BENCH error: stop marker without start\n");
        return;
    }
    running = 0;
    snprintf(line, sizeof line, "QEMU-BENCH %llu\n", (unsigned long long)(executed - started));
    say(line);
}

static int grow(void)
{
    size_t cap = cap_blocks ? 2 * cap_blocks : 4096;
    struct block **b = realloc(blocks, cap * sizeof *b);
    if (b == NULL) {
        return 0;
    }
    blocks = b;
    cap_blocks = cap;
    return 1;
}

struct total {
    const char *sym;
    uint64_t insns;
};

static int by_symbol(const void *a, const void *b)
{
    const char *x = (*(struct block *const *)a)->sym, *y = (*(struct block *const *)b)->sym;
    return strcmp(x ? x : "?", y ? y : "?");
}

static int by_count(const void *a, const void *b)
{
    uint64_t x = ((const struct total *)a)->insns, y = ((const struct total *)b)->insns;
    return x < y ? 1 : x > y ? -1 : 0;
}

static void print_profile(void)
{
    struct total *t;
    size_t n = 0;
    char line[512];
    if (n_blocks == 0 || (t = calloc(n_blocks, sizeof *t)) == NULL) {
        return;
    }
    qsort(blocks, n_blocks, sizeof *blocks, by_symbol);
    for (size_t i = 0; i < n_blocks; i++) {
        const char *s = blocks[i]->sym ? blocks[i]->sym : "?";
        if (n == 0 || strcmp(t[n - 1].sym, s) != 0) {
            t[n++].sym = s;
        }
        t[n - 1].insns += blocks[i]->insns * blocks[i]->execs;
    }
    qsort(t, n, sizeof *t, by_count);
    for (size_t i = 0; i < n && i < (size_t)profile_top; i++) {
        snprintf(line, sizeof line, "QEMU-PROFILE %llu %s\n", (unsigned long long)t[i].insns, t[i].sym);
        say(line);
    }
    free(t);
}

static int by_block_count(const void *a, const void *b)
{
    const struct block *x = *(struct block *const *)a, *y = *(struct block *const *)b;
    uint64_t u = x->insns * x->execs, v = y->insns * y->execs;
    return u < v ? 1 : u > v ? -1 : 0;
}

/* The hottest blocks, by start address: where inside a function the
 * instructions go (look the addresses up in `llvm-objdump -d`). */
static void print_hot(void)
{
    char line[512];
    qsort(blocks, n_blocks, sizeof *blocks, by_block_count);
    for (size_t i = 0; i < n_blocks && i < (size_t)hot_top; i++) {
        const struct block *b = blocks[i];
        snprintf(line, sizeof line, "QEMU-HOT %llu 0x%llx %llu x %llu %s\n",
                 (unsigned long long)(b->insns * b->execs), (unsigned long long)b->vaddr,
                 (unsigned long long)b->execs, (unsigned long long)b->insns,
                 b->sym ? b->sym : "?");
        say(line);
    }
}

static int is(const char *sym, const char *name)
{
    return sym != NULL && strcmp(sym, name) == 0;
}

/* Each marker's entry address: the first block translated in it. */
static uint64_t start_entry = UINT64_MAX;
static uint64_t stop_entry = UINT64_MAX;

/* Whether `at` is the marker's entry, `*seen` its first block's address
 * (set by the first call). */
static int entry(uint64_t *seen, uint64_t at)
{
    if (*seen == UINT64_MAX) {
        *seen = at;
    }
    return *seen == at;
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    size_t n = qemu_plugin_tb_n_insns(tb);
    (void)id;
    if (n > 0) {
        const char *sym = qemu_plugin_insn_symbol(qemu_plugin_tb_get_insn(tb, 0));
        uint64_t at = qemu_plugin_tb_vaddr(tb);
        /* The markers are only ever entered by a call, so the first block
         * translated in one starts at its entry; a later block in it (a
         * marker that crosses a 1 KiB page, where QEMU splits blocks) is
         * not an entry, and is not a marker. */
        if (is(sym, "auvnav_bench_start") && entry(&start_entry, at)) {
            qemu_plugin_register_vcpu_tb_exec_cb(tb, on_start, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else if (is(sym, "auvnav_bench_stop") && entry(&stop_entry, at)) {
            qemu_plugin_register_vcpu_tb_exec_cb(tb, on_stop, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
    }
    if ((profile_top > 0 || hot_top > 0) && n > 0) {
        struct block *b = calloc(1, sizeof *b);
        if (b != NULL && (n_blocks < cap_blocks || grow())) {
            b->sym = qemu_plugin_insn_symbol(qemu_plugin_tb_get_insn(tb, 0));
            b->vaddr = qemu_plugin_tb_vaddr(tb);
            b->insns = n;
            blocks[n_blocks++] = b;
            qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &b->execs, 1);
        }
    }
    if (per_block) {
        qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &executed, n);
    } else {
        for (size_t i = 0; i < n; i++) {
            qemu_plugin_register_vcpu_insn_exec_inline(qemu_plugin_tb_get_insn(tb, i),
                                                       QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
        }
    }
}

static void on_end(qemu_plugin_id_t id, void *udata)
{
    char line[64];
    (void)id;
    (void)udata;
    snprintf(line, sizeof line, "QEMU-TOTAL %llu\n", (unsigned long long)executed);
    say(line);
    if (profile_top > 0) {
        print_profile();
    }
    if (hot_top > 0) {
        print_hot();
    }
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc,
                                           char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "profile=", 8) == 0) {
            profile_top = atoi(argv[i] + 8);
        } else if (strncmp(argv[i], "hot=", 4) == 0) {
            hot_top = atoi(argv[i] + 4);
        } else if (strcmp(argv[i], "count=block") == 0) {
            per_block = 1;
        }
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_end, NULL);
    return 0;
}
