"""Full equations (2.3) (free decay) in the original coordinates y = (f, f', g, g'), integrated by
scipy's solve_ivp (DOP853, an explicit Runge-Kutta 8(5,3) with step control: another integrator
and another set of variables than the project's fixed-step RK4 in van der Pol variables)."""
import numpy as np
from scipy.integrate import solve_ivp

from .forces import force


def raw_free_decay(z, omega, q0, duration_s, rate_hz, rtol=1e-10):
    """Raw f, g sampled at rate_hz on [0, duration_s], starting from the slow state q0 at t = 0
    (by (2.4): f = q1, f' = omega p1, g = q2, g' = omega p2)."""
    w2 = omega * omega

    def deriv(t, y):
        f, fd, g, gd = y
        ff, fg = force(z, omega, t, f, fd, g, gd)
        return (fd, -w2 * f + ff, gd, -w2 * g + fg)

    q1, p1, q2, p2 = q0
    n = int(round(duration_s * rate_hz)) + 1
    t = np.arange(n) / rate_hz
    sol = solve_ivp(deriv, (0.0, t[-1]), [q1, omega * p1, q2, omega * p2], method="DOP853",
                    t_eval=t, rtol=rtol, atol=rtol * 1e-2, max_step=2.0 * np.pi / omega / 4.0)
    if not sol.success:
        raise RuntimeError("full-equation integration failed: " + sol.message)
    return t, sol.y[0], sol.y[2]


def slow_from_fast(t, f, fd, omega):
    """Inverse of (2.4) at reference omega (for the self-check): q = f cos - (f'/W) sin,
    p = f sin + (f'/W) cos."""
    c, s = np.cos(omega * t), np.sin(omega * t)
    return f * c - fd / omega * s, f * s + fd / omega * c
