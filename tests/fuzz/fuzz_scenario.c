/* libFuzzer harness of the SIL's scenario input, the path of `pmstep-sil --scenario FILE --set
 * key=value...`: sil_scenario_load() on a file holding the fuzzed text, every --set through
 * sil_scenario_set_assignment(), then sil_scenario_check(). Checked, besides no crash and no
 * undefined behaviour (sanitizers) and bounded time (the fuzzer's -timeout):
 *   - a refusal comes with a message (non-empty, terminated within SIL_ERROR_MAX);
 *   - an accepted scenario names its output folder out/<name> with a plain file name (so the
 *     runner writes only inside the output folder), and its set-point profile is well formed.
 *
 * Input layout: the scenario file's bytes; if the line "--set" occurs, the file ends before it
 * and each line after it is one --set argument. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "sil/scenario.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[64];

static void remove_scratch(void) { remove(path); }

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_scenario: %s: %s\n", what, detail);
    abort();
}

static void check_message(const char *err)
{
    if (memchr(err, '\0', SIL_ERROR_MAX) == NULL || err[0] == '\0') {
        fail("a refusal without a message", "");
    }
}

static void check_accepted(const sil_scenario_t *sc)
{
    const char *name = sc->name;
    size_t n;
    int k;
    if (memchr(name, '\0', sizeof sc->name) == NULL || name[0] == '\0' || name[0] == '.') {
        fail("output folder name empty, unterminated or hidden", name);
    }
    for (n = 0; name[n] != '\0'; ++n) {
        const char c = name[n];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_'
              || c == '-')) {
            fail("output folder name is not a plain file name", name);
        }
    }
    if (sc->speed_points < 1 || sc->speed_points > SIL_SPEED_POINTS_MAX) {
        fail("speed profile point count out of range", name);
    }
    for (k = 0; k < sc->speed_points; ++k) {
        if (!(sc->speed_time_s[k] >= 0.0) || (k > 0 && !(sc->speed_time_s[k] > sc->speed_time_s[k - 1]))) {
            fail("speed profile times not increasing", name);
        }
    }
}

/* --print-scenario writes every key in INI form, "a template users can edit": read back on top
 * of the paper scenario, it must load, pass the check, and print the same text again. */
static void round_trip(const sil_scenario_t *sc)
{
    static sil_scenario_t again;
    static char printed[2][1 << 16];
    char err[SIL_ERROR_MAX];
    int pass;
    for (pass = 0; pass < 2; ++pass) {
        FILE *file = fopen(path, "wb");
        size_t length;
        if (file == NULL) {
            fail("cannot write the scratch file", path);
        }
        sil_scenario_print(pass == 0 ? sc : &again, file);
        if (fclose(file) != 0) {
            fail("cannot write the scratch file", path);
        }
        file = fopen(path, "rb");
        length = fread(printed[pass], 1u, sizeof printed[pass] - 1u, file);
        fclose(file);
        printed[pass][length] = '\0';
        sil_scenario_paper(&again);
        if (sil_scenario_load(&again, path, err, sizeof err) != 0) {
            fail("the printed scenario does not load", err);
        }
        if (sil_scenario_check(&again, err, sizeof err) != 0) {
            fail("the printed scenario does not pass the check", err);
        }
    }
    if (strcmp(printed[0], printed[1]) != 0) {
        fail("the printed scenario does not print the same after a reload", printed[0]);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static sil_scenario_t sc;
    static const char marker[] = "\n--set\n";
    char err[SIL_ERROR_MAX];
    const uint8_t *sets = NULL;
    size_t file_size = size;
    FILE *file;
    size_t n;

    if (path[0] == '\0') {
        const char *dir = getenv("TMPDIR");
        int fd;
        snprintf(path, sizeof path, "%.40s/fuzz_scenario_XXXXXX", dir != NULL && dir[0] != '\0' ? dir : "/tmp");
        fd = mkstemp(path);
        if (fd < 0) {
            fail("cannot make a scratch file", path);
        }
        close(fd);
        atexit(remove_scratch);
    }
    for (n = 0; n + sizeof marker - 1u <= size; ++n) {
        if (memcmp(data + n, marker, sizeof marker - 1u) == 0) {
            file_size = n + 1u; /* keep the newline that ends the last line */
            sets = data + n + sizeof marker - 1u;
            break;
        }
    }
    file = fopen(path, "wb");
    if (file == NULL || fwrite(data, 1u, file_size, file) != file_size || fclose(file) != 0) {
        fail("cannot write the scratch file", path);
    }

    sil_scenario_paper(&sc);
    memset(err, 0x55, sizeof err);
    if (sil_scenario_load(&sc, path, err, sizeof err) != 0) {
        check_message(err);
        return 0;
    }
    if (sets != NULL) {
        const uint8_t *end = data + size;
        while (sets < end) {
            const uint8_t *newline = memchr(sets, '\n', (size_t)(end - sets));
            const size_t length = (size_t)((newline != NULL ? newline : end) - sets);
            char *assignment = malloc(length + 1u);
            int rc;
            if (assignment == NULL) {
                fail("out of memory", "");
            }
            memcpy(assignment, sets, length);
            assignment[length] = '\0'; /* an argv string ends at its first NUL, as here */
            memset(err, 0x55, sizeof err);
            rc = sil_scenario_set_assignment(&sc, assignment, err, sizeof err);
            free(assignment);
            if (rc != 0) {
                check_message(err);
                return 0;
            }
            sets += length + (newline != NULL ? 1u : 0u);
        }
    }
    memset(err, 0x55, sizeof err);
    if (sil_scenario_check(&sc, err, sizeof err) != 0) {
        check_message(err);
        return 0;
    }
    check_accepted(&sc);
    round_trip(&sc);
    return 0;
}
