/*
 * pil-compare: compares the outputs the target computed in the replay (pil-replay's
 * output file) with the host's outputs in the SIL record, period by period and word
 * by word. Exit 0 only when every word is bit-identical; otherwise prints, for each
 * output, the number of differing periods, the first one, and the largest difference
 * in ULP (float words) or in value (integer words).
 *
 * usage: pil-compare RECORD TARGET_OUTPUTS
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "pil_record.h"

/* Distance in units in the last place between two binary32 values (0 for +0/-0). */
static uint64_t ulp_distance(uint32_t a, uint32_t b)
{
    const int64_t ia = (a & 0x80000000u) ? -(int64_t)(a & 0x7FFFFFFFu) : (int64_t)a;
    const int64_t ib = (b & 0x80000000u) ? -(int64_t)(b & 0x7FFFFFFFu) : (int64_t)b;
    return (uint64_t)(ia > ib ? ia - ib : ib - ia);
}

int main(int argc, char **argv)
{
    FILE *rec;
    FILE *tgt;
    uint32_t head[SIL_RECORD_HEADER_WORDS];
    uint32_t w[SIL_RECORD_PERIOD_WORDS];
    uint32_t t[SIL_RECORD_OUT_WORDS];
    unsigned long differing[SIL_RECORD_OUT_WORDS] = {0};
    long first[SIL_RECORD_OUT_WORDS];
    uint64_t max_ulp[SIL_RECORD_OUT_WORDS] = {0};
    unsigned long periods = 0;
    unsigned long periods_differing = 0;
    unsigned k;

    if (argc != 3) {
        fprintf(stderr, "usage: pil-compare RECORD TARGET_OUTPUTS\n");
        return 2;
    }
    rec = fopen(argv[1], "rb");
    tgt = fopen(argv[2], "rb");
    if (rec == NULL || tgt == NULL) {
        fprintf(stderr, "pil-compare: cannot open '%s' or '%s'\n", argv[1], argv[2]);
        return 2;
    }
    if (sil_record_read_words(rec, head, SIL_RECORD_HEADER_WORDS) != 0 || sil_record_check_header(head) != 0) {
        fprintf(stderr, "pil-compare: '%s' is not a version %u SIL record\n", argv[1], SIL_RECORD_VERSION);
        return 2;
    }
    if (sil_record_read_words(tgt, t, 3u) != 0 || t[0] != PIL_OUTPUT_MAGIC || t[1] != SIL_RECORD_VERSION
        || t[2] != (uint32_t)SIL_RECORD_OUT_WORDS) {
        fprintf(stderr, "pil-compare: '%s' is not a pil-replay output file\n", argv[2]);
        return 2;
    }
    for (k = 0; k < SIL_RECORD_OUT_WORDS; ++k) {
        first[k] = -1;
    }
    for (;;) {
        uint32_t tag;
        if (sil_record_read_words(rec, &tag, 1u) != 0) {
            fprintf(stderr, "pil-compare: record truncated\n");
            return 2;
        }
        if (tag == SIL_RECORD_TAG_SPEED_TARGET) {
            if (sil_record_read_words(rec, w, 2u) != 0) {
                fprintf(stderr, "pil-compare: record truncated\n");
                return 2;
            }
        } else if (tag == SIL_RECORD_TAG_PERIOD) {
            const uint32_t *host = &w[SIL_RECORD_IN_WORDS];
            int any = 0;
            if (sil_record_read_words(rec, w, SIL_RECORD_PERIOD_WORDS) != 0
                || sil_record_read_words(tgt, t, SIL_RECORD_OUT_WORDS) != 0) {
                fprintf(stderr, "pil-compare: a file ends before period %lu\n", periods);
                return 1;
            }
            for (k = 0; k < SIL_RECORD_OUT_WORDS; ++k) {
                if (host[k] != t[k]) {
                    const uint64_t d = pil_output_word_is_float(k)
                                           ? ulp_distance(host[k], t[k])
                                           : (uint64_t)(host[k] > t[k] ? host[k] - t[k] : t[k] - host[k]);
                    any = 1;
                    if (differing[k]++ == 0u) {
                        first[k] = (long)periods;
                    }
                    if (d > max_ulp[k]) {
                        max_ulp[k] = d;
                    }
                }
            }
            periods_differing += (unsigned long)any;
            ++periods;
        } else if (tag == SIL_RECORD_TAG_END) {
            if (sil_record_read_words(rec, w, 1u) != 0 || w[0] != periods || sil_record_read_words(tgt, t, 2u) != 0
                || t[0] != PIL_OUTPUT_END || t[1] != periods) {
                fprintf(stderr, "pil-compare: period counts differ (record %lu)\n", periods);
                return 1;
            }
            break;
        } else {
            fprintf(stderr, "pil-compare: unknown tag %lu in the record\n", (unsigned long)tag);
            return 2;
        }
    }
    fclose(rec);
    fclose(tgt);

    printf("pil-compare: %lu periods, %u output words each: %lu periods differ\n", periods,
           (unsigned)SIL_RECORD_OUT_WORDS, periods_differing);
    for (k = 0; k < SIL_RECORD_OUT_WORDS; ++k) {
        if (differing[k] != 0u) {
            printf("  %-22s %lu periods differ, first at period %ld, largest difference %llu %s\n",
                   pil_output_word_name(k), differing[k], first[k], (unsigned long long)max_ulp[k],
                   pil_output_word_is_float(k) ? "ULP" : "(integer)");
        }
    }
    if (periods == 0u) {
        printf("pil-compare: the record has no period\n");
        return 1;
    }
    if (periods_differing != 0u) {
        return 1;
    }
    printf("pil-compare: target and host outputs are bit-identical (largest difference 0 ULP)\n");
    return 0;
}
