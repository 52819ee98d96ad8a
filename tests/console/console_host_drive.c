/*
 * A drive on the host for the console's tests: the console (simulation mode) and the real
 * core on stdin/stdout as a byte stream (a pty or a pipe), with constant samples (0.3 A,
 * 0.2 A, 48 V) in place of a motor. Periods run on SIM_ADVANCE; SIM_FINISH ends it.
 * usage: console-host-drive [--position]   (--position: position control attached, updated after
 * every step; without it the drive is an image in speed mode)
 */
#include <fcntl.h>
#include <string.h>
#include <poll.h>
#include <stdint.h>
#include <time.h>
#include <unistd.h>

#include "pmstep_console.h"

static uint32_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

static pmstep_console_t con;

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

int main(int argc, char **argv)
{
    static pmstep_position_t position;
    static pmstep_position_output_t pos_out;
    const int with_position = argc > 1 && strcmp(argv[1], "--position") == 0;
    static pmstep_t motor;
    static pmstep_config_t cfg;
    static pmstep_console_snapshot_t snap; /* zero: no output yet */
    const pmstep_meas_t meas = {0.3f, 0.2f, 48.0f, 0.0f, 0.0f, 0.0f};
    snap.period = UINT32_MAX;                /* no step yet */
    cfg = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    if (pmstep_init(&motor, &cfg) != PMSTEP_OK) {
        return 2;
    }
    pmstep_console_init(&con, "pmstep host-drive");
    pmstep_console_attach_simulation(&con);
    if (with_position) {
        pmstep_position_config_t gains;
        if (pmstep_position_design(&cfg, &gains) != PMSTEP_OK || pmstep_position_init(&position, &motor, &gains) != PMSTEP_OK) {
            return 2;
        }
        pmstep_console_attach_position(&con, &position);
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
                pmstep_position_update(&position, &snap.out, &pos_out);
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
