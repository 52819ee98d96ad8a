/**
 * @file plant.h
 * @brief Model (1) of the PM step motor in double precision, integrated with the
 *        phase voltages held over each step (sil/inverter.h decides them within a
 *        control period) by one of two fourth-order methods: classical RK4, or
 *        exponential time-differencing RK4 that solves the R/L and F/J parts exactly.
 *        Its parameters may differ from the firmware's.
 *
 *   theta' = omega
 *   omega' = -(F/J) omega + (k_M/J)(-i_a sin p theta + i_b cos p theta) - T_L/J
 *            - (T_d/J) sin 4 p theta
 *   i_a'   = -(R/L) i_a + (k_M/L) omega sin p theta + u_a/L
 *   i_b'   = -(R/L) i_b - (k_M/L) omega cos p theta + u_b/L
 *
 * The detent term (T_d = 0 in the paper) is the cogging of a hybrid stepper: four periods
 * per electrical period, zero at the full steps p theta = k pi/2 (the alignment equilibria).
 */
#ifndef SIL_PLANT_H
#define SIL_PLANT_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Physical motor parameters (SI). */
typedef struct {
    double resistance_Ohm;       /**< R */
    double inductance_H;         /**< L */
    double inertia_kgm2;         /**< J */
    double friction_Nms_rad;     /**< F */
    double torque_constant_Nm_A; /**< k_M */
    int pole_pairs;              /**< p */
    double detent_torque_Nm;     /**< T_d >= 0: detent torque amplitude, -T_d sin 4 p theta (0 = none) */
    /* A hard stop (plant_stop_torque()): a one-sided spring and damper the rotor meets at stop_position_rad. */
    int stop_side;                /**< 0: none; +1: it blocks motion above stop_position_rad; -1: below */
    double stop_position_rad;     /**< where the rotor meets it (mechanical rad, the plant's theta) */
    double stop_stiffness_Nm_rad; /**< k_s > 0: its torque per rad pressed into it */
    double stop_damping_Nms_rad;  /**< c_s >= 0: its damping while in contact */
} plant_params_t;

/**
 * The hard stop's torque on the rotor at (@p theta_rad, @p omega_rad_s): with d = side (theta - stop)
 * the depth pressed in, -side max(0, k_s d + c_s side omega) for d > 0, else 0. It pushes the
 * rotor out and never pulls it in (the damper lets go as the spring does).
 */
double plant_stop_torque(const plant_params_t *params, double theta_rad, double omega_rad_s);

/** Load torque T_L(t, omega). */
typedef enum {
    PLANT_LOAD_NONE = 0,         /**< T_L = 0 */
    PLANT_LOAD_CONSTANT = 1,     /**< T_L = torque_Nm */
    PLANT_LOAD_STEP = 2,         /**< T_L = torque_Nm for t >= step_time_s, else 0 */
    PLANT_LOAD_PROPORTIONAL = 3, /**< T_L = coefficient * omega (viscous load) */
    PLANT_LOAD_TABLE = 4         /**< piecewise linear in t through the points, held outside */
} plant_load_kind_t;

#define PLANT_LOAD_TABLE_MAX 32

typedef struct {
    plant_load_kind_t kind;
    double torque_Nm;
    double step_time_s;
    double coefficient_Nms_rad;
    int table_points;
    double table_time_s[PLANT_LOAD_TABLE_MAX]; /**< strictly increasing */
    double table_torque_Nm[PLANT_LOAD_TABLE_MAX];
} plant_load_t;

typedef struct {
    double theta_rad;
    double omega_rad_s;
    double i_a_A;
    double i_b_A;
} plant_state_t;

/**
 * Integration method of one step of length h with (u_a, u_b) held.
 *
 * PLANT_INTEGRATOR_RK4: classical Runge-Kutta 4 on (1).
 *
 * PLANT_INTEGRATOR_EXPONENTIAL: (1) split as y' = lambda (y - y*) + N(t, y), per component
 * lambda = (0, -F/J, -R/L, -R/L) and y* = (., 0, u_a/R, u_b/R) constant over the step
 * (the steady currents of the held voltages), N = (omega, (k_M/J)(-i_a sin p theta +
 * i_b cos p theta) - T_L/J - (T_d/J) sin 4 p theta, (k_M/L) omega sin p theta,
 * -(k_M/L) omega cos p theta): the back EMF, the torque, the load and the detent. With w = y - y*, w(h) = e^{lambda h} w(0) + the
 * integral of e^{lambda (h - s)} N ds, taken by exponential time differencing RK4 (Cox and
 * Matthews 2002), z = lambda h, phi_k(z) = sum_j z^j / (j + k)!:
 *   a  = e^{z/2} w0 + (h/2) phi_1(z/2) N(t, y0)
 *   b  = e^{z/2} w0 + (h/2) phi_1(z/2) N(t + h/2, a)
 *   c  = e^{z/2} a  + (h/2) phi_1(z/2) (2 N(t + h/2, b) - N(t, y0))
 *   w1 = e^{z} w0 + h [(phi_1 - 3 phi_2 + 4 phi_3) N0 + 2 (phi_2 - 2 phi_3)(Na + Nb)
 *                      + (4 phi_3 - phi_2) Nc]
 * Fourth order like RK4 (to which it reduces when lambda = 0), and exact when N is zero:
 * the R/L rise of the currents under a held voltage and the F/J decay carry no truncation
 * error whatever the step; what remains is the error of the back-EMF and torque coupling,
 * which vary at the electrical speed p omega and the electromechanical frequency.
 */
typedef enum { PLANT_INTEGRATOR_RK4 = 0, PLANT_INTEGRATOR_EXPONENTIAL = 1 } plant_integrator_t;

/** Weights of one component in one step of the exponential integrator (plant.c). */
typedef struct {
    double decay_half, decay;     /**< e^{z/2}, e^{z} */
    double half;                  /**< (h/2) phi_1(z/2) */
    double w_start, w_mid, w_end; /**< h (phi_1 - 3 phi_2 + 4 phi_3), h (phi_2 - 2 phi_3), h (4 phi_3 - phi_2) */
} plant_etd_weights_t;

typedef struct {
    plant_params_t params;
    plant_load_t load;
    plant_state_t x;
    double time_s;
    plant_integrator_t integrator; /**< method of plant_substep() (0 = RK4) */
    /* The exponential integrator's weights for the last step length (recomputed when h,
     * R/L or F/J change). */
    double cache_h_s, cache_r_over_l, cache_f_over_j;
    plant_etd_weights_t cache_current; /**< lambda = -R/L */
    plant_etd_weights_t cache_speed;   /**< lambda = -F/J */
    plant_etd_weights_t cache_free;    /**< lambda = 0 (theta, an open phase) */
    /* Currents (A) that act in the torque only, at the start, middle and end of the next
     * exponential step: the smooth part of the PWM ripple that the switching inverter adds
     * to the currents outside the step (sil/inverter.c); zero otherwise. */
    double torque_extra_a_a[3], torque_extra_b_a[3];
    /* sin and cos of p theta at a base angle (plant_sin_cos()). */
    bool trig_valid;
    double trig_angle_rad, trig_sin, trig_cos;
    bool open_a;   /**< phase a open (bridge off, current extinguished): i_a' = 0, i_a held at exactly 0 */
    bool open_b;   /**< same for phase b */
    bool broken_a; /**< winding a open (a broken wire, faults.open_phase): held at 0 whatever the bridge does */
    bool broken_b; /**< same for winding b */
} plant_t;

/** The motor of the paper's Section III.B (no detent torque). */
plant_params_t plant_paper_params(void);

/** Load torque (Nm) at time @p t_s and speed @p omega_rad_s. */
double plant_load_torque(const plant_load_t *load, double t_s, double omega_rad_s);

/** Right-hand side of (1). */
void plant_derivative(const plant_params_t *params, const plant_load_t *load, double t_s, const plant_state_t *x,
                      double u_a_V, double u_b_V, plant_state_t *dx);

/**
 * sin(p theta) and cos(p theta) of the present state: one sincos for a base angle, and
 * for angles within 0.01 rad of it (the steps of a control period) a rotation of the
 * base's by the small difference, with its sine and cosine from their Taylor series
 * (exact to double rounding).
 */
void plant_sin_cos(plant_t *plant, double *sin_ptheta, double *cos_ptheta);

/** Advances by @p period_s with (u_a, u_b) held, in @p substeps steps of plant->integrator. */
void plant_advance(plant_t *plant, double u_a_V, double u_b_V, double period_s, int substeps);

/**
 * One step of @p h_s of plant->integrator from time @p t_s with (u_a, u_b) held (an open
 * phase ignores its voltage). Leaves plant->time_s alone. When @p charge_a_c and
 * @p charge_b_c are not NULL they receive the integrals of i_a and i_b over the step (C):
 * RK4 weights the stage currents as it weights the derivatives; the exponential method
 * uses Simpson's rule on the start, the mean of the two midpoint stages and the end.
 */
void plant_substep(plant_t *plant, double t_s, double h_s, double u_a_V, double u_b_V, double *charge_a_c,
                   double *charge_b_c);

#ifdef __cplusplus
}
#endif

#endif /* SIL_PLANT_H */
