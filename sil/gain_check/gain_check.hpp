/**
 * @file gain_check.hpp
 * @brief What the paper's theorems guarantee for one motor + gains configuration,
 *        and what the SIL shows beyond it.
 *
 * Theory (Tomei & Verrelli): condition (4) of Theorem 2; the bounds (7) of Theorem 3
 * (p_e, gamma minimised over T_p, r); the eigenvalues s1, s2 of P; q and the radius
 * rho of the domain of attraction B. Conditions (7) are sufficient only: "not met"
 * means the theorem promises nothing, not that the loop fails.
 *
 * Practice: the empirical domain of attraction of the real firmware in the SIL: the
 * estimation errors (i~_a, i~_b, e_w, T~_L) of Theorem 3 are set at t_c in many
 * directions with growing norm, and each run is judged converged or not.
 */
#ifndef PMSTEP_GAIN_CHECK_HPP
#define PMSTEP_GAIN_CHECK_HPP

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sil/scenario.h" // C header with extern "C" guards

struct cJSON;

namespace pmstep_gain {

/** What the theorems are about: the motor model and gains the controller uses (SI units). */
struct TheoremInputs {
    double resistance_Ohm;           ///< R
    double inductance_H;             ///< L
    double inertia_kgm2;            ///< J
    double friction_Nms_rad;    ///< F
    double torque_constant_Nm_A; ///< k_M
    int pole_pairs;                  ///< p
    double observer_gain_per_s;      ///< K_e
    double gamma;                    ///< gamma
    double lambda;                   ///< lambda
    double r;                        ///< r
    double s_align_voltage_V;        ///< u_cs
    double c_align_voltage_V;        ///< u_cc
};

/** The controller's side of a scenario (the [controller] section). */
TheoremInputs inputs_from_config(const pmstep_config_t &cfg);

struct TheoremReport {
    TheoremInputs in;
    // Theorem 2, condition (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) > 0.
    double condition4_attraction;    ///< k_M u_cc/(p L R)
    double condition4_excitation;    ///< (u_cs^2 + u_cc^2)/(2 R^2)
    double condition4_margin;        ///< their difference
    bool condition4_met;
    // Theorem 3, (7).
    double p_e_bound;                ///< p_e must be below this
    double t_p_s;                    ///< T_p minimising the gamma (and r) bound
    double gamma_bound;              ///< gamma must exceed this (infimum over T_p > 0 and admissible p_e)
    bool gamma_met;
    double r_bound;                  ///< r must be at least this (at t_p_s, p_e -> p_e_bound, configured gamma)
    bool r_enters_controller;        ///< false when F = 0: r is then an analysis parameter, free to choose
    bool r_met;                      ///< r_bound satisfied, or satisfiable by choice (F = 0)
    bool condition7_met;             ///< some (T_p, p_e) satisfies all of (7)
    double p_e_low;                  ///< smallest admissible p_e at t_p_s (NaN if (7) not met)
    // P of Theorem 3 and the radius of B.
    double s1, s2;                   ///< min and max eigenvalue of P
    double q;                        ///< q at p_e_low (NaN if (7) not met)
    double rho;                      ///< guaranteed radius of B (NaN if (7) not met)
    double rho_ceiling;              ///< the rho formula's supremum over p_e (p_e -> 0): no gains of this kind can be promised more
};

/** Evaluates (4), (7), P, q and rho. */
TheoremReport check_theorems(const TheoremInputs &in);

/** The lower bound of gamma in (7) at one (T_p, p_e): lambda^2 e^{4 T_p} L^4/(p_e k_M^4 T_p^2) + 8 p_e k_M^4/L^4. */
double gamma_bound_at(const TheoremInputs &in, double t_p_s, double p_e);

/** The lower bound of r in (7) at one (T_p, p_e): 2 gamma^2 L^4 / (J^3 k_M^4 T_p^2 e^{-4 T_p} p_e). */
double r_bound_at(const TheoremInputs &in, double t_p_s, double p_e);

/** rho of Theorem 3 at one p_e (needs p_e below the p_e bound, so that q > 0). */
double rho_at(const TheoremInputs &in, double p_e, double s1, double s2);

/** Plain-text report. @p plant_differs adds the caveat that the theorems assume the model is exact. */
std::string theorem_text(const TheoremReport &rep, bool plant_differs);

/** JSON object of the report (caller owns it). */
cJSON *theorem_json(const TheoremReport &rep, bool plant_differs);

// ---------------------------------------------------------------- empirical domain of attraction

struct DoaOptions {
    int random_directions = 40;      ///< besides the 8 signed axes of (i~_a, i~_b, e_w, T~_L)
    std::uint32_t seed = 1;          ///< for the random directions (std::mt19937)
    double radius_min = 1e-3;        ///< first radius tried on each ray
    double radius_max = 1e5;         ///< last radius tried
    double radius_factor = 2.0;      ///< grid ratio between radii
    int bisection_steps = 4;         ///< refinements between the last success and the first failure
    double final_window_s = 0.2;     ///< convergence is judged on [end - window, end]
    double speed_tol_rad_s = 0.05;   ///< max |w - w*| and |w-hat - w| on the window
    double load_tol_Nm = 0.05;       ///< |T_L-hat - T_L| at the end
};

/** One SIL run with estimation errors set at the start of (6). */
struct DoaRun {
    int direction;
    double radius;                   ///< requested norm of (i~_a, i~_b, e_w, T~_L)
    double measured_norm;            ///< the norm the firmware's estimates and the plant show at t_c + T_s
    bool converged;
    std::string reason;              ///< "converged", "fault: ...", "speed error ...", ...
    double final_speed_error_rad_s;  ///< max |w - w*| on the final window
    double final_load_error_Nm;
};

struct DoaDirection {
    std::array<double, 4> unit;      ///< (i~_a A, i~_b A, e_w rad/s, T~_L Nm) direction
    std::string label;               ///< "+i~_a", ..., or "random 7"
    double last_converged_radius;    ///< largest radius converged before the first failure (0 if none)
    double first_failed_radius;      ///< +inf if none failed up to radius_max
    std::string failure_reason;
};

struct DoaResult {
    DoaOptions options;
    std::vector<DoaDirection> directions;
    std::vector<DoaRun> runs;
    double radius_all_converged;     ///< min over directions of last_converged_radius
    bool baseline_converged;         ///< the scenario with no added error converges
    std::string baseline_reason;
    double wall_time_s;
};

/** Runs one scenario with the estimation errors (i~_a, i~_b, e_w, T~_L) of Theorem 3 set at the start
 *  of (6): controller (6) starts at t_c as in the paper; one period later, at t_c + T_s, its
 *  estimates are overwritten so that the errors against the plant are exactly @p error. */
DoaRun doa_single_run(const sil_scenario_t &sc, const std::array<double, 4> &error, const DoaOptions &opt);

/** The study: every direction, growing radii until the first failure, then bisection. */
DoaResult doa_study(const sil_scenario_t &sc, const DoaOptions &opt, bool progress);

std::string doa_text(const DoaResult &res, const TheoremReport &rep);
cJSON *doa_json(const DoaResult &res);

/** Writes one line per run: direction, label, radius, measured norm, converged, reason. */
bool doa_write_csv(const DoaResult &res, const std::string &path);

} // namespace pmstep_gain

#endif // PMSTEP_GAIN_CHECK_HPP
