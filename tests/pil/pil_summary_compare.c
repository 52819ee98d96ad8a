/*
 * pil-summary-compare: compares the closed-loop summary computed on the target
 * (pil-closed-loop --summary) with the host SIL's summary.json of the same scenario
 * and settings, metric by metric, against the tolerances below. Prints every metric
 * with both values and the difference, and whether the two runs were bit-identical.
 *
 * Tolerances. Both sides run the same C (core in float32, plant in IEEE double, no
 * fused multiply-add); the plant's sin/cos come from different libraries (glibc on the
 * host, newlib on the target), each within an ULP of the exact value, so the plant
 * states may differ by a few double ULPs. Such a difference reaches the core only if
 * it moves a sample across a float32 rounding boundary; the loop then carries a
 * perturbation of the order of float32 resolution of the signals (2^-24 relative: about
 * 6e-7 rad/s at 10 rad/s, 1.2e-7 Nm at 2 Nm, 6e-8 on c-hat and s-hat, 5e-7 A at 8 A).
 * Each tolerance is about 10x above that, and 100x or more below the SIL's own bounds
 * for the same metric (tests/closed_loop: 1 and 0.05 rad/s, 0.02 Nm, 1e-3).
 * Integers (periods, fault) and the final mode must be equal.
 *
 * usage: pil-summary-compare HOST_SUMMARY TARGET_SUMMARY
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *path; /* dot-separated */
    double tolerance; /* absolute; 0: equal */
    const char *unit;
} metric_t;

static const metric_t metrics[] = {
    /* Before RUN the voltages are constants: only the plant's libm can differ. */
    {"alignment.cos_ptheta_at_ts", 1e-9, ""},
    {"alignment.sin_ptheta_at_ts", 1e-9, ""},
    {"alignment.i_b_minus_ucs_over_r_at_ts_A", 1e-9, "A"},
    {"alignment.cos_ptheta_at_tc", 1e-9, ""},
    {"alignment.sin_ptheta_at_tc", 1e-9, ""},
    {"alignment.i_a_minus_ucc_over_r_at_tc_A", 1e-9, "A"},
    {"speed.transient_max_abs_error_rad_s", 1e-5, "rad/s"},
    {"speed.transient_rms_error_rad_s", 1e-5, "rad/s"},
    {"speed.tracking_max_abs_error_rad_s", 1e-5, "rad/s"},
    {"speed.tracking_rms_error_rad_s", 1e-5, "rad/s"},
    {"final_load_hat_Nm", 2e-6, "Nm"},
    {"final_load_Nm", 0.0, "Nm"},
    {"final_load_abs_error_Nm", 2e-6, "Nm"},
    {"angle_estimate.max_abs_cos_error", 1e-6, ""},
    {"angle_estimate.max_abs_sin_error", 1e-6, ""},
    {"max_abs_phase_voltage_V", 1e-4, "V"},
    {"max_abs_phase_current_a", 1e-5, "A"},
    {"voltage_limited_periods", 0.0, ""},
    {"inverter_clipped_periods", 0.0, ""},
    {"fault.code", 0.0, ""},
    {"fault.step", 0.0, ""},
    {"timing.steps", 0.0, ""},
};

static cJSON *load(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *text;
    long n;
    cJSON *json;
    if (f == NULL) {
        fprintf(stderr, "pil-summary-compare: cannot open '%s'\n", path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = calloc((size_t)n + 1u, 1u);
    if (text == NULL || fread(text, 1u, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(text);
        return NULL;
    }
    fclose(f);
    json = cJSON_Parse(text);
    free(text);
    if (json == NULL) {
        fprintf(stderr, "pil-summary-compare: '%s' is not JSON\n", path);
    }
    return json;
}

static const cJSON *find(const cJSON *root, const char *path)
{
    char key[64];
    const cJSON *node = root;
    const char *p = path;
    while (node != NULL && *p != '\0') {
        size_t n = 0;
        while (p[n] != '\0' && p[n] != '.' && n + 1u < sizeof key) {
            key[n] = p[n];
            ++n;
        }
        key[n] = '\0';
        node = cJSON_GetObjectItemCaseSensitive(node, key);
        p += n;
        if (*p == '.') {
            ++p;
        }
    }
    return node;
}

int main(int argc, char **argv)
{
    cJSON *host;
    cJSON *target;
    int failures = 0;
    int identical = 1;
    size_t k;
    if (argc != 3) {
        fprintf(stderr, "usage: pil-summary-compare HOST_SUMMARY TARGET_SUMMARY\n");
        return 2;
    }
    host = load(argv[1]);
    target = load(argv[2]);
    if (host == NULL || target == NULL) {
        return 2;
    }
    printf("%-42s %24s %24s %10s %9s\n", "metric", "host SIL", "target (Cortex-M4)", "|diff|", "tolerance");
    for (k = 0; k < sizeof metrics / sizeof metrics[0]; ++k) {
        const cJSON *h = find(host, metrics[k].path);
        const cJSON *t = find(target, metrics[k].path);
        double diff;
        int ok;
        if (!cJSON_IsNumber(h) || !cJSON_IsNumber(t)) {
            printf("%-42s missing in %s\n", metrics[k].path, cJSON_IsNumber(h) ? "target" : "host");
            failures++;
            continue;
        }
        diff = fabs(h->valuedouble - t->valuedouble);
        ok = diff <= metrics[k].tolerance;
        identical = identical && h->valuedouble == t->valuedouble;
        printf("%-42s %24.17g %24.17g %10.3g %9.0e %s%s\n", metrics[k].path, h->valuedouble, t->valuedouble, diff,
               metrics[k].tolerance, metrics[k].unit, ok ? "" : "  <-- FAILS");
        failures += !ok;
    }
    {
        const cJSON *h = find(host, "final_mode");
        const cJSON *t = find(target, "final_mode");
        const int ok = cJSON_IsString(h) && cJSON_IsString(t) && strcmp(h->valuestring, t->valuestring) == 0;
        printf("%-42s %24s %24s%s\n", "final_mode", cJSON_IsString(h) ? h->valuestring : "?",
               cJSON_IsString(t) ? t->valuestring : "?", ok ? "" : "  <-- FAILS");
        failures += !ok;
    }
    cJSON_Delete(host);
    cJSON_Delete(target);
    printf("pil-summary-compare: %s; %s\n", failures == 0 ? "every metric within its tolerance" : "MISMATCH",
           identical ? "all numbers bit-identical" : "not all numbers bit-identical (see |diff|)");
    return failures == 0 ? 0 : 1;
}
