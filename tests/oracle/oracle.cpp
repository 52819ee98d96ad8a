// Continuous-time oracle of plant (1) + alignment (3), (5) + controller (6) / (13).
// Written from the paper (Tomei & Verrelli) and docs' design notes, section 3.
#include "oracle.hpp"

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/external/eigen/eigen.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pmstep_oracle {

namespace ode = boost::numeric::odeint;
using State = Eigen::VectorXd;

Scenario paper_scenario()
{
    Scenario sc;
    // Section III.B: F = 0, p = 6, J = 0.01, R = 3, L = 0.006, k_M = 2 (SI).
    sc.motor = Motor{3.0, 0.006, 0.01, 0.0, 2.0, 6};
    // u_cs = u_cc = 24, k_w = 100, K_e = 100, K_i = 20, gamma = J/9, lambda = 0.2, kappa = 9, w0 = 300.
    sc.gains = Gains{100.0, 100.0, 20.0, 0.01 / 9.0, 0.2, 1.0, 9.0, 300.0};
    sc.s_align_time_s = 0.3;
    sc.c_align_time_s = 0.6;
    sc.s_align_voltage_V = 24.0;
    sc.c_align_voltage_V = 24.0;
    sc.theta0_rad = 30.0 * M_PI / 180.0;
    sc.omega0_rad_s = 0.0;
    sc.i_a0_A = 0.0;
    sc.i_b0_A = 0.0;
    // Ramps: 0 -> 10 rad/s over [0.65, 0.85], -> -10 over [1.2, 1.5], -> 0 over [1.8, 2.0].
    sc.speed_commands = {{0.65, 10.0, 50.0}, {1.2, -10.0, 20.0 / 0.3}, {1.8, 0.0, 50.0}};
    sc.load_steps = {{0.63, 2.0}}; // 2 Nm (rated) at 0.63 s
    sc.known_load = false;
    sc.duration_s = 2.4;
    return sc;
}

/** The detent's potential energy over L, T_d (1 - cos 4 p theta)/(4 p L) >= 0: its rate, (T_d/L) sin(4 p theta) w,
 *  cancels the detent's share of d/dt (J/(2L)) w^2, so U_s and U_c keep their derivatives with a detent. */
static double detent_energy(const Motor &m, double theta_rad)
{
    if (m.detent_torque_Nm == 0.0) {
        return 0.0;
    }
    const double p = m.pole_pairs;
    return m.detent_torque_Nm * (1.0 - std::cos(4.0 * p * theta_rad)) / (4.0 * p * m.inductance_H);
}

double lyapunov_s(const Motor &m, double u_cs_V, double theta_rad, double omega_rad_s, double i_a_A, double i_b_A)
{
    const double i_b_err = i_b_A - u_cs_V / m.resistance_Ohm;
    const double p = m.pole_pairs;
    return 0.5 * (m.inertia_kgm2 / m.inductance_H * omega_rad_s * omega_rad_s + i_a_A * i_a_A + i_b_err * i_b_err)
           - m.torque_constant_Nm_A * u_cs_V / (p * m.inductance_H * m.resistance_Ohm)
                 * (std::sin(p * theta_rad) - 2.0)
           + detent_energy(m, theta_rad);
}

double lyapunov_c(const Motor &m, double u_cc_V, double theta_rad, double omega_rad_s, double i_a_A, double i_b_A)
{
    const double i_a_err = i_a_A - u_cc_V / m.resistance_Ohm;
    const double p = m.pole_pairs;
    return 0.5 * (m.inertia_kgm2 / m.inductance_H * omega_rad_s * omega_rad_s + i_a_err * i_a_err + i_b_A * i_b_A)
           - m.torque_constant_Nm_A * u_cc_V / (p * m.inductance_H * m.resistance_Ohm)
                 * (std::cos(p * theta_rad) - 2.0)
           + detent_energy(m, theta_rad);
}

double speed_injection_gain(const Motor &m, const Gains &g)
{
    const double J = m.inertia_kgm2, F = m.friction_Nms_rad;
    const double den = g.gamma * g.gamma * g.lambda + g.r * F * g.lambda * g.lambda * J * J;
    return (2.0 * g.gamma * g.gamma + g.r * F * g.lambda * J * J) / den;
}

double load_injection_gain(const Motor &m, const Gains &g)
{
    const double J = m.inertia_kgm2, F = m.friction_Nms_rad;
    const double den = g.gamma * g.gamma * g.lambda + g.r * F * g.lambda * g.lambda * J * J;
    return (2.0 * g.gamma * g.gamma * F + g.lambda * J * g.gamma + g.lambda * J * J * g.r * F * F) / den;
}

namespace {

/** Corner of the piecewise-linear speed set-point r(t), t >= t_c (held after the last corner). */
struct Knot {
    double t_s;
    double value_rad_s;
};

/** Turns the ramp commands into the corners of r(t): r(t_c) = 0, each command ramps from the
 *  set-point's present value, a ramp ends where it reaches its target. */
std::vector<Knot> setpoint_knots(const Scenario &sc)
{
    const double t_c = sc.c_align_time_s;
    std::vector<Knot> knots{{t_c, 0.0}};
    double origin_t = t_c, origin_v = 0.0, target = 0.0, rate = 0.0;
    auto value_at = [&](double t) {
        if (rate <= 0.0) {
            return target;
        }
        const double travel = rate * (t - origin_t);
        return target > origin_v ? std::min(target, origin_v + travel) : std::max(target, origin_v - travel);
    };
    auto ramp_end = [&]() { return rate > 0.0 ? origin_t + std::fabs(target - origin_v) / rate : origin_t; };
    for (const RampCommand &cmd : sc.speed_commands) {
        const double t = std::max(cmd.time_s, t_c);
        if (ramp_end() < t && ramp_end() > origin_t) {
            knots.push_back({ramp_end(), target});
        }
        const double v = value_at(t);
        if (knots.back().t_s != t) {
            knots.push_back({t, v});
        }
        origin_t = t;
        origin_v = v;
        target = cmd.target_rad_s;
        rate = cmd.rate_rad_s2;
        if (rate <= 0.0) { // a step: a vertical corner, made of two knots at the same time
            knots.push_back({t, target});
        }
    }
    if (rate > 0.0 && ramp_end() > origin_t) {
        knots.push_back({ramp_end(), target});
    }
    return knots;
}

/** r(t) on [t0, t1) is r0 + slope (t - t0): smooth on one segment between events. */
struct SetpointPiece {
    double t0_s, value0_rad_s, slope_rad_s2;
};

SetpointPiece setpoint_piece(const std::vector<Knot> &knots, double t_start)
{
    // The last knot at or before t_start (the later of two equal-time knots: after a step).
    std::size_t k = 0;
    for (std::size_t n = 0; n < knots.size(); ++n) {
        if (knots[n].t_s <= t_start) {
            k = n;
        }
    }
    if (k + 1 < knots.size()) {
        const double dt = knots[k + 1].t_s - knots[k].t_s;
        const double slope = dt > 0.0 ? (knots[k + 1].value_rad_s - knots[k].value_rad_s) / dt : 0.0;
        return {knots[k].t_s, knots[k].value_rad_s, slope};
    }
    return {knots[k].t_s, knots[k].value_rad_s, 0.0};
}

double load_at(const Scenario &sc, double t_s)
{
    double torque = 0.0;
    for (const LoadStep &s : sc.load_steps) {
        if (s.time_s <= t_s) {
            torque = s.torque_Nm;
        }
    }
    return torque;
}

/** sat_k(x) = x / sqrt(1 + (x/k)^2): smooth, odd, |sat| < k, slope 1 at 0; and its derivative. */
void smooth_sat(double x, double kappa, double &sat, double &slope)
{
    const double ratio = x / kappa;
    const double root = std::sqrt(1.0 + ratio * ratio);
    sat = x / root;
    slope = 1.0 / (root * root * root);
}

/** The closed loop on one segment: phase, load and set-point piece are constant there. */
struct ClosedLoop {
    const Scenario &sc;
    Phase phase;
    double load_Nm;          ///< T_L on the segment
    SetpointPiece setpoint;
    double i_a_tc_A, i_b_tc_A; ///< i_a(t_c), i_b(t_c) of the angle formula of (6)

    /** Evaluates the law and, when @p dx is given, the time derivative of the state. */
    void eval(const State &x, double t, Signals &sig, State *dx) const
    {
        const Motor &m = sc.motor;
        const Gains &g = sc.gains;
        const double R = m.resistance_Ohm, L = m.inductance_H, J = m.inertia_kgm2;
        const double F = m.friction_Nms_rad, kM = m.torque_constant_Nm_A;
        const double p = m.pole_pairs;
        const double w0 = g.reference_bandwidth_rad_s;
        const double theta = x[idx::theta], omega = x[idx::omega], i_a = x[idx::i_a], i_b = x[idx::i_b];
        const double sin_pt = std::sin(p * theta), cos_pt = std::cos(p * theta);

        sig = Signals();
        sig.load_Nm = load_Nm;
        double u_a = 0.0, u_b = 0.0;
        double d_phi1 = 0.0, d_phi2 = 0.0, d_ia_hat = 0.0, d_ib_hat = 0.0, d_omega_hat = 0.0, d_load_hat = 0.0;
        double d_ref1 = 0.0, d_ref2 = 0.0, d_ref3 = 0.0, d_lref1 = 0.0, d_lref2 = 0.0, d_lref3 = 0.0;
        double d_dissipation = 0.0;

        if (phase == Phase::s_align) {
            // (3): u_a = 0, u_b = u_cs. Theorem 1: U_s' = -(F/L) w^2 - (R/L)(i_a^2 + (i_b - u_cs/R)^2).
            u_b = sc.s_align_voltage_V;
            const double i_b_err = i_b - sc.s_align_voltage_V / R;
            d_dissipation = -(F / L) * omega * omega - (R / L) * (i_a * i_a + i_b_err * i_b_err);
        } else if (phase == Phase::c_align) {
            // (5): u_a = u_cc, u_b = 0. Theorem 2: U_c' = -(F/L) w^2 - (R/L)((i_a - u_cc/R)^2 + i_b^2).
            u_a = sc.c_align_voltage_V;
            const double i_a_err = i_a - sc.c_align_voltage_V / R;
            d_dissipation = -(F / L) * omega * omega - (R / L) * (i_a_err * i_a_err + i_b * i_b);
        } else {
            // Controller (6) (design notes, section 3).
            const double phi1 = x[idx::phi1], phi2 = x[idx::phi2];
            const double i_a_hat = x[idx::i_a_hat], i_b_hat = x[idx::i_b_hat];
            const double omega_hat = x[idx::omega_hat], load_hat = x[idx::load_hat];
            // Angle from the current integrals: c-hat, s-hat.
            const double c_hat = -(L * p / kM) * (i_a - i_a_tc_A - phi1) + 1.0;
            const double s_hat = -(L * p / kM) * (i_b - i_b_tc_A - phi2);
            // Park with the estimate.
            const double i_d = c_hat * i_a + s_hat * i_b;
            const double i_q = -s_hat * i_a + c_hat * i_b;
            // Reference: r through H(s) = w0^3/(s+w0)^3 as three lags; w*, w*', w*''.
            const double r = setpoint.value0_rad_s + setpoint.slope_rad_s2 * (t - setpoint.t0_s);
            const double x1 = x[idx::ref1], x2 = x[idx::ref2], x3 = x[idx::ref3];
            d_ref1 = w0 * (r - x1);
            d_ref2 = w0 * (x1 - x2);
            d_ref3 = w0 * (x2 - x3);
            const double w_ref = x3, w_ref_rate = d_ref3, w_ref_accel = w0 * (d_ref2 - d_ref3);
            // T_L* of Remark 1: the same H(s) applied to the known load.
            d_lref1 = w0 * (load_Nm - x[idx::lref1]);
            d_lref2 = w0 * (x[idx::lref1] - x[idx::lref2]);
            d_lref3 = w0 * (x[idx::lref2] - x[idx::lref3]);
            const double load_star = x[idx::lref3], load_star_rate = d_lref3;
            // i_d* = 0 (Section III.B).
            const double i_d_ref = 0.0, i_d_ref_rate_A_s = 0.0;
            // Injection term eps = (k_M/L)(s-hat i~_a - c-hat i~_b).
            const double i_a_err = i_a - i_a_hat, i_b_err = i_b - i_b_hat;
            const double eps = (kM / L) * (s_hat * i_a_err - c_hat * i_b_err);

            double speed_term, speed_slope; // k_w sat_k(e) and k_w sat_k'(e) in (6); k_w e and k_w in (13)
            const double e = omega_hat - w_ref;
            if (sc.known_load) {
                speed_term = g.speed_gain_per_s * e;
                speed_slope = g.speed_gain_per_s;
            } else {
                double sat, slope;
                smooth_sat(e, g.sat_kappa_rad_s, sat, slope);
                speed_term = g.speed_gain_per_s * sat;
                speed_slope = g.speed_gain_per_s * slope;
            }
            const double law_load = sc.known_load ? load_star : load_hat;
            // i_q* of (6) (erratum: T_L-hat/J) or (13) (T_L*/J).
            const double i_q_ref = (J / kM) * ((F / J) * w_ref - speed_term + law_load / J + w_ref_rate);
            double law_load_rate;
            if (sc.known_load) {
                // (13): w-hat' = -(F/J) w-hat + (k_M/J) i_q - T_L*/J + (1/l)[p i_q i~_d - p i_d i~_q - (k_M/L) i~_q].
                const double i_d_err = i_d - i_d_ref, i_q_err = i_q - i_q_ref;
                d_omega_hat = -(F / J) * omega_hat + (kM / J) * i_q - load_star / J
                              + (1.0 / g.lambda) * (p * i_q * i_d_err - p * i_d * i_q_err - (kM / L) * i_q_err);
                d_load_hat = 0.0;
                law_load_rate = load_star_rate;
            } else {
                // (6): w-hat' = -(F/J) w-hat - T_L-hat/J + (k_M/J) i_q + g_w eps, T_L-hat' = -g_T eps.
                d_omega_hat = -(F / J) * omega_hat - load_hat / J + (kM / J) * i_q
                              + speed_injection_gain(m, g) * eps;
                d_load_hat = -load_injection_gain(m, g) * eps;
                law_load_rate = d_load_hat;
            }
            // i_q*' with the observer's own right-hand sides (design notes, errata).
            const double i_q_ref_rate = (J / kM) * ((F / J) * w_ref_rate - speed_slope * (d_omega_hat - w_ref_rate)
                                                    + law_load_rate / J + w_ref_accel);
            const double phi_d = -(R / L) * i_d_ref + p * omega_hat * i_q - i_d_ref_rate_A_s;
            const double phi_q = -(R / L) * i_q_ref - p * omega_hat * i_d - (kM / L) * omega_hat - i_q_ref_rate;
            const double u_d = L * (-phi_d - g.current_gain_per_s * (i_d - i_d_ref));
            const double u_q = L * (-phi_q - g.current_gain_per_s * (i_q - i_q_ref));
            // Inverse Park with (c-hat, s-hat).
            u_a = c_hat * u_d - s_hat * u_q;
            u_b = s_hat * u_d + c_hat * u_q;
            // phi_1' = -(R/L) i_a + u_a/L, phi_2' = -(R/L) i_b + u_b/L.
            d_phi1 = -(R / L) * i_a + u_a / L;
            d_phi2 = -(R / L) * i_b + u_b / L;
            // Current observer of (6).
            d_ia_hat = -(R / L) * i_a_hat + (kM / L) * omega_hat * s_hat + u_a / L + g.observer_gain_per_s * i_a_err
                       + p * omega_hat * i_b_err;
            d_ib_hat = -(R / L) * i_b_hat - (kM / L) * omega_hat * c_hat + u_b / L + g.observer_gain_per_s * i_b_err
                       - p * omega_hat * i_a_err;

            sig.omega_ref_rad_s = w_ref;
            sig.omega_ref_rate_rad_s2 = w_ref_rate;
            sig.omega_ref_accel_rad_s3 = w_ref_accel;
            sig.cos_hat = c_hat;
            sig.sin_hat = s_hat;
            sig.i_d_A = i_d;
            sig.i_q_A = i_q;
            sig.i_q_ref_A = i_q_ref;
            sig.law_load_Nm = law_load;
        }
        sig.u_a_V = u_a;
        sig.u_b_V = u_b;

        if (dx != nullptr) {
            State &d = *dx;
            d.resize(idx::size);
            // Plant (1).
            d[idx::theta] = omega;
            d[idx::omega] = -(F / J) * omega + (kM / J) * (-i_a * sin_pt + i_b * cos_pt) - load_Nm / J;
            if (m.detent_torque_Nm != 0.0) {
                // Detent of a hybrid stepper: four periods per electrical period.
                d[idx::omega] -= (m.detent_torque_Nm / J) * std::sin(4.0 * p * theta);
            }
            d[idx::i_a] = -(R / L) * i_a + (kM / L) * omega * sin_pt + u_a / L;
            d[idx::i_b] = -(R / L) * i_b - (kM / L) * omega * cos_pt + u_b / L;
            d[idx::phi1] = d_phi1;
            d[idx::phi2] = d_phi2;
            d[idx::i_a_hat] = d_ia_hat;
            d[idx::i_b_hat] = d_ib_hat;
            d[idx::omega_hat] = d_omega_hat;
            d[idx::load_hat] = d_load_hat;
            d[idx::ref1] = d_ref1;
            d[idx::ref2] = d_ref2;
            d[idx::ref3] = d_ref3;
            d[idx::lref1] = d_lref1;
            d[idx::lref2] = d_lref2;
            d[idx::lref3] = d_lref3;
            d[idx::dissipation] = d_dissipation;
        }
    }
};

} // namespace

std::vector<Sample> simulate(const Scenario &sc, const std::vector<double> &sample_times_s, const Options &opt,
                             Stats *stats)
{
    if (!(sc.s_align_time_s > 0.0 && sc.c_align_time_s > sc.s_align_time_s && sc.duration_s > 0.0)) {
        throw std::invalid_argument("oracle: need 0 < t_s < t_c and duration > 0");
    }
    if (!std::is_sorted(sample_times_s.begin(), sample_times_s.end())) {
        throw std::invalid_argument("oracle: sample times must be sorted");
    }
    const std::vector<Knot> knots = setpoint_knots(sc);

    // Events: every time the right-hand side changes non-smoothly.
    std::vector<double> events{0.0, sc.s_align_time_s, sc.c_align_time_s, sc.duration_s};
    for (const LoadStep &s : sc.load_steps) {
        events.push_back(s.time_s);
    }
    for (const Knot &k : knots) {
        events.push_back(k.t_s);
    }
    std::sort(events.begin(), events.end());
    events.erase(std::remove_if(events.begin(), events.end(),
                                [&](double t) { return t < 0.0 || t > sc.duration_s; }),
                 events.end());
    events.erase(std::unique(events.begin(), events.end()), events.end());

    State x = State::Zero(idx::size);
    x[idx::theta] = sc.theta0_rad;
    x[idx::omega] = sc.omega0_rad_s;
    x[idx::i_a] = sc.i_a0_A;
    x[idx::i_b] = sc.i_b0_A;

    std::vector<Sample> out;
    out.reserve(sample_times_s.size());
    std::size_t next_sample = 0;
    double i_a_tc = 0.0, i_b_tc = 0.0;
    Stats local;

    for (std::size_t e = 0; e + 1 < events.size(); ++e) {
        const double a = events[e], b = events[e + 1];
        const Phase phase = a < sc.s_align_time_s ? Phase::s_align
                            : a < sc.c_align_time_s ? Phase::c_align
                                                     : Phase::run;
        if (a == sc.s_align_time_s) {
            x[idx::dissipation] = 0.0; // U_c's balance starts at t_s
        }
        if (a == sc.c_align_time_s) {
            // Start of (6) at t_c: phi = 0, i-hat = i(t_c), w-hat = 0, T_L-hat = 0 (section III.B), moved by
            // the requested offsets; reference filters at rest, T_L* filter at T_L(t_c).
            const InitialErrors &err = sc.initial_errors;
            i_a_tc = x[idx::i_a];
            i_b_tc = x[idx::i_b];
            x[idx::phi1] = 0.0;
            x[idx::phi2] = 0.0;
            x[idx::i_a_hat] = x[idx::i_a] - err.i_a_err_A;
            x[idx::i_b_hat] = x[idx::i_b] - err.i_b_err_A;
            x[idx::omega_hat] = err.speed_err_rad_s;
            x[idx::load_hat] = -err.load_err_Nm - sc.motor.friction_Nms_rad * err.speed_err_rad_s;
            if (sc.known_load) {
                x[idx::load_hat] = 0.0;
            }
            x[idx::ref1] = x[idx::ref2] = x[idx::ref3] = 0.0;
            x[idx::lref1] = x[idx::lref2] = x[idx::lref3] = load_at(sc, a);
            x[idx::dissipation] = 0.0;
        }
        const ClosedLoop loop{sc, phase, load_at(sc, a), setpoint_piece(knots, a), i_a_tc, i_b_tc};
        auto rhs = [&loop](const State &s, State &ds, double t) {
            Signals unused;
            loop.eval(s, t, unused, &ds);
        };

        // Observation times: the samples in [a, b), the end b (and b itself if it is the last sample).
        std::vector<double> times{a};
        const bool last = (e + 2 == events.size());
        std::vector<bool> is_sample{false};
        while (next_sample < sample_times_s.size()
               && (sample_times_s[next_sample] < b || (last && sample_times_s[next_sample] <= b))) {
            const double t = sample_times_s[next_sample];
            if (t < a) {
                throw std::invalid_argument("oracle: sample time before 0");
            }
            if (t == times.back()) {
                is_sample.back() = true;
            } else {
                times.push_back(t);
                is_sample.push_back(true);
            }
            ++next_sample;
        }
        if (times.back() != b) {
            times.push_back(b);
            is_sample.push_back(false);
        }
        std::size_t obs_index = 0;
        auto observer = [&](const State &s, double t) {
            if (is_sample[obs_index]) {
                Sample smp{t, phase, s, Signals()};
                loop.eval(s, t, smp.sig, nullptr);
                out.push_back(std::move(smp));
            }
            ++obs_index;
        };
        auto stepper = ode::make_controlled(opt.abs_tol, opt.rel_tol,
                                            ode::runge_kutta_dopri5<State, double, State, double,
                                                                    ode::vector_space_algebra>());
        const double dt0 = std::min(opt.initial_step_s, b - a);
        local.steps += ode::integrate_times(stepper, rhs, x, times.begin(), times.end(), dt0, observer,
                                            ode::max_step_checker(1000000));
        ++local.segments;
    }
    if (stats != nullptr) {
        *stats = local;
    }
    return out;
}

} // namespace pmstep_oracle
