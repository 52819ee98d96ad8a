/**
 * @file faults.h
 * @brief Faults the SIL injects into its "hardware" ([faults] of a scenario), for the tests that
 *        show the firmware catches each with the bridge off:
 *
 *   open phase:   from open_phase_time_s on, the chosen winding is open (a broken wire or
 *                 connector): its current is forced to 0 at that instant and stays 0 whatever
 *                 the bridge applies (the plant's open-phase model);
 *   sensor fault: from sensor_time_s on, the chosen phase's current reading is
 *                 open:  what the measurement chain makes of 0 A (its offset, noise and
 *                        quantisation: an amplifier whose input is cut), or
 *                 stuck: the reading of the last sample before the failure, held (a frozen ADC).
 *
 * Time 0 means from the start. Host only (the port of sil/port applies them).
 */
#ifndef SIL_FAULTS_H
#define SIL_FAULTS_H

#ifdef __cplusplus
extern "C" {
#endif

/** Which phases a fault takes. */
typedef enum { SIL_PHASES_NONE = 0, SIL_PHASES_A = 1, SIL_PHASES_B = 2, SIL_PHASES_BOTH = 3 } sil_phases_t;

/** What a failed current sensor reads. */
typedef enum { SIL_SENSOR_OK = 0, SIL_SENSOR_OPEN = 1, SIL_SENSOR_STUCK = 2 } sil_sensor_fault_t;

/** [faults] of a scenario. */
typedef struct {
    sil_phases_t open_phase;   /**< faults.open_phase: none | a | b | both */
    double open_phase_time_s;  /**< faults.open_phase_time_s */
    sil_sensor_fault_t sensor; /**< faults.sensor: none | open | stuck */
    sil_phases_t sensor_phase; /**< faults.sensor_phase: a | b | both */
    double sensor_time_s;      /**< faults.sensor_time_s */
} sil_fault_config_t;

/** Whether @p set takes phase a (@p phase 0) or b (1). */
static inline int sil_phases_take(sil_phases_t set, int phase)
{
    return ((unsigned)set & (phase == 0 ? 1u : 2u)) != 0u;
}

#ifdef __cplusplus
}
#endif

#endif /* SIL_FAULTS_H */
