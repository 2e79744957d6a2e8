"""Real songs' whole drum parts on the shipped kit: ``python benchmarks/kit_songs.py``.

Every General MIDI file of tests/data/midi with drums on channel 10 is read with the shipped kit and composed
with default options (``read_score(path, kit=default_kit())``, ``compose_kit(score)``), as
``drumstroke compose SONG.mid --kit`` does. For each song it prints the notes on the kit, those two hands and
two feet can play (all but a third hand note at one time and a foot's note while both its feet play another
at that instant), how many of those are played (%), the notes left out by the kind of reason, and the time to
compose (one run, after a warm-up on a three-note pattern). Writes the same, with the machine and date, to
benchmarks/kit_songs_results.json. Takes about ten seconds.
"""

import json
import subprocess
import time
from collections import Counter
from pathlib import Path

import mido
from _timing import machine, progress

from drumstroke.compose import compose_kit
from drumstroke.kit.pieces import FEET, default_kit
from drumstroke.score import parse_pattern, read_score

HERE = Path(__file__).resolve().parent
DATA = HERE.parent / "tests" / "data" / "midi"

UNPLAYABLE = {"third hand": "a third hand note at one time", "no foot free": "no foot is free"}
"""The reasons a note is beyond two hands and two feet, whatever they do: the start of its reason, by category."""

CATEGORIES = ("third hand", "no foot free", "no hand in time", "hand's move too slow", "stroke", "pedal")
"""The kinds of reason a note is left out for, in the order the table shows them."""


def category(outcome):
    """The kind of reason ``outcome``'s note is left out for (:data:`CATEGORIES`).

    No limb assigned: beyond two hands and two feet (:data:`UNPLAYABLE`), else no hand could get to it in time
    (the limb assignment's moves); assigned a hand: its move from its last piece does not fit before the throw,
    or else the stroke itself (the planner: notes too close, a throw beyond the force limit); a foot: its pedal.
    """
    reason = outcome.problem.reason
    for name, start in UNPLAYABLE.items():
        if reason.startswith(start):
            return name
    if outcome.limb is None:
        return "no hand in time"
    if outcome.limb in FEET:
        return "pedal"
    return "hand's move too slow" if "hand's move from" in reason else "stroke"


def has_drums(path):
    return any(m.type == "note_on" and m.velocity > 0 and m.channel == 9 for m in mido.MidiFile(path))


def song_row(path):
    """One song's figures: notes, playable, played, left out by category, compose time (s)."""
    score = read_score(path, kit=default_kit())
    start = time.perf_counter()
    piece = compose_kit(score)
    seconds = time.perf_counter() - start
    outcomes = piece.performance.outcomes
    left = Counter(category(o) for o in outcomes if not o.played)
    playable = len(outcomes) - sum(left[name] for name in UNPLAYABLE)
    played = sum(o.played for o in outcomes)
    return {"song": path.name, "channel_10": score.report.count(channel=10), "on_kit": len(outcomes),
            "playable": playable, "played": played, "played_of_playable": played / playable,
            "left_out": {name: left[name] for name in CATEGORIES if left[name]}, "compose_s": seconds}


def commit():
    try:
        done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], check=False, cwd=HERE, capture_output=True,
                              text=True, timeout=5)
    except OSError:
        return None
    return done.stdout.strip() or None


def table(rows):
    header = (f"{'song':<38} {'ch 10':>6} {'on kit':>6} {'playable':>8} {'played':>7} {'%':>6} {'compose':>8}"
              "  left out")
    lines = [header, "-" * len(header)]
    for r in rows:
        left = ", ".join(f"{name} {n}" for name, n in r["left_out"].items()) or "—"
        lines.append(f"{r['song']:<38} {r['channel_10']:>6} {r['on_kit']:>6} {r['playable']:>8} {r['played']:>7} "
                     f"{100 * r['played_of_playable']:>5.1f}% {r['compose_s']:>7.2f}s  {left}")
    played, playable = sum(r["played"] for r in rows), sum(r["playable"] for r in rows)
    lines.append(f"{'all':<38} {sum(r['channel_10'] for r in rows):>6} {sum(r['on_kit'] for r in rows):>6} "
                 f"{playable:>8} {played:>7} {100 * played / playable:>5.1f}%")
    return "\n".join(lines)


def main():
    songs = sorted(path for path in DATA.glob("*.mid") if has_drums(path))
    progress("warm-up (the compiled kernels' cache)")
    compose_kit(parse_pattern("tempo 120\n0 auto 100 auto kick\n0 auto 90 auto hihat\n1 auto 110 auto\n"))
    rows = []
    for path in songs:
        progress(f"  {path.name}")
        rows.append(song_row(path))
    print(table(rows))
    info = machine() | {"git_commit": commit()}
    (HERE / "kit_songs_results.json").write_text(json.dumps({"machine": info, "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
