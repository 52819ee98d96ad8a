// pmstep-integrator-study: the plant integrators of sil/plant.h against a fine RK4
// reference and against the continuous-time oracle. Prints Markdown tables.
//
// 1. Open loop (the integrator's own error): the inverter commands of a closed-loop run
//    (RK4, 25 steps a period) are replayed through the inverter and plant with each
//    method and step count; the states at every period boundary are compared with the
//    replay at the reference setting (which reproduces the closed-loop run bit for bit).
// 2. Closed loop: each setting runs the scenario through the real firmware; the summary
//    metrics the tests bound are compared with those of the reference setting.
// 3. Oracle (paper scenario only): max |omega_SIL - omega_oracle| on [t_c, end], the
//    electrical-angle differences at t_s and t_c and the final load estimates, as
//    tests/oracle/test_oracle.cpp measures them.
//
// usage: pmstep-integrator-study [--scenario FILE] [--set key=value]... [--no-oracle]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "oracle.hpp"
#include "sil_capture.hpp"
#include "sil_grid.hpp"
#include "pmstep_hal_host.h"

using namespace pmstep_oracle;

namespace {

struct Setting {
    plant_integrator_t method;
    int steps;
};

const char *method_name(plant_integrator_t m)
{
    return m == PLANT_INTEGRATOR_RK4 ? "rk4" : "exponential";
}

/** What the bridge was told in one period of the closed-loop run. */
struct Command {
    bool enable;
    double a_v, b_v, bus_V;
};

struct Recorded {
    std::vector<Command> commands;
};

bool keep_command(const sil_sample_t *, void *user)
{
    auto *rec = static_cast<Recorded *>(user);
    const sil_inverter_t &inv = pmstep_hal_host_state()->inverter;
    rec->commands.push_back(Command{inv.bridge_enable, inv.command_a_V, inv.command_b_V, inv.command_bus_V});
    return true;
}

struct Trajectory {
    std::vector<plant_state_t> x; ///< at the end of every period
    double wall_s;
};

Trajectory replay(const sil_scenario_t &sc, const Recorded &rec, Setting set)
{
    plant_t plant;
    std::memset(&plant, 0, sizeof plant);
    plant.params = sc.motor;
    plant.load = sc.load;
    plant.x.theta_rad = sc.theta0_rad;
    plant.x.omega_rad_s = sc.omega0_rad_s;
    plant.x.i_a_A = sc.i_a0_A;
    plant.x.i_b_A = sc.i_b0_A;
    plant.integrator = set.method;
    sil_inverter_t inv;
    sil_inverter_init(&inv, &sc.inverter, &sc.bus, sc.bus_voltage_V, sc.controller.timing.computational_delay_periods);
    const double period_s = static_cast<double>(sc.controller.timing.period_s);
    Trajectory tr;
    tr.x.reserve(rec.commands.size());
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < rec.commands.size(); ++k) {
        const Command &c = rec.commands[k];
        plant.time_s = static_cast<double>(k) * period_s;
        inv.bridge_enable = c.enable;
        inv.command_a_V = c.a_v;
        inv.command_b_V = c.b_v;
        inv.command_bus_V = c.bus_V;
        sil_drive_advance(&plant, &inv, period_s, set.steps);
        tr.x.push_back(plant.x);
    }
    tr.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return tr;
}

struct Errors {
    double angle_rad, omega_rad_s, current_a;
};

Errors max_errors(const Trajectory &a, const Trajectory &ref, int pole_pairs)
{
    Errors e{0.0, 0.0, 0.0};
    for (std::size_t k = 0; k < a.x.size(); ++k) {
        const plant_state_t &x = a.x[k];
        const plant_state_t &r = ref.x[k];
        e.angle_rad = std::fmax(e.angle_rad, std::fabs(pole_pairs * (x.theta_rad - r.theta_rad)));
        e.omega_rad_s = std::fmax(e.omega_rad_s, std::fabs(x.omega_rad_s - r.omega_rad_s));
        e.current_a = std::fmax(e.current_a, std::fmax(std::fabs(x.i_a_A - r.i_a_A), std::fabs(x.i_b_A - r.i_b_A)));
    }
    return e;
}

struct OracleDiff {
    double speed_rad_s, angle_ts_rad, angle_tc_rad, load_hat_Nm;
};

OracleDiff against_oracle(const sil_scenario_t &sil, const SilRun &run, const std::vector<Sample> &oracle)
{
    const double p = sil.motor.pole_pairs;
    const auto k_s = static_cast<std::size_t>(sil_period_index(sil, static_cast<double>(sil.controller.alignment.s_align_time_s)));
    const auto k_c = static_cast<std::size_t>(sil_period_index(sil, static_cast<double>(sil.controller.alignment.c_align_time_s)));
    OracleDiff d{0.0, 0.0, 0.0, 0.0};
    for (std::size_t k = k_c; k < run.samples.size() && k < oracle.size(); ++k) {
        d.speed_rad_s = std::fmax(d.speed_rad_s, std::fabs(run.samples[k].omega_rad_s - oracle[k].x[idx::omega]));
    }
    d.angle_ts_rad = std::fabs(p * (run.samples[k_s].theta_rad - oracle[k_s].x[idx::theta]));
    d.angle_tc_rad = std::fabs(p * (run.samples[k_c].theta_rad - oracle[k_c].x[idx::theta]));
    d.load_hat_Nm = std::fabs(run.samples.back().load_hat_Nm - oracle.back().x[idx::load_hat]);
    return d;
}

int usage()
{
    std::fprintf(stderr, "usage: pmstep-integrator-study [--scenario FILE] [--set key=value]... [--no-oracle]\n");
    return 2;
}

} // namespace

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    char err[SIL_ERROR_MAX];
    bool oracle_wanted = true;
    std::string label = "paper";
    sil_scenario_paper(&sc);
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--scenario") == 0 && i + 1 < argc) {
            label = argv[++i];
            if (sil_scenario_load(&sc, label.c_str(), err, sizeof err) != 0) {
                std::fprintf(stderr, "pmstep-integrator-study: %s\n", err);
                return 2;
            }
        } else if (std::strcmp(argv[i], "--set") == 0 && i + 1 < argc) {
            if (sil_scenario_set_assignment(&sc, argv[++i], err, sizeof err) != 0) {
                std::fprintf(stderr, "pmstep-integrator-study: %s\n", err);
                return 2;
            }
            label += std::string(" ") + argv[i];
        } else if (std::strcmp(argv[i], "--no-oracle") == 0) {
            oracle_wanted = false;
        } else {
            return usage();
        }
    }
    if (sil_scenario_check(&sc, err, sizeof err) != 0) {
        std::fprintf(stderr, "pmstep-integrator-study: %s\n", err);
        return 2;
    }
    const Setting reference{PLANT_INTEGRATOR_RK4, 25};
    const std::vector<Setting> settings = {
        {PLANT_INTEGRATOR_RK4, 100},         {PLANT_INTEGRATOR_RK4, 25},          {PLANT_INTEGRATOR_RK4, 10},
        {PLANT_INTEGRATOR_RK4, 5},           {PLANT_INTEGRATOR_RK4, 2},           {PLANT_INTEGRATOR_RK4, 1},
        {PLANT_INTEGRATOR_EXPONENTIAL, 5},   {PLANT_INTEGRATOR_EXPONENTIAL, 2},   {PLANT_INTEGRATOR_EXPONENTIAL, 1}};
    const double period_s = static_cast<double>(sc.controller.timing.period_s);

    // The reference closed-loop run and its bridge commands.
    sil_scenario_t ref_sc = sc;
    ref_sc.integrator = reference.method;
    ref_sc.substeps = reference.steps;
    Recorded rec;
    sil_summary_t ref_summary;
    if (sil_run(&ref_sc, keep_command, &rec, false, &ref_summary) != 0) {
        std::fprintf(stderr, "pmstep-integrator-study: the reference run failed\n");
        return 1;
    }
    const Trajectory ref = replay(sc, rec, reference);

    std::printf("## %s: %s inverter, %.0f Hz, %.3g s\n\n", label.c_str(),
                sc.inverter.model == SIL_INVERTER_SWITCHING ? "switching" : "averaged", 1.0 / period_s, sc.duration_s);
    std::printf("Open loop: the reference run's bridge commands replayed; max error against %s x%d over %zu "
                "periods, and the wall time of the plant and inverter per period.\n\n",
                method_name(reference.method), reference.steps, rec.commands.size());
    std::printf("| method | steps/period | max abs(p dtheta) (rad) | max abs(d omega) (rad/s) | max abs(d i) (A) | "
                "plant ns/period |\n|---|---|---|---|---|---|\n");
    for (const Setting &set : settings) {
        const Trajectory tr = replay(sc, rec, set);
        const Errors e = max_errors(tr, ref, sc.motor.pole_pairs);
        std::printf("| %s | %d | %.2e | %.2e | %.2e | %.0f |\n", method_name(set.method), set.steps, e.angle_rad,
                    e.omega_rad_s, e.current_a, tr.wall_s / static_cast<double>(tr.x.size()) * 1e9);
    }

    std::vector<Sample> oracle;
    const bool with_oracle = oracle_wanted && sc.inverter.model == SIL_INVERTER_AVERAGED;
    if (with_oracle) {
        oracle = simulate(oracle_on_sil_grid(sc), sil_sample_times(sc));
    }
    std::printf("\nClosed loop (real firmware): summary metrics, and their differences from %s x%d%s.\n\n",
                method_name(reference.method), reference.steps,
                with_oracle ? "; against the oracle as tests/oracle measures it" : "");
    std::printf("| method | steps/period | transient max speed err (rad/s) | tracking max speed err (rad/s) | "
                "max angle err after settle (rad) | R-hat (Ohm) | d(tracking max) | d(final T_L-hat) (Nm) |%s\n",
                with_oracle ? " oracle: max abs(d omega) (rad/s) | abs(p dtheta) t_s / t_c (rad) | abs(d T_L-hat) (Nm) |" : "");
    std::printf("|---|---|---|---|---|---|---|---|%s\n", with_oracle ? "---|---|---|" : "");
    for (const Setting &set : settings) {
        sil_scenario_t run_sc = sc;
        run_sc.integrator = set.method;
        run_sc.substeps = set.steps;
        const SilRun run = capture_sil(run_sc);
        if (run.status != 0) {
            std::fprintf(stderr, "pmstep-integrator-study: run failed (%d)\n", run.status);
            return 1;
        }
        const sil_summary_t &s = run.summary;
        std::printf("| %s | %d | %.6f | %.6f | %.3e | %.5f | %.1e | %.1e |", method_name(set.method), set.steps,
                    s.transient_max_speed_error_rad_s, s.tracking_max_speed_error_rad_s, s.max_angle_error_rad,
                    static_cast<double>(s.commissioning.resistance_Ohm),
                    s.tracking_max_speed_error_rad_s - ref_summary.tracking_max_speed_error_rad_s,
                    s.final_load_hat_Nm - ref_summary.final_load_hat_Nm);
        if (with_oracle) {
            const OracleDiff d = against_oracle(run_sc, run, oracle);
            std::printf(" %.6f | %.1e / %.1e | %.1e |", d.speed_rad_s, d.angle_ts_rad, d.angle_tc_rad, d.load_hat_Nm);
        }
        std::printf("\n");
    }
    return 0;
}
