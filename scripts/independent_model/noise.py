"""Measurement noise the tool is not told about: white, AR(1) on each slow channel (stationary,
marginal std sigma, q_k = rho q_{k-1} + sqrt(1 - rho^2) sigma e_k), and a slow pick-off gain drift
(the f channel's gain ramps by gain_f over the record, the g channel's by gain_g)."""
import numpy as np
from scipy.signal import lfilter

NOISE_MODELS = {
    "white": dict(rho=0.0, gain=(0.0, 0.0)),
    "ar1_0.5": dict(rho=0.5, gain=(0.0, 0.0)),
    "ar1_0.9": dict(rho=0.9, gain=(0.0, 0.0)),
    "white+gain_drift": dict(rho=0.0, gain=(3e-3, -2e-3)),
}


def ar1(rng, n, cols, rho, sigma):
    e = rng.standard_normal((n, cols)) * sigma
    if rho == 0.0:
        return e
    # out_k = rho out_{k-1} + sqrt(1 - rho^2) e_k, out_0 = e_0 (stationary from the start)
    e[1:] *= np.sqrt(1.0 - rho * rho)
    return lfilter([1.0], [1.0, -rho], e, axis=0)


def gain_ramp(n, gain):
    """Per-sample gains of the f and g channels, linear over the record."""
    s = np.linspace(0.0, 1.0, n)
    return 1.0 + gain[0] * s, 1.0 + gain[1] * s


def noisy_slow(q, model, sigma, rng):
    """q: (n, 4) = q1, p1, q2, p2; returns the measured q."""
    m = NOISE_MODELS[model]
    gf, gg = gain_ramp(len(q), m["gain"])
    out = q * np.column_stack([gf, gf, gg, gg])
    return out + ar1(rng, len(q), 4, m["rho"], sigma)


def noisy_raw(f, g, model, sigma, rng, omega, t):
    """Raw f, g with the gain drift and noise of std sigma: white per raw sample, or (rho > 0)
    narrow-band noise around the carrier, a cos(omega t) + b sin(omega t) with a, b AR(1) per raw
    sample (the noise the slow variables q, p see is then coloured after demodulation)."""
    m = NOISE_MODELS[model]
    gf, gg = gain_ramp(len(f), m["gain"])
    if m["rho"] == 0.0:
        e = rng.standard_normal((len(f), 2)) * sigma
    else:
        ab = ar1(rng, len(f), 4, m["rho"], sigma)
        c, s = np.cos(omega * t), np.sin(omega * t)
        e = np.column_stack([ab[:, 0] * c + ab[:, 1] * s, ab[:, 2] * c + ab[:, 3] * s])
    return f * gf + e[:, 0], g * gg + e[:, 1]
