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

/* Every byte of pmstep_config_t is a value of the table, or padding after a boolean: a field the
 * table lacks would not be stored. */
static void test_table_covers_every_field(void **state)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    unsigned char covered[sizeof(pmstep_config_t)] = {0};
    bool after_bool[sizeof(pmstep_config_t)] = {false};
    uint32_t id;
    size_t i;
    (void)state;
    assert_true(count <= PMSTEP_STORE_MAX_VALUES);
    for (id = 0; id < count; ++id) {
        const size_t size = t[id].type == PMSTEP_CONSOLE_CFG_BOOL ? sizeof(bool) : 4u;
        for (i = 0; i < size; ++i) {
            covered[t[id].offset + i] = 1u;
        }
        if (t[id].type == PMSTEP_CONSOLE_CFG_BOOL) {
            for (i = t[id].offset + sizeof(bool); i < sizeof(pmstep_config_t) && i % 4u != 0u; ++i) {
                after_bool[i] = true;
            }
        }
    }
    for (i = 0; i < sizeof(pmstep_config_t); ++i) {
        if (!covered[i] && !after_bool[i]) {
            fail_msg("byte %zu of pmstep_config_t is in no entry of the configuration table", i);
        }
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
    assert_true(back.config.motor.inertia_kgm2 == 0.01f * 1.7f);
    {
        uint32_t id;
        for (id = 0; id < count; ++id) {
            float x = 0.0f;
            float y = 1.0f;
            (void)pmstep_console_config_get(&rec.config, id, &x);
            (void)pmstep_console_config_get(&back.config, id, &y);
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

static void test_empty_store(void **state)
{
    pmstep_store_record_t out;
    (void)state;
    assert_int_equal(pmstep_store_load(&store, &board, &out, NULL), PMSTEP_STORE_EMPTY);
    assert_int_equal(store.slot, -1);
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
static long save_operations(void)
{
    return 1L + (long)((pmstep_store_record_bytes() + 7u) / 8u);
}

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
        cmocka_unit_test_setup(test_empty_store, setup),
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
