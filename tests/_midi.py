"""Reading a MIDI file in tests independently of drumstroke: mido's messages, walked and timed by hand."""

import math

import mido


def tick_seconds(tick, tempo_map, ticks_per_beat):
    """Seconds at absolute ``tick`` given ``tempo_map``, a sorted list of (tick, µs per beat) starting at tick 0."""
    seconds = 0.0
    for (start, tempo), (end, _) in zip(tempo_map, tempo_map[1:] + [(math.inf, None)]):
        if tick <= start:
            break
        seconds += (min(tick, end) - start) * tempo / (1e6 * ticks_per_beat)
    return seconds


def read_with_mido(path, charset="latin1"):
    """A MIDI file's tracks, walked here from their delta ticks: (file, names, tempo map, meters, notes).

    Notes are dicts with track, channel, key, velocity, start and end ticks and seconds; a note ends at the
    first note-off (or note-on with velocity 0) of its key and channel on its track."""
    file = mido.MidiFile(path, charset=charset)
    tempo_map, meters, names, notes = {0: 500_000}, [], [], []
    for number, track in enumerate(file.tracks):
        tick, sounding = 0, {}
        names.append(next((m.name for m in track if m.type == "track_name"), ""))
        for message in track:
            tick += message.time
            if message.type == "set_tempo":
                tempo_map[tick] = message.tempo
            elif message.type == "time_signature":
                meters.append((tick, message.numerator, message.denominator))
            elif message.type in ("note_on", "note_off"):
                key = (message.channel, message.note)
                if message.type == "note_off" or message.velocity == 0:
                    if key in sounding:
                        sounding.pop(key)["end_tick"] = tick
                    continue
                sounding[key] = {"track": number, "tick": tick, "note": message.note, "velocity": message.velocity,
                                 "channel": message.channel}
                notes.append(sounding[key])
    tempo_map = sorted(tempo_map.items())
    for note in notes:
        note["time"] = tick_seconds(note["tick"], tempo_map, file.ticks_per_beat)
        note["end"] = tick_seconds(note.get("end_tick", math.inf), tempo_map, file.ticks_per_beat)
    notes.sort(key=lambda note: (note["tick"], note["track"]))
    return file, names, tempo_map, meters, notes
