"""MIDI files under their old name, while the command line moves to :mod:`drumstroke.formats.midi`."""

from ..formats.midi import NOTE_LENGTH, PERCUSSION_CHANNEL, SNARE, TICKS_PER_BEAT, Note, read_midi_notes, write_midi

__all__ = ["NOTE_LENGTH", "PERCUSSION_CHANNEL", "SNARE", "TICKS_PER_BEAT", "Note", "read_midi_notes", "write_midi"]
