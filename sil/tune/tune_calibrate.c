/* pmstep-tune --self-commission: the drive's own calibration (pmstep_calibrate.h) run in the SIL on
 * the preset's plant and measurement chain, told nothing but the rated current and the pole pairs;
 * its design set beside the datasheet's. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pmstep/pmstep_text.h"
#include "pmstep_hal_host.h"
#include "pmstep_tune.h"

#define CALIBRATION_LIMIT_S 120.0 /* simulated time a calibration may take */

static const char *stage_name(pmstep_calibrate_stage_t s)
{
    switch (s) {
    case PMSTEP_CALIBRATE_MEASURING: return "measuring";
    case PMSTEP_CALIBRATE_IDENTIFYING: return "identifying";
    case PMSTEP_CALIBRATE_DONE: return "done";
    case PMSTEP_CALIBRATE_FAILED: return "failed";
    default: return "idle";
    }
}

const char *calibrate_status_text(int32_t status)
{
    switch (status) {
    case PMSTEP_CALIBRATE_OK: return "ok";
    case PMSTEP_CALIBRATE_ERR_REQUEST: return "rated current, pole pairs or bus not usable";
    case PMSTEP_CALIBRATE_ERR_NO_MOTOR: return "no current at any level: a phase open or no motor";
    case PMSTEP_CALIBRATE_ERR_FAULT: return "a run latched a fault";
    case PMSTEP_CALIBRATE_ERR_NOT_CONVERGED: return "R did not settle";
    case PMSTEP_CALIBRATE_ERR_IDENTIFICATION: return "J and F not identified";
    case PMSTEP_CALIBRATE_ERR_TIMEOUT: return "a run did not end in time";
    case PMSTEP_CALIBRATE_ERR_CANCELLED: return "cancelled";
    default: return pmstep_status_str((pmstep_status_t)status);
    }
}

int calibrate_on_drive(const sil_scenario_t *sc, bool robust, double detent_per_holding, pmstep_calibrate_t *cal,
                       pmstep_config_t *cfg, double *simulated_s)
{
    static pmstep_t inst; /* as on the MCU: one static instance */
    sil_inverter_t *inverter = pmstep_hal_host_inverter();
    const double period_s = (double)sc->controller.timing.period_s;
    const long limit = sil_periods_in(CALIBRATION_LIMIT_S, period_s);
    pmstep_calibrate_request_t req;
    pmstep_output_t out;
    pmstep_meas_t meas;
    plant_t plant;
    uint32_t runs_seen = 0u;
    uint32_t run_start = 0u;
    bool was_running = false;
    long k;

    if (sil_bind_plant(sc, &plant) != 0) {
        fprintf(stderr, "pmstep-tune: cannot set up the measurement chain\n");
        return 2;
    }
    plant.load.kind = PLANT_LOAD_NONE; /* a motor free on its shaft, as it is calibrated */
    req.rated_current_A = (float)sc->datasheet.rated_current_A;
    req.pole_pairs = sc->motor.pole_pairs;
    req.robust = robust;
    req.detent_per_holding = (float)detent_per_holding;
    pmstep_hal_read_measurements(&meas); /* the bus as the drive measures it before anything runs */
    if (pmstep_calibrate_start(cal, &req, &sc->controller, meas.bus_voltage_V) != PMSTEP_OK) {
        pmstep_hal_host_release();
        fprintf(stderr, "pmstep-tune: cannot self-commission: %s\n", calibrate_status_text(cal->status));
        return 2;
    }
    printf("pmstep-tune: self-commissioning on the drive from I = %g A, p = %d, bus %.2f V measured\n",
           (double)req.rated_current_A, (int)req.pole_pairs, (double)meas.bus_voltage_V);
    for (k = 0; k < limit && pmstep_calibrate_active(cal); ++k) {
        plant.time_s = (double)k * period_s;
        (void)pmstep_calibrate_boundary(cal, &inst, cfg, (uint32_t)k);
        if (cal->running != was_running && was_running) { /* a run just ended: what it gave */
            printf("    ended %.3f s into the run: %s; R %.4g Ohm, L %.4g H, k_M %.4g N m/A; identification %s, "
                   "J %.4g kg m^2, F %.3g N m s/rad\n",
                   (double)(k - (long)run_start) * period_s,
                   cal->fault != PMSTEP_FAULT_NONE ? pmstep_fault_str(cal->fault) : "no fault",
                   (double)cal->resistance_Ohm, (double)cal->inductance_H, (double)cal->torque_constant_Nm_A,
                   pmstep_identification_str(cal->identification), (double)cal->inertia_kgm2,
                   (double)cal->friction_Nms_rad);
        }
        if (cal->running && !was_running) {
            run_start = cal->run_start;
        }
        was_running = cal->running;
        if (cal->runs != runs_seen) {
            runs_seen = cal->runs;
            printf("  run %u at %.2f s: %s, designed for R %.4g Ohm, J %.4g kg m^2\n", (unsigned)cal->runs,
                   (double)k * period_s, stage_name(cal->stage), (double)cal->design_resistance_Ohm,
                   (double)cal->report.inertia_kgm2);
            fflush(stdout);
        }
        if (!pmstep_calibrate_active(cal)) {
            break;
        }
        pmstep_hal_read_measurements(&meas);
        pmstep_step(&inst, &meas, &out);
        pmstep_hal_apply_output(&out);
        sil_drive_advance(&plant, inverter, period_s, sc->substeps);
    }
    pmstep_hal_host_release();
    if (cal->fault != PMSTEP_FAULT_NONE && cal->stage == PMSTEP_CALIBRATE_FAILED) {
        printf("    ended %.3f s into the run: %s\n", (double)(k - (long)run_start) * period_s,
               pmstep_fault_str(cal->fault));
    }
    *simulated_s = (double)k * period_s;
    if (pmstep_calibrate_active(cal)) {
        pmstep_calibrate_cancel(cal, &inst);
        printf("pmstep-tune: self-commissioning did not end within %.0f s simulated\n", CALIBRATION_LIMIT_S);
        return 1;
    }
    if (cal->stage != PMSTEP_CALIBRATE_DONE) {
        printf("pmstep-tune: self-commissioning failed after %u runs, %.2f s: %s (%d)%s%s\n", (unsigned)cal->runs,
               *simulated_s, calibrate_status_text(cal->status), (int)cal->status,
               cal->fault != PMSTEP_FAULT_NONE ? "; fault " : "",
               cal->fault != PMSTEP_FAULT_NONE ? pmstep_fault_str(cal->fault) : "");
        return 1;
    }
    printf("pmstep-tune: self-commissioning done in %u runs, %.2f s simulated\n", (unsigned)cal->runs, *simulated_s);
    return 0;
}

static void row(const char *name, const char *unit, double datasheet, double drive, double plant)
{
    printf("  %-28s %-9s %12.5g %12.5g %+8.1f %%", name, unit, datasheet, drive,
           datasheet != 0.0 ? 100.0 * (drive / datasheet - 1.0) : 0.0);
    if (plant > 0.0) {
        printf("   plant %.5g (%+.1f %%)", plant, 100.0 * (drive / plant - 1.0));
    }
    printf("\n");
}

void print_calibration(const sil_scenario_t *sc, const pmstep_config_t *datasheet,
                       const pmstep_design_report_t *datasheet_report, const pmstep_config_t *drive,
                       const pmstep_design_report_t *drive_report)
{
    printf("  %-28s %-9s %12s %12s %10s\n", "", "", "datasheet", "drive", "drive/ds");
    row("R", "Ohm", (double)datasheet->motor.resistance_Ohm, (double)drive->motor.resistance_Ohm,
        sc->motor.resistance_Ohm);
    row("L", "H", (double)datasheet->motor.inductance_H, (double)drive->motor.inductance_H, sc->motor.inductance_H);
    row("k_M", "N m/A", (double)datasheet->motor.torque_constant_Nm_A, (double)drive->motor.torque_constant_Nm_A,
        sc->motor.torque_constant_Nm_A);
    row("J", "kg m^2", (double)datasheet->motor.inertia_kgm2, (double)drive->motor.inertia_kgm2,
        sc->motor.inertia_kgm2);
    row("F", "N m s/rad", (double)datasheet->motor.friction_Nms_rad, (double)drive->motor.friction_Nms_rad,
        sc->motor.friction_Nms_rad);
    row("top speed", "rad/s", (double)datasheet_report->top_speed_rad_s, (double)drive_report->top_speed_rad_s, 0.0);
    row("current bandwidth", "rad/s", (double)datasheet_report->current_bandwidth_rad_s,
        (double)drive_report->current_bandwidth_rad_s, 0.0);
    row("observer bandwidth", "rad/s", (double)datasheet_report->observer_bandwidth_rad_s,
        (double)drive_report->observer_bandwidth_rad_s, 0.0);
    row("speed gain k_w", "1/s", (double)datasheet->gains.speed_gain_per_s, (double)drive->gains.speed_gain_per_s, 0.0);
    row("alignment voltage u_cs", "V", (double)datasheet->alignment.s_align_voltage_V,
        (double)drive->alignment.s_align_voltage_V, 0.0);
    row("t_c", "s", (double)datasheet->alignment.c_align_time_s, (double)drive->alignment.c_align_time_s, 0.0);
    row("overcurrent trip", "A", (double)datasheet->limits.max_phase_current_A,
        (double)drive->limits.max_phase_current_A, 0.0);
}
