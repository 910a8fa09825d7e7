"""The harness's own resonators (not config/resonators/*): other frequencies, Q, defects, sample
steps and record lengths (2 s steps over an hour to 2 ms steps over 3 s), other sweep grids.
Defects are given in units of gamma so each preset has its own proportions. Effect sizes (EFFECTS)
were fixed before the validation runs from the standard errors of a clean record fitted with the
whole library (about 10-15 standard errors each: large enough to be found, not so large that the
first-order averaging breaks), see docs/validation_independent.md."""
import math


def _defects(gamma, nu, b_c, b_s, c_m, n, h_c, h_s):
    return dict(gamma=gamma, nu=nu * gamma, b_c=b_c * gamma, b_s=b_s * gamma, c_m=c_m * gamma,
                n=n * gamma, h_c=h_c * gamma, h_s=h_s * gamma)


def _omega(hz):
    return 2.0 * math.pi * hz


# free decay, slow variables: t,q1,p1,q2,p2 records
FREE_DECAY = {
    # quartz hemisphere-like, Q = 2e7 at 3 kHz, one hour at 2 s steps
    "fd_hrg_1h": dict(omega=_omega(3000.0), z=_defects(_omega(3000.0) / 2e7, 0.06, 0.05, -0.03,
                                                      0.8, 0.15, 0.35, -0.25),
                      q0=(0.30, 0.90, 0.22, 0.28), duration=3600.0, step=2.0, sigma=3e-4),
    # metal/quartz cylinder-like, Q = 2e5 at 6 kHz, 40 s at 50 ms
    "fd_cyl_40s": dict(omega=_omega(6000.0), z=_defects(_omega(6000.0) / 2e5, -0.04, -0.06, 0.05,
                                                       -0.6, 0.12, -0.2, 0.3),
                       q0=(0.85, -0.25, -0.30, 0.20), duration=40.0, step=0.05, sigma=5e-4),
    # vacuum-packaged MEMS ring, Q = 4e4 at 9 kHz, 3 s at 2 ms
    "fd_mems_3s": dict(omega=_omega(9000.0), z=_defects(_omega(9000.0) / 4e4, 0.08, 0.03, 0.04,
                                                       1.1, -0.1, 0.25, 0.3),
                       q0=(-0.2, 0.8, 0.35, -0.15), duration=3.0, step=0.002, sigma=1e-3),
}

# free decay, raw f, g (full equations), demodulated by the tool
RAW = {
    "raw_1k2": dict(omega=_omega(1200.0), z=_defects(_omega(1200.0) / 2500.0, 0.05, 0.04, -0.05,
                                                    0.7, 0.1, 0.3, -0.2),
                    q0=(0.30, 0.90, 0.22, 0.28), duration=1.0, rate=12000.0, sigma=1e-3),
    "raw_700": dict(omega=_omega(700.0), z=_defects(_omega(700.0) / 4000.0, -0.05, 0.05, 0.03,
                                                   -0.5, 0.1, 0.25, 0.3),
                    q0=(0.8, -0.3, -0.25, 0.25), duration=2.0, rate=7000.0, sigma=1e-3),
}

# forced sweeps: omega0,q1,p1,q2,p2 stationary points
SWEEP = {
    "sw_ring_11k": dict(omega=_omega(11000.0),
                        z=dict(_defects(_omega(11000.0) / 3000.0, 0.05, 0.04, -0.03, 0.6, 0.035,
                                        0.3, -0.22), u1=20.0, u2=-12.0, u3=3.0, u4=2.0),
                        lam=(-90.0, 110.0), points=41, sigma=2e-3),
    "sw_ring_24k": dict(omega=_omega(24000.0),
                        z=dict(_defects(_omega(24000.0) / 8000.0, -0.04, -0.03, 0.06, -0.5,
                                        -0.08, -0.2, 0.3), u1=-15.0, u2=10.0, u3=-2.5, u4=1.5),
                        lam=(-80.0, 70.0), points=81, sigma=1.5e-3),
}

# Library terms per mode (the tool's candidate extensions), and effects outside the library with
# the library stand-in that counts as a correct answer besides "unexplained" (None: only
# "unexplained" is correct).
LIBRARY = {"free_decay": ["xi", "kappa", "gamma_nl", "xi_diff", "cm_rate"],
           "forced": ["xi", "kappa", "gamma_nl", "xi_diff", "mu"]}
OUTSIDE = {"free_decay": {"gamma_nl4": "gamma_nl", "cm_step": "cm_rate", "xi_k": None},
           "forced": {"delay": None, "pump": None, "xi_k": None}}
# Terms the generator knows that newer tools add to their library: scored as library terms when
# the tool's `explain --help` names them, as effects outside the library (no stand-in) otherwise.
NEWER_TERMS = ["xi_k"]


def library(mode, tool_terms=()):
    """(library terms, outside effects with stand-ins) for a tool that knows tool_terms."""
    lib = LIBRARY[mode] + [t for t in NEWER_TERMS if t in tool_terms
                           or "%s:%s" % (mode, t) in tool_terms]
    out = {k: v for k, v in OUTSIDE[mode].items() if k not in lib}
    return lib, out

# xi_k (added later): xi's size times SE(xi_k)/SE(xi) of a Fisher-information fit of the averaged
# model with the linear terms, xi and xi_k (and the initial state) to the clean preset record.
# Effect sizes per preset, about 12 standard errors of the clean record fitted with the whole
# library (pilot of 2026-11-23, white noise; mu from a Ceres fit of xi+mu). Outside the library:
# gamma_nl4 with the same decay-rate change at amplitude 0.7 as gamma_nl, cm_step the same total
# frequency change as cm_rate but saturating (tau = record / 4), delay a drive-phase change of
# ~0.15 rad across the sweep, pump (eta of (2.1)) a parametric coefficient of ~5 standard errors
# of c_m.
EFFECTS = {
    "fd_hrg_1h": dict(xi=6.6e-4, kappa=5.4e-4, gamma_nl=3.4e-4, xi_diff=2.3e-4, cm_rate=4.6e-8,
                      gamma_nl4=6.9e-4, cm_step=1.7e-4, xi_k=3.1e-3),
    "fd_cyl_40s": dict(xi=0.13, kappa=0.15, gamma_nl=0.34, xi_diff=0.085, cm_rate=5.7e-3,
                       gamma_nl4=0.69, cm_step=0.23, xi_k=1.75),
    "fd_mems_3s": dict(xi=3.9, kappa=4.6, gamma_nl=2.5, xi_diff=1.7, cm_rate=0.36,
                       gamma_nl4=5.1, cm_step=1.1, xi_k=24.0),
    "raw_1k2": dict(xi=7.9, kappa=8.2, gamma_nl=2.9, xi_diff=1.75, cm_rate=1.45, gamma_nl4=5.8,
                    cm_step=1.45, xi_k=38.0),
    "raw_700": dict(xi=3.6, kappa=3.1, gamma_nl=1.0, xi_diff=0.73, cm_rate=0.45, gamma_nl4=2.0,
                    cm_step=0.9, xi_k=17.0),
    "sw_ring_11k": dict(xi=24.0, kappa=15.0, gamma_nl=8.8, xi_diff=16.0, mu=0.026, delay=7.5e-4,
                        pump=2.3e6, xi_k=85.0),
    "sw_ring_24k": dict(xi=10.0, kappa=9.0, gamma_nl=3.6, xi_diff=5.0, mu=0.016, delay=1.0e-3,
                        pump=6.1e6, xi_k=34.0),
}


def effect_coefficients(preset, names, duration=None):
    """Coefficients (forces.py names) of the hidden effects `names` at this preset's sizes."""
    z = {}
    for name in names:
        v = EFFECTS[preset][name]
        if name == "cm_step":
            z.update(cm_step=v, cm_tau=duration / 4.0)
        elif name == "delay":
            z["delay_s"] = v
        elif name == "pump":
            z["eta_pump"] = v
        else:
            z[name] = v
    return z
