"""Known-answer checks of the generator against itself and closed forms (run before every
validation and by test/python/test_validate_independent.py). Each check returns (name, error,
tolerance); a check passes when error <= tolerance."""
import numpy as np

from . import averaged, full


def _paper_linear(z, q):
    """2 q' of (2.5), rows typed from the paper (section 2's D_gamma)."""
    q1, p1, q2, p2 = q
    g, nu, bc, bs, cm, n, hc, hs = (z[k] for k in ("gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c",
                                                    "h_s"))
    return np.array([
        -g * q1 - bc * q1 + nu * q2 - bs * q2 + cm * p1 + hc * p1 + n * p2 + hs * p2,
        -g * p1 - bc * p1 + nu * p2 - bs * p2 - cm * q1 - hc * q1 - n * q2 - hs * q2,
        -g * q2 + bc * q2 - nu * q1 - bs * q1 + cm * p2 - hc * p2 - n * p1 + hs * p1,
        -g * p2 + bc * p2 - nu * p1 - bs * p1 - cm * q2 + hc * q2 + n * q1 - hs * q1])


def _compact_nonlinear(xi, kappa, q):
    """2 q' of the cubic and quintic terms in the compact complex form of docs/paper.md item 1:
    2 Z' = (i xi/4)(2 N Z + S conj Z) + (i kappa/8)((2 N^2 + |S|^2) Z + 2 N S conj Z)."""
    a, b = q[0] + 1j * q[1], q[2] + 1j * q[3]
    nn = abs(a) ** 2 + abs(b) ** 2
    s = a * a + b * b
    out = []
    for x in (a, b):
        out.append(1j * xi / 4 * (2 * nn * x + s * np.conj(x))
                   + 1j * kappa / 8 * ((2 * nn * nn + abs(s) ** 2) * x + 2 * nn * s * np.conj(x)))
    return np.array([out[0].real, out[0].imag, out[1].real, out[1].imag])


def _orbit(q):
    """Orbit elements of (5.1): r, k from the ellipse q1,p1 / q2,p2 (r the major semi-axis, r k
    the determinant) and the pattern angle theta of the major axis."""
    m = np.array([[q[0], q[1]], [q[2], q[3]]])
    r = np.linalg.svd(m, compute_uv=False)[0]
    th = 0.5 * np.arctan2(2 * (q[0] * q[2] + q[1] * q[3]),
                          q[0] ** 2 + q[1] ** 2 - q[2] ** 2 - q[3] ** 2)
    return r, np.linalg.det(m) / r, th


def _orbit_rates(z, omega, q, h=1e-6):
    """r', k', theta' of the averaged model at q (central difference along q')."""
    dq = averaged.rhs(z, omega, 0.0, q)
    a, b = _orbit(q - h * dq), _orbit(q + h * dq)
    return [(y - x) / (2 * h) for x, y in zip(a, b)]


Z = dict(gamma=0.8, nu=0.05, b_c=0.07, b_s=-0.04, c_m=0.5, n=0.1, h_c=0.3, h_s=-0.2)


def checks(fast=True):
    rng = np.random.default_rng(7)
    res = []
    omega = 2 * np.pi * 500.0
    # (1) the averaged linear part equals (2.5), the cubic/quintic parts the compact forms
    err_lin = err_nl = 0.0
    for _ in range(5):
        q = rng.normal(size=4)
        err_lin = max(err_lin, np.max(np.abs(2 * averaged.rhs(Z, omega, 0.0, q) - _paper_linear(Z, q))))
        znl = {"xi": 0.7, "kappa": -0.4}
        err_nl = max(err_nl, np.max(np.abs(2 * averaged.rhs(znl, omega, 0.0, q)
                                           - _compact_nonlinear(0.7, -0.4, q))))
    res.append(("averaged linear part = (2.5) rows", err_lin, 1e-12))
    res.append(("averaged cubic+quintic = compact form (item 1)", err_nl, 1e-12))
    # (1b) the second cubic invariant xi_k: the same precession rate as xi at equal coefficient
    # (both enter theta' of (5.9) as coefficient r k / 8, docs/paper.md item 4), r and k unchanged,
    # and no effect at all on a standing wave (k = 0)
    err_prec = err_rk = 0.0
    for _ in range(5):
        q = rng.normal(size=4)
        rk_xi = _orbit_rates({"xi": 0.7}, omega, q)
        rk_k = _orbit_rates({"xi_k": 0.7}, omega, q)
        err_prec = max(err_prec, abs(rk_k[2] - rk_xi[2]) / abs(rk_xi[2]))
        err_rk = max(err_rk, abs(rk_k[0]), abs(rk_k[1]))
    res.append(("xi_k: precession rate = xi's at equal coefficient (relative)", err_prec, 1e-5))
    res.append(("xi_k: r' and k' vanish", err_rk, 1e-8))
    res.append(("xi_k: no force on a standing wave", np.max(np.abs(averaged.rhs(
        {"xi_k": 0.7}, omega, 0.0, np.array([0.6, 0.2, 0.3, 0.1])))), 1e-14))
    # (2) linear free decay with only gamma: q(t) = q0 exp(-gamma t / 2)
    t = np.linspace(0.0, 3.0, 31)
    q0 = np.array([0.3, 0.9, 0.2, -0.1])
    q = averaged.free_decay({"gamma": 0.8}, omega, q0, t)
    res.append(("free decay envelope = exp(-gamma t/2)",
                np.max(np.abs(q - np.outer(np.exp(-0.4 * t), q0))), 1e-8))
    # (3) stationary sweep, linear model: the affine solve of (3.2) at each detuning
    zf = dict(Z, u1=0.6, u2=-0.3, u3=0.1, u4=0.05)
    w0 = omega + np.linspace(-2.0, 2.0, 9)
    qs, stable = averaged.stationary_sweep(dict(zf, xi=0.3), omega, w0)
    worst = max(np.max(np.abs(averaged.rhs(dict(zf, xi=0.3), omega, 0.0, qq, ww)))
                for qq, ww in zip(qs, w0))
    res.append(("sweep: stationary residual (3.3)", worst, 1e-10))
    ql, _ = averaged.stationary_sweep(zf, omega, w0)
    errs = []
    for qq, ww in zip(ql, w0):
        lam2 = (ww * ww - omega * omega) / ww
        a = np.column_stack([_paper_linear(Z, e) for e in np.eye(4)])
        a += lam2 * np.array([[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 0, -1], [0, 0, 1, 0]])
        errs.append(np.max(np.abs(np.linalg.solve(a, -np.array([0.6, -0.3, 0.1, 0.05])) - qq)))
    res.append(("sweep: linear points = closed-form solve of (3.2)", max(errs), 1e-10))
    # (4) full equations vs averaged: the difference is first order in eps = gamma/omega, so it
    # halves when omega doubles (checked with a cubic term, i.e. nonlinear and anisotropic case)
    diffs = []
    zc = dict(Z, xi=0.6, xi_k=0.4)
    for om in ((2 * np.pi * 40.0, 2 * np.pi * 80.0) if fast else (2 * np.pi * 80.0, 2 * np.pi * 160.0)):
        tt, f, g = full.raw_free_decay(zc, om, q0, 1.0, 40 * om / (2 * np.pi), rtol=1e-11)
        qa = averaged.free_decay(zc, om, q0, tt)
        fa = qa[:, 0] * np.cos(om * tt) + qa[:, 1] * np.sin(om * tt)
        ga = qa[:, 2] * np.cos(om * tt) + qa[:, 3] * np.sin(om * tt)
        diffs.append(max(np.max(np.abs(f - fa)), np.max(np.abs(g - ga))))
    eps = 1.0 / (2 * np.pi * 40.0)
    res.append(("full vs averaged: |f - f_avg| at eps = %.1e (first order: < 3 eps)" % eps,
                diffs[0], 3 * eps))
    res.append(("full vs averaged: error ratio when omega doubles (first order: ~2, > 1.6)",
                -diffs[0] / diffs[1], -1.6))
    return res


def run(fast=True, out=print):
    ok = True
    for name, err, tol in checks(fast):
        good = err <= tol
        ok &= good
        out("  %-75s %s (%.3g vs %.3g)" % (name, "ok" if good else "FAILED", abs(err), abs(tol)))
    return ok
