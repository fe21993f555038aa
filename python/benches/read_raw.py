"""read_raw against spicelib's RawRead on the same binary raw file, in the
same process: the best and the median of several whole reads each, the
readers taking turns.

    python python/benches/read_raw.py [FILE.raw] [--repeat N]

Without a file, ngspice writes one of about 100 MB first (an RC ladder
driven by a sine, 7 vectors of 1.8 million points) into a temporary
directory. Needs ngspice, numpy, the package and spicelib
(`pip install spicelib`); spicelib is for this comparison only, the
package does not use it.
"""

import argparse
import gc
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import chatterspice

DECK = """rc ladder for the read benchmark
V1 n0 0 SIN(0 1 10k)
R1 n0 n1 1k
C1 n1 0 1n
R2 n1 n2 1k
C2 n2 0 1n
R3 n2 n3 1k
C3 n3 0 1n
R4 n3 n4 1k
C4 n4 0 1n
.options filetype=binary
.tran 5.5n 10m 0 5.5n
.end
"""


def make_raw(directory):
    deck = directory / "ladder.cir"
    deck.write_text(DECK)
    raw = directory / "ladder.raw"
    subprocess.run(
        ["ngspice", "-b", "-r", str(raw), str(deck)],
        check=True,
        capture_output=True,
        cwd=directory,
    )
    return raw


def timed(read):
    gc.collect()
    started = time.perf_counter()
    result = read()
    elapsed = time.perf_counter() - started
    del result
    return elapsed


def compare(readers, repeat):
    """Each reader once a round, the rounds interleaved so that every
    reader sees the same load; the best and the median of each."""
    times = {label: [] for label in readers}
    for _ in range(repeat):
        for label, read in readers.items():
            times[label].append(timed(read))
    for label, spent in times.items():
        spent.sort()
        print(f"{label:<40} best {spent[0]:.3f} s  median {spent[len(spent) // 2]:.3f} s")
    return {label: (spent[0], spent[len(spent) // 2]) for label, spent in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("raw", nargs="?", type=Path)
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args()
    from spicelib import RawRead

    with tempfile.TemporaryDirectory() as tmp:
        path = args.raw or make_raw(Path(tmp))
        size = path.stat().st_size / 1e6
        ours = chatterspice.read_raw(path)
        theirs = RawRead(str(path), traces_to_read="*", dialect="ngspice", verbose=False)
        names = list(ours.keys())
        print(f"{path.name}: {size:.1f} MB, {len(names)} vectors of {len(ours['time'])} points")
        # The same numbers, vector by vector.
        for name in names:
            want = np.asarray(theirs.get_trace(name).get_wave(0))
            if name == "time":
                want = np.abs(want)
            assert np.array_equal(ours[name], want), name

        def chatterspice_read():
            return chatterspice.read_raw(path)

        def spicelib_read():
            return RawRead(str(path), traces_to_read="*", dialect="ngspice", verbose=False)

        def spicelib_arrays():
            raw = RawRead(str(path), traces_to_read="*", dialect="ngspice", verbose=False)
            return [raw.get_trace(n).get_wave(0) for n in names]

        figures = compare(
            {
                "chatterspice.read_raw": chatterspice_read,
                'spicelib RawRead(traces_to_read="*")': spicelib_read,
                "spicelib RawRead + every get_wave": spicelib_arrays,
            },
            args.repeat,
        )
        ours = figures["chatterspice.read_raw"]
        theirs = figures['spicelib RawRead(traces_to_read="*")']
        print(
            f"read_raw / RawRead: {ours[0] / theirs[0]:.2f} (best), "
            f"{ours[1] / theirs[1]:.2f} (median)"
        )


if __name__ == "__main__":
    main()
