"""Effect-size calibration for a term added after the pilot (presets.EFFECTS): the ratio
SE(term) / SE(xi) of a Fisher-information (Gauss-Newton) fit of the averaged model to a preset's
clean record, with the linear terms, xi, the term and (free decay) the initial state free. The
term's size is then xi's size times that ratio, i.e. the same number of standard errors.

Usage: /usr/bin/python3 -m independent_model.calibrate [term]   (from scripts/; default xi_k)
"""
import sys

import numpy as np

from . import averaged, presets

LINEAR = ["gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c", "h_s"]
STATE = ["q1", "p1", "q2", "p2"]


def _trajectory(kind, p, t_or_w0):
    if kind == "sweep":
        return lambda z: averaged.stationary_sweep(z, p["omega"], t_or_w0)[0].ravel()

    def run(z):
        q0 = [z.get(k, p["q0"][i]) for i, k in enumerate(STATE)]
        zz = {k: v for k, v in z.items() if k not in STATE}
        return averaged.free_decay(zz, p["omega"], q0, t_or_w0).ravel()
    return run


def se_ratio(kind, p, term):
    z = dict(p["z"], xi=0.0, **{term: 0.0})
    if kind == "sweep":
        grid = p["omega"] + np.linspace(p["lam"][0], p["lam"][1], p["points"])
        names = LINEAR + ["u1", "u2", "u3", "u4", "xi", term]
    else:  # raw presets: the averaged model on ~1000 slow samples (the ratio, not the SE, is used)
        step = p.get("step", p["duration"] / 1000.0)
        grid = np.arange(int(round(p["duration"] / step)) + 1) * step
        names = LINEAR + ["xi", term] + STATE
        z.update(zip(STATE, p["q0"]))
    traj = _trajectory(kind, p, grid)
    cols = []
    for k in names:
        h = 1e-6 if k in STATE else 1e-6 * max(1.0, abs(z[k]) if k in z else 0.0, p["z"]["gamma"])
        zp, zm = dict(z), dict(z)
        zp[k], zm[k] = z.get(k, 0.0) + h, z.get(k, 0.0) - h
        cols.append((traj(zp) - traj(zm)) / (2.0 * h))
    r = np.linalg.qr(np.column_stack(cols), mode="r")  # covariance ~ R^-1 R^-T (QR, no normal eq.)
    se = np.sqrt(np.sum(np.linalg.solve(r, np.eye(len(names))) ** 2, axis=1))
    return se[names.index(term)] / se[names.index("xi")]


def main(term="xi_k"):
    for kind, table in (("fd", presets.FREE_DECAY), ("raw", presets.RAW),
                        ("sweep", presets.SWEEP)):
        for name, p in table.items():
            ratio = se_ratio(kind, p, term)
            print("%s: SE(%s)/SE(xi) = %.3g -> %s = %.3g (xi %g)" % (
                name, term, ratio, term, ratio * presets.EFFECTS[name]["xi"],
                presets.EFFECTS[name]["xi"]))


if __name__ == "__main__":
    main(*sys.argv[1:])
