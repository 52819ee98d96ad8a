#!/usr/bin/env python3
"""Draws the paper's Figs 1-3 (Tomei & Verrelli, Section III) from one pmstep-sil run.

Usage: tools/plot_run.py RUN_DIR [--out DIR]

Reads RUN_DIR/run.csv and RUN_DIR/summary.json (written by pmstep-sil) and writes
fig1_reference_and_load.png, fig2_alignment.png and fig3_tracking.png into DIR
(default RUN_DIR), printing each path; a position scenario's run (columns position_ref_rad,
position_hat_rad, position_rad) also gives fig4_position.png: the position and its errors. Exit status 2 if a file, a
key or a column is
missing or unreadable.
"""

import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, MultipleLocator  # noqa: E402

COLUMNS = (
    "t_s",
    "theta_rad",
    "omega_rad_s",
    "omega_ref_rad_s",
    "i_a_A",
    "i_b_A",
    "u_a_V",
    "u_b_V",
    "cos_hat",
    "sin_hat",
    "cos_ptheta",
    "sin_ptheta",
    "load_hat_Nm",
    "load_Nm",
    "mode",
)
POSITION_COLUMNS = ("position_ref_rad", "position_hat_rad", "position_rad")
KEYS = ("pole_pairs", "s_align_time_s", "c_align_time_s")
MODE_RUN, MODE_FAULT = 3, 4
WIDTH_IN, DPI = 8.0, 120


def fail(msg):
    sys.stderr.write(f"plot_run.py: {msg}\n")
    sys.exit(2)


def load(run_dir):
    csv_path, json_path = os.path.join(run_dir, "run.csv"), os.path.join(run_dir, "summary.json")
    for path in (csv_path, json_path):
        if not os.path.isfile(path):
            fail(f"missing file {path}")
    try:
        with open(json_path) as f:
            summary = json.load(f)
    except ValueError as e:
        fail(f"{json_path}: not valid JSON: {e}")
    absent = [k for k in KEYS if not isinstance(summary.get(k), (int, float))]
    if absent:
        fail(f"{json_path}: missing or non-numeric key(s): {', '.join(absent)}")
    with open(csv_path, newline="") as f:
        reader = csv.reader(f)
        header = [h.strip() for h in next(reader, [])]
        rows = [r for r in reader if r]
    absent = [c for c in COLUMNS if c not in header]
    if absent:
        fail(f"{csv_path}: missing column(s): {', '.join(absent)}")
    if not rows:
        fail(f"{csv_path}: no data rows")
    bad = next((i for i, r in enumerate(rows) if len(r) != len(header)), None)
    if bad is not None:
        fail(f"{csv_path}: data row {bad + 1} has {len(rows[bad])} fields, the header {len(header)}")
    try:
        table = np.array(rows, dtype=float)
    except ValueError as e:
        fail(f"{csv_path}: non-numeric value: {e}")
    present = COLUMNS + tuple(c for c in POSITION_COLUMNS if c in header)
    return {c: table[:, header.index(c)] for c in present}, summary


def mark(ax, t, label, color="0.35"):
    ax.axvline(t, color=color, ls=":", lw=1)
    ax.text(t, 1.01, label, transform=ax.get_xaxis_transform(), ha="center", va="bottom", color=color, fontsize=9)


def pi_ticks(ax, lo, hi):
    step = math.pi / 2 * max(1, math.ceil((hi - lo) / (math.pi / 2) / 8))
    ax.yaxis.set_major_locator(MultipleLocator(step))

    def fmt(y, _):
        n = round(y / (math.pi / 2))
        num, den = (n // 2, "") if n % 2 == 0 else (n, "/2")
        coef = {0: "0", 1: "π", -1: "−π"}.get(num, f"{num}π".replace("-", "−"))
        return coef if num == 0 else coef + den

    ax.yaxis.set_major_formatter(FuncFormatter(fmt))


def save(fig, out_dir, name):
    path = os.path.join(out_dir, name)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print(path)


def main():
    ap = argparse.ArgumentParser(description="Draws the paper's Figs 1-3 from a pmstep-sil run.")
    ap.add_argument("run_dir", metavar="RUN_DIR", help="folder with run.csv and summary.json")
    ap.add_argument("--out", metavar="DIR", help="where to write the PNGs (default RUN_DIR)")
    args = ap.parse_args()
    d, summary = load(args.run_dir)
    out_dir = args.out or args.run_dir
    os.makedirs(out_dir, exist_ok=True)
    p, ts, tc = summary["pole_pairs"], summary["s_align_time_s"], summary["c_align_time_s"]
    name = summary.get("scenario", os.path.basename(os.path.normpath(args.run_dir)))
    t = d["t_s"]
    run = (t >= tc) & (d["mode"] == MODE_RUN)  # estimates are meaningful only in RUN
    after = t >= tc
    before = t <= tc
    faulted = np.flatnonzero(d["mode"] == MODE_FAULT)
    t_fault = t[faulted[0]] if faulted.size else None
    if t_fault is not None:
        sys.stderr.write(f"plot_run.py: warning: run latched a fault at t = {t_fault:.4f} s\n")
    stepped = np.flatnonzero(np.abs(d["load_Nm"] - d["load_Nm"][0]) > 1e-9)
    t_load = t[stepped[0]] if stepped.size else None

    def finish(axes):
        for ax in axes:
            ax.grid(True, alpha=0.4)
            if t_fault is not None and ax.get_xlim()[0] <= t_fault <= ax.get_xlim()[1]:
                mark(ax, t_fault, "fault", color="tab:red")
        axes[-1].set_xlabel("time t (s)")

    # Fig. 1: speed reference and load torque over the whole run.
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(WIDTH_IN, 5.5))
    a1.plot(t, d["omega_ref_rad_s"], color="tab:blue")
    a1.set_ylabel("ω* (rad/s)")
    a1.set_title(f"Fig. 1 — Rotor speed reference and applied load torque ({name})", pad=16)
    a2.plot(t, d["load_Nm"], color="tab:red", label="$T_L$ applied")
    a2.plot(t[run], d["load_hat_Nm"][run], color="k", ls="--", lw=1, label="$\\hat{T}_L$ estimate (t ≥ $t_c$)")
    a2.set_ylabel("load torque (Nm)")
    a2.legend(loc="best", fontsize=9)
    finish((a1, a2))
    save(fig, out_dir, "fig1_reference_and_load.png")

    # Fig. 2: electrical angle p·θ and speed during the s- and c-alignment (t <= t_c).
    ptheta = p * np.unwrap(d["theta_rad"][before])
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(WIDTH_IN, 5.5))
    a1.plot(t[before], ptheta, color="tab:blue")
    pi_ticks(a1, ptheta.min(), ptheta.max())
    a1.set_ylabel("p·θ (rad)")
    a1.set_title(f"Fig. 2 — Electrical angle and rotor speed, alignment (p = {p:g})", pad=16)
    a2.plot(t[before], d["omega_rad_s"][before], color="tab:green")
    a2.set_ylabel("ω (rad/s)")
    for ax in (a1, a2):
        ax.set_xlim(t[before][0], tc)
        mark(ax, ts, "$t_s$")
        mark(ax, tc, "$t_c$")
    finish((a1, a2))
    save(fig, out_dir, "fig2_alignment.png")

    # Fig. 3: tracking error, currents, voltages and angle-estimate errors for t >= t_c.
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(WIDTH_IN, 9.5))
    if not after.any():
        sys.stderr.write("plot_run.py: warning: the run ends before t_c; Fig. 3 is empty\n")
        axes[0].text(
            0.5,
            0.5,
            f"no samples at t ≥ t_c (run ends at {t[-1]:.3f} s)",
            transform=axes[0].transAxes,
            ha="center",
            va="center",
            color="tab:red",
        )
    ta = t[after]
    axes[0].plot(ta, (d["omega_rad_s"] - d["omega_ref_rad_s"])[after], color="tab:blue")
    axes[0].set_ylabel("ω − ω* (rad/s)")
    axes[0].set_title("Fig. 3 — Speed tracking error, (a, b) currents and voltages, angle estimate (t ≥ $t_c$)", pad=16)
    axes[1].plot(ta, d["i_a_A"][after], label="$i_a$")
    axes[1].plot(ta, d["i_b_A"][after], label="$i_b$")
    axes[1].set_ylabel("current (A)")
    axes[2].plot(ta, d["u_a_V"][after], label="$u_a$")
    axes[2].plot(ta, d["u_b_V"][after], label="$u_b$")
    axes[2].set_ylabel("voltage (V)")
    axes[3].plot(t[run], (d["cos_hat"] - d["cos_ptheta"])[run], label="$\\hat{c}$ − cos pθ")
    axes[3].plot(t[run], (d["sin_hat"] - d["sin_ptheta"])[run], label="$\\hat{s}$ − sin pθ")
    axes[3].set_ylabel("angle estimate error")
    axes[3].ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useOffset=False)
    for ax in axes[1:]:
        ax.legend(loc="best", fontsize=9, ncol=2, framealpha=0.8)
    if ta.size:
        axes[0].set_xlim(ta[0], ta[-1])
    if t_load is not None and t_load >= tc:
        mark(axes[0], t_load, "$T_L$ step")
    finish(axes)
    save(fig, out_dir, "fig3_tracking.png")

    if all(c in d for c in POSITION_COLUMNS):
        # Fig. 4 (position scenario): theta*, theta-hat, theta, and the errors in electrical rad.
        fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(WIDTH_IN, 6.5))
        a1.plot(t[run], d["position_ref_rad"][run], color="tab:blue", label="θ* commanded")
        a1.plot(t[run], d["position_hat_rad"][run], color="k", ls="--", lw=1, label="$\\hat{θ}$ estimate")
        a1.plot(t[run], d["position_rad"][run], color="tab:orange", lw=1, label="θ true")
        a1.set_ylabel("position (rad, mechanical)")
        a1.set_title(f"Fig. 4 — Position control ({name}): position and position error", pad=16)
        a1.legend(loc="best", fontsize=9)
        a2.plot(t[run], p * (d["position_ref_rad"] - d["position_rad"])[run], color="tab:blue", label="p (θ* − θ)")
        a2.plot(
            t[run],
            p * (d["position_hat_rad"] - d["position_rad"])[run],
            color="tab:red",
            lw=1,
            label="p ($\\hat{θ}$ − θ)",
        )
        a2.set_ylabel("error (electrical rad)")
        a2.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3), useOffset=False)
        a2.legend(loc="best", fontsize=9)
        finish((a1, a2))
        save(fig, out_dir, "fig4_position.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
