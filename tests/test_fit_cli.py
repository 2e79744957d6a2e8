"""``drumstroke fit`` as a user runs it: onsets in, a recipe out that the other commands take."""

import json
import re

import matplotlib.image
import numpy as np
import pytest
import soundfile

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.analysis import Onsets, write_onsets


@pytest.fixture
def recorded(tmp_path):
    """A stroke under one constant force and its onsets above -30 dB, 0.5 s into a 'recording'."""
    recipe = drumstroke.Recipe(force=drumstroke.Constant(100.0), theta0=0.2, cor=0.8, t_end=3.0)
    stroke = drumstroke.simulate(recipe)
    impacts = stroke.impacts
    loud = impacts.level_db >= impacts.level_db.max() - 30.0
    onsets = Onsets(impacts.t[loud] + 0.5, impacts.level_db[loud] - impacts.level_db.max(), threshold_db=-30.0,
                    source="constant-100")
    path = tmp_path / "stroke.csv"
    write_onsets(path, onsets)
    return path, onsets, stroke


def test_fit_writes_a_recipe_every_command_takes(recorded, tmp_path):
    path, onsets, stroke = recorded
    out = tmp_path / "fitted"
    result = run("fit", path, "--fit-cor", "--out", out / "fit.toml", "--json", out / "fit.json", "--plot",
                 out / "fit.png", "--wav", out / "fit.wav", "--mkdir")
    assert result.returncode == 0, result.stderr
    assert "on the paper model: c = 0.8000 (fitted)" in result.stdout
    assert "0 onsets not played, 0 impacts added: within 2 ms and 1 dB" in result.stdout
    assert len([line for line in result.stdout.splitlines() if line[:4].strip().isdigit()]) == len(onsets)
    data = json.loads((out / "fit.json").read_text())
    assert data["model"] == "paper" and data["within"] and data["fitted_cor"]
    assert data["offset_db"] == pytest.approx(stroke.impacts.level_db.max(), abs=0.05)
    assert data["release"] == pytest.approx(0.5, abs=1e-4)  # the stroke was let go 0.5 s into the recording
    assert max(abs(x) for x in data["time_residual"]) < 2e-3
    # the recipe, read back and simulated: the onsets at their times, after the release
    fitted = drumstroke.simulate(drumstroke.Recipe.from_toml(out / "fit.toml"))
    assert fitted.impacts.t[:len(onsets)] + data["release"] == pytest.approx(onsets.t, abs=2e-3)
    assert matplotlib.image.imread(out / "fit.png").shape[2] in (3, 4)
    audio, rate = soundfile.read(out / "fit.wav")
    assert rate == 48000 and np.abs(audio).max() > 0.0
    simulated = run("simulate", out / "fit.toml")
    assert simulated.returncode == 0 and "model paper" in simulated.stdout
    # into a library, beside the shipped strokes' kind of file
    (tmp_path / "palette.toml").write_text('[[stroke]]\nname = "human"\ncategory = "single stroke"\n'
                                           'description = "fitted to a recording"\nrecipe = "fitted/fit.toml"\n')
    built = run("library", "build", tmp_path / "lib", "--palette", tmp_path / "palette.toml")
    assert built.returncode == 0, built.stderr
    listed = run("library", "list", tmp_path / "lib")
    assert listed.returncode == 0 and "human" in listed.stdout
    # and the composer plays it from the library
    (tmp_path / "one.pattern").write_text("tempo 120\n0 human 100\n2 human 80\n")
    composed = run("compose", tmp_path / "one.pattern", "--library", tmp_path / "lib", "--json", tmp_path / "c.json")
    assert composed.returncode == 0, composed.stderr


def test_fit_with_a_given_level_and_c(recorded, tmp_path):
    path = recorded[0]
    result = run("fit", path, "--cor", "0.8", "--level", "0", "--out", tmp_path / "f.toml")
    assert result.returncode == 0, result.stderr
    assert "on the paper model: c = 0.8000, loudest onset at 0.00 dB" in result.stdout
    result = run("fit", path, "--model", "geometry", "--out", tmp_path / "g.toml")
    assert result.returncode == 0, result.stderr
    assert "on the geometry model: c = 0.8600," in result.stdout and "within 2 ms and 1 dB" in result.stdout
    assert drumstroke.Recipe.from_toml(tmp_path / "g.toml").model == "geometry"
    # the paper's stroke on the 3.9-times faster model at a loud level: only a pull (a < 0) slows its flights enough
    pulled = run("fit", path, "--model", "geometry", "--level", "-3", "--out", tmp_path / "h.toml")
    assert pulled.returncode == 0 and "beyond the human thumb (0-250 m/s^2): it pulls the stick down to -" in pulled.stdout
    forces = re.search(r"forces (\S+) to (\S+) m/s\^2", pulled.stdout)
    assert float(forces[1]) < 0.0 and ("presses up to" in pulled.stdout) == (float(forces[2]) > 250.0)
    assert "within 2 ms and 1 dB" in pulled.stdout


def test_the_thumbs_range_says_which_way_a_design_leaves_it():
    from drumstroke.cli._common import thumb_range

    assert thumb_range(0.0, 250.0) == "within the human thumb (0-250 m/s^2)"
    assert thumb_range(-3.3, 250.0) == "beyond the human thumb (0-250 m/s^2): it pulls the stick down to -3.3 m/s^2"
    assert thumb_range(12.0, 310.5) == "beyond the human thumb (0-250 m/s^2): it presses up to 310.5 m/s^2"
    assert thumb_range(-1.0, 251.0).endswith("it pulls the stick down to -1 m/s^2 and presses up to 251 m/s^2")


def test_fit_errors_are_one_line_and_write_nothing(recorded, tmp_path):
    path = recorded[0]
    out = tmp_path / "x.toml"
    assert_one_line_error(run("fit", tmp_path / "none.csv", "--out", out), "does not exist")
    assert_one_line_error(run("fit", path, "--cor", "1.5", "--out", out), "--cor", "[0, 1)")
    assert_one_line_error(run("fit", path, "--level", "20", "--out", out), "--level")
    assert_one_line_error(run("fit", path, "--out", tmp_path / "x.txt"), "--out", ".toml")
    assert_one_line_error(run("fit", path, "--out", tmp_path / "missing" / "x.toml"), "does not exist", "--mkdir")
    both = run("fit", path, "--cor", "0.8", "--fit-cor", "--out", out)
    assert both.returncode == 2 and "not allowed with argument" in both.stderr
    assert run("fit", path).returncode == 2  # --out is required
    one = tmp_path / "one.csv"
    write_onsets(one, Onsets([0.3], [0.0]))
    assert_one_line_error(run("fit", one, "--out", out), "at least 2 onsets", "got 1")
    echo = tmp_path / "echo.csv"
    write_onsets(echo, Onsets([0.3, 0.3004, 0.3008], [0.0, -1.0, -2.0]))
    assert_one_line_error(run("fit", echo, "--out", out), "no two of the 3 onsets", "onset 2: 0.8 ms after onset 0")
    soundfile.write(tmp_path / "silent.wav", np.zeros(48000), 48000)
    assert_one_line_error(run("fit", tmp_path / "silent.wav", "--out", out), "got 0 (no impacts found)")
    (tmp_path / "notes.txt").write_text("hello")
    assert_one_line_error(run("fit", tmp_path / "notes.txt", "--out", out), "notes.txt")
    assert not out.exists()


def test_a_recording_end_to_end(tmp_path):
    """A simulated stroke, synthesized with noise (30 dB SNR), written as a WAV, fitted by the command."""
    recipe = drumstroke.Recipe(force=drumstroke.Constant(100.0), theta0=0.3, cor=0.8, t_end=4.0)
    impacts = drumstroke.simulate(recipe).impacts
    from drumstroke.render.audio import Drum, synthesize

    signal = synthesize(impacts.t + 0.3, impacts.tip_speed, drum=Drum(snares=False))
    rng = np.random.default_rng(30)
    signal = signal + rng.normal(0.0, 1.0, len(signal)) * np.sqrt(np.mean(signal**2)) * 10 ** (-30 / 20)
    soundfile.write(tmp_path / "stroke.wav", signal, 48000, subtype="FLOAT")
    result = run("fit", tmp_path / "stroke.wav", "--cor", "0.8", "--out", tmp_path / "fit.toml", "--json",
                 tmp_path / "fit.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "fit.json").read_text())
    assert len(data["onsets"]["t"]) >= 10 and not data["extra"]["t"]
    fitted = drumstroke.simulate(drumstroke.Recipe.from_toml(tmp_path / "fit.toml")).impacts
    times, levels = fitted.t + data["release"], fitted.level_db - data["offset_db"]
    original = impacts.t + 0.3
    left_out = {entry["onset"] for entry in data["unmatched"]}
    assert len(left_out) <= 2
    for i, (t, level) in enumerate(zip(data["onsets"]["t"], data["onsets"]["level_db"])):
        if i in left_out:  # only what the detector found in the noise: no impact of the stroke is there
            assert np.min(np.abs(original - t)) > 2e-3
            continue
        j = int(np.argmin(np.abs(times - t)))
        assert abs(times[j] - t) < 2e-3 and abs(levels[j] - level) < 1.0  # the fit plays what was detected
        # and the impact re-simulated is the original's, in time (levels: as well as the detector measured them)
        assert np.min(np.abs(original - times[j])) < 2e-3


def test_fit_and_compare_say_what_reading_a_recording_noted(tmp_path):
    """A stereo recording, clipped: fit and compare say so on stderr, as onsets does (the loudest levels read low)."""
    recipe = drumstroke.Recipe(force=drumstroke.Constant(100.0), theta0=0.3, cor=0.8, t_end=2.0)
    impacts = drumstroke.simulate(recipe).impacts
    from drumstroke.render.audio import Drum, synthesize

    signal = synthesize(impacts.t + 0.3, impacts.tip_speed, drum=Drum(snares=False))
    loud = np.clip(3.0 * signal / np.abs(signal).max(), -1.0, 1.0)
    clipped = int(np.count_nonzero(np.abs(loud) >= 0.999))
    assert clipped > 10
    soundfile.write(tmp_path / "stereo.wav", np.column_stack((loud, loud)), 48000, subtype="FLOAT")
    for result in (run("fit", tmp_path / "stereo.wav", "--out", tmp_path / "fit.toml"),
                   run("compare", tmp_path / "stereo.wav", tmp_path / "fit.toml")):
        assert result.returncode == 0, result.stderr
        assert "note: stereo.wav has 2 channels, mixed down to one" in result.stderr
        assert f"warning: stereo.wav has {2 * clipped} clipped samples" in result.stderr
