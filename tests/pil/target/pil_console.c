/*
 * Processor in the loop with the console: the closed loop of pil_closed_loop.c (plant model
 * (1) from sil/ on the emulated Cortex-M4, the real core in the port's control interrupt,
 * the SIL's paper scenario and metrics) driven from the host through the command and
 * telemetry interface on UART0 (QEMU's first -serial backend) instead of a built-in
 * profile. The image starts with the motor in IDLE and waits for commands; simulated time
 * moves only on SIM_ADVANCE (so the host decides at which period each command lands, and
 * the run can be compared with the host SIL period by period); SIM_FINISH ends the run.
 * Between any two periods the main loop reads the UART, parses, applies a waiting command
 * at the period boundary and sends replies and telemetry; bad input is dropped or answered.
 *
 * usage (semihosting command line):
 *   pil-console [--duration S] [--substeps N] [--summary FILE] [--cost FILE] [--stepdir FILE]
 *               [--flash FILE [--board-id N] [--power-cut-after N]] [--no-load]
 * --flash: the board's stored configuration (pmstep_store.h) and self-commissioning attached, on a
 * flash of two 2 KiB slots kept in FILE on the host (read at boot, every erase and program written
 * through at once): the image boots from the newest valid record, or with no motor configured. A
 * restart of QEMU with the same FILE is a reset of the board. --power-cut-after N: the N-th erase or
 * 8-byte program is cut half-way (half its bytes written) and the image stops at once, as a board
 * losing its supply (exit status 5). What this proves: the firmware's store, console and
 * self-commissioning across resets and cut saves, run by the real core on the emulated Cortex-M4;
 * not the STM32G4's flash controller (its driver is tested on hal/stm32g4's behavioural model).
 * --no-load: the plant without the scenario's load torque (a motor free on its shaft, as it is
 * calibrated).
 * Position control (pmstep_position) is attached to the console: pmstep_position_update() runs
 * after every step (in the main loop, after the control interrupt), and MOVE_TO, HOLD,
 * GET_POSITION, SET_POSITION_ZERO reach it; in speed mode it changes nothing of the run.
 * A STEP/DIR input (pmstep_stepdir) on the console's emulated step counter is attached too
 * (pmstep_console_attach_sim_stepdir()): the host puts STEP edges on the counter period by period
 * (SIM_STEPS), the image reads it after every step as the STM32G4 port reads its timer (the count,
 * the position update, DIAG), and SIM_FOLLOW_STEPS puts the position loop on the count; with no
 * edges and no SIM_FOLLOW_STEPS it changes nothing of the run.
 * --stepdir: the STEP/DIR run's figures on the plant's true position, from the period the loop
 * starts following the count (the first SIM_FOLLOW_STEPS accepted): the edges the host sent since,
 * the input's count, the following error (the count's position less the plant's angle from the
 * equilibrium p theta = 0 mod 2 pi nearest the rotor then, in full steps pi / (2 p), as the host
 * SIL's stepdir summary) at its largest and at the end, and the periods DIAG was asserted.
 * --summary: the closed-loop metrics (the keys of pil-closed-loop's summary);
 * --cost: the control step's cost per mode from SysTick (with -icount shift=0), and the
 * console's counters.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmsdk_uart.h"
#include "pmstep/pmstep_text.h"
#include "pmstep_console.h"
#include "pmstep_hal_qemu_mps2.h"
#include "sil/inverter.h"
#include "sil/metrics.h"
#include "pil_summary.h"
#include "sil/plant.h"

#ifndef PMSTEP_VERSION_TEXT
#define PMSTEP_VERSION_TEXT "0.0.0"
#endif

#define PI 3.14159265358979323846
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYSTICK_HZ 25000000u /* QEMU's mps2 SysTick reference clock */

static pmstep_t motor;
static pmstep_config_t config; /* outlives the instance, as pmstep_init() requires */
static pmstep_console_t console;
static pmstep_store_t store;
static pmstep_console_store_t stored;
static pmstep_calibrate_t calibration;
static pmstep_position_t position;
static pmstep_stepdir_t stepdir; /* the STEP/DIR input, on the console's emulated counter */
static const char *const mode_names[MPS2_PIL_MODES] = {"IDLE", "S_ALIGN", "C_ALIGN", "RUN", "FAULT"};

/* ---- the console's side of the main loop ---- */

static uint64_t systick_total;
static uint32_t systick_last;
static uint8_t tx_buf[64];
static uint32_t tx_len;
static uint32_t tx_pos;

/* Milliseconds of virtual time from SysTick (free running over 24 bits; polled far more often
 * than it wraps, every 0.67 s). */
static uint32_t now_ms(void)
{
    const uint32_t now = SYST_CVR;
    systick_total += (systick_last - now) & 0x00FFFFFFu;
    systick_last = now;
    return (uint32_t)(systick_total / (SYSTICK_HZ / 1000u));
}

static void service_uart(void)
{
    uint8_t rx[16];
    const uint32_t n = cmsdk_uart_read(rx, sizeof rx);
    uint32_t sent;
    pmstep_console_receive(&console, rx, n, now_ms());
    do { /* as much as the transmitter takes now */
        if (tx_pos == tx_len) {
            tx_len = pmstep_console_transmit(&console, tx_buf, sizeof tx_buf);
            tx_pos = 0u;
        }
        sent = cmsdk_uart_write(&tx_buf[tx_pos], tx_len - tx_pos);
        tx_pos += sent;
    } while (sent > 0u);
}

static void flush_uart(void)
{
    uint32_t guard;
    for (guard = 0; guard < 1000000u && (tx_pos != tx_len || console.tx_head != console.tx_tail); ++guard) {
        service_uart();
    }
}

/* ---- the board's flash: two slots in a host file (semihosting) ---- */

#define SLOT_BYTES 2048u

static struct {
    FILE *file;
    long cut_after; /* operations left before the power cut; 0: none planned */
} flash;

static int32_t flash_io(uint32_t slot, uint32_t offset, void *data, uint32_t n, bool write)
{
    if (slot > 1u || offset + n > SLOT_BYTES || fseek(flash.file, (long)(slot * SLOT_BYTES + offset), SEEK_SET) != 0) {
        return -1;
    }
    if (write) {
        return fwrite(data, 1u, n, flash.file) == n && fflush(flash.file) == 0 ? 0 : -2;
    }
    return fread(data, 1u, n, flash.file) == n ? 0 : -2;
}

/* An erase or a program about to happen: the one the plan cuts leaves its @p n bytes with only part
 * of their bits programmed (a program turns 1s to 0s: half of them still 1), then the board loses its
 * supply. */
static void maybe_cut(uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n)
{
    if (flash.cut_after > 0 && --flash.cut_after == 0) {
        uint8_t partial[256];
        uint32_t k;
        n = n < sizeof partial ? n : (uint32_t)sizeof partial;
        for (k = 0; k < n; ++k) {
            partial[k] = (uint8_t)(data[k] | 0x55u);
        }
        (void)flash_io(slot, offset, partial, n, true);
        fclose(flash.file);
        fprintf(stderr, "pil-console: power cut in a flash write (slot %u, offset %u)\n", (unsigned)slot,
                (unsigned)offset);
        exit(5);
    }
}

static int32_t flash_erase(void *ctx, uint32_t slot)
{
    uint8_t ff[256];
    uint32_t off;
    (void)ctx;
    memset(ff, 0xFF, sizeof ff);
    maybe_cut(slot, 0u, ff, sizeof ff); /* a cut erase: the slot's first bytes erased, the rest as it was */
    for (off = 0; off < SLOT_BYTES; off += sizeof ff) {
        if (flash_io(slot, off, ff, sizeof ff, true) != 0) {
            return -2;
        }
    }
    return 0;
}

static int32_t flash_program(void *ctx, uint32_t slot, uint32_t offset, const uint8_t *data, uint32_t n)
{
    uint8_t was[PMSTEP_STORE_PROGRAM_UNIT];
    uint32_t k;
    (void)ctx;
    for (k = 0; k < n; k += PMSTEP_STORE_PROGRAM_UNIT) {
        uint32_t b;
        if (flash_io(slot, offset + k, was, sizeof was, false) != 0) {
            return -2;
        }
        for (b = 0; b < sizeof was; ++b) {
            if (was[b] != 0xFFu) {
                return -3; /* NOR flash: a unit is programmed once after its erase */
            }
        }
        maybe_cut(slot, offset + k, &data[k], PMSTEP_STORE_PROGRAM_UNIT);
        if (flash_io(slot, offset + k, (void *)(uintptr_t)&data[k], PMSTEP_STORE_PROGRAM_UNIT, true) != 0) {
            return -2;
        }
    }
    return 0;
}

static int32_t flash_read(void *ctx, uint32_t slot, uint32_t offset, uint8_t *data, uint32_t n)
{
    (void)ctx;
    return flash_io(slot, offset, data, n, false);
}

static const pmstep_store_flash_t flash_ops = {SLOT_BYTES, flash_erase, flash_program, flash_read, NULL};

/* Opens the flash file, made erased (0xFF) where it is shorter than two slots. @return 0 or -1. */
static int flash_open(const char *path)
{
    long size;
    flash.file = fopen(path, "r+b");
    if (flash.file == NULL) {
        flash.file = fopen(path, "w+b");
    }
    if (flash.file == NULL || fseek(flash.file, 0, SEEK_END) != 0) {
        return -1;
    }
    size = ftell(flash.file);
    while (size >= 0 && size < (long)(2u * SLOT_BYTES)) {
        if (fputc(0xFF, flash.file) == EOF) {
            return -1;
        }
        ++size;
    }
    return fflush(flash.file) == 0 ? 0 : -1;
}

/* ---- the closed loop (as pil_closed_loop.c) ---- */

/* The STEP/DIR run on the plant's true position (--stepdir). */
typedef struct {
    bool on;                 /* the loop follows the count (from the first SIM_FOLLOW_STEPS accepted) */
    uint32_t edges_at_start; /* the emulated counter's edges then */
    double origin_rad;       /* the equilibrium the count's position is measured from */
    long periods;            /* periods since */
    double max_error;        /* the following error at its largest (|.|, full steps) */
    double final_error;      /* at the last period (full steps) */
    long diag_periods;       /* periods DIAG was asserted (the whole run) */
} stepdir_figures_t;

typedef struct {
    sil_scenario_t sc;
    plant_t plant;
    sil_inverter_t inv;
    sil_metrics_t metrics;
    sil_summary_t s;
    stepdir_figures_t sd;
    double period_s;
    double p;
} loop_t;

/* The count's position (the edges the host sent since following began) less the plant's angle @p theta_rad
 * at the start of the period, from the equilibrium nearest the rotor when following began. */
static void stepdir_figures(loop_t *L, double theta_rad, uint32_t edges_before)
{
    stepdir_figures_t *f = &L->sd;
    if (!f->on && stepdir.following) {
        f->on = true;
        f->edges_at_start = edges_before;
        f->origin_rad = floor(theta_rad * L->p / (2.0 * PI) + 0.5) * 2.0 * PI / L->p;
    }
    if (f->on) {
        const double count = (double)(int32_t)(console.sim_step_edges - f->edges_at_start);
        const double microstep_rad = 2.0 * PI / (4.0 * L->p * (double)stepdir.cfg.microsteps);
        const double error = (count * microstep_rad - (theta_rad - f->origin_rad)) / (0.5 * PI / L->p);
        f->max_error = fmax(f->max_error, fabs(error));
        f->final_error = error;
        f->periods++;
    }
}

static void run_period(loop_t *L, long k, pmstep_console_snapshot_t *snap)
{
    const double t_s = (double)k * L->period_s;
    pmstep_meas_t meas;
    pmstep_output_t out;
    sil_sample_t sample;
    L->plant.time_s = t_s;
    sample.step = k;
    sample.t_s = t_s;
    sample.theta_rad = L->plant.x.theta_rad;
    sample.omega_rad_s = L->plant.x.omega_rad_s;
    sample.i_a_A = L->plant.x.i_a_A;
    sample.i_b_A = L->plant.x.i_b_A;
    sample.load_Nm = plant_load_torque(&L->plant.load, t_s, L->plant.x.omega_rad_s);
    meas.i_a_A = (float)sample.i_a_A;
    meas.i_b_A = (float)sample.i_b_A;
    meas.bus_voltage_V = (float)sil_inverter_bus_voltage(&L->inv, t_s);
    meas.load_torque_Nm = (float)sample.load_Nm;
    meas.phase_voltage_a_V = (float)L->inv.applied_a_V; /* the mean voltage of the period just ended */
    meas.phase_voltage_b_V = (float)L->inv.applied_b_V;
    mps2_pil_control_period(&meas, &out);
    {
        /* the port's order: the step, the step counter read, the position update, DIAG */
        const uint32_t edges_before = console.sim_step_edges;
        pmstep_position_output_t pos_out;
        pmstep_stepdir_count(&stepdir, pmstep_console_sim_steps_period(&console));
        pmstep_position_update(&position, &out, &pos_out);
        pmstep_console_home_period(&console, &out, &pos_out);
        if (pmstep_stepdir_diag(&stepdir, out.mode, pos_out.position_rad, pos_out.tracked)) {
            L->sd.diag_periods++;
        }
        stepdir_figures(L, sample.theta_rad, edges_before);
    }
    sil_inverter_apply(&L->inv, &out, (double)meas.bus_voltage_V);
    sil_drive_advance(&L->plant, &L->inv, L->period_s, L->sc.substeps);
    sample.cos_ptheta = cos(L->p * sample.theta_rad);
    sample.sin_ptheta = sin(L->p * sample.theta_rad);
    sample.u_a_V = L->inv.applied_a_V;
    sample.u_b_V = L->inv.applied_b_V;
    sample.out = &out;
    sample.inst = &motor;
    sil_metrics_add(&L->metrics, &sample, &L->s);
    snap->period = (uint32_t)k;
    snap->out = out;
    snap->meas = meas;
}

static void write_cost(FILE *f, double insns_per_tick, long periods)
{
    const mps2_pil_cost_t *cost = mps2_pil_cost();
    const pmstep_console_counters_t *n = &console.count;
    unsigned m;
    fprintf(f, "pil_cost 1\nperiods %ld\ninstructions_per_tick %.6f\n", periods, insns_per_tick);
    for (m = 0; m < MPS2_PIL_MODES; ++m) {
        if (cost->steps[m] > 0u) {
            /* step bracket minus empty bracket, plus the empty function's one instruction (BX LR) */
            const double steps = (double)cost->steps[m];
            const double insns =
                ((double)cost->step_ticks[m] - (double)cost->empty_ticks[m]) * insns_per_tick / steps + 1.0;
            fprintf(f,
                    "mode %s steps %lu step_ticks %llu empty_ticks %llu instructions_mean %.2f stack_max_bytes %lu\n",
                    mode_names[m], (unsigned long)cost->steps[m], (unsigned long long)cost->step_ticks[m],
                    (unsigned long long)cost->empty_ticks[m], insns, (unsigned long)cost->stack_max_bytes[m]);
        }
    }
    fprintf(f,
            "console rx_bytes %lu rx_frames %lu rx_garbage_bytes %lu rx_bad_length %lu rx_crc_errors %lu "
            "rx_truncated %lu rx_error_replies %lu commands_applied %lu tx_frames %lu tx_dropped %lu "
            "telemetry_frames %lu\n",
            (unsigned long)n->rx_bytes, (unsigned long)n->rx_frames, (unsigned long)n->rx_garbage_bytes,
            (unsigned long)n->rx_bad_length, (unsigned long)n->rx_crc_errors, (unsigned long)n->rx_truncated,
            (unsigned long)n->rx_error_replies, (unsigned long)n->commands_applied, (unsigned long)n->tx_frames,
            (unsigned long)n->tx_dropped, (unsigned long)n->telemetry_frames);
}

static void write_stepdir(FILE *f, const stepdir_figures_t *sd)
{
    fprintf(f, "pil_stepdir 1\nfollowing_periods %ld\nedges_sent %ld\nsteps_counted %ld\nmicrosteps %lu\n", sd->periods,
            sd->on ? (long)(int32_t)(console.sim_step_edges - sd->edges_at_start) : 0L, (long)stepdir.steps,
            (unsigned long)stepdir.cfg.microsteps);
    fprintf(f, "max_error_full_steps %.9g\nfinal_error_full_steps %.9g\ndiag_periods %ld\n", sd->max_error,
            sd->final_error, sd->diag_periods);
}

static int write_file(const char *path, int which, loop_t *L, double insns_per_tick, long steps)
{
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        fprintf(stderr, "pil-console: cannot write '%s'\n", path);
        return 2;
    }
    if (which == 0) {
        pil_write_summary(f, "qemu mps2-an386 (Cortex-M4F), console-driven", &L->s, L->sc.duration_s, L->sc.substeps);
    } else if (which == 1) {
        write_cost(f, insns_per_tick, steps);
    } else {
        write_stepdir(f, &L->sd);
    }
    return fclose(f) == 0 ? 0 : 2;
}

int main(int argc, char **argv)
{
    static loop_t L;
    static pmstep_console_snapshot_t snap;
    const char *summary_path = NULL;
    const char *cost_path = NULL;
    const char *stepdir_path = NULL;
    const char *flash_path = NULL;
    bool no_load = false;
    uint32_t board_id = 0x4D505332u; /* "MPS2" */
    double insns_per_tick;
    pmstep_status_t st;
    long steps;
    long k = 0;
    int i;

    sil_scenario_paper(&L.sc);
    L.sc.duration_s = 0.9;
    L.sc.substeps = 10;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--duration") == 0 && i + 1 < argc) {
            L.sc.duration_s = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--substeps") == 0 && i + 1 < argc) {
            L.sc.substeps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--summary") == 0 && i + 1 < argc) {
            summary_path = argv[++i];
        } else if (strcmp(argv[i], "--cost") == 0 && i + 1 < argc) {
            cost_path = argv[++i];
        } else if (strcmp(argv[i], "--stepdir") == 0 && i + 1 < argc) {
            stepdir_path = argv[++i];
        } else if (strcmp(argv[i], "--flash") == 0 && i + 1 < argc) {
            flash_path = argv[++i];
        } else if (strcmp(argv[i], "--board-id") == 0 && i + 1 < argc) {
            board_id = (uint32_t)strtoul(argv[++i], NULL, 0);
        } else if (strcmp(argv[i], "--power-cut-after") == 0 && i + 1 < argc) {
            flash.cut_after = strtol(argv[++i], NULL, 0);
        } else if (strcmp(argv[i], "--no-load") == 0) {
            no_load = true;
        } else {
            fprintf(stderr, "usage: pil-console [--duration S] [--substeps N] [--summary FILE] [--cost FILE]\n"
                            "                   [--stepdir FILE] [--flash FILE [--board-id N] [--power-cut-after N]]\n"
                            "                   [--no-load]\n");
            return 2;
        }
    }
    if (!(L.sc.duration_s > 0.0) || L.sc.substeps < 1) {
        fprintf(stderr, "pil-console: --duration must be > 0 and --substeps >= 1\n");
        return 2;
    }
    config = L.sc.controller;
    if (flash_path != NULL) {
        /* The board with its flash: the stored record, or no motor configured. */
        const pmstep_config_t defaults = L.sc.controller;
        pmstep_store_status_t boot;
        if (flash_open(flash_path) != 0 || pmstep_store_init(&store, &flash_ops, board_id) != PMSTEP_STORE_OK) {
            fprintf(stderr, "pil-console: cannot use '%s' as the flash\n", flash_path);
            return 2;
        }
        boot = pmstep_console_store_boot(&stored, &store, &defaults, &config);
        fprintf(stderr, "pil-console: stored configuration: %s (%d)\n",
                boot == PMSTEP_STORE_OK ? "in force" : "none in force, no motor configured", (int)boot);
    }
    L.sc.controller = config; /* the metrics' windows from the configuration in force */
    st = pmstep_init(&motor, &config);
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-console: pmstep_init: %s\n", pmstep_status_str(st));
        return 2;
    }
    {
        pmstep_position_config_t gains;
        (void)pmstep_position_design(&config, &gains);
        st = pmstep_position_init(&position, &motor, &gains);
        if (st != PMSTEP_OK) {
            fprintf(stderr, "pil-console: pmstep_position_init: %s\n", pmstep_status_str(st));
            return 2;
        }
    }
    L.period_s = (double)pmstep_console_config_period_s(&config);
    steps = sil_periods_in(L.sc.duration_s, L.period_s);
    sil_metrics_init(&L.metrics, &L.sc, &L.s);
    memset(&L.plant, 0, sizeof L.plant);
    L.plant.params = L.sc.motor;
    L.plant.load = L.sc.load;
    if (no_load) {
        L.plant.load.kind = PLANT_LOAD_NONE;
    }
    L.plant.x.theta_rad = L.sc.theta0_rad;
    L.plant.x.omega_rad_s = L.sc.omega0_rad_s;
    L.plant.x.i_a_A = L.sc.i_a0_A;
    L.plant.x.i_b_A = L.sc.i_b0_A;
    L.plant.integrator = L.sc.integrator; /* as the host runner */
    L.p = (double)L.plant.params.pole_pairs;
    sil_inverter_init(&L.inv, &L.sc.inverter, &L.sc.bus, L.sc.bus_voltage_V,
                      pmstep_console_config_delay_periods(&config));

    mps2_pil_init(&motor);
    insns_per_tick = mps2_pil_instructions_per_tick(100000u);
    cmsdk_uart_init(16u);
    pmstep_console_init(&console, "pmstep " PMSTEP_VERSION_TEXT " qemu-mps2-an386");
    pmstep_console_attach_simulation(&console);
    pmstep_console_attach_position(&console, &position);
    if (flash_path != NULL) {
        pmstep_console_attach_store(&console, &stored);
        pmstep_console_attach_calibration(&console, &calibration);
    }
    st = pmstep_console_attach_sim_stepdir(&console, &stepdir, &config); /* the settings in force, stored or not */
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-console: pmstep_console_attach_sim_stepdir: %s\n", pmstep_status_str(st));
        return 2;
    }
    snap.period = UINT32_MAX; /* no step yet */
    systick_last = SYST_CVR;

    while (!pmstep_console_finish_requested(&console)) {
        uint32_t n;
        service_uart();
        pmstep_console_boundary(&console, &motor, &config, &snap);
        n = pmstep_console_advance_request(&console);
        if (n == 0u) {
            continue;
        }
        /* SIM_ADVANCE: n periods (at most to the end of the run), the console served between them. */
        while (n > 0u && k < steps) {
            service_uart();
            pmstep_console_boundary(&console, &motor, &config, &snap); /* a command lands between two periods */
            run_period(&L, k, &snap);
            pmstep_console_telemetry(&console, &snap);
            ++k;
            --n;
        }
        flush_uart(); /* room for the reply, whatever a flood left in the transmit buffer */
        pmstep_console_advance_done(&console, (uint32_t)k);
    }
    flush_uart();
    {
        /* The SIM_FINISH reply on its way before QEMU exits and closes the socket. */
        const uint32_t t0 = now_ms();
        while (now_ms() - t0 < 200u) {
            service_uart();
        }
    }

    sil_metrics_finish(&L.metrics, &L.s);
    L.s.inverter_limited_periods = (long)L.inv.limited_periods;
    if (k != steps) {
        fprintf(stderr, "pil-console: finished after %ld of %ld periods\n", k, steps);
    }
    if (summary_path != NULL && write_file(summary_path, 0, &L, insns_per_tick, k) != 0) {
        return 2;
    }
    if (cost_path != NULL && write_file(cost_path, 1, &L, insns_per_tick, k) != 0) {
        return 2;
    }
    if (stepdir_path != NULL && write_file(stepdir_path, 2, &L, insns_per_tick, k) != 0) {
        return 2;
    }
    return k != steps ? 4 : (L.s.fault != PMSTEP_FAULT_NONE ? 3 : 0);
}
