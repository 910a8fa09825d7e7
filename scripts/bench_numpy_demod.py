#!/usr/bin/python3
"""NumPy reference for the demodulator benchmark (test/benchmarks/demodulator_benchmark.cpp).

The same demodulation in NumPy: per-sample cos/sin of W t, mixing into 2 f cos, 2 f sin,
2 g cos, 2 g sin, and the same two-stage Kaiser low-pass cascade (100 kHz -> 2 kHz -> 100 Hz,
passband 20 Hz, stopband 50 Hz, 126 dB per stage). A fair reference computes only the outputs it
keeps, as the C++ decimating filter does: three variants are timed and the fastest is the one the
ratio uses (under the C++ benchmark's name); all are printed:
  - "full rate": np.convolve at the input rate, then every 50th / 20th output (wasteful, shown
    for comparison with the earlier ratio);
  - "strided": a strided window view of the input, one dot product per kept output;
  - "scipy polyphase": scipy.signal.upfirdn(h, x, down=M) (polyphase, only kept outputs), where
    SciPy is present.
Prints one JSON line per case: {"name", "items_per_second", ...}.
"""
import json
import time

import numpy as np

FS = 100000.0
OMEGA = 85732.0


def kaiser_lowpass(fs, fp, fst, att_db):
    """Kaiser-windowed sinc, odd length by Kaiser's formula, DC gain 1."""
    dw = 2 * np.pi * (fst - fp) / fs
    n = int(np.ceil((att_db - 7.95) / (2.285 * dw))) + 1
    n |= 1
    beta = 0.1102 * (att_db - 8.7)
    m = np.arange(n) - (n - 1) / 2
    fc = 0.5 * (fp + fst) / fs
    h = 2 * fc * np.sinc(2 * fc * m) * np.kaiser(n, beta)
    return h / h.sum()


H1 = kaiser_lowpass(FS, 20.0, 1950.0, 126.03)
H2 = kaiser_lowpass(FS / 50, 20.0, 50.0, 126.03)


def filter_full_rate(x, h, m):
    return np.convolve(x, h, mode="valid")[::m]


def filter_strided(x, h, m):
    windows = np.lib.stride_tricks.sliding_window_view(x, len(h))[::m]
    return windows @ h[::-1]


def filter_polyphase(x, h, m):
    from scipy.signal import upfirdn
    y = upfirdn(h, x, up=1, down=m)
    first = -(-(len(h) - 1) // m)  # the first output whose window lies inside x ("valid")
    return y[first:first + (len(x) - len(h)) // m + 1]


FILTERS = {"full rate": filter_full_rate, "strided": filter_strided}
try:
    import scipy.signal  # noqa: F401
    FILTERS["scipy polyphase"] = filter_polyphase
except ImportError:
    pass


def demodulate(t, f, g, lowpass):
    ph = OMEGA * t
    c, s = 2 * np.cos(ph), 2 * np.sin(ph)
    out = []
    for x in (f * c, f * s, g * c, g * s):
        out.append(lowpass(lowpass(x, H1, 50), H2, 20))
    return np.stack(out, axis=1)


def bench(n, lowpass, min_time=1.0):
    t = np.arange(n) / FS
    f = 0.8 * np.cos(OMEGA * t) - 0.3 * np.sin(OMEGA * t)
    g = 0.1 * np.cos(OMEGA * t) + 0.05 * np.sin(OMEGA * t)
    demodulate(t, f, g, lowpass)  # warm-up
    runs, cpu = 0, 0.0
    while cpu < min_time or runs < 3:
        c0 = time.process_time()
        demodulate(t, f, g, lowpass)
        cpu += time.process_time() - c0
        runs += 1
    return n * runs / cpu, cpu / runs, runs


def main():
    t = np.arange(200000) / FS
    f = np.cos(OMEGA * t + 0.3)
    ref = demodulate(t, f, f, filter_full_rate)
    for name, lp in FILTERS.items():  # every variant gives the same output
        assert np.allclose(demodulate(t, f, f, lp), ref, atol=1e-12), name
    for size in (100000, 1000000):
        results = {name: bench(size, lp) for name, lp in FILTERS.items()}
        best = max(results, key=lambda k: results[k][0])
        for name, (ips, cpu, runs) in results.items():
            rec = {"name": "demod_uniform/%d %s" % (size, name), "items_per_second": ips,
                   "cpu_time_s": cpu, "iterations": runs}
            print(json.dumps(rec), flush=True)
        ips, cpu, runs = results[best]
        print(json.dumps({"name": "demod_uniform/%d" % size, "items_per_second": ips,
                          "cpu_time_s": cpu, "iterations": runs, "reference": best,
                          "taps_stage1": len(H1), "taps_stage2": len(H2)}), flush=True)


if __name__ == "__main__":
    main()
