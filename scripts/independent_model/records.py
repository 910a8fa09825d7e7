"""CSV records in the tool's input format (interfaces.md): `# key: value` lines, header row."""
import numpy as np


def _write(path, meta, header, cols):
    with open(path, "w") as fh:
        for k, v in meta.items():
            fh.write("# %s: %s\n" % (k, v))
        fh.write(",".join(header) + "\n")
        np.savetxt(fh, np.column_stack(cols), delimiter=",", fmt="%.10g")


def write_slow(path, omega, t, q):
    _write(path, {"omega": "%.10g" % omega, "mode": "free_decay"}, ["t", "q1", "p1", "q2", "p2"],
           [t, q[:, 0], q[:, 1], q[:, 2], q[:, 3]])


def write_sweep(path, omega, omega0, q):
    _write(path, {"omega": "%.10g" % omega, "mode": "forced"},
           ["omega0", "q1", "p1", "q2", "p2"], [omega0, q[:, 0], q[:, 1], q[:, 2], q[:, 3]])


def write_raw(path, omega, t, f, g):
    _write(path, {"omega": "%.10g" % omega, "mode": "free_decay"}, ["t", "f", "g"], [t, f, g])
