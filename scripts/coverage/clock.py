#!/usr/bin/env python3
"""Coverage of the self-calibration on random devices whose board clock
runs off `clock_hz` within the tolerance the host is told (`gyrocal
calibrate`, in process).

    scripts/coverage/clock.py SEED DEVICES OUT_DIR    (JOBS=2 by default)

The devices are common.py's (`Draw.device`, as turning.py's); each gets
`[drive] clock_tolerance_ppm` log-uniform over 10..5000 ppm and a
`clock_error_ppm` uniform within it, either way. The budget's clock term
(`selfcal::budget::clock`) is the bound over sqrt(3), so an error at the
bound's edge reads sqrt(3) of it where the term dominates. Prints a line
per device (the tolerance, the error, both self-calibration errors in
their sigmas and the clock term's share of each sigma), then the summary
line. $GYROCAL runs another revision's binary side by side.
"""
import os
import sys

from common import Draw, calibrations, summary, write


def devices(seed, n, out):
    draw = Draw(seed)
    for i in range(n):
        text = draw.device()
        tolerance = draw.log_uniform(10, 5000)
        error = draw.rng.uniform(-tolerance, tolerance)
        clock = f"clock_tolerance_ppm = {tolerance:.3f}\nclock_error_ppm = {error:.3f}\n"
        text = text.replace("\n\n[experiment]", f"\n{clock}\n[experiment]", 1)
        yield i, write(out, i, text), tolerance, error


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: clock.py SEED DEVICES OUT_DIR")
    seed, n, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    os.makedirs(out, exist_ok=True)
    ts = []
    jobs = list(devices(seed, n, out))
    calibrate = lambda j: ["calibrate", "--config", j[1], "--json"]
    for (i, path, tol, err), d in calibrations(jobs, calibrate, lambda j: f"{j[0]:3d}"):
        t = d["truth"]
        tv = [t["selfcal_error"][k] / t["selfcal_error_uncertainty"][k] for k in range(2)]
        clock = d["sf_selfcal_uncertainty_sources"]["clock"]
        share = [clock[k] / t["selfcal_error_uncertainty"][k] for k in range(2)]
        ts += tv
        print(f"{i:3d} tolerance {tol:7.1f} ppm error {err:+8.1f} ppm errors {tv[0]:+6.2f} "
              f"{tv[1]:+6.2f} sigma, clock share {share[0]:.2f} {share[1]:.2f}", flush=True)
    summary("self-calibrated scale factors", ts)


if __name__ == "__main__":
    main()
