"""Forces of the full equations (2.3)/(3.1): f'' + omega^2 f = F_f, g'' + omega^2 g = F_g.

A truth is a dict of coefficients (plain names, tilde = divided by omega as in the tool):
  linear (2.3): gamma, nu, b_c, b_s, c_m, n, h_c, h_s
  library extensions: xi (cubic, (2.3)), kappa (quintic, (2.3)), gamma_nl (-gamma_nl N f'),
    xi_diff (+xi_diff N f on f, -xi_diff N g on g), cm_rate (c_m(t) = c_m + cm_rate t)
  the second isotropic cubic invariant xi_k (library term of newer tools, outside the library of
    older ones): F_f = -(xi_k/(2 omega)) l g', F_g = +(xi_k/(2 omega)) l f' with the angular
    momentum l = f g' - g f'; it leaves a standing wave (l = 0) alone and adds xi_k r k / 8 to the
    averaged precession theta' of (5.9), as xi does (docs/paper.md item 4)
  drive (3.1): u1..u4 (u~ = eta u / omega), mu, at drive phase theta = omega0 t
  outside the library (not in the tool's model):
    gamma_nl4   -gamma_nl4 N^2 f' (damping growing with amplitude^4)
    cm_step, cm_tau   c_m(t) = c_m + cm_step (1 - exp(-t / cm_tau)) (thermal transient)
    delay_s     the drive arrives delayed: phase theta - omega0 delay_s
    eta_pump    the 2 omega0 parametric terms of (2.1), -(eta/2)((u1^2 - u2^2) cos 2 theta
                + 2 u1 u2 sin 2 theta) f, likewise g (docs/paper.md item 6); eta in 1/s^2
Every function takes numpy arrays (broadcast) so the averaging can evaluate a period at once.
"""
import numpy as np

LINEAR = ("gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c", "h_s")


def c_m_of_t(z, t):
    c = z.get("c_m", 0.0) + z.get("cm_rate", 0.0) * t
    if z.get("cm_step", 0.0):
        c = c + z["cm_step"] * (1.0 - np.exp(-t / z["cm_tau"]))
    return c


def force(z, omega, t, f, fd, g, gd, theta=None):
    """F_f, F_g of (2.3) with the drive of (3.1) when theta (drive phase) is given."""
    w = omega
    gm, nu, bc, bs = z.get("gamma", 0.0), z.get("nu", 0.0), z.get("b_c", 0.0), z.get("b_s", 0.0)
    cm, n, hc, hs = c_m_of_t(z, t), z.get("n", 0.0), z.get("h_c", 0.0), z.get("h_s", 0.0)
    nn = f * f + g * g
    ff = -(gm + bc) * fd - (-nu + bs) * gd - w * (cm + hc) * f - w * (n + hs) * g
    fg = -(gm - bc) * gd - (nu + bs) * fd - w * (cm - hc) * g - w * (-n + hs) * f
    xi, xd, ka = z.get("xi", 0.0), z.get("xi_diff", 0.0), z.get("kappa", 0.0)
    ff = ff + w * (xi + xd) * nn * f + w * ka * nn * nn * f
    fg = fg + w * (xi - xd) * nn * g + w * ka * nn * nn * g
    xk = z.get("xi_k", 0.0)
    if xk:
        ell = f * gd - g * fd
        ff = ff - xk / (2.0 * w) * ell * gd
        fg = fg + xk / (2.0 * w) * ell * fd
    damp_nl = z.get("gamma_nl", 0.0) * nn + z.get("gamma_nl4", 0.0) * nn * nn
    ff = ff - damp_nl * fd
    fg = fg - damp_nl * gd
    if theta is not None:
        ph = theta - z.get("omega0", w) * z.get("delay_s", 0.0)
        sn, cs = np.sin(ph), np.cos(ph)
        mu = z.get("mu", 0.0)
        u1, u2, u3, u4 = (z.get(k, 0.0) for k in ("u1", "u2", "u3", "u4"))
        # eta (1 + 3 mu f^2)(-u1 sin + u2 cos) with eta u = omega u~ (3.1)
        ff = ff + w * (1.0 + 3.0 * mu * f * f) * (-u1 * sn + u2 * cs)
        fg = fg + w * (1.0 + 3.0 * mu * g * g) * (-u3 * sn + u4 * cs)
        eta = z.get("eta_pump", 0.0)
        if eta:
            k = w * w / (2.0 * eta)  # (eta/2) u_i u_j = omega^2/(2 eta) u~_i u~_j
            c2, s2 = np.cos(2.0 * theta), np.sin(2.0 * theta)
            ff = ff - k * ((u1 * u1 - u2 * u2) * c2 + 2.0 * u1 * u2 * s2) * f
            fg = fg - k * ((u3 * u3 - u4 * u4) * c2 + 2.0 * u3 * u4 * s2) * g
    return ff, fg
