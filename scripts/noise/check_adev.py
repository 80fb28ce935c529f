"""Check a `gyrocal datasheet --out DIR` against allantools.

    python check_adev.py DIR

Reads DIR/datasheet.json and DIR/rate.csv (time_s, rate1_dps, rate2_dps)
and, per output, prints one JSON line per tau of the datasheet:

    {"output": k, "tau_s": .., "m": .., "ours": .., "allantools": ..,
     "ci_ours": [lo, hi], "ci_allantools": [lo, hi]}

- "allantools": allantools.oadev of the rate series (data_type="freq",
  the rate as the frequency), at the datasheet's own taus, in deg/h;
- "ci_allantools": allantools.confidence_interval(dev, edf) with the
  datasheet's own edf (one sigma): the same chi-square quantiles from
  scipy, so the Rust side's statrs quantiles are checked;
- "edf_greenhall": allantools.edf_greenhall for each pure rate-noise type
  (alpha 0, -1, -2; d = 2, overlapping) at this m and N = n + 1, with the
  datasheet's mixture edf beside them ("edf_ours").

The Rust test (tests/datasheet_cli.rs) asserts the agreement; this script
only computes.
"""

import csv
import json
import sys

import allantools
import numpy as np


def main(folder):
    with open(f"{folder}/datasheet.json") as f:
        sheet = json.load(f)
    with open(f"{folder}/rate.csv") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time_s", "rate1_dps", "rate2_dps"], rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    fs = sheet["series"]["sample_rate_hz"]
    n = len(data)
    for k, out in enumerate(sheet["outputs"]):
        adev = out["adev"]
        rate = data[:, k + 1]
        taus = np.array(adev["tau_s"])
        t2, dev, _, ns = allantools.oadev(rate, rate=fs, data_type="freq", taus=taus)
        assert len(t2) == len(taus), (t2, taus)
        for i, tau in enumerate(taus):
            m = adev["cluster"][i]
            ours = adev["sigma_deg_per_h"][i]
            lo, hi = allantools.confidence_interval(ours, adev["edf"][i])
            greenhall = [
                allantools.edf_greenhall(alpha=a, d=2, m=m, N=n + 1, overlapping=True)
                for a in (0, -1, -2)
            ]
            print(json.dumps({
                "output": k + 1,
                "tau_s": float(tau),
                "m": int(m),
                "allantools_tau_s": float(t2[i]),
                "ours": ours,
                "allantools": float(dev[i]) * 3600.0,
                "ci_ours": [adev["ci_low"][i], adev["ci_high"][i]],
                "ci_allantools": [float(lo), float(hi)],
                "edf_ours": adev["edf"][i],
                "edf_greenhall": [float(g) for g in greenhall],
            }))


if __name__ == "__main__":
    main(sys.argv[1])
