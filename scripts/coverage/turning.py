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
import concurrent.futures as cf
import json
import math
import os
import random
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GYROCAL = os.environ.get("GYROCAL", os.path.join(ROOT, "target", "release", "gyrocal"))


def devices(seed, n, out):
    rng = random.Random(seed)

    def logu(a, b):
        return math.exp(rng.uniform(math.log(a), math.log(b)))

    for i in range(n):
        f1 = logu(10e3, 150e3)
        split = f1 * rng.uniform(0.005, 0.04) * rng.choice([-1, 1])
        q1, q2 = logu(800, 10000), logu(800, 10000)
        lam = rng.uniform(0.6, 0.9)
        clock = f1 * rng.uniform(20, 60)
        quad = rng.gauss(0, 30) if rng.random() < 0.5 else 0.0
        damp = rng.gauss(0, 2) if rng.random() < 0.3 else 0.0
        rate = 0.0 if rng.random() < 0.2 else rng.choice([-1, 1]) * logu(0.01, 300)
        path = os.path.join(out, f"dev{i}.toml")
        with open(path, "w") as f:
            f.write(
                f"[gyro]\nf1_hz = {f1:.3f}\nf2_hz = {f1 + split:.3f}\nq1 = {q1:.1f}\n"
                f"q2 = {q2:.1f}\nangular_gain = {lam:.4f}\nquadrature_dps = {quad:.3f}\n"
                f"damping_coupling_dps = {damp:.3f}\n\n[drive]\ncarrier_hz = {f1:.3f}\n"
                f"clock_hz = {clock:.1f}\n\n[experiment]\nreadout_rates_dps = [50, 150, 300]\n"
                "cal_freqs_hz = [3, 5, 8]\n"
            )
        yield i, path, rate


def run(job):
    i, path, rate = job
    args = [GYROCAL, "calibrate", "--config", path, "--rate", repr(rate), "--json"]
    p = subprocess.run(args, capture_output=True, text=True)
    return i, rate, p.returncode, p.stdout, p.stderr


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: turning.py SEED DEVICES OUT_DIR")
    seed, n, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    os.makedirs(out, exist_ok=True)
    ts = []
    with cf.ThreadPoolExecutor(int(os.environ.get("JOBS", "2"))) as ex:
        for i, rate, rc, so, se in ex.map(run, list(devices(seed, n, out))):
            try:
                d = json.loads(so)
            except json.JSONDecodeError:
                print(f"{i:3d} rate {rate:+9.4f} exit {rc}: {se.strip().splitlines()[-1:]}")
                continue
            if d.get("failed") or not d.get("truth"):
                print(f"{i:3d} rate {rate:+9.4f} failed: {(d.get('failed') or {}).get('error')}")
                continue
            t = d["truth"]
            tv = [t["selfcal_error"][k] / t["selfcal_error_uncertainty"][k] for k in range(2)]
            ts += tv
            read = d["identified"]["cycle_rate_dps"]
            sd = d["identified"]["cycle_rate_dps_uncertainty"]
            said = any(w.startswith("warning: the device turned") for w in d["warnings"])
            print(f"{i:3d} rate {rate:+9.4f} read {read:+9.4f} +- {sd:.4f} said {int(said)} "
                  f"errors {tv[0]:+6.2f} {tv[1]:+6.2f} sigma")
    a = [abs(t) for t in ts]
    if a:
        within = sum(x <= 2 for x in a) / len(a) * 100
        rms = math.sqrt(sum(x * x for x in a) / len(a))
        print(f"{len(a)} figures: {within:.1f}% within 2 sigma, {sum(x > 3 for x in a)} beyond 3, "
              f"largest {max(a):.2f}, RMS {rms:.2f}")


if __name__ == "__main__":
    main()
