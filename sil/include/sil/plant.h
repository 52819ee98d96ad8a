/**
 * @file plant.h
 * @brief Model (1) of the PM step motor in double precision, integrated by RK4
 *        with the phase voltages held over each step (sil/inverter.h decides
 *        them within a control period). Its parameters may differ from the firmware's.
 *
 *   theta' = omega
 *   omega' = -(F/J) omega + (k_M/J)(-i_a sin p theta + i_b cos p theta) - T_L/J
 *   i_a'   = -(R/L) i_a + (k_M/L) omega sin p theta + u_a/L
 *   i_b'   = -(R/L) i_b - (k_M/L) omega cos p theta + u_b/L
 */
#ifndef SIL_PLANT_H
#define SIL_PLANT_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Physical motor parameters (SI). */
typedef struct {
    double resistance_Ohm;          /**< R */
    double inductance_H;            /**< L */
    double inertia_kgm2;           /**< J */
    double friction_Nms_rad;   /**< F */
    double torque_constant_Nm_A;/**< k_M */
    int pole_pairs;                 /**< p */
} plant_params_t;

/** Load torque T_L(t, omega). */
typedef enum {
    PLANT_LOAD_NONE = 0,        /**< T_L = 0 */
    PLANT_LOAD_CONSTANT = 1,    /**< T_L = torque_Nm */
    PLANT_LOAD_STEP = 2,        /**< T_L = torque_Nm for t >= step_time_s, else 0 */
    PLANT_LOAD_PROPORTIONAL = 3,/**< T_L = coefficient * omega (viscous load) */
    PLANT_LOAD_TABLE = 4        /**< piecewise linear in t through the points, held outside */
} plant_load_kind_t;

#define PLANT_LOAD_TABLE_MAX 32

typedef struct {
    plant_load_kind_t kind;
    double torque_Nm;
    double step_time_s;
    double coefficient_Nms_rad;
    int table_points;
    double table_time_s[PLANT_LOAD_TABLE_MAX];   /**< strictly increasing */
    double table_torque_Nm[PLANT_LOAD_TABLE_MAX];
} plant_load_t;

typedef struct {
    double theta_rad;
    double omega_rad_s;
    double i_a_A;
    double i_b_A;
} plant_state_t;

typedef struct {
    plant_params_t params;
    plant_load_t load;
    plant_state_t x;
    double time_s;
    bool open_a;   /**< phase a open (bridge off, current extinguished): i_a' = 0, i_a held at exactly 0 */
    bool open_b;   /**< same for phase b */
} plant_t;

/** The motor of the paper's Section III.B. */
plant_params_t plant_paper_params(void);

/** Load torque (Nm) at time @p t_s and speed @p omega_rad_s. */
double plant_load_torque(const plant_load_t *load, double t_s, double omega_rad_s);

/** Right-hand side of (1). */
void plant_derivative(const plant_params_t *params, const plant_load_t *load, double t_s,
                      const plant_state_t *x, double u_a_V, double u_b_V, plant_state_t *dx);

/** Advances by @p period_s with (u_a, u_b) held, in @p substeps RK4 steps. */
void plant_advance(plant_t *plant, double u_a_V, double u_b_V, double period_s, int substeps);

/**
 * One RK4 step of @p h_s from time @p t_s with (u_a, u_b) held (an open phase ignores its
 * voltage). Leaves plant->time_s alone. When @p charge_a_c and @p charge_b_c are not NULL
 * they receive the integrals of i_a and i_b over the step (C), by the same RK4 quadrature.
 */
void plant_substep(plant_t *plant, double t_s, double h_s, double u_a_V, double u_b_V, double *charge_a_c,
                   double *charge_b_c);

#ifdef __cplusplus
}
#endif

#endif /* SIL_PLANT_H */
