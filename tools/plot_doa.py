#!/usr/bin/env python3
"""Plots the empirical domain of attraction measured by pmstep-gain-check --doa.

Usage: tools/plot_doa.py RUNS.csv REPORT.json OUT.png

RUNS.csv is --doa-csv (one line per SIL run), REPORT.json is --out. The figure shows,
for every direction of the estimation errors (i~_a A, i~_b A, e_w rad/s, T~_L Nm) set at
the start of controller (6), the radii that converged and the first that failed, and the
fraction of directions that converge at each radius, beside the radius of Theorem 3.
"""

import csv
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)


def main(argv):
    if len(argv) != 4:
        sys.stderr.write(__doc__)
        return 2
    runs_path, report_path, out_path = argv[1:]
    with open(runs_path, newline="") as f:
        runs = list(csv.DictReader(f))
    with open(report_path) as f:
        report = json.load(f)
    doa = report["empirical_domain_of_attraction"]
    theory = report["theorems"]
    directions = doa["directions"]
    rho_ceiling = theory["domain_of_attraction"]["rho_ceiling"]
    rho = theory["domain_of_attraction"]["rho"]
    r_all = doa["radius_all_converged"]
    met = theory["condition_7"]["met"]

    # Rows sorted by the last converged radius (the ray's boundary).
    def boundary(d):
        return d["last_converged_radius"] or 0.0

    order = sorted(range(len(directions)), key=lambda i: boundary(directions[i]))
    row_of = {d: row for row, d in enumerate(order)}

    fig, (ax_rays, ax_frac) = plt.subplots(1, 2, figsize=(12, 6.5), gridspec_kw={"width_ratios": [1.35, 1]})
    ok_x, ok_y, bad_x, bad_y = [], [], [], []
    for r in runs:
        d = int(r["direction"])
        (ok_x if r["converged"] == "1" else bad_x).append(float(r["radius"]))
        (ok_y if r["converged"] == "1" else bad_y).append(row_of[d])
    ax_rays.scatter(ok_x, ok_y, s=9, c="tab:green", marker="o", label="converged", zorder=3)
    ax_rays.scatter(bad_x, bad_y, s=22, c="tab:red", marker="x", label="not converged", zorder=3)
    ax_rays.set_xscale("log")
    ax_rays.set_yticks(range(len(order)))
    ax_rays.set_yticklabels([directions[i]["label"] for i in order], fontsize=6)
    ax_rays.set_xlabel("radius  ||(i~_a, i~_b, e_w, T~_L)||  at the start of (6)")
    ax_rays.set_ylabel("direction (sorted by its boundary)")
    ax_rays.set_title("SIL runs along each direction")

    # Fraction of directions converging at each radius (each ray converges below its boundary).
    bounds = sorted(boundary(d) for d in directions)
    lo = min(float(r["radius"]) for r in runs)
    hi = max(float(r["radius"]) for r in runs)
    grid = [lo * (hi / lo) ** (k / 400.0) for k in range(401)]
    frac = [sum(1 for b in bounds if b >= x) / len(bounds) for x in grid]
    ax_frac.plot(grid, frac, color="tab:blue", drawstyle="steps-post")
    ax_frac.set_xscale("log")
    ax_frac.set_ylim(-0.02, 1.05)
    ax_frac.set_xlabel("radius")
    ax_frac.set_ylabel("fraction of directions converging")
    ax_frac.set_title("Convergence against radius")

    for ax in (ax_rays, ax_frac):
        ax.axvline(
            rho_ceiling, color="tab:purple", linestyle="--", label=f"Theorem 3 rho at best (any p_e): {rho_ceiling:.3g}"
        )
        if met and rho is not None:
            ax.axvline(rho, color="tab:purple", linestyle="-", label=f"Theorem 3 radius rho: {rho:.3g}")
        ax.axvline(r_all, color="black", linestyle="-", label=f"100% convergence up to {r_all:.4g}")
        ax.grid(True, which="major", alpha=0.3)
    for ax in (ax_rays, ax_frac):
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, fontsize=7)
    verdict = "(7) met" if met else "(7) NOT met: no radius guaranteed"
    opts = doa["options"]
    fig.suptitle(
        f"Empirical domain of attraction, scenario '{report['scenario']}' — {verdict}\n"
        f"{len(directions)} directions, {int(doa['runs'])} SIL runs; converged = no fault, "
        f"|w - w*|, |w-hat - w| < {opts['speed_tol_rad_s']:g} rad/s on the last {opts['final_window_s']:g} s, "
        f"|T_L-hat - T_L| < {opts['load_tol_Nm']:g} Nm",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(out_path, dpi=130)
    print(
        f"plot_doa: wrote {out_path} (100% convergence up to {r_all:.4g}; theory best case {rho_ceiling:.3g}, "
        f"ratio {r_all / rho_ceiling if rho_ceiling else math.nan:.3g})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
