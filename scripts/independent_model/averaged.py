"""First-order averaged model, by numerical averaging of the full forces over one period.

Van der Pol variables (2.4) at reference W: f = q1 cos(W t) + p1 sin(W t), f' = W (p1 cos - q1 sin),
likewise g with q2, p2. For f'' + W^2 f = G: q1' = -<G sin>/W, p1' = <G cos>/W (first order).
As the paper's (2.5)/(3.2), the perturbing forces are evaluated with f' = omega (p cos - q sin) and
divided by omega (their W/omega factors are second order), while the detuning is kept exact:
G = F + (W^2 - omega^2) f gives 2 q1' += -((W^2 - omega^2)/W) p1 (docs/paper.md item 7).
M quadrature points integrate trigonometric polynomials up to degree M - 1 exactly (the quintic
term with the drive's mu f^2 is degree 7 after multiplying by sin/cos).
"""
import numpy as np
from scipy.integrate import solve_ivp

from .forces import force

M = 16
_TH = 2.0 * np.pi * np.arange(M) / M
_C, _S = np.cos(_TH), np.sin(_TH)


def rhs(z, omega, t, q, omega0=None):
    """q' (not 2 q') of the averaged model at slow time t. omega0 given = forced, frame W = omega0."""
    q1, p1, q2, p2 = q
    w = omega
    f = q1 * _C + p1 * _S
    g = q2 * _C + p2 * _S
    fd = w * (p1 * _C - q1 * _S)
    gd = w * (p2 * _C - q2 * _S)
    if omega0 is not None:
        z = dict(z, omega0=omega0)
    ff, fg = force(z, omega, t, f, fd, g, gd, theta=None if omega0 is None else _TH)
    dq = np.array([-np.mean(ff * _S), np.mean(ff * _C), -np.mean(fg * _S), np.mean(fg * _C)]) / w
    if omega0 is not None:
        det = (omega0 * omega0 - omega * omega) / omega0
        dq += 0.5 * det * np.array([-p1, q1, -p2, q2])
    return dq


def free_decay(z, omega, q0, t):
    """Slow record q(t) at sample times t (t[0] = start), DOP853 at tight tolerances."""
    sol = solve_ivp(lambda tt, y: rhs(z, omega, tt, y), (t[0], t[-1]), np.asarray(q0, float),
                    method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12)
    if not sol.success:
        raise RuntimeError("averaged free decay failed: " + sol.message)
    return sol.y.T


def jacobian(z, omega, q, omega0, h=1e-7):
    j = np.zeros((4, 4))
    for k in range(4):
        e = np.zeros(4)
        e[k] = h
        j[:, k] = (rhs(z, omega, 0.0, q + e, omega0) - rhs(z, omega, 0.0, q - e, omega0)) / (2 * h)
    return j


def _solve(z, omega, omega0, guess):
    """Newton on rhs(q) = 0 with a central-difference Jacobian (the stationary equations (3.3))."""
    q = np.array(guess, float)
    for _ in range(40):
        r = rhs(z, omega, 0.0, q, omega0)
        dq = np.linalg.lstsq(jacobian(z, omega, q, omega0), -r, rcond=None)[0]
        q = q + dq
        if np.linalg.norm(dq) < 1e-12 * (1.0 + np.linalg.norm(q)):
            return q, True
    return q, False


def stationary_sweep(z, omega, omega0s):
    """Stationary q at each omega0 (swept in the given order) by continuation: each point starts
    from the previous one, the step is halved where the solver does not converge. Returns the
    points and, per point, whether it is stable (Jacobian eigenvalues with negative real part)."""
    lin = {k: v for k, v in z.items() if k not in ("xi", "kappa", "xi_diff", "gamma_nl", "mu",
                                                     "gamma_nl4", "eta_pump", "xi_k")}
    # linear start: the averaged model is affine in q, rhs(q) = A q + b
    zz = lin
    b = rhs(zz, omega, 0.0, np.zeros(4), omega0s[0])
    a = np.column_stack([rhs(zz, omega, 0.0, np.eye(4)[k], omega0s[0]) - b for k in range(4)])
    q = np.linalg.solve(a, -b)
    q, ok = _solve(z, omega, omega0s[0], q)
    if not ok:
        raise RuntimeError("stationary solve failed at the first detuning")
    out, stable = [q], []
    prev_w = omega0s[0]
    for w0 in omega0s[1:]:
        cur, w, step = q, prev_w, w0 - prev_w
        while w < w0:
            target = min(w0, w + step)
            cand, ok = _solve(z, omega, target, cur)
            if ok and np.linalg.norm(cand - cur) < 0.3 * (1 + np.linalg.norm(cur)):
                cur, w = cand, target
            else:
                step *= 0.5
                if step < (w0 - prev_w) / 1024:
                    raise RuntimeError("continuation failed near omega0 = %g" % target)
        q, prev_w = cur, w0
        out.append(q)
    for w0, qq in zip(omega0s, out):  # a bench sweep shows stable states only
        stable.append(bool(np.all(np.linalg.eigvals(jacobian(z, omega, qq, w0)).real < 0)))
    return np.array(out), np.array(stable)
