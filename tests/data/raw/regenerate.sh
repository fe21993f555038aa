#!/bin/sh
# Rewrites the golden raw files from the decks next to them (ngspice 39).
# The tests check values, not bytes, so a newer ngspice should still pass;
# the Date: lines change on every run.
set -eu
cd "$(dirname "$0")"
for deck in rc_tran rc_tran_ascii rc_ac divider_op_tran; do
    ngspice -b -r "$deck.raw" "$deck.cir" >/dev/null 2>&1
done
# The .control block has no analysis lines, so ngspice exits 1 after writing.
ngspice -b control_write.cir >/dev/null 2>&1 || true

# Killed runs: start a run that would take hours, kill it, then keep the
# header and the first whole points plus part of the next one, so the files
# stay small. The cut positions are what the tests expect (40 and 25 points).
tmp=$(mktemp -d)
timeout -s KILL 1 ngspice -b -r "$tmp/b.raw" killed.cir >/dev/null 2>&1 || true
timeout -s KILL 1 ngspice -b -r "$tmp/a.raw" killed_ascii.cir >/dev/null 2>&1 || true
python3 - "$tmp" <<'PY'
import sys
tmp = sys.argv[1]
b = open(f"{tmp}/b.raw", "rb").read()
i = b.index(b"Binary:\n") + len(b"Binary:\n")
open("killed_binary.raw", "wb").write(b[: i + 40 * 32 + 13])  # 40 points + 13 bytes
a = open(f"{tmp}/a.raw", "rb").read()
j = a.index(b"Values:\n") + len(b"Values:\n")
k = a.index(b"\n25\t\t", j) + 1
lines = a[k:].split(b"\n")
# point 25: index+time, v(in), and 9 characters of v(out)
open("killed_ascii.raw", "wb").write(a[:k] + b"\n".join(lines[:2]) + b"\n" + lines[2][:9])
# ngspice 44+ writes its version as a Command: line before Variables:
r = open("rc_tran.raw", "rb").read()
v = r.index(b"Variables:\n")
open("rc_tran_ngspice44.raw", "wb").write(r[:v] + b"Command: version 44.2\n" + r[v:])
PY
rm -r "$tmp"
