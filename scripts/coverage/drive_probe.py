#!/usr/bin/env python3
"""Coverage of `[drive_probe]`'s drive-gain ratio, and of the scale factors
predicted with it, on random devices (`gyrocal field`, in process).

    scripts/coverage/drive_probe.py SEED DEVICES OUT_DIR    (JOBS=2 by default)

The devices are common.py's (`Draw.device`, as turning.py's); their drives
part by 200 to 1000 ppm/K each way over two steps, 25 and 35 deg C, and
after each cycle the device turns at a probe rate log-uniform over 20..300
deg/s either way. Prints a line per step (the probe's rate, the measured
g2/g1 against the truth in its sigmas, both self-calibration errors in
theirs), then a summary line for the ratios and one for the scale factors.
$GYROCAL runs another revision's binary side by side.
"""
import json
import os
import sys

from common import Draw, runs, summary, write


def devices(seed, n, out):
    draw = Draw(seed)
    for i in range(n):
        text = draw.device()
        probe = draw.rng.choice([-1, 1]) * draw.log_uniform(20, 300)
        ppm = draw.rng.uniform(200, 1000)
        text += (
            "\n[drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n"
            f"drive_gain_ppm_per_k = [{ppm:.1f}, {-ppm:.1f}]\n\n[drive_probe]\nrate_dps = {probe:.3f}\n"
        )
        yield i, write(out, i, text), probe


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: drive_probe.py SEED DEVICES OUT_DIR")
    seed, n, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    os.makedirs(out, exist_ok=True)
    ratios, scale_factors = [], []
    jobs = list(devices(seed, n, out))
    for (i, path, probe), rc, so, se in runs(jobs, lambda j: ["field", "--json", "--config", j[1]]):
        try:
            d = json.loads(so)
        except json.JSONDecodeError:
            print(f"{i:3d} probe {probe:+8.2f} exit {rc}: {se.strip().splitlines()[-1:]}")
            continue
        for f in d.get("failed", []):
            print(f"{i:3d} probe {probe:+8.2f} failed at {f['temperature_c']} deg C: {f['error']}")
        for s in d.get("steps", []):
            idf = s["identified"]
            r, sd = idf["drive_gain_ratio"], idf["drive_gain_ratio_uncertainty"]
            t = (r - s["drive_gain_ratio_true"]) / sd
            sf = [s["selfcal_error"][k] / s["selfcal_error_uncertainty"][k] for k in range(2)]
            ratios.append(t)
            scale_factors += sf
            print(f"{i:3d} {s['temperature_c']:4.0f} deg C probe {probe:+8.2f} g2/g1 {r:.6f} "
                  f"+- {sd:.1e} (truth {s['drive_gain_ratio_true']:.6f}) {t:+7.2f} sigma, "
                  f"self-cal {sf[0]:+6.2f} {sf[1]:+6.2f} sigma", flush=True)
    summary("g2/g1", ratios)
    summary("self-calibrated scale factors", scale_factors)


if __name__ == "__main__":
    main()
