#!/usr/bin/env python3
"""Writes the LTspice raw files of this directory, byte by byte, in the
layout LTspice uses (see README.md). Python 3 standard library only.

Every value comes from a formula of + - * / on doubles (no library
functions), so that the Rust tests (tests/integration/ltspice.rs) can
compute the same doubles independently and compare bit for bit. A value
stored as float32 is the double rounded to nearest float32, as
struct.pack('<f') and Rust's `as f32` both do.

    python3 tests/data/ltspice/generate.py    # rewrites the .raw files

It also writes two seeds of the rawfile fuzz target, in
fuzz/seeds/rawfile/.
"""

import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
COMMAND = "Linear Technology Corporation LTspice XVII"
DATE = "Tue Mar  4 10:20:30 2025"


def header(title, plotname, flags, variables, points, output=None,
           backannotations=(), command=COMMAND):
    """The header text, `Variables:` list included, without the data line."""
    lines = [f"Title: {title}", f"Date: {DATE}", f"Plotname: {plotname}"]
    if output is not None:
        lines.append(f"Output: {output}")
    lines += [
        f"Flags: {flags}",
        f"No. Variables: {len(variables)}",
        f"No. Points: {points:>12}",
        "Offset:    0.0000000000000000e+00",
        f"Command: {command}",
    ]
    lines += [f"Backannotation: {b}" for b in backannotations]
    lines.append("Variables:")
    lines += [f"\t{i}\t{name}\t{kind}" for i, (name, kind) in enumerate(variables)]
    return "\n".join(lines) + "\n"


def f64(x):
    return struct.pack("<d", x)


def f32(x):
    return struct.pack("<f", x)


def cplx(z):
    return struct.pack("<dd", z[0], z[1])


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def binary_file(text_header, rows, cells, fastaccess=False, encoding="utf-16-le"):
    """`rows`: one list of values per point; `cells`: per vector, 'd'
    (float64), 'f' (float32) or 'c' (complex: two float64)."""
    pack = {"d": f64, "f": f32, "c": cplx}
    if fastaccess:
        data = b"".join(pack[c](row[j]) for j, c in enumerate(cells) for row in rows)
    else:
        data = b"".join(pack[c](v) for row in rows for c, v in zip(cells, row))
    return (text_header + "Binary:\n").encode(encoding) + data


def ascii_file(text_header, rows, complex_values, newline="\n", encoding="utf-16-le"):
    """LTspice's `Values:` layout: the point index, two tabs and the first
    value, then a tab and each other value on a line of its own; 16
    significant digits; `re,im` for complex values."""
    def fmt(v):
        return f"{v[0]:.15e},{v[1]:.15e}" if complex_values else f"{v:.15e}"
    lines = text_header.rstrip("\n").split("\n") + ["Values:"]
    for k, row in enumerate(rows):
        lines.append(f"{k}\t\t{fmt(row[0])}")
        lines += [f"\t{fmt(v)}" for v in row[1:]]
    return (newline.join(lines) + newline).encode(encoding)


# --- transient: time (sign bit on every third stamp) and four traces ---

TRAN_POINTS = 24


def tran_rows():
    rows = []
    for k in range(TRAN_POINTS):
        t = k * 2.5e-5
        stored_t = -t if k % 3 == 2 else t
        vin = 0.0 if k == 0 else 1.0
        vout = 1.0 - 1.0 / (1.0 + k / 4.0)
        i_r1 = (vin - vout) / 1000.0
        rows.append([stored_t, vin, vout, i_r1, 0.1])
    return rows


TRAN_VARS = [("time", "time"), ("V(in)", "voltage"), ("V(out)", "voltage"),
             ("I(R1)", "device_current"), ("V(ref)", "voltage")]
TRAN_TITLE = "* C:\\sim\\relay_tran.asc"
BACKANNOTATIONS = ["u1 1 2 3 4 5", "_in1 1 2"]


def transient():
    rows = tran_rows()
    real = ["d", "f", "f", "f", "f"]
    h = header(TRAN_TITLE, "Transient Analysis", "real forward", TRAN_VARS,
               len(rows), backannotations=BACKANNOTATIONS)
    write("tran.raw", binary_file(h, rows, real))
    h = header(TRAN_TITLE, "Transient Analysis", "real forward fastaccess", TRAN_VARS,
               len(rows), backannotations=BACKANNOTATIONS)
    write("tran_fastaccess.raw", binary_file(h, rows, real, fastaccess=True))
    h = header(TRAN_TITLE, "Transient Analysis", "real forward double", TRAN_VARS, len(rows))
    write("tran_double.raw", binary_file(h, rows, ["d"] * 5))
    h = header(TRAN_TITLE, "Transient Analysis", "real forward", TRAN_VARS, len(rows))
    write("tran_ascii.raw", ascii_file(h, rows, False))
    # The same header in UTF-8: told from ngspice's by its `Command:` line.
    h = header(TRAN_TITLE, "Transient Analysis", "real forward", TRAN_VARS, len(rows))
    write("tran_utf8.raw", binary_file(h, rows, real, encoding="utf-8"))
    # Names beyond ASCII, one outside the Basic Multilingual Plane (a
    # UTF-16 surrogate pair).
    names = [("time", "time"), ("V(eingang_ü)", "voltage"), ("V(出力)", "voltage"),
             ("I(R°1)", "device_current"), ("V(𝛂)", "voltage")]
    h = header("* C:\\sim\\Prüfstand — relais.asc", "Transient Analysis", "real forward",
               names, len(rows))
    write("names.raw", binary_file(h, rows, real))


# --- stepped transient: three steps of 5, 7 and 6 points ---

STEP_POINTS = [5, 7, 6]


def stepped_rows():
    rows = []
    for s, n in enumerate(STEP_POINTS):
        for k in range(n):
            t = k * 1e-4
            stored_t = -t if k % 3 == 2 else t
            vout = 1.0 - 1.0 / (1.0 + k / (s + 1.0))
            rows.append([stored_t, vout, vout / ((s + 1.0) * 1000.0)])
    return rows


def stepped():
    rows = stepped_rows()
    variables = [("time", "time"), ("V(out)", "voltage"), ("I(R1)", "device_current")]
    h = header("* C:\\sim\\steps.asc", "Transient Analysis", "real forward stepped",
               variables, len(rows))
    write("tran_stepped.raw", binary_file(h, rows, ["d", "f", "f"]))


# --- AC: complex values, the frequency a complex pair too ---

def ac_rows(points, corner):
    rows = []
    for k in range(points):
        f = 10.0 * 2.0 ** k
        x = f / corner
        d = 1.0 + x * x
        h = (1.0 / d, -x / d)
        rows.append([(f, 0.0), (1.0, 0.0), h, ((1.0 - h[0]) / 1000.0, -h[1] / 1000.0)])
    return rows


AC_VARS = [("frequency", "frequency"), ("V(in)", "voltage"), ("V(out)", "voltage"),
           ("I(C1)", "device_current")]


def ac():
    rows = ac_rows(12, 1000.0)
    h = header("* C:\\sim\\lowpass.asc", "AC Analysis", "complex forward log", AC_VARS, len(rows))
    write("ac.raw", binary_file(h, rows, ["c"] * 4))
    write("ac_ascii_utf8.raw", ascii_file(h, rows, True, newline="\r\n", encoding="utf-8"))
    rows = ac_rows(6, 1000.0) + ac_rows(6, 2000.0)
    h = header("* C:\\sim\\lowpass.asc", "AC Analysis", "complex forward log stepped",
               AC_VARS, len(rows))
    write("ac_stepped.raw", binary_file(h, rows, ["c"] * 4))


# --- operating points ---

def op():
    variables = [("V(in)", "voltage"), ("V(out)", "voltage"), ("I(R1)", "device_current"),
                 ("I(V1)", "device_current")]
    h = header("* C:\\sim\\divider.asc", "Operating Point", "real", variables, 1)
    write("op.raw", binary_file(h, [[5.0, 2.5, 0.0025, -0.0025]], ["d", "f", "f", "f"]))
    # `.step param r1`: one point a step, the stepped value first.
    variables = [("r1", "param"), ("V(out)", "voltage"), ("I(R1)", "device_current")]
    rows = []
    for s in range(4):
        r1 = 1000.0 * (s + 1.0)
        vout = 5.0 * 1000.0 / (r1 + 1000.0)
        rows.append([r1, vout, vout / 1000.0])
    h = header("* C:\\sim\\divider.asc", "Operating Point", "real stepped", variables, len(rows))
    write("op_stepped.raw", binary_file(h, rows, ["d", "f", "f"]))


# --- noise spectral density: a plot name beyond ASCII, an `Output:` line ---

def noise():
    variables = [("frequency", "frequency"), ("gain", "gain"), ("V(onoise)", "voltage"),
                 ("V(inoise)", "voltage")]
    rows = []
    for k in range(10):
        f = 10.0 * 2.0 ** k
        x = f / 1e4
        gain = 1.0 / (1.0 + x * x)
        onoise = 1e-8 * (1.0 + 1000.0 / f)
        rows.append([f, gain, onoise, onoise / gain])
    h = header("* C:\\sim\\noise.asc", "Noise Spectral Density - (V/Hz½ or A/Hz½)",
               "real forward log", variables, len(rows), output="out")
    write("noise.raw", binary_file(h, rows, ["d", "f", "f", "f"]))


# --- fuzz seeds: combinations the test files leave out ---

def fuzz_seeds():
    """Writes fuzz/seeds/rawfile/ltspice_*.raw (see scripts/fuzz)."""
    out = os.path.join(HERE, "..", "..", "..", "fuzz", "seeds", "rawfile")
    os.makedirs(out, exist_ok=True)
    # Complex, FastAccess and stepped at once.
    rows = ac_rows(3, 1000.0) + ac_rows(3, 2000.0)
    h = header("* seed", "AC Analysis", "complex forward log stepped fastaccess", AC_VARS, len(rows))
    with open(os.path.join(out, "ltspice_ac_stepped_fastaccess.raw"), "wb") as f:
        f.write(binary_file(h, rows, ["c"] * 4, fastaccess=True))
    # A byte order mark, stepped ASCII values, then a second, binary plot
    # and an all-zero point after its declared ones.
    rows = stepped_rows()[:7]
    variables = [("time", "time"), ("V(out)", "voltage"), ("I(R1)", "device_current")]
    h = header("* seed", "Transient Analysis", "real forward stepped", variables, len(rows))
    data = b"\xff\xfe" + ascii_file(h, rows, False)
    h = header("* seed", "Transient Analysis", "real forward", variables, 2)
    data += binary_file(h, rows[:2], ["d", "f", "f"]) + bytes(16)
    with open(os.path.join(out, "ltspice_bom_ascii_then_binary.raw"), "wb") as f:
        f.write(data)


if __name__ == "__main__":
    transient()
    stepped()
    ac()
    op()
    noise()
    fuzz_seeds()
