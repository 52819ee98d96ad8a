/* A flash for the store's tests: see fake_flash.h. */
#include "fake_flash.h"

#include <string.h>

/* 1: the operation runs whole; 0: it is the one the power cut stops half-way; -1: no power. */
static int power_for_op(fake_flash_t *f)
{
    if (!f->powered) {
        return -1;
    }
    if (f->budget > 0) {
        --f->budget;
        if (f->budget == 0) {
            f->powered = false;
            f->budget = -1;
            return 0;
        }
    }
    return 1;
}

static int32_t flash_erase(void *ctx, uint32_t slot)
{
    fake_flash_t *f = ctx;
    int power;
    uint32_t u;
    if (slot > 1u) {
        return -1;
    }
    power = power_for_op(f);
    if (power < 0) {
        return -2;
    }
    if (power > 0 && f->fail_erase) {
        f->fail_erase = 0;
        return -3;
    }
    f->erases++;
    for (u = 0; u < FAKE_FLASH_UNITS; ++u) {
        /* Cut half-way: the first half erased, the unit at the cut torn, the rest as it was. */
        if (power > 0 || u < FAKE_FLASH_UNITS / 2u) {
            memset(&f->bytes[slot][u * 8u], 0xFF, 8u);
            f->torn[slot][u] = false;
            f->written[slot][u] = false;
        } else if (u == FAKE_FLASH_UNITS / 2u) {
            memset(&f->bytes[slot][u * 8u], 0x5A, 8u);
            f->torn[slot][u] = true;
        }
    }
    return power > 0 ? 0 : -2;
}

static int32_t flash_program(void *ctx, uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n)
{
    fake_flash_t *f = ctx;
    uint32_t k;
    if (slot > 1u || offset % 8u != 0u || n % 8u != 0u || offset + n > FAKE_FLASH_SLOT_BYTES) {
        return -1;
    }
    for (k = 0; k < n; k += 8u) {
        const uint32_t u = (offset + k) / 8u;
        const int power = power_for_op(f);
        if (power < 0) {
            return -2;
        }
        if (power == 0) { /* half its bits, and an ECC error on reading it */
            memcpy(&f->bytes[slot][u * 8u], &data[k], 4u);
            f->torn[slot][u] = true;
            f->written[slot][u] = true;
            return -2;
        }
        if (f->fail_program_at >= 0 && (uint32_t)f->fail_program_at == f->programs) {
            f->programs++;
            return -4;
        }
        if (f->written[slot][u]) {
            return -5; /* a unit programmed twice without an erase */
        }
        f->programs++;
        memcpy(&f->bytes[slot][u * 8u], &data[k], 8u);
        f->written[slot][u] = true;
    }
    return 0;
}

static int32_t flash_read(void *ctx, uint32_t slot, uint32_t offset, uint8_t *data, uint32_t n)
{
    fake_flash_t *f = ctx;
    uint32_t u;
    if (!f->powered) {
        return -2;
    }
    if (slot > 1u || offset + n > FAKE_FLASH_SLOT_BYTES) {
        return -1;
    }
    memcpy(data, &f->bytes[slot][offset], n);
    for (u = offset / 8u; u * 8u < offset + n; ++u) {
        if (f->torn[slot][u]) {
            return -6; /* ECC: two or more bits wrong in this double word */
        }
    }
    return 0;
}

void fake_flash_init(fake_flash_t *f)
{
    memset(f, 0, sizeof *f);
    memset(f->bytes, 0xFF, sizeof f->bytes);
    f->budget = -1;
    f->powered = true;
    f->fail_program_at = -1;
    f->ops.slot_bytes = FAKE_FLASH_SLOT_BYTES;
    f->ops.erase = flash_erase;
    f->ops.program = flash_program;
    f->ops.read = flash_read;
    f->ops.ctx = f;
}

void fake_flash_cut_after(fake_flash_t *f, long n) { f->budget = n; }

void fake_flash_power_on(fake_flash_t *f)
{
    f->powered = true;
    f->budget = -1;
}
