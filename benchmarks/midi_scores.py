"""MIDI scores in and out, timed and measured: ``python benchmarks/midi_scores.py``.

For the three real General MIDI files of tests/data/midi and two long files made here (the
type-0 song played ten times over: 28,520 notes on 9 channels; and 20,000 snare notes), in
one process: reading the score (what is played and skipped), composing it with a small
library, then writing ``--midi`` and reading it back with mido and pretty_midi. Prints a
Markdown table: notes read, to play and skipped, notes composed (the others come too soon after
the one before on the stick), the time to read (the best of two runs) and to compose (the first
run: later ones find the moves between strokes cached), the peak memory of reading plus
composing (tracemalloc, a third run), and the largest error of a written note's time against
its impact's, by either reader. Takes about a minute.
"""

import tempfile
import time
import tracemalloc
from pathlib import Path

import mido
import numpy as np
import pretty_midi

from drumstroke.compose import compose
from drumstroke.dynamics import FLOOR_DB
from drumstroke.palette import motion
from drumstroke.palette.library import build_library, read_palette
from drumstroke.render.outputs import write_composition_outputs
from drumstroke.score import read_score

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "midi"
SONG = DATA / "d6caebd1964d9e4a3c5ea59525230e2a.mid"
STROKES = ("single", "tap", "double", "press-roll")


def ten_times(folder):
    """The type-0 song ten times over, a bar's rest between: 28,520 notes, 37 minutes, 650 tempo changes."""
    source = mido.MidiFile(SONG)
    messages = [m for m in source.tracks[0] if m.type != "end_of_track"]
    track = mido.MidiTrack()
    for i in range(10):
        track.extend(m.copy() for m in messages)
        if i < 9:
            track.append(mido.MetaMessage("marker", text=f"take {i + 2}", time=4 * source.ticks_per_beat))
    track.append(mido.MetaMessage("end_of_track"))
    path = folder / "song-ten-times.mid"
    mido.MidiFile(type=0, ticks_per_beat=source.ticks_per_beat, tracks=[track]).save(path)
    return path


def snare_notes(folder, count=20_000):
    """``count`` snare notes an eighth apart at 120 bpm (0.25 s), 38 and 40 mixed, six velocities (seeded)."""
    rng = np.random.default_rng(20261124)
    track = mido.MidiTrack()
    for i in range(count):
        key, velocity = (40 if i % 4 == 0 else 38), int(rng.choice([40, 64, 90, 100, 110, 127]))
        track.append(mido.Message("note_on", channel=9, note=key, velocity=velocity, time=0 if i == 0 else 230))
        track.append(mido.Message("note_off", channel=9, note=key, velocity=0, time=10))
    path = folder / f"snare-{count}.mid"
    mido.MidiFile(type=0, ticks_per_beat=480, tracks=[track]).save(path)
    return path


def measure(path, library, folder):
    motion._shortest_on_grid.cache_clear()  # each file's first compose from cold: no moves cached by another's
    motion._fits_once.cache_clear()
    reads, composes = [], []
    for _ in range(2):
        started = time.perf_counter()
        score = read_score(path, stroke_names=list(library))
        reads.append(time.perf_counter() - started)
        if score.notes:
            started = time.perf_counter()
            piece = compose(score, library)
            composes.append(time.perf_counter() - started)
    tracemalloc.start()
    score = read_score(path, stroke_names=list(library))
    if score.notes:
        piece = compose(score, library)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    report = score.report
    row = {"file": path.name, "notes": report.count(), "to play": report.played, "skipped": report.skipped,
           "read s": min(reads), "peak MB": peak / 1e6}
    if score.notes:
        written = folder / f"{path.stem}-out.mid"
        write_composition_outputs(piece, title=path.stem, midi=written)
        row |= {"composed": sum(p.played for p in piece.placements), "compose s": composes[0],
                "error ms": max(_error(piece, written, reader) for reader in (_mido_times, _pretty_midi_times)) * 1e3}
    return row


def _mido_times(path):
    """Note-on times (s), by mido's own clock over the merged tracks (iterating a MidiFile)."""
    times, now = [], 0.0
    for message in mido.MidiFile(path):
        now += message.time
        if message.type == "note_on" and message.velocity:
            times.append(now)
    return np.array(times)


def _pretty_midi_times(path):
    return np.array([n.start for i in pretty_midi.PrettyMIDI(str(path)).instruments for n in i.notes])


def _error(piece, path, reader):
    """The largest |note time - impact time| over every audible impact, all sticks together, in time order."""
    impacts = np.sort(np.concatenate([t[level >= FLOOR_DB] for t, level, _ in piece.stick_impacts().values()]))
    notes = np.sort(reader(path))
    if notes.size != impacts.size:
        raise AssertionError(f"{path}: {notes.size} notes for {impacts.size} impacts")
    return float(np.max(np.abs(notes - impacts))) if impacts.size else 0.0


def main():
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        library = build_library(folder / "lib", palette=[e for e in read_palette() if e.name in STROKES])
        files = [*sorted(DATA.glob("*.mid")), ten_times(folder), snare_notes(folder)]
        rows = [measure(path, library, folder) for path in files]
    columns = ["file", "notes", "to play", "skipped", "composed", "read s", "compose s", "peak MB", "error ms"]
    print("| " + " | ".join(columns) + " |")
    print("|" + "---|" * len(columns))
    for row in rows:
        print("| " + " | ".join(_cell(row.get(c, "-")) for c in columns) + " |")


def _cell(value):
    if isinstance(value, float):
        return f"{value:.3g}" if value < 100 else f"{value:,.0f}"
    return f"{value:,}" if isinstance(value, int) else str(value)


if __name__ == "__main__":
    main()
