"""From recordings to the model (SPEC §10): analysis by synthesis.

The data flows through it in this order:

- :mod:`.onsets`: :class:`Onsets`, a recording's impacts (times, relative levels), found in audio;
- :mod:`.drop`: c from a stick dropped on the head (the ratio of successive flights and levels);
- :mod:`.fit`: the start, c and force profile whose impacts match a recording's (via :mod:`drumstroke.design`);
- :mod:`.compare`: two strokes side by side (onsets, intervals, level envelopes, bounce rate).
"""

from .onsets import Onsets

__all__ = ["Onsets"]
