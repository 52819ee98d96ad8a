/*
 * Processor in the loop, replay: the core's inputs of every period recorded by the
 * host SIL (pmstep-sil --record) go through the real pmstep_step() on the emulated
 * Cortex-M4, from the port's control interrupt; the outputs are written for the host
 * to compare with its own (tests/pil/pil_compare.c).
 *
 * usage (semihosting command line): pil-replay RECORD OUTPUTS [COST]
 *   RECORD   the SIL record (sil/include/sil/runner.h)
 *   OUTPUTS  written: this target's outputs (pil_record.h, "PMSO")
 *   COST     written: the step's cost per mode from SysTick (meaningful with -icount shift=0)
 */
#include <stdio.h>
#include <stdlib.h>

#include "pil_record.h"
#include "pmstep_hal_qemu_mps2.h"
#include "pmstep/pmstep_text.h"

#define IO_BUFFER_BYTES 65536u

static pmstep_t motor;
static pmstep_config_t config; /* outlives the instance, as pmstep_init() requires */

static const char *const mode_names[MPS2_PIL_MODES] = {"IDLE", "S_ALIGN", "C_ALIGN", "RUN", "FAULT"};

static void write_cost(FILE *f, double insns_per_tick, unsigned long periods)
{
    const mps2_pil_cost_t *cost = mps2_pil_cost();
    unsigned m;
    fprintf(f, "pil_cost 1\n");
    fprintf(f, "periods %lu\n", periods);
    fprintf(f, "instructions_per_tick %.6f\n", insns_per_tick);
    fprintf(f, "sizeof_pmstep_t %u\n", (unsigned)sizeof(pmstep_t));
    fprintf(f, "sizeof_pmstep_config_t %u\n", (unsigned)sizeof(pmstep_config_t));
    for (m = 0; m < MPS2_PIL_MODES; ++m) {
        if (cost->steps[m] > 0u) {
            /* step bracket minus empty bracket, plus the empty function's one instruction (BX LR) */
            const double n = (double)cost->steps[m];
            const double insns =
                ((double)cost->step_ticks[m] - (double)cost->empty_ticks[m]) * insns_per_tick / n + 1.0;
            fprintf(f,
                    "mode %s steps %lu step_ticks %llu empty_ticks %llu instructions_mean %.2f stack_max_bytes %lu\n",
                    mode_names[m], (unsigned long)cost->steps[m], (unsigned long long)cost->step_ticks[m],
                    (unsigned long long)cost->empty_ticks[m], insns, (unsigned long)cost->stack_max_bytes[m]);
        }
    }
}

int main(int argc, char **argv)
{
    FILE *in;
    FILE *out;
    uint32_t head[SIL_RECORD_HEADER_WORDS];
    uint32_t w[SIL_RECORD_PERIOD_WORDS];
    uint32_t out_words[SIL_RECORD_OUT_WORDS];
    unsigned long periods = 0;
    unsigned long commands = 0;
    double insns_per_tick;
    pmstep_status_t st;

    if (argc < 3) {
        fprintf(stderr, "usage: pil-replay RECORD OUTPUTS [COST]\n");
        return 2;
    }
    in = fopen(argv[1], "rb");
    out = fopen(argv[2], "wb");
    if (in == NULL || out == NULL) {
        fprintf(stderr, "pil-replay: cannot open '%s' or '%s'\n", argv[1], argv[2]);
        return 2;
    }
    /* Few, large semihosting transfers instead of one per period. */
    (void)setvbuf(in, NULL, _IOFBF, IO_BUFFER_BYTES);
    (void)setvbuf(out, NULL, _IOFBF, IO_BUFFER_BYTES);

    if (sil_record_read_words(in, head, SIL_RECORD_HEADER_WORDS) != 0 || sil_record_check_header(head) != 0) {
        fprintf(stderr, "pil-replay: '%s' is not a version %u SIL record\n", argv[1], SIL_RECORD_VERSION);
        return 2;
    }
    sil_record_config_from_words(&head[5], &config);
    st = pmstep_init(&motor, &config);
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-replay: pmstep_init: %s\n", pmstep_status_str(st));
        return 2;
    }
    (void)pmstep_set_id_target(&motor, sil_record_float(head[5u + SIL_RECORD_CONFIG_WORDS]));
    (void)pmstep_start(&motor);
    mps2_pil_init(&motor);
    insns_per_tick = mps2_pil_instructions_per_tick(1000000u);

    out_words[0] = PIL_OUTPUT_MAGIC;
    out_words[1] = SIL_RECORD_VERSION;
    out_words[2] = (uint32_t)SIL_RECORD_OUT_WORDS;
    if (sil_record_write_words(out, out_words, 3u) != 0) {
        fprintf(stderr, "pil-replay: write error\n");
        return 2;
    }
    for (;;) {
        uint32_t tag;
        if (sil_record_read_words(in, &tag, 1u) != 0) {
            fprintf(stderr, "pil-replay: record truncated after %lu periods\n", periods);
            return 2;
        }
        if (tag == SIL_RECORD_TAG_SPEED_TARGET) {
            if (sil_record_read_words(in, w, 2u) != 0) {
                fprintf(stderr, "pil-replay: record truncated in a command\n");
                return 2;
            }
            (void)pmstep_set_speed_target(&motor, sil_record_float(w[0]), sil_record_float(w[1]));
            ++commands;
        } else if (tag == SIL_RECORD_TAG_PERIOD) {
            pmstep_meas_t meas;
            pmstep_output_t o;
            if (sil_record_read_words(in, w, SIL_RECORD_PERIOD_WORDS) != 0) {
                fprintf(stderr, "pil-replay: record truncated in period %lu\n", periods);
                return 2;
            }
            sil_record_meas_from_words(w, &meas);
            mps2_pil_control_period(&meas, &o);
            sil_record_output_to_words(&o, out_words);
            if (sil_record_write_words(out, out_words, SIL_RECORD_OUT_WORDS) != 0) {
                fprintf(stderr, "pil-replay: write error in period %lu\n", periods);
                return 2;
            }
            ++periods;
        } else if (tag == SIL_RECORD_TAG_END) {
            if (sil_record_read_words(in, w, 1u) != 0 || w[0] != periods) {
                fprintf(stderr, "pil-replay: the record's period count does not match (%lu read)\n", periods);
                return 2;
            }
            break;
        } else {
            fprintf(stderr, "pil-replay: unknown tag %lu after %lu periods\n", (unsigned long)tag, periods);
            return 2;
        }
    }
    out_words[0] = PIL_OUTPUT_END;
    out_words[1] = (uint32_t)periods;
    if (sil_record_write_words(out, out_words, 2u) != 0 || fclose(out) != 0) {
        fprintf(stderr, "pil-replay: write error at the end\n");
        return 2;
    }
    fclose(in);
    printf("pil-replay: %lu periods, %lu speed commands replayed through pmstep_step on the target\n", periods,
           commands);
    if (argc >= 4) {
        FILE *cost = fopen(argv[3], "w");
        if (cost == NULL) {
            fprintf(stderr, "pil-replay: cannot write '%s'\n", argv[3]);
            return 2;
        }
        write_cost(cost, insns_per_tick, periods);
        fclose(cost);
    }
    write_cost(stdout, insns_per_tick, periods);
    return 0;
}
