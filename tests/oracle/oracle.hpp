/**
 * @file oracle.hpp
 * @brief Continuous-time, double-precision test oracle of Tomei & Verrelli's strategy:
 *        plant (1), s-alignment (3), c-alignment (5), controller (6) — or (13) of
 *        Remark 1 when the load is known — written from the paper and the design
 *        notes only. It shares no source with firmware/ or sil/.
 *
 * The closed loop is one ODE (plant + controller states + the reference filters
 * H(s) = w0^3/(s + w0)^3 realised as three first-order lags), integrated by
 * Boost.Odeint's Dormand-Prince 5(4) with error control (default 1e-10 relative,
 * 1e-12 absolute) and exact stops at every discontinuity (t_s, t_c, load steps,
 * set-point ramp corners), so the right-hand side is smooth on each segment.
 *
 * Units: rad, rad/s, A, V, Nm, s, kg m^2, Ohm, H (in the names).
 */
#ifndef PMSTEP_ORACLE_HPP
#define PMSTEP_ORACLE_HPP

#include <Eigen/Dense>

#include <cstddef>
#include <vector>

namespace pmstep_oracle {

/** Motor of model (1). */
struct Motor {
    double resistance_Ohm;          ///< R
    double inductance_H;            ///< L
    double inertia_kgm2;           ///< J
    double friction_Nms_rad;   ///< F >= 0
    double torque_constant_Nm_A;///< k_M
    int pole_pairs;                 ///< p
    double detent_torque_Nm = 0.0;  ///< T_d >= 0: detent torque -T_d sin(4 p theta) (not in the paper)
};

/** Gains of controller (6). */
struct Gains {
    double speed_gain_per_s;        ///< k_omega
    double observer_gain_per_s;     ///< K_e
    double current_gain_per_s;      ///< K_i
    double gamma;                   ///< gamma of (6), (7)
    double lambda;                  ///< lambda of (6), (7)
    double r;                       ///< r of (6), (7)
    double sat_kappa_rad_s;         ///< kappa: sat_k(x) = x / sqrt(1 + (x/kappa)^2)
    double reference_bandwidth_rad_s; ///< w0 of H(s) (Section III.B)
};

/** A set-point command: from @p time_s (or from t_c if earlier) ramp to @p target_rad_s at @p rate_rad_s2
 *  (rate <= 0: step). The ramp starts from the set-point's value at that time. */
struct RampCommand {
    double time_s;
    double target_rad_s;
    double rate_rad_s2;
};

/** Load steps: T_L(t) = torque of the last step with time_s <= t, 0 before the first. */
struct LoadStep {
    double time_s;
    double torque_Nm;
};

/** Offsets of controller (6)'s initial estimates at t_c (zero in the paper): the estimates start at
 *  i-hat = i(t_c) - i~, w-hat = 0 + e_w, T_L-hat = 0 - T~_L - F e_w, so the estimation errors
 *  (i~_a, i~_b, e_w, T~_L) of Theorem 3 grow by these amounts. */
struct InitialErrors {
    double i_a_err_A = 0.0;   ///< i~_a(t_c) = i_a - i_a-hat
    double i_b_err_A = 0.0;   ///< i~_b(t_c)
    double speed_err_rad_s = 0.0; ///< e_w(t_c) = w-hat - w
    double load_err_Nm = 0.0; ///< T~_L(t_c) = T_L - T_L-hat - F e_w
};

struct Scenario {
    Motor motor;
    Gains gains;
    double s_align_time_s;   ///< t_s
    double c_align_time_s;   ///< t_c
    double s_align_voltage_V;///< u_cs of (3)
    double c_align_voltage_V;///< u_cc of (5)
    double theta0_rad;
    double omega0_rad_s;
    double i_a0_A;
    double i_b0_A;
    std::vector<RampCommand> speed_commands; ///< in time order
    std::vector<LoadStep> load_steps;        ///< in time order
    bool known_load;          ///< Remark 1: law (13) with T_L* = H(s) T_L
    InitialErrors initial_errors;
    double duration_s;
};

/** The paper's Section III.B, with the set-point ramps at their nominal times. */
Scenario paper_scenario();

struct Options {
    double rel_tol = 1e-10;
    double abs_tol = 1e-12;
    double initial_step_s = 1e-7;
};

enum class Phase { s_align, c_align, run };

/** Indices into the ODE state. */
namespace idx {
constexpr int theta = 0, omega = 1, i_a = 2, i_b = 3;               // plant (1)
constexpr int phi1 = 4, phi2 = 5;                                   // angle integrals of (6)
constexpr int i_a_hat = 6, i_b_hat = 7, omega_hat = 8, load_hat = 9; // observer of (6) / (13)
constexpr int ref1 = 10, ref2 = 11, ref3 = 12;                      // H(s) of w*: three lags, w* = ref3
constexpr int lref1 = 13, lref2 = 14, lref3 = 15;                   // H(s) of T_L (Remark 1), T_L* = lref3
constexpr int dissipation = 16; ///< integral of U_s' (s-align) or U_c' (c-align) from the phase start
constexpr int size = 17;
} // namespace idx

/** Signals derived from the state at one instant (all of the control law's internals). */
struct Signals {
    double omega_ref_rad_s = 0, omega_ref_rate_rad_s2 = 0, omega_ref_accel_rad_s3 = 0;
    double cos_hat = 0, sin_hat = 0;     ///< estimates of cos p theta, sin p theta
    double i_d_A = 0, i_q_A = 0, i_q_ref_A = 0;
    double u_a_V = 0, u_b_V = 0;
    double load_Nm = 0;                  ///< true T_L
    double law_load_Nm = 0;              ///< T_L-hat, or T_L* in Remark 1
};

struct Sample {
    double t_s;
    Phase phase;
    Eigen::VectorXd x;
    Signals sig;
};

struct Stats {
    std::size_t steps = 0;      ///< accepted steps reported by odeint
    std::size_t segments = 0;
};

/**
 * Integrates @p sc from 0 to duration and returns the state at each of @p sample_times_s
 * (sorted, within [0, duration]). At a switching time the sample belongs to the new phase.
 */
std::vector<Sample> simulate(const Scenario &sc, const std::vector<double> &sample_times_s,
                             const Options &opt = Options(), Stats *stats = nullptr);

/** U_s of Theorem 1's proof: (1/2)(J/L w^2 + i_a^2 + (i_b - u_cs/R)^2) - k_M u_cs/(p L R) (sin p theta - 2),
 *  plus the detent's potential T_d (1 - cos 4 p theta)/(4 p L) when T_d > 0 (so U_s' is unchanged). */
double lyapunov_s(const Motor &m, double u_cs_V, double theta_rad, double omega_rad_s, double i_a_A, double i_b_A);

/** U_c of Theorem 2's proof: (1/2)(J/L w^2 + (i_a - u_cc/R)^2 + i_b^2) - k_M u_cc/(p L R) (cos p theta - 2),
 *  plus the same detent potential. */
double lyapunov_c(const Motor &m, double u_cc_V, double theta_rad, double omega_rad_s, double i_a_A, double i_b_A);

/** Injection gains of (6): g_w = (2g^2 + rF l J^2)/(g^2 l + rF l^2 J^2), g_T = (2g^2 F + l J g + l J^2 r F^2)/(same). */
double speed_injection_gain(const Motor &m, const Gains &g);
double load_injection_gain(const Motor &m, const Gains &g);

} // namespace pmstep_oracle

#endif // PMSTEP_ORACLE_HPP
