"""c from a drop: exact simulated drops, rendered noisy ones, the command."""

import json

import numpy as np
import pytest
import soundfile

from _cli import assert_one_line_error, run
from _recordings import RATE, render, room_response
from drumstroke.analysis import Onsets, find_onsets, measure_cor, write_onsets
from drumstroke.analysis.drop import drop_impacts
from drumstroke.errors import ParameterError
from drumstroke.stroke import simulate


def _drop(cor, theta0, *, model="paper", t_end=4.0):
    """A stick let fall from rest at ``theta0`` under gravity alone: its impacts' times and tip speeds."""
    stroke = simulate(theta0=theta0, cor=cor, t_end=t_end, model=model)
    return stroke.impacts.t, stroke.impacts.tip_speed


def _onsets(times, speeds, count=10):
    return Onsets(times[:count], 20.0 * np.log10(speeds[:count] / speeds[0]))


@pytest.mark.parametrize("model", ["paper", "geometry"])
def test_c_of_exact_drops_is_recovered_to_a_millionth(model):
    """Impact times from the solver (to 1e-9 s): c from the flights, and from the levels, to 1e-6."""
    rng = np.random.default_rng(5)
    for cor, theta0 in zip(rng.uniform(0.5, 0.95, 4), rng.uniform(0.1, 1.4, 4)):
        drop = measure_cor(_onsets(*_drop(cor, theta0, model=model)), model=model)
        assert drop.cor == pytest.approx(cor, abs=1e-6) and drop.interval[0] <= drop.cor <= drop.interval[1]
        assert drop.cor_levels == pytest.approx(cor, abs=1e-6)
        assert np.abs(drop.residuals).max() < 1e-7 and drop.model == model


def test_the_small_flight_limit_would_misread_a_high_drop():
    """T ∝ launch speed (a ball's flights) misreads c by more than 0.01 for a drop from 1.4 rad; the arcs do not."""
    times, speeds = _drop(0.9, 1.4)
    flights = np.diff(times[:10])
    naive = np.exp(np.polyfit(np.arange(len(flights)), np.log(flights), 1)[0])
    assert abs(naive - 0.9) > 0.01
    assert measure_cor(_onsets(times, speeds)).cor == pytest.approx(0.9, abs=1e-6)


def test_ringing_and_rattle_between_the_impacts_are_passed_over():
    """Quieter onsets between a drop's impacts (what a detector may add) do not change c."""
    times, speeds = _drop(0.8, 0.4)
    onsets = _onsets(times, speeds)
    extra_t = np.concatenate([onsets.t, onsets.t[:-1] + 0.016, onsets.t[:-1] + 0.3 * np.diff(onsets.t)])
    extra_level = np.concatenate([onsets.level_db, onsets.level_db[:-1] - 8.0, onsets.level_db[:-1] - 20.0])
    order = np.argsort(extra_t)
    noisy = Onsets(extra_t[order], extra_level[order])
    assert np.array_equal(noisy.t[drop_impacts(noisy)], onsets.t)
    assert measure_cor(noisy).cor == pytest.approx(0.8, abs=1e-6)


DROPS = 6


@pytest.fixture(scope="module")
def rendered_drops():
    """Random drops (c 0.5–0.95, from 0.1–0.6 rad), rendered: snares on and off, SNR 20–40 dB, two in a room."""
    rng = np.random.default_rng(18)
    room = room_response(rt60=0.3)
    drops = []
    for i in range(DROPS):
        cor, theta0, snr = rng.uniform(0.5, 0.95), rng.uniform(0.1, 0.6), rng.uniform(20.0, 40.0)
        times, speeds = _drop(cor, theta0)
        signal, _ = render(times[times < 3.5], speeds[times < 3.5], snares=bool(i % 2), snr=snr,
                           room=room if i >= 4 else None, seed=i)
        drops.append((cor, signal))
    return drops


def test_c_of_rendered_noisy_drops_is_within_a_hundredth(rendered_drops):
    """From audio: c within 0.01 (measured: within 0.0001), a tight interval, and the levels agreeing within 0.08."""
    for cor, signal in rendered_drops:
        drop = measure_cor(find_onsets(signal, RATE))
        assert abs(drop.cor - cor) <= 0.01, (drop, cor)
        assert drop.interval[1] - drop.interval[0] < 0.05 and drop.flights >= 3
        assert abs(drop.cor_levels - cor) <= 0.08, (drop.cor_levels, cor)


def test_too_few_impacts_are_refused_by_name():
    times, speeds = _drop(0.7, 0.3)
    with pytest.raises(ParameterError, match=r"at least 3 flights \(4 impacts\) .* found 3 impact\(s\)"):
        measure_cor(_onsets(times, speeds, count=3))
    with pytest.raises(ParameterError, match="found 0 impact"):
        measure_cor(Onsets([], []))
    with pytest.raises(ParameterError, match="model must be one of"):
        measure_cor(_onsets(times, speeds), model="ball")
    with pytest.raises(ParameterError, match=r"confidence must be in \(0, 1\)"):
        measure_cor(_onsets(times, speeds), confidence=1.0)
    with pytest.raises(ParameterError, match="onsets must be an Onsets"):
        measure_cor(times)


def test_the_command_measures_c_from_a_recording_and_from_its_onsets(tmp_path, rendered_drops):
    cor, signal = rendered_drops[1]
    wav = tmp_path / "drop.wav"
    soundfile.write(str(wav), signal, RATE, subtype="PCM_24")
    result = run("measure-cor", wav, "--json", tmp_path / "c.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "c.json").read_text())
    assert abs(data["cor"] - cor) <= 0.01 and data["model"] == "paper" and "levels cross-check" in result.stdout
    assert f"c = {data['cor']:.4f}" in result.stdout and f"from {data['flights']} flights" in result.stdout
    write_onsets(tmp_path / "drop.csv", find_onsets(signal, RATE))
    again = run("measure-cor", tmp_path / "drop.csv")
    assert again.returncode == 0 and f"c = {data['cor']:.4f}" in again.stdout


def test_the_command_refuses_a_silent_file_and_a_single_hit(tmp_path):
    silent = tmp_path / "silent.wav"
    soundfile.write(str(silent), np.zeros(RATE), RATE)
    assert_one_line_error(run("measure-cor", silent), "no impacts found", "silent")
    one, _ = render(np.array([0.2]), np.array([1.0]), kind="other")
    hit = tmp_path / "hit.wav"
    soundfile.write(str(hit), one, RATE)
    assert_one_line_error(run("measure-cor", hit), "at least 3 flights")
