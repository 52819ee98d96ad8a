/*
 * The console's simulation requests (pmstep_console.h, SIM_ADVANCE and SIM_FINISH): in a file
 * of its own so that only an image that calls pmstep_console_attach_simulation() (the QEMU
 * processor-in-the-loop image, the host drive of the tool's tests) links them; a hardware image
 * refuses them as PMSTEP_CONSOLE_ERR_NOT_SUPPORTED.
 */
#include "pmstep_console_internal.h"

/* SIM_ADVANCE: periods to run, answered once they have run (pmstep_console_advance_done());
 * SIM_FINISH: acknowledged at once, the image then writes its results and exits. */
static int sim_request(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *d, uint32_t n)
{
    (void)n; /* checked by the request table */
    if (c->advancing) {
        return PMSTEP_CONSOLE_ERR_BUSY;
    }
    if (type == PMSTEP_CONSOLE_SIM_FINISH) {
        c->finish_requested = true;
        pmstep_console_send_ack(c, type, seq, 0, 0u);
        return 0;
    }
    if (get_u32(d) == 0u) {
        return PMSTEP_CONSOLE_ERR_BAD_VALUE;
    }
    c->advance_periods = get_u32(d);
    c->advance_seq = seq;
    c->advancing = true;
    return 0;
}

void pmstep_console_attach_simulation(pmstep_console_t *c)
{
    c->sim_request = sim_request;
}

uint32_t pmstep_console_advance_request(pmstep_console_t *c)
{
    return c->advancing ? c->advance_periods : 0u;
}

void pmstep_console_advance_done(pmstep_console_t *c, uint32_t period)
{
    writer_t w;
    if (!c->advancing) {
        return;
    }
    c->advancing = false;
    w.n = 0;
    put_u16(&w, 0u);
    put_u32(&w, period);
    pmstep_console_send(c, PMSTEP_CONSOLE_SIM_ADVANCE | 0x80u, c->advance_seq, w.b, w.n);
}

bool pmstep_console_finish_requested(const pmstep_console_t *c)
{
    return c->finish_requested;
}
