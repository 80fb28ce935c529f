#!/usr/bin/env python3
"""Coverage of the self-calibration on random devices that turn at a random
steady rate during the cycle (`gyrocal calibrate --rate`, in process).

    scripts/coverage/turning.py SEED DEVICES OUT_DIR    (JOBS=2 by default)

Each device is drawn from SEED: f1 log-uniform over 10..150 kHz, the split
0.5 to 4% of f1 either side, Q1 and Q2 log-uniform over 800..10000, lambda
0.6..0.9, 20..60 clocks per carrier, half of them a quadrature coupling
(normal, sd 30 deg/s), 30% a damping coupling (sd 2 deg/s); the rate is 0
for a fifth of them, else log-uniform over 0.01..300 deg/s either way.
The datasheet is the device. OUT_DIR gets each device's file. Prints a line
per device (the rate, the windows' reading, whether the run said the device
turned, both self-calibration errors in their sigmas), then the share of
figures within 2 sigma, how many lie beyond 3 and the RMS. Runs
target/release/gyrocal (`cargo build --release`), or the binary $GYROCAL
(another revision's, side by side).
"""
import os
import sys

from common import Draw, calibrations, summary, write


def devices(seed, n, out):
    draw = Draw(seed)
    for i in range(n):
        text = draw.device()
        rate = 0.0 if draw.rng.random() < 0.2 else draw.rng.choice([-1, 1]) * draw.log_uniform(0.01, 300)
        yield i, write(out, i, text), rate


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: turning.py SEED DEVICES OUT_DIR")
    seed, n, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    os.makedirs(out, exist_ok=True)
    ts = []
    jobs = list(devices(seed, n, out))
    calibrate = lambda j: ["calibrate", "--config", j[1], "--rate", repr(j[2]), "--json"]
    label = lambda j: f"{j[0]:3d} rate {j[2]:+9.4f}"
    for (i, path, rate), d in calibrations(jobs, calibrate, label):
        t = d["truth"]
        tv = [t["selfcal_error"][k] / t["selfcal_error_uncertainty"][k] for k in range(2)]
        ts += tv
        read = d["identified"]["cycle_rate_dps"]
        sd = d["identified"]["cycle_rate_dps_uncertainty"]
        said = any(w.startswith("warning: the device turned") for w in d["warnings"])
        print(f"{i:3d} rate {rate:+9.4f} read {read:+9.4f} +- {sd:.4f} said {int(said)} "
              f"errors {tv[0]:+6.2f} {tv[1]:+6.2f} sigma")
    summary("self-calibrated scale factors", ts)


if __name__ == "__main__":
    main()
