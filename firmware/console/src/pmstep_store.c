/*
 * The stored configuration (see pmstep_store.h): the record's encoding and decoding on the
 * console's configuration table, and its two flash slots. Every loop is bounded by the table's
 * length or a record's; nothing here waits except in the port's flash functions.
 */
#include "pmstep_store.h"

#include <stddef.h>
#include <string.h>

#include "pmstep_console.h"

#define OFF_MAGIC 0u
#define OFF_FORMAT 4u
#define OFF_HEADER 6u
#define OFF_BOARD 8u
#define OFF_LAYOUT 12u
#define OFF_SEQUENCE 16u
#define OFF_VALUES 20u
#define OFF_MEASURED 22u
#define OFF_BYTES 24u
#define OFF_RESERVED 28u

static void put16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
}

static void put32(uint8_t *p, uint32_t v)
{
    put16(p, v & 0xFFFFu);
    put16(p + 2, v >> 16);
}

static uint32_t get16(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}

static uint32_t get32(const uint8_t *p)
{
    return get16(p) | (get16(p + 2) << 16);
}

static void put_float(uint8_t *p, float x)
{
    uint32_t v;
    memcpy(&v, &x, sizeof v);
    put32(p, v);
}

static float get_float(const uint8_t *p)
{
    const uint32_t v = get32(p);
    float x;
    memcpy(&x, &v, sizeof x);
    return x;
}

uint32_t pmstep_store_crc32(uint32_t crc, const uint8_t *data, uint32_t n)
{
    uint32_t c = ~crc;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        uint32_t bit;
        c ^= data[i];
        for (bit = 0; bit < 8u; ++bit) {
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u))); /* reflected 0x04C11DB7 */
        }
    }
    return ~c;
}

static uint32_t table_count(void)
{
    uint32_t count;
    (void)pmstep_console_config_table(&count);
    return count;
}

uint32_t pmstep_store_layout_id(void)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t crc = 0u;
    uint32_t id;
    for (id = 0; id < count; ++id) {
        const char *name = t[id].name;
        const uint8_t type = t[id].type;
        crc = pmstep_store_crc32(crc, (const uint8_t *)name, (uint32_t)strlen(name) + 1u); /* with its NUL */
        crc = pmstep_store_crc32(crc, &type, 1u);
    }
    return crc;
}

static uint32_t record_bytes(uint32_t values)
{
    return PMSTEP_STORE_HEADER_BYTES + 4u * values + 4u * PMSTEP_STORE_MEASURED_VALUES + 4u;
}

uint32_t pmstep_store_record_bytes(void)
{
    return record_bytes(table_count());
}

uint32_t pmstep_store_encode(const pmstep_store_record_t *rec, uint32_t board_id, uint32_t sequence, uint8_t *out)
{
    const uint32_t count = table_count();
    const uint32_t n = record_bytes(count);
    const pmstep_store_measured_t *m = &rec->measured;
    const float measured[PMSTEP_STORE_MEASURED_VALUES - 1u] = {
        m->offset_a_A,           m->offset_b_A,   m->resistance_Ohm,  m->inductance_H,
        m->torque_constant_Nm_A, m->inertia_kgm2, m->friction_Nms_rad};
    uint8_t *p = out + PMSTEP_STORE_HEADER_BYTES;
    uint32_t id;
    put32(out + OFF_MAGIC, PMSTEP_STORE_MAGIC);
    put16(out + OFF_FORMAT, PMSTEP_STORE_FORMAT_VERSION);
    put16(out + OFF_HEADER, PMSTEP_STORE_HEADER_BYTES);
    put32(out + OFF_BOARD, board_id);
    put32(out + OFF_LAYOUT, pmstep_store_layout_id());
    put32(out + OFF_SEQUENCE, sequence);
    put16(out + OFF_VALUES, count);
    put16(out + OFF_MEASURED, PMSTEP_STORE_MEASURED_VALUES);
    put32(out + OFF_BYTES, n);
    put32(out + OFF_RESERVED, 0u);
    for (id = 0; id < count; ++id) {
        float value = 0.0f;
        (void)pmstep_console_config_get(&rec->config, &rec->stepdir, id, &value);
        put_float(p, value);
        p += 4;
    }
    put32(p, m->flags);
    p += 4;
    for (id = 0; id < PMSTEP_STORE_MEASURED_VALUES - 1u; ++id) {
        put_float(p, measured[id]);
        p += 4;
    }
    put32(p, pmstep_store_crc32(0u, out, n - 4u));
    return n;
}

/* The header's checks, in the order that names the most useful cause first: a record of another
 * format or layout may have any length. */
static pmstep_store_status_t check_header(const uint8_t *in, uint32_t n, uint32_t board_id)
{
    const uint32_t count = table_count();
    uint32_t length;
    if (n < PMSTEP_STORE_HEADER_BYTES || get32(in + OFF_MAGIC) != PMSTEP_STORE_MAGIC) {
        return n < PMSTEP_STORE_HEADER_BYTES ? PMSTEP_STORE_ERR_LENGTH : PMSTEP_STORE_ERR_CRC;
    }
    length = get32(in + OFF_BYTES);
    if (length < PMSTEP_STORE_HEADER_BYTES + 4u || length > n) {
        return PMSTEP_STORE_ERR_LENGTH;
    }
    if (pmstep_store_crc32(0u, in, length - 4u) != get32(in + length - 4u)) {
        return PMSTEP_STORE_ERR_CRC;
    }
    if (get16(in + OFF_FORMAT) != PMSTEP_STORE_FORMAT_VERSION || get16(in + OFF_HEADER) != PMSTEP_STORE_HEADER_BYTES) {
        return PMSTEP_STORE_ERR_FORMAT;
    }
    if (get32(in + OFF_LAYOUT) != pmstep_store_layout_id() || get16(in + OFF_VALUES) != count) {
        return PMSTEP_STORE_ERR_LAYOUT;
    }
    if (get32(in + OFF_BOARD) != board_id) {
        return PMSTEP_STORE_ERR_BOARD;
    }
    if (get16(in + OFF_MEASURED) != PMSTEP_STORE_MEASURED_VALUES || length != record_bytes(count)) {
        return PMSTEP_STORE_ERR_LENGTH;
    }
    return PMSTEP_STORE_OK;
}

/* The settings of a record, one float per row of the console's table from @p p on, over @p trial's
 * (the board's, the STEP/DIR defaults): a read-only one must equal the board's own. */
static pmstep_store_status_t decode_settings(const uint8_t *p, const pmstep_config_t *board,
                                             pmstep_store_record_t *trial)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    pmstep_store_status_t st = PMSTEP_STORE_OK;
    uint32_t id;
    for (id = 0; id < count && st == PMSTEP_STORE_OK; ++id) {
        const float value = get_float(p + 4u * id);
        if ((t[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) != 0u) {
            float own = 0.0f;
            (void)pmstep_console_config_get(board, &trial->stepdir, id, &own);
            if (value != own) {
                st = PMSTEP_STORE_ERR_BOARD; /* made for another period, delay or sensing */
            }
        } else if (pmstep_console_config_set(&trial->config, &trial->stepdir, id, value) != 0) {
            st = PMSTEP_STORE_ERR_INVALID;
        } else {
            /* taken */
        }
    }
    return st;
}

/* The measured constants of a record from @p p on: their flags, then the values in their order. */
static void decode_measured(const uint8_t *p, pmstep_store_measured_t *m)
{
    float measured[PMSTEP_STORE_MEASURED_VALUES - 1u];
    uint32_t id;
    m->flags = get32(p);
    for (id = 0; id < PMSTEP_STORE_MEASURED_VALUES - 1u; ++id) {
        measured[id] = get_float(p + 4u + 4u * id);
    }
    m->offset_a_A = measured[0];
    m->offset_b_A = measured[1];
    m->resistance_Ohm = measured[2];
    m->inductance_H = measured[3];
    m->torque_constant_Nm_A = measured[4];
    m->inertia_kgm2 = measured[5];
    m->friction_Nms_rad = measured[6];
}

pmstep_store_status_t pmstep_store_decode(const uint8_t *in, uint32_t n, uint32_t board_id,
                                          const pmstep_config_t *board, pmstep_store_record_t *rec,
                                          pmstep_status_t *validation, uint32_t *sequence)
{
    uint32_t count;
    pmstep_store_record_t trial;
    pmstep_store_status_t st;
    pmstep_status_t valid;
    if (validation != NULL) {
        *validation = PMSTEP_OK;
    }
    if (in == NULL || board == NULL || rec == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    st = check_header(in, n, board_id);
    if (st != PMSTEP_STORE_OK) {
        return st;
    }
    trial.config = *board;
    trial.stepdir = pmstep_console_stepdir_defaults(); /* every one of them is in the record */
    st = decode_settings(in + PMSTEP_STORE_HEADER_BYTES, board, &trial);
    if (st != PMSTEP_STORE_OK) {
        return st;
    }
    (void)pmstep_console_config_table(&count);
    decode_measured(in + PMSTEP_STORE_HEADER_BYTES + 4u * count, &trial.measured);
    valid = pmstep_validate_config(&trial.config);
    if (valid == PMSTEP_OK) {
        pmstep_stepdir_config_t in_force;
        valid = pmstep_console_stepdir_config(&trial.config, &trial.stepdir, &in_force); /* with the trip */
    }
    if (valid != PMSTEP_OK) {
        if (validation != NULL) {
            *validation = valid;
        }
        return PMSTEP_STORE_ERR_INVALID;
    }
    if (sequence != NULL) {
        *sequence = get32(in + OFF_SEQUENCE);
    }
    *rec = trial;
    return PMSTEP_STORE_OK;
}

pmstep_store_status_t pmstep_store_init(pmstep_store_t *s, const pmstep_store_flash_t *flash, uint32_t board_id)
{
    if (s == NULL || flash == NULL || flash->erase == NULL || flash->program == NULL || flash->read == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    s->flash = flash;
    s->board_id = board_id;
    s->slot = -1;
    s->sequence = 0u;
    s->flash_error = 0;
    if (flash->slot_bytes < PMSTEP_STORE_RECORD_MAX_BYTES) {
        return PMSTEP_STORE_ERR_SLOT_SIZE;
    }
    return PMSTEP_STORE_OK;
}

/* Reads slot @p slot's record into @p buf. @return its check (CRC and header), or ERR_FLASH. */
static pmstep_store_status_t read_slot(pmstep_store_t *s, uint32_t slot, uint8_t *buf, uint32_t *sequence)
{
    const int32_t err = s->flash->read(s->flash->ctx, slot, 0u, buf, PMSTEP_STORE_RECORD_MAX_BYTES);
    uint32_t length;
    if (err != 0) {
        s->flash_error = err;
        return PMSTEP_STORE_ERR_FLASH;
    }
    if (get32(buf + OFF_MAGIC) != PMSTEP_STORE_MAGIC) {
        return PMSTEP_STORE_EMPTY; /* erased, or torn before its header */
    }
    length = get32(buf + OFF_BYTES);
    if (length < PMSTEP_STORE_HEADER_BYTES + 4u || length > PMSTEP_STORE_RECORD_MAX_BYTES
        || pmstep_store_crc32(0u, buf, length - 4u) != get32(buf + length - 4u)) {
        return PMSTEP_STORE_ERR_CRC;
    }
    *sequence = get32(buf + OFF_SEQUENCE);
    return PMSTEP_STORE_OK;
}

pmstep_store_status_t pmstep_store_load(pmstep_store_t *s, const pmstep_config_t *board, pmstep_store_record_t *rec,
                                        pmstep_status_t *validation)
{
    uint8_t buf[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t seq[2] = {0u, 0u};
    bool ok[2];
    uint32_t slot;
    int32_t newest = -1;
    if (validation != NULL) {
        *validation = PMSTEP_OK;
    }
    if (s == NULL || s->flash == NULL || board == NULL || rec == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    s->slot = -1;
    s->sequence = 0u;
    for (slot = 0; slot < 2u; ++slot) {
        /* A slot that cannot be read (a torn double word) or fails its CRC holds no record: a save
         * was cut short there; the other slot's record is the one in force. */
        ok[slot] = read_slot(s, slot, buf, &seq[slot]) == PMSTEP_STORE_OK;
        if (ok[slot] && (newest < 0 || (int32_t)(seq[slot] - seq[newest]) > 0)) {
            newest = (int32_t)slot;
        }
    }
    if (newest < 0) {
        return PMSTEP_STORE_EMPTY;
    }
    s->slot = newest;
    s->sequence = seq[newest];
    if (newest == 0 && read_slot(s, 0u, buf, &seq[0]) != PMSTEP_STORE_OK) {
        return PMSTEP_STORE_ERR_FLASH; /* read a moment ago */
    }
    return pmstep_store_decode(buf, PMSTEP_STORE_RECORD_MAX_BYTES, s->board_id, board, rec, validation, NULL);
}

/* Whether slot @p slot holds the @p n bytes of @p image, read back in small pieces. */
static int32_t verify_slot(const pmstep_store_t *s, uint32_t slot, const uint8_t *image, uint32_t n, bool *same)
{
    uint8_t piece[32];
    uint32_t off;
    *same = true;
    for (off = 0; off < n; off += sizeof piece) {
        const uint32_t k = n - off < sizeof piece ? n - off : (uint32_t)sizeof piece;
        const int32_t err = s->flash->read(s->flash->ctx, slot, off, piece, k);
        if (err != 0) {
            return err;
        }
        if (memcmp(piece, &image[off], k) != 0) {
            *same = false;
        }
    }
    return 0;
}

pmstep_store_status_t pmstep_store_save(pmstep_store_t *s, const pmstep_store_record_t *rec, bool bridge_off)
{
    uint8_t image[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n;
    uint32_t target;
    uint32_t off;
    int32_t err;
    bool same = false;
    if (s == NULL || s->flash == NULL || rec == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    if (!bridge_off) {
        return PMSTEP_STORE_ERR_BRIDGE_ON;
    }
    (void)memset(image, 0xFF, sizeof image);
    n = pmstep_store_encode(rec, s->board_id, s->sequence + 1u, image);
    n = (n + PMSTEP_STORE_PROGRAM_UNIT - 1u) & ~(PMSTEP_STORE_PROGRAM_UNIT - 1u);
    target = s->slot == 0 ? 1u : 0u;
    err = s->flash->erase(s->flash->ctx, target);
    /* In address order, so the CRC's double word is programmed last: until it is, the slot's record
     * fails its CRC whatever the flash holds. */
    for (off = 0; err == 0 && off < n; off += PMSTEP_STORE_PROGRAM_UNIT) {
        err = s->flash->program(s->flash->ctx, target, off, &image[off], PMSTEP_STORE_PROGRAM_UNIT);
    }
    if (err == 0) {
        err = verify_slot(s, target, image, n, &same);
    }
    if (err != 0) {
        s->flash_error = err;
        return PMSTEP_STORE_ERR_FLASH;
    }
    if (!same) {
        return PMSTEP_STORE_ERR_VERIFY;
    }
    s->slot = (int32_t)target;
    s->sequence++;
    return PMSTEP_STORE_OK;
}

pmstep_store_status_t pmstep_store_erase(pmstep_store_t *s, bool bridge_off)
{
    /* The slot without the newest record first: a power cut between the two erases leaves the
     * newest record in force, never an older one. */
    const uint32_t order[2] = {s != NULL && s->slot == 0 ? 1u : 0u, s != NULL && s->slot == 0 ? 0u : 1u};
    uint32_t k;
    if (s == NULL || s->flash == NULL) {
        return PMSTEP_STORE_ERR_NULL;
    }
    if (!bridge_off) {
        return PMSTEP_STORE_ERR_BRIDGE_ON;
    }
    for (k = 0; k < 2u; ++k) {
        const int32_t err = s->flash->erase(s->flash->ctx, order[k]);
        if (err != 0) {
            s->flash_error = err;
            return PMSTEP_STORE_ERR_FLASH;
        }
    }
    s->slot = -1;
    s->sequence = 0u;
    return PMSTEP_STORE_OK;
}
