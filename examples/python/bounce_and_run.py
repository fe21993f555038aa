# %% [markdown]
# # chatterspice from Python: the default relay, bounced and run
#
# A notebook as a script (`# %%` cells, which Jupyter, VS Code and
# Spyder open as cells; `python examples/python/bounce_and_run.py` runs it
# whole). Needs `pip install ./python` and ngspice. With matplotlib
# installed it also saves `bounce_and_run.png` in the working directory.

# %%
import numpy as np

import chatterspice

# %% [markdown]
# ## The chatter of one closing
# `bounce()` with no argument simulates the built-in default relay: a
# 1.1 kHz signal relay with a Kelvin–Voigt contact.

# %%
closing = chatterspice.bounce()
print(f"{closing['bounce_count']} bounces, {closing['outcome']}")
print(f"first make {closing['first_impact'] * 1e3:.4f} ms, "
      f"closed for good {closing['settle_time'] * 1e3:.4f} ms")
for interval in closing["intervals"][:4]:
    print(f"  {interval['state']:<6} {interval['start'] * 1e3:8.4f} ms "
          f"to {interval['end'] * 1e3:8.4f} ms")

# %% [markdown]
# ## A change over the default
# `toml_text` sets only the keys it names; the rest come from the default
# scenario. Three times the contact damping leaves fewer bounces.

# %%
for damping in (1.92, 4.0, 6.0):
    doc = chatterspice.bounce(toml_text=f"[surface]\ndamping = {damping}\n")
    print(f"surface.damping = {damping}: {doc['bounce_count']} bounces")

# %% [markdown]
# ## The contact switching an MCU input in ngspice
# `run()` returns the run report and every vector of the raw file as a
# numpy array.

# %%
result = chatterspice.run()
time, v_in = result.waveforms["time"], result.waveforms["v(in)"]
probe = result.report["probes"][0]
print(f"{probe['signal']}: {probe['edges']} edges, {probe['glitches']} glitches, "
      f"{len(time)} points, peak {v_in.max():.3f} V")
ideal = result.ideal_waveforms
print(f"ideal contact: {result.report['probes'][0]['ideal']['edges']} edge")

# %% [markdown]
# ## When v(in) first crosses the low threshold
# The report's first edge, found again in the samples: the first sample
# below the threshold, and the crossing interpolated before it.

# %%
low, high = probe["low"], probe["high"]
i = np.flatnonzero(v_in < low)[0]
crossing = time[i - 1] + (low - v_in[i - 1]) * (time[i] - time[i - 1]) / (v_in[i] - v_in[i - 1])
print(f"v(in) crosses {low} V at {crossing * 1e3:.4f} ms "
      f"(report: first edge {probe['first_edge'] * 1e3:.4f} ms)")

# %% [markdown]
# ## A plot, when matplotlib is there

# %%
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
else:
    fig, ax = plt.subplots(figsize=(8, 3))
    ax.plot(ideal["time"] * 1e3, ideal["v(in)"], label="ideal contact", color="0.6")
    ax.plot(time * 1e3, v_in, label="bouncing contact")
    for level in (low, high):
        ax.axhline(level, linestyle=":", color="0.3")
    ax.set_xlim(0, 2)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("v(in) (V)")
    ax.legend()
    fig.tight_layout()
    fig.savefig("bounce_and_run.png", dpi=100)
    print("saved bounce_and_run.png")
