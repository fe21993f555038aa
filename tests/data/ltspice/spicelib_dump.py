#!/usr/bin/env python3
"""Reads LTspice raw files with spicelib (https://pypi.org/project/spicelib/)
and prints what it read as JSON, for tests/integration/ltspice.rs to
compare with chatterspice's reader value by value.

    python3 spicelib_dump.py FILE[:STEPS]...

STEPS: for a stepped file, the number of steps. spicelib takes the steps of
a stepped file from LTspice's .log file next to it; this script writes one
with STEPS `.step` lines (in a temporary directory, with a copy of the
file). spicelib then finds the steps in the data itself (wherever the axis
comes back to its first value) and fails if it finds another number.

Output: {"FILE": [plot, ...]}, or {"FILE": {"error": "..."}} for a file
spicelib cannot read, with, per plot, its name, spicelib's dialect,
encoding and raw type ("binary:" or "values:"), the points of each step
(null for a plot without an axis) and every trace: its name, the numpy
dtype spicelib stores it in, and its values, step after step, as the bits
of the float64 each converts to ("re", and "im" for complex traces). The time
axis is spicelib's get_wave(), which takes the absolute value of time.
"""

import json
import logging
import os
import shutil
import struct
import sys
import tempfile

logging.disable(logging.CRITICAL)

import numpy as np  # noqa: E402
from spicelib import RawRead  # noqa: E402


def bits(x):
    return struct.unpack("<Q", struct.pack("<d", float(x)))[0]


def read(path, steps):
    with tempfile.TemporaryDirectory() as tmp:
        if steps:
            copy = os.path.join(tmp, "stepped.raw")
            shutil.copyfile(path, copy)
            with open(os.path.join(tmp, "stepped.log"), "w") as log:
                log.write("Circuit: * stepped\n")
                for s in range(steps):
                    log.write(f".step run={s + 1}\n")
            path = copy
        raw = RawRead(path, traces_to_read="*", verbose=False)
        plots = []
        for plot in raw.plots:
            stepped = plot.steps is not None and plot.has_axis
            count = len(plot.get_steps()) if stepped else 1
            traces = []
            for name in plot.get_trace_names():
                if plot.has_axis:
                    waves = [np.asarray(plot.get_wave(name, s)) for s in range(count)]
                else:
                    waves = [np.asarray(plot.get_trace(name).data)]
                values = np.concatenate(waves)
                traces.append({
                    "name": name,
                    "dtype": str(waves[0].dtype),
                    "re": [bits(v) for v in np.real(values)],
                    "im": [bits(v) for v in np.imag(values)] if np.iscomplexobj(values) else None,
                })
            plots.append({
                "name": plot.get_plot_name(),
                "dialect": plot.dialect,
                "encoding": plot.encoding,
                "raw_type": plot.raw_type,
                "step_points": [len(plot.get_wave(0, s)) for s in range(count)]
                if plot.has_axis else None,
                "traces": traces,
            })
        return plots


def main():
    out = {}
    for arg in sys.argv[1:]:
        path, _, steps = arg.rpartition(":") if arg.rpartition(":")[2].isdigit() else (arg, "", "")
        try:
            out[arg] = read(path, int(steps) if steps else 0)
        except Exception as e:  # noqa: BLE001 (reported to the caller)
            out[arg] = {"error": f"{type(e).__name__}: {e}"}
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
