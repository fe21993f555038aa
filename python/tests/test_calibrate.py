"""capture() and fit(): a scope trace of the default relay's contact, made
from its own chatter, read back and fitted back to the relay."""

import numpy as np
import pytest

import chatterspice
from conftest import ROOT

OPEN, CLOSED = 5.0, 0.05  # V across the contact, open and closed


def contact_closed(doc, t):
    """Whether the contact of a bounce report is closed at each time in t."""
    closed = np.zeros(t.shape, dtype=bool)
    for interval in doc["intervals"]:
        if interval["state"] == "closed":
            closed |= (t >= interval["start"]) & (t < interval["end"])
    return closed


@pytest.fixture(scope="module")
def truth():
    return chatterspice.bounce()


@pytest.fixture()
def scope_csv(truth, tmp_path):
    """A plain `time,value` scope export of the contact, 2 ms at 1 µs per
    sample, with 20 mV of seeded noise."""
    t = np.arange(-100e-6, 2e-3, 1e-6)
    rng = np.random.default_rng(7)
    v = np.where(contact_closed(truth, t), CLOSED, OPEN) + rng.normal(0, 0.02, t.size)
    path = tmp_path / "scope.csv"
    np.savetxt(path, np.column_stack([t, v]), delimiter=",", header="time,value", comments="")
    return path


def test_a_capture_finds_every_make_and_break_of_the_contact(truth, scope_csv, cli_json):
    doc = chatterspice.capture(scope_csv)
    assert doc == cli_json("capture", scope_csv)
    assert doc["layout"] == "plain"
    assert doc["levels"]["open"] == pytest.approx(OPEN, abs=0.01)
    assert doc["levels"]["closed"] == pytest.approx(CLOSED, abs=0.01)
    assert doc["bounce_count"] == truth["bounce_count"]
    makes = [i["start"] for i in truth["intervals"] if i["state"] == "closed"]
    breaks = [i["start"] for i in truth["intervals"][1:] if i["state"] == "open"]
    # Each edge within a sample of the truth (the 50 % crossing).
    assert doc["makes"] == pytest.approx(makes, abs=1.5e-6)
    assert doc["breaks"] == pytest.approx(breaks, abs=1.5e-6)


def test_capture_options_are_checked(scope_csv, tmp_path):
    with pytest.raises(ValueError, match="low and high together"):
        chatterspice.capture(scope_csv, low=1.0)
    with pytest.raises(ValueError, match='closed = "up"'):
        chatterspice.capture(scope_csv, closed="up")
    with pytest.raises(FileNotFoundError, match="no-such-scope.csv"):
        chatterspice.capture(tmp_path / "no-such-scope.csv")
    flat = tmp_path / "flat.csv"
    flat.write_text("time,value\n" + "".join(f"{i}e-6,1.0\n" for i in range(50)))
    with pytest.raises(chatterspice.InputError, match="flat.csv"):
        chatterspice.capture(flat)


def test_a_fit_to_the_capture_recovers_the_surface_damping(truth, scope_csv):
    # A prior 1.6x off in the damping, which alone the fit may move.
    fitted = chatterspice.fit(
        toml_text="[surface]\ndamping = 3.0\n",
        capture=scope_csv,
        free=["surface.damping"],
    )
    (key,) = fitted.report["parameters"]
    assert key["key"] == "surface.damping"
    assert key["value"] == pytest.approx(1.92, rel=0.02)
    assert key["determined"] is True
    # The fitted scenario reads back, and bounces as the truth did.
    assert "[provenance]" in fitted.scenario
    again = chatterspice.bounce(toml_text=fitted.scenario)
    assert again["bounce_count"] == truth["bounce_count"]


def test_a_fit_to_a_measured_record_matches_the_cli(truth, tmp_path, cli_json):
    record = tmp_path / "chatter.csv"
    rows = [f"{i['start']!r},{i['state']}" for i in truth["intervals"]]
    record.write_text("time,state\n" + "\n".join(rows) + "\n")
    prior = tmp_path / "prior.toml"
    prior.write_text(
        (ROOT / "scenarios" / "default.toml").read_text().replace("damping = 1.92", "damping = 1.2")
        + '\n[fit]\nfree = ["surface.damping"]\n'
    )
    fitted = chatterspice.fit(prior, measured=record)
    expected = cli_json("fit", prior, "--measured", record)
    # Wall-clock time is the one thing that differs between two fits.
    for doc in (fitted.report, expected):
        doc.pop("elapsed", None)
    assert fitted.report == expected
    assert fitted.report["parameters"][0]["value"] == pytest.approx(1.92, rel=0.02)


def test_a_fit_without_free_keys_says_so():
    with pytest.raises(ValueError, match="free"):
        chatterspice.fit()
