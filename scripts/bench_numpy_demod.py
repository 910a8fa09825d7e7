#!/usr/bin/python3
"""NumPy reference for the demodulator benchmark (test/benchmarks/demodulator_benchmark.cpp).

The same demodulation written the straightforward NumPy way: per-sample cos/sin of W t, mixing
into 2 f cos, 2 f sin, 2 g cos, 2 g sin, and the same two-stage Kaiser low-pass cascade (100 kHz
-> 2 kHz -> 100 Hz, passband 20 Hz, stopband 50 Hz, 126 dB per stage) by np.convolve followed by
decimation. Prints one JSON line per case: {"name", "items_per_second", ...}; the names match the
C++ benchmark names so scripts/run_benchmarks.sh can form ratios.
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


def demodulate(t, f, g):
    ph = OMEGA * t
    c, s = 2 * np.cos(ph), 2 * np.sin(ph)
    out = []
    for x in (f * c, f * s, g * c, g * s):
        y1 = np.convolve(x, H1, mode="valid")[::50]
        out.append(np.convolve(y1, H2, mode="valid")[::20])
    return np.stack(out, axis=1)


def bench(n, min_time=1.0):
    t = np.arange(n) / FS
    f = 0.8 * np.cos(OMEGA * t) - 0.3 * np.sin(OMEGA * t)
    g = 0.1 * np.cos(OMEGA * t) + 0.05 * np.sin(OMEGA * t)
    demodulate(t, f, g)  # warm-up
    runs, cpu = 0, 0.0
    while cpu < min_time or runs < 3:
        c0 = time.process_time()
        demodulate(t, f, g)
        cpu += time.process_time() - c0
        runs += 1
    return {"name": "demod_uniform/%d" % n, "items_per_second": n * runs / cpu,
            "cpu_time_s": cpu / runs, "iterations": runs, "taps_stage1": len(H1),
            "taps_stage2": len(H2)}


if __name__ == "__main__":
    for size in (100000, 1000000):
        print(json.dumps(bench(size)), flush=True)
