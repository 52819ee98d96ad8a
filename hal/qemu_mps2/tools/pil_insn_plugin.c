/*
 * QEMU TCG plugin: exact instruction counts of each pmstep_step() call, for the
 * processor-in-the-loop cost measurement (tools/bench_target.py).
 *
 * Every executed guest instruction adds one to a counter (inline, exact). A
 * callback on the first instruction of pmstep_step() (entry=ADDR) notes the
 * counter; a callback on the instruction the call returns to (ret=ADDR, the one
 * after the BL in the control interrupt) appends the difference to the output
 * file: the instructions of that step, from its first to its return, callees
 * included. With profile=FILE, it also writes, for every instruction executed
 * inside a step, its address, size, execution count and how many times control
 * left it for a non-sequential address (a taken branch or a return): the input of
 * a cycle model (tools/bench_target.py); profile_from=K,profile_to=L restrict the
 * profile to the steps K <= index < L (counted from 0).
 *
 *   qemu-system-arm ... -plugin pil_insn_plugin.so,entry=0x...,ret=0x...,out=steps.txt[,profile=prof.txt]
 *
 * QEMU's plugin header (qemu-plugin.h) is not packaged by Debian, so the few
 * declarations used are repeated below: plugin API version 1 (QEMU 4.2 to 8.x;
 * the Debian 12 package is QEMU 7.2).
 */
#include <inttypes.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- subset of qemu-plugin.h, API version 1 ---- */
typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
typedef struct qemu_info_t qemu_info_t;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb, size_t idx);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
size_t qemu_plugin_insn_size(const struct qemu_plugin_insn *insn);
void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn, qemu_plugin_vcpu_udata_cb_t cb,
                                            enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn, enum qemu_plugin_op op, void *ptr,
                                                uint64_t imm);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
#define PLUGIN_EXPORT __attribute__((visibility("default")))
PLUGIN_EXPORT int qemu_plugin_version = 1;
PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv);
/* ---- end of the subset ---- */

static uint64_t total;      /* every executed instruction */
static uint64_t step_start; /* total at the entry of the current step */
static bool in_step;
static uint64_t entry_addr, ret_addr;
static FILE *out;
static uint64_t steps_counted;
static uint64_t unmatched;

/* Profile inside steps: one record per translated instruction address. */
typedef struct insn_rec {
    uint64_t pc;
    uint64_t size;
    uint64_t count;
    uint64_t jumps; /* times the next instruction executed was not at pc + size */
    struct insn_rec *next;
} insn_rec_t;
#define PROFILE_BUCKETS 4096u
static insn_rec_t *profile_table[PROFILE_BUCKETS];
static bool profiling;
static bool profile_this_step;
static uint64_t profile_from, profile_to = UINT64_MAX;
static char profile_path[1024];
static insn_rec_t *last_in_step;

static insn_rec_t *profile_record(uint64_t pc, uint64_t size)
{
    const size_t b = (size_t)((pc >> 1) % PROFILE_BUCKETS);
    insn_rec_t *r;
    for (r = profile_table[b]; r != NULL; r = r->next) {
        if (r->pc == pc) {
            return r; /* translated again (a new TB through the same code): same record */
        }
    }
    r = calloc(1u, sizeof *r);
    if (r == NULL) {
        abort();
    }
    r->pc = pc;
    r->size = size;
    r->next = profile_table[b];
    profile_table[b] = r;
    return r;
}

static void on_entry(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    (void)udata;
    if (in_step) {
        unmatched++; /* re-entered without returning: not expected in this image */
    }
    step_start = total;
    in_step = true;
    last_in_step = NULL;
    profile_this_step = steps_counted >= profile_from && steps_counted < profile_to;
}

static void on_return(unsigned int vcpu, void *udata)
{
    (void)vcpu;
    (void)udata;
    if (!in_step) {
        return;
    }
    in_step = false;
    profile_this_step = false;
    if (last_in_step != NULL) {
        last_in_step->jumps++; /* the step's return */
        last_in_step = NULL;
    }
    fprintf(out, "%" PRIu64 "\n", total - step_start);
    steps_counted++;
}

static void on_insn_profile(unsigned int vcpu, void *udata)
{
    insn_rec_t *r = udata;
    (void)vcpu;
    if (!profile_this_step) {
        return;
    }
    r->count++;
    if (last_in_step != NULL && r->pc != last_in_step->pc + last_in_step->size) {
        last_in_step->jumps++;
    }
    last_in_step = r;
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    const size_t n = qemu_plugin_tb_n_insns(tb);
    size_t i;
    (void)id;
    for (i = 0; i < n; ++i) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        const uint64_t pc = qemu_plugin_insn_vaddr(insn);
        /* Callbacks first, then the count: the same order at both ends keeps the difference exact. */
        if (pc == entry_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_entry, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        if (pc == ret_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_return, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        if (profiling) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_insn_profile, QEMU_PLUGIN_CB_NO_REGS,
                                                   profile_record(pc, qemu_plugin_insn_size(insn)));
        }
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &total, 1);
    }
}

static void on_exit_cb(qemu_plugin_id_t id, void *udata)
{
    (void)id;
    (void)udata;
    fprintf(out, "# steps %" PRIu64 " unmatched %" PRIu64 " total_instructions %" PRIu64 "\n", steps_counted, unmatched,
            total);
    fclose(out);
    if (profiling) {
        FILE *f = fopen(profile_path, "w");
        if (f != NULL) {
            size_t b;
            fprintf(f, "# pc size count jumps (inside pmstep_step calls)\n");
            for (b = 0; b < PROFILE_BUCKETS; ++b) {
                const insn_rec_t *r;
                for (r = profile_table[b]; r != NULL; r = r->next) {
                    if (r->count != 0u) {
                        fprintf(f, "0x%08" PRIx64 " %" PRIu64 " %" PRIu64 " %" PRIu64 "\n", r->pc, r->size, r->count,
                                r->jumps);
                    }
                }
            }
            fclose(f);
        }
    }
}

PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    const char *out_path = NULL;
    int i;
    (void)info;
    for (i = 0; i < argc; ++i) {
        const char *a = argv[i];
        if (strncmp(a, "entry=", 6) == 0) {
            entry_addr = strtoull(a + 6, NULL, 0);
        } else if (strncmp(a, "ret=", 4) == 0) {
            ret_addr = strtoull(a + 4, NULL, 0);
        } else if (strncmp(a, "out=", 4) == 0) {
            out_path = a + 4;
        } else if (strncmp(a, "profile=", 8) == 0) {
            snprintf(profile_path, sizeof profile_path, "%s", a + 8);
            profiling = true;
        } else if (strncmp(a, "profile_from=", 13) == 0) {
            profile_from = strtoull(a + 13, NULL, 0);
        } else if (strncmp(a, "profile_to=", 11) == 0) {
            profile_to = strtoull(a + 11, NULL, 0);
        } else {
            fprintf(stderr, "pil_insn_plugin: unknown argument '%s'\n", a);
            return -1;
        }
    }
    if (entry_addr == 0u || ret_addr == 0u || out_path == NULL) {
        fprintf(stderr, "pil_insn_plugin: needs entry=ADDR,ret=ADDR,out=FILE\n");
        return -1;
    }
    out = fopen(out_path, "w");
    if (out == NULL) {
        fprintf(stderr, "pil_insn_plugin: cannot write '%s'\n", out_path);
        return -1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_exit_cb, NULL);
    return 0;
}
