"""A listening test from recordings: each human stroke fitted and the robot's version rendered beside it."""

import numpy as np
import pytest
import soundfile

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.errors import ParameterError
from drumstroke.evaluation.app import Config
from drumstroke.evaluation.stimuli import fit_stimuli
from drumstroke.formats.wav import write_wav
from drumstroke.recipe import Recipe
from drumstroke.render.audio import Drum, synthesize

RATE = 44100  # not the renderer's 48 kHz: the robot's side follows the recording's rate


def record(path, preset, *, delay=0.3, seed=0):
    """A 'human' recording: a simulated stroke rendered without snares, started ``delay`` s in, with a little noise."""
    impacts = drumstroke.simulate(preset).impacts
    signal = synthesize(impacts.t + delay, impacts.tip_speed, drum=Drum(snares=False), rate=RATE)
    noise = np.random.default_rng(seed).normal(0.0, 1e-4, len(signal))  # about 60 dB below the peak
    write_wav(path, 0.5 * signal + noise, rate=RATE)
    return impacts.t[0] + delay


def first_sound(signal, rate):
    """When a signal first rises above a hundredth of its peak (s): an attack, found without drumstroke."""
    return np.flatnonzero(np.abs(signal) > 0.01 * np.abs(signal).max())[0] / rate


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("recordings")
    first = {"free-bounce": record(folder / "human-free-bounce.wav", "free-bounce"),
             "constant": record(folder / "constant.flac", "constant", delay=0.45, seed=1)}
    out = folder / "test"
    return fit_stimuli([folder / "human-free-bounce.wav", folder / "constant.flac"], out), folder, first


def test_each_recording_makes_a_pair_the_app_serves(made):
    stimuli, _, _ = made
    config = Config.from_toml(stimuli.config)
    assert [pair.id for pair in config.pairs] == ["free-bounce", "constant"]
    for pair in config.pairs:
        human, robot = soundfile.info(str(pair.human)), soundfile.info(str(pair.robot))
        assert human.samplerate == robot.samplerate == RATE and human.frames == robot.frames
    assert stimuli.config.stat().st_mode & 0o777 == 0o600


def test_the_robots_version_starts_with_the_human_and_is_as_loud(made):
    stimuli, _, first = made
    for stimulus in stimuli.stimuli:
        human, _ = soundfile.read(str(stimuli.config.parent / f"human-{stimulus.name}.wav"))
        robot, _ = soundfile.read(str(stimulus.path))
        assert abs(first_sound(human, RATE) - first[stimulus.name]) < 2e-4  # the recording as recorded
        assert abs(first_sound(robot, RATE) - first_sound(human, RATE)) < 2e-3
        assert np.abs(robot).max() == pytest.approx(np.abs(human).max(), abs=1e-4)  # 16-bit PCM


def test_the_fitted_recipes_play_the_recordings_onsets(made):
    stimuli, _, first = made
    for stimulus in stimuli.stimuli:
        fit = stimulus.fit
        assert fit.model == "paper" and fit.cor == 0.86 and stimulus.onsets >= 5
        again = drumstroke.simulate(Recipe.from_toml(stimulus.recipe))
        assert np.array_equal(again.impacts.t, fit.stroke.impacts.t)
        assert abs(again.impacts.t[0] + fit.release - first[stimulus.name]) < 1e-3


def test_recordings_are_all_read_and_fitted_before_anything_is_written(tmp_path):
    record(tmp_path / "good.wav", "free-bounce")
    (tmp_path / "bad.wav").write_bytes(b"RIFF not really a wave file")
    with pytest.raises(ParameterError, match="bad.wav"):
        fit_stimuli([tmp_path / "good.wav", tmp_path / "bad.wav"], tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_two_recordings_of_one_name_are_refused(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    with pytest.raises(ParameterError, match="both make the pair 'x'"):
        fit_stimuli([tmp_path / "a" / "human-x.wav", tmp_path / "b" / "x.wav"], tmp_path / "out")
    with pytest.raises(ParameterError, match="at least one recording"):
        fit_stimuli([], tmp_path / "out")


def test_make_stimuli_from_recordings_on_the_command_line(tmp_path):
    record(tmp_path / "human-free.wav", "free-bounce")
    result = run("listen", "make-stimuli", "--recordings", tmp_path / "human-free.wav", "--out", tmp_path / "test")
    assert result.returncode == 0, result.stderr
    assert "fitted on the paper model with c = 0.86" in result.stdout and "the pairs are complete" in result.stdout
    assert (tmp_path / "test" / "robot-free.wav").exists() and (tmp_path / "test" / "free.toml").exists()
    mono, rate = soundfile.read(tmp_path / "human-free.wav")
    soundfile.write(tmp_path / "human-wide.wav", np.column_stack((mono, mono)), rate, subtype="FLOAT")
    result = run("listen", "make-stimuli", "--recordings", tmp_path / "human-wide.wav", "--out", tmp_path / "wide")
    assert result.returncode == 0, result.stderr
    assert "note: human-wide.wav has 2 channels, mixed down to one" in result.stderr  # as onsets and fit say


@pytest.mark.parametrize("args, needle", [
    (["--strokes", "a"], "--strokes picks library strokes"),
    (["--cor", "1.5"], "--cor"),
    (["--cor", "0.8", "--fit-cor"], "not allowed with argument"),
])
def test_bad_make_stimuli_options_are_one_line(tmp_path, args, needle):
    record(tmp_path / "human-free.wav", "free-bounce")
    result = run("listen", "make-stimuli", "--recordings", tmp_path / "human-free.wav", "--out", tmp_path / "t", *args)
    assert_one_line_error(result, needle)
    assert not (tmp_path / "t").exists()


@pytest.mark.parametrize("option", [["--fit-cor"], ["--cor", "0.8"], ["--model", "paper"], ["--model", "geometry"]])
def test_fit_options_are_refused_with_a_library(tmp_path, option):
    """Even the default model, named: it would be ignored (a library's strokes carry their own)."""
    assert_one_line_error(run("listen", "make-stimuli", "--library", tmp_path, "--out", tmp_path / "t", *option),
                          "--model, --cor and --fit-cor fit recordings")
