/*
 * Unit tests of the stored configuration (pmstep_store.c): the record's encoding, every cause of
 * refusal, the two slots, and a power cut at every erase and program step of a save and of an
 * erase (fake_flash.c: a NOR flash with ECC, torn units reading with an error).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "fake_flash.h"
#include "pmstep_console.h"
#include "pmstep_store.h"
#include "pmstep/pmstep_text.h"
#include "stepdir_settings_equal.h"

#define BOARD_ID 0x47343331u

static fake_flash_t flash;
static pmstep_store_t store;
static pmstep_config_t board;

static int setup(void **state)
{
    (void)state;
    fake_flash_init(&flash);
    board = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    return 0;
}

/* A record of the board's configuration told apart by its rotor inertia, @p mark x 10 g m^2 (a value
 * the core accepts; mark < 0 one it refuses), and measured values. */
static pmstep_store_record_t record_with(float mark)
{
    pmstep_store_record_t rec;
    memset(&rec, 0, sizeof rec);
    rec.config = board;
    rec.stepdir = pmstep_console_stepdir_defaults();
    rec.config.motor.inertia_kgm2 = 0.01f * mark;
    rec.measured.flags = PMSTEP_STORE_MEASURED_RESISTANCE | PMSTEP_STORE_MEASURED_MECHANICS;
    rec.measured.resistance_Ohm = 2.1f;
    rec.measured.inertia_kgm2 = 0.0123f;
    rec.measured.friction_Nms_rad = 1e-4f;
    return rec;
}

static void rewrite_crc(uint8_t *b, uint32_t n)
{
    const uint32_t crc = pmstep_store_crc32(0u, b, n - 4u);
    b[n - 4u] = (uint8_t)crc;
    b[n - 3u] = (uint8_t)(crc >> 8);
    b[n - 2u] = (uint8_t)(crc >> 16);
    b[n - 1u] = (uint8_t)(crc >> 24);
}

static void test_crc32_check_value(void **state)
{
    (void)state;
    assert_int_equal(pmstep_store_crc32(0u, (const uint8_t *)"123456789", 9u), 0xCBF43926u);
}

/* Every byte of @p bytes-long struct is a value of the table's entries with (@p flags & STEPDIR) equal
 * to @p stepdir, or padding after a boolean: a field the table lacks would not be stored. */
static void check_covered(uint8_t stepdir, size_t bytes, const char *what)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    unsigned char covered[sizeof(pmstep_config_t)] = {0};
    bool after_bool[sizeof(pmstep_config_t)] = {false};
    uint32_t id;
    size_t i;
    assert_true(bytes <= sizeof covered);
    for (id = 0; id < count; ++id) {
        const size_t size = t[id].type == PMSTEP_CONSOLE_CFG_BOOL ? sizeof(bool) : 4u;
        if ((t[id].flags & PMSTEP_CONSOLE_CFG_STEPDIR) != stepdir) {
            continue;
        }
        assert_true(t[id].offset + size <= bytes);
        for (i = 0; i < size; ++i) {
            covered[t[id].offset + i] = 1u;
        }
        if (t[id].type == PMSTEP_CONSOLE_CFG_BOOL) {
            for (i = t[id].offset + sizeof(bool); i < bytes && i % 4u != 0u; ++i) {
                after_bool[i] = true;
            }
        }
    }
    for (i = 0; i < bytes; ++i) {
        if (!covered[i] && !after_bool[i]) {
            fail_msg("byte %zu of %s is in no entry of the configuration table", i, what);
        }
    }
}

static void test_table_covers_every_field(void **state)
{
    uint32_t count;
    uint32_t id;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    (void)state;
    assert_true(count <= PMSTEP_STORE_MAX_VALUES);
    check_covered(0u, sizeof(pmstep_config_t), "pmstep_config_t");
    check_covered(PMSTEP_CONSOLE_CFG_STEPDIR, sizeof(pmstep_stepdir_settings_t), "pmstep_stepdir_settings_t");
    /* The STEP/DIR settings are named stepdir.*, and only they. */
    for (id = 0; id < count; ++id) {
        assert_int_equal(strncmp(t[id].name, "stepdir.", 8u) == 0, pmstep_console_config_is_stepdir(id));
    }
}

static void test_round_trip(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const pmstep_store_record_t rec = record_with(1.7f);
    pmstep_store_record_t back;
    uint32_t seq = 0u;
    uint32_t count;
    const uint32_t n = pmstep_store_encode(&rec, BOARD_ID, 7u, b);
    (void)state;
    (void)pmstep_console_config_table(&count);
    assert_int_equal(n, 32u + 4u * count + 32u + 4u);
    assert_int_equal(n, pmstep_store_record_bytes());
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &back, NULL, &seq), PMSTEP_STORE_OK);
    assert_int_equal(seq, 7u);
    assert_memory_equal(&back.measured, &rec.measured, sizeof rec.measured);
    assert_stepdir_settings_equal(&back.stepdir, &rec.stepdir);
    assert_true(back.config.motor.inertia_kgm2 == 0.01f * 1.7f);
    {
        uint32_t id;
        for (id = 0; id < count; ++id) {
            float x = 0.0f;
            float y = 1.0f;
            (void)pmstep_console_config_get(&rec.config, &rec.stepdir, id, &x);
            (void)pmstep_console_config_get(&back.config, &back.stepdir, id, &y);
            assert_true(x == y);
        }
    }
}

/* Each refusal names its cause, and leaves the output untouched. */
static void test_refusals(void **state)
{
    uint8_t good[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const pmstep_store_record_t rec = record_with(1.7f);
    pmstep_store_record_t out;
    pmstep_store_record_t untouched;
    pmstep_status_t why;
    uint32_t count;
    const uint32_t n = pmstep_store_encode(&rec, BOARD_ID, 1u, good);
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t period_id = 0u;
    uint32_t bool_id = 0u;
    uint32_t id;
    (void)state;
    for (id = 0; id < count; ++id) {
        if (strcmp(t[id].name, "timing.period_s") == 0) {
            period_id = id;
        }
        if (strcmp(t[id].name, "known_load_mode") == 0) {
            bool_id = id;
        }
    }
    memset(&out, 0xAB, sizeof out);
    untouched = out;

    memcpy(b, good, n);
    b[40] ^= 1u; /* one bit of a value */
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_CRC);

    memcpy(b, good, n);
    b[4] = 2u; /* format version 2: a newer firmware's record */
    rewrite_crc(b, n);
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_FORMAT);

    memcpy(b, good, n);
    b[12] ^= 0xFFu; /* another table */
    rewrite_crc(b, n);
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_LAYOUT);

    assert_int_equal(pmstep_store_decode(good, n, BOARD_ID + 1u, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_BOARD);

    memcpy(b, good, n);
    {
        const float other_period = 100e-6f; /* a board of another carrier */
        memcpy(&b[32u + 4u * period_id], &other_period, 4u);
    }
    rewrite_crc(b, n);
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_BOARD);

    memcpy(b, good, n);
    {
        const float half = 0.5f; /* a boolean that is neither */
        memcpy(&b[32u + 4u * bool_id], &half, 4u);
    }
    rewrite_crc(b, n);
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_INVALID);

    {
        pmstep_store_record_t bad = record_with(-1.0f); /* J < 0: the core refuses it */
        (void)pmstep_store_encode(&bad, BOARD_ID, 1u, b);
        assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, &why, NULL), PMSTEP_STORE_ERR_INVALID);
        assert_int_equal(why, PMSTEP_ERR_INERTIA);
    }

    assert_int_equal(pmstep_store_decode(good, n - 4u, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_LENGTH);
    assert_int_equal(pmstep_store_decode(good, 16u, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_LENGTH);
    assert_memory_equal(&out, &untouched, sizeof out);
}

/* The id of the table's entry @p name. */
static uint32_t entry(const char *name)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t id;
    for (id = 0; id < count; ++id) {
        if (strcmp(t[id].name, name) == 0) {
            return id;
        }
    }
    fail_msg("no configuration entry %s", name);
    return 0u;
}

/* STEP/DIR settings other than the defaults, every one of them, saved and loaded after a reset. */
static void test_stepdir_settings_saved(void **state)
{
    pmstep_store_record_t rec = record_with(1.0f);
    pmstep_store_record_t out;
    (void)state;
    rec.stepdir.microsteps = 256u;
    rec.stepdir.invert_direction = true;
    rec.stepdir.enable_active_high = true;
    rec.stepdir.diag_active_high = false;
    rec.stepdir.diag_mode = 1u;
    rec.stepdir.following_error_limit_full_steps = 2.5f;
    assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    memset(&out, 0, sizeof out);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
    assert_int_equal(out.stepdir.microsteps, 256u);
    assert_true(out.stepdir.invert_direction);
    assert_true(out.stepdir.enable_active_high);
    assert_false(out.stepdir.diag_active_high);
    assert_int_equal(out.stepdir.diag_mode, PMSTEP_DIAG_PULSE);
    assert_true(out.stepdir.following_error_limit_full_steps == 2.5f);
}

/* A record with a STEP/DIR value out of range: refused whole with the cause's own code, never clamped. */
static void test_stepdir_settings_refused_by_cause(void **state)
{
    static const struct {
        const char *name;
        float value;
        pmstep_status_t why;
    } bad[] = {
        {"stepdir.microsteps", 0.0f, PMSTEP_ERR_STEPDIR_MICROSTEPS},
        {"stepdir.microsteps", 257.0f, PMSTEP_ERR_STEPDIR_MICROSTEPS},
        {"stepdir.microsteps", 1024.0f, PMSTEP_ERR_STEPDIR_MICROSTEPS},
        {"stepdir.diag_mode", 2.0f, PMSTEP_ERR_STEPDIR_DIAG_MODE},
        {"stepdir.following_error_limit_full_steps", 0.0f, PMSTEP_ERR_STEPDIR_LIMIT},
        {"stepdir.following_error_limit_full_steps", -1.0f, PMSTEP_ERR_STEPDIR_LIMIT},
    };
    uint8_t good[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const pmstep_store_record_t rec = record_with(1.0f);
    const uint32_t n = pmstep_store_encode(&rec, BOARD_ID, 1u, good);
    pmstep_store_record_t out;
    pmstep_store_record_t untouched;
    size_t k;
    (void)state;
    memset(&out, 0xAB, sizeof out);
    untouched = out;
    for (k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        pmstep_status_t why = PMSTEP_OK;
        memcpy(b, good, n);
        memcpy(&b[32u + 4u * entry(bad[k].name)], &bad[k].value, 4u);
        rewrite_crc(b, n);
        assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, &why, NULL), PMSTEP_STORE_ERR_INVALID);
        assert_int_equal(why, bad[k].why);
    }
    {
        /* Not a whole number, and a boolean that is neither: the value's type refuses it. */
        const float half = 0.5f;
        pmstep_status_t why = PMSTEP_ERR_NULL_ARGUMENT;
        memcpy(b, good, n);
        memcpy(&b[32u + 4u * entry("stepdir.microsteps")], &half, 4u);
        rewrite_crc(b, n);
        assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, &why, NULL), PMSTEP_STORE_ERR_INVALID);
        assert_int_equal(why, PMSTEP_OK);
        memcpy(b, good, n);
        memcpy(&b[32u + 4u * entry("stepdir.invert_direction")], &half, 4u);
        rewrite_crc(b, n);
        assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_INVALID);
    }
    assert_memory_equal(&out, &untouched, sizeof out);
}

/* A record as the firmware before the STEP/DIR settings wrote it: the same format, its table's entries
 * only (those before the first stepdir.*: every later entry was appended after them), that table's
 * layout id. */
static uint32_t record_before_stepdir(const pmstep_store_record_t *rec, uint32_t sequence, uint8_t *out)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t old = 0u;
    uint32_t layout = 0u;
    uint8_t full[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n;
    uint32_t id;
    (void)pmstep_store_encode(rec, BOARD_ID, sequence, full);
    for (id = 0; id < count && !pmstep_console_config_is_stepdir(id); ++id) {
        const uint8_t type = t[id].type;
        layout = pmstep_store_crc32(layout, (const uint8_t *)t[id].name, (uint32_t)strlen(t[id].name) + 1u);
        layout = pmstep_store_crc32(layout, &type, 1u);
        ++old;
    }
    n = 32u + 4u * old + 4u * PMSTEP_STORE_MEASURED_VALUES + 4u;
    memcpy(out, full, 32u);
    memcpy(&out[32], &full[32], 4u * old);                                                    /* the values */
    memcpy(&out[32u + 4u * old], &full[32u + 4u * count], 4u * PMSTEP_STORE_MEASURED_VALUES); /* measured */
    out[12] = (uint8_t)layout;
    out[13] = (uint8_t)(layout >> 8);
    out[14] = (uint8_t)(layout >> 16);
    out[15] = (uint8_t)(layout >> 24);
    out[20] = (uint8_t)old;
    out[21] = (uint8_t)(old >> 8);
    out[24] = (uint8_t)n;
    out[25] = (uint8_t)(n >> 8);
    out[26] = 0u;
    out[27] = 0u;
    rewrite_crc(out, n);
    return n;
}

/* A record of the firmware before the STEP/DIR settings is refused by name (another layout), as the
 * newest record at boot too: the store never reads it in part, and a save of this firmware's record
 * goes to the other slot and is in force after a reset. */
static void test_record_before_stepdir_settings_refused(void **state)
{
    const pmstep_store_record_t rec = record_with(1.0f);
    pmstep_store_record_t out;
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n;
    uint32_t off;
    uint32_t count;
    uint32_t stepdir_values = 0u;
    uint32_t older = 0u; /* entries before the first stepdir.* */
    uint32_t id;
    (void)state;
    memset(b, 0xFF, sizeof b);
    (void)pmstep_console_config_table(&count);
    for (id = 0; id < count; ++id) {
        stepdir_values += pmstep_console_config_is_stepdir(id) ? 1u : 0u;
    }
    while (older < count && !pmstep_console_config_is_stepdir(older)) {
        ++older;
    }
    n = record_before_stepdir(&rec, 1u, b);
    assert_int_equal(stepdir_values, 7u);
    /* the STEP/DIR values and the entries appended after them fewer */
    assert_int_equal(n, pmstep_store_record_bytes() - 4u * (count - older));
    assert_int_equal(pmstep_store_decode(b, n, BOARD_ID, &board, &out, NULL, NULL), PMSTEP_STORE_ERR_LAYOUT);
    assert_int_equal(flash.ops.erase(flash.ops.ctx, 0u), 0);
    for (off = 0; off < ((n + 7u) & ~7u); off += 8u) {
        assert_int_equal(flash.ops.program(flash.ops.ctx, 0u, off, &b[off], 8u), 0);
    }
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_ERR_LAYOUT);
    assert_int_equal(store.slot, 0);
    assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_OK);
    assert_int_equal(store.slot, 1);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
    assert_stepdir_settings_equal(&out.stepdir, &rec.stepdir);
}

static void test_empty_store(void **state)
{
    pmstep_store_record_t out;
    (void)state;
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_EMPTY);
    assert_int_equal(store.slot, -1);
}

/* The store's outcomes and the core's status codes share an ACK's status field: no store
 * code is a core status (pmstep_status_str() knows none of them). */
static void test_codes_disjoint_from_core_status(void **state)
{
    int code;
    (void)state;
    for (code = (int)PMSTEP_STORE_EMPTY; code >= (int)PMSTEP_STORE_ERR_NULL; code--) {
        assert_string_equal(pmstep_status_str((pmstep_status_t)code), "unknown status");
    }
}

static void test_saves_alternate_slots(void **state)
{
    pmstep_store_record_t a = record_with(1.0f);
    pmstep_store_record_t b = record_with(2.0f);
    pmstep_store_record_t c = record_with(3.0f);
    pmstep_store_record_t out;
    (void)state;
    assert_int_equal(pmstep_store_save(&store, &a, true), PMSTEP_STORE_OK);
    assert_int_equal(store.slot, 0);
    assert_int_equal(pmstep_store_save(&store, &b, true), PMSTEP_STORE_OK);
    assert_int_equal(store.slot, 1);
    assert_int_equal(pmstep_store_save(&store, &c, true), PMSTEP_STORE_OK);
    assert_int_equal(store.slot, 0);
    assert_int_equal(store.sequence, 3u);
    /* a reset: a new store on the same flash */
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
    assert_true(out.config.motor.inertia_kgm2 == 0.01f * 3.0f);
    assert_int_equal(store.sequence, 3u);
    assert_int_equal(store.slot, 0);
}

/* The operations (erases and 8-byte programs) of one save. */
static long save_operations(void) { return 1L + (long)((pmstep_store_record_bytes() + 7u) / 8u); }

/* A power cut in the middle of every operation of a save, over a store holding one record and
 * over one holding two: after the reset the previous record is in force, and the next save works. */
static void test_power_cut_at_every_save_step(void **state)
{
    const long ops = save_operations();
    unsigned before;
    (void)state;
    for (before = 1u; before <= 2u; ++before) {
        long cut;
        for (cut = 1; cut <= ops; ++cut) {
            pmstep_store_record_t out;
            pmstep_store_record_t prev = record_with(1.0f);
            pmstep_store_record_t next = record_with(9.0f);
            fake_flash_init(&flash);
            assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
            if (before == 2u) {
                pmstep_store_record_t older = record_with(0.5f);
                assert_int_equal(pmstep_store_save(&store, &older, true), PMSTEP_STORE_OK);
            }
            assert_int_equal(pmstep_store_save(&store, &prev, true), PMSTEP_STORE_OK);
            fake_flash_cut_after(&flash, cut);
            assert_int_equal(pmstep_store_save(&store, &next, true), PMSTEP_STORE_ERR_FLASH);
            fake_flash_power_on(&flash);
            assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
            if (pmstep_store_load(&store, &board, &out, NULL) != PMSTEP_STORE_OK) {
                fail_msg("cut at operation %ld of %ld (%u record(s) before): no record after the reset", cut, ops,
                         before);
            }
            if (out.config.motor.inertia_kgm2 != 0.01f * 1.0f) {
                fail_msg("cut at operation %ld of %ld: J %g x 10 g m^2 in force, not the previous record's 1", cut, ops,
                         (double)(out.config.motor.inertia_kgm2 / 0.01f));
            }
            assert_int_equal(pmstep_store_save(&store, &next, true), PMSTEP_STORE_OK);
            assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
            assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
            assert_true(out.config.motor.inertia_kgm2 == 0.01f * 9.0f);
        }
    }
}

/* The first save ever, cut anywhere: the store stays empty (a safe default), never half a record. */
static void test_power_cut_in_first_save(void **state)
{
    const long ops = save_operations();
    long cut;
    (void)state;
    for (cut = 1; cut <= ops; ++cut) {
        pmstep_store_record_t out;
        pmstep_store_record_t rec = record_with(1.0f);
        fake_flash_init(&flash);
        assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
        fake_flash_cut_after(&flash, cut);
        assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_ERR_FLASH);
        fake_flash_power_on(&flash);
        assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
        assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_EMPTY);
    }
}

/* Erasing the store, cut in the first or second erase: the newest record or nothing, never the older. */
static void test_power_cut_in_erase(void **state)
{
    long cut;
    (void)state;
    for (cut = 1; cut <= 2; ++cut) {
        pmstep_store_record_t out;
        pmstep_store_record_t a = record_with(1.0f);
        pmstep_store_record_t b = record_with(2.0f);
        pmstep_store_status_t st;
        fake_flash_init(&flash);
        assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
        assert_int_equal(pmstep_store_save(&store, &a, true), PMSTEP_STORE_OK);
        assert_int_equal(pmstep_store_save(&store, &b, true), PMSTEP_STORE_OK);
        fake_flash_cut_after(&flash, cut);
        assert_int_equal(pmstep_store_erase(&store, true), PMSTEP_STORE_ERR_FLASH);
        fake_flash_power_on(&flash);
        assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
        st = pmstep_store_load(&store, &board, &out, NULL);
        if (cut == 1) {
            assert_int_equal(st, PMSTEP_STORE_OK);
            assert_true(out.config.motor.inertia_kgm2 == 0.01f * 2.0f);
        } else {
            assert_int_equal(st, PMSTEP_STORE_EMPTY);
        }
    }
}

static void test_flash_errors_keep_previous(void **state)
{
    pmstep_store_record_t a = record_with(1.0f);
    pmstep_store_record_t b = record_with(2.0f);
    pmstep_store_record_t out;
    (void)state;
    assert_int_equal(pmstep_store_save(&store, &a, true), PMSTEP_STORE_OK);
    flash.fail_program_at = (int32_t)flash.programs + 5; /* a program error on the sixth unit */
    assert_int_equal(pmstep_store_save(&store, &b, true), PMSTEP_STORE_ERR_FLASH);
    assert_int_equal(store.flash_error, -4);
    flash.fail_erase = 1;
    assert_int_equal(pmstep_store_save(&store, &b, true), PMSTEP_STORE_ERR_FLASH);
    assert_int_equal(store.flash_error, -3);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
    assert_true(out.config.motor.inertia_kgm2 == 0.01f * 1.0f);
}

static void test_bridge_on_refused(void **state)
{
    pmstep_store_record_t a = record_with(1.0f);
    (void)state;
    assert_int_equal(pmstep_store_save(&store, &a, false), PMSTEP_STORE_ERR_BRIDGE_ON);
    assert_int_equal(pmstep_store_erase(&store, false), PMSTEP_STORE_ERR_BRIDGE_ON);
    assert_int_equal(flash.erases, 0u);
    assert_int_equal(flash.programs, 0u);
}

/* The newest record of a future format: refused by name, the older record of this format not used
 * in its place; a save then goes to the other slot and is in force. */
static void test_newest_foreign_record_refused(void **state)
{
    pmstep_store_record_t a = record_with(1.0f);
    pmstep_store_record_t out;
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n;
    uint32_t off;
    (void)state;
    assert_int_equal(pmstep_store_save(&store, &a, true), PMSTEP_STORE_OK); /* slot 0, sequence 1 */
    memset(b, 0xFF, sizeof b);
    n = pmstep_store_encode(&a, BOARD_ID, 2u, b);
    b[4] = 2u;
    rewrite_crc(b, n);
    assert_int_equal(flash.ops.erase(flash.ops.ctx, 1u), 0);
    for (off = 0; off < ((n + 7u) & ~7u); off += 8u) {
        assert_int_equal(flash.ops.program(flash.ops.ctx, 1u, off, &b[off], 8u), 0);
    }
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_ERR_FORMAT);
    assert_int_equal(store.slot, 1);
    a.config.motor.inertia_kgm2 = 0.04f;
    assert_int_equal(pmstep_store_save(&store, &a, true), PMSTEP_STORE_OK);
    assert_int_equal(store.slot, 0);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_OK);
    assert_true(out.config.motor.inertia_kgm2 == 0.01f * 4.0f);
}

static void test_small_slots_refused(void **state)
{
    pmstep_store_flash_t small = flash.ops;
    (void)state;
    small.slot_bytes = 256u;
    assert_int_equal(pmstep_store_init(&store, &small, BOARD_ID), PMSTEP_STORE_ERR_SLOT_SIZE);
    small.read = NULL;
    assert_int_equal(pmstep_store_init(&store, &small, BOARD_ID), PMSTEP_STORE_ERR_NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32_check_value),
        cmocka_unit_test(test_table_covers_every_field),
        cmocka_unit_test_setup(test_round_trip, setup),
        cmocka_unit_test_setup(test_refusals, setup),
        cmocka_unit_test_setup(test_stepdir_settings_saved, setup),
        cmocka_unit_test_setup(test_stepdir_settings_refused_by_cause, setup),
        cmocka_unit_test_setup(test_record_before_stepdir_settings_refused, setup),
        cmocka_unit_test_setup(test_empty_store, setup),
        cmocka_unit_test(test_codes_disjoint_from_core_status),
        cmocka_unit_test_setup(test_saves_alternate_slots, setup),
        cmocka_unit_test_setup(test_power_cut_at_every_save_step, setup),
        cmocka_unit_test_setup(test_power_cut_in_first_save, setup),
        cmocka_unit_test_setup(test_power_cut_in_erase, setup),
        cmocka_unit_test_setup(test_flash_errors_keep_previous, setup),
        cmocka_unit_test_setup(test_bridge_on_refused, setup),
        cmocka_unit_test_setup(test_newest_foreign_record_refused, setup),
        cmocka_unit_test_setup(test_small_slots_refused, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
