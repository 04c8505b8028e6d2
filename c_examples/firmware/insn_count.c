/*
 * A QEMU TCG plugin (host code, not firmware): counts the guest
 * instructions executed from the entry of one function to the entry of
 * another, e.g. the firmware's mark_begin and mark_end:
 *
 *   qemu-system-arm ... -plugin ./insn_count.so,begin=0x1a4,end=0x1a8,out=FILE
 *
 * and writes "instructions N" to FILE each time `end` is reached after
 * `begin` (N summed over every such pair). With profile=FILE2 it also
 * writes, at that point, "ADDRESS N" for every translation block that ran
 * between the marks: the block's first address (8 hex digits, as nm
 * prints them) and the instructions it executed there, to be summed per
 * function with the ELF's symbols. Debian's QEMU loads plugins but
 * ships neither its example plugins nor qemu-plugin.h, so the few calls of
 * the plugin API used here (API version 1, QEMU 4.2 to 8.x) are declared
 * below. Counting is by translation block: a block adds its instruction
 * count when it starts, so both marks count whole blocks and their
 * difference is exact when, as here, each mark begins a block (a function
 * entry does: a block ends at every call).
 */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- The plugin API, as far as used ----------------------------------- */

typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;

enum { QEMU_PLUGIN_CB_NO_REGS = 0 }; /* the callback reads no registers */

typedef void (*tb_trans_cb)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*vcpu_udata_cb)(unsigned int vcpu_index, void *userdata);

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, tb_trans_cb cb);
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, vcpu_udata_cb cb, int flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, vcpu_udata_cb cb, int flags,
                                            void *userdata);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t index);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

/* ---- The count ---------------------------------------------------------- */

static uint64_t begin_addr, end_addr;
static const char *out_path, *profile_path;
static uint64_t executed; /* instructions of every block started so far */
static uint64_t at_begin, counted;
static int inside;

/* One per translation (a block translated twice has two). */
typedef struct block {
    uint64_t addr, instructions, counted;
    struct block *next;
} block;
static block *blocks;

static void on_block(unsigned int vcpu, void *data) {
    (void)vcpu;
    block *b = data;
    executed += b->instructions;
    if (inside) b->counted += b->instructions;
}

static void write_profile(void) {
    FILE *f = fopen(profile_path, "w");
    if (!f) return;
    for (const block *b = blocks; b; b = b->next) {
        if (b->counted) fprintf(f, "%08" PRIx64 " %" PRIu64 "\n", b->addr, b->counted);
    }
    fclose(f);
}

static void on_begin(unsigned int vcpu, void *unused) {
    (void)vcpu;
    (void)unused;
    at_begin = executed;
    inside = 1;
}

static void on_end(unsigned int vcpu, void *unused) {
    (void)vcpu;
    (void)unused;
    if (!inside) return;
    inside = 0;
    counted += executed - at_begin;
    FILE *f = fopen(out_path, "w");
    if (f) {
        fprintf(f, "instructions %" PRIu64 "\n", counted);
        fclose(f);
    }
    if (profile_path) write_profile();
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
    (void)id;
    const size_t n = qemu_plugin_tb_n_insns(tb);
    if (n == 0) return;
    block *b = calloc(1, sizeof *b);
    if (!b) {
        fputs("insn_count: out of memory\n", stderr);
        abort();
    }
    b->addr = qemu_plugin_insn_vaddr(qemu_plugin_tb_get_insn(tb, 0));
    b->instructions = n;
    b->next = blocks;
    blocks = b;
    qemu_plugin_register_vcpu_tb_exec_cb(tb, on_block, QEMU_PLUGIN_CB_NO_REGS, b);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        const uint64_t at = qemu_plugin_insn_vaddr(insn);
        /* The block's callback runs before its instructions' callbacks. */
        if (at == begin_addr) qemu_plugin_register_vcpu_insn_exec_cb(insn, on_begin, QEMU_PLUGIN_CB_NO_REGS, NULL);
        if (at == end_addr) qemu_plugin_register_vcpu_insn_exec_cb(insn, on_end, QEMU_PLUGIN_CB_NO_REGS, NULL);
    }
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id, const void *info, int argc,
                                                                char **argv) {
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "begin=", 6) == 0) begin_addr = strtoull(argv[i] + 6, NULL, 0);
        else if (strncmp(argv[i], "end=", 4) == 0) end_addr = strtoull(argv[i] + 4, NULL, 0);
        else if (strncmp(argv[i], "out=", 4) == 0) out_path = argv[i] + 4;
        else if (strncmp(argv[i], "profile=", 8) == 0) profile_path = argv[i] + 8;
    }
    if (begin_addr == 0 || end_addr == 0 || out_path == NULL) {
        fprintf(stderr, "insn_count: give begin=ADDRESS,end=ADDRESS,out=FILE\n");
        return -1;
    }
    /* Thumb function symbols carry the Thumb bit; instructions do not. */
    begin_addr &= ~(uint64_t)1;
    end_addr &= ~(uint64_t)1;
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    return 0;
}
