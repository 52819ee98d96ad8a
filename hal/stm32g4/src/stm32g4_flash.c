/*
 * The stored configuration's flash on the STM32G431xB (pmstep_stm32g4_store_flash()): two slots,
 * the last two 2 KiB pages of the single 128 KiB bank, erased by page and programmed by double
 * word through the FLASH registers (RM0440 chapter 3 "Embedded flash memory (FLASH)"; register
 * and bit facts in stm32g4_regs.h). Every wait is bounded; every FLASH_SR error flag is checked
 * after each operation and reported by its own code; FLASH_CR is locked again after each one.
 */
#include <stddef.h>

#include "pmstep_hal_stm32g4.h"
#include "pmstep_store.h"
#include "stm32g4_regs.h"

/* Polls of FLASH_SR.BSY before giving up. A poll (a load from the AHB register, the test, the
 * branch and the count) takes at least 4 CPU cycles: 4 000 000 polls are at least 94 ms at
 * 170 MHz, several times the longest page erase of the datasheet (DS12589, t_ERASE: 22 ms typical). */
#define FLASH_WAIT_LIMIT 4000000u

#define SLOT_BYTES STM32G4_FLASH_PAGE_BYTES
#define STORE_END (PMSTEP_STM32G4_STORE_ADDR + PMSTEP_STM32G4_STORE_SLOTS * SLOT_BYTES)

STM32G4_STATIC_ASSERT(PMSTEP_STM32G4_STORE_ADDR
                          == STM32G4_FLASH_MEM_BASE + PMSTEP_STM32G4_STORE_FIRST_PAGE * STM32G4_FLASH_PAGE_BYTES,
                      store_addr_is_first_page);
STM32G4_STATIC_ASSERT(STORE_END == STM32G4_FLASH_MEM_BASE + STM32G4_FLASH_MEM_BYTES, store_is_last_pages);
STM32G4_STATIC_ASSERT(SLOT_BYTES >= PMSTEP_STORE_RECORD_MAX_BYTES, slot_holds_a_record);

/* Double ECC errors in the store's pages: counted by the NMI (on the hardware, ECCD raises it at
 * once) or by a read that finds ECCD still set. A read compares it before and after. */
static volatile uint32_t ecc_errors;

static uint32_t slot_addr(uint32_t slot)
{
    return PMSTEP_STM32G4_STORE_ADDR + slot * SLOT_BYTES;
}

/* The code of the first error flag in @p sr: the cause of a failed operation before PGSERR,
 * which the flash also sets when an operation follows an error (RM0440 §3.7.5). */
static int32_t status_of_flags(uint32_t sr)
{
    static const struct {
        uint32_t flag;
        pmstep_stm32g4_status_t status;
    } causes[] = {
        {FLASH_SR_PROGERR, PMSTEP_STM32G4_ERR_FLASH_PROGERR}, {FLASH_SR_WRPERR, PMSTEP_STM32G4_ERR_FLASH_WRPERR},
        {FLASH_SR_PGAERR, PMSTEP_STM32G4_ERR_FLASH_PGAERR},   {FLASH_SR_SIZERR, PMSTEP_STM32G4_ERR_FLASH_SIZERR},
        {FLASH_SR_MISERR, PMSTEP_STM32G4_ERR_FLASH_MISERR},   {FLASH_SR_FASTERR, PMSTEP_STM32G4_ERR_FLASH_FASTERR},
        {FLASH_SR_PGSERR, PMSTEP_STM32G4_ERR_FLASH_PGSERR},   {FLASH_SR_OPERR, PMSTEP_STM32G4_ERR_FLASH_OPERR},
        {FLASH_SR_RDERR, PMSTEP_STM32G4_ERR_FLASH_RDERR},     {FLASH_SR_OPTVERR, PMSTEP_STM32G4_ERR_FLASH_OPTVERR},
    };
    size_t k;
    for (k = 0; k < sizeof causes / sizeof causes[0]; ++k) {
        if ((sr & causes[k].flag) != 0u) {
            return (int32_t)causes[k].status;
        }
    }
    return 0;
}

/* Waits until no operation runs (FLASH_SR.BSY clear). */
static int32_t wait_not_busy(void)
{
    uint32_t n;
    for (n = 0; n < FLASH_WAIT_LIMIT; ++n) {
        STM32G4_WAIT_HOOK(); /* nothing on the target; the host tests' flash model */
        if ((STM32G4_FLASH->SR & FLASH_SR_BSY) == 0u) {
            return 0;
        }
    }
    return (int32_t)PMSTEP_STM32G4_ERR_FLASH_TIMEOUT;
}

/* The end of an operation: BSY clear, then its error flags read and cleared (writing 1), EOP too. */
static int32_t finish_operation(void)
{
    uint32_t sr;
    const int32_t st = wait_not_busy();
    if (st != 0) {
        return st;
    }
    sr = STM32G4_FLASH->SR;
    if ((sr & (FLASH_SR_ERRORS | FLASH_SR_EOP)) != 0u) {
        STM32G4_FLASH_REG_WRITE(SR, sr & (FLASH_SR_ERRORS | FLASH_SR_EOP));
    }
    return status_of_flags(sr);
}

/* The start of an operation (RM0440 §3.3.6, §3.3.7, steps 1 and 2): no operation running, FLASH_CR
 * unlocked (§3.3.5: KEY1 then KEY2 into FLASH_KEYR), and the error flags of anything before
 * cleared, or the flash would refuse the operation with PGSERR. OPTVERR is among them: the flash
 * may set it at the option bytes' load. */
static int32_t begin(void)
{
    const int32_t st = wait_not_busy();
    if (st != 0) {
        return st;
    }
    if ((STM32G4_FLASH->CR & FLASH_CR_LOCK) != 0u) {
        STM32G4_FLASH_REG_WRITE(KEYR, FLASH_KEY1);
        STM32G4_FLASH_REG_WRITE(KEYR, FLASH_KEY2);
        if ((STM32G4_FLASH->CR & FLASH_CR_LOCK) != 0u) {
            return (int32_t)PMSTEP_STM32G4_ERR_FLASH_LOCKED;
        }
    }
    STM32G4_FLASH_REG_WRITE(SR, FLASH_SR_ERRORS | FLASH_SR_EOP);
    return 0;
}

/* PG, PER and the page number cleared, FLASH_CR locked again (LOCK is set by writing 1). */
static void end(void)
{
    STM32G4_FLASH_REG_WRITE(CR,
                            (STM32G4_FLASH->CR & ~(FLASH_CR_PG | FLASH_CR_PER | FLASH_CR_PNB_MASK)) | FLASH_CR_LOCK);
}

/* After an erase: the data cache may hold lines of the page as it was, which a read of the slot
 * would return; it is reset (FLASH_ACR.DCRST, writable only while DCEN = 0, §3.7.1) and enabled
 * again. The instruction cache holds no line of the store's pages (no code there). */
static void data_cache_reset(void)
{
    const uint32_t acr = STM32G4_FLASH->ACR;
    if ((acr & FLASH_ACR_DCEN) != 0u) {
        STM32G4_FLASH_REG_WRITE(ACR, acr & ~FLASH_ACR_DCEN);
        STM32G4_FLASH_REG_WRITE(ACR, (acr & ~FLASH_ACR_DCEN) | FLASH_ACR_DCRST);
        STM32G4_FLASH_REG_WRITE(ACR, acr & ~FLASH_ACR_DCRST);
    }
}

/* Page erase of slot @p slot (RM0440 §3.3.6 "Flash main memory erase sequences", page erase):
 * PER with the page in PNB (PG, MER1 and FSTPG clear, or the flash sets PGSERR), then STRT. */
static int32_t flash_erase(void *ctx, uint32_t slot)
{
    int32_t st;
    (void)ctx;
    if (slot >= PMSTEP_STM32G4_STORE_SLOTS) {
        return (int32_t)PMSTEP_STM32G4_ERR_FLASH_RANGE;
    }
    st = begin();
    if (st == 0) {
        const uint32_t page = PMSTEP_STM32G4_STORE_FIRST_PAGE + slot;
        const uint32_t cr = STM32G4_FLASH->CR & ~(FLASH_CR_PG | FLASH_CR_MER1 | FLASH_CR_FSTPG | FLASH_CR_PNB_MASK);
        STM32G4_FLASH_REG_WRITE(CR, cr | FLASH_CR_PER | (page << FLASH_CR_PNB_POS));
        STM32G4_FLASH_REG_WRITE(CR, cr | FLASH_CR_PER | (page << FLASH_CR_PNB_POS) | FLASH_CR_STRT);
        st = finish_operation();
    }
    end();
    data_cache_reset();
    return st;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* Programs whole double words (RM0440 §3.3.7 "Flash main memory programming sequences", standard
 * programming): PG set (PER, MER1, FSTPG clear), then per double word its first 32-bit word at the
 * aligned address and its second at the next word, which starts the program; BSY waited for and
 * the error flags checked after each. */
static int32_t flash_program(void *ctx, uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n)
{
    int32_t st;
    uint32_t k;
    (void)ctx;
    if (slot >= PMSTEP_STM32G4_STORE_SLOTS || offset > SLOT_BYTES || n > SLOT_BYTES - offset
        || offset % STM32G4_FLASH_DOUBLE_WORD_BYTES != 0u || n % STM32G4_FLASH_DOUBLE_WORD_BYTES != 0u
        || (data == NULL && n > 0u)) {
        return (int32_t)PMSTEP_STM32G4_ERR_FLASH_RANGE;
    }
    st = begin();
    if (st == 0) {
        STM32G4_FLASH_REG_WRITE(
            CR,
            (STM32G4_FLASH->CR & ~(FLASH_CR_PER | FLASH_CR_MER1 | FLASH_CR_FSTPG | FLASH_CR_PNB_MASK)) | FLASH_CR_PG);
    }
    for (k = 0; st == 0 && k < n; k += STM32G4_FLASH_DOUBLE_WORD_BYTES) {
        const uint32_t addr = slot_addr(slot) + offset + k;
        STM32G4_FLASH_MEM_WRITE32(addr, le32(&data[k]));
        STM32G4_INSTRUCTION_BARRIER(); /* two separate word writes, in this order */
        STM32G4_FLASH_MEM_WRITE32(addr + 4u, le32(&data[k + 4u]));
        st = finish_operation();
    }
    end();
    return st;
}

/* Reads with 32-bit loads. A double word with two or more bits wrong sets FLASH_ECCR.ECCD (and
 * raises the NMI, which pmstep_stm32g4_flash_ecc_nmi() takes); the flash records a failure only
 * while ECCC and ECCD are both clear (§3.3.2), so both are cleared first: a corrected single error
 * left over from elsewhere would otherwise hide a double error here. */
static int32_t flash_read(void *ctx, uint32_t slot, uint32_t offset, uint8_t *data, uint32_t n)
{
    uint32_t before;
    uint32_t eccr;
    uint32_t k = 0u;
    (void)ctx;
    if (slot >= PMSTEP_STM32G4_STORE_SLOTS || offset > SLOT_BYTES || n > SLOT_BYTES - offset
        || (data == NULL && n > 0u)) {
        return (int32_t)PMSTEP_STM32G4_ERR_FLASH_RANGE;
    }
    STM32G4_FLASH_REG_WRITE(ECCR, (STM32G4_FLASH->ECCR & FLASH_ECCR_ECCIE) | FLASH_ECCR_ECCC | FLASH_ECCR_ECCD);
    before = ecc_errors;
    while (k < n) {
        const uint32_t addr = slot_addr(slot) + offset + k;
        const uint32_t word_addr = addr & ~3u;
        const uint32_t word = STM32G4_FLASH_MEM_READ32(word_addr);
        uint32_t b;
        for (b = addr - word_addr; b < 4u && k < n; ++b) {
            data[k++] = (uint8_t)((word >> (8u * b)) & 0xFFu);
        }
    }
    /* ECCD still set: taken by no NMI (the host model without one); counted and cleared here. */
    eccr = STM32G4_FLASH->ECCR;
    if ((eccr & FLASH_ECCR_ECCD) != 0u) {
        const uint32_t failed = STM32G4_FLASH_MEM_BASE + (eccr & FLASH_ECCR_ADDR_ECC_MASK);
        if ((eccr & FLASH_ECCR_SYSF_ECC) == 0u && failed >= PMSTEP_STM32G4_STORE_ADDR && failed < STORE_END) {
            STM32G4_FLASH_REG_WRITE(ECCR, (eccr & FLASH_ECCR_ECCIE) | FLASH_ECCR_ECCD);
            ecc_errors++;
        }
    }
    return ecc_errors != before ? (int32_t)PMSTEP_STM32G4_ERR_FLASH_ECC : 0;
}

bool pmstep_stm32g4_flash_ecc_nmi(void)
{
    const uint32_t eccr = STM32G4_FLASH->ECCR;
    const uint32_t failed = STM32G4_FLASH_MEM_BASE + (eccr & FLASH_ECCR_ADDR_ECC_MASK);
    if ((eccr & FLASH_ECCR_ECCD) == 0u || (eccr & FLASH_ECCR_SYSF_ECC) != 0u || failed < PMSTEP_STM32G4_STORE_ADDR
        || failed >= STORE_END) {
        return false;
    }
    /* ECCD cleared (writing 1; ECCC written 0 is left as it is); the read in progress sees the count. */
    STM32G4_FLASH_REG_WRITE(ECCR, (eccr & FLASH_ECCR_ECCIE) | FLASH_ECCR_ECCD);
    ecc_errors++;
    return true;
}

uint32_t pmstep_stm32g4_flash_ecc_errors(void)
{
    return ecc_errors;
}

static const pmstep_store_flash_t store_flash = {SLOT_BYTES, flash_erase, flash_program, flash_read, NULL};

const pmstep_store_flash_t *pmstep_stm32g4_store_flash(void)
{
    return &store_flash;
}

uint32_t pmstep_stm32g4_board_id(void)
{
    static const char name[] = PMSTEP_STM32G4_BOARD_NAME;
    return pmstep_store_crc32(0u, (const uint8_t *)name, (uint32_t)(sizeof name - 1u));
}
