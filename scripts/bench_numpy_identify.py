#!/usr/bin/python3
"""NumPy reference of the batch free-decay identification (linear model, 8 parameters, 10^6
slow samples): D(q) of (2.5) (section 3's D_gamma with NOTES.md item 2 applied), Simpson integral
over [t_{i-1}, t_{i+1}], y_i = 2 (q_{i+1} - q_{i-1}), least squares by numpy.linalg.lstsq.
Same synthetic data as BM_FreeDecayBatchLinear1e6Samples. Prints one JSON line per benchmark."""
import json
import time

import numpy as np


def regressor(q):
    q1, p1, q2, p2 = q.T
    d = np.empty((q.shape[0], 4, 8))
    d[:, 0] = np.stack([-q1, q2, -q1, -q2, p1, p2, p1, p2], axis=1)
    d[:, 1] = np.stack([-p1, p2, -p1, -p2, -q1, -q2, -q1, -q2], axis=1)
    d[:, 2] = np.stack([-q2, -q1, q2, -q1, p2, -p1, -p2, p1], axis=1)
    d[:, 3] = np.stack([-p2, -p1, p2, -p1, -q2, q1, q2, -q1], axis=1)
    return d


def identify(t, q):
    d = regressor(q)
    h = t[1] - t[0]
    dbar = (h / 3.0) * (d[:-2] + 4.0 * d[1:-1] + d[2:])
    y = 2.0 * (q[2:] - q[:-2])
    z, _, rank, _ = np.linalg.lstsq(dbar.reshape(-1, 8), y.reshape(-1), rcond=None)
    return z, rank


def main():
    n = 1000000
    rng = np.random.default_rng(1)
    t = np.arange(n) * 1e-3
    a = np.exp(-0.05 * t)
    q = np.stack([a * np.cos(0.3 * t), a * np.sin(0.3 * t), 0.3 * a * np.cos(0.2 * t),
                  0.3 * a * np.sin(0.25 * t)], axis=1) + rng.normal(0.0, 1e-4, (n, 4))
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        identify(t, q)
        best = min(best, time.perf_counter() - start)
    print(json.dumps({"name": "BM_FreeDecayBatchLinear1e6Samples", "seconds": best,
                      "items_per_second": n / best}))


if __name__ == "__main__":
    main()
