"""The palette on the command line: simulate with post-processing, library build/list, compose, demo.

Run as a user runs it (a real process, real files). Every file written is read back with an independent
reader — numpy for CSV, json, soundfile for WAV, mido and pretty_midi for MIDI, html.parser for the page,
librosa's onset detector for the audio — and compared with values worked out here: impact times from
``drumstroke.simulate`` mirrored by hand, note times from beats, velocities from the documented map.
"""

import json
import math
import shutil
import subprocess
import sys
from html.parser import HTMLParser

import librosa
import mido
import numpy as np
import pretty_midi
import pytest
import soundfile

import drumstroke
from _cli import assert_one_line_error, run
from drumstroke.demo import RUDIMENTS
from drumstroke.palette.library import load_library
from drumstroke.palette.rudiments import rudiment

PNG = b"\x89PNG\r\n\x1a\n"
TIP = 0.27  # pivot to tip (m) of the paper's stick
FLOOR_DB = 20 * math.log10(4.0) - 48.0  # velocity 1: 48 dB below 4 m/s


def hand_velocity(level_db):
    """The documented map: velocity 1 at FLOOR_DB, 127 at 4 m/s, linear in dB, rounded to nearest."""
    return int(min(127, max(1, math.floor(1 + (level_db - FLOOR_DB) * 126 / 48 + 0.5))))


def read_csv(path):
    """The header and the numbers of a drumstroke CSV (its first line is the header), read with numpy."""
    with open(path) as handle:
        header = handle.readline().strip()
    return header.split(","), np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def midi_note_ons(path):
    """(time s, channel, note, velocity) of every sounding note_on, timed by mido's own tempo handling."""
    out, now = [], 0.0
    for message in mido.MidiFile(path):
        now += message.time
        if message.type == "note_on" and message.velocity > 0:
            out.append((now, message.channel, message.note, message.velocity))
    return out


# --- simulate with post-processing -------------------------------------------------------------------------------

def test_simulate_catch_stretch_reverse_writes_every_file(tmp_path):
    paths = {key: tmp_path / f"fb.{key}" for key in ("csv", "json", "wav", "mid", "png")}
    result = run("simulate", "free-bounce", "--catch", 3, "--stretch", 2, "--reverse", "--csv", paths["csv"],
                 "--json", paths["json"], "--wav", paths["wav"], "--midi", paths["mid"], "--plot", paths["png"])
    assert result.returncode == 0, result.stderr
    # the summary is of the stroke written, after the transforms: its first impact is the written one
    assert "; after catch 3, stretch 2, reverse\n3 impacts;" in result.stdout

    bounce = drumstroke.simulate("free-bounce")
    t, omega = bounce.impacts.t, bounce.impacts.omega
    caught = t[2] + (t[3] - t[2]) / 2  # gravity only: the flight after impact 3 is a parabola, apex midway
    expected = [2 * (caught - t[i]) for i in (2, 1, 0)]
    cor = drumstroke.preset("free-bounce").cor

    data = json.loads(paths["json"].read_text())
    impacts = data["impacts"]
    first = result.stdout.split("level (dB)\n", 1)[1].split()
    assert first[:2] == ["1", f"{impacts[0]['t']:.6f}"] and first[3] == f"{impacts[0]['tip_speed']:.6f}"
    assert data["t_end"] == pytest.approx(2 * caught, abs=1e-9)
    assert [i["t"] for i in impacts] == pytest.approx(expected, abs=1e-9)
    # backwards, each impact's speeds before and after swap; twice as slow halves them
    for row, i in zip(impacts, (2, 1, 0)):
        assert row["tip_speed"] == pytest.approx(cor * abs(omega[i]) * TIP / 2, rel=1e-9)
        assert row["omega_after"] == pytest.approx(abs(omega[i]) / 2, rel=1e-9)
    head = data["theta_max"]

    header, table = read_csv(paths["csv"])
    assert header == ["t", "theta", "omega"]
    assert data["csv"]["rate"] == 1000.0 and data["csv"]["file"] == "fb.csv"  # fb.json is the JSON beside fb.csv
    times, theta, speed = table.T
    assert times == pytest.approx(np.arange(len(times)) / 1000.0, abs=1e-12)
    assert 2 * caught - 1e-3 < times[-1] <= 2 * caught
    assert theta.min() >= head - 1e-12
    for impact in expected:
        k = round(impact * 1000)
        assert 0.0 <= theta[k] - head <= np.abs(speed).max() / 1000
    assert theta[0] > head and speed[0] == pytest.approx(0.0, abs=1e-6)  # it starts at the caught apex, still

    info = soundfile.info(paths["wav"])
    assert (info.samplerate, info.channels) == (48000, 1)
    assert info.frames == round((expected[-1] + 7 * 0.25) * 48000)  # last impact plus 7 fundamental decays

    midi = pretty_midi.PrettyMIDI(str(paths["mid"]))
    (drum,) = midi.instruments
    assert drum.is_drum
    audible = [(row["t"], row["level_db"]) for row in impacts if row["level_db"] >= FLOOR_DB]
    assert len(audible) == 3
    assert [n.pitch for n in drum.notes] == [38, 40, 40]  # the stroke's first impact, then its bounces
    assert [n.start for n in drum.notes] == pytest.approx([time for time, _ in audible], abs=0.5e-3)
    assert [n.velocity for n in drum.notes] == [hand_velocity(level) for _, level in audible]

    assert paths["png"].read_bytes()[:8] == PNG


@pytest.mark.parametrize("steps, duration, scale, last", [(["--trim", "0:1", "--stretch", 2], 2.0, 2.0, 1.0),
                                                          (["--stretch", 2, "--trim", "0:1"], 1.0, 2.0, 0.5)])
def test_post_processing_applies_in_the_order_given(tmp_path, steps, duration, scale, last):
    """trim then stretch: 2 s holding the impacts of the first second; stretch then trim: 1 s, first half second."""
    result = run("simulate", "free-bounce", *steps, "--json", tmp_path / "s.json")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "s.json").read_text())
    assert data["t_end"] == pytest.approx(duration, abs=1e-12)
    t = drumstroke.simulate("free-bounce").impacts.t
    assert [i["t"] for i in data["impacts"]] == pytest.approx((scale * t[t <= last]).tolist(), abs=1e-9)


@pytest.mark.parametrize(
    "option, needles",
    [
        (["--stretch", "nan"], ["--stretch", "nan"]),
        (["--stretch", "0"], ["--stretch", "0.0", "[0.01, 100]"]),
        (["--compress", "1000"], ["--compress", "1000.0", "upright"]),
        (["--trim", "1:x"], ["--trim", "'1:x'"]),
        (["--trim", "2:1"], ["--trim", "'2:1'", "0 <= T0 < T1"]),
        (["--catch", "0"], ["--catch", "0", "[1, inf)"]),
        (["--catch", "500"], ["--catch", "500", "[1, 98]"]),
    ],
)
def test_bad_post_processing_options_give_one_line_and_status_2(tmp_path, option, needles):
    result = run("simulate", "free-bounce", *option, "--json", tmp_path / "s.json")
    assert_one_line_error(result, *needles)
    assert not (tmp_path / "s.json").exists()


# --- library build and list ------------------------------------------------------------------------------------------

PALETTE = """\
[[stroke]]
name = "single"
category = "single stroke"
description = "One full stroke, caught at the top of its rebound."
recipe = { theta0 = 0.1, omega0 = -2.0, t_end = 1.0, force = { kind = "constant", value = 200.0 } }
transforms = [{ catch = 1 }]

[[stroke]]
name = "tap"
category = "single stroke"
description = "A ghost note from just above the head."
recipe = { theta0 = -0.2, omega0 = -0.5, t_end = 1.0, force = { kind = "constant", value = 200.0 } }
transforms = [{ catch = 1 }]

[[stroke]]
name = "bounce3"
category = "gravity only"
description = "The free bounce caught after its third impact."
recipe = "free-bounce"
transforms = [{ catch = 3 }]
"""
NAMES = ["single", "tap", "bounce3"]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A library built by the command at 500 Hz from a three-stroke palette: (folder, the build's result)."""
    folder = tmp_path_factory.mktemp("cli")
    (folder / "palette.toml").write_text(PALETTE)
    result = run("library", "build", folder / "lib", "--rate", 500, "--palette", folder / "palette.toml")
    return folder / "lib", result


def test_library_build_writes_every_stroke_on_the_rate(built):
    folder, result = built
    assert result.returncode == 0, result.stderr
    assert f"wrote {folder}/: 3 strokes at 500 Hz" in result.stdout
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["rate"] == 500 and [s["name"] for s in manifest["strokes"]] == NAMES
    for record in manifest["strokes"]:
        header, table = read_csv(folder / manifest["folder"] / record["files"]["trajectory"])
        assert header == ["t", "theta", "omega"]
        impacts_file = folder / manifest["folder"] / record["files"]["impacts"]
        assert json.loads(impacts_file.read_text())["csv"]["rate"] == 500.0
        t, theta, _ = table.T
        assert t == pytest.approx(np.arange(len(t)) / 500.0, abs=1e-12)
        assert t[-1] == pytest.approx(record["t_end"], abs=1e-12)
        assert theta.min() >= record["theta_max"] - 1e-12
    impacts = {s["name"]: s["impacts"] for s in manifest["strokes"]}
    assert impacts == {"single": 1, "tap": 1, "bounce3": 3}


def test_library_list_prints_every_stroke(built):
    folder, _ = built
    result = run("library", "list", folder)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == f"{folder}: 3 strokes at 500 Hz"
    assert len(lines) == 2 + len(NAMES)
    manifest = json.loads((folder / "manifest.json").read_text())
    # default mapping off channel 10 (on it the drum map's notes are the planner's): the i-th stroke is 60 + i
    for line, record, note in zip(lines[2:], manifest["strokes"], (60, 61, 62)):
        fields = line.split()
        assert fields[0] == record["name"] and int(fields[1]) == note and int(fields[2]) == record["impacts"]
        assert int(fields[4]) == hand_velocity(record["first_level_db"])
        assert line.endswith(f"{record['category']}: {record['description']}")


def corrupt_copy(built, tmp_path):
    folder = tmp_path / "lib"
    shutil.copytree(built[0], folder)
    csv = next(folder.glob("strokes-*/single.csv"))
    data = bytearray(csv.read_bytes())
    at = data.index(b"\n", data.index(b"\n") + 1) + 5  # a digit in the first row of numbers
    data[at] = ord("7") if data[at] != ord("7") else ord("3")
    csv.write_bytes(bytes(data))
    return folder


def test_a_corrupted_library_is_named_by_list_and_compose(built, tmp_path):
    folder = corrupt_copy(built, tmp_path)
    assert_one_line_error(run("library", "list", folder), "single.csv", "corrupt")
    pattern = tmp_path / "one.pattern"
    pattern.write_text("tempo 120\n0 single 100\n")
    assert_one_line_error(run("compose", pattern, "--library", folder), "single.csv", "corrupt")


def test_library_check_names_each_damaged_file_as_list_does_and_a_build_repairs_it(built, tmp_path):
    folder = tmp_path / "lib"
    shutil.copytree(built[0], folder)
    whole = run("library", "check", folder)
    assert whole.returncode == 0 and whole.stdout == f"{folder}: whole: 3 strokes at 500 Hz, 9 files as the manifest " \
                                                     "lists them\n", whole
    strokes = next(folder.glob("strokes-*"))
    (strokes / "single.json").unlink()
    data = bytearray((strokes / "tap.csv").read_bytes())
    data[-10] ^= 0x02
    (strokes / "tap.csv").write_bytes(bytes(data))
    (strokes / "notes.txt").write_text("mine")
    killed = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                            check=True)
    pid = int(killed.stdout)  # a process that ran and runs no more
    staging = folder / f".strokes.drumstroke-{pid}-0123abcd.tmp"
    staging.mkdir()  # the staging folder of a build killed before it finished
    result = run("library", "check", folder)
    assert result.returncode == 2 and result.stderr == "", result
    assert result.stdout.splitlines() == [
        f"library file {str(strokes / 'single.json')!r} is missing (stroke 'single')",
        f"library file {str(strokes / 'tap.csv')!r} is corrupt: its SHA-256 differs from the manifest's",
        f"library file {str(strokes / 'notes.txt')!r} is not in the manifest (an extra file in the stroke folder)",
        (f"note: {str(staging)!r}: a temporary folder of drumstroke process {pid}, which was stopped before it "
         "finished; the next run writing here removes it")]
    assert_one_line_error(run("library", "list", folder), f"library {str(folder)!r} has 3 problems",
                          *result.stdout.splitlines()[:3])
    rebuilt = run("library", "build", folder, "--rate", 500, "--palette", built[0].parent / "palette.toml")
    assert rebuilt.returncode == 0, rebuilt.stderr
    assert run("library", "check", folder).stdout == whole.stdout
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", strokes.name]


@pytest.mark.parametrize("args, needles", [(["--rate", "0"], ["--rate", "0.0", "[1, 100000]"]),
                                           (["--rate", "nan"], ["--rate", "nan"])])
def test_library_build_refuses_a_bad_rate(tmp_path, args, needles):
    assert_one_line_error(run("library", "build", tmp_path / "lib", *args), *needles)
    assert not (tmp_path / "lib" / "manifest.json").exists()


# --- compose -------------------------------------------------------------------------------------------------------

GROOVE = """\
# singles only, every note 0.25 s from the next on either stick, so each sounds alone
tempo 120
0    single  100
0.5  single  60   left
1    single  127
1.5  single  80   left
2    single  20         # 41 dB below the loudest: in the MIDI file, below the onset check's threshold
2.5  single  110  left
3    single  90
3.5  single  64   left
4    single  45         # 31 dB below the loudest
"""
GROOVE_NOTES = [(b / 2, s, v) for b, s, v in [(0, "right", 100), (0.5, "left", 60), (1, "right", 127),
                                              (1.5, "left", 80), (2, "right", 20), (2.5, "left", 110),
                                              (3, "right", 90), (3.5, "left", 64), (4, "right", 45)]]


@pytest.fixture(scope="module")
def composed(built, tmp_path_factory):
    folder = tmp_path_factory.mktemp("compose")
    (folder / "groove.pattern").write_text(GROOVE)
    paths = {key: folder / f"groove.{key}" for key in ("csv", "json", "wav", "mid", "png")}
    result = run("compose", folder / "groove.pattern", "--library", built[0], "--csv", paths["csv"],
                 "--json", paths["json"], "--wav", paths["wav"], "--midi", paths["mid"], "--plot", paths["png"])
    assert result.returncode == 0, result.stderr
    assert f"composed {len(GROOVE_NOTES)} of {len(GROOVE_NOTES)} notes" in result.stdout
    return paths, json.loads(paths["json"].read_text())


def test_compose_json_places_every_note(composed):
    _, data = composed
    assert data["problems"] == [] and data["rate"] == 500
    offset = data["offset"]
    assert offset * 500 == pytest.approx(round(offset * 500), abs=1e-9)
    assert [(n["time"], n["stick"], n["velocity"]) for n in data["notes"]] == GROOVE_NOTES
    assert all(n["played"] for n in data["notes"])
    assert [n["impact"] for n in data["notes"]] == pytest.approx([offset + t for t, _, _ in GROOVE_NOTES], abs=1e-9)


def test_compose_csv_has_theta_and_omega_per_stick_on_the_rate(composed, built):
    paths, data = composed
    header, table = read_csv(paths["csv"])
    assert header == ["t", "theta_right", "omega_right", "theta_left", "omega_left"]
    # groove.json is the JSON beside groove.csv: the CSV's metadata is in it, with where the score's time 0 is
    meta = data["csv"]
    assert (meta["rate"], meta["offset"], meta["sticks"], meta["columns"]) == (500.0, data["offset"], ["right", "left"],
                                                                               header)
    t = table[:, 0]
    assert t == pytest.approx(np.arange(len(t)) / 500.0, abs=1e-12)
    assert data["t_end"] - 1 / 500 < t[-1] <= data["t_end"]
    head = json.loads((built[0] / "manifest.json").read_text())["strokes"][0]["theta_max"]
    columns = {"right": table[:, 1:3], "left": table[:, 3:5]}
    for stick, (theta, omega) in ((s, c.T) for s, c in columns.items()):
        assert head - 1e-12 <= theta.min() and theta.max() <= math.pi / 2
        for time, note_stick, _ in GROOVE_NOTES:
            if note_stick == stick:
                k = round((data["offset"] + time) * 500)
                assert 0.0 <= theta[k] - head <= np.abs(omega).max() / 500


def test_compose_csv_of_one_stick_is_t_theta_omega(built, tmp_path):
    pattern = tmp_path / "solo.pattern"
    pattern.write_text("tempo 120\n0 single 100\n1 single 80\n")
    result = run("compose", pattern, "--library", built[0], "--csv", tmp_path / "solo.csv")
    assert result.returncode == 0, result.stderr
    header, table = read_csv(tmp_path / "solo.csv")
    assert header == ["t", "theta", "omega"] and table.shape[1] == 3
    assert f"wrote {tmp_path / 'solo.json'} (with the metadata of solo.csv)" in result.stdout
    assert json.loads((tmp_path / "solo.json").read_text())["csv"]["sticks"] == ["right"]


def test_compose_midi_round_trips_time_and_velocity(composed):
    """One note per audible impact, on the score's time (the JSON's impact times less the offset); the notes'
    first impacts at their time within 0.5 ms, on key 38 (singles only: no bounce), at their velocity ±1."""
    paths, data = composed
    impacts = sorted((row["t"] - data["offset"], row["level_db"]) for rows in data["impacts"].values() for row in rows)
    audible = [(t, level) for t, level in impacts if level >= FLOOR_DB]
    expected = [(time, velocity) for time, _, velocity in GROOVE_NOTES]

    ons = midi_note_ons(paths["mid"])
    assert len(ons) == len(audible)
    assert {(channel, note) for _, channel, note, _ in ons} == {(9, 38)}
    assert [t for t, _, _, _ in ons] == pytest.approx([t for t, _ in audible], abs=0.5e-3)
    assert ons[0][0] == 0.0  # the first note on the downbeat

    sticks = pretty_midi.PrettyMIDI(str(paths["mid"])).instruments
    assert [i.name for i in sticks] == ["right", "left"] and all(i.is_drum for i in sticks)
    notes = sorted((n for i in sticks for n in i.notes), key=lambda n: n.start)
    assert {n.pitch for n in notes} == {38}
    starts = np.array([n.start for n in notes])
    errors = []
    for time, velocity in expected:
        i = int(np.argmin(np.abs(starts - time)))
        errors.append(abs(starts[i] - time))
        assert abs(notes[i].velocity - velocity) <= 1, (time, notes[i].velocity, velocity)
        assert abs(ons[i][3] - velocity) <= 1
    assert max(errors) <= 0.5e-3, max(errors)


def test_compose_wav_has_an_onset_at_every_loud_impact(composed):
    """librosa's onset detector (hop 64, n_fft 512, 64 mel bands: 1.3 ms frames) finds an onset within ±5 ms
    of every impact louder than −30 dB of the loudest. Fair because the score has only single strokes (one
    impact each) at least 0.25 s apart, so every impact sounds alone; and every onset found is within ±5 ms
    of an impact."""
    paths, data = composed
    signal, rate = soundfile.read(paths["wav"])
    assert rate == 48000 and signal.ndim == 1
    assert np.abs(signal).max() <= 0.99 + 2.0**-23
    impacts = np.array(sorted((row["t"], row["level_db"]) for rows in data["impacts"].values() for row in rows))
    times, levels = impacts.T
    loud = times[levels >= levels.max() - 30.0]
    # 30 dB is 30·126/48 = 78.75 velocity steps: the notes at velocity 49 and up (not those at 20 and 45)
    assert loud == pytest.approx([data["offset"] + t for t, _, v in GROOVE_NOTES if v >= 127 - 78.75], abs=1e-9)
    envelope = librosa.onset.onset_strength(y=signal, sr=rate, hop_length=64, n_fft=512, n_mels=64)
    onsets = librosa.onset.onset_detect(onset_envelope=envelope, sr=rate, hop_length=64, units="time",
                                        backtrack=False)
    errors = [float(onsets[np.argmin(np.abs(onsets - t))] - t) for t in loud]
    print("onset errors (ms):", np.round(np.array(errors) * 1e3, 2))
    assert max(abs(e) for e in errors) <= 5e-3, errors
    assert all(np.min(np.abs(times - onset)) <= 5e-3 for onset in onsets), onsets


def test_compose_plot_is_a_png(composed):
    paths, _ = composed
    assert paths["png"].read_bytes()[:8] == PNG and paths["png"].stat().st_size > 10_000


# --- demo ----------------------------------------------------------------------------------------------------------

class Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.sections = [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag in ("img", "audio") and "src" in attrs:
            self.links.append(attrs["src"])
        elif tag == "a" and "href" in attrs:
            self.links.append(attrs["href"])
        elif tag == "section":
            self.sections.append(attrs.get("id"))


def test_demo_writes_a_page_whose_every_link_is_a_real_file(demo):
    result, out = demo
    assert result.returncode == 0, result.stderr
    page = Links()
    page.feed((out / "index.html").read_text(encoding="utf-8"))
    library = load_library(out / "library")
    assert len(library) >= 17
    rudiments = [f"{rudiment(name).number}-{name}" for name, _ in RUDIMENTS]
    assert page.sections == ["groove", *library, *rudiments, "fig-4", "fig-5", "fig-6", "fig-7"]
    # the groove: its sound, MIDI, CSV, JSON, pattern and picture; a stroke: sound, MIDI, picture; a rudiment:
    # sound, MIDI, JSON, picture; a figure: JSON, CSV, picture
    assert len(page.links) == 6 + 3 * len(library) + 4 * len(RUDIMENTS) + 3 * 4
    for link in page.links:
        path = out / link
        assert path.is_file() and path.stat().st_size > 0, link
        if link.endswith(".wav"):
            assert soundfile.info(path).samplerate == 48000, link
        elif link.endswith(".png"):
            assert path.read_bytes()[:8] == PNG, link
        elif link.endswith(".mid"):
            assert len(mido.MidiFile(path).tracks) >= 1, link
        elif link.endswith(".json"):
            assert json.loads(path.read_text())["model"] == "paper", link
        elif link.endswith((".csv", ".pattern")):
            assert path.read_text().count("\n") > 2, link
        else:
            pytest.fail(f"unexpected link {link}")
    groove = json.loads((out / "groove.json").read_text())
    assert groove["problems"] == []
    pattern = (out / "groove.pattern").read_text()
    notes = [line for line in pattern.splitlines() if line.split("#")[0].strip()][1:]  # after the tempo line
    assert len(groove["notes"]) == len(notes) and all(n["played"] for n in groove["notes"])
