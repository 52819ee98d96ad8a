/**
 * @file pmstep_store.h
 * @brief The drive's stored configuration: a record of the whole pmstep_config_t and of the STEP/DIR
 *        settings (every value of the console's configuration table, by id) and of what commissioning
 *        measured, with a format version, the board's id, the table's layout id and a CRC-32, kept in
 *        two flash slots written alternately. C99, no heap, no stdio; portable (a port gives it its
 *        flash through pmstep_store_flash_t).
 *
 * Record (little-endian, PMSTEP_STORE_HEADER_BYTES of header, then the values, then the CRC):
 *
 *     offset  size  field
 *          0     4  magic PMSTEP_STORE_MAGIC ("PMSR")
 *          4     2  format version (PMSTEP_STORE_FORMAT_VERSION)
 *          6     2  header bytes (32)
 *          8     4  board id (the port's: which board and sensing the record was made for)
 *         12     4  layout id: CRC-32 of the configuration table's names and types, in id order
 *         16     4  sequence: 1 for the first record saved, +1 for each save after it
 *         20     2  value count n (the configuration table's length)
 *         22     2  measured count m (PMSTEP_STORE_MEASURED_VALUES)
 *         24     4  record bytes (header + 4 n + 4 m + 4)
 *         28     4  reserved, 0
 *         32   4 n  the configuration's values, f32 each, in table order (integers and booleans as
 *                   exact floats, as GET_CONFIG reads them): the core's configuration and the STEP/DIR
 *                   settings (pmstep_stepdir_settings_t, the table's stepdir.* entries)
 *     32+4n    4 m  what the configuration was measured with: flags u32 (PMSTEP_STORE_MEASURED_*),
 *                   then offsets a/b (A), R (Ohm), L (H), k_M (N m/A), J (kg m^2), F (N m s/rad), f32
 *    32+4n+4m    4  CRC-32 (ISO-HDLC: reflected 0x04C11DB7, initial and final XOR 0xFFFFFFFF) of every
 *                   byte before it
 *
 * The same bytes travel on the console (CONFIG_READ, CONFIG_WRITE; sequence 0 there) and in the
 * flash slots. A record is accepted only whole: the right magic, format version and layout id, the
 * board's id, a good CRC, the read-only values (period, delay, sensing ranges) equal to the board's,
 * pmstep_validate_config() and pmstep_console_stepdir_validate() passing; otherwise its status names
 * why and nothing is applied. The layout id covers every entry of the table: a record of a firmware
 * whose table had other entries, or fewer (one from before the STEP/DIR settings), is refused with
 * PMSTEP_STORE_ERR_LAYOUT, never read in part.
 *
 * Slots: a save erases the slot that does not hold the newest valid record and programs the new one
 * there, CRC last; the newest valid record is the one of the higher sequence. A power cut at any
 * point of an erase or a program leaves the slot being written without a valid CRC, so the previous
 * record stays the newest valid one. Only the newest record is ever considered: when it is of another
 * format, board or layout, the store is refused, never an older record used in its place.
 */
#ifndef PMSTEP_STORE_H
#define PMSTEP_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PMSTEP_STORE_MAGIC 0x52534D50u     /**< "PMSR" in memory order (little-endian) */
#define PMSTEP_STORE_FORMAT_VERSION 1u
#define PMSTEP_STORE_HEADER_BYTES 32u
#define PMSTEP_STORE_MAX_VALUES 96u        /**< configuration table entries a record can hold */
#define PMSTEP_STORE_MEASURED_VALUES 8u    /**< flags and seven values */
/** The largest record, rounded up to the 8-byte unit every flash programs in. */
#define PMSTEP_STORE_RECORD_MAX_BYTES \
    ((PMSTEP_STORE_HEADER_BYTES + 4u * PMSTEP_STORE_MAX_VALUES + 4u * PMSTEP_STORE_MEASURED_VALUES + 4u + 7u) & ~7u)
#define PMSTEP_STORE_PROGRAM_UNIT 8u       /**< bytes programmed at once: offsets and lengths are multiples */

/** Which values of pmstep_store_measured_t were measured on this motor (the others are 0). */
#define PMSTEP_STORE_MEASURED_OFFSETS 1u
#define PMSTEP_STORE_MEASURED_RESISTANCE 2u
#define PMSTEP_STORE_MEASURED_INDUCTANCE 4u
#define PMSTEP_STORE_MEASURED_TORQUE_CONSTANT 8u
#define PMSTEP_STORE_MEASURED_MECHANICS 16u  /**< J and F identified in RUN */

/** What the configuration in force was measured with (commissioning, identification). */
typedef struct {
    uint32_t flags;              /**< PMSTEP_STORE_MEASURED_* */
    float offset_a_A;
    float offset_b_A;
    float resistance_Ohm;
    float inductance_H;
    float torque_constant_Nm_A;
    float inertia_kgm2;
    float friction_Nms_rad;
} pmstep_store_measured_t;

/**
 * The STEP/DIR input's settings a drive keeps with its configuration (the console's table entries
 * stepdir.*, PMSTEP_CONSOLE_CFG_STEPDIR), as a TMC driver keeps its own: what an image in STEP/DIR
 * mode applies to its step tracker (pmstep_console_stepdir_config()) and to its EN and DIAG pins.
 * Checked by pmstep_console_stepdir_validate(); pmstep_console_stepdir_defaults() gives a TMC
 * driver's conventions.
 */
typedef struct {
    uint32_t microsteps;                    /**< microsteps per full step, 1..PMSTEP_STEPDIR_MAX_MICROSTEPS: the
                                                 controller's setting for this axis */
    bool invert_direction;                  /**< DIR's sense reversed (counts down while DIR is high) */
    bool enable_active_high;                /**< EN enables the drive while high; false: while low (a TMC driver's
                                                 EN) */
    bool diag_active_high;                  /**< DIAG high while asserted (a TMC2209's DIAG); false: low */
    uint32_t diag_mode;                     /**< DIAG's mode: PMSTEP_DIAG_LEVEL (0) or PMSTEP_DIAG_PULSE (1) */
    float following_error_limit_full_steps; /**< DIAG beyond this following error, in full steps of the motor
                                                 (pi / (2 p) mechanical rad each; > 0, the designer's 1) */
    float stall_current_A;                  /**< homing on DIAG: a stall at this q current (or at the following-error
                                                 limit) drops the steps toward the block (pmstep_stepdir.h); 0 = off,
                                                 else below max_phase_current_A (the designer's homing: half the rated
                                                 current) */
} pmstep_stepdir_settings_t;

/** A record's contents. */
typedef struct {
    pmstep_config_t config;
    pmstep_store_measured_t measured;
    pmstep_stepdir_settings_t stepdir;
} pmstep_store_record_t;

/** Outcomes: one per cause. Disjoint from pmstep_status_t's codes, so that an ACK's status names
 *  either. */
typedef enum {
    PMSTEP_STORE_OK = 0,
    PMSTEP_STORE_EMPTY = -140,         /**< no record in either slot (never saved, or erased) */
    PMSTEP_STORE_ERR_CRC = -141,       /**< the record's CRC does not match its bytes */
    PMSTEP_STORE_ERR_FORMAT = -142,    /**< a record of another format version (another firmware) */
    PMSTEP_STORE_ERR_LAYOUT = -143,    /**< a record of another configuration table (another firmware) */
    PMSTEP_STORE_ERR_BOARD = -144,     /**< a record of another board: its id or its read-only values differ */
    PMSTEP_STORE_ERR_LENGTH = -145,    /**< the record's length does not match its counts or the bytes given */
    PMSTEP_STORE_ERR_INVALID = -146,   /**< a value the configuration cannot take (an integer or boolean not
                                            exact), or a configuration pmstep_validate_config() or
                                            pmstep_console_stepdir_validate() refuses */
    PMSTEP_STORE_ERR_FLASH = -147,     /**< the flash reported an error (erase, program, or an uncorrectable
                                            read); the previous record stays in force */
    PMSTEP_STORE_ERR_VERIFY = -148,    /**< the slot read back differs from what was programmed */
    PMSTEP_STORE_ERR_BRIDGE_ON = -149, /**< a flash write asked for while the bridge may switch */
    PMSTEP_STORE_ERR_SLOT_SIZE = -150, /**< the port's slots are smaller than a record */
    PMSTEP_STORE_ERR_NULL = -151       /**< a NULL argument, or no flash given */
} pmstep_store_status_t;

/**
 * The flash a port lends the store: two slots, each one erase unit (a page) of at least
 * PMSTEP_STORE_RECORD_MAX_BYTES. Every function returns 0, or a negative code of the port's
 * (kept in pmstep_store_t::flash_error for the report). Called from the main loop only, with the
 * bridge off; each may take as long as the flash needs (a page erase is tens of milliseconds).
 */
typedef struct {
    uint32_t slot_bytes;
    /** Erases slot 0 or 1 (every byte then reads 0xFF). */
    int32_t (*erase)(void *ctx, uint32_t slot);
    /** Programs @p n bytes from @p data at @p offset of a slot erased since; @p offset and @p n are
     *  multiples of PMSTEP_STORE_PROGRAM_UNIT. */
    int32_t (*program)(void *ctx, uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n);
    /** Reads @p n bytes at @p offset of a slot; negative if the memory could not read them (an
     *  uncorrectable ECC error, e.g. a double word cut short by a power loss). */
    int32_t (*read)(void *ctx, uint32_t slot, uint32_t offset, uint8_t *data, uint32_t n);
    void *ctx;
} pmstep_store_flash_t;

/** A store on a port's flash. */
typedef struct {
    const pmstep_store_flash_t *flash;
    uint32_t board_id;
    int32_t slot;          /**< slot of the newest valid record, -1: none */
    uint32_t sequence;     /**< its sequence (0: none) */
    int32_t flash_error;   /**< the port's code of the last flash error (0: none) */
} pmstep_store_t;

/** CRC-32 (ISO-HDLC) of @p n bytes, continuing from @p crc (start with 0). */
uint32_t pmstep_store_crc32(uint32_t crc, const uint8_t *data, uint32_t n);

/** The layout id of this firmware's configuration table (CRC-32 of its names and types). */
uint32_t pmstep_store_layout_id(void);

/** The size in bytes of this firmware's record. */
uint32_t pmstep_store_record_bytes(void);

/**
 * Encodes @p rec into @p out (room for pmstep_store_record_bytes()) for @p board_id, with @p sequence.
 * @return the record's length in bytes.
 */
uint32_t pmstep_store_encode(const pmstep_store_record_t *rec, uint32_t board_id, uint32_t sequence,
                             uint8_t *out);

/**
 * Decodes the record of @p n bytes at @p in, made for @p board_id, into @p rec: every value over
 * @p board (the board's own configuration), whose read-only values the record's must equal; then
 * validates the configuration and the STEP/DIR settings. @p rec is written only when the whole record
 * is accepted.
 * @param validation if not NULL: pmstep_validate_config()'s or pmstep_console_stepdir_validate()'s
 *        status when that is what refused it.
 * @param sequence if not NULL: the record's sequence.
 */
pmstep_store_status_t pmstep_store_decode(const uint8_t *in, uint32_t n, uint32_t board_id,
                                          const pmstep_config_t *board, pmstep_store_record_t *rec,
                                          pmstep_status_t *validation, uint32_t *sequence);

/** A store on @p flash for @p board_id; nothing read yet. */
pmstep_store_status_t pmstep_store_init(pmstep_store_t *s, const pmstep_store_flash_t *flash, uint32_t board_id);

/**
 * Finds the newest record of either slot (the valid one of the higher sequence) and decodes it as
 * pmstep_store_decode() does. @p rec is written only when it is accepted.
 * @return PMSTEP_STORE_OK, PMSTEP_STORE_EMPTY (no valid record: both slots erased or torn), or why the
 *         newest record was refused.
 */
pmstep_store_status_t pmstep_store_load(pmstep_store_t *s, const pmstep_config_t *board, pmstep_store_record_t *rec,
                                        pmstep_status_t *validation);

/**
 * Saves @p rec: encoded with the next sequence, programmed into the slot that does not hold the
 * newest valid record (erased first), read back and compared. @p bridge_off must say that the
 * bridge cannot switch (the caller's check: the motor IDLE or in FAULT, the outputs off).
 * @return PMSTEP_STORE_OK, or why not; on any error the previous record stays the newest valid one.
 */
pmstep_store_status_t pmstep_store_save(pmstep_store_t *s, const pmstep_store_record_t *rec, bool bridge_off);

/** Erases both slots (the store is then empty). */
pmstep_store_status_t pmstep_store_erase(pmstep_store_t *s, bool bridge_off);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_STORE_H */
