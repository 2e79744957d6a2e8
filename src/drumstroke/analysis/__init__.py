"""From recordings to the model: analysis by synthesis.

The data flows through it in this order:

- :mod:`.onsets`: :class:`Onsets`, a recording's impacts (times, relative levels), found in audio by a detector
  whose thresholds are an :class:`OnsetConfig`;
- :mod:`.drop`: c from a stick dropped on the head (the ratio of successive flights and levels);
- :mod:`.fit`: the start, c and force profile whose impacts match a recording's (via :mod:`drumstroke.design`);
- :mod:`.compare`: two strokes side by side (onsets, intervals, level envelopes, bounce rate).
"""

from .drop import Drop, measure_cor
from .fit import Fit, fit_stroke
from .onsets import OnsetConfig, Onsets, find_onsets, find_recording_onsets, read_onsets, read_recording, write_onsets

__all__ = ["Drop", "Fit", "OnsetConfig", "Onsets", "find_onsets", "find_recording_onsets", "fit_stroke", "measure_cor",
           "read_onsets", "read_recording", "write_onsets"]
