"""What a Python user expects of the package beyond the command line's
reports: pickling, reprs, argument errors, bases in toml_text, the bundled
parts, the contact include, kept work directories and logs, envelopes,
progress callbacks and docstrings."""

import inspect
import os
import pickle
import shutil
import threading

import numpy as np
import pytest

import chatterspice
from conftest import ROOT

DEFAULT = (ROOT / "scenarios" / "default.toml").read_text()
SWEEP_TEXT = '[sweep]\nsamples = 40\nseed = 2\n[sweep.vary]\n"surface.damping" = 0.3\n'


@pytest.fixture(scope="module")
def default_run():
    return chatterspice.run()


# --- pickling and repr ---------------------------------------------------


def test_a_run_pickles_to_an_equal_run(default_run):
    again = pickle.loads(pickle.dumps(default_run))
    assert type(again) is chatterspice.Run
    assert again == default_run
    assert np.array_equal(again.waveforms["v(in)"], default_run.waveforms["v(in)"])
    assert again.report == default_run.report
    # Equality looks at the values: another relay's run is not equal.
    other = chatterspice.run(toml_text="[surface]\ndamping = 6.0\n", ideal=False)
    assert other != default_run


def test_a_run_says_what_it_holds(default_run):
    text = repr(default_run)
    assert "5 bounces (stuck)" in text
    assert "v(in): 7 edges" in text
    assert f"{len(default_run.waveforms['time'])} points" in text


def test_a_sweep_pickles_and_says_its_size():
    result = chatterspice.sweep(toml_text=SWEEP_TEXT, mechanics_only=True)
    again = pickle.loads(pickle.dumps(result))
    assert again == result and again.rows == result.rows and again.csv == result.csv
    assert repr(result).startswith("<chatterspice.Sweep: 40 samples of surface.damping;")
    fewer = chatterspice.sweep(toml_text=SWEEP_TEXT, mechanics_only=True, samples=39)
    assert fewer != result


def test_a_fit_pickles_and_names_its_keys(tmp_path):
    truth = chatterspice.bounce()
    record = tmp_path / "chatter.csv"
    rows = [f"{i['start']!r},{i['state']}" for i in truth["intervals"]]
    record.write_text("time,state\n" + "\n".join(rows) + "\n")
    fitted = chatterspice.fit(
        toml_text="[surface]\ndamping = 1.5\n", measured=record, free="surface.damping"
    )
    assert pickle.loads(pickle.dumps(fitted)) == fitted
    assert repr(fitted).startswith("<chatterspice.Fit surface.damping = 1.9")


def test_a_raw_file_and_its_plots_pickle_read_only():
    raw = chatterspice.read_raw(ROOT / "tests" / "data" / "raw" / "divider_op_tran.raw")
    again = pickle.loads(pickle.dumps(raw))
    assert again == raw
    assert again.plots[1] == raw.plots[1] and again.plots[0] != raw.plots[1]
    assert not again["v(mid)"].flags.writeable
    assert np.array_equal(again["v(mid)"], raw["v(mid)"])


# --- arguments -----------------------------------------------------------


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, samples=-1), "samples"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, samples=True), "samples"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, samples=2.5), "samples"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, jobs=0), "jobs"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, seed=-3), "seed"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, progress=3), "progress"),
        (lambda: chatterspice.sweep(toml_text=SWEEP_TEXT, mechanics_only="yes"), "mechanics_only"),
        (lambda: chatterspice.run(timeout="60"), "timeout"),
        (lambda: chatterspice.run(timeout=float("nan")), "timeout"),
        (lambda: chatterspice.run(ideal=1), "ideal"),
        (lambda: chatterspice.run(keep_workdir=None), "keep_workdir"),
        (lambda: chatterspice.bounce(3), "path"),
        (lambda: chatterspice.bounce(toml_text=b"[surface]"), "toml_text"),
        (lambda: chatterspice.bounce(measured=1.5), "measured"),
        (lambda: chatterspice.fit(free=3), "free"),
        (lambda: chatterspice.fit(free=["surface.damping", 4]), "free"),
        (lambda: chatterspice.capture(None), "path"),
        (lambda: chatterspice.capture(ROOT / "x.csv", low="1"), "low"),
        (lambda: chatterspice.read_raw(["a.raw"]), "path"),
        (lambda: chatterspice.bounce(origin="x.toml"), "origin"),
        (lambda: chatterspice.part("no-such-relay"), "name"),
    ],
)
def test_a_bad_argument_is_an_input_error_naming_it(call, name):
    with pytest.raises(chatterspice.InputError) as caught:
        call()
    assert str(caught.value).startswith(name), str(caught.value)


def test_numpy_integers_and_a_single_free_key_are_taken():
    text = SWEEP_TEXT
    by_int = chatterspice.sweep(toml_text=text, mechanics_only=True, samples=5)
    by_numpy = chatterspice.sweep(toml_text=text, mechanics_only=np.True_, samples=np.int64(5))
    assert by_numpy == by_int and len(by_int.rows) == 5


def test_a_path_like_is_taken(tmp_path):
    path = tmp_path / "damped.toml"
    path.write_text(DEFAULT.replace("damping = 1.92", "damping = 6.0"))
    assert chatterspice.bounce(path) == chatterspice.bounce(os.fsencode(path))


# --- bases in toml_text --------------------------------------------------


def test_text_on_a_bundled_part_reads_as_the_same_file(cli_json, tmp_path):
    text = 'base = "part:te-axicom-im-5v"\n'
    path = tmp_path / "axicom.toml"
    path.write_text(text)
    doc = chatterspice.bounce(toml_text=text)
    assert doc == cli_json("bounce", path)
    assert doc == chatterspice.bounce(ROOT / "parts" / "te-axicom-im-5v.toml")


def test_text_on_a_file_base_reads_it_relative_to_the_working_directory(
    cli_json, tmp_path, monkeypatch
):
    (tmp_path / "damped.toml").write_text(DEFAULT.replace("damping = 1.92", "damping = 6.0"))
    text = 'base = "damped.toml"\n[mechanics]\nmass = 1.1e-4\n'
    (tmp_path / "mine.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    doc = chatterspice.bounce(toml_text=text)
    assert doc == cli_json("bounce", tmp_path / "mine.toml")
    # The base's damping, not the default's: fewer bounces than its 5.
    assert doc["bounce_count"] < chatterspice.bounce()["bounce_count"]


def test_text_on_a_file_base_reads_it_relative_to_its_origin(tmp_path):
    relay = tmp_path / "relays"
    relay.mkdir()
    (relay / "damped.toml").write_text(DEFAULT.replace("damping = 1.92", "damping = 6.0"))
    text = 'base = "damped.toml"\n'
    doc = chatterspice.bounce(toml_text=text, origin=relay / "mine.toml")
    assert doc == chatterspice.bounce(relay / "damped.toml")
    with pytest.raises(chatterspice.InputError, match="damped.toml"):
        chatterspice.bounce(toml_text=text, origin=tmp_path / "mine.toml")


def test_an_error_in_text_on_a_base_names_the_text_and_its_line():
    text = 'base = "part:te-axicom-im-5v"\n\n[surface]\ndampign = 3.0\n'
    with pytest.raises(chatterspice.InputError) as caught:
        chatterspice.bounce(toml_text=text)
    assert (caught.value.path, caught.value.line) == ("<toml_text>", 4)


# --- parts, the contact include, the run's files -------------------------


def test_parts_are_the_bundled_part_files():
    names = chatterspice.parts()
    assert names == sorted(p.stem for p in (ROOT / "parts").glob("*.toml"))
    for name in names:
        assert chatterspice.part(name) == (ROOT / "parts" / f"{name}.toml").read_text()


def test_pwl_is_the_cli_include(cli):
    include = chatterspice.pwl()
    assert include == cli("pwl", "--element", "pwl").stdout
    assert ".subckt CONTACT" in include
    damped = chatterspice.pwl(toml_text="[surface]\ndamping = 6.0\n")
    assert damped != include


def test_a_kept_work_directory_holds_the_raw_file_of_the_waveforms():
    result = chatterspice.run(keep_workdir=True)
    try:
        assert os.path.isdir(result.workdir)
        raw = chatterspice.read_raw(result.raw_path)
        assert np.array_equal(raw["v(in)"], result.waveforms["v(in)"])
        assert os.path.isdir(result.ideal_workdir)
        assert result.ideal_workdir != result.workdir
    finally:
        for d in (result.workdir, result.ideal_workdir):
            if d:
                shutil.rmtree(d, ignore_errors=True)


def test_a_run_keeps_ngspice_s_log_and_no_directory(default_run):
    assert default_run.workdir is None and default_run.raw_path is None
    rows = len(default_run.waveforms["time"])
    assert f"No. of Data Rows : {rows}" in default_run.log
    assert "No. of Data Rows" in default_run.ideal_log


# --- envelopes and progress ----------------------------------------------


def test_an_envelope_is_the_cli_check_envelope(cli_json):
    part = ROOT / "parts" / "te-axicom-im-5v.toml"
    doc = chatterspice.envelope(part, samples=4)
    assert doc == cli_json("check", part, "--envelope", "--samples", "4")
    assert doc["envelope"]["samples"] == 4
    text = 'base = "part:te-axicom-im-5v"\n'
    assert chatterspice.envelope(toml_text=text, samples=4)["envelope"] == doc["envelope"]


def test_progress_is_called_with_done_and_total_up_to_the_end():
    calls, threads = [], set()

    def progress(done, total):
        calls.append((done, total))
        threads.add(threading.get_ident())

    chatterspice.sweep(toml_text=SWEEP_TEXT, mechanics_only=True, progress=progress)
    # On the calling thread, never on the sweep's own.
    assert threads == {threading.get_ident()}
    assert calls[-1] == (40, 40)
    assert all(total == 40 for _, total in calls)
    done = [d for d, _ in calls]
    assert done == sorted(done) and len(set(done)) == len(done)


# --- docstrings ----------------------------------------------------------

FUNCTIONS = [
    chatterspice.bounce,
    chatterspice.run,
    chatterspice.check,
    chatterspice.envelope,
    chatterspice.life,
    chatterspice.sweep,
    chatterspice.fit,
    chatterspice.capture,
    chatterspice.read_raw,
    chatterspice.parts,
    chatterspice.part,
    chatterspice.pwl,
]


@pytest.mark.parametrize("function", FUNCTIONS, ids=lambda f: f.__name__)
def test_every_function_documents_each_of_its_parameters(function):
    doc = inspect.getdoc(function)
    assert doc and len(doc.splitlines()) > 1, f"{function.__name__} has no docstring"
    for name in inspect.signature(function).parameters:
        assert name in doc, f"{function.__name__}'s docstring does not explain {name}"


@pytest.mark.parametrize(
    "cls",
    [
        chatterspice.Run,
        chatterspice.Sweep,
        chatterspice.SweepRows,
        chatterspice.Fit,
        chatterspice.RawFile,
        chatterspice.Plot,
        chatterspice.InputError,
        chatterspice.NgspiceError,
        chatterspice.SimulationError,
        chatterspice.ChatterspiceWarning,
    ],
)
def test_every_class_is_documented(cls):
    assert inspect.getdoc(cls)
    for name, member in vars(cls).items():
        if not name.startswith("_") and (inspect.isgetsetdescriptor(member) or callable(member)):
            assert inspect.getdoc(member), f"{cls.__name__}.{name} has no docstring"


def test_help_shows_no_rust_link_or_path():
    """help() of every public name reads as Python: no leaked Rust link
    such as "[`run`](crate)" or a `crate::` path."""
    import pydoc

    for name in chatterspice.__all__:
        obj = getattr(chatterspice, name)
        if not (callable(obj) or inspect.isclass(obj)):
            continue
        text = pydoc.render_doc(obj, renderer=pydoc.plaintext)
        for leak in ("](", "`crate", "crate::", "[`"):
            assert leak not in text, f"help({name}) shows {leak!r}"
