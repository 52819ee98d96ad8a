/*
 * Behavioural model of the STM32G431's flash (see stm32g4_model.h, "Flash"): the controller's
 * registers and the 128 KiB array with an ECC state per double word. Every rule names the section
 * of ST RM0440 (Rev 8) chapter 3 "Embedded flash memory (FLASH)" it follows; the times are the
 * datasheet's (DS12589). Power cuts and failures are injected by the test.
 *
 * Not modelled: fast programming (FSTPG), mass erase (MER1), option bytes and their loading
 * (OPTVERR), write protection and PCROP (WRPERR, RDERR only by injection), ECC single errors
 * (ECCC), the power-down modes, the ART caches' contents (only the rule of their reset bits), the
 * bus stall of instruction fetches during an operation (the CPU runs the driver's loop on), and
 * the physics of an interrupted erase (all the cells of a page move at once: the model erases the
 * page in address order up to the cut instead).
 */
#include <string.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"

stm32g4_model_flash_t stm32g4_model_flash;

#define F stm32g4_model_flash
#define REGS (&stm32g4_fake.flash)
#define DW_COUNT (STM32G4_FLASH_MEM_BYTES / STM32G4_FLASH_DOUBLE_WORD_BYTES)

#define OP_NONE 0u
#define OP_ERASE 1u
#define OP_PROGRAM 2u

/* The array and its ECC state survive stm32g4_model_reset(): the flash is non-volatile. */
static uint8_t mem[STM32G4_FLASH_MEM_BYTES];
static bool ecc_bad[DW_COUNT]; /* reads with an uncorrectable error (two or more bits wrong) */

static bool in_array(uint32_t addr)
{
    return addr >= STM32G4_FLASH_MEM_BASE && addr - STM32G4_FLASH_MEM_BASE < STM32G4_FLASH_MEM_BYTES;
}

static uint32_t dw_of(uint32_t addr)
{
    return (addr - STM32G4_FLASH_MEM_BASE) / STM32G4_FLASH_DOUBLE_WORD_BYTES;
}

/* FLASH_SR as software reads it: the flags, and BSY while an operation runs (§3.7.5). */
static void publish(void)
{
    REGS->SR = F.sr | (F.op != OP_NONE ? FLASH_SR_BSY : 0u);
    REGS->KEYR = 0u; /* write-only: reads 0 */
}

/* An error ends the access or operation (§3.7.5); with ERRIE, OPERR is set too (§3.7.5 OPERR,
 * §3.6 "FLASH interrupts"). */
static void raise(uint32_t flags)
{
    F.sr |= flags;
    if ((REGS->CR & FLASH_CR_ERRIE) != 0u) {
        F.sr |= FLASH_SR_OPERR;
    }
    publish();
}

void stm32g4_model_flash_reset(void)
{
    memset(&F, 0, sizeof F);
    F.poll_ticks = 170u;
    F.cut_erase_dw = STM32G4_MODEL_FLASH_PAGE_DW / 2u;
    F.inject_flags = FLASH_SR_PROGERR;
    F.powered = true;
    /* §3.7.6: FLASH_CR resets to 0xC000 0000 (LOCK, OPTLOCK); §3.7.5, §3.7.7: no flag. */
    REGS->CR = FLASH_CR_LOCK | FLASH_CR_OPTLOCK;
    REGS->ECCR = 0u;
    publish();
}

void stm32g4_model_flash_erase_all(void)
{
    memset(mem, 0xFF, sizeof mem);
    memset(ecc_bad, 0, sizeof ecc_bad);
}

const uint8_t *stm32g4_model_flash_bytes(uint32_t addr)
{
    return in_array(addr) ? &mem[addr - STM32G4_FLASH_MEM_BASE] : NULL;
}

void stm32g4_model_flash_set_ecc_error(uint32_t addr)
{
    if (in_array(addr)) {
        ecc_bad[dw_of(addr)] = true;
    }
}

bool stm32g4_model_flash_ecc_error(uint32_t addr)
{
    return in_array(addr) && ecc_bad[dw_of(addr)];
}

bool stm32g4_model_flash_busy(void)
{
    return F.op != OP_NONE;
}

/* ---------------------------------------------------------------------------
 * Operations end: §3.3.6 (page erase: every bit of the page to 1), §3.3.7 (program: the double
 * word written with its ECC), §3.7.5 (BSY cleared at the end; EOP set only with EOPIE), §3.7.6
 * (STRT cleared by hardware with BSY).
 * ------------------------------------------------------------------------- */
static void complete(void)
{
    if (F.op == OP_ERASE) {
        memset(&mem[F.op_index * STM32G4_FLASH_PAGE_BYTES], 0xFF, STM32G4_FLASH_PAGE_BYTES);
        memset(&ecc_bad[F.op_index * STM32G4_MODEL_FLASH_PAGE_DW], 0, STM32G4_MODEL_FLASH_PAGE_DW * sizeof(bool));
        F.erases++;
    } else if (F.op == OP_PROGRAM) {
        uint8_t *p = &mem[F.op_index * STM32G4_FLASH_DOUBLE_WORD_BYTES];
        unsigned b;
        for (b = 0; b < 8u; ++b) {
            p[b] = (uint8_t)((F.op_data[b / 4u] >> (8u * (b % 4u))) & 0xFFu);
        }
        ecc_bad[F.op_index] = false; /* data and ECC bits written together */
        F.programs++;
    }
    F.op = OP_NONE;
    REGS->CR &= ~FLASH_CR_STRT;
    if ((REGS->CR & FLASH_CR_EOPIE) != 0u) {
        F.sr |= FLASH_SR_EOP;
    }
    publish();
}

void stm32g4_model_flash_advance(uint64_t ticks)
{
    uint64_t d;
    if (F.op == OP_NONE || !F.powered) {
        return;
    }
    if (F.stuck_busy) {
        F.busy_ticks += ticks;
        return;
    }
    d = ticks < F.op_left ? ticks : F.op_left;
    F.busy_ticks += d;
    F.op_left -= d;
    if (F.op_left == 0u) {
        complete();
    }
}

/* ---------------------------------------------------------------------------
 * Power cut in the middle of a step: the chip stops there. A double word cut while programming
 * holds some of its new bits (here: its first word's cleared bits) and reads with an ECC double
 * error until erased; a page cut while erasing is erased up to cut_erase_dw double words, the
 * double word at the cut is torn (garbage, ECC error), the rest is as it was. Then nothing reaches
 * the flash until the reset; FLASH_SR reads 0 (the driver runs on in the test, its result
 * meaningless: on the hardware it would not run at all).
 * ------------------------------------------------------------------------- */
static void power_cut_program(uint32_t dw, const uint32_t data[2])
{
    uint8_t *p = &mem[dw * STM32G4_FLASH_DOUBLE_WORD_BYTES];
    unsigned b;
    for (b = 0; b < 4u; ++b) {
        p[b] &= (uint8_t)((data[0] >> (8u * b)) & 0xFFu);
    }
    ecc_bad[dw] = true;
}

static void power_cut_erase(uint32_t page)
{
    const uint32_t first = page * STM32G4_MODEL_FLASH_PAGE_DW;
    const uint32_t done = F.cut_erase_dw < STM32G4_MODEL_FLASH_PAGE_DW ? F.cut_erase_dw : STM32G4_MODEL_FLASH_PAGE_DW;
    memset(&mem[first * STM32G4_FLASH_DOUBLE_WORD_BYTES], 0xFF, done * STM32G4_FLASH_DOUBLE_WORD_BYTES);
    memset(&ecc_bad[first], 0, done * sizeof(bool));
    if (done < STM32G4_MODEL_FLASH_PAGE_DW) {
        memset(&mem[(first + done) * STM32G4_FLASH_DOUBLE_WORD_BYTES], 0x5A, STM32G4_FLASH_DOUBLE_WORD_BYTES);
        ecc_bad[first + done] = true;
    }
}

static void power_off(void)
{
    F.powered = false;
    F.op = OP_NONE;
    F.latched = false;
    F.sr = 0u;
    publish();
}

/* A program or erase step starts: counted; the planned cut or injected failure happens here.
 * @return true if the step goes on. */
static bool step_starts(void)
{
    F.steps++;
    if (F.cut_at_step != 0u && F.steps == F.cut_at_step) {
        return false; /* the caller tears its target, then power_off() */
    }
    if (F.inject_step != 0u && F.steps == F.inject_step) {
        raise(F.inject_flags); /* the failure ends the step: nothing changed */
        return false;
    }
    return true;
}

/* §3.3.6 "Flash main memory erase sequences", page erase: STRT starts the erase of page PNB with
 * PER set; it is refused with PGSERR while an operation runs, while a programming error flag of
 * before is set ("check and clear all error programming flags ... if not, PGSERR is set"), or
 * with PG, MER1 or FSTPG set alongside PER. */
static void erase_start(uint32_t cr)
{
    const uint32_t page = (cr & FLASH_CR_PNB_MASK) >> FLASH_CR_PNB_POS;
    if (F.op != OP_NONE || (F.sr & FLASH_SR_PROGRAMMING_ERRORS) != 0u
        || (cr & (FLASH_CR_PG | FLASH_CR_MER1 | FLASH_CR_FSTPG)) != 0u || (cr & FLASH_CR_PER) == 0u) {
        REGS->CR &= ~FLASH_CR_STRT;
        raise(FLASH_SR_PGSERR);
        return;
    }
    if (!step_starts()) {
        if (F.steps == F.cut_at_step) {
            power_cut_erase(page);
            power_off();
        }
        REGS->CR &= ~FLASH_CR_STRT;
        return;
    }
    F.op = OP_ERASE;
    F.op_index = page;
    F.op_left = STM32G4_MODEL_FLASH_ERASE_TICKS;
    publish();
}

/* ---------------------------------------------------------------------------
 * Register writes with side effects.
 * ------------------------------------------------------------------------- */
/* §3.3.5 "Flash program and erase operations", unlocking: KEY1 then KEY2 into FLASH_KEYR clear
 * LOCK; any other sequence while locked is a bus error (a hard fault) and locks FLASH_CR until the
 * next reset. A key written while unlocked is not described there; the model ignores it. */
static void key_write(uint32_t value)
{
    if (F.key_error) {
        F.bus_errors++;
        return;
    }
    if ((REGS->CR & FLASH_CR_LOCK) == 0u) {
        return;
    }
    if (F.key_step == 0u && value == FLASH_KEY1) {
        F.key_step = 1u;
    } else if (F.key_step == 1u && value == FLASH_KEY2) {
        F.key_step = 0u;
        REGS->CR &= ~FLASH_CR_LOCK;
    } else {
        F.key_step = 0u;
        F.key_error = true;
        F.bus_errors++;
    }
}

/* §3.7.6 FLASH_CR: not writable while LOCK is set; LOCK and OPTLOCK are set by writing 1 and
 * cleared only by their key sequences; STRT is set by software and cleared by hardware (a 0
 * written does not clear it), and its setting starts an erase. */
static void cr_write(uint32_t value)
{
    const uint32_t old = REGS->CR;
    uint32_t cr;
    if ((old & FLASH_CR_LOCK) != 0u || F.key_error) {
        return;
    }
    cr = (value & ~(FLASH_CR_LOCK | FLASH_CR_OPTLOCK | FLASH_CR_STRT)) | (old & (FLASH_CR_OPTLOCK | FLASH_CR_STRT))
         | (value & (FLASH_CR_LOCK | FLASH_CR_OPTLOCK));
    if ((value & FLASH_CR_LOCK) != 0u) {
        F.key_step = 0u;
    }
    if ((value & FLASH_CR_STRT) != 0u && (old & FLASH_CR_STRT) == 0u) {
        REGS->CR = cr | FLASH_CR_STRT;
        erase_start(cr);
        return;
    }
    REGS->CR = cr;
}

/* §3.7.1 FLASH_ACR: a cache's reset bit can be written only while that cache is disabled. */
static void acr_write(uint32_t value)
{
    const uint32_t old = REGS->ACR;
    uint32_t acr = value;
    if ((value & FLASH_ACR_DCRST) != 0u) {
        if ((old & FLASH_ACR_DCEN) != 0u) {
            acr &= ~FLASH_ACR_DCRST;
        } else if ((old & FLASH_ACR_DCRST) == 0u) {
            F.dcache_resets++;
        }
    }
    if ((value & FLASH_ACR_ICRST) != 0u && (old & FLASH_ACR_ICEN) != 0u) {
        acr &= ~FLASH_ACR_ICRST;
    }
    REGS->ACR = acr;
}

void stm32g4_fake_flash_reg_write(uint32_t offset, uint32_t value)
{
    if (!F.powered) {
        return;
    }
    switch (offset) {
    case offsetof(stm32g4_flash_t, ACR): acr_write(value); break;
    case offsetof(stm32g4_flash_t, KEYR): key_write(value); break;
    case offsetof(stm32g4_flash_t, SR): /* §3.7.5: EOP and the error flags cleared by writing 1 */
        F.sr &= ~(value & (FLASH_SR_EOP | FLASH_SR_ERRORS));
        break;
    case offsetof(stm32g4_flash_t, CR): cr_write(value); break;
    case offsetof(stm32g4_flash_t, ECCR): /* §3.7.7: ECCC, ECCD cleared by writing 1; ECCIE read-write */
        REGS->ECCR = (REGS->ECCR & ~(value & (FLASH_ECCR_ECCC | FLASH_ECCR_ECCD)) & ~FLASH_ECCR_ECCIE)
                     | (value & FLASH_ECCR_ECCIE);
        break;
    default: break;
    }
    publish();
}

/* ---------------------------------------------------------------------------
 * The array.
 * ------------------------------------------------------------------------- */
/* §3.3.7 "Flash main memory programming sequences", standard programming, and FLASH_SR
 * (§3.7.5): with PG set, the first word written at a double-word-aligned address is latched and
 * the second, at the next word, starts the program (BSY for t_PROG).
 *   PGSERR: a write with neither PG nor FSTPG set, with PER or MER1 set alongside PG, while a
 *           programming error flag of before is set, or (a model choice: the manual describes
 *           the stall of reads only) while an operation runs; FSTPG (not modelled) likewise.
 *   SIZERR: a byte or half-word write (only double words, as two words, are programmed).
 *   PGAERR: the two words not in one double word (a first word not 8-aligned, or a second
 *           elsewhere than the next word).
 *   PROGERR: the double word does not read all 1 (it is not erased) and the data is not all 0;
 *           a double word with an ECC error is taken as not erased.
 * A failed write programs nothing and drops the latched word. */
void stm32g4_model_flash_write(uint32_t addr, uint32_t value, uint32_t bytes)
{
    const uint32_t cr = REGS->CR;
    uint32_t dw;
    uint32_t data[2];
    bool erased = true;
    unsigned b;
    if (!F.powered || !in_array(addr)) {
        return;
    }
    if (F.op != OP_NONE || (cr & FLASH_CR_PG) == 0u || (cr & (FLASH_CR_PER | FLASH_CR_MER1 | FLASH_CR_FSTPG)) != 0u
        || (F.sr & FLASH_SR_PROGRAMMING_ERRORS) != 0u) {
        F.latched = false;
        raise(FLASH_SR_PGSERR);
        return;
    }
    if (bytes != 4u) {
        F.latched = false;
        raise(FLASH_SR_SIZERR);
        return;
    }
    if (!F.latched) {
        if (addr % STM32G4_FLASH_DOUBLE_WORD_BYTES != 0u) {
            raise(FLASH_SR_PGAERR);
            return;
        }
        F.latched = true;
        F.latch_addr = addr;
        F.latch_word = value;
        return;
    }
    F.latched = false;
    if (addr != F.latch_addr + 4u) {
        raise(FLASH_SR_PGAERR);
        return;
    }
    dw = dw_of(F.latch_addr);
    data[0] = F.latch_word;
    data[1] = value;
    for (b = 0; b < 8u; ++b) {
        erased = erased && mem[dw * STM32G4_FLASH_DOUBLE_WORD_BYTES + b] == 0xFFu;
    }
    if ((!erased || ecc_bad[dw]) && (data[0] != 0u || data[1] != 0u)) {
        raise(FLASH_SR_PROGERR);
        return;
    }
    if (!step_starts()) {
        if (F.steps == F.cut_at_step) {
            power_cut_program(dw, data);
            power_off();
        }
        return;
    }
    F.op = OP_PROGRAM;
    F.op_index = dw;
    F.op_data[0] = data[0];
    F.op_data[1] = data[1];
    F.op_left = STM32G4_MODEL_FLASH_PROGRAM_TICKS;
    publish();
}

/* §3.3.5: a read of the flash while an operation runs stalls until it ends (a single bank).
 * §3.3.2 "Error code correction (ECC)", §3.7.7: a double word with two or more bits wrong sets
 * ECCD with its address in ADDR_ECC (here its byte offset from 0x0800 0000) if ECCC and ECCD are
 * both clear, else nothing is recorded; ECCD raises the NMI, which runs the port's handler (its
 * flash part, pmstep_stm32g4_flash_ecc_nmi()). The word read is what the array holds. */
uint32_t stm32g4_model_flash_read(uint32_t addr)
{
    const uint32_t word_addr = addr & ~3u;
    const uint8_t *p;
    if (!in_array(word_addr)) {
        return 0u;
    }
    if (F.op != OP_NONE && F.powered) {
        F.stalled_reads++;
        if (!F.stuck_busy) {
            stm32g4_model_flash_advance(F.op_left);
        }
    }
    p = &mem[word_addr - STM32G4_FLASH_MEM_BASE];
    if (ecc_bad[dw_of(word_addr)] && (REGS->ECCR & (FLASH_ECCR_ECCC | FLASH_ECCR_ECCD)) == 0u) {
        REGS->ECCR =
            (REGS->ECCR & ~FLASH_ECCR_ADDR_ECC_MASK) | FLASH_ECCR_ECCD | ((word_addr & ~7u) - STM32G4_FLASH_MEM_BASE);
        F.nmis++;
        if (!pmstep_stm32g4_flash_ecc_nmi()) {
            F.nmis_fatal++;
        }
    }
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

uint32_t stm32g4_fake_flash_read32(uint32_t addr)
{
    return stm32g4_model_flash_read(addr);
}

void stm32g4_fake_flash_write32(uint32_t addr, uint32_t value)
{
    stm32g4_model_flash_write(addr, value, 4u);
}

/* The driver's poll of FLASH_SR (from the wait hook): poll_ticks pass for the flash. */
void stm32g4_model_flash_poll(void)
{
    stm32g4_model_flash_advance(F.poll_ticks);
}
