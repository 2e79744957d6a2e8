"""The hostile corpus: every command and every kind of file, given what a careless user or an attacker would.

Each case runs the console script in a process of its own (:mod:`_hostile`) and must end with
exit status 2 and exactly one line on stderr that names the file or the option at fault, shows
no long value whole, is no "internal error" and no traceback; in under 1 GiB of memory and
10 s of CPU. The inputs: symlink loops, directories, FIFOs and devices where files are read or
written, files that are empty, truncated, binary, not UTF-8, one huge line, with a byte-order
mark, NaN, infinities, negative or misplaced numbers and wrong types in their fields, outputs
that are the run's own inputs (by name, by a link, by a hard link) and files of a bundle whose
publication did not finish. The campaign's figures are in docs/testing.md.
"""

import io
import json
import os
from pathlib import Path

import numpy as np
import pytest

from _hostile import FIFO, FOLDER, LOOP, Case, run_cases

MOST_MIB = 1024.0
"""The most memory a case may take (MiB): none of these inputs asks for more."""

MOST_CPU = 10.0
"""The most CPU time a case may take (s): generous, as the machine may be busy."""

LONGEST_LINE = 1200
"""The longest error line (characters): every value in it is shortened to 80."""

RECIPE = '[force]\nkind = "constant"\nvalue = 100.0\n'
PATTERN = "tempo 120\n0 auto 100\n"
BOM = "\ufeff"
HEADER = "subject,pair,robot,answer,confidence,similarity\n"
ONSETS = "t,level_db\n0,0\n0.1,-3\n0.18,-6\n0.24,-9\n"
HUGE = "x" * 10_000_000
"""A 10 MB value: no error line may show it whole."""


def trajectory(theta=0.1, rows=50):
    """A valid one-stick trajectory CSV: ``rows`` samples at 1 kHz holding ``theta`` (rad)."""
    return "t,theta,omega\n" + "".join(f"{i / 1000:.3f},{theta},0\n" for i in range(rows))


def midi(tempo=500_000, notes=((0, 38, 100),), cut=None):
    """A callable writing a type-1 MIDI file: a tempo, then notes (tick, key, velocity) on channel 10."""
    def write(path):
        import mido

        file = mido.MidiFile(type=1, ticks_per_beat=480)
        track = mido.MidiTrack([mido.MetaMessage("set_tempo", tempo=tempo)])
        now = 0
        for tick, key, velocity in notes:
            track.append(mido.Message("note_on", channel=9, note=key, velocity=velocity, time=tick - now))
            track.append(mido.Message("note_off", channel=9, note=key, velocity=0, time=10))
            now = tick + 10
        file.tracks.append(track)
        buffer = io.BytesIO()
        file.save(file=buffer)
        path.write_bytes(buffer.getvalue()[:cut])
    return write


def wav(samples=None, rate=48000, subtype="FLOAT", cut=None):
    """A callable writing a WAV file of ``samples`` (default: two decaying hits in 0.5 s), cut to ``cut`` bytes."""
    def write(path):
        import soundfile

        signal = samples
        if signal is None:
            t = np.arange(rate // 2) / rate
            signal = sum(a * np.where(t >= t0, np.exp(-(t - t0) / 0.02) * np.sin(2 * np.pi * 300 * (t - t0)), 0.0)
                         for t0, a in ((0.05, 0.8), (0.25, 0.4)))
        buffer = io.BytesIO()
        soundfile.write(buffer, np.asarray(signal, dtype=float), rate, subtype=subtype, format="WAV")
        path.write_bytes(buffer.getvalue()[:cut])
    return write


def nan_wav(at=1000):
    signal = np.zeros(24000)
    signal[5000] = 0.5
    signal[at] = np.nan
    return wav(signal)


def unfinished(*names):
    """A callable making the record of a killed writer's committed bundle listing ``names`` beside it."""
    def write(path):
        folder, pid = path.parent, 4_194_000  # beyond the ids a process gets here: a writer no longer running
        record = folder / f".files.drumstroke-{pid}-0123abcd.bundle"
        files = [[str(folder / n), str(folder / f".{n}.drumstroke-{pid}-{i:08x}.tmp")] for i, n in enumerate(names)]
        record.write_text(json.dumps({"records": [str(record)], "files": files}))
    return write


def hard_link(target):
    return lambda path: os.link(path.parent / target, path)


def case(id, files, *argv_and_needles):
    """A case: ``files``, then the command line, '|', then the texts its error must name."""
    split = argv_and_needles.index("|")
    return Case(id, files, tuple(argv_and_needles[:split]), tuple(argv_and_needles[split + 1:]))


_ROTATION = iter(range(1_000_000))


def reader_cases(kind, name, argv, *, base=None, text=True):
    """The same reader (``argv`` runs it on ``{d}/NAME``) given what is no file of its kind: a symlink loop, random
    bytes, (text) a 10 MB line and a byte-order mark before garbage, and two more in turn over the readers
    (a dangling link, a path under a file, a name too long, NUL bytes, UTF-8 cut mid-character); ``base`` holds
    the other files the command needs."""
    base = base or {}
    path = "{d}/" + name
    cases = [
        case(f"{kind}/symlink-loop", {**base, name: LOOP}, *argv, "|", path),
        case(f"{kind}/random-bytes", {**base, name: bytes(range(256)) * 64}, *argv, "|", path),
    ]
    if text:
        cases += [
            case(f"{kind}/huge-line", {**base, name: HUGE + "\n"}, *argv, "|", name),
            case(f"{kind}/bom-then-garbage", {**base, name: BOM + "=\n"}, *argv, "|", name),
        ]
    others = [
        case(f"{kind}/dangling-symlink", {**base, name: ("->", "{d}/nowhere")}, *argv, "|", name),
        case(f"{kind}/under-a-file", {**base, "file": "x\n"}, *[a.replace(path, "{d}/file/" + name) for a in argv],
             "|", "file/" + name),
        case(f"{kind}/name-too-long", base, *[a.replace(path, "{d}/" + "n" * 300 + name) for a in argv], "|", "nnnn"),
        case(f"{kind}/nul-bytes", {**base, name: b"\0" * 1000}, *argv, "|", name),
        case(f"{kind}/truncated-utf8", {**base, name: "tempo 120\n0 auto 100 caf\u00e9".encode()[:-1]}, *argv, "|",
             path),
    ]
    if path not in argv:  # a file the command finds through another: no path of it to change
        others = others[:1] + others[3:]
    turn = next(_ROTATION)
    return cases + [others[turn % len(others)], others[(turn + 2) % len(others)]]


def _cases():
    cases = []
    # every reader given what is no file of its kind
    cases += reader_cases("recipe", "r.toml", ["simulate", "{d}/r.toml"])
    cases += reader_cases("samples", "thumb.csv", ["simulate", "{d}/r.toml"],
                          base={"r.toml": '[force]\nkind = "samples"\nfile = "thumb.csv"\n'})
    cases += reader_cases("pattern", "p.pattern", ["compose", "{d}/p.pattern"])
    cases += reader_cases("midi", "s.mid", ["compose", "{d}/s.mid"], text=False)
    cases += reader_cases("mapping", "m.toml", ["compose", "{d}/s.mid", "--mapping", "{d}/m.toml"], base={"s.mid": midi()})
    cases += reader_cases("robot-config", "robot.toml", ["robot", "validate", "{d}/t.csv", "--config", "{d}/robot.toml"],
                          base={"t.csv": trajectory()})
    cases += reader_cases("trajectory", "t.csv", ["robot", "validate", "{d}/t.csv"])
    cases += reader_cases("responses", "a.csv", ["stats", "{d}/a.csv"])
    cases += reader_cases("palette", "pal.toml", ["library", "build", "{d}/lib", "--palette", "{d}/pal.toml"])
    cases += reader_cases("sweep", "g.toml", ["sweep", "{d}/g.toml", "--out", "{d}/o.csv"])
    cases += reader_cases("kit", "kit.toml", ["compose", "{d}/p.pattern", "--kit", "{d}/kit.toml"],
                          base={"p.pattern": PATTERN})
    cases += reader_cases("onsets", "on.csv", ["measure-cor", "{d}/on.csv"])
    cases += reader_cases("compare-b", "b.csv", ["compare", "{d}/a.csv", "{d}/b.csv"], base={"a.csv": ONSETS})
    cases += reader_cases("audio", "x.wav", ["onsets", "{d}/x.wav"], text=False)
    cases += reader_cases("live-score", "p.pattern", ["live", "--score", "{d}/p.pattern", "--csv"])

    # the issue's examples: the file and line of each error
    cases += [
        case("issue/samples-symlink-loop", {"r.toml": '[force]\nkind = "samples"\nfile = "s.csv"\n', "s.csv": LOOP},
             "simulate", "{d}/r.toml", "|", "{d}/r.toml", "s.csv", "symbolic links"),
        case("issue/pattern-10MB-line", {"p.pattern": "tempo 120\n0 single " + HUGE + "\n"}, "compose", "{d}/p.pattern",
             "|", "{d}/p.pattern line 2", "10000002 characters"),
        case("issue/toml-1MB-key", {"r.toml": "k" * 1_000_000 + " = 1\n" + RECIPE}, "simulate", "{d}/r.toml", "|",
             "{d}/r.toml", "characters)"),
        case("issue/toml-1MB-quoted-key", {"r.toml": '"' + "k" * 1_000_000 + '" = 1\n' + RECIPE}, "simulate",
             "{d}/r.toml", "|", "{d}/r.toml"),
        case("issue/compare-nan-in-a", {"a.wav": nan_wav(), "b.wav": wav()}, "compare", "{d}/a.wav", "{d}/b.wav", "|",
             "{d}/a.wav", "sample 1000"),
        case("issue/compare-nan-in-b", {"a.wav": wav(), "b.wav": nan_wav()}, "compare", "{d}/a.wav", "{d}/b.wav", "|",
             "{d}/b.wav", "sample 1000"),
        case("issue/onsets-inf-sample", {"x.wav": nan_wav(at=7)}, "onsets", "{d}/x.wav", "|", "{d}/x.wav", "sample 7"),
        case("issue/fit-nan-sample", {"x.wav": nan_wav(at=3)}, "fit", "{d}/x.wav", "--out", "{d}/r.toml", "|",
             "{d}/x.wav"),
        case("issue/measure-cor-nan-sample", {"x.wav": nan_wav(at=11)}, "measure-cor", "{d}/x.wav", "|", "{d}/x.wav"),
        case("issue/planned-notes-at-one-time", {"p.pattern": "tempo 120\n0 auto 100\n0 auto 100 right\n"}, "compose",
             "{d}/p.pattern", "|", "{d}/p.pattern line 3", "{d}/p.pattern line 2"),
        case("issue/planned-notes-0.1ms-apart", {"p.pattern": "tempo 120\n0 auto 100\n0.0002 auto 90 right\n"},
             "compose", "{d}/p.pattern", "|", "{d}/p.pattern line 3"),
        case("issue/pattern-tempo-1e-310", {"p.pattern": "tempo 1e-310\n0 auto 100\n"}, "compose", "{d}/p.pattern",
             "|", "{d}/p.pattern line 1", "tempo"),
        case("issue/live-score-tempo-1e-310", {"p.pattern": "tempo 1e-310\n0 auto 100\n"}, "live", "--score",
             "{d}/p.pattern", "--csv", "|", "{d}/p.pattern line 1"),
        case("issue/bom-pattern-bad-tempo", {"p.pattern": BOM + "tempo fast\n0 auto 100\n"}, "compose", "{d}/p.pattern",
             "|", "{d}/p.pattern line 1", "'fast'"),
        case("issue/bom-recipe-bad-cor", {"r.toml": BOM + "cor = 2.0\n" + RECIPE}, "simulate", "{d}/r.toml", "|",
             "{d}/r.toml", "cor"),
        case("issue/compose-midi-onto-itself", {"s.mid": midi()}, "compose", "{d}/s.mid", "--midi", "{d}/s.mid", "|",
             "--midi", "{d}/s.mid", "input"),
        case("issue/output-fifo", {"p.pattern": PATTERN, "o.json": FIFO}, "compose", "{d}/p.pattern", "--json",
             "{d}/o.json", "|", "--json", "{d}/o.json", "FIFO"),
        case("issue/output-device", {"p.pattern": PATTERN, "o.json": ("->", "/dev/null")}, "compose", "{d}/p.pattern",
             "--json", "{d}/o.json", "|", "--json", "{d}/o.json", "character device"),
        case("issue/validate-unfinished-bundle", {"t.csv": trajectory(), "t.json": "{}", "x": unfinished("t.csv",
             "t.json")}, "robot", "validate", "{d}/t.csv", "|", "{d}/t.csv", "publication did not finish"),
    ]

    # numbers and types in files: NaN, infinities, negatives, wrong types, each named by file and line or key
    recipe = lambda text: {"r.toml": text}
    cases += [case(f"recipe/{id}", recipe(text), "simulate", "{d}/r.toml", "|", "{d}/r.toml", key) for id, text, key in (
        ("cor-nan", f"cor = nan\n{RECIPE}", "cor"),
        ("cor-string", f'cor = "high"\n{RECIPE}', "cor"),
        ("cor-array", f"cor = [0.5]\n{RECIPE}", "cor"),
        ("cor-bool", f"cor = true\n{RECIPE}", "cor"),
        ("force-value-nan", '[force]\nkind = "constant"\nvalue = nan\n', "force.value"),
        ("force-kind-number", "[force]\nkind = 3\n", "kind"),
        ("force-not-table", "force = 3\n", "force"),
        ("gravity-inf", f'{RECIPE}[gravity]\nkind = "constant"\nvalue = -inf\n', "gravity.value"),
        ("stick-mass-negative", f"{RECIPE}[stick]\nmass = -0.05\n", "mass"),
        ("samples-file-number", '[force]\nkind = "samples"\nfile = 3\n', "force.file"),
        ("samples-file-directory", '[force]\nkind = "samples"\nfile = "."\n', "force.file"),
        ("pulses-amplitude-inf", '[force]\nkind = "pulses"\namplitude = inf\nperiod = 0.1\nduty = 0.5\n', "amplitude"),
        ("points-not-pairs", '[force]\nkind = "piecewise-linear"\npoints = [1, 2, 3]\n', "force.points"),
        ("points-nan", '[force]\nkind = "piecewise-linear"\npoints = [[0, 1], [nan, 2]]\n', "force.points"),
        ("sum-parts-empty", '[force]\nkind = "sum"\nparts = []\n', "parts"),
    )]
    cases += [
        case("samples/negative-time-nan", {"r.toml": '[force]\nkind = "samples"\nfile = "s.csv"\n',
                                           "s.csv": "t,value\n-inf,1\n0.1,2\n"}, "simulate", "{d}/r.toml", "|", "s.csv"),
        case("samples/bom-then-nan", {"r.toml": '[force]\nkind = "samples"\nfile = "s.csv"\n',
                                      "s.csv": BOM + "t,value\n0,nan\n"}, "simulate", "{d}/r.toml", "|", "s.csv"),
    ]
    pattern = lambda text: {"p.pattern": text}
    cases += [case(f"pattern/{id}", pattern(text), "compose", "{d}/p.pattern", "|", "{d}/p.pattern line " + line)
              for id, text, line in (
        ("velocity-0", "tempo 120\n0 single 0\n", "2"),
        ("velocity-float", "tempo 120\n0 single 99.5\n", "2"),
        ("beat-nan", "tempo 120\nnan single 100\n", "2"),
        ("beat-huge", "tempo 120\n1e300 single 100\n", "2"),
        ("tempo-inf", "tempo inf\n0 single 100\n", "1"),
        ("meter-after-notes", "tempo 120\n0 single 100\nmeter 3/4\n", "3"),
        ("meter-three", "tempo 120\nmeter 3/3\n0 single 100\n", "2"),
        ("buzz-length-inf", "tempo 120\n0 buzz 100 right -inf\n", "2"),
        ("length-on-single", "tempo 120\n0 single 100 right 2\n", "2"),
        ("piece-bad", "tempo 120\n0 single 100 right 9piece\n", "2"),
        ("seven-fields", "tempo 120\n0 single 100 right 1 snare extra\n", "2"),
        ("unknown-stroke", "tempo 120\n0 nosuch 100\n", "2"),
        ("tempo-twice", "tempo 120\ntempo 90\n0 single 100\n", "2"),
        ("crlf-bad-velocity", "tempo 120\r\n0 single 300\r\n", "2"),
    )]
    cases += [
        case("pattern/only-comments", pattern("# nothing\n\n# here\n"), "compose", "{d}/p.pattern", "|", "{d}/p.pattern"),
        case("pattern/tempo-no-notes", pattern("tempo 120\n"), "compose", "{d}/p.pattern", "|", "{d}/p.pattern"),
        case("midi/truncated-header", {"s.mid": midi(cut=10)}, "compose", "{d}/s.mid", "|", "{d}/s.mid"),
        case("midi/truncated-track", {"s.mid": midi(notes=[(i * 120, 38, 90) for i in range(20)], cut=60)}, "compose",
             "{d}/s.mid", "|", "{d}/s.mid"),
        case("midi/empty", {"s.mid": b""}, "compose", "{d}/s.mid", "|", "{d}/s.mid"),
        case("midi/bom-text", {"s.mid": BOM + PATTERN}, "compose", "{d}/s.mid", "|", "{d}/s.mid"),
        case("midi/channel-0", {"s.mid": midi()}, "compose", "{d}/s.mid", "--channel", "0", "|", "--channel"),
        case("midi/track-missing", {"s.mid": midi()}, "compose", "{d}/s.mid", "--track", "9", "|", "--track"),
        case("mapping/note-128", {"s.mid": midi(), "m.toml": '[notes]\n128 = "single"\n'}, "compose", "{d}/s.mid",
             "--mapping", "{d}/m.toml", "|", "{d}/m.toml"),
        case("mapping/stick-bad", {"s.mid": midi(), "m.toml": '[notes]\n38 = {stroke = "single", stick = "LEFT!"}\n'},
             "compose", "{d}/s.mid", "--mapping", "{d}/m.toml", "|", "{d}/m.toml", "stick"),
        case("mapping/notes-array", {"s.mid": midi(), "m.toml": "notes = [1, 2]\n"}, "compose", "{d}/s.mid",
             "--mapping", "{d}/m.toml", "|", "{d}/m.toml"),
        case("mapping/with-pattern", {"p.pattern": PATTERN, "m.toml": '[notes]\n38 = "single"\n'}, "compose",
             "{d}/p.pattern", "--mapping", "{d}/m.toml", "|", "--mapping"),
    ]
    config = lambda text: {"t.csv": trajectory(), "robot.toml": text}
    cases += [case(f"robot-config/{id}", config(text), "robot", "validate", "{d}/t.csv", "--config", "{d}/robot.toml",
                   "|", "{d}/robot.toml", key) for id, text, key in (
        ("max-speed-negative", "[limits]\nmax_speed = -1.0\n", "max_speed"),
        ("max-speed-string", '[limits]\nmax_speed = "fast"\n', "max_speed"),
        ("limits-array", "limits = [1, 2]\n", "limits"),
        ("unknown-table", "[engine]\nx = 1\n", "engine"),
        ("plant-inertia-inf", "[plant]\ninertia = inf\n", "inertia"),
    )]
    cases += [case(f"trajectory/{id}", {"t.csv": text}, "robot", "validate", "{d}/t.csv", "|", "{d}/t.csv", needle)
              for id, text, needle in (
        ("theta-inf", trajectory().replace("0.003,0.1,0", "0.003,inf,0"), "line 5"),
        ("time-backwards", trajectory().replace("0.004,", "0.002,"), "sample 4"),
        ("below-the-head", trajectory(theta=-1.0), "theta"),
        ("over-the-top", trajectory(theta=2.0), "theta"),
        ("header-only", "t,theta,omega\n", "t.csv"),
        ("wrong-header", "time,angle\n0,0\n", "t.csv"),
        ("bom-then-nan", BOM + trajectory().replace("0.010,0.1,0", "0.010,nan,0"), "t.csv"),
        ("semicolons", trajectory().replace(",", ";"), "t.csv"),
    )]
    cases += [
        case("trajectory/export-unfinished-bundle", {"t.csv": trajectory(), "x": unfinished("t.csv", "t.json")},
             "robot", "export", "{d}/t.csv", "--format", "csv", "--out", "{d}/o.csv", "|", "{d}/t.csv",
             "publication"),
        case("trajectory/track-a-loop", {"t.csv": LOOP}, "robot", "track", "{d}/t.csv", "|", "t.csv"),
    ]
    responses = lambda rows: {"a.csv": HEADER + rows}
    cases += [case(f"responses/{id}", responses(rows), "stats", "{d}/a.csv", "|", "{d}/a.csv", needle)
              for id, rows, needle in (
        ("confidence-nan", "s1,p1,A,B,nan,3\n", "line 2"),
        ("similarity-0", "s1,p1,A,B,3,0\n", "line 2"),
        ("answer-C", "s1,p1,A,C,3,3\n", "line 2"),
        ("short-row", "s1,p1,A\n", "line 2"),
        ("huge-subject", HUGE + ",p1,A,B,3,3\n", "a.csv"),
        ("bom-then-bad", "s1,p1,A,B,9,3\n", "line 2"),
    )]
    cases[-1] = case("responses/bom-then-bad", {"a.csv": BOM + HEADER + "s1,p1,A,B,9,3\n"}, "stats", "{d}/a.csv", "|",
                     "{d}/a.csv line 2")
    cases += [case(f"onsets/{id}", {"on.csv": text}, "measure-cor", "{d}/on.csv", "|", "on.csv", needle)
              for id, text, needle in (
        ("times-repeat", "t,level_db\n0,0\n0,-3\n", "line 3"),
        ("times-backwards", "t,level_db\n0,0\n0.2,-3\n0.1,-6\n", "line 4"),
        ("level-inf", "t,level_db\n0,0\n0.1,inf\n", "line 3"),
        ("time-text", "t,level_db\n0,0\nsoon,-3\n", "line 3"),
        ("bom-then-nan", BOM + "t,level_db\n0,0\n0.1,nan\n", "line 3"),
        ("header-only", "t,level_db\n", "{d}/on.csv': none"),
        ("level-positive", "t,level_db\n0,6\n0.1,0\n", "on.csv"),
    )]
    cases += [
        case("fit/onsets-times-repeat", {"on.csv": "t,level_db\n0,0\n0,-3\n"}, "fit", "{d}/on.csv", "--out",
             "{d}/r.toml", "|", "{d}/on.csv' line 3"),
        case("compare/a-times-repeat", {"a.csv": "t,level_db\n0,0\n0,-3\n", "b.csv": ONSETS}, "compare", "{d}/a.csv",
             "{d}/b.csv", "|", "{d}/a.csv' line 3"),
        case("compare/b-recipe-bad", {"a.csv": ONSETS, "b.toml": "cor = -1\n" + RECIPE}, "compare", "{d}/a.csv",
             "{d}/b.toml", "|", "{d}/b.toml", "cor"),
        case("audio/truncated-wav", {"x.wav": wav(cut=30)}, "onsets", "{d}/x.wav", "|", "{d}/x.wav"),
        case("audio/empty-wav", {"x.wav": b""}, "onsets", "{d}/x.wav", "|", "{d}/x.wav"),
        case("audio/text-wav", {"x.wav": BOM + PATTERN}, "compare", "{d}/x.wav", "{d}/x.wav", "|", "{d}/x.wav"),
    ]
    cases += [case(f"palette/{id}", {"pal.toml": text}, "library", "build", "{d}/lib", "--palette", "{d}/pal.toml", "|",
                   "{d}/pal.toml", needle) for id, text, needle in (
        ("stroke-not-array", 'stroke = "single"\n', "stroke"),
        ("name-bad", '[[stroke]]\nname = "A B"\nrecipe = "free-bounce"\n', "name"),
        ("recipe-missing-file", '[[stroke]]\nname = "a"\nrecipe = "none.toml"\n', "none.toml"),
        ("recipe-inline-bad", ('[[stroke]]\nname = "a"\n[stroke.recipe]\ncor = 3\n[stroke.recipe.force]\n'
                               'kind = "constant"\nvalue = 1.0\n'), "cor"),
        ("name-twice", '[[stroke]]\nname = "a"\nrecipe = "free-bounce"\n[[stroke]]\nname = "a"\nrecipe = "free-bounce"\n',
         "twice"),
    )]
    cases += [case(f"sweep/{id}", {"g.toml": text}, "sweep", "{d}/g.toml", "--out", "{d}/o.csv", "|", "{d}/g.toml",
                   needle) for id, text, needle in (
        ("cor-over-1", 'base = "constant"\n[parameters]\ncor = {start = 0.5, stop = 2, num = 3}\n', "cor"),
        ("num-negative", 'base = "constant"\n[parameters]\ncor = {start = 0.5, stop = 0.9, num = -3}\n', "num"),
        ("base-missing-file", 'base = "none.toml"\n[parameters]\ncor = [0.5]\n', "none.toml"),
        ("parameters-string", 'base = "constant"\nparameters = "cor"\n', "parameters"),
        ("mode-unknown", 'base = "constant"\nmode = "zigzag"\n[parameters]\ncor = [0.5]\n', "mode"),
    )]
    cases += [case(f"kit/{id}", {"p.pattern": PATTERN, "kit.toml": text}, "compose", "{d}/p.pattern", "--kit",
                   "{d}/kit.toml", "|", "{d}/kit.toml") for id, text in (
        ("pieces-string", 'pieces = "snare"\n'),
        ("no-limbs", "[pieces.snare]\nx = 1\n"),
        ("bom-no-limbs", BOM + "[pieces.snare]\nx = 1\n"),
    )]
    cases += [
        case("library/manifest-loop", {"lib": FOLDER, "lib/library.json": LOOP}, "library", "list", "{d}/lib", "|",
             "{d}/lib"),
        case("library/list-a-loop", {"lib": LOOP}, "library", "list", "{d}/lib", "|", "{d}/lib"),
        case("library/check-a-fifo", {"lib": FIFO}, "library", "check", "{d}/lib", "|", "{d}/lib"),
        case("library/simulate-from-a-loop", {"lib": LOOP}, "simulate", "single", "--library", "{d}/lib", "|",
             "--library"),
        case("library/build-onto-a-loop", {"lib": LOOP}, "library", "build", "{d}/lib", "|", "{d}/lib"),
    ]

    # outputs: FIFOs, devices, loops, the run's own inputs (by name, a link, a hard link)
    writers = [
        ("simulate-json", {}, ["simulate", "single", "--json"], "o.json"),
        ("simulate-csv", {}, ["simulate", "single", "--csv"], "o.csv"),
        ("simulate-midi", {}, ["simulate", "single", "--midi"], "o.mid"),
        ("simulate-audio", {}, ["simulate", "single", "--audio"], "o.wav"),
        ("simulate-plot", {}, ["simulate", "single", "--plot"], "o.png"),
        ("compose-csv", {"p.pattern": PATTERN}, ["compose", "{d}/p.pattern", "--csv"], "o.csv"),
        ("design-out", {}, ["design", "--times", "0,0.1", "--velocities", "90,80", "--out"], "o.toml"),
        ("rudiment-json", {}, ["rudiment", "1", "--bars", "1", "--json"], "o.json"),
        ("stats-json", {}, ["stats", "--summary", "4.227,2.654,4.999,1.564,22", "--json"], "o.json"),
        ("onsets-out", {"x.wav": wav()}, ["onsets", "{d}/x.wav", "--out"], "o.csv"),
        ("measure-cor-json", {"on.csv": ONSETS}, ["measure-cor", "{d}/on.csv", "--json"], "o.json"),
        ("compare-json", {"a.csv": ONSETS}, ["compare", "{d}/a.csv", "{d}/a.csv", "--json"], "o.json"),
        ("export-out", {"t.csv": trajectory()}, ["robot", "export", "{d}/t.csv", "--format", "csv", "--out"], "o.csv"),
        ("track-report", {}, ["robot", "track", "single", "--report"], "o.json"),
        ("sweep-out", {"g.toml": 'base = "constant"\n[parameters]\ncor = [0.5]\n'}, ["sweep", "{d}/g.toml", "--out"],
         "o.csv"),
    ]
    for id, files, argv, name in writers:
        option = next(a for a in reversed(argv) if a.startswith("--"))
        cases.append(case(f"write-fifo/{id}", {**files, name: FIFO}, *argv, "{d}/" + name, "|", option, name, "FIFO"))
    for id, files, argv, name in writers[::3]:
        option = next(a for a in reversed(argv) if a.startswith("--"))
        cases.append(case(f"write-device/{id}", {**files, name: ("->", "/dev/null")}, *argv, "{d}/" + name, "|", option,
                          "character device"))
    for id, files, argv, name in writers[1::3]:
        option = next(a for a in reversed(argv) if a.startswith("--"))
        cases.append(case(f"write-loop/{id}", {**files, name: LOOP}, *argv, "{d}/" + name, "|", option, name))
    cases += [
        case("same/compose-pattern-as-json", {"p.json": PATTERN}, "compose", "{d}/p.json", "--json", "{d}/p.json",
             "|", "--json", "input"),
        case("same/compose-midi-via-link", {"s.mid": midi(), "o.mid": ("->", "{d}/s.mid")}, "compose", "{d}/s.mid",
             "--midi", "{d}/o.mid", "|", "--midi", "input"),
        case("same/compose-midi-hard-link", {"s.mid": midi(), "o.mid": hard_link("s.mid")}, "compose", "{d}/s.mid",
             "--midi", "{d}/o.mid", "|", "--midi", "input"),
        case("same/compose-midi-dot-path", {"s.mid": midi()}, "compose", "{d}/s.mid", "--midi", "{d}/./s.mid", "|",
             "--midi", "input"),
        case("same/export-onto-input", {"t.csv": trajectory()}, "robot", "export", "{d}/t.csv", "--format", "csv",
             "--out", "{d}/t.csv", "|", "--out", "input"),
        case("same/simulate-csv-onto-samples", {"r.toml": '[force]\nkind = "samples"\nfile = "s.csv"\n',
                                                "s.csv": "t,value\n0,1\n0.1,2\n"}, "simulate", "{d}/r.toml", "--csv",
             "{d}/s.csv", "|", "--csv", "s.csv", "input"),
        case("same/simulate-json-onto-recipe", {"r.toml": RECIPE, "r.json": hard_link("r.toml")}, "simulate",
             "{d}/r.toml", "--json", "{d}/r.json", "|", "--json", "input"),
        case("same/onsets-out-onto-wav-sidecar", {"x.wav": wav(), "o.json": hard_link("x.wav")}, "onsets", "{d}/x.wav",
             "--out", "{d}/o.csv", "|", "o.json"),
        case("same/measure-cor-json-onto-input", {"on.json": ONSETS}, "measure-cor", "{d}/on.json", "--json",
             "{d}/on.json", "|", "--json", "input"),
        case("same/stats-json-onto-link", {"a.csv": HEADER + "s1,p1,A,B,3,3\n", "o.json": ("->", "{d}/a.csv")},
             "stats", "{d}/a.csv", "--json", "{d}/o.json", "|", "--json", "input"),
        case("same/compare-json-onto-b", {"a.csv": ONSETS, "b.json": ONSETS}, "compare", "{d}/a.csv", "{d}/b.json",
             "--json", "{d}/b.json", "|", "--json", "input"),
        case("same/fit-out-onto-recipe-input", {"on.csv": ONSETS, "r.toml": hard_link("on.csv")}, "fit", "{d}/on.csv",
             "--out", "{d}/r.toml", "|", "--out", "input"),
    ]

    # options: long values shortened, files named by options that are no files
    cases += [
        case("option/rate-100kB", {}, "simulate", "single", "--rate", "9" * 100_000, "|", "--rate"),
        case("option/model-100kB", {}, "simulate", "single", "--model", HUGE[:100_000], "|", "--model"),
        case("option/stroke-100kB", {}, "simulate", HUGE[:100_000], "|", "xxxx"),
        case("option/times-120kB", {}, "design", "--times", ",".join(["0.1"] * 30_000), "--velocities", "90", "|",
             "times"),
        case("option/config-loop", {"r": LOOP}, "rudiment", "1", "--config", "{d}/r", "|", "{d}/r"),
        case("option/config-fifo", {"r.toml": FIFO}, "rudiment", "1", "--config", "{d}/r.toml", "|", "{d}/r.toml"),
        case("option/config-directory", {"r.toml": FOLDER}, "robot", "track", "single", "--config", "{d}/r.toml", "|",
             "{d}/r.toml"),
        case("option/score-loop", {"p.pattern": LOOP}, "live", "--score", "{d}/p.pattern", "--csv", "|", "p.pattern"),
        case("option/db-loop", {"a.db": LOOP}, "listen", "analyze", "--db", "{d}/a.db", "|", "{d}/a.db"),
        case("option/library-directory-empty", {"lib": FOLDER}, "compose", "{d}/p.pattern", "--library", "{d}/lib",
             "|", "lib"),
        case("option/output-missing-folder-loop", {"loop": LOOP}, "simulate", "single", "--json", "{d}/loop/o.json",
             "|", "--json"),
    ]
    return cases


CASES = _cases()


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """Every case run once, two at a time."""
    return run_cases(CASES, tmp_path_factory.mktemp("hostile"), workers=2)


def test_the_corpus_is_large_and_its_ids_unique():
    assert len(CASES) >= 150
    assert len({c.id for c in CASES}) == len(CASES)


@pytest.mark.parametrize("id", [c.id for c in CASES])
def test_one_line_naming_the_input_exit_2(outcomes, id):
    outcome = outcomes[id]
    assert not outcome.killed, f"{id}: still running after 60 s"
    assert outcome.status == 2, f"{id}: exit {outcome.status}: {outcome.stderr[-2000:]}"
    assert len(outcome.lines) == 1, f"{id}: {outcome.stderr[-2000:]}"
    line = outcome.lines[0]
    assert ": error: " in line and "internal error" not in line and "Traceback" not in line, line[:2000]
    assert len(line) <= LONGEST_LINE, f"{id}: a line of {len(line)} characters"
    for needle in outcome.needles:
        assert needle in line or needle[:60] in line, f"{id}: {needle[:80]!r} not in {line[:2000]!r}"
    assert outcome.peak_mib < MOST_MIB, f"{id}: {outcome.peak_mib:.0f} MiB"
    assert outcome.cpu_seconds < MOST_CPU, f"{id}: {outcome.cpu_seconds:.1f} s of CPU"


def test_the_campaign_figures(outcomes, capsys):
    """The figures docs/testing.md gives (printed with -s): the cases, the peak memory, the longest times."""
    def most(measure):
        id = max(outcomes, key=lambda id: getattr(outcomes[id], measure))
        return f"{getattr(outcomes[id], measure):.2f} ({id})"

    with capsys.disabled():
        print(f"\n{len(outcomes)} hostile cases: peak memory {most('peak_mib')} MiB, most CPU {most('cpu_seconds')} s, "
              f"longest wall {most('wall_seconds')} s")
    assert len(outcomes) == len(CASES)


@pytest.mark.parametrize("files, argv", [
    ({"p.pattern": BOM + PATTERN}, ["compose", "p.pattern", "--json", "o.json"]),
    ({"r.toml": BOM + RECIPE}, ["simulate", "r.toml"]),
    ({"on.csv": BOM + ONSETS}, ["measure-cor", "on.csv"]),
    ({"a.csv": BOM + HEADER + "s1,p1,A,B,3,3\ns2,p1,A,A,4,2\n"}, ["stats", "a.csv"]),
    ({"t.csv": BOM + trajectory()}, ["robot", "validate", "t.csv"]),
    ({"robot.toml": BOM + "[limits]\n", "t.csv": trajectory()}, ["robot", "validate", "t.csv", "--config", "robot.toml"]),
])
def test_a_byte_order_mark_is_read_past(tmp_path, files, argv):
    """Text files that start with a byte-order mark (a Windows editor's) read as without it: patterns, TOML, CSV."""
    from _cli import run

    for name, text in files.items():
        (tmp_path / name).write_text(text)
    done = run(*argv, cwd=tmp_path)
    assert done.returncode == 0, done.stderr


def test_json_with_a_byte_order_mark_reads(tmp_path):
    from drumstroke.formats.json import read_json

    path = tmp_path / "x.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps({"a": [1, 2]}).encode())
    assert read_json(path, "x") == {"a": [1, 2]}
    assert Path(path).read_bytes()[:3] == b"\xef\xbb\xbf"
