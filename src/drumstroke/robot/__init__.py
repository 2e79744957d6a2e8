"""Robot execution: a simulated joint, controllers, what was played, validation and export."""

ENGINES = ("simple", "mujoco")
"""The plants a reference can be played on: the simple joint, MuJoCo's (the ``robot`` extra)."""
