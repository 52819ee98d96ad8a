// Theorem and gain checker: conditions (4) and (7), P, q, rho of Theorem 3; and the
// empirical domain of attraction of the firmware in the SIL. See gain_check.hpp.
#include "gain_check.hpp"

#include <Eigen/Dense>
#include <cjson/cJSON.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>

#include "pmstep_hal_host.h"
#include "sil/runner.h"
#include "pmstep/pmstep_text.h"

namespace pmstep_gain {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/** Bracket of the bound on p_e in (7): 12(4 k_M^6/(l^2 L^6) + k_M^2 (R + L K_e)^2/L^4 + k_M^2/L^2) + k_M^2/L^2. */
double p_e_denominator(const TheoremInputs &in)
{
    const double kl = in.torque_constant_Nm_A / in.inductance_H; // k_M/L
    const double rl = (in.resistance_Ohm + in.inductance_H * in.observer_gain_per_s) / in.inductance_H;
    const double kl2 = kl * kl;
    return 12.0 * (4.0 * kl2 * kl2 * kl2 / (in.lambda * in.lambda) + kl2 * rl * rl + kl2) + kl2;
}

/** R/L + K_e. */
double observer_rate(const TheoremInputs &in)
{
    return in.resistance_Ohm / in.inductance_H + in.observer_gain_per_s;
}

/** e^{4 T}/T^2: the T_p dependence shared by the gamma and r bounds of (7) (minimum at T = 1/2). */
double t_p_factor(double t_p_s)
{
    return std::exp(4.0 * t_p_s) / (t_p_s * t_p_s);
}

/** Infimum over admissible p_e in (0, p_e bound) of gamma_bound_at(T_p, p_e) = A/p_e + B p_e. */
double gamma_bound_inf_over_p_e(const TheoremInputs &in, double t_p_s, double p_e_bound)
{
    const double L = in.inductance_H, kM = in.torque_constant_Nm_A;
    const double coef_a = in.lambda * in.lambda * std::pow(L / kM, 4) * t_p_factor(t_p_s);
    const double coef_b = 8.0 * std::pow(kM / L, 4);
    const double p_star = std::sqrt(coef_a / coef_b); // minimiser of A/p + B p
    const double p = std::min(p_star, p_e_bound);
    return coef_a / p + coef_b * p;
}

/** Golden-section search of a unimodal function on [lo, hi] (in log T_p). */
template <class Fn> double golden_min(Fn f, double lo, double hi)
{
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = std::log(lo), b = std::log(hi);
    double c = b - g * (b - a), d = a + g * (b - a);
    for (int n = 0; n < 200 && b - a > 1e-12; ++n) {
        if (f(std::exp(c)) < f(std::exp(d))) {
            b = d;
        } else {
            a = c;
        }
        c = b - g * (b - a);
        d = a + g * (b - a);
    }
    return std::exp(0.5 * (a + b));
}

std::string fmt(const char *format, double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

} // namespace

TheoremInputs inputs_from_config(const pmstep_config_t &cfg)
{
    TheoremInputs in;
    in.resistance_Ohm = static_cast<double>(cfg.motor.resistance_Ohm);
    in.inductance_H = static_cast<double>(cfg.motor.inductance_H);
    in.inertia_kgm2 = static_cast<double>(cfg.motor.inertia_kgm2);
    in.friction_Nms_rad = static_cast<double>(cfg.motor.friction_Nms_rad);
    in.torque_constant_Nm_A = static_cast<double>(cfg.motor.torque_constant_Nm_A);
    in.pole_pairs = static_cast<int>(cfg.motor.pole_pairs);
    in.observer_gain_per_s = static_cast<double>(cfg.gains.observer_gain_per_s);
    in.gamma = static_cast<double>(cfg.gains.adapt_gamma);
    in.lambda = static_cast<double>(cfg.gains.adapt_lambda);
    in.r = static_cast<double>(cfg.gains.adapt_r);
    in.s_align_voltage_V = static_cast<double>(cfg.alignment.s_align_voltage_V);
    in.c_align_voltage_V = static_cast<double>(cfg.alignment.c_align_voltage_V);
    return in;
}

double gamma_bound_at(const TheoremInputs &in, double t_p_s, double p_e)
{
    const double L = in.inductance_H, kM = in.torque_constant_Nm_A;
    return in.lambda * in.lambda * std::exp(4.0 * t_p_s) * std::pow(L, 4) / (p_e * std::pow(kM, 4) * t_p_s * t_p_s)
           + 8.0 * p_e * std::pow(kM / L, 4);
}

double r_bound_at(const TheoremInputs &in, double t_p_s, double p_e)
{
    const double L = in.inductance_H, kM = in.torque_constant_Nm_A, J = in.inertia_kgm2;
    return 2.0 * in.gamma * in.gamma * std::pow(L, 4)
           / (J * J * J * std::pow(kM, 4) * t_p_s * t_p_s * std::exp(-4.0 * t_p_s) * p_e);
}

double rho_at(const TheoremInputs &in, double p_e, double s1, double s2)
{
    const double L = in.inductance_H, kM = in.torque_constant_Nm_A, p = in.pole_pairs;
    const double kl = kM / L;
    const double q = observer_rate(in) - p_e * p_e_denominator(in);
    return L / (2.0 * kM * p)
           * std::sqrt(std::min(s1, p_e) * q / (p_e * (s2 + 2.0 * p_e * kl * kl * std::max(1.0, kl * kl))));
}

TheoremReport check_theorems(const TheoremInputs &in)
{
    TheoremReport rep;
    rep.in = in;
    const double R = in.resistance_Ohm, L = in.inductance_H, J = in.inertia_kgm2, F = in.friction_Nms_rad;
    const double kM = in.torque_constant_Nm_A, p = in.pole_pairs;

    // (4)
    rep.condition4_attraction = kM * in.c_align_voltage_V / (p * L * R);
    rep.condition4_excitation = (in.s_align_voltage_V * in.s_align_voltage_V + in.c_align_voltage_V * in.c_align_voltage_V)
                                / (2.0 * R * R);
    rep.condition4_margin = rep.condition4_attraction - rep.condition4_excitation;
    rep.condition4_met = rep.condition4_margin > 0.0;

    // (7): p_e < (R/L + K_e) / [12(...) + k_M^2/L^2].
    rep.p_e_bound = observer_rate(in) / p_e_denominator(in);
    // gamma > lambda^2 e^{4T_p} L^4/(p_e k_M^4 T_p^2) + 8 p_e k_M^4/L^4, minimised over T_p > 0 and the
    // admissible p_e. Both bounds of (7) depend on T_p only through e^{4T_p}/T_p^2, smallest at T_p = 1/2;
    // the search below finds it numerically as a check.
    rep.t_p_s = golden_min([&](double t) { return gamma_bound_inf_over_p_e(in, t, rep.p_e_bound); }, 1e-4, 1e2);
    rep.gamma_bound = gamma_bound_inf_over_p_e(in, rep.t_p_s, rep.p_e_bound);
    rep.gamma_met = in.gamma > rep.gamma_bound;
    // r >= 2 gamma^2 L^4 / (J^3 k_M^4 T_p^2 e^{-4T_p} p_e): smallest as p_e -> its bound.
    rep.r_bound = r_bound_at(in, rep.t_p_s, rep.p_e_bound);
    // With F = 0, r disappears from (6) (g_w = 2/lambda, g_T = J/gamma) and from P; the r-bound only
    // makes the e_w^2 term of (11) small and can be met by choosing r, without changing the loop.
    rep.r_enters_controller = F > 0.0;
    rep.r_met = !rep.r_enters_controller || in.r > rep.r_bound;

    // The admissible p_e at T_p: gamma > A/p_e + B p_e  <=>  p_e in (p1, p2); and p_e >= C/r (F > 0);
    // and p_e < p_e bound. rho decreases with p_e, so the best guarantee is at the smallest p_e.
    {
        const double coef_a = in.lambda * in.lambda * std::pow(L / kM, 4) * t_p_factor(rep.t_p_s);
        const double coef_b = 8.0 * std::pow(kM / L, 4);
        const double disc = in.gamma * in.gamma - 4.0 * coef_a * coef_b;
        double low = kNaN, high = kNaN;
        if (disc > 0.0) {
            low = 2.0 * coef_a / (in.gamma + std::sqrt(disc)); // the smaller root, without cancellation
            high = (in.gamma + std::sqrt(disc)) / (2.0 * coef_b);
        }
        if (rep.r_enters_controller && !std::isnan(low)) {
            const double p_r = r_bound_at(in, rep.t_p_s, 1.0) / in.r; // r_bound_at(p_e) = C/p_e
            low = std::max(low, p_r);
        }
        rep.condition7_met = !std::isnan(low) && low < std::min(high, rep.p_e_bound);
        rep.p_e_low = rep.condition7_met ? low : kNaN;
    }

    // P (symmetric 4x4): p11 = p22 = 1/2, p33 = lambda/2, p44 = gamma^2/(lambda J^2) + r F/2, p34 = -gamma/(2J).
    Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
    P(0, 0) = P(1, 1) = 0.5;
    P(2, 2) = in.lambda / 2.0;
    P(3, 3) = in.gamma * in.gamma / (in.lambda * J * J) + in.r * F / 2.0;
    P(2, 3) = P(3, 2) = -in.gamma / (2.0 * J);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(P, Eigen::EigenvaluesOnly);
    rep.s1 = eig.eigenvalues().minCoeff();
    rep.s2 = eig.eigenvalues().maxCoeff();

    if (rep.condition7_met) {
        rep.q = observer_rate(in) - rep.p_e_low * p_e_denominator(in);
        rep.rho = rho_at(in, rep.p_e_low, rep.s1, rep.s2);
    } else {
        rep.q = kNaN;
        rep.rho = kNaN;
    }
    // p_e -> 0: min{s1, p_e}/p_e -> 1, q -> R/L + K_e.
    rep.rho_ceiling = L / (2.0 * kM * p) * std::sqrt(observer_rate(in) / rep.s2);
    return rep;
}

std::string theorem_text(const TheoremReport &rep, bool plant_differs)
{
    const TheoremInputs &in = rep.in;
    std::ostringstream o;
    o << "Controller model: R " << in.resistance_Ohm << " Ohm, L " << in.inductance_H << " H, J " << in.inertia_kgm2
      << " kg m^2, F " << in.friction_Nms_rad << " Nm s/rad, k_M " << in.torque_constant_Nm_A << " Nm/A, p "
      << in.pole_pairs << "\n";
    o << "Gains: K_e " << in.observer_gain_per_s << " 1/s, gamma " << fmt("%.6g", in.gamma) << ", lambda " << in.lambda
      << ", r " << in.r << "; u_cs " << in.s_align_voltage_V << " V, u_cc " << in.c_align_voltage_V << " V\n";
    if (plant_differs) {
        o << "Note: the plant ([motor]) differs from the controller's model; the theorems assume the model is exact.\n";
    }
    o << "\nTheorem 2 (c-alignment), condition (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) = "
      << fmt("%.4f", rep.condition4_attraction) << " - " << fmt("%.4f", rep.condition4_excitation) << " = "
      << fmt("%.4f", rep.condition4_margin) << (rep.condition4_met ? "  > 0: MET\n" : "  <= 0: NOT MET\n");
    o << "\nTheorem 3, conditions (7) (sufficient, not necessary):\n";
    o << "  p_e < " << fmt("%.6e", rep.p_e_bound) << "\n";
    o << "  gamma > " << fmt("%.6e", rep.gamma_bound) << "  (smallest over T_p > 0 and p_e, at T_p = "
      << fmt("%.4f", rep.t_p_s) << " s, p_e -> its bound)\n";
    o << "    configured gamma = " << fmt("%.6e", in.gamma) << ": "
      << (rep.gamma_met ? "met" : "NOT met (" + fmt("%.3g", rep.gamma_bound / in.gamma) + " times too small)") << "\n";
    o << "  r >= " << fmt("%.6e", rep.r_bound) << "  (at that T_p, p_e -> its bound, configured gamma)\n";
    o << "    configured r = " << fmt("%.6g", in.r) << ": ";
    if (!rep.r_enters_controller) {
        o << "F = 0, so r does not enter controller (6) or P; the bound holds for a suitable r without changing the "
             "loop\n";
    } else {
        o << (rep.r_met ? "met" : "NOT met") << "\n";
    }
    o << "  P: s1 = " << fmt("%.6g", rep.s1) << ", s2 = " << fmt("%.6g", rep.s2) << "\n";
    if (rep.condition7_met) {
        o << "  verdict: (7) MET. Theorem 3 guarantees convergence for estimation errors at t_c with\n"
          << "    ||(i~_a, i~_b, e_w, T~_L)|| < rho = " << fmt("%.6e", rep.rho) << "  (p_e = " << fmt("%.6e", rep.p_e_low)
          << ", q = " << fmt("%.6g", rep.q) << ")\n";
    } else {
        o << "  verdict: (7) NOT MET. Theorem 3 guarantees nothing for these gains. (7) is sufficient only:\n"
          << "    the loop may still converge; measure it (--doa).\n";
    }
    o << "  rho can never exceed " << fmt("%.6e", rep.rho_ceiling)
      << " for this motor, K_e and P, whatever p_e (the formula's limit as p_e -> 0)\n";
    return o.str();
}

cJSON *theorem_json(const TheoremReport &rep, bool plant_differs)
{
    auto num = [](cJSON *obj, const char *key, double v) {
        if (std::isfinite(v)) {
            cJSON_AddNumberToObject(obj, key, v);
        } else {
            cJSON_AddNullToObject(obj, key);
        }
    };
    cJSON *root = cJSON_CreateObject();
    cJSON *inputs = cJSON_AddObjectToObject(root, "controller_model");
    num(inputs, "resistance_Ohm", rep.in.resistance_Ohm);
    num(inputs, "inductance_H", rep.in.inductance_H);
    num(inputs, "inertia_kgm2", rep.in.inertia_kgm2);
    num(inputs, "friction_Nms_rad", rep.in.friction_Nms_rad);
    num(inputs, "torque_constant_Nm_A", rep.in.torque_constant_Nm_A);
    num(inputs, "pole_pairs", rep.in.pole_pairs);
    num(inputs, "observer_gain_per_s", rep.in.observer_gain_per_s);
    num(inputs, "gamma", rep.in.gamma);
    num(inputs, "lambda", rep.in.lambda);
    num(inputs, "r", rep.in.r);
    num(inputs, "s_align_voltage_V", rep.in.s_align_voltage_V);
    num(inputs, "c_align_voltage_V", rep.in.c_align_voltage_V);
    cJSON_AddBoolToObject(root, "plant_differs_from_model", plant_differs);
    cJSON *c4 = cJSON_AddObjectToObject(root, "condition_4");
    num(c4, "attraction", rep.condition4_attraction);
    num(c4, "excitation", rep.condition4_excitation);
    num(c4, "margin", rep.condition4_margin);
    cJSON_AddBoolToObject(c4, "met", rep.condition4_met);
    cJSON *c7 = cJSON_AddObjectToObject(root, "condition_7");
    num(c7, "p_e_upper_bound", rep.p_e_bound);
    num(c7, "t_p_s", rep.t_p_s);
    num(c7, "gamma_lower_bound", rep.gamma_bound);
    cJSON_AddBoolToObject(c7, "gamma_met", rep.gamma_met);
    num(c7, "r_lower_bound", rep.r_bound);
    cJSON_AddBoolToObject(c7, "r_enters_controller", rep.r_enters_controller);
    cJSON_AddBoolToObject(c7, "r_met", rep.r_met);
    cJSON_AddBoolToObject(c7, "met", rep.condition7_met);
    cJSON_AddBoolToObject(c7, "sufficient_only", true);
    num(c7, "p_e_used", rep.p_e_low);
    cJSON *b = cJSON_AddObjectToObject(root, "domain_of_attraction");
    num(b, "s1", rep.s1);
    num(b, "s2", rep.s2);
    num(b, "q", rep.q);
    num(b, "rho", rep.rho);
    num(b, "rho_ceiling", rep.rho_ceiling);
    return root;
}

// ---------------------------------------------------------------- empirical domain of attraction

namespace {

/** State of one perturbed run, seen by the SIL's sample callback. */
struct RunProbe {
    std::array<double, 4> error;     // set at t_c + T_s: (i~_a, i~_b, e_w, T~_L)
    double friction_Nms_rad;    // the controller's F: T~_L = T_L - T_L-hat - F e_w
    double window_start_s;
    long perturbed_step = -1;
    double measured_norm = 0.0;
    double window_speed_error = 0.0;
    double window_speed_hat_error = 0.0;
    double last_load_error = 0.0;
    bool nonfinite = false;
};

bool probe_sample(const sil_sample_t *x, void *user)
{
    auto *pr = static_cast<RunProbe *>(user);
    const pmstep_output_t *o = x->out;
    if (o->fault != PMSTEP_FAULT_NONE) {
        return false; // latched: the run has failed
    }
    if (o->mode != PMSTEP_MODE_RUN) {
        return true;
    }
    if (pr->perturbed_step < 0) {
        // First period of (6), t_c. The observer already holds its estimates for t_c + T_s and the
        // plant has advanced to t_c + T_s: set the estimates so that the errors of Theorem 3 are
        // exactly the requested ones there (the sample callback has no post-period plant state;
        // the host port's plant has it).
        const plant_t *plant = pmstep_hal_host_state()->plant;
        const double t_next_s = x->t_s + static_cast<double>(x->inst->cfg->timing.period_s);
        const double load_next_Nm = plant_load_torque(&plant->load, t_next_s, plant->x.omega_rad_s);
        pmstep_observer_t &obs = x->inst->observer;
        obs.i_a_hat_A = static_cast<float>(plant->x.i_a_A - pr->error[0]);
        obs.i_b_hat_A = static_cast<float>(plant->x.i_b_A - pr->error[1]);
        obs.speed_hat_rad_s = static_cast<float>(plant->x.omega_rad_s + pr->error[2]);
        obs.load_hat_Nm = static_cast<float>(load_next_Nm - pr->error[3] - pr->friction_Nms_rad * pr->error[2]);
        pr->perturbed_step = x->step;
        return true;
    }
    const double e_w = static_cast<double>(o->speed_hat_rad_s) - x->omega_rad_s;
    if (x->step == pr->perturbed_step + 1) {
        const double e[4] = {x->i_a_A - static_cast<double>(o->i_a_hat_A), x->i_b_A - static_cast<double>(o->i_b_hat_A),
                             e_w, x->load_Nm - static_cast<double>(o->load_hat_Nm) - pr->friction_Nms_rad * e_w};
        pr->measured_norm = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
    }
    if (!std::isfinite(x->omega_rad_s) || !std::isfinite(e_w)) {
        pr->nonfinite = true;
        return false;
    }
    if (x->t_s >= pr->window_start_s) {
        pr->window_speed_error = std::max(pr->window_speed_error,
                                          std::fabs(x->omega_rad_s - static_cast<double>(o->speed_ref_rad_s)));
        pr->window_speed_hat_error = std::max(pr->window_speed_hat_error, std::fabs(e_w));
    }
    pr->last_load_error = std::fabs(static_cast<double>(o->load_hat_Nm) - x->load_Nm);
    return true;
}

std::string axis_label(int axis, double sign)
{
    static const char *const names[4] = {"i~_a", "i~_b", "e_w", "T~_L"};
    return std::string(sign > 0 ? "+" : "-") + names[axis];
}

} // namespace

DoaRun doa_single_run(const sil_scenario_t &sc, const std::array<double, 4> &error, const DoaOptions &opt)
{
    RunProbe probe;
    probe.error = error;
    probe.friction_Nms_rad = static_cast<double>(sc.controller.motor.friction_Nms_rad);
    probe.window_start_s = sc.duration_s - opt.final_window_s;
    sil_summary_t summary;
    DoaRun run;
    run.direction = -1;
    run.radius = std::sqrt(error[0] * error[0] + error[1] * error[1] + error[2] * error[2] + error[3] * error[3]);
    run.converged = false;
    run.final_speed_error_rad_s = kNaN;
    run.final_load_error_Nm = kNaN;
    run.measured_norm = kNaN;
    if (sil_run(&sc, probe_sample, &probe, false, &summary) != 0) {
        run.reason = std::string("configuration rejected: ") + pmstep_status_str(summary.init_status);
        return run;
    }
    run.measured_norm = probe.perturbed_step >= 0 ? probe.measured_norm : kNaN;
    run.final_speed_error_rad_s = std::max(probe.window_speed_error, probe.window_speed_hat_error);
    run.final_load_error_Nm = probe.last_load_error;
    char buf[160];
    if (summary.fault != PMSTEP_FAULT_NONE) {
        std::snprintf(buf, sizeof buf, "fault at %.4f s: %s", summary.fault_time_s, pmstep_fault_str(summary.fault));
        run.reason = buf;
    } else if (probe.nonfinite) {
        run.reason = "non-finite state";
    } else if (probe.perturbed_step < 0) {
        run.reason = "never reached RUN";
    } else if (probe.window_speed_error >= opt.speed_tol_rad_s) {
        std::snprintf(buf, sizeof buf, "max |w - w*| = %.3g rad/s on the final window", probe.window_speed_error);
        run.reason = buf;
    } else if (probe.window_speed_hat_error >= opt.speed_tol_rad_s) {
        std::snprintf(buf, sizeof buf, "max |w-hat - w| = %.3g rad/s on the final window", probe.window_speed_hat_error);
        run.reason = buf;
    } else if (probe.last_load_error >= opt.load_tol_Nm) {
        std::snprintf(buf, sizeof buf, "|T_L-hat - T_L| = %.3g Nm at the end", probe.last_load_error);
        run.reason = buf;
    } else {
        run.converged = true;
        run.reason = "converged";
    }
    return run;
}

DoaResult doa_study(const sil_scenario_t &sc, const DoaOptions &opt, bool progress)
{
    const auto wall_start = std::chrono::steady_clock::now();
    DoaResult res;
    res.options = opt;
    // Directions: the 8 signed axes, then random points on the unit sphere of R^4 (normalised Gaussians).
    for (int axis = 0; axis < 4; ++axis) {
        for (double sign : {1.0, -1.0}) {
            DoaDirection d{};
            d.unit[static_cast<std::size_t>(axis)] = sign;
            d.label = axis_label(axis, sign);
            res.directions.push_back(d);
        }
    }
    std::mt19937 rng(opt.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (int n = 0; n < opt.random_directions; ++n) {
        DoaDirection d{};
        double norm = 0.0;
        for (double &c : d.unit) {
            c = gauss(rng);
            norm += c * c;
        }
        norm = std::sqrt(norm);
        for (double &c : d.unit) {
            c /= norm;
        }
        d.label = "random " + std::to_string(n);
        res.directions.push_back(d);
    }

    const DoaRun base = doa_single_run(sc, {0.0, 0.0, 0.0, 0.0}, opt);
    res.baseline_converged = base.converged;
    res.baseline_reason = base.reason;

    auto run_at = [&](int dir, double radius) {
        std::array<double, 4> e;
        for (std::size_t i = 0; i < 4; ++i) {
            e[i] = radius * res.directions[static_cast<std::size_t>(dir)].unit[i];
        }
        DoaRun r = doa_single_run(sc, e, opt);
        r.direction = dir;
        r.radius = radius;
        res.runs.push_back(r);
        return r;
    };

    res.radius_all_converged = kInf;
    for (int dir = 0; dir < static_cast<int>(res.directions.size()); ++dir) {
        DoaDirection &d = res.directions[static_cast<std::size_t>(dir)];
        d.last_converged_radius = 0.0;
        d.first_failed_radius = kInf;
        for (double radius = opt.radius_min; radius <= opt.radius_max * (1.0 + 1e-12); radius *= opt.radius_factor) {
            const DoaRun r = run_at(dir, radius);
            if (!r.converged) {
                d.first_failed_radius = radius;
                d.failure_reason = r.reason;
                break;
            }
            d.last_converged_radius = radius;
        }
        if (std::isfinite(d.first_failed_radius) && d.last_converged_radius > 0.0) {
            for (int n = 0; n < opt.bisection_steps; ++n) {
                const double mid = std::sqrt(d.last_converged_radius * d.first_failed_radius);
                const DoaRun r = run_at(dir, mid);
                if (r.converged) {
                    d.last_converged_radius = mid;
                } else {
                    d.first_failed_radius = mid;
                    d.failure_reason = r.reason;
                }
            }
        }
        res.radius_all_converged = std::min(res.radius_all_converged, d.last_converged_radius);
        if (progress) {
            std::fprintf(stderr, "  direction %3d/%zu %-10s converges to %.4g, first failure %.4g%s%s\n", dir + 1,
                         res.directions.size(), d.label.c_str(), d.last_converged_radius, d.first_failed_radius,
                         d.failure_reason.empty() ? "" : ": ", d.failure_reason.c_str());
        }
    }
    res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return res;
}

std::string doa_text(const DoaResult &res, const TheoremReport &rep)
{
    std::ostringstream o;
    const DoaOptions &opt = res.options;
    o << "\nEmpirical domain of attraction (SIL: the firmware with the plant model):\n";
    o << "  errors (i~_a A, i~_b A, e_w rad/s, T~_L Nm) set at t_c + T_s along " << res.directions.size()
      << " directions (8 axes + " << opt.random_directions << " random, seed " << opt.seed << "), radii "
      << fmt("%.3g", opt.radius_min) << " x " << fmt("%.3g", opt.radius_factor) << "^k up to " << fmt("%.3g", opt.radius_max)
      << ", " << opt.bisection_steps << " bisections\n";
    o << "  converged = no fault, max |w - w*| and |w-hat - w| < " << fmt("%.3g", opt.speed_tol_rad_s)
      << " rad/s on the last " << fmt("%.3g", opt.final_window_s) << " s, |T_L-hat - T_L| < "
      << fmt("%.3g", opt.load_tol_Nm) << " Nm at the end\n";
    o << "  without added errors: " << res.baseline_reason << "\n";
    for (const DoaDirection &d : res.directions) {
        if (d.label[0] == '+' || d.label[0] == '-') {
            o << "  " << d.label << ": converges up to " << fmt("%.4g", d.last_converged_radius);
            if (std::isfinite(d.first_failed_radius)) {
                o << ", fails at " << fmt("%.4g", d.first_failed_radius) << " (" << d.failure_reason << ")\n";
            } else {
                o << " (no failure up to " << fmt("%.3g", opt.radius_max) << ")\n";
            }
        }
    }
    const DoaDirection *worst = nullptr;
    for (const DoaDirection &d : res.directions) {
        if (worst == nullptr || d.last_converged_radius < worst->last_converged_radius) {
            worst = &d;
        }
    }
    o << "  largest radius with 100% convergence: " << fmt("%.4g", res.radius_all_converged);
    if (worst != nullptr && std::isfinite(worst->first_failed_radius)) {
        o << " (limited by " << worst->label << ": " << worst->failure_reason << ")";
    }
    o << "\n  theory: rho = " << (rep.condition7_met ? fmt("%.4g", rep.rho) : std::string("none ((7) not met)"))
      << ", and at most " << fmt("%.4g", rep.rho_ceiling) << " for any p_e\n";
    o << "  " << res.runs.size() << " runs in " << fmt("%.1f", res.wall_time_s) << " s\n";
    return o.str();
}

cJSON *doa_json(const DoaResult &res)
{
    auto num = [](cJSON *obj, const char *key, double v) {
        if (std::isfinite(v)) {
            cJSON_AddNumberToObject(obj, key, v);
        } else {
            cJSON_AddNullToObject(obj, key);
        }
    };
    const DoaOptions &opt = res.options;
    cJSON *root = cJSON_CreateObject();
    cJSON *o = cJSON_AddObjectToObject(root, "options");
    num(o, "random_directions", opt.random_directions);
    num(o, "seed", opt.seed);
    num(o, "radius_min", opt.radius_min);
    num(o, "radius_max", opt.radius_max);
    num(o, "radius_factor", opt.radius_factor);
    num(o, "bisection_steps", opt.bisection_steps);
    num(o, "final_window_s", opt.final_window_s);
    num(o, "speed_tol_rad_s", opt.speed_tol_rad_s);
    num(o, "load_tol_Nm", opt.load_tol_Nm);
    cJSON_AddBoolToObject(root, "baseline_converged", res.baseline_converged);
    cJSON_AddStringToObject(root, "baseline_reason", res.baseline_reason.c_str());
    num(root, "radius_all_converged", res.radius_all_converged);
    num(root, "runs", static_cast<double>(res.runs.size()));
    num(root, "wall_time_s", res.wall_time_s);
    cJSON *dirs = cJSON_AddArrayToObject(root, "directions");
    for (const DoaDirection &d : res.directions) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "label", d.label.c_str());
        cJSON *u = cJSON_AddArrayToObject(j, "unit");
        for (double c : d.unit) {
            cJSON_AddItemToArray(u, cJSON_CreateNumber(c));
        }
        num(j, "last_converged_radius", d.last_converged_radius);
        num(j, "first_failed_radius", d.first_failed_radius);
        cJSON_AddStringToObject(j, "failure_reason", d.failure_reason.c_str());
        cJSON_AddItemToArray(dirs, j);
    }
    return root;
}

bool doa_write_csv(const DoaResult &res, const std::string &path)
{
    std::FILE *f = std::fopen(path.c_str(), "w");
    if (f == nullptr) {
        return false;
    }
    std::fprintf(f, "direction,label,radius,measured_norm,converged,final_speed_error_rad_s,final_load_error_Nm,reason\n");
    for (const DoaRun &r : res.runs) {
        std::string reason = r.reason;
        std::replace(reason.begin(), reason.end(), ',', ';');
        std::fprintf(f, "%d,%s,%.9g,%.9g,%d,%.6g,%.6g,%s\n", r.direction,
                     res.directions[static_cast<std::size_t>(r.direction)].label.c_str(), r.radius, r.measured_norm,
                     r.converged ? 1 : 0, r.final_speed_error_rad_s, r.final_load_error_Nm, reason.c_str());
    }
    return std::fclose(f) == 0;
}

} // namespace pmstep_gain
