"""What the coverage scripts (turning.py, drive_probe.py) share: the random
devices they draw (one generator per seed, each device's draws in a fixed
order, so a script's extra draws after them leave the devices as they
were), the gyrocal they run, their parallel runs and their summary line.
"""
import concurrent.futures as cf
import json
import math
import os
import random
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GYROCAL = os.environ.get("GYROCAL", os.path.join(ROOT, "target", "release", "gyrocal"))


class Draw:
    """Devices from `seed`, drawn one by one (`device`)."""

    def __init__(self, seed):
        self.rng = random.Random(seed)

    def log_uniform(self, a, b):
        return math.exp(self.rng.uniform(math.log(a), math.log(b)))

    def device(self):
        """One device's [gyro], [drive] and [experiment] as TOML text: f1
        log-uniform over 10..150 kHz, the split 0.5 to 4% of f1 either side,
        Q1 and Q2 log-uniform over 800..10000, lambda 0.6..0.9, 20..60 clocks
        per carrier, half of them a quadrature coupling (normal, sd 30
        deg/s), 30% a damping coupling (sd 2 deg/s)."""
        rng, logu = self.rng, self.log_uniform
        f1 = logu(10e3, 150e3)
        split = f1 * rng.uniform(0.005, 0.04) * rng.choice([-1, 1])
        q1, q2 = logu(800, 10000), logu(800, 10000)
        lam = rng.uniform(0.6, 0.9)
        clock = f1 * rng.uniform(20, 60)
        quad = rng.gauss(0, 30) if rng.random() < 0.5 else 0.0
        damp = rng.gauss(0, 2) if rng.random() < 0.3 else 0.0
        return (
            f"[gyro]\nf1_hz = {f1:.3f}\nf2_hz = {f1 + split:.3f}\nq1 = {q1:.1f}\n"
            f"q2 = {q2:.1f}\nangular_gain = {lam:.4f}\nquadrature_dps = {quad:.3f}\n"
            f"damping_coupling_dps = {damp:.3f}\n\n[drive]\ncarrier_hz = {f1:.3f}\n"
            f"clock_hz = {clock:.1f}\n\n[experiment]\nreadout_rates_dps = [50, 150, 300]\n"
            "cal_freqs_hz = [3, 5, 8]\n"
        )


def write(out, i, text):
    """Device i's file in `out`: its path."""
    path = os.path.join(out, f"dev{i}.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def runs(jobs, args):
    """Each job's (job, exit status, stdout, stderr) in order, gyrocal run
    with `args(job)` (JOBS at a time, 2 by default)."""
    def one(job):
        p = subprocess.run([GYROCAL] + args(job), capture_output=True, text=True)
        return job, p.returncode, p.stdout, p.stderr

    with cf.ThreadPoolExecutor(int(os.environ.get("JOBS", "2"))) as ex:
        yield from ex.map(one, jobs)


def calibrations(jobs, args, label):
    """Each job's (job, report) from `gyrocal calibrate --json` runs
    (`runs`) whose report has a truth, in order; a run that printed no
    report or failed gets one line instead, `label(job)` first."""
    for job, rc, so, se in runs(jobs, args):
        try:
            d = json.loads(so)
        except json.JSONDecodeError:
            print(f"{label(job)} exit {rc}: {se.strip().splitlines()[-1:]}")
            continue
        if d.get("failed") or not d.get("truth"):
            print(f"{label(job)} failed: {(d.get('failed') or {}).get('error')}")
            continue
        yield job, d


def summary(name, ts):
    """`name`: the share of the t within 2, how many beyond 3, the largest
    |t| and the RMS."""
    a = [abs(t) for t in ts]
    if a:
        within = sum(x <= 2 for x in a) / len(a) * 100
        rms = math.sqrt(sum(x * x for x in a) / len(a))
        print(f"{name}: {len(a)} figures, {within:.1f}% within 2 sigma, "
              f"{sum(x > 3 for x in a)} beyond 3, largest {max(a):.2f}, RMS {rms:.2f}")
