"""Trajectory CSV helpers under their old names, while the command line moves to :mod:`drumstroke.formats`."""

from ..formats.trajectory_csv import columns_text as csv_text
from ..formats.trajectory_csv import comment_line as csv_header
from ..formats.trajectory_csv import read_columns as read_csv
from ..formats.trajectory_csv import read_stick, stated_model
from ..trajectory import THETA_TOP, Trajectory

__all__ = ["THETA_TOP", "Trajectory", "csv_header", "csv_text", "read_csv", "read_trajectory_csv"]


def read_trajectory_csv(path, *, stick=None):
    """t (s), θ (rad), ω (rad/s) and the model of one stick of a trajectory CSV."""
    t, theta, omega, _, comment = read_stick(path, stick=stick)
    return t, theta, omega, stated_model(comment)
