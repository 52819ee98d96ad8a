/**
 * @file sil_capture.hpp
 * @brief Runs a SIL scenario (the real float32 firmware + the plant model, through
 *        sil_run()) and keeps every control period's sample, for comparisons with
 *        the oracle and for the theorem checks.
 */
#ifndef PMSTEP_SIL_CAPTURE_HPP
#define PMSTEP_SIL_CAPTURE_HPP

#include <vector>

#include "sil/runner.h" // C header with extern "C" guards

namespace pmstep_oracle {

/** One control period of the SIL at its sample time t_k (plant state before the period). */
struct SilSample {
    double t_s;
    double theta_rad, omega_rad_s, i_a_A, i_b_A;
    double u_a_V, u_b_V, load_Nm;
    pmstep_mode_t mode;
    double omega_ref_rad_s, speed_hat_rad_s, load_hat_Nm, i_a_hat_A, i_b_hat_A;
    double cos_hat, sin_hat;
};

struct SilRun {
    std::vector<SilSample> samples;
    sil_summary_t summary;
    int status; ///< sil_run()'s return value
};

/** Runs @p sc to the end and captures every sample. */
SilRun capture_sil(const sil_scenario_t &sc);

/** Sample times k T_s of the SIL for @p sc (T_s as the firmware holds it, in float). */
std::vector<double> sil_sample_times(const sil_scenario_t &sc);

/** The SIL's period index nearest @p t_s (as the runner and the core count periods). */
long sil_period_index(const sil_scenario_t &sc, double t_s);

} // namespace pmstep_oracle

#endif // PMSTEP_SIL_CAPTURE_HPP
