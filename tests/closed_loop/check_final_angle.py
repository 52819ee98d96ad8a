#!/usr/bin/env python3
"""Checks a pmstep-sil summary.json: the run ended in RUN and the angle estimate's error at its
end is within a bound (electrical rad). Prints the measured value; exits 1 on a miss."""
import argparse
import json
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("summary", help="pmstep-sil summary.json")
    parser.add_argument("--max-final-angle-error", type=float, required=True, metavar="RAD",
                        help="bound on |angle error| at the run's end (electrical rad)")
    args = parser.parse_args()
    with open(args.summary, encoding="utf-8") as f:
        summary = json.load(f)
    mode = summary["final_mode"]
    error = summary["robustness"]["final_angle_error_rad"]
    print(f"final mode {mode}, final angle error {error:.4f} rad (bound {args.max_final_angle_error:g})")
    if mode != "RUN":
        print("check_final_angle: the run did not end in RUN", file=sys.stderr)
        return 1
    if not abs(error) < args.max_final_angle_error:
        print("check_final_angle: final angle error over the bound", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
