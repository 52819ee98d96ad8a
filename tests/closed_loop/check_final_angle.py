#!/usr/bin/env python3
"""Checks a pmstep-sil summary.json: the run ended in RUN and the angle estimate's error at its
end is below --max-final-angle-error, or (a run that shows a drift) at least
--min-final-angle-error (electrical rad); optionally its largest error after settling below
--max-angle-error, and its largest speed error after settling below --max-speed-error. Prints
the measured values; exits 1 on a miss. With several summaries (runs of one scenario with other
seeds), each must end in RUN, and with --median the bounds hold for the median of each figure
over them, else for every run."""

import argparse
import json
import statistics
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("summary", nargs="+", help="pmstep-sil summary.json, one per run")
    parser.add_argument(
        "--median", action="store_true", help="the bounds hold for the median over the runs (else for each)"
    )
    bound = parser.add_mutually_exclusive_group(required=True)
    bound.add_argument(
        "--max-final-angle-error",
        type=float,
        metavar="RAD",
        help="|angle error| at the run's end must be below this (electrical rad)",
    )
    bound.add_argument(
        "--min-final-angle-error",
        type=float,
        metavar="RAD",
        help="|angle error| at the run's end must be at least this (electrical rad)",
    )
    parser.add_argument(
        "--max-angle-error",
        type=float,
        metavar="RAD",
        help="the largest |angle error| after settling must be below this (electrical rad)",
    )
    parser.add_argument(
        "--max-speed-error",
        type=float,
        metavar="RAD_S",
        help="the largest |w - w*| after settling must be below this (rad/s)",
    )
    args = parser.parse_args()
    errors, largests, largest_speeds = [], [], []
    for path in args.summary:
        with open(path, encoding="utf-8") as f:
            summary = json.load(f)
        mode = summary["final_mode"]
        errors.append(abs(summary["robustness"]["final_angle_error_rad"]))
        largests.append(summary["robustness"]["max_angle_error_rad"])
        largest_speeds.append(summary["robustness"]["max_speed_error_rad_s"])
        print(
            f"final mode {mode}, final angle error {errors[-1]:.4f} rad, largest after settling "
            f"{largests[-1]:.4f} rad at {summary['robustness']['max_angle_error_time_s']:.4f} s, largest speed "
            f"error {largest_speeds[-1]:.3f} rad/s"
        )
        if mode != "RUN":
            print(f"check_final_angle: {path}: the run did not end in RUN", file=sys.stderr)
            return 1
    if args.median:
        errors, largests, largest_speeds = ([statistics.median(x)] for x in (errors, largests, largest_speeds))
        print(
            f"medians over {len(args.summary)} runs: final angle error {errors[0]:.4f} rad, largest after "
            f"settling {largests[0]:.4f} rad, largest speed error {largest_speeds[0]:.3f} rad/s"
        )
    error, largest, largest_speed = max(errors), max(largests), max(largest_speeds)
    if args.max_final_angle_error is not None and not error < args.max_final_angle_error:
        print(f"check_final_angle: not below {args.max_final_angle_error:g} rad", file=sys.stderr)
        return 1
    if args.min_final_angle_error is not None and not min(errors) >= args.min_final_angle_error:
        print(f"check_final_angle: not at least {args.min_final_angle_error:g} rad", file=sys.stderr)
        return 1
    if args.max_angle_error is not None and not largest < args.max_angle_error:
        print(
            f"check_final_angle: largest error after settling not below {args.max_angle_error:g} rad", file=sys.stderr
        )
        return 1
    if args.max_speed_error is not None and not largest_speed < args.max_speed_error:
        print(
            f"check_final_angle: largest speed error after settling not below {args.max_speed_error:g} rad/s",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
