#!/usr/bin/python3
"""NumPy references of the batch identification, same data shapes as the C++ benchmarks of the
same names; prints one JSON line per benchmark.
- BM_FreeDecayBatchLinear1e6Samples: linear model (8 parameters), 10^6 slow samples: D(q) of (2.5)
  (section 3's D_gamma with docs/paper.md item 2 applied), Simpson integral over [t_{i-1}, t_{i+1}],
  y_i = 2 (q_{i+1} - q_{i-1}), least squares by numpy.linalg.lstsq (no covariance: the C++
  figure includes the honest covariance, so this ratio is conservative).
- BM_ForcedBatch14Params1e6Points: the forced model linear+controls+xi+kappa (14 parameters,
  mu = 0), 10^6 sweep points: y_j = rate_j (p1, -q1, p2, -q2), rate = (omega0^2 - omega^2)/omega0,
  least squares by QR and the per-point sandwich covariance (scores D_j' r_j), as the C++ does."""
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


def complex_column(scale, a_part, b_part):
    """(Re, Im) of scale * A and scale * B as the 4 rows of one column."""
    ca, cb = scale * a_part, scale * b_part
    return np.stack([ca.real, ca.imag, cb.real, cb.imag], axis=1)


def forced_regressor(q):
    """D(q) of linear + controls (mu = 0: the identity) + xi + kappa, shape (n, 4, 14)."""
    n = q.shape[0]
    d = np.zeros((n, 4, 14))
    d[:, :, :8] = regressor(q)
    d[:, :, 8:12] = np.eye(4)
    a = q[:, 0] + 1j * q[:, 1]
    b = q[:, 2] + 1j * q[:, 3]
    n_sq = np.abs(a) ** 2 + np.abs(b) ** 2
    s = a * a + b * b
    d[:, :, 12] = complex_column(0.25j, 2 * n_sq * a + s * np.conj(a), 2 * n_sq * b + s * np.conj(b))
    c0 = 2 * n_sq * n_sq + np.abs(s) ** 2
    c1 = 2 * n_sq * s
    d[:, :, 13] = complex_column(0.125j, c0 * a + c1 * np.conj(a), c0 * b + c1 * np.conj(b))
    return d


def identify_forced(omega, omega0, q):
    d = forced_regressor(q)
    rate = (omega0 ** 2 - omega ** 2) / omega0
    y = rate[:, None] * np.stack([q[:, 1], -q[:, 0], q[:, 3], -q[:, 2]], axis=1)
    a = d.reshape(-1, 14)
    qm, r = np.linalg.qr(a)
    z = np.linalg.solve(r, qm.T @ y.reshape(-1))
    r_inv = np.linalg.inv(r)  # triangular factor only: C = R^-1 R^-T
    c = r_inv @ r_inv.T
    res = y - np.einsum("nij,j->ni", d, z)
    scores = np.einsum("nij,ni->nj", d, res)
    g, dof = q.shape[0], a.shape[0] - 14
    cov = g / (g - 1.0) * (a.shape[0] - 1) / dof * c @ (scores.T @ scores) @ c
    return z, cov


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

    omega = 85732.0
    omega0 = omega - 80.0 + 160.0 * np.arange(n) / 1e6
    q = rng.uniform(-1.0, 1.0, (n, 4))
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        identify_forced(omega, omega0, q)
        best = min(best, time.perf_counter() - start)
    print(json.dumps({"name": "BM_ForcedBatch14Params1e6Points", "seconds": best,
                      "items_per_second": n / best}))


if __name__ == "__main__":
    main()
