/*
 * A drive on the host for the console's tests: the console (simulation mode) and the real
 * core on stdin/stdout as a byte stream (a pty or a pipe), with constant samples (0.3 A,
 * 0.2 A, 48 V) in place of a motor. Periods run on SIM_ADVANCE; SIM_FINISH ends it.
 *
 * usage: console-host-drive [--position] [--flash FILE [--board-id N] [--power-cut-after N]]
 *   --position   position control attached, updated after every step (without it the drive is an
 *                image in speed mode), and the STEP/DIR input on the console's emulated counter, read
 *                after every step (SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR), as the QEMU image's
 *   --flash      the stored configuration attached, on a flash kept in FILE: two slots of 2048 bytes,
 *                slot 0 then slot 1 (a file that is absent or shorter reads as erased, 0xFF). Every
 *                erase and program is written to the file before it returns, so killing the process
 *                is a power cut and starting it again on the same file is a reset. As on NOR flash,
 *                programming an 8-byte unit not erased since its last program fails.
 *   --board-id   the board's id the records are made for (default HOST_BOARD_ID; decimal or 0x hex)
 *   --power-cut-after N  the N-th flash operation (erase or program, counted from 1 since the start)
 *                is cut half-way, then the process exits with status 3 at once, as a board loses its
 *                power (a deterministic power cut for the tests): an erase leaves the slot's first
 *                half erased and the rest as it was; a program leaves its bytes with half their bits
 *                programmed (NOR flash programs 1s to 0s: every byte reads data | 0x55)
 * Without --flash there is no store: the configuration in force is the image's own (as before
 * the store existed) and the CONFIG_* requests get NO_STORE.
 * Exit status: 0 SIM_FINISH or the other side closed, 2 bad arguments or flash file, 3 power cut.
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "pmstep_console.h"

#define HOST_BOARD_ID 0x54534F48u /* "HOST" in memory order */
#define SLOT_BYTES 2048u
#define UNIT_BYTES PMSTEP_STORE_PROGRAM_UNIT
#define SLOT_UNITS (SLOT_BYTES / UNIT_BYTES)

/* Flash errors reported to the store (pmstep_store_t::flash_error). */
#define FLASH_ERR_RANGE (-1)   /* slot, offset or length outside the slots or not whole units */
#define FLASH_ERR_IO (-2)      /* the file could not be written */
#define FLASH_ERR_PROGRAM (-3) /* a unit programmed twice without an erase (STM32G4 PROGERR) */

/* The flash in a file, with a copy in memory that is what reads return. */
typedef struct {
    int fd;
    uint8_t bytes[2][SLOT_BYTES];
    /* A unit programmed since its last erase: a second program of it fails. Known only for what this
     * process programmed; a unit of the file that is not all 0xFF counts as programmed too. */
    uint8_t written[2][SLOT_UNITS];
    long ops;    /* erases and programs so far */
    long cut_at; /* the operation cut half-way (0: none) */
} file_flash_t;

static uint32_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

static pmstep_console_t con;
static file_flash_t flash_file;

/* Writes @p n bytes of slot @p slot from @p offset of the memory copy to the file. @return 0 or -1. */
static int write_through(file_flash_t *f, uint32_t slot, uint32_t offset, uint32_t n)
{
    const off_t at = (off_t)(slot * SLOT_BYTES + offset);
    uint32_t done = 0u;
    while (done < n) {
        const ssize_t w = pwrite(f->fd, &f->bytes[slot][offset + done], n - done, at + (off_t)done);
        if (w < 0 && errno == EINTR) {
            continue;
        }
        if (w <= 0) {
            return -1;
        }
        done += (uint32_t)w;
    }
    return 0;
}

/* Counts an operation: at the planned cut, what the memory copy holds for its @p n bytes from @p offset
 * (the cut's state, set by the caller) reaches the file and the power is gone. */
static void power_check(file_flash_t *f, uint32_t slot, uint32_t offset, uint32_t n, const char *what)
{
    f->ops++;
    if (f->cut_at > 0 && f->ops == f->cut_at) {
        (void)write_through(f, slot, offset, n);
        fprintf(stderr, "console-host-drive: power cut in flash operation %ld (%s of slot %u at %u)\n", f->ops, what,
                (unsigned)slot, (unsigned)offset);
        _exit(3);
    }
}

/* Whether the operation about to run is the one cut. */
static int cut_now(const file_flash_t *f) { return f->cut_at > 0 && f->ops + 1 == f->cut_at; }

static int32_t flash_erase(void *ctx, uint32_t slot)
{
    file_flash_t *f = ctx;
    if (slot > 1u) {
        return FLASH_ERR_RANGE;
    }
    /* Cut: the first half erased (the rest of the memory copy no longer matters). */
    memset(f->bytes[slot], 0xFF, cut_now(f) ? SLOT_BYTES / 2u : SLOT_BYTES);
    memset(f->written[slot], 0, SLOT_UNITS);
    power_check(f, slot, 0u, SLOT_BYTES / 2u, "erase");
    return write_through(f, slot, 0u, SLOT_BYTES) == 0 ? 0 : FLASH_ERR_IO;
}

static int32_t flash_program(void *ctx, uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n)
{
    file_flash_t *f = ctx;
    uint32_t u;
    if (slot > 1u || offset % UNIT_BYTES != 0u || n % UNIT_BYTES != 0u || offset > SLOT_BYTES
        || n > SLOT_BYTES - offset) {
        return FLASH_ERR_RANGE;
    }
    for (u = offset / UNIT_BYTES; u < (offset + n) / UNIT_BYTES; ++u) {
        if (f->written[slot][u] != 0u) {
            return FLASH_ERR_PROGRAM; /* nothing of this program is written */
        }
    }
    for (u = offset / UNIT_BYTES; u < (offset + n) / UNIT_BYTES; ++u) {
        f->written[slot][u] = 1u;
    }
    for (u = 0; u < n; ++u) { /* cut: half of each byte's bits still erased */
        f->bytes[slot][offset + u] = (uint8_t)(cut_now(f) ? data[u] | 0x55u : data[u]);
    }
    power_check(f, slot, offset, n, "program");
    return write_through(f, slot, offset, n) == 0 ? 0 : FLASH_ERR_IO;
}

static int32_t flash_read(void *ctx, uint32_t slot, uint32_t offset, uint8_t *data, uint32_t n)
{
    const file_flash_t *f = ctx;
    if (slot > 1u || offset > SLOT_BYTES || n > SLOT_BYTES - offset) {
        return FLASH_ERR_RANGE;
    }
    memcpy(data, &f->bytes[slot][offset], n);
    return 0;
}

/* Opens (or creates) the flash file @p path: its bytes, the rest of the two slots erased. @return 0,
 * or -1 with a message on stderr. */
static int flash_open(file_flash_t *f, const char *path)
{
    struct stat st;
    uint32_t got = 0u;
    uint32_t slot;
    uint32_t u;
    f->fd = open(path, O_RDWR | O_CREAT, 0644);
    if (f->fd < 0 || fstat(f->fd, &st) != 0) {
        fprintf(stderr, "console-host-drive: cannot open the flash file %s: %s\n", path, strerror(errno));
        return -1;
    }
    if (st.st_size > (off_t)(2u * SLOT_BYTES)) {
        fprintf(stderr, "console-host-drive: %s is %ld bytes, more than the flash's two slots of %u bytes\n", path,
                (long)st.st_size, (unsigned)SLOT_BYTES);
        return -1;
    }
    memset(f->bytes, 0xFF, sizeof f->bytes);
    while (got < (uint32_t)st.st_size) {
        const ssize_t r = pread(f->fd, &f->bytes[0][0] + got, (size_t)st.st_size - got, (off_t)got);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r <= 0) {
            fprintf(stderr, "console-host-drive: cannot read the flash file %s\n", path);
            return -1;
        }
        got += (uint32_t)r;
    }
    for (slot = 0; slot < 2u; ++slot) {
        for (u = 0; u < SLOT_UNITS; ++u) {
            uint32_t k;
            f->written[slot][u] = 0u;
            for (k = 0; k < UNIT_BYTES; ++k) {
                if (f->bytes[slot][u * UNIT_BYTES + k] != 0xFFu) {
                    f->written[slot][u] = 1u;
                }
            }
        }
        /* The file as long as the flash from now on: what was absent is written erased. */
        if (write_through(f, slot, 0u, SLOT_BYTES) != 0) {
            fprintf(stderr, "console-host-drive: cannot write the flash file %s\n", path);
            return -1;
        }
    }
    return 0;
}

static void drain(void)
{
    uint8_t out[256];
    uint32_t n;
    while ((n = pmstep_console_transmit(&con, out, sizeof out)) > 0u) {
        uint32_t k = 0;
        while (k < n) {
            const ssize_t w = write(1, out + k, n - k);
            if (w <= 0) {
                return;
            }
            k += (uint32_t)w;
        }
    }
}

/* @p text as a whole number below 2^32 (decimal, or hex with 0x). @return 0, or -1 if it is not one. */
static int parse_u32(const char *text, unsigned long max, unsigned long *value)
{
    char *end = NULL;
    if (text == NULL || text[0] == '\0' || text[0] == '-') {
        return -1;
    }
    errno = 0;
    *value = strtoul(text, &end, 0);
    return errno == 0 && *end == '\0' && *value <= max ? 0 : -1;
}

static int usage(const char *why)
{
    fprintf(stderr,
            "console-host-drive: %s\nusage: console-host-drive [--position] [--flash FILE "
            "[--board-id N] [--power-cut-after N]]\n",
            why);
    return 2;
}

int main(int argc, char **argv)
{
    static pmstep_position_t position;
    static pmstep_position_output_t pos_out;
    static pmstep_stepdir_t stepdir;
    static pmstep_t motor;
    static pmstep_config_t cfg;
    static pmstep_config_t defaults;
    static pmstep_console_snapshot_t snap; /* zero: no output yet */
    static pmstep_store_t store;
    static pmstep_console_store_t stored;
    static pmstep_store_flash_t flash_ops;
    const pmstep_meas_t meas = {0.3f, 0.2f, 48.0f, 0.0f, 0.0f, 0.0f};
    int with_position = 0;
    const char *flash_path = NULL;
    unsigned long board_id = HOST_BOARD_ID;
    unsigned long cut_at = 0u;
    int k;
    for (k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--position") == 0) {
            with_position = 1;
        } else if (strcmp(argv[k], "--flash") == 0 && k + 1 < argc) {
            flash_path = argv[++k];
        } else if (strcmp(argv[k], "--board-id") == 0 && k + 1 < argc) {
            if (parse_u32(argv[++k], 0xFFFFFFFFul, &board_id) != 0) {
                return usage("--board-id: expected a whole number from 0 to 0xFFFFFFFF");
            }
        } else if (strcmp(argv[k], "--power-cut-after") == 0 && k + 1 < argc) {
            if (parse_u32(argv[++k], 0x7FFFFFFFul, &cut_at) != 0 || cut_at == 0u) {
                return usage("--power-cut-after: expected a whole number from 1");
            }
        } else {
            return usage("unknown or incomplete argument");
        }
    }
    if (flash_path == NULL && (board_id != HOST_BOARD_ID || cut_at != 0u)) {
        return usage("--board-id and --power-cut-after need --flash");
    }
    snap.period = UINT32_MAX; /* no step yet */
    /* What the drive uses with no motor configured: the image's configuration on the port's values. */
    defaults = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    cfg = defaults;
    if (flash_path != NULL) {
        pmstep_store_status_t st;
        if (flash_open(&flash_file, flash_path) != 0) {
            return 2;
        }
        flash_file.cut_at = (long)cut_at;
        flash_ops.slot_bytes = SLOT_BYTES;
        flash_ops.erase = flash_erase;
        flash_ops.program = flash_program;
        flash_ops.read = flash_read;
        flash_ops.ctx = &flash_file;
        st = pmstep_store_init(&store, &flash_ops, (uint32_t)board_id);
        if (st != PMSTEP_STORE_OK) {
            fprintf(stderr, "console-host-drive: pmstep_store_init: %d\n", (int)st);
            return 2;
        }
        /* Any outcome boots: a refused or absent record leaves the defaults in force, not configured,
         * and the cause in CONFIG_STATUS. */
        (void)pmstep_console_store_boot(&stored, &store, &defaults, &cfg);
    }
    if (pmstep_init(&motor, &cfg) != PMSTEP_OK) {
        return 2;
    }
    pmstep_console_init(&con, "pmstep host-drive");
    pmstep_console_attach_simulation(&con);
    if (with_position) {
        pmstep_position_config_t gains;
        if (pmstep_position_design(&cfg, &gains) != PMSTEP_OK
            || pmstep_position_init(&position, &motor, &gains) != PMSTEP_OK) {
            return 2;
        }
        pmstep_console_attach_position(&con, &position);
    }
    if (flash_path != NULL) {
        pmstep_console_attach_store(&con, &stored);
    }
    if (with_position && pmstep_console_attach_sim_stepdir(&con, &stepdir, &cfg) != PMSTEP_OK) {
        return 2;
    }
    (void)fcntl(0, F_SETFL, fcntl(0, F_GETFL) | O_NONBLOCK);
    while (!pmstep_console_finish_requested(&con)) {
        struct pollfd p = {0, POLLIN, 0};
        uint8_t in[64];
        ssize_t r;
        uint32_t n;
        (void)poll(&p, 1, 1);
        r = read(0, in, sizeof in);
        if (r == 0) {
            return 0; /* the other side closed */
        }
        pmstep_console_receive(&con, in, r > 0 ? (uint32_t)r : 0u, now_ms());
        pmstep_console_boundary(&con, &motor, &cfg, &snap);
        for (n = pmstep_console_advance_request(&con); n > 0u; --n) {
            pmstep_console_boundary(&con, &motor, &cfg, &snap);
            pmstep_step(&motor, &meas, &snap.out);
            if (with_position) {
                pmstep_stepdir_count(&stepdir, pmstep_console_sim_steps_period(&con));
                pmstep_position_update(&position, &snap.out, &pos_out);
                pmstep_console_home_period(&con, &snap.out, &pos_out);
                (void)pmstep_stepdir_diag(&stepdir, snap.out.mode, pos_out.position_rad, pos_out.tracked);
            }
            snap.meas = meas;
            snap.period++;
            pmstep_console_telemetry(&con, &snap);
        }
        if (pmstep_console_advance_request(&con) > 0u) {
            pmstep_console_advance_done(&con, snap.period + 1u);
        }
        drain();
    }
    drain();
    return 0;
}
