"""Live performance (SPEC §9): notes in as they arrive, validated setpoints out at the control rate.

- :mod:`.performer`: :class:`Performer`, the runtime on one clock — notes planned into the running
  motion within a lookahead, setpoints given as time passes, a session replayed offline.
"""

from .performer import Chunk, LiveNote, ManualClock, Outcome, Performer, SystemClock

__all__ = ["Chunk", "LiveNote", "ManualClock", "Outcome", "Performer", "SystemClock"]
