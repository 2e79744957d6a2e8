"""The workflows the command line runs, used from Python as a user would: robot config, trajectory sources,
score reading, output bundles, listening-test stimuli and the demo. Files are checked with independent
readers (csv, json, tomllib, soundfile, mido, PNG magic bytes), not with the writers' own code."""

import csv
import json
import re
import shutil
import tomllib
from html.parser import HTMLParser

import mido
import numpy as np
import pytest
import soundfile

import drumstroke
from drumstroke.cli import main
from drumstroke.compose import compose
from drumstroke.errors import ParameterError, SampledImpactsWarning
from drumstroke.evaluation.app import Config
from drumstroke.evaluation.stimuli import make_stimuli
from drumstroke.palette.library import build_library, load_library, read_palette
from drumstroke.palette.motion import Limits
from drumstroke.render.data import write_csv
from drumstroke.render.outputs import write_composition_outputs, write_stroke_outputs
from drumstroke.robot.config import RobotConfig, load_source
from drumstroke.robot.controllers import CONTROLLERS
from drumstroke.robot.plant import Plant
from drumstroke.score import parse_pattern, read_score

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """A small library: the shipped palette's single and double strokes, in that order."""
    folder = tmp_path_factory.mktemp("library")
    build_library(folder, palette=[e for e in read_palette() if e.name in ("single", "double")])
    return folder


def read_csv_columns(path):
    """{column: values} of a CSV whose comment lines start with '#', read with the csv module."""
    with open(path, newline="") as handle:
        rows = list(csv.reader(line for line in handle if not line.startswith("#")))
    return {name: np.array([float(row[i]) for row in rows[1:]]) for i, name in enumerate(rows[0])}


def midi_note_ons(path):
    """(time s, channel 0-15, note, velocity) of every note_on of a MIDI file, timed by mido."""
    notes, seconds = [], 0.0
    for message in mido.MidiFile(path):  # iterating a MidiFile yields delta times in seconds
        seconds += message.time
        if message.type == "note_on" and message.velocity > 0:
            notes.append((seconds, message.channel, message.note, message.velocity))
    return notes


# --- robot config --------------------------------------------------------------------------------------------------

def test_a_robot_config_file_sets_the_plant_one_controller_and_the_limits(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text("[plant]\ngear_ratio = 10.0\n[plant.stick]\nmass = 0.05\n"
                    "[controller.pi]\nkp = 5.0\n[limits]\nmax_speed = 20.0\n")
    config = RobotConfig.from_toml(path)
    assert config.plant.gear_ratio == 10.0 and config.plant.stick.mass == 0.05
    assert config.plant.max_torque == Plant().max_torque
    assert list(config.controllers) == list(CONTROLLERS)
    assert config.controllers["pi"].kp == 5.0
    assert config.controllers["impedance"] == CONTROLLERS["impedance"]()
    assert config.limits.max_speed == 20.0 and config.limits.max_jerk == Limits().max_jerk
    assert RobotConfig.from_dict(config.to_dict()) == config


def test_the_default_robot_config_is_every_default_and_read_only():
    config = RobotConfig()
    assert config.plant == Plant() and config.limits == Limits()
    assert config == RobotConfig.from_dict({})
    assert {name: type(law) for name, law in config.controllers.items()} == CONTROLLERS
    with pytest.raises(TypeError):
        config.controllers["pi"] = CONTROLLERS["impedance"]()


@pytest.mark.parametrize("text, match", [
    ("[wheels]\ncount = 4\n", "robot config has unknown key 'wheels'"),
    ("[plant]\nwheels = 4\n", "plant has unknown key 'wheels'"),
    ("controller = 3\n", "controller must be a table of"),
    ("[controller.lqr]\nkp = 1.0\n", "controller has unknown key 'lqr'"),
    ("[limits]\nmax_speed = -1.0\n", r"limits.max_speed must be in \(0, inf\) rad/s"),
    ("[plant\n", "is not valid TOML"),
])
def test_a_bad_robot_config_is_refused_naming_what_is_wrong(tmp_path, text, match):
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        RobotConfig.from_toml(path)


def test_a_source_is_a_preset_a_library_stroke_or_a_trajectory_csv(library, tmp_path):
    preset = load_source("free-bounce")
    assert preset.name == "free-bounce" and len(preset.impacts) == len(drumstroke.simulate("free-bounce").impacts)
    stroke = load_source("double", library=library)
    (record,) = [r for r in json.loads((library / "manifest.json").read_text())["strokes"] if r["name"] == "double"]
    assert stroke.name == "double" and len(stroke.impacts) == record["impacts"] > 1
    assert stroke.impacts.t[0] == pytest.approx(record["first_impact"], abs=1e-9)
    write_csv(preset, tmp_path / "bounce.csv", rate=2000.0)
    with pytest.warns(SampledImpactsWarning, match="found again in its samples"):  # no JSON records them
        sampled = load_source(tmp_path / "bounce.csv")
    assert sampled.name == "bounce" and sampled.model == "paper"
    audible = preset.impacts.t[preset.impacts.tip_speed > 0.05]
    found = sampled.impacts.t
    assert all(np.min(np.abs(found - t)) < 1e-3 for t in audible)
    with pytest.raises(ParameterError, match="'triple' is not in the library"):
        load_source("triple", library=library)


# --- scores --------------------------------------------------------------------------------------------------------

@pytest.fixture
def midi_score(tmp_path):
    """A type 1 MIDI file: 120 bpm, then 60 bpm from beat 2 (1 s); notes 38, 61, 37, 38 on beats 0, 1, 2, 3."""
    conductor = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=500_000, time=0),
                                mido.MetaMessage("set_tempo", tempo=1_000_000, time=960)])
    drums = mido.MidiTrack()
    for note, velocity in ((38, 100), (61, 70), (37, 50), (38, 90)):
        drums.append(mido.Message("note_on", channel=9, note=note, velocity=velocity, time=0))
        drums.append(mido.Message("note_off", channel=9, note=note, velocity=0, time=480))
    path = tmp_path / "score.mid"
    mido.MidiFile(type=1, ticks_per_beat=480, tracks=[conductor, drums]).save(path)
    return path


def test_a_midi_score_goes_through_the_default_mapping_with_its_tempo_change(midi_score):
    score = read_score(midi_score, stroke_names=["single", "double"])
    # on channel 10, the drum map: 38 and 37 (side stick) are notes the planner designs, on sticks it chooses; 61
    # is a General MIDI bongo there, not a library stroke (it is on other channels: 60 + i is the i-th stroke)
    assert [(n.time, n.stroke, n.velocity, n.stick) for n in score.notes] == [
        (0.0, "auto", 100, None), (1.0, "auto", 50, None), (2.0, "auto", 90, None)]
    assert score.report.counts == {("played", 10): 3, ("unmapped", 10): 1}
    assert score.tempo_map.tempi == ((0.0, 500_000), (2.0, 1_000_000))


def test_a_midi_score_goes_through_a_mapping_file_or_a_dict(midi_score, tmp_path):
    mapping = tmp_path / "mapping.toml"
    mapping.write_text('[notes]\n37 = { stroke = "double", stick = "left" }\n')
    score = read_score(midi_score, mapping=mapping, stroke_names=["single", "double"])
    assert [(n.time, n.stroke, n.velocity, n.stick) for n in score.notes] == [(1.0, "double", 50, "left")]
    assert score.report.counts == {("played", 10): 1, ("unmapped", 10): 3}
    score = read_score(midi_score, mapping={38: ("single", "left")})
    assert [(n.time, n.stick) for n in score.notes] == [(0.0, "left"), (2.0, "left")]
    assert score.report.count("unmapped") == 2
    assert [n.stroke for n in read_score(midi_score).notes] == ["auto"] * 3  # the drum map needs no library


def test_a_pattern_names_its_strokes_and_refuses_a_mapping(tmp_path):
    pattern = tmp_path / "beat.pattern"
    pattern.write_text("tempo 60\n0 single 100\n1.5 double 80 left\n")
    score = read_score(pattern)
    assert [(n.time, n.stroke, n.velocity, n.stick) for n in score.notes] == [
        (0.0, "single", 100, "right"), (1.5, "double", 80, "left")]
    assert score.report.skipped == 0
    with pytest.raises(ParameterError, match=r"^mapping applies to MIDI scores \(\.mid, \.midi\)"):
        read_score(pattern, mapping=tmp_path / "mapping.toml")


def test_the_command_names_the_mapping_option_it_refuses(library, tmp_path, capsys):
    pattern = tmp_path / "beat.pattern"
    pattern.write_text("tempo 60\n0 single 100\n")
    (tmp_path / "m.toml").write_text('[notes]\n38 = "single"\n')
    assert main(["compose", str(pattern), "--library", str(library), "--mapping", str(tmp_path / "m.toml")]) == 2
    assert capsys.readouterr().err.startswith("drumstroke compose: error: --mapping applies to MIDI scores")


# --- output bundles ------------------------------------------------------------------------------------------------

def test_a_stroke_bundle_is_five_files_that_other_readers_open(tmp_path, capsys):
    stroke = drumstroke.simulate("free-bounce")
    names = {key: tmp_path / f"bounce.{suffix}" for key, suffix in
             (("json", "json"), ("csv", "csv"), ("plot", "png"), ("audio", "wav"), ("midi", "mid"))}
    written = write_stroke_outputs(stroke, **names, rate=500.0, title="a bounce")
    assert written == [names[key] for key in ("json", "csv", "plot", "audio", "midi")]
    assert capsys.readouterr() == ("", "")

    data = json.loads(names["json"].read_text())
    assert [i["t"] for i in data["impacts"]] == pytest.approx(stroke.impacts.t, abs=1e-12)
    columns = read_csv_columns(names["csv"])
    assert list(columns) == ["t", "theta", "omega"]
    assert np.allclose(np.diff(columns["t"]), 1 / 500.0) and columns["t"][-1] == pytest.approx(stroke.t_end)
    assert columns["theta"].min() >= stroke.recipe.theta_max - 1e-9
    assert names["plot"].read_bytes()[:8] == PNG
    audio, rate = soundfile.read(names["audio"])
    assert rate == 48000 and audio.ndim == 1 and len(audio) / rate > stroke.impacts.t[-1]
    first = int(stroke.impacts.t[0] * rate)
    assert np.max(np.abs(audio[:first - 48])) < 1e-6 < np.max(np.abs(audio[first:first + 480]))
    notes = midi_note_ons(names["midi"])
    assert [(channel, note) for _, channel, note, _ in notes] == [(9, 38)] + [(9, 40)] * (len(notes) - 1)
    assert notes[0][0] == pytest.approx(stroke.impacts.t[0], abs=1e-3)  # the stroke's own time
    assert 1 < len(notes) <= len(stroke.impacts)


def test_a_bundle_writes_only_what_it_is_given(tmp_path):
    assert write_stroke_outputs(drumstroke.simulate("constant")) == []
    assert write_stroke_outputs(drumstroke.simulate("constant"), midi=tmp_path / "c.mid") == [tmp_path / "c.mid"]
    assert [p.name for p in tmp_path.iterdir()] == ["c.mid"]


def test_a_composition_bundle_has_a_column_pair_per_stick_and_its_notes_on_time(library, tmp_path):
    piece = compose(parse_pattern("tempo 120\n0 single 100\n1 double 80 left\n2 single 60\n"), load_library(library))
    names = {key: tmp_path / f"piece.{suffix}" for key, suffix in
             (("csv", "csv"), ("json", "json"), ("plot", "png"), ("audio", "wav"), ("midi", "mid"))}
    written = write_composition_outputs(piece, title="piece", **names, snares=False)
    assert written == [names[key] for key in ("csv", "json", "plot", "audio", "midi")]

    columns = read_csv_columns(names["csv"])
    assert list(columns) == ["t", "theta_right", "omega_right", "theta_left", "omega_left"]
    assert np.allclose(np.diff(columns["t"]), 1 / piece.rate)
    data = json.loads(names["json"].read_text())
    assert len(data["notes"]) == 3 and all(note["played"] for note in data["notes"])
    assert names["plot"].read_bytes()[:8] == PNG
    info = soundfile.info(names["audio"])
    assert info.samplerate == 48000 and info.channels == 1 and info.duration > piece.offset + 1.0
    onsets = [(t, note) for t, _, note, _ in midi_note_ons(names["midi"])]
    assert piece.offset > 0.0  # the trajectory has a lead-in; the MIDI file is on the score's time
    assert [(round(t, 9), note) for t, note in onsets if note == 38] == [(0.0, 38), (0.5, 38), (1.0, 38)]


# --- stimuli -------------------------------------------------------------------------------------------------------

def test_stimuli_are_robot_recordings_and_a_config_the_app_reads(library, tmp_path):
    done = []
    made = make_stimuli(library, tmp_path / "stimuli", progress=done.append)
    assert [s.name for s in made.stimuli] == ["single", "double"] and done[-1] == 1.0
    for stimulus in made.stimuli:
        audio, rate = soundfile.read(stimulus.path)
        assert rate == 48000 and np.max(np.abs(audio)) > 0.01 and stimulus.onsets >= 1
        shutil.copy(stimulus.path, made.config.parent / f"human-{stimulus.name}.wav")  # as if recorded
    pairs = tomllib.loads(made.config.read_text())["pair"]
    assert [(p["id"], p["robot"]) for p in pairs] == [("single", "robot-single.wav"), ("double", "robot-double.wav")]
    config = Config.from_toml(made.config)
    assert [p.id for p in config.pairs] == ["single", "double"]
    # the export's token: new for each config, 43 random URL-safe characters, the file readable by its owner only
    again = make_stimuli(library, tmp_path / "again", strokes=["single"])
    assert re.fullmatch(r"[A-Za-z0-9_-]{43}", config.admin_token)
    assert tomllib.loads(again.config.read_text())["admin_token"] != config.admin_token
    assert made.config.stat().st_mode & 0o777 == 0o600


def test_stimuli_check_every_stroke_name_before_writing(library, tmp_path):
    with pytest.raises(ParameterError, match="'tap' is not in the library"):
        make_stimuli(library, tmp_path / "stimuli", strokes=["double", "tap"])
    assert not (tmp_path / "stimuli").exists()
    made = make_stimuli(load_library(library), tmp_path / "stimuli", strokes=["double"])
    assert [p.name for p in sorted((tmp_path / "stimuli").iterdir())] == ["listening-test.toml", "robot-double.wav"]
    assert len(made.stimuli) == 1


# --- the demo ------------------------------------------------------------------------------------------------------

class Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.links += [attrs[key] for key in ("src", "href") if key in attrs and tag in ("img", "audio", "a")]


class Structure(HTMLParser):
    """What a valid HTML5 page needs of its structure: a doctype, every element closed in order, ids unique."""

    VOID = frozenset({"meta", "img", "br", "hr", "link", "input", "source"})

    def __init__(self):
        super().__init__()
        self.open, self.ids, self.errors, self.doctype, self.seen = [], [], [], None, []

    def handle_decl(self, decl):
        self.doctype = decl

    def handle_starttag(self, tag, attrs):
        self.seen.append((tag, dict(attrs)))
        self.ids += [value for key, value in attrs if key == "id"]
        if tag not in self.VOID:
            self.open.append(tag)

    def handle_endtag(self, tag):
        if not self.open or self.open.pop() != tag:
            self.errors.append(f"</{tag}> closes nothing open")


def test_the_demo_writes_a_page_whose_links_are_files_and_returns_what_it_made(tmp_path):
    from drumstroke.demo import run_demo

    done = []
    demo = run_demo(tmp_path / "demo", progress=done.append)
    assert done == sorted(done) and done[-1] == 1.0
    text = demo.index.read_text(encoding="utf-8")
    structure = Structure()
    structure.feed(text)
    structure.close()
    assert structure.doctype == "DOCTYPE html" and structure.errors == [] and structure.open == []
    assert len(structure.ids) == len(set(structure.ids)) and all(" " not in i for i in structure.ids)
    assert ("html", {"lang": "en"}) in structure.seen and ("meta", {"charset": "utf-8"}) in structure.seen
    assert all(attrs.get("alt") for tag, attrs in structure.seen if tag == "img")
    assert re.search(r"\b1 impact in", text) and not re.search(r"\b1 impacts", text)  # 'single' has one impact
    page = Links()
    page.feed(text)
    assert sorted(page.links) == sorted(p.relative_to(demo.outdir).as_posix() for p in (
        *demo.groove, *demo.strokes, *demo.rudiments, *(path for f in demo.figures for path in f.paths)))
    for link in page.links:
        path = demo.outdir / link
        if link.endswith(".png"):
            assert path.read_bytes()[:8] == PNG, link
        elif link.endswith(".wav"):
            assert soundfile.info(path).samplerate == 48000, link
        elif link.endswith(".mid"):
            assert mido.MidiFile(path).tracks, link
        else:
            assert link.endswith((".json", ".csv", ".pattern")) and path.stat().st_size > 0, link
    assert [f.preset for f in demo.figures] == ["free-bounce", "low-high", "high-low", "finger-pulses"]
    for figure in demo.figures:
        assert [p.suffix for p in figure.paths] == [".json", ".csv", ".png"]
        assert len(json.loads(figure.paths[0].read_text())["impacts"]) == len(figure.stroke.impacts)
    assert list(load_library(demo.outdir / "library")) == list(demo.library)
    groove = json.loads((demo.outdir / "groove.json").read_text())
    assert demo.played == sum(n["played"] for n in groove["notes"]) == len(demo.piece.placements)
