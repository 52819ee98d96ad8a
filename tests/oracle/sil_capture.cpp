// Captures a SIL run sample by sample (see sil_capture.hpp).
#include "sil_capture.hpp"

#include <cmath>

namespace pmstep_oracle {

namespace {

bool keep_sample(const sil_sample_t *x, void *user)
{
    auto *run = static_cast<SilRun *>(user);
    const pmstep_output_t *o = x->out;
    run->samples.push_back(SilSample{x->t_s, x->theta_rad, x->omega_rad_s, x->i_a_A, x->i_b_A, x->u_a_V, x->u_b_V,
                                     x->load_Nm, o->mode, static_cast<double>(o->speed_ref_rad_s),
                                     static_cast<double>(o->speed_hat_rad_s), static_cast<double>(o->load_hat_Nm),
                                     static_cast<double>(o->i_a_hat_A), static_cast<double>(o->i_b_hat_A),
                                     static_cast<double>(o->cos_hat), static_cast<double>(o->sin_hat)});
    return true;
}

} // namespace

SilRun capture_sil(const sil_scenario_t &sc)
{
    SilRun run;
    run.samples.reserve(static_cast<std::size_t>(sc.duration_s / static_cast<double>(sc.controller.timing.period_s)) + 2);
    run.status = sil_run(&sc, keep_sample, &run, false, &run.summary);
    return run;
}

long sil_period_index(const sil_scenario_t &sc, double t_s)
{
    return static_cast<long>(std::floor(t_s / static_cast<double>(sc.controller.timing.period_s) + 0.5));
}

std::vector<double> sil_sample_times(const sil_scenario_t &sc)
{
    const double period_s = static_cast<double>(sc.controller.timing.period_s);
    const long steps = sil_period_index(sc, sc.duration_s);
    std::vector<double> times(static_cast<std::size_t>(steps));
    for (long k = 0; k < steps; ++k) {
        times[static_cast<std::size_t>(k)] = static_cast<double>(k) * period_s;
    }
    return times;
}

} // namespace pmstep_oracle
