/* The parts of a scenario a target image can use too (no file parsing): the
 * paper's scenario and the speed commands of a set-point profile. */
#include "sil/scenario.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

void sil_scenario_paper(sil_scenario_t *sc)
{
    static const double times[] = {0.0, 0.65, 0.85, 1.2, 1.5, 1.8, 2.0, 2.4};
    static const double speeds[] = {0.0, 0.0, 10.0, 10.0, -10.0, -10.0, 0.0, 0.0};
    int k;
    memset(sc, 0, sizeof *sc);
    snprintf(sc->name, sizeof sc->name, "paper");
    /* The paper gives no rating: its alignment current 24 V / 3 Ohm = 8 A is taken as rated,
     * holding torque sqrt(2) k_M I = 22.6 Nm. */
    sc->datasheet.rated_current_A = 8.0;
    sc->datasheet.holding_torque_Nm = 22.627417;
    sc->datasheet.detent_torque_Nm = 0.0;
    sc->motor = plant_paper_params();
    sc->controller = pmstep_paper_config();
    sc->load.kind = PLANT_LOAD_STEP;
    sc->load.torque_Nm = 2.0;
    sc->load.step_time_s = 0.63;
    sc->duration_s = 2.4;
    /* One exponential step a period: the default fidelity from the README's integrator table. */
    sc->substeps = 1;
    sc->integrator = PLANT_INTEGRATOR_EXPONENTIAL;
    sc->bus_voltage_V = 48.0;
    sc->theta0_rad = 30.0 * PI / 180.0;
    sc->decimation = 10;
    sc->transient_window_s = 0.2;
    sc->speed_points = (int)(sizeof times / sizeof times[0]);
    for (k = 0; k < sc->speed_points; ++k) {
        sc->speed_time_s[k] = times[k];
        sc->speed_value_rad_s[k] = speeds[k];
    }
    sc->id_target_A = 0.0;
    sc->loss_speed_error_rad_s = 2.0;
    sc->loss_angle_error_rad = 0.5;
    sc->loss_position_error_rad = 0.5 * PI; /* a full step of a two-phase motor */
    sc->max_csv_MB = 1000.0;
    /* Measurement chain, inverter and bus: all ideal. */
    sc->seed = 1u;
    sc->sensors = sil_sensors_ideal();
    sil_scenario_sense_ranges(sc);
    sc->inverter = sil_inverter_ideal_config();
    sc->bus = sil_bus_ideal_config();
    sc->drive = SIL_DRIVE_PMSTEP;
    sc->metrics_start_s = -1.0;
    /* No moves (a speed scenario); the limits a position scenario starts from. */
    sc->move_speed_rad_s = 5.0;
    sc->move_accel_rad_s2 = 50.0;
    sc->position.hold_current_A = -1.0f; /* the designer's */
    /* Moves planned by the drive; a STEP/DIR input at 16 microsteps (a printer board's usual), DIAG as a level. */
    sc->position_source = SIL_SOURCE_MOVE;
    sc->stepdir_microsteps = 16u;
    sc->stepdir_diag_mode = PMSTEP_DIAG_LEVEL;
    sc->homing_speed_rad_s = 0.0;
    sc->homing_stall_current_A = 0.0;
    sc->homing_back_off_rad = -1.0;
}

double sil_scenario_hold_end_s(const sil_scenario_t *sc)
{
    int k;
    if (sc->position_source == SIL_SOURCE_STEPDIR && sc->position_moves > 0) {
        return sc->move_time_s[0];
    }
    for (k = 0; k + 1 < sc->speed_points; ++k) {
        if (sc->speed_value_rad_s[k + 1] != sc->speed_value_rad_s[k]) {
            return sc->speed_time_s[k];
        }
    }
    return sc->duration_s;
}

int sil_scenario_speed_command(const sil_scenario_t *sc, double t_s, int *next_segment, float *target_rad_s,
                               float *ramp_rate_rad_s2)
{
    while (*next_segment + 1 < sc->speed_points && t_s >= sc->speed_time_s[*next_segment]) {
        const int k = *next_segment;
        const double dv = sc->speed_value_rad_s[k + 1] - sc->speed_value_rad_s[k];
        const double dt = sc->speed_time_s[k + 1] - sc->speed_time_s[k];
        ++*next_segment;
        if (dv != 0.0) {
            *target_rad_s = (float)sc->speed_value_rad_s[k + 1];
            *ramp_rate_rad_s2 = (float)(fabs(dv) / dt);
            return 1;
        }
    }
    return 0;
}
