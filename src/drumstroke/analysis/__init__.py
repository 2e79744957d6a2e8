"""From recordings to the model: analysis by synthesis.

The data flows through it in this order:

- :mod:`.onsets`: :class:`Onsets`, a recording's impacts (times, relative levels), found in audio by a detector
  whose thresholds are an :class:`OnsetConfig`;
- :mod:`.drums`: one drum of a kit's onsets (:func:`keep_drum`: a groove's snare, kick or hi-hat);
- :mod:`.drop`: c from a stick dropped on the head (the ratio of successive flights and levels);
- :mod:`.fit`: the start, c and force profile whose impacts match a recording's (via :mod:`drumstroke.design`);
- :mod:`.compare`: two strokes side by side (onsets, intervals, level envelopes, bounce rate).
"""

from typing import TYPE_CHECKING

from .drop import Drop, measure_cor
from .drums import DRUMS, drum_of_onsets, keep_drum
from .onsets import OnsetConfig, Onsets, find_onsets, find_recording_onsets, read_onsets, read_recording, write_onsets

__all__ = ["DRUMS", "Drop", "Fit", "OnsetConfig", "Onsets", "drum_of_onsets", "find_onsets", "find_recording_onsets",
           "fit_stroke", "keep_drum", "measure_cor", "read_onsets", "read_recording", "write_onsets"]

if TYPE_CHECKING:  # for the tools that read the source; at run time, as below
    from .fit import Fit, fit_stroke


def __getattr__(name):
    """``Fit`` and ``fit_stroke``, imported on first use.

    A fit needs scipy.optimize and the designer; reading onsets, and the command line's parser, need neither.
    """
    if name in ("Fit", "fit_stroke"):
        from . import fit

        return getattr(fit, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
