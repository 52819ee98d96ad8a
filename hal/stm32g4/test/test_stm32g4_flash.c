/*
 * The STM32G431 port's flash driver (stm32g4_flash.c) on the behavioural model of the flash
 * (stm32g4_model_flash.c): its register sequences, each FLASH_SR error by its own code, the
 * timeout, ECC errors on read; then the stored configuration (pmstep_store.c) on that driver: a
 * save and a load across a reset, a power cut at every erase and program step of a save, an ECC
 * error, an injected PROGERR, a full slot, a record of a future format. Prints the save time.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_console.h"
#include "pmstep_hal_stm32g4.h"
#include "pmstep_store.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"

#define F stm32g4_model_flash
#define SLOT_ADDR(slot) (PMSTEP_STM32G4_STORE_ADDR + (slot)*STM32G4_FLASH_PAGE_BYTES)

static const pmstep_store_flash_t *flash;
static pmstep_config_t board;
static pmstep_store_t store;

/* A fresh part, the chip out of reset; the board's configuration as the application makes it. */
static int setup(void **state)
{
    pmstep_stm32g4_config_t port;
    (void)state;
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all();
    port = pmstep_stm32g4_default_config();
    board = pmstep_console_app_config(pmstep_stm32g4_period_s(&port), 1u, pmstep_stm32g4_current_sense_range_A(&port),
                                      pmstep_stm32g4_bus_sense_range_V(&port));
    flash = pmstep_stm32g4_store_flash();
    return 0;
}

/* A power cycle: the chip's registers to reset, the flash array kept; a new store on it. */
static void power_cycle(void)
{
    stm32g4_model_reset();
    assert_int_equal(pmstep_store_init(&store, flash, pmstep_stm32g4_board_id()), PMSTEP_STORE_OK);
}

static bool all_bytes(uint32_t addr, uint32_t n, uint8_t value)
{
    uint32_t k;
    for (k = 0; k < n; ++k) {
        if (*stm32g4_model_flash_bytes(addr + k) != value) {
            return false;
        }
    }
    return true;
}

/* The little-endian word the array holds at @p addr (no CPU read: no ECC check, no stall). */
static uint32_t array_word(uint32_t addr)
{
    const uint8_t *p = stm32g4_model_flash_bytes(addr);
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static bool cr_locked_and_idle(void)
{
    const uint32_t cr = stm32g4_fake.flash.CR;
    return (cr & FLASH_CR_LOCK) != 0u && (cr & (FLASH_CR_PG | FLASH_CR_PER | FLASH_CR_PNB_MASK | FLASH_CR_STRT)) == 0u
           && (stm32g4_fake.flash.SR & (FLASH_SR_ERRORS | FLASH_SR_BSY)) == 0u;
}

/* ===========================================================================
 * The driver on the model
 * ========================================================================= */

static void test_geometry_and_board_id(void **state)
{
    const char name[] = PMSTEP_STM32G4_BOARD_NAME;
    (void)state;
    assert_int_equal(flash->slot_bytes, STM32G4_FLASH_PAGE_BYTES);
    assert_true(flash->slot_bytes >= PMSTEP_STORE_RECORD_MAX_BYTES);
    assert_int_equal(SLOT_ADDR(2u), STM32G4_FLASH_MEM_BASE + STM32G4_FLASH_MEM_BYTES); /* the last two pages */
    assert_int_equal(pmstep_stm32g4_board_id(), pmstep_store_crc32(0u, (const uint8_t *)name, (uint32_t)strlen(name)));
}

/* The flash's codes: each with a text of its own (pmstep_stm32g4_status_str()). */
static void test_flash_codes_have_texts(void **state)
{
    int32_t code;
    int32_t other;
    (void)state;
    for (code = PMSTEP_STM32G4_ERR_FLASH_RANGE; code >= PMSTEP_STM32G4_ERR_FLASH_ECC; --code) {
        const char *text = pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)code);
        assert_string_not_equal(text, pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)1000));
        for (other = code + 1; other <= 0; ++other) {
            assert_string_not_equal(text, pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)other));
        }
    }
}

static void test_program_read_erase_sequences(void **state)
{
    const uint8_t data[16] = {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF,
                              0x10, 0x32, 0x54, 0x76, 0x98, 0xBA, 0xDC, 0xFE};
    uint8_t back[24];
    (void)state;
    assert_true((stm32g4_fake.flash.CR & FLASH_CR_LOCK) != 0u); /* locked out of reset */
    /* Two double words into slot 1 at offset 8: programmed in address order, each t_PROG busy. */
    assert_int_equal(flash->program(flash->ctx, 1u, 8u, data, sizeof data), 0);
    assert_true(cr_locked_and_idle());
    assert_int_equal(F.programs, 2u);
    assert_int_equal(F.steps, 2u);
    assert_int_equal(F.busy_ticks, 2u * STM32G4_MODEL_FLASH_PROGRAM_TICKS);
    assert_memory_equal(stm32g4_model_flash_bytes(SLOT_ADDR(1u) + 8u), data, sizeof data);
    assert_true(all_bytes(SLOT_ADDR(1u), 8u, 0xFFu));
    assert_true(all_bytes(SLOT_ADDR(1u) + 24u, STM32G4_FLASH_PAGE_BYTES - 24u, 0xFFu));
    assert_true(all_bytes(SLOT_ADDR(0u), STM32G4_FLASH_PAGE_BYTES, 0xFFu)); /* the other slot untouched */
    /* Read back from an unaligned offset, across word boundaries. */
    assert_int_equal(flash->read(flash->ctx, 1u, 5u, back, 21u), 0);
    assert_true(back[0] == 0xFFu && back[1] == 0xFFu && back[2] == 0xFFu);
    assert_memory_equal(&back[3], data, sizeof data);
    assert_true(back[19] == 0xFFu && back[20] == 0xFFu);
    /* Erase slot 1 (page 63): all 0xFF, t_ERASE busy, the data cache reset and enabled again. */
    assert_int_equal(flash->erase(flash->ctx, 1u), 0);
    assert_true(cr_locked_and_idle());
    assert_int_equal(F.erases, 1u);
    assert_int_equal(F.busy_ticks, 2u * STM32G4_MODEL_FLASH_PROGRAM_TICKS + STM32G4_MODEL_FLASH_ERASE_TICKS);
    assert_true(all_bytes(SLOT_ADDR(1u), STM32G4_FLASH_PAGE_BYTES, 0xFFu));
    assert_int_equal(F.dcache_resets, 1u);
    assert_true((stm32g4_fake.flash.ACR & FLASH_ACR_DCEN) != 0u);
    assert_true((stm32g4_fake.flash.ACR & FLASH_ACR_DCRST) == 0u);
    assert_int_equal(F.bus_errors, 0u);
}

/* A double word programmed twice without an erase: PROGERR (RM0440 §3.7.5), unless the data is
 * all 0; the flag is cleared by the driver and the next operation works. */
static void test_program_over_data_is_progerr(void **state)
{
    const uint8_t a[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    const uint8_t b[8] = {8, 7, 6, 5, 4, 3, 2, 1};
    const uint8_t zero[8] = {0};
    (void)state;
    assert_int_equal(flash->program(flash->ctx, 0u, 64u, a, 8u), 0);
    assert_int_equal(flash->program(flash->ctx, 0u, 64u, b, 8u), PMSTEP_STM32G4_ERR_FLASH_PROGERR);
    assert_memory_equal(stm32g4_model_flash_bytes(SLOT_ADDR(0u) + 64u), a, 8u);
    assert_true(cr_locked_and_idle());
    assert_int_equal(flash->program(flash->ctx, 0u, 64u, zero, 8u), 0); /* the all-0 exception */
    assert_memory_equal(stm32g4_model_flash_bytes(SLOT_ADDR(0u) + 64u), zero, 8u);
    assert_int_equal(flash->erase(flash->ctx, 0u), 0);
    assert_int_equal(flash->program(flash->ctx, 0u, 64u, b, 8u), 0);
    assert_memory_equal(stm32g4_model_flash_bytes(SLOT_ADDR(0u) + 64u), b, 8u);
}

/* Each FLASH_SR error flag, injected into a program and into an erase, returns its own code. */
static void test_each_error_flag_its_own_code(void **state)
{
    static const struct {
        uint32_t flag;
        int32_t code;
    } cases[] = {
        {FLASH_SR_PROGERR, PMSTEP_STM32G4_ERR_FLASH_PROGERR}, {FLASH_SR_WRPERR, PMSTEP_STM32G4_ERR_FLASH_WRPERR},
        {FLASH_SR_PGAERR, PMSTEP_STM32G4_ERR_FLASH_PGAERR},   {FLASH_SR_SIZERR, PMSTEP_STM32G4_ERR_FLASH_SIZERR},
        {FLASH_SR_PGSERR, PMSTEP_STM32G4_ERR_FLASH_PGSERR},   {FLASH_SR_MISERR, PMSTEP_STM32G4_ERR_FLASH_MISERR},
        {FLASH_SR_FASTERR, PMSTEP_STM32G4_ERR_FLASH_FASTERR}, {FLASH_SR_OPERR, PMSTEP_STM32G4_ERR_FLASH_OPERR},
        {FLASH_SR_RDERR, PMSTEP_STM32G4_ERR_FLASH_RDERR},     {FLASH_SR_OPTVERR, PMSTEP_STM32G4_ERR_FLASH_OPTVERR},
    };
    const size_t n = sizeof cases / sizeof cases[0];
    const uint8_t data[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
    size_t k;
    size_t j;
    (void)state;
    for (k = 0; k < n; ++k) {
        for (j = 0; j < k; ++j) {
            assert_int_not_equal(cases[k].code, cases[j].code);
        }
        assert_true(cases[k].code < 0);
        assert_int_not_equal(cases[k].code, PMSTEP_STM32G4_ERR_FLASH_TIMEOUT);
        stm32g4_model_reset();
        F.inject_step = 1u;
        F.inject_flags = cases[k].flag;
        assert_int_equal(flash->program(flash->ctx, 1u, 0u, data, 8u), cases[k].code);
        assert_true(all_bytes(SLOT_ADDR(1u), 8u, 0xFFu)); /* nothing programmed */
        assert_true(cr_locked_and_idle());                /* flag cleared, FLASH_CR locked again */
        F.inject_step = 2u;
        assert_int_equal(flash->erase(flash->ctx, 1u), cases[k].code);
        assert_int_equal(F.erases, 0u);
        assert_true(cr_locked_and_idle());
    }
    /* Two flags at once: the cause (PROGERR) before the PGSERR that goes with it. */
    stm32g4_model_reset();
    F.inject_step = 1u;
    F.inject_flags = FLASH_SR_PROGERR | FLASH_SR_PGSERR;
    assert_int_equal(flash->program(flash->ctx, 1u, 0u, data, 8u), PMSTEP_STM32G4_ERR_FLASH_PROGERR);
}

/* The model's sequence rules, by writes the driver never makes (RM0440 §3.3.7, §3.7.5). */
static void unlock_by_keys(void)
{
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, KEYR), FLASH_KEY1);
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, KEYR), FLASH_KEY2);
    assert_true((stm32g4_fake.flash.CR & FLASH_CR_LOCK) == 0u);
}

static void clear_flags(void)
{
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, SR), FLASH_SR_ERRORS | FLASH_SR_EOP);
    assert_int_equal(stm32g4_fake.flash.SR & FLASH_SR_ERRORS, 0u);
}

static void test_model_programming_sequence_errors(void **state)
{
    const uint32_t a = SLOT_ADDR(0u);
    (void)state;
    /* No PG: PGSERR, nothing latched. */
    stm32g4_model_flash_write(a, 0x12345678u, 4u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_PGSERR);
    unlock_by_keys();
    clear_flags();
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_PG);
    /* A half-word write: SIZERR. */
    stm32g4_model_flash_write(a, 0x1234u, 2u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_SIZERR);
    /* While a programming error flag is set, any program write: PGSERR. */
    stm32g4_model_flash_write(a, 0x12345678u, 4u);
    assert_true((stm32g4_fake.flash.SR & FLASH_SR_PGSERR) != 0u);
    clear_flags();
    /* A first word not 8-aligned, or a second word elsewhere than the next: PGAERR. */
    stm32g4_model_flash_write(a + 4u, 0x12345678u, 4u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_PGAERR);
    clear_flags();
    stm32g4_model_flash_write(a, 0x12345678u, 4u);
    stm32g4_model_flash_write(a + 12u, 0x9ABCDEF0u, 4u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_PGAERR);
    clear_flags();
    assert_int_equal(F.steps, 0u);
    assert_true(all_bytes(a, 16u, 0xFFu));
    /* Both words: BSY for t_PROG; a write meanwhile is a sequence error; then EOP stays clear
     * (EOPIE = 0). */
    stm32g4_model_flash_write(a, 0x12345678u, 4u);
    assert_false(stm32g4_model_flash_busy()); /* the first word only latched */
    stm32g4_model_flash_write(a + 4u, 0x9ABCDEF0u, 4u);
    assert_true((stm32g4_fake.flash.SR & FLASH_SR_BSY) != 0u);
    stm32g4_model_flash_write(a + 8u, 0u, 4u);
    assert_true((stm32g4_fake.flash.SR & FLASH_SR_PGSERR) != 0u);
    stm32g4_model_flash_advance(STM32G4_MODEL_FLASH_PROGRAM_TICKS - 1u);
    assert_true(stm32g4_model_flash_busy());
    stm32g4_model_flash_advance(1u);
    assert_false(stm32g4_model_flash_busy());
    assert_int_equal(stm32g4_fake.flash.SR & (FLASH_SR_BSY | FLASH_SR_EOP), 0u);
    assert_int_equal(array_word(a), 0x12345678u);
    clear_flags();
    /* With EOPIE, EOP at the end; with ERRIE, OPERR along with an error. */
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_PG | FLASH_CR_EOPIE | FLASH_CR_ERRIE);
    stm32g4_model_flash_write(a + 8u, 0x0u, 4u);
    stm32g4_model_flash_write(a + 12u, 0x1u, 4u);
    stm32g4_model_flash_advance(STM32G4_MODEL_FLASH_PROGRAM_TICKS);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_EOP);
    stm32g4_model_flash_write(a + 8u, 0x5u, 1u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_EOP | FLASH_SR_SIZERR | FLASH_SR_OPERR);
    clear_flags();
    /* PG with PER: a program write and an erase start are both sequence errors. */
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_PG | FLASH_CR_PER);
    stm32g4_model_flash_write(a + 16u, 0x0u, 4u);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_PGSERR);
    clear_flags();
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR),
                                 FLASH_CR_PG | FLASH_CR_PER | (62u << FLASH_CR_PNB_POS) | FLASH_CR_STRT);
    assert_int_equal(stm32g4_fake.flash.SR, FLASH_SR_PGSERR);
    assert_false(stm32g4_model_flash_busy());
    assert_int_equal(stm32g4_fake.flash.CR & FLASH_CR_STRT, 0u);
    /* An erase start while a programming error flag is set: PGSERR, nothing erased. */
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_PER | (62u << FLASH_CR_PNB_POS));
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR),
                                 FLASH_CR_PER | (62u << FLASH_CR_PNB_POS) | FLASH_CR_STRT);
    assert_false(stm32g4_model_flash_busy());
    assert_int_equal(array_word(a), 0x12345678u);
    /* Cleared: the erase starts; a read of the flash meanwhile waits for its end (§3.3.5). */
    clear_flags();
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR),
                                 FLASH_CR_PER | (62u << FLASH_CR_PNB_POS) | FLASH_CR_STRT);
    assert_true(stm32g4_model_flash_busy());
    assert_int_equal(stm32g4_model_flash_read(a), 0xFFFFFFFFu);
    assert_int_equal(F.stalled_reads, 1u);
    assert_int_equal(F.busy_ticks, STM32G4_MODEL_FLASH_PROGRAM_TICKS * 2u + STM32G4_MODEL_FLASH_ERASE_TICKS);
    assert_int_equal(stm32g4_fake.flash.CR & FLASH_CR_STRT, 0u);
    /* FLASH_CR locked again by writing LOCK: later writes do nothing. */
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_LOCK);
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, CR), FLASH_CR_PG);
    assert_int_equal(stm32g4_fake.flash.CR & FLASH_CR_PG, 0u);
}

/* A wrong key locks FLASH_CR until the reset (§3.3.5): the driver reports it; after a reset it works. */
static void test_wrong_key_locks_until_reset(void **state)
{
    (void)state;
    stm32g4_fake_flash_reg_write(offsetof(stm32g4_flash_t, KEYR), FLASH_KEY2);
    assert_int_equal(F.bus_errors, 1u);
    assert_int_equal(flash->erase(flash->ctx, 0u), PMSTEP_STM32G4_ERR_FLASH_LOCKED);
    assert_int_equal(F.steps, 0u);
    stm32g4_model_reset();
    assert_int_equal(flash->erase(flash->ctx, 0u), 0);
    assert_int_equal(F.erases, 1u);
}

/* BSY never clears: the driver gives up after its bound, well after any erase could end. */
static void test_timeout(void **state)
{
    (void)state;
    F.stuck_busy = true;
    assert_int_equal(flash->erase(flash->ctx, 0u), PMSTEP_STM32G4_ERR_FLASH_TIMEOUT);
    assert_true(F.busy_ticks > 10u * (uint64_t)STM32G4_MODEL_FLASH_ERASE_TICKS);
    assert_int_equal(F.erases, 0u);
}

/* Out of the slots, or not whole double words: refused before any register is touched. */
static void test_range_checks(void **state)
{
    uint8_t buf[16] = {0};
    (void)state;
    assert_int_equal(flash->erase(flash->ctx, 2u), PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(flash->program(flash->ctx, 0u, 4u, buf, 8u), PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(flash->program(flash->ctx, 0u, 0u, buf, 12u), PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(flash->program(flash->ctx, 1u, STM32G4_FLASH_PAGE_BYTES - 8u, buf, 16u),
                     PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(flash->read(flash->ctx, 1u, STM32G4_FLASH_PAGE_BYTES - 8u, buf, 9u),
                     PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(flash->read(flash->ctx, 3u, 0u, buf, 1u), PMSTEP_STM32G4_ERR_FLASH_RANGE);
    assert_int_equal(F.steps, 0u);
    assert_true((stm32g4_fake.flash.CR & FLASH_CR_LOCK) != 0u);
}

/* A double word with an ECC double error: the read reports it through the NMI's flash part, which
 * clears ECCD; a corrected single error left in ECCR does not hide it (the driver clears ECCC). */
static void test_read_ecc_error(void **state)
{
    const uint8_t data[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
    uint8_t back[16];
    const uint32_t errors = pmstep_stm32g4_flash_ecc_errors();
    (void)state;
    assert_int_equal(flash->program(flash->ctx, 0u, 0u, data, 16u), 0);
    stm32g4_model_flash_set_ecc_error(SLOT_ADDR(0u) + 8u);
    assert_int_equal(flash->read(flash->ctx, 0u, 0u, back, 8u), 0); /* the good double word */
    stm32g4_fake.flash.ECCR = FLASH_ECCR_ECCC; /* a single error corrected elsewhere, not cleared */
    assert_int_equal(flash->read(flash->ctx, 0u, 0u, back, 16u), PMSTEP_STM32G4_ERR_FLASH_ECC);
    assert_int_equal(F.nmis, 2u); /* one per word of the double word */
    assert_int_equal(F.nmis_fatal, 0u);
    assert_int_equal(pmstep_stm32g4_flash_ecc_errors(), errors + 2u);
    assert_int_equal(stm32g4_fake.flash.ECCR & (FLASH_ECCR_ECCD | FLASH_ECCR_ECCC), 0u);
    /* Erased, the page reads without error. */
    assert_int_equal(flash->erase(flash->ctx, 0u), 0);
    assert_int_equal(flash->read(flash->ctx, 0u, 0u, back, 16u), 0);
    assert_false(stm32g4_model_flash_ecc_error(SLOT_ADDR(0u) + 8u));
}

/* An ECC double error outside the store's pages is not the store's: the NMI stays fatal, ECCD set;
 * while it is set, no further failure is recorded (§3.3.2). */
static void test_ecc_error_outside_store_is_fatal(void **state)
{
    const uint32_t code = STM32G4_FLASH_MEM_BASE + 10u * STM32G4_FLASH_PAGE_BYTES + 40u;
    (void)state;
    stm32g4_model_flash_set_ecc_error(code);
    stm32g4_model_flash_set_ecc_error(SLOT_ADDR(1u));
    (void)stm32g4_model_flash_read(code + 4u);
    assert_int_equal(F.nmis, 1u);
    assert_int_equal(F.nmis_fatal, 1u);
    assert_int_equal(stm32g4_fake.flash.ECCR, FLASH_ECCR_ECCD | (code - STM32G4_FLASH_MEM_BASE));
    assert_false(pmstep_stm32g4_flash_ecc_nmi());
    (void)stm32g4_model_flash_read(SLOT_ADDR(1u));
    assert_int_equal(F.nmis, 1u);
    assert_int_equal(stm32g4_fake.flash.ECCR, FLASH_ECCR_ECCD | (code - STM32G4_FLASH_MEM_BASE));
}

/* ===========================================================================
 * The stored configuration on the driver on the model
 * ========================================================================= */

/* A record of the board's configuration told apart by its rotor inertia (mark x 10 g m^2). */
static pmstep_store_record_t record_with(float mark)
{
    pmstep_store_record_t rec;
    memset(&rec, 0, sizeof rec);
    rec.config = board;
    rec.stepdir = pmstep_console_stepdir_defaults();
    rec.config.motor.inertia_kgm2 = 0.01f * mark;
    rec.measured.flags = PMSTEP_STORE_MEASURED_RESISTANCE;
    rec.measured.resistance_Ohm = 1.0f + mark;
    return rec;
}

/* Loads after a power cycle: @return the status; @p mark_out the loaded record's mark. */
static pmstep_store_status_t load_after_reset(float *mark_out)
{
    pmstep_store_record_t rec;
    pmstep_store_status_t st;
    power_cycle();
    memset(&rec, 0, sizeof rec);
    st = pmstep_store_load(&store, &board, &rec, NULL);
    *mark_out = rec.config.motor.inertia_kgm2 / 0.01f;
    if (st == PMSTEP_STORE_OK) {
        assert_float_equal(rec.measured.resistance_Ohm, 1.0f + *mark_out, 1e-5f);
    }
    return st;
}

static void save_ok(float mark)
{
    const pmstep_store_record_t rec = record_with(mark);
    assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_OK);
}

static void test_store_save_and_load_after_reset(void **state)
{
    const uint32_t dw = (pmstep_store_record_bytes() + 7u) / 8u;
    float mark = 0.0f;
    double save_ms;
    (void)state;
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_EMPTY);
    assert_int_equal(F.steps, 0u);
    save_ok(1.5f);
    /* One page erase and the record's double words, each checked; nothing else. */
    assert_int_equal(F.erases, 1u);
    assert_int_equal(F.programs, dw);
    assert_int_equal(F.busy_ticks, STM32G4_MODEL_FLASH_ERASE_TICKS + (uint64_t)dw * STM32G4_MODEL_FLASH_PROGRAM_TICKS);
    assert_true(cr_locked_and_idle());
    save_ms = 1e3 * (double)F.busy_ticks / (double)STM32G4_MODEL_TICKS_PER_S;
    printf("[ SAVE     ] one record on the model: %.2f ms busy (page erase %.2f ms + %u double words x %.1f us), "
           "%u bytes\n",
           save_ms, 1e3 * (double)STM32G4_MODEL_FLASH_ERASE_TICKS / (double)STM32G4_MODEL_TICKS_PER_S, (unsigned)dw,
           1e6 * (double)STM32G4_MODEL_FLASH_PROGRAM_TICKS / (double)STM32G4_MODEL_TICKS_PER_S,
           (unsigned)pmstep_store_record_bytes());
    /* The first record in slot 0 (page 62), its magic first. */
    assert_int_equal(array_word(SLOT_ADDR(0u)), PMSTEP_STORE_MAGIC);
    assert_true(all_bytes(SLOT_ADDR(1u), STM32G4_FLASH_PAGE_BYTES, 0xFFu));
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 1.5f, 1e-5f);
    assert_int_equal(store.slot, 0);
    assert_int_equal(store.sequence, 1u);
    /* The next save goes to the other slot; the newest wins after a reset. */
    save_ok(2.5f);
    assert_int_equal(array_word(SLOT_ADDR(1u)), PMSTEP_STORE_MAGIC);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 2.5f, 1e-5f);
    assert_int_equal(store.slot, 1);
    assert_int_equal(store.sequence, 2u);
}

/* Records A (slot 0, sequence 1) and B (slot 1, sequence 2) on a fresh part, after a reset. */
static void two_records(void)
{
    float mark;
    pmstep_store_record_t none;
    stm32g4_model_flash_erase_all();
    power_cycle();
    assert_int_equal(pmstep_store_load(&store, &board, &none, NULL), PMSTEP_STORE_EMPTY);
    save_ok(1.0f);
    save_ok(2.0f);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 2.0f, 1e-5f);
}

/* After a cut: B is still the newest record; the next save (into A's slot) works and wins. */
static void after_cut_b_then_next_save_works(void)
{
    float mark = 0.0f;
    assert_false(F.powered);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 2.0f, 1e-5f);
    assert_int_equal(store.slot, 1);
    assert_int_equal(store.sequence, 2u);
    save_ok(3.0f);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 3.0f, 1e-5f);
    assert_int_equal(store.slot, 0);
    assert_int_equal(store.sequence, 3u);
}

/* A power cut at every step of a save: the erase of the older record's page (cut at several
 * points of the page), then each double word's program, the CRC's last. */
static void test_store_power_cut_at_every_step(void **state)
{
    const uint32_t dw = (pmstep_store_record_bytes() + 7u) / 8u;
    const uint32_t erased_before_cut[] = {
        0u, 1u, dw / 2u, dw - 1u, dw, STM32G4_MODEL_FLASH_PAGE_DW / 2u, STM32G4_MODEL_FLASH_PAGE_DW - 1u};
    const pmstep_store_record_t c = record_with(3.0f);
    uint32_t step;
    size_t k;
    unsigned cuts = 0u;
    (void)state;
    for (k = 0; k < sizeof erased_before_cut / sizeof erased_before_cut[0]; ++k) {
        two_records();
        F.cut_at_step = 1u; /* the erase */
        F.cut_erase_dw = erased_before_cut[k];
        (void)pmstep_store_save(&store, &c, true); /* the chip is off: its result means nothing */
        assert_int_equal(F.erases, 0u);
        after_cut_b_then_next_save_works();
        cuts++;
    }
    for (step = 2u; step <= dw + 1u; ++step) {
        two_records();
        F.cut_at_step = step; /* the program of double word step - 2 */
        (void)pmstep_store_save(&store, &c, true);
        assert_int_equal(F.erases, 1u);
        assert_int_equal(F.programs, step - 2u);
        assert_true(stm32g4_model_flash_ecc_error(SLOT_ADDR(0u) + 8u * (step - 2u))); /* the torn one */
        after_cut_b_then_next_save_works();
        cuts++;
    }
    assert_int_equal(cuts, 7u + dw);
}

/* An ECC error in the newest record: its slot is taken as holding none, the other record is used;
 * the next save erases the bad page and writes there. */
static void test_store_ecc_error_uses_other_record(void **state)
{
    float mark = 0.0f;
    (void)state;
    two_records();
    stm32g4_model_flash_set_ecc_error(SLOT_ADDR(1u) + 8u * 3u);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 1.0f, 1e-5f);
    assert_int_equal(store.slot, 0);
    assert_int_equal(store.flash_error, PMSTEP_STM32G4_ERR_FLASH_ECC);
    assert_int_equal(F.nmis_fatal, 0u);
    save_ok(4.0f);
    assert_false(stm32g4_model_flash_ecc_error(SLOT_ADDR(1u) + 8u * 3u));
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 4.0f, 1e-5f);
    assert_int_equal(store.sequence, 2u); /* the record after A's */
}

/* PROGERR on the third double word of a save: PMSTEP_STORE_ERR_FLASH, the previous record stays. */
static void test_store_progerr_keeps_previous(void **state)
{
    const pmstep_store_record_t c = record_with(3.0f);
    float mark = 0.0f;
    (void)state;
    two_records();
    F.inject_step = 4u; /* step 1 the erase, 2.. the programs */
    F.inject_flags = FLASH_SR_PROGERR;
    assert_int_equal(pmstep_store_save(&store, &c, true), PMSTEP_STORE_ERR_FLASH);
    assert_int_equal(store.flash_error, PMSTEP_STM32G4_ERR_FLASH_PROGERR);
    assert_int_equal(F.programs, 2u);
    assert_true(cr_locked_and_idle());
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 2.0f, 1e-5f);
}

/* A slot full of data (not a record): programming over it fails with PROGERR; a save there works,
 * the store erasing first. */
static void test_store_save_over_full_slot(void **state)
{
    uint8_t junk[STM32G4_FLASH_PAGE_BYTES];
    float mark = 0.0f;
    uint32_t k;
    (void)state;
    for (k = 0; k < sizeof junk; ++k) {
        junk[k] = (uint8_t)(k * 7u + 3u);
    }
    assert_int_equal(flash->program(flash->ctx, 0u, 0u, junk, sizeof junk), 0);
    assert_int_equal(flash->program(flash->ctx, 0u, 0u, junk, 8u), PMSTEP_STM32G4_ERR_FLASH_PROGERR);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_EMPTY);
    save_ok(1.5f); /* slot 0 again: no valid record anywhere */
    assert_int_equal(F.erases, 1u);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_OK);
    assert_float_equal(mark, 1.5f, 1e-5f);
    assert_int_equal(store.slot, 0);
}

/* A record of a future format version, valid CRC, in the newest slot: refused as such, the older
 * record not used in its place. */
static void test_store_future_format_refused(void **state)
{
    const pmstep_store_record_t b = record_with(2.0f);
    uint8_t image[PMSTEP_STORE_RECORD_MAX_BYTES];
    float mark = 0.0f;
    uint32_t n;
    uint32_t crc;
    (void)state;
    power_cycle();
    save_ok(1.0f); /* slot 0, sequence 1 */
    memset(image, 0xFF, sizeof image);
    n = pmstep_store_encode(&b, pmstep_stm32g4_board_id(), 2u, image);
    image[4] = (uint8_t)(PMSTEP_STORE_FORMAT_VERSION + 1u);
    image[5] = 0u;
    crc = pmstep_store_crc32(0u, image, n - 4u);
    image[n - 4u] = (uint8_t)crc;
    image[n - 3u] = (uint8_t)(crc >> 8);
    image[n - 2u] = (uint8_t)(crc >> 16);
    image[n - 1u] = (uint8_t)(crc >> 24);
    assert_int_equal(flash->erase(flash->ctx, 1u), 0);
    assert_int_equal(flash->program(flash->ctx, 1u, 0u, image, (n + 7u) & ~7u), 0);
    assert_int_equal(load_after_reset(&mark), PMSTEP_STORE_ERR_FORMAT);
    assert_int_equal(store.slot, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_geometry_and_board_id, setup),
        cmocka_unit_test_setup(test_flash_codes_have_texts, setup),
        cmocka_unit_test_setup(test_program_read_erase_sequences, setup),
        cmocka_unit_test_setup(test_program_over_data_is_progerr, setup),
        cmocka_unit_test_setup(test_each_error_flag_its_own_code, setup),
        cmocka_unit_test_setup(test_model_programming_sequence_errors, setup),
        cmocka_unit_test_setup(test_wrong_key_locks_until_reset, setup),
        cmocka_unit_test_setup(test_timeout, setup),
        cmocka_unit_test_setup(test_range_checks, setup),
        cmocka_unit_test_setup(test_read_ecc_error, setup),
        cmocka_unit_test_setup(test_ecc_error_outside_store_is_fatal, setup),
        cmocka_unit_test_setup(test_store_save_and_load_after_reset, setup),
        cmocka_unit_test_setup(test_store_power_cut_at_every_step, setup),
        cmocka_unit_test_setup(test_store_ecc_error_uses_other_record, setup),
        cmocka_unit_test_setup(test_store_progerr_keeps_previous, setup),
        cmocka_unit_test_setup(test_store_save_over_full_slot, setup),
        cmocka_unit_test_setup(test_store_future_format_refused, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
