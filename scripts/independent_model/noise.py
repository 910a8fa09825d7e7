"""Measurement noise the tool is not told about: white, AR(1) on each slow channel (stationary,
marginal std sigma, q_k = rho q_{k-1} + sqrt(1 - rho^2) sigma e_k), and a slow pick-off gain drift
(the f channel's gain ramps by gain_f over the record, the g channel's by gain_g)."""
import numpy as np

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
    out = np.empty_like(e)
    out[0] = e[0]
    s = np.sqrt(1.0 - rho * rho)
    for k in range(1, n):
        out[k] = rho * out[k - 1] + s * e[k]
    return out


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


def noisy_raw(f, g, model, sigma, rng):
    """Raw f, g: white noise of std sigma (AR(1) on raw samples is not a slow-noise model; the
    coloured case of raw records is the demodulator's own filtering) and the gain drift."""
    m = NOISE_MODELS[model]
    gf, gg = gain_ramp(len(f), m["gain"])
    e = rng.standard_normal((len(f), 2)) * sigma
    return f * gf + e[:, 0], g * gg + e[:, 1]
