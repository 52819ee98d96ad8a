/**
 * @file pmstep_console.h
 * @brief Command and telemetry interface of a pmstep drive over a byte stream (a UART):
 *        framing, parser, commands, replies and a telemetry stream. C99, no heap, no stdio,
 *        bounded work per byte; portable (the ports give it bytes and take its bytes).
 *
 * Frame (both directions):
 *
 *     0xA5 | LEN | TYPE SEQ DATA... (LEN bytes, 2..PMSTEP_CONSOLE_MAX_PAYLOAD) | CRC16 (LE)
 *
 * CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF, no reflection, no final XOR) over
 * LEN and the payload. Numbers are little-endian; floats IEEE-754 binary32, in SI units
 * (rad/s, rad/s^2, A, V, Nm, s). A reply has TYPE = request | 0x80 and the request's SEQ;
 * an error reply has TYPE 0xFF and DATA = request TYPE, error code (pmstep_console_error_t).
 * Telemetry frames (TYPE 0x90, SEQ 0) come unasked at the chosen decimation.
 *
 * Requests (DATA):
 *   0x01 HELLO              -                        -> protocol version u8, max payload u8, record
 *                              format u8 (0: no stored configuration), flags u8 (1 a store attached,
 *                              2 a motor configured), text "pmstep <version> <port>"
 *   0x02 START, 0x03 STOP, 0x04 CLEAR_FAULT  -       -> ACK: status i16, period u32
 *   0x05 SPEED_TARGET       target f32, ramp f32     -> ACK (pmstep_set_speed_target)
 *   0x06 ID_TARGET          target f32               -> ACK (pmstep_set_id_target)
 *   0x07 GET_STATUS         -                        -> STATUS (pmstep_console_encode_status)
 *   0x08 GET_CONFIG         id u8 | 0xFF name        -> id u8, type u8, flags u8 (1 read-only, 2 a STEP/DIR
 *                              setting), value f32, name
 *   0x09 SET_CONFIG         id u8 | 0xFF, value f32 [, name]  -> ACK (IDLE only, as the core is at the
 *                              boundary that applies it: else error NOT_STOPPED; the whole
 *                              configuration is validated, position gains designed again; a STEP/DIR
 *                              setting is validated with the others, pmstep_console_stepdir_validate(),
 *                              and the core left as it is)
 *   0x0A GET_COMMISSIONING  -                        -> measured u8, offset_samples u32,
 *                              realignments u32, 8 f32 (offsets a/b, R, current scale, L, k_M,
 *                              voltage biases a/b)
 *   0x0B TELEMETRY          decimation u32 (0: off)  -> ACK; then TELEMETRY frames
 *   0x0C GET_COUNTERS       -                        -> the counters, u32 each
 *   0x0D MOVE_TO            target f32, v_max f32, a_max f32 [, j_max f32]
 *                                                    -> ACK (pmstep_position_move_to; mechanical
 *                              rad, rad/s, rad/s^2, rad/s^3; j_max absent or 0: a_max varpi_0)
 *   0x0E HOLD               [a_max f32]              -> ACK (pmstep_position_hold; a_max only from
 *                              speed mode, absent = 0: refused there, -3 BAD_COMMAND_VALUE)
 *   0x0F GET_POSITION       -                        -> status i16, period u32, position f32,
 *                              position_ref f32, position_error f32 (rad, mechanical, of that
 *                              period: pmstep_get_position, pmstep_position_reference), flags u8
 *                              (1 tracked, 2 position mode, 4 moving); status -2 BAD_MODE and
 *                              zeros while not tracked
 *   0x10 SET_POSITION_ZERO  -                        -> ACK (pmstep_position_set_zero)
 *   0x11 CONFIG_READ        offset u16               -> offset u16, total u16, the bytes of the record
 *                              of the configuration in force from offset (up to 56; pmstep_store.h's
 *                              layout, sequence 0); offset 0 encodes it anew
 *   0x12 CONFIG_WRITE       offset u16, bytes        -> staged u16: bytes of a record staged, in order
 *                              (offset 0 starts a new one, any other must be the bytes staged so far:
 *                              else BAD_VALUE); answered at once
 *   0x13 CONFIG_APPLY       -                        -> ACK (IDLE only: the staged record decoded and
 *                              validated whole, then in force and the drive configured; status a
 *                              pmstep_store_status_t, or the pmstep_status_t that refused it)
 *   0x14 CONFIG_SAVE        -                        -> ACK (IDLE or FAULT, bridge off: the configuration
 *                              in force and what it was measured with, to flash; pmstep_store_status_t)
 *   0x15 CONFIG_ERASE       -                        -> ACK (IDLE or FAULT, bridge off: both slots erased;
 *                              the configuration in force stays until a reset or CONFIG_DEFAULTS)
 *   0x16 CONFIG_DEFAULTS    -                        -> ACK (IDLE only: the board's configuration with no
 *                              motor and the default STEP/DIR settings in force, the drive not configured;
 *                              the flash untouched)
 *   0x17 CONFIG_STATUS      -                        -> configured u8, boot status i16, boot validation
 *                              i16, last status i16, slot i8, sequence u32, record bytes u16, format u8,
 *                              layout id u32, board id u32; answered at once
 *   0x18 CALIBRATE          rated current f32, pole pairs u16 [, flags u8 [, detent fraction f32]]
 *                                                    -> ACK (IDLE only: self-commissioning from the rated
 *                              current, pmstep_calibrate.h; flags 1 = paper mode, else robust; detent
 *                              fraction of the holding torque, absent = 0.05); its runs follow at the
 *                              period boundaries; when done, the design is in force, the drive configured
 *                              and the record saved. STOP cancels it; while it runs, any other request
 *                              that touches the core gets BUSY
 *   0x1A HOME               direction f32, speed f32, travel f32 [, stall current f32]
 *                                                    -> ACK (pmstep_homing_start() toward direction's sign
 *                              (+1 or -1) on the designer's homing settings (pmstep_homing_design()), with
 *                              speed (rad/s; 0 = the designer's), the largest travel (rad, > 0) and the
 *                              stall current (A; absent or 0 = the designer's); runs at the period
 *                              boundaries (pmstep_console_home_period()); found, the zero is at the stop.
 *                              A position or speed command, or leaving RUN, ends it (aborted)
 *   0x1B HOME_STATUS        -                        -> status i16, period u32, state u8
 *                              (pmstep_homing_state_t), found by u8 (1 the current, 0 the following
 *                              error), stop f32 (where it was found, rad before the zero was set), position
 *                              f32 (theta-hat now, 0 while not tracked)
 *   0x19 CALIBRATE_STATUS   -                        -> stage u8, status i16, fault u8, runs u8,
 *                              identification u8, save status i16, R f32, L f32, k_M f32, J f32, F f32;
 *                              answered at once
 *   0x40 SIM_ADVANCE        periods u32              -> (simulation images only) reply when run:
 *                                                       status i16 (0), period u32
 *   0x41 SIM_FINISH         -                        -> (simulation images only) ACK, then the
 *                                                       image writes its results and exits
 *   0x42 SIM_STEPS          edges i8 per period (1..PMSTEP_CONSOLE_SIM_STEPS_MAX)  -> (simulation images
 *                              with the STEP/DIR input attached, pmstep_console_attach_sim_stepdir())
 *                              ACK: status 0 at once. The emulated STEP/DIR input: the STEP edges of each of
 *                              the next periods the image runs, DIR by the sign, onto the emulated 16-bit
 *                              step counter before the image reads it that period (it wraps as a timer's
 *                              CNT); periods beyond them get none. BUSY while edges of the last SIM_STEPS
 *                              remain, or a SIM_ADVANCE runs
 *   0x43 SIM_FOLLOW_STEPS   -                        -> (the same images) ACK: the STEP/DIR input started
 *                              afresh on the STEP/DIR settings in force at the counter's present value
 *                              (what it counted before is dropped, as EN does on a STEP/DIR image), and
 *                              the position loop follows its count from the next period
 *                              (pmstep_position_follow_steps(); status -2 BAD_MODE, nothing changed, while
 *                              not tracked). MOVE_TO, HOLD, a speed command or leaving RUN end it
 *   0x44 SIM_STEPDIR        -                        -> (the same images) period u32, steps i32 (the
 *                              input's count since it was started), edges i32 (every edge the emulated
 *                              counter took since it was attached), counter u16, flags u8 (1 following,
 *                              2 moving, 4 DIAG asserted), commanded f32 (the count's position, mechanical
 *                              rad: pmstep_stepdir_commanded()), following error f32 (the count's position
 *                              at the last update less its theta-hat: pmstep_stepdir_following_error(); 0
 *                              while not following)
 *
 * ACK status: 0 done, a negative pmstep_status_t when the core refused (e.g. -2
 * PMSTEP_ERR_BAD_MODE), and the period from which the command takes effect (the first
 * step that sees it). The position requests 0x0D..0x10, 0x1A and 0x1B need position control attached
 * (pmstep_console_attach_position); without it (an image in speed mode) they get the error
 * reply PMSTEP_CONSOLE_ERR_NO_POSITION (9). The CONFIG_* requests 0x11..0x17 need the stored
 * configuration attached (pmstep_console_attach_store), else PMSTEP_CONSOLE_ERR_NO_STORE (11); with it,
 * START on a drive with no motor configured gets PMSTEP_CONSOLE_ERR_NOT_CONFIGURED (10). CALIBRATE and
 * CALIBRATE_STATUS need self-commissioning attached too (pmstep_console_attach_calibration), else
 * PMSTEP_CONSOLE_ERR_NO_CALIBRATION (12). STATUS and TELEMETRY carry the index of the period whose step they
 * report; telemetry comes for the periods that are multiples of the decimation.
 *
 * Timing: pmstep_console_receive() runs in the main loop, never in the control interrupt.
 * Commands that touch the core wait in a one-slot mailbox and are applied by
 * pmstep_console_boundary(), which the application calls at a period boundary (between two
 * control interrupts, with that interrupt held off): a command never lands inside a step.
 * Bad input - bytes outside a frame, a length out of range, a frame cut short (no byte for
 * PMSTEP_CONSOLE_TRUNCATION_MS), a wrong CRC - is dropped and counted; a well-framed
 * request that is unknown, of the wrong length, with a non-finite value, or sent while one
 * is still waiting, gets an error reply and is counted; a refused request changes nothing (it
 * is parsed into a request of its own and enters the mailbox whole, or not at all). Nothing blocks: a full transmit
 * buffer drops the frame and counts it.
 */
#ifndef PMSTEP_CONSOLE_H
#define PMSTEP_CONSOLE_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_homing.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "pmstep_store.h"
#include "pmstep_console_config.h"
#include "pmstep/pmstep_calibrate.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PMSTEP_CONSOLE_PROTOCOL_VERSION 2u
#define PMSTEP_CONSOLE_SYNC 0xA5u
#define PMSTEP_CONSOLE_MAX_PAYLOAD 64u    /**< TYPE + SEQ + DATA */
#define PMSTEP_CONSOLE_TX_BYTES 1024u     /**< transmit ring */
#define PMSTEP_CONSOLE_TRUNCATION_MS 20u  /**< a frame silent this long is dropped */

/** Request types. */
typedef enum {
    PMSTEP_CONSOLE_HELLO = 0x01,
    PMSTEP_CONSOLE_START = 0x02,
    PMSTEP_CONSOLE_STOP = 0x03,
    PMSTEP_CONSOLE_CLEAR_FAULT = 0x04,
    PMSTEP_CONSOLE_SPEED_TARGET = 0x05,
    PMSTEP_CONSOLE_ID_TARGET = 0x06,
    PMSTEP_CONSOLE_GET_STATUS = 0x07,
    PMSTEP_CONSOLE_GET_CONFIG = 0x08,
    PMSTEP_CONSOLE_SET_CONFIG = 0x09,
    PMSTEP_CONSOLE_GET_COMMISSIONING = 0x0A,
    PMSTEP_CONSOLE_TELEMETRY = 0x0B,
    PMSTEP_CONSOLE_GET_COUNTERS = 0x0C,
    PMSTEP_CONSOLE_MOVE_TO = 0x0D,
    PMSTEP_CONSOLE_HOLD = 0x0E,
    PMSTEP_CONSOLE_GET_POSITION = 0x0F,
    PMSTEP_CONSOLE_SET_POSITION_ZERO = 0x10,
    PMSTEP_CONSOLE_CONFIG_READ = 0x11,
    PMSTEP_CONSOLE_CONFIG_WRITE = 0x12,
    PMSTEP_CONSOLE_CONFIG_APPLY = 0x13,
    PMSTEP_CONSOLE_CONFIG_SAVE = 0x14,
    PMSTEP_CONSOLE_CONFIG_ERASE = 0x15,
    PMSTEP_CONSOLE_CONFIG_DEFAULTS = 0x16,
    PMSTEP_CONSOLE_CONFIG_STATUS = 0x17,
    PMSTEP_CONSOLE_CALIBRATE = 0x18,
    PMSTEP_CONSOLE_CALIBRATE_STATUS = 0x19,
    PMSTEP_CONSOLE_HOME = 0x1A,
    PMSTEP_CONSOLE_HOME_STATUS = 0x1B,
    PMSTEP_CONSOLE_SIM_ADVANCE = 0x40,
    PMSTEP_CONSOLE_SIM_FINISH = 0x41,
    PMSTEP_CONSOLE_SIM_STEPS = 0x42,
    PMSTEP_CONSOLE_SIM_FOLLOW_STEPS = 0x43,
    PMSTEP_CONSOLE_SIM_STEPDIR = 0x44,
    PMSTEP_CONSOLE_TELEMETRY_FRAME = 0x90,
    PMSTEP_CONSOLE_ERROR_FRAME = 0xFF
} pmstep_console_type_t;

/** Error reply codes: one per cause. */
typedef enum {
    PMSTEP_CONSOLE_ERR_UNKNOWN_COMMAND = 1,
    PMSTEP_CONSOLE_ERR_BAD_LENGTH = 2,     /**< DATA length wrong for the request */
    PMSTEP_CONSOLE_ERR_BAD_VALUE = 3,      /**< a value NaN/Inf, or out of the field's range */
    PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG = 4, /**< no configuration value of that id or name */
    PMSTEP_CONSOLE_ERR_READ_ONLY = 5,      /**< the value is fixed by the port (period, delay) */
    PMSTEP_CONSOLE_ERR_NOT_STOPPED = 6,    /**< a configuration change while the motor runs */
    PMSTEP_CONSOLE_ERR_BUSY = 7,           /**< the previous command has not reached the core yet */
    PMSTEP_CONSOLE_ERR_NOT_SUPPORTED = 8,  /**< e.g. SIM_ADVANCE on hardware */
    PMSTEP_CONSOLE_ERR_NO_POSITION = 9,    /**< a position request, no position control attached */
    PMSTEP_CONSOLE_ERR_NOT_CONFIGURED = 10, /**< START or CONFIG_SAVE with no motor configured: write a
                                                 record (pmstep_console.py setup) or CALIBRATE first */
    PMSTEP_CONSOLE_ERR_NO_STORE = 11,      /**< a CONFIG_* or CALIBRATE request, no stored configuration attached */
    PMSTEP_CONSOLE_ERR_NO_CALIBRATION = 12 /**< CALIBRATE, no self-commissioning attached */
} pmstep_console_error_t;

#define PMSTEP_CONSOLE_SIM_STEPS_MAX 60u /**< periods of STEP edges one SIM_STEPS carries at most (a byte each) */

/** SIM_STEPDIR flags. */
#define PMSTEP_CONSOLE_SIM_STEPDIR_FOLLOWING 1u /**< the position loop follows the count */
#define PMSTEP_CONSOLE_SIM_STEPDIR_MOVING 2u    /**< steps within the stop time, or the tracker not yet at rest */
#define PMSTEP_CONSOLE_SIM_STEPDIR_DIAG 4u      /**< DIAG asserted after the last period */

/** GET_POSITION flags. */
#define PMSTEP_CONSOLE_POSITION_TRACKED 1u
#define PMSTEP_CONSOLE_POSITION_MODE 2u
#define PMSTEP_CONSOLE_POSITION_MOVING 4u

/** What GET_POSITION and HOME_STATUS read (mechanical rad). */
typedef struct {
    float position_rad;
    float position_ref_rad;
    float position_error_rad;
    uint8_t flags;
    uint8_t homing_state;   /**< HOME_STATUS: pmstep_homing_state_t */
    uint8_t homing_by_current;
    float homing_stop_rad;
} pmstep_console_position_reading_t;

struct pmstep_console;

/** Applies a position request to @p c's position control (pmstep_console_position.c, linked only by an
 *  image that attaches it): @p args as parsed; @p reading filled for GET_POSITION and HOME_STATUS. @p cmd
 *  SET_CONFIG: the core's configuration changed, the loop's gains are designed from it again.
 *  @return the pmstep_status_t of the core's call. */
typedef int32_t (*pmstep_console_position_apply_t)(struct pmstep_console *c, uint8_t cmd, const float *args,
                                                    pmstep_console_position_reading_t *reading);

/** What the console counted, since init. */
typedef struct {
    uint32_t rx_bytes;
    uint32_t rx_frames;         /**< frames with a good CRC */
    uint32_t rx_garbage_bytes;  /**< bytes outside any frame (before a sync) */
    uint32_t rx_bad_length;     /**< LEN out of 2..PMSTEP_CONSOLE_MAX_PAYLOAD (frame dropped) */
    uint32_t rx_crc_errors;     /**< frames dropped for their CRC */
    uint32_t rx_truncated;      /**< frames dropped because they stopped mid-way */
    uint32_t rx_error_replies;  /**< well-framed requests answered with an error */
    uint32_t commands_applied;  /**< commands that reached the core at a period boundary */
    uint32_t tx_frames;
    uint32_t tx_dropped;        /**< frames not sent: transmit buffer full */
    uint32_t telemetry_frames;
} pmstep_console_counters_t;

/** The drive's state as the application saw it at the last period boundary. */
typedef struct {
    uint32_t period;            /**< index of the period whose step @p out is (periods since start-up
                                     minus one; UINT32_MAX before the first step) */
    pmstep_output_t out;        /**< the last step's output */
    pmstep_meas_t meas;         /**< the last step's samples */
    uint8_t port_fault;         /**< the port's own fault (break, driver fault input), 0 = none */
} pmstep_console_snapshot_t;

/** A request as parsed from its frame: the mailbox takes a whole one when it is accepted, or
 *  nothing (a refused request, busy included, changes no state). */
typedef struct {
    uint8_t cmd;
    uint8_t seq;
    uint8_t cfg_id;       /**< GET_CONFIG, SET_CONFIG */
    float a;              /**< SPEED_TARGET target, ID_TARGET target, SET_CONFIG value */
    float b;              /**< SPEED_TARGET ramp */
    uint32_t u;           /**< TELEMETRY decimation */
    float arg[4];         /**< a position request's values (absent ones 0) */
    uint16_t offset;      /**< CONFIG_READ's byte offset */
} pmstep_console_request_t;

/**
 * The stored configuration as the console serves it (pmstep_console_store.c, linked only by an image
 * that attaches it with pmstep_console_attach_store()): the store on the port's flash, the board's
 * own configuration, and whether a motor is configured. Until one is - from the store at boot, a
 * whole record written (CONFIG_WRITE, CONFIG_APPLY) or CALIBRATE - START is refused with
 * PMSTEP_CONSOLE_ERR_NOT_CONFIGURED, and SET_CONFIG alone does not make the drive configured.
 */
typedef struct {
    pmstep_store_t *store;              /**< the port's flash slots (pmstep_store_init() done) */
    pmstep_config_t defaults;           /**< the board's configuration with no motor: its read-only values
                                             (period, delay, sensing ranges) are every record's */
    pmstep_store_measured_t measured;   /**< what the configuration in force was measured with */
    bool configured;                    /**< a motor's configuration is in force: START allowed */
    int16_t boot_status;                /**< pmstep_store_load()'s at boot (pmstep_store_status_t) */
    int16_t boot_validation;            /**< pmstep_validate_config()'s, when that refused the stored one */
    int16_t last_status;                /**< the last save's, erase's or apply's status */
    pmstep_stepdir_settings_t boot_stepdir; /**< the STEP/DIR settings of the record loaded at boot (the defaults
                                             when none was): pmstep_console_attach_store() puts them in force */
    uint8_t staging[PMSTEP_STORE_RECORD_MAX_BYTES]; /**< CONFIG_WRITE's bytes, in order from 0 */
    uint32_t staged;                    /**< bytes staged */
    uint8_t image[PMSTEP_STORE_RECORD_MAX_BYTES];   /**< the record CONFIG_READ serves (encoded at offset 0) */
    uint32_t image_bytes;
} pmstep_console_store_t;

/**
 * At boot, before pmstep_init(): loads the newest record of @p store (pmstep_store_load()) into
 * @p cfg (its STEP/DIR settings into @p cs->boot_stepdir) and marks the drive configured; when there
 * is none, or it is refused (another format, board or layout, a bad CRC, a configuration the core
 * refuses, STEP/DIR settings out of range), @p cfg is @p defaults, the STEP/DIR settings
 * pmstep_console_stepdir_defaults(), the drive is not configured, and the cause stays in
 * @p cs->boot_status for HELLO and CONFIG_STATUS. Never half applied. @return the load's status.
 */
pmstep_store_status_t pmstep_console_store_boot(pmstep_console_store_t *cs, pmstep_store_t *store,
                                                const pmstep_config_t *defaults, pmstep_config_t *cfg);

struct pmstep_console;

/** Applies a CONFIG_* request at the period boundary (pmstep_console_store.c, linked only by an image
 *  that attaches the store): sends its reply. @return false if it was refused (not counted as applied). */
typedef bool (*pmstep_console_store_apply_t)(struct pmstep_console *c, const pmstep_console_request_t *req,
                                             pmstep_t *inst, pmstep_config_t *cfg,
                                             const pmstep_console_snapshot_t *snap);

/** The simulation images' requests answered at once (SIM_ADVANCE, SIM_FINISH, SIM_STEPS;
 *  pmstep_console_sim.c): answers @p type with DATA @p d of @p n bytes. @return 0, or the
 *  pmstep_console_error_t to reply. */
typedef int (*pmstep_console_sim_request_t)(struct pmstep_console *c, uint8_t type, uint8_t seq,
                                            const uint8_t *d, uint32_t n);

typedef struct pmstep_console {
    /* receiver */
    uint8_t state;
    uint8_t len;
    uint8_t pos;
    uint8_t buf[PMSTEP_CONSOLE_MAX_PAYLOAD + 2u];
    uint32_t last_byte_ms;
    /* mailbox: one command waiting for a period boundary */
    bool pending;
    pmstep_console_request_t mail;
    /* the STEP/DIR settings in force (GET_CONFIG and SET_CONFIG of stepdir.*, the records read and saved):
     * an image in STEP/DIR mode reads them from here */
    pmstep_stepdir_settings_t stepdir;
    /* position control (NULL: none, the position requests are refused) */
    pmstep_position_t *position;
    pmstep_console_position_apply_t position_apply;
    pmstep_homing_t homing;       /**< HOME's run (pmstep_console_home_period()) */
    /* simulation images (NULL: none, the simulation requests are refused): periods to run */
    pmstep_console_sim_request_t sim_request;
    /* stored configuration (NULL: none; the image's configuration is then the one in force) */
    pmstep_console_store_t *store;
    pmstep_console_store_apply_t store_apply;
    /* self-commissioning (NULL: none; CALIBRATE refused) */
    pmstep_calibrate_t *calibration;
    pmstep_console_store_apply_t calibration_apply; /**< CALIBRATE at the boundary, and each boundary while it runs */
    int16_t calibration_save_status;                /**< the store's status of the calibrated design's save */
    bool calibrating;                               /**< a calibration runs, or its design waits to be saved */
    uint32_t advance_periods;
    uint8_t advance_seq;
    bool advancing;
    bool finish_requested;
    /* a simulation image's STEP/DIR input on an emulated counter (NULL: none; SIM_STEPS, SIM_FOLLOW_STEPS
     * and SIM_STEPDIR refused) */
    pmstep_stepdir_t *sim_stepdir;
    pmstep_console_store_apply_t sim_stepdir_apply; /**< SIM_FOLLOW_STEPS and SIM_STEPDIR at the boundary */
    uint8_t sim_edges[PMSTEP_CONSOLE_SIM_STEPS_MAX]; /**< SIM_STEPS: the STEP edges of the coming periods (i8 each) */
    uint32_t sim_edges_queued;                      /**< periods of them queued */
    uint32_t sim_edges_next;                        /**< the next period's among them */
    uint16_t sim_step_counter;                      /**< the emulated counter (a timer's CNT: 16 bits, wraps) */
    uint32_t sim_step_edges;                        /**< edges it took since attached (signed, modulo 2^32) */
    /* telemetry */
    uint32_t decimation;
    uint32_t next_telemetry;
    /* transmitter */
    uint8_t tx[PMSTEP_CONSOLE_TX_BYTES];
    uint32_t tx_head;
    uint32_t tx_tail;
    const char *identity; /**< "pmstep <version> <port>" */
    pmstep_console_counters_t count;
} pmstep_console_t;

/** A console in its initial state, the STEP/DIR settings pmstep_console_stepdir_defaults(); @p identity is
 *  the hello text (must outlive it). */
void pmstep_console_init(pmstep_console_t *c, const char *identity);

/**
 * Makes @p c a simulation image's console: SIM_ADVANCE and SIM_FINISH are served
 * (pmstep_console_sim.c, linked only by an image that calls this); elsewhere they get the error
 * reply PMSTEP_CONSOLE_ERR_NOT_SUPPORTED.
 */
void pmstep_console_attach_simulation(pmstep_console_t *c);

/**
 * Attaches a simulation image's STEP/DIR input @p sd (after pmstep_console_attach_simulation() and
 * pmstep_console_attach_position(), and after pmstep_console_attach_store() if the image has one, whose
 * STEP/DIR settings it takes): @p sd is started on the console's STEP/DIR settings for the motor of
 * @p cfg, its counter the emulated one at 0 (a timer after reset), and SIM_STEPS, SIM_FOLLOW_STEPS and
 * SIM_STEPDIR are served (pmstep_console_sim.c). Every period, after the step, the image reads the
 * counter as a port reads its timer: pmstep_stepdir_count(sd, pmstep_console_sim_steps_period(c)), then
 * runs pmstep_position_update() and pmstep_stepdir_diag().
 * @return pmstep_console_stepdir_config()'s or pmstep_stepdir_init()'s status (nothing attached unless
 *         PMSTEP_OK); PMSTEP_ERR_NULL_ARGUMENT without a simulation or position control attached.
 */
pmstep_status_t pmstep_console_attach_sim_stepdir(pmstep_console_t *c, pmstep_stepdir_t *sd,
                                                  const pmstep_config_t *cfg);

/** One period of the emulated STEP/DIR input (simulation images, once a period before the counter is
 *  read): the period's edges queued by SIM_STEPS onto the counter. @return the counter. */
uint16_t pmstep_console_sim_steps_period(pmstep_console_t *c);

/**
 * Attaches position control (@p pos, initialised with pmstep_position_init() on the instance the
 * console drives): MOVE_TO, HOLD, GET_POSITION and SET_POSITION_ZERO then reach it at the
 * period boundary. The application runs pmstep_position_update() after every step.
 */
void pmstep_console_attach_position(pmstep_console_t *c, pmstep_position_t *pos);

/** HOME's run, once a period after pmstep_position_update() with that period's outputs (an image with
 *  position control attached): pmstep_homing_update() while a homing started by HOME is under way. */
void pmstep_console_home_period(pmstep_console_t *c, const pmstep_output_t *out,
                                const pmstep_position_output_t *pos_out);

/**
 * Attaches the stored configuration (@p cs, filled by pmstep_console_store_boot()): the STEP/DIR
 * settings loaded at boot are put in force (c->stepdir), the CONFIG_* requests then reach it, and
 * START needs a configured motor. Saves and erases run at the period
 * boundary, with the motor IDLE or in FAULT and the bridge off; the flash may take tens of
 * milliseconds there (the control interrupt held off all that time, as the flash stalls the core).
 */
void pmstep_console_attach_store(pmstep_console_t *c, pmstep_console_store_t *cs);

/**
 * Attaches self-commissioning (@p cal; the stored configuration must be attached too): CALIBRATE starts it,
 * and while it runs pmstep_console_pending() is true, so that the application calls
 * pmstep_console_boundary() at every period boundary, where its runs advance.
 */
void pmstep_console_attach_calibration(pmstep_console_t *c, pmstep_calibrate_t *cal);

/** Feeds received bytes (main loop). @p now_ms: a millisecond clock, for the truncation timeout. */
void pmstep_console_receive(pmstep_console_t *c, const uint8_t *data, uint32_t n, uint32_t now_ms);

/** Drops a frame that has been silent for PMSTEP_CONSOLE_TRUNCATION_MS (main loop). */
void pmstep_console_poll(pmstep_console_t *c, uint32_t now_ms);

/** Whether the console needs the next period boundary: a command waits, or a calibration runs. */
bool pmstep_console_pending(const pmstep_console_t *c);

/**
 * At a period boundary (no control step running, none can start): applies the waiting
 * command to @p inst (configuration changes to @p cfg, then pmstep_init()) and queues its
 * reply, built from @p snap.
 */
void pmstep_console_boundary(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                             const pmstep_console_snapshot_t *snap);

/** Queues a telemetry frame if @p snap->period is due (main loop, after a period). */
void pmstep_console_telemetry(pmstep_console_t *c, const pmstep_console_snapshot_t *snap);

/** Periods a SIM_ADVANCE asks for (0: none); the application runs them, then calls _advance_done(). */
uint32_t pmstep_console_advance_request(pmstep_console_t *c);

/** Replies to the SIM_ADVANCE once its periods have run; @p period: the period count now. */
void pmstep_console_advance_done(pmstep_console_t *c, uint32_t period);

/** Whether a SIM_FINISH was received (simulation images). */
bool pmstep_console_finish_requested(const pmstep_console_t *c);

/** The request waiting in the mailbox (0 if none), e.g. for a port's own part of CLEAR_FAULT. */
uint8_t pmstep_console_pending_command(const pmstep_console_t *c);

/** Takes up to @p max bytes to transmit into @p out. @return the count. */
uint32_t pmstep_console_transmit(pmstep_console_t *c, uint8_t *out, uint32_t max);

/** CRC-16/CCITT-FALSE of @p n bytes, continuing from @p crc (start with 0xFFFF). */
uint16_t pmstep_console_crc16(uint16_t crc, const uint8_t *data, uint32_t n);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_CONSOLE_H */
