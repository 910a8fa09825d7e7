"""Shared helpers of the real ring-down validation (docs/validation_ringdown.md, "Real records").

The development set lives outside the repository (../shared/data/ringdowns_qpit_dev, never copied
here); its split by sample is scripts/validation/ringdown_real_split.csv, fixed before tuning.
"""
import csv
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_DATA = os.path.join(os.path.dirname(REPO), "shared", "data", "ringdowns_qpit_dev")
SPLIT = os.path.join(HERE, "ringdown_real_split.csv")
CLASSES = os.path.join(HERE, "ringdown_real_classes.csv")
DB_PER_NEPER = 20.0 / math.log(10.0)


def data_dir():
    return os.environ.get("CVG_REAL_RINGDOWNS", DEFAULT_DATA)


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def labels():
    """id -> label row (authors_q, frequency_hz, sample_id, mode_id, ...)."""
    return {r["id"]: r for r in read_rows(os.path.join(data_dir(), "labels.csv"))}


def split():
    """id -> 'tuning' | 'heldout'."""
    return {r["id"]: r["part"] for r in read_rows(SPLIT)}


def classes():
    """id -> row of the by-eye classification (class, note); empty when not yet made."""
    if not os.path.exists(CLASSES):
        return {}
    return {r["id"]: r for r in read_rows(CLASSES)}


def record_path(rid):
    return os.path.join(data_dir(), "records", rid + ".txt")


def load_record(rid):
    """(t [s], level [dB]) of a record: '%' comment lines, then 'time, power' rows."""
    import numpy as np

    t, y = [], []
    with open(record_path(rid)) as f:
        for line in f:
            s = line.strip()
            if not s or s[0] in "%#":
                continue
            parts = s.replace(";", ",").split(",")
            try:
                a, b = float(parts[0]), float(parts[1])
            except (ValueError, IndexError):
                continue
            t.append(a)
            y.append(b)
    return np.asarray(t), np.asarray(y)


def authors_slope_db_per_s(q, f_hz):
    """Slope of the power level in dB/s for Q = pi f tau (tau the amplitude 1/e time)."""
    tau = q / (math.pi * f_hz)
    return -DB_PER_NEPER / tau


def wilson(k, n, z=1.959964):
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))
