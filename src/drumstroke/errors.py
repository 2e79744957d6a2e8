"""The one exception root of drumstroke and its two branches, and the one warning drumstroke gives."""

import contextlib


class DrumstrokeError(Exception):
    """Root of every error drumstroke raises on purpose."""


class ParameterError(DrumstrokeError, ValueError):
    """An input is out of range, malformed or inconsistent.

    The message names the parameter, the value and the allowed range. An error about one
    parameter carries them as data too, for a caller that calls the parameter something else
    (the command line names its option, a recipe the table a profile came from):

    >>> error = ParameterError("cor must be in [0, 1), got 1.5", parameter="cor", value=1.5, allowed="[0, 1)")
    >>> error.parameter, error.value, error.allowed, error.reason
    ('cor', 1.5, '[0, 1)', 'must be in [0, 1), got 1.5')
    >>> str(error.renamed("--cor"))
    '--cor must be in [0, 1), got 1.5'
    >>> str(error.renamed("--cor", allowed="[0, 1) ('drumstroke presets' shows some)"))
    "--cor must be in [0, 1) ('drumstroke presets' shows some), got 1.5"

    Attributes
    ----------
    parameter : str or None
        The parameter's name, with which the message begins; None when the error is not about one parameter.
    value : object
        The value given (None when ``parameter`` is None).
    allowed : str or None
        What is allowed, as the message says it (``"[0, 1)"``, ``"one of 'a', 'b'"``), when the message says it.
    """

    def __init__(self, message, *, parameter=None, value=None, allowed=None):
        super().__init__(message)
        self.parameter, self.value, self.allowed = parameter, value, allowed

    @property
    def reason(self):
        """The message after the parameter's name (the whole message when it is about no one parameter)."""
        return str(self)[len(self.parameter or ""):].lstrip()

    def renamed(self, parameter, *, allowed=None):
        """The same error (about a parameter) with the parameter called ``parameter``: ``--cor``, ``force.value``;
        and what is allowed said as ``allowed``, if given (the command line's words for it)."""
        message = parameter + str(self)[len(self.parameter):]
        if allowed is not None and self.allowed:
            message = message.replace(self.allowed, allowed)
        return type(self)(message, parameter=parameter, value=self.value,
                          allowed=self.allowed if allowed is None else allowed)

    def located(self, where):
        """The same error said to come from ``where`` (a file, a line of it), unless its message says so already.

        >>> str(ParameterError("tempi[0] tempo must be finite").located("pattern 'p.txt' line 1"))
        "pattern 'p.txt' line 1: tempi[0] tempo must be finite"
        """
        if where in str(self):
            return self
        return type(self)(f"{where}: {self}")  # about no one parameter now: the message starts with where


@contextlib.contextmanager
def located(where):
    """Inside, a :class:`ParameterError` is said to come from ``where`` (:meth:`ParameterError.located`).

    The readers wrap what they build from a file in it, so that an error found later (by a
    constructor that knows nothing of files) names the file and line it came from.
    """
    try:
        yield
    except ParameterError as error:
        raise error.located(where) from None


class SimulationError(DrumstrokeError):
    """A valid recipe asks for motion the model does not cover.

    Examples: the stick swinging past the vertical, or more impacts than the
    solver's limit before ``t_end``.
    """


class TrajectoryError(ParameterError):
    """Samples break a check of a trajectory: off the time grid, not finite, below the head, over a limit.

    The message names the sample, the quantity, its value and the limit, e.g.
    ``sample 1203: speed 41.2 rad/s exceeds max_speed 40 rad/s``.
    """


class SampledImpactsWarning(UserWarning):
    """Impacts found again in sampled motion, as the exact ones were not recorded: the fast ones may be missed.

    :meth:`drumstroke.Trajectory.read_csv` gives it for a CSV whose JSON beside it records no impacts.
    The command line does not show it: its commands read a CSV for its samples.
    """
