// pmstep-gain-check: what Theorems 2 and 3 guarantee for a motor + gains configuration
// (conditions (4), (7), P, q, rho), and the measured domain of attraction of the firmware.
#include <cjson/cJSON.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "gain_check.hpp"
#include "pmstep/pmstep_text.h"

namespace {

const char *const kUsage =
    "usage: pmstep-gain-check [options]\n"
    "  --scenario FILE|paper   scenario INI (the SIL's format), applied on top of the paper's\n"
    "  --set section.key=value override one key (repeatable)\n"
    "  --json                  print JSON instead of text\n"
    "  --out FILE              also write the JSON report to FILE\n"
    "  --doa                   measure the empirical domain of attraction in the SIL\n"
    "  --doa-directions N      random directions besides the 8 axes (default 40)\n"
    "  --doa-seed S            seed of the random directions (default 1)\n"
    "  --doa-radius-min R      first radius (default 1e-3)\n"
    "  --doa-radius-max R      last radius (default 1e5)\n"
    "  --doa-factor F          ratio between radii (default 2)\n"
    "  --doa-bisections N      refinements at the boundary (default 4)\n"
    "  --doa-csv FILE          write every run (for tools/plot_doa.py)\n"
    "  --quiet                 no progress lines\n"
    "Exit status: 0 report written (whatever the verdict), 2 bad input.\n";

bool parse_number(const char *text, double &value)
{
    char *end = nullptr;
    value = std::strtod(text, &end);
    return end != text && *end == '\0' && std::isfinite(value);
}

bool close(double a, double b)
{
    return std::fabs(a - b) <= 1e-6 * std::max(std::fabs(a), std::fabs(b));
}

/** The theorems assume the controller's model is the plant. */
bool plant_differs(const sil_scenario_t &sc)
{
    const pmstep_motor_config_t &c = sc.controller.motor;
    const plant_params_t &m = sc.motor;
    return !close(m.resistance_Ohm, static_cast<double>(c.resistance_Ohm))
           || !close(m.inductance_H, static_cast<double>(c.inductance_H))
           || !close(m.inertia_kgm2, static_cast<double>(c.inertia_kgm2))
           || !close(m.friction_Nms_rad, static_cast<double>(c.friction_Nms_rad))
           || !close(m.torque_constant_Nm_A, static_cast<double>(c.torque_constant_Nm_A))
           || m.pole_pairs != c.pole_pairs;
}

int fail(const std::string &message)
{
    std::fprintf(stderr, "pmstep-gain-check: %s\n", message.c_str());
    return 2;
}

} // namespace

int main(int argc, char **argv)
{
    sil_scenario_t sc;
    sil_scenario_paper(&sc);
    char err[SIL_ERROR_MAX];
    bool json = false, doa = false, quiet = false;
    std::string out_path, csv_path;
    pmstep_gain::DoaOptions opt;

    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> const char * { return i + 1 < argc ? argv[++i] : nullptr; };
        auto number = [&](double &target) {
            const char *v = value();
            return v != nullptr && parse_number(v, target);
        };
        if (arg == "--help" || arg == "-h") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (arg == "--scenario") {
            const char *v = value();
            if (v == nullptr) {
                return fail("--scenario needs a file");
            }
            if (std::strcmp(v, "paper") != 0 && sil_scenario_load(&sc, v, err, sizeof err) != 0) {
                return fail(err);
            }
        } else if (arg == "--set") {
            const char *v = value();
            if (v == nullptr) {
                return fail("--set needs section.key=value");
            }
            if (sil_scenario_set_assignment(&sc, v, err, sizeof err) != 0) {
                return fail(std::string("--set: ") + err);
            }
        } else if (arg == "--json") {
            json = true;
        } else if (arg == "--out") {
            const char *v = value();
            if (v == nullptr) {
                return fail("--out needs a file");
            }
            out_path = v;
        } else if (arg == "--doa") {
            doa = true;
        } else if (arg == "--doa-csv") {
            const char *v = value();
            if (v == nullptr) {
                return fail("--doa-csv needs a file");
            }
            csv_path = v;
            doa = true;
        } else if (arg == "--quiet") {
            quiet = true;
        } else if (arg == "--doa-directions" || arg == "--doa-seed" || arg == "--doa-bisections") {
            double v = 0.0;
            if (!number(v) || v < 0.0 || v != std::floor(v) || v > 1e6) {
                return fail(arg + " needs a whole number >= 0");
            }
            if (arg == "--doa-directions") {
                opt.random_directions = static_cast<int>(v);
            } else if (arg == "--doa-seed") {
                opt.seed = static_cast<std::uint32_t>(v);
            } else {
                opt.bisection_steps = static_cast<int>(v);
            }
        } else if (arg == "--doa-radius-min" || arg == "--doa-radius-max" || arg == "--doa-factor") {
            double v = 0.0;
            if (!number(v) || !(v > 0.0)) {
                return fail(arg + " needs a number > 0");
            }
            if (arg == "--doa-radius-min") {
                opt.radius_min = v;
            } else if (arg == "--doa-radius-max") {
                opt.radius_max = v;
            } else {
                opt.radius_factor = v;
            }
        } else {
            return fail("unknown argument '" + arg + "'\n" + kUsage);
        }
    }
    if (sil_scenario_check(&sc, err, sizeof err) != 0) {
        return fail(err);
    }
    {
        const pmstep_status_t st = pmstep_validate_config(&sc.controller);
        if (st != PMSTEP_OK) {
            return fail(std::string("the firmware rejects the configuration: ") + pmstep_status_str(st));
        }
    }
    if (doa && sc.controller.known_load_mode) {
        return fail("--doa studies controller (6); controller.known_load_mode = true uses (13), which has no T_L-hat");
    }
    if (doa && !(opt.radius_factor > 1.0 && opt.radius_max >= opt.radius_min)) {
        return fail("--doa needs --doa-factor > 1 and --doa-radius-max >= --doa-radius-min");
    }
    if (doa && !(sc.duration_s - opt.final_window_s > static_cast<double>(sc.controller.alignment.c_align_time_s))) {
        return fail("--doa needs run.duration_s > t_c + 0.2 s (the final window)");
    }

    const bool differs = plant_differs(sc);
    const pmstep_gain::TheoremReport rep = pmstep_gain::check_theorems(pmstep_gain::inputs_from_config(sc.controller));
    pmstep_gain::DoaResult res;
    if (doa) {
        if (!quiet) {
            std::fprintf(stderr, "pmstep-gain-check: domain of attraction of scenario '%s' (%d directions)\n", sc.name,
                         8 + opt.random_directions);
        }
        res = pmstep_gain::doa_study(sc, opt, !quiet);
        if (!csv_path.empty() && !pmstep_gain::doa_write_csv(res, csv_path)) {
            return fail("cannot write " + csv_path);
        }
    }

    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scenario", sc.name);
    cJSON_AddItemToObject(root, "theorems", pmstep_gain::theorem_json(rep, differs));
    if (doa) {
        cJSON *d = pmstep_gain::doa_json(res);
        cJSON_AddItemToObject(root, "empirical_domain_of_attraction", d);
    }
    char *text = cJSON_Print(root);
    if (!out_path.empty()) {
        std::FILE *f = std::fopen(out_path.c_str(), "w");
        if (f == nullptr || std::fprintf(f, "%s\n", text) < 0 || std::fclose(f) != 0) {
            cJSON_free(text);
            cJSON_Delete(root);
            return fail("cannot write " + out_path);
        }
    }
    if (json) {
        std::printf("%s\n", text);
    } else {
        std::printf("pmstep-gain-check: scenario '%s'\n%s", sc.name, pmstep_gain::theorem_text(rep, differs).c_str());
        if (doa) {
            std::printf("%s", pmstep_gain::doa_text(res, rep).c_str());
        }
    }
    cJSON_free(text);
    cJSON_Delete(root);
    return 0;
}
