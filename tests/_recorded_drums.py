"""Recorded drums with known times: General MIDI SoundFonts' snares played by FluidSynth, for tests and benchmarks.

The recordings (48 kHz, 5 s each, seeded) are snare notes (keys 38 and 40) on FluidR3_GM and
TimGM6mb, in four sets:

- ``singles``: isolated strokes, velocities 30-127, each ending in digital silence before the next;
- ``drop``: a dropped stick, intervals ×0.86 from 0.25 s, the level falling 1.3 dB a bounce
  (the velocity nearest), two drops a recording;
- ``roll``: accents (velocity 95-127) each followed by one or two ghost notes (30-60) 50-120 ms after it;
- ``flams``: a grace note (velocity 30-70) 15-30 ms before a main note (90-127);

in four conditions: ``dry``; ``noise72`` and ``noise60`` (white noise at -72 and -60 dBFS RMS added
to the dry recording); ``reverb`` (FluidSynth's own reverb on).

The truth of a note is where it starts when it is rendered alone: its first sample above -40 dB of its
own peak. FluidSynth starts a note at a 64-sample block boundary, the block after the one whose
player clock (whole milliseconds, rounded to MIDI ticks) reaches the note's tick (:func:`note_block`:
it depends on the time, not only on it modulo 64 samples or 1 ms), and the sample's lead-in
before that threshold depends on the SoundFont, the key and the velocity only. So the truth is
``note_block(t) + lead(font, key, velocity)``; the leads (and each note's peak, for its level)
are measured once by rendering the note alone and cached in ``tests/data/soundfont_leads.json``;
``test_recorded_onsets.py`` checks the sum against notes rendered alone at random times.
"""

import json
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

RATE = 48000
SECONDS = 5.0
FONTS = {"FluidR3": Path("/usr/share/sounds/sf2/FluidR3_GM.sf2"), "TimGM6mb": Path("/usr/share/sounds/sf2/TimGM6mb.sf2")}
KEYS = (38, 40)
SETS = ("singles", "drop", "roll", "flams")
CONDITIONS = ("dry", "noise72", "noise60", "reverb")
NOISE_DBFS = {"noise72": -72.0, "noise60": -60.0}
TRUTH_DB = -40.0  # a note starts at its first sample above this, re its own peak
LOUD_DB = 30.0  # the notes scored: within this of the recording's loudest
BLOCK = 64  # FluidSynth's samples a block
TICKS_PER_SECOND = 3840  # drumstroke's MIDI files: 1920 ticks a beat at 120 bpm
_CACHE = Path(__file__).parent / "data" / "soundfont_leads.json"
_REFERENCE = 0.1  # s: where a note is rendered alone to measure its lead


def note_block(t, rate=RATE):
    """The sample at which FluidSynth starts a note written at ``t`` s: a block boundary.

    Its player runs once a block, before the block, at the block's start in whole milliseconds
    (truncated), and plays the notes whose tick is at most that time in ticks (rounded); the voice
    sounds from the next block on.
    """
    tick = round(t * TICKS_PER_SECOND)
    per_ms = TICKS_PER_SECOND / 1000.0
    block = max(0, int(tick / per_ms * rate / 1000.0 / BLOCK) - 3)
    while round(math.floor(block * BLOCK * 1000.0 / rate) * per_ms) < tick:
        block += 1
    return (block + 1) * BLOCK


def speed_of(velocity):
    """The tip speed (m/s) that drumstroke writes as MIDI ``velocity``."""
    from drumstroke.dynamics import velocity_to_level

    return 10.0 ** (velocity_to_level(velocity) / 20.0)


def first_above(x, db=TRUTH_DB):
    """The first sample of ``x`` above ``db`` re its peak."""
    magnitude = np.abs(x)
    return int(np.flatnonzero(magnitude >= magnitude.max() * 10.0 ** (db / 20.0))[0])


def render_alone(font, key, velocity, t, *, duration=0.4):
    """One note rendered alone at ``t`` s (``duration`` s after it): the samples."""
    from drumstroke.render.soundfont import render_soundfont

    return render_soundfont([(t, "snare", key, speed_of(velocity))], FONTS[font], duration=t + duration, rate=RATE)


class Leads:
    """Each (font, key, velocity)'s lead-in (samples from its block to its truth) and peak, measured alone, cached."""

    def __init__(self, path=_CACHE):
        self.path = path
        self.table = json.loads(path.read_text()) if path.is_file() else {}
        self.dirty = False

    def __call__(self, font, key, velocity):
        name = f"{font} {key} {velocity}"
        if name not in self.table:
            x = render_alone(font, key, velocity, _REFERENCE)
            self.table[name] = [first_above(x) - note_block(_REFERENCE), float(np.abs(x).max())]
            self.dirty = True
        lead, peak = self.table[name]
        return lead, peak

    def save(self):
        if self.dirty:
            self.path.write_text(json.dumps(dict(sorted(self.table.items())), indent=0) + "\n")
            self.dirty = False


@dataclass(frozen=True)
class Recording:
    """One recording and its truth: ``t`` (s) and ``level_db`` (each note's own peak, dB re the loudest's)."""

    font: str
    key: int
    set: str
    condition: str
    signal: np.ndarray
    t: np.ndarray
    level_db: np.ndarray

    @property
    def name(self):
        return f"{self.font} {self.key} {self.set} {self.condition}"


def notes(set_name, seed):
    """The notes of a set: (time s, velocity) pairs, in time order, within :data:`SECONDS` less 0.7 s."""
    rng = np.random.default_rng(seed)
    end = SECONDS - 0.7
    out = []
    if set_name == "singles":
        for t in np.arange(0.2, end, 0.7):  # every note dies away (≤ 0.63 s) before the next
            out.append((t + rng.uniform(0.0, 0.01), int(rng.integers(30, 128))))
    elif set_name == "drop":
        from drumstroke.dynamics import level_to_velocity, velocity_to_level

        for start in (0.2, 2.3):
            level, t, interval = velocity_to_level(int(rng.integers(105, 128))), start + rng.uniform(0, 0.01), 0.25
            while interval > 4e-3 and level_to_velocity(level) > 1:
                out.append((t, int(level_to_velocity(level))))
                t, interval, level = t + interval, interval * 0.86, level - 1.3
    elif set_name == "roll":
        t = 0.2
        while t < end:
            out.append((t, int(rng.integers(95, 128))))
            ghost = t
            for _ in range(int(rng.integers(1, 3))):
                ghost += rng.uniform(0.05, 0.12) if ghost == t else rng.uniform(0.05, 0.08)
                out.append((ghost, int(rng.integers(30, 61))))
            t = ghost + rng.uniform(0.15, 0.3)
    elif set_name == "flams":
        t = 0.2
        while t < end:
            out.append((t, int(rng.integers(30, 71))))
            out.append((t + rng.uniform(0.015, 0.03), int(rng.integers(90, 128))))
            t = out[-1][0] + rng.uniform(0.3, 0.5)
    else:
        raise ValueError(f"set must be one of {SETS}, got {set_name!r}")
    return [(t, v) for t, v in out if t < end]


def recordings(*, fonts=tuple(FONTS), keys=KEYS, sets=SETS, conditions=CONDITIONS, seed=0, leads=None):
    """Yield the corpus's :class:`Recording` s: each font × key × set, each in every condition asked for (seeded by
    their indices in the tuples given: the full corpus's with the defaults)."""
    leads = Leads() if leads is None else leads
    for f, font in enumerate(fonts):
        for k, key in enumerate(keys):
            for s, set_name in enumerate(sets):
                yield from _played(font, key, set_name, conditions, seed * 1000 + 100 * f + 10 * k + s, leads)
    leads.save()


def recording(font, key, set_name, condition, *, seed=0):
    """One :class:`Recording` exactly as :func:`recordings` renders it in the full corpus on ``seed``."""
    leads = Leads()
    base = seed * 1000 + 100 * tuple(FONTS).index(font) + 10 * KEYS.index(key) + SETS.index(set_name)
    (out,) = _played(font, key, set_name, (condition,), base, leads)
    leads.save()
    return out


@lru_cache(maxsize=64)
def _rendered(font, key, set_name, base, reverb):
    """FluidSynth's recording of the notes of a set seeded by ``base`` (read-only: shared by every test that asks).

    A pure function of its arguments, so it is rendered once a process: many tests read the same recordings, and
    :func:`recordings` renders those before the one a test looks for (64 recordings of 5 s: some 120 MB).
    """
    from drumstroke.render.soundfont import render_soundfont

    hits = [(t, "snare", key, speed_of(v)) for t, v in notes(set_name, base)]
    signal = render_soundfont(hits, FONTS[font], duration=SECONDS, rate=RATE, reverb=reverb)
    signal.flags.writeable = False
    return signal


def _played(font, key, set_name, conditions, base, leads):
    """The recordings of one font, key and set (notes seeded by ``base``, noise by ``base`` + 7), one a condition."""
    played = notes(set_name, base)
    measured = [leads(font, key, v) for _, v in played]
    t = np.array([note_block(t) + lead for (t, _), (lead, _) in zip(played, measured)]) / RATE
    peak = np.array([p for _, p in measured])
    level = 20.0 * np.log10(peak / peak.max())
    out = []
    for condition in conditions:
        signal = _rendered(font, key, set_name, base, condition == "reverb")
        if condition in NOISE_DBFS:
            noise = np.random.default_rng(base + 7).standard_normal(len(signal))
            signal = signal + noise * 10.0 ** (NOISE_DBFS[condition] / 20.0)
        out.append(Recording(font, key, set_name, condition, signal, t, level))
    return out


def match(truth, found, window):
    """Pairs (truth index, found index) matched one to one within ``window`` s (mir_eval's optimal matching)."""
    from mir_eval.util import match_events

    if not len(truth) or not len(found):
        return []
    return match_events(np.asarray(truth), np.asarray(found), window)


def score(recording, found):
    """A detection (times s) against the truth: counts of loud notes, found within 1 and 5 ms; detections, correct within 5 ms."""
    loud = recording.level_db >= -LOUD_DB
    within = {}
    for window in (1e-3, 5e-3):
        pairs = match(recording.t, found, window)
        within[window] = int(sum(loud[i] for i, _ in pairs)), len(pairs)
    return {"loud": int(loud.sum()), "within_1ms": within[1e-3][0], "within_5ms": within[5e-3][0],
            "found": len(found), "correct_5ms": within[5e-3][1]}
