"""The one exception root of drumstroke and its two branches."""


class DrumstrokeError(Exception):
    """Root of every error drumstroke raises on purpose."""


class ParameterError(DrumstrokeError, ValueError):
    """An input is out of range, malformed or inconsistent.

    The message names the parameter, the value and the allowed range.
    """


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
