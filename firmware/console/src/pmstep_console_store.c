/*
 * Command and telemetry interface: the stored configuration (see pmstep_console.h,
 * pmstep_store.h). Linked only by an image that calls pmstep_console_attach_store(): the CONFIG_*
 * requests that need the configuration in force are applied here at the period boundary.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

/* The bytes of a CONFIG_READ reply: offset u16, total u16, then the record's bytes. */
#define READ_CHUNK (PMSTEP_CONSOLE_MAX_PAYLOAD - 2u - 4u)

pmstep_store_status_t pmstep_console_store_boot(pmstep_console_store_t *cs, pmstep_store_t *store,
                                                const pmstep_config_t *defaults, pmstep_config_t *cfg)
{
    pmstep_store_record_t rec;
    pmstep_status_t why = PMSTEP_OK;
    pmstep_store_status_t st;
    if (cs == NULL || store == NULL || defaults == NULL || cfg == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    memset(cs, 0, sizeof *cs);
    cs->store = store;
    cs->defaults = *defaults;
    cs->boot_stepdir = pmstep_console_stepdir_defaults();
    st = pmstep_store_load(store, defaults, &rec, &why);
    cs->boot_status = (int16_t)st;
    cs->boot_validation = (int16_t)why;
    if (st == PMSTEP_STORE_OK) {
        *cfg = rec.config;
        cs->measured = rec.measured;
        cs->boot_stepdir = rec.stepdir;
        cs->configured = true;
    } else {
        *cfg = *defaults; /* nothing of a refused record */
    }
    return st;
}

/* What the instance's commissioning measured on this motor since its last start, as a record
 * keeps it; @p keep when it measured nothing. */
static pmstep_store_measured_t measured_now(const pmstep_t *inst, const pmstep_store_measured_t *keep)
{
    pmstep_commissioning_t cm;
    pmstep_store_measured_t m;
    pmstep_get_commissioning(inst, &cm);
    if (!cm.measured) {
        return *keep;
    }
    memset(&m, 0, sizeof m);
    m.offset_a_A = cm.offset_a_A;
    m.offset_b_A = cm.offset_b_A;
    m.flags |= cm.offset_samples > 0u ? PMSTEP_STORE_MEASURED_OFFSETS : 0u;
    m.resistance_Ohm = cm.resistance_Ohm;
    m.flags |= cm.resistance_Ohm > 0.0f ? PMSTEP_STORE_MEASURED_RESISTANCE : 0u;
    m.inductance_H = cm.inductance_H;
    m.flags |= cm.inductance_H > 0.0f ? PMSTEP_STORE_MEASURED_INDUCTANCE : 0u;
    m.torque_constant_Nm_A = cm.torque_constant_Nm_A;
    m.flags |= cm.torque_constant_Nm_A > 0.0f ? PMSTEP_STORE_MEASURED_TORQUE_CONSTANT : 0u;
    if (cm.identification == PMSTEP_IDENT_DONE || cm.identification == PMSTEP_IDENT_FRICTION_NEGATIVE) {
        m.inertia_kgm2 = cm.inertia_kgm2;
        m.friction_Nms_rad = cm.friction_Nms_rad;
        m.flags |= PMSTEP_STORE_MEASURED_MECHANICS;
    }
    return m;
}

int32_t pmstep_console_put_in_force(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                                    const pmstep_config_t *next)
{
    int32_t st;
    *cfg = *next;
    st = (int32_t)pmstep_init(inst, cfg);
    if (st == (int32_t)PMSTEP_OK && c->position_apply != NULL) {
        const float none[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        st = c->position_apply(c, PMSTEP_CONSOLE_SET_CONFIG, none, NULL);
    }
    return st;
}

static bool send_record(pmstep_console_t *c, const pmstep_console_request_t *req, const pmstep_t *inst,
                        const pmstep_config_t *cfg)
{
    pmstep_console_store_t *cs = c->store;
    uint32_t k;
    uint32_t n;
    writer_t w;
    if (req->offset == 0u || cs->image_bytes == 0u) {
        pmstep_store_record_t rec;
        rec.config = *cfg;
        rec.measured = measured_now(inst, &cs->measured);
        rec.stepdir = c->stepdir;
        cs->image_bytes = pmstep_store_encode(&rec, cs->store->board_id, 0u, cs->image);
    }
    if (req->offset >= cs->image_bytes) {
        pmstep_console_send_error(c, req->cmd, req->seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
        return false;
    }
    n = cs->image_bytes - req->offset < READ_CHUNK ? cs->image_bytes - req->offset : READ_CHUNK;
    w.n = 0;
    put_u16(&w, req->offset);
    put_u16(&w, cs->image_bytes);
    for (k = 0; k < n; ++k) {
        put_u8(&w, cs->image[req->offset + k]);
    }
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return true;
}

/* CONFIG_APPLY: the staged record decoded and validated whole, then in force. */
static int32_t apply_staged(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg)
{
    pmstep_console_store_t *cs = c->store;
    pmstep_store_record_t rec;
    pmstep_status_t why = PMSTEP_OK;
    const pmstep_store_status_t st =
        pmstep_store_decode(cs->staging, cs->staged, cs->store->board_id, &cs->defaults, &rec, &why, NULL);
    int32_t init;
    cs->staged = 0u; /* consumed, accepted or not: the next write starts at 0 */
    if (st != PMSTEP_STORE_OK) {
        return st == PMSTEP_STORE_ERR_INVALID && why != PMSTEP_OK ? (int32_t)why : (int32_t)st;
    }
    init = pmstep_console_put_in_force(c, inst, cfg, &rec.config);
    cs->configured = init == (int32_t)PMSTEP_OK;
    cs->measured = rec.measured;
    c->stepdir = rec.stepdir; /* validated with the rest by the decode */
    cs->image_bytes = 0u;
    return init;
}

static bool store_apply(pmstep_console_t *c, const pmstep_console_request_t *req, pmstep_t *inst, pmstep_config_t *cfg,
                        const pmstep_console_snapshot_t *snap)
{
    pmstep_console_store_t *cs = c->store;
    const pmstep_mode_t mode = pmstep_get_mode(inst);
    const bool idle = mode == PMSTEP_MODE_IDLE;
    const bool stopped = idle || mode == PMSTEP_MODE_FAULT;
    /* The flash is written only while the bridge cannot switch: stopped, and the last step's output off. */
    const bool bridge_off = stopped && !snap->out.bridge_enable;
    int32_t st;
    if (req->cmd == PMSTEP_CONSOLE_CONFIG_READ) {
        return send_record(c, req, inst, cfg);
    }
    if (req->cmd == PMSTEP_CONSOLE_CONFIG_APPLY || req->cmd == PMSTEP_CONSOLE_CONFIG_DEFAULTS ? !idle : !stopped) {
        pmstep_console_send_error(c, req->cmd, req->seq, PMSTEP_CONSOLE_ERR_NOT_STOPPED);
        return false;
    }
    switch (req->cmd) {
    case PMSTEP_CONSOLE_CONFIG_APPLY: st = apply_staged(c, inst, cfg); break;
    case PMSTEP_CONSOLE_CONFIG_SAVE: {
        pmstep_store_record_t rec;
        if (!cs->configured) {
            pmstep_console_send_error(c, req->cmd, req->seq, PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
            return false;
        }
        rec.config = *cfg;
        rec.measured = measured_now(inst, &cs->measured);
        rec.stepdir = c->stepdir;
        st = (int32_t)pmstep_store_save(cs->store, &rec, bridge_off);
        if (st == (int32_t)PMSTEP_STORE_OK) {
            cs->measured = rec.measured;
        }
        break;
    }
    case PMSTEP_CONSOLE_CONFIG_ERASE: st = (int32_t)pmstep_store_erase(cs->store, bridge_off); break;
    default: /* PMSTEP_CONSOLE_CONFIG_DEFAULTS */
        st = pmstep_console_put_in_force(c, inst, cfg, &cs->defaults);
        c->stepdir = pmstep_console_stepdir_defaults();
        cs->configured = false;
        memset(&cs->measured, 0, sizeof cs->measured);
        cs->image_bytes = 0u;
        break;
    }
    cs->last_status = (int16_t)st;
    pmstep_console_send_ack(c, req->cmd, req->seq, st, snap->period + 1u);
    return true;
}

void pmstep_console_attach_store(pmstep_console_t *c, pmstep_console_store_t *cs)
{
    c->store = cs;
    c->store_apply = store_apply;
    c->stepdir = cs->boot_stepdir;
}
