"""bounce(), the three ways of giving a scenario, and the errors that name
the key, the file and the line."""

import pytest

import chatterspice
from conftest import ROOT

DEFAULT = (ROOT / "scenarios" / "default.toml").read_text()


def test_the_default_scenario_bounces_five_times_as_the_cli_says(cli_json):
    doc = chatterspice.bounce()
    assert doc["bounce_count"] == 5
    assert doc["outcome"] == "stuck"
    assert doc == cli_json("bounce")
    assert len(doc["impacts"]) == 6  # the first make and 5 rebounds


def test_a_file_reads_as_the_cli_reads_it(cli_json, tmp_path):
    path = tmp_path / "damped.toml"
    path.write_text(DEFAULT.replace("damping = 1.92", "damping = 6.0"))
    doc = chatterspice.bounce(path)
    assert doc == cli_json("bounce", path)
    assert doc["bounce_count"] < 5
    assert chatterspice.bounce(str(path)) == doc


def test_text_sets_only_the_keys_it_names_over_the_default(tmp_path):
    edited = tmp_path / "edited.toml"
    edited.write_text(DEFAULT.replace("damping = 1.92", "damping = 6.0"))
    partial = chatterspice.bounce(toml_text="[surface]\ndamping = 6.0\n")
    assert partial == chatterspice.bounce(edited)
    assert chatterspice.bounce(toml_text="") == chatterspice.bounce()


def test_text_with_a_law_of_its_own_replaces_the_default_surface():
    # The default's Kelvin–Voigt keys (stiffness, damping) would not belong
    # to a rigid surface.
    doc = chatterspice.bounce(toml_text='[surface]\nlaw = "rigid"\nrestitution = 0.5\n')
    rigid = [i["restitution"] for i in doc["impacts"][:3]]
    assert rigid == pytest.approx([0.5, 0.5, 0.5])


def test_a_whole_coil_relay_in_text_reads_as_its_file(cli_json):
    # A [coil] drops the default's step force, circuit and probe; the
    # default's other keys are the library's defaults.
    part = ROOT / "parts" / "songle-srd-05vdc-sl-c.toml"
    doc = chatterspice.bounce(toml_text=part.read_text())
    assert doc == chatterspice.bounce(part) == cli_json("bounce", part)
    assert doc["first_impact"] > 1e-3  # a coil takes milliseconds to pull in


def test_a_negative_mass_in_text_names_the_key_and_the_line():
    with pytest.raises(ValueError) as caught:
        chatterspice.bounce(toml_text="[mechanics]\nmass = -1.0\n")
    err = caught.value
    assert isinstance(err, chatterspice.InputError)
    assert "mass" in str(err)
    assert str(err).startswith("<toml_text>:2: `mechanics.mass` = -1.0")
    assert (err.key, err.path, err.line) == ("mechanics.mass", "<toml_text>", 2)


def test_a_negative_mass_in_a_file_names_the_file_and_the_line(tmp_path):
    path = tmp_path / "negative.toml"
    path.write_text(DEFAULT.replace("mass = 1.0e-4", "mass = -1.0"))
    line = 1 + DEFAULT[: DEFAULT.index("mass = 1.0e-4")].count("\n")
    with pytest.raises(ValueError, match=rf"negative.toml:{line}: `mechanics.mass` = -1.0"):
        chatterspice.bounce(path)


def test_an_unknown_key_names_its_line_in_the_text():
    text = "# a comment\n[surface]\ndamping = 2.0\ndampign = 3.0\n"
    with pytest.raises(chatterspice.InputError) as caught:
        chatterspice.bounce(toml_text=text)
    assert "unknown key `surface.dampign`" in str(caught.value)
    assert caught.value.line == 4


def test_a_key_missing_from_a_replaced_table_names_its_header():
    # A law of its own replaces the default [surface]: Hunt–Crossley then
    # lacks its stiffness, reported at the text's [surface] header.
    with pytest.raises(chatterspice.InputError) as caught:
        chatterspice.bounce(toml_text='\n[surface]\nlaw = "hunt-crossley"\n')
    err = caught.value
    assert (err.key, err.path, err.line) == ("surface.stiffness", "<toml_text>", 2)


def test_a_default_key_the_text_contradicts_is_named_in_the_default_file():
    # The text's preload exceeds the default's step force: the error is
    # about `mechanics.force`, which only the default scenario sets.
    with pytest.raises(chatterspice.InputError) as caught:
        chatterspice.bounce(toml_text="[mechanics]\npreload = 2.0\n")
    err = caught.value
    force_line = 1 + DEFAULT[: DEFAULT.index("force = 1.0")].count("\n")
    assert err.key == "mechanics.force"
    # Named as the user names the built-in scenario, never by a path of
    # the checkout the package was built in.
    assert err.path == "default"
    assert str(ROOT) not in str(err)
    assert err.line == force_line
    assert str(err).startswith(f"{err.path}:{force_line}: `mechanics.force` = 1.0 must exceed")


def test_broken_toml_names_the_line_and_column():
    with pytest.raises(chatterspice.InputError, match=r"<toml_text>:3: not valid TOML"):
        chatterspice.bounce(toml_text="[mechanics]\nmass = 1e-4\nforce = \n")


def test_a_missing_file_is_file_not_found_naming_it(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(FileNotFoundError, match="nowhere.toml: cannot read the scenario"):
        chatterspice.bounce(missing)


def test_a_path_and_text_together_are_refused():
    with pytest.raises(ValueError, match="not both"):
        chatterspice.bounce(ROOT / "scenarios" / "default.toml", toml_text="")


def test_a_measured_record_is_reported_as_it_is(cli_json):
    record = ROOT / "fuzz" / "seeds" / "measured" / "cli_run.csv"
    doc = chatterspice.bounce(measured=record)
    assert doc == cli_json("bounce", "--measured", record)
    states = [r.split(",")[1].strip() for r in record.read_text().split()[1:]]
    makes = sum(1 for a, b in zip(states, states[1:]) if (a, b) == ("open", "closed"))
    assert doc["bounce_count"] == makes - 1
