"""Live performance: notes in as they arrive, validated setpoints out at the control rate.

The data flows through it in this order:

- :mod:`.inputs`: OSC messages, MIDI messages and score files made requests (or one line saying why not);
- :mod:`.performer`: :class:`Performer`, each note planned into the running motion within the lookahead,
  setpoints evaluated as time passes, a session replayed offline;
- :mod:`.kit`: :class:`KitPerformer`, the same on a kit: each note on its piece, by a limb chosen as it
  arrives, a hand moved between pieces, a foot's pedal pressed, every joint a column;
- :mod:`.runtime`: :class:`Runtime`, the loop on the clock: requests planned, chunks validated and sent on
  time, the session's record;
- :mod:`.outputs` and :mod:`.monitor`: setpoints to OSC, to CSV, to a simulated robot;
- :mod:`.stage`: :func:`perform`, a whole session from its inputs to its outputs (``drumstroke live``).
"""

from .kit import KitPerformer
from .performer import Chunk, LiveNote, ManualClock, Outcome, Performer, SystemClock
from .runtime import LiveError, Runtime, replay_session
from .stage import perform

__all__ = ["Chunk", "KitPerformer", "LiveError", "LiveNote", "ManualClock", "Outcome", "Performer", "Runtime", "SystemClock",
           "perform", "replay_session"]
