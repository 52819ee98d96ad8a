/*
 * A flash for the store's tests (pmstep_store_flash_t): two slots in RAM that behave as NOR flash
 * with ECC does. An erase sets every byte to 0xFF; a program writes an erased 8-byte unit once
 * (over a unit not erased it fails, as the STM32G4's PROGERR); a unit whose program or erase was cut
 * short by a power loss holds garbage and reads with an uncorrectable error until erased again.
 * A power cut is injected by a budget of operations: the operation that exhausts it is cut half-way
 * and every later one fails (the power is gone) until fake_flash_power_on().
 */
#ifndef FAKE_FLASH_H
#define FAKE_FLASH_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep_store.h"

#define FAKE_FLASH_SLOT_BYTES 2048u
#define FAKE_FLASH_UNITS (FAKE_FLASH_SLOT_BYTES / PMSTEP_STORE_PROGRAM_UNIT)

typedef struct {
    uint8_t bytes[2][FAKE_FLASH_SLOT_BYTES];
    bool torn[2][FAKE_FLASH_UNITS];    /**< unit reads with an uncorrectable error */
    bool written[2][FAKE_FLASH_UNITS]; /**< unit programmed since its erase */
    long budget;                       /**< operations left before the cut; < 0: no cut planned */
    bool powered;
    unsigned erases;
    unsigned programs;
    int32_t fail_program_at; /**< the program of this index (from 0) reports an error, -1: none */
    int32_t fail_erase;      /**< the next erase reports an error without erasing (1) */
    pmstep_store_flash_t ops;
} fake_flash_t;

/** Both slots erased, no cut planned, powered. */
void fake_flash_init(fake_flash_t *f);

/** Cut the power in the middle of the @p n-th erase or program from now (n >= 1). */
void fake_flash_cut_after(fake_flash_t *f, long n);

/** Power back on (a reset): what the cut left stays. */
void fake_flash_power_on(fake_flash_t *f);

#endif
