// The oracle's scenario on the SIL's sample grid: shared by the oracle tests and the
// integrator study, so both compare the SIL against the same continuous-time run.
#ifndef PMSTEP_SIL_GRID_HPP
#define PMSTEP_SIL_GRID_HPP

#include <cmath>

#include "oracle.hpp"
#include "sil_capture.hpp"

namespace pmstep_oracle {

/** The first sample time k T_s >= t, as the SIL runner issues a set-point command. */
inline double first_sample_at_or_after(double t_s, double period_s)
{
    double k = std::floor(t_s / period_s);
    while (k * period_s < t_s) {
        k += 1.0;
    }
    while (k > 0.0 && (k - 1.0) * period_s >= t_s) {
        k -= 1.0;
    }
    return k * period_s;
}

/** The paper's scenario for the oracle, with the timing the SIL actually realises at its period:
 *  t_s, t_c and the ramp commands on the sample grid (the runner issues a command at the first
 *  period whose time is >= the breakpoint), ramp rates as the firmware holds them (float).
 *  The motor and gains stay the oracle's own (from the paper), not the SIL's, except the detent
 *  torque, which the paper does not have. */
inline pmstep_oracle::Scenario oracle_on_sil_grid(const sil_scenario_t &sil)
{
    pmstep_oracle::Scenario sc = pmstep_oracle::paper_scenario();
    sc.motor.detent_torque_Nm = sil.motor.detent_torque_Nm; // not in the paper: the SIL plant's, like for like
    const double period_s = static_cast<double>(sil.controller.timing.period_s);
    sc.s_align_time_s = static_cast<double>(sil_period_index(sil, static_cast<double>(sil.controller.alignment.s_align_time_s)))
                        * period_s;
    sc.c_align_time_s = static_cast<double>(sil_period_index(sil, static_cast<double>(sil.controller.alignment.c_align_time_s)))
                        * period_s;
    for (pmstep_oracle::RampCommand &cmd : sc.speed_commands) {
        cmd.time_s = first_sample_at_or_after(cmd.time_s, period_s);
        cmd.rate_rad_s2 = static_cast<double>(static_cast<float>(cmd.rate_rad_s2));
    }
    return sc;
}

} // namespace pmstep_oracle

#endif // PMSTEP_SIL_GRID_HPP
