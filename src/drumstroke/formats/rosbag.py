"""A ROS 2 bag (rosbag2) holding one ``trajectory_msgs/msg/JointTrajectory`` message, written with ``rosbags``.

The message is the plain data of :func:`drumstroke.formats.ros_json.joint_trajectory`, serialized
as CDR with the message types of ROS 2 Jazzy (``rosbags.typesys.Stores.ROS2_JAZZY``; the
JointTrajectory types and their RIHS01 hashes are the same from Humble to Kilted), on one topic
(default :data:`DEFAULT_TOPIC`), received at time 0. The bag is rosbag2 format version 9 (Jazzy's),
in either storage: ``mcap`` (one ``.mcap`` file, the default since Iron) or ``sqlite3`` (a ``.db3``).
drumstroke's own metadata goes into the bag's ``metadata.yaml`` under ``custom_data`` →
``drumstroke`` (JSON text), which message readers ignore.

The bag is a folder: it is written into a temporary sibling and renamed into place, so it
appears only complete; an existing one is an error unless overwritten. rosbags (the ``ros``
extra) is imported when a bag is written.
"""

import re

import numpy as np

from .._atomic import write_folder_atomic
from .._checks import check_choice
from ..errors import ParameterError
from .json import json_text
from .ros_json import MESSAGE_TYPE

DEFAULT_TOPIC = "/drumstroke/joint_trajectory"
"""The topic the message is written on, unless another is named."""

STORAGES = ("mcap", "sqlite3")
"""The rosbag2 storage formats."""

BAG_VERSION = 9
"""The rosbag2 metadata format version written (ROS 2 Jazzy's)."""

_TOPIC = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")


def check_topic(topic, *, name="topic"):
    """Return ``topic`` if it is a fully qualified ROS 2 topic name (``/name/space``: letters, digits, '_').

    ``name`` is the parameter named in the error.
    """
    if not isinstance(topic, str) or not _TOPIC.fullmatch(topic):
        raise ParameterError(f"{name} must be a ROS 2 topic name: '/' then names of letters, digits and '_' "
                             f"(not starting with a digit) separated by '/', got {topic!r}")
    return topic


def write_rosbag(path, message, *, topic=DEFAULT_TOPIC, storage="mcap", metadata=None, overwrite=False):
    """Write ``message`` (a JointTrajectory as plain data) as a rosbag2 folder at ``path``.

    Parameters
    ----------
    path : str or Path
        The bag's folder; its parent must exist.
    message : dict
        As :func:`drumstroke.formats.ros_json.joint_trajectory` gives it.
    topic : str
        A fully qualified topic name (:func:`check_topic`).
    storage : {"mcap", "sqlite3"}
    metadata : dict or None
        drumstroke's own data (plain data), written to ``custom_data`` → ``drumstroke``.
    overwrite : bool
        Replace an existing ``path`` (else it is an error).
    """
    check_topic(topic)
    check_choice("storage", storage, STORAGES)
    try:
        from rosbags.rosbag2 import StoragePlugin, Writer
        from rosbags.typesys import Stores, get_typestore
    except ImportError as error:
        raise ImportError("drumstroke rosbag2 export needs rosbags: pip install 'drumstroke[ros]'") from error
    store = get_typestore(Stores.ROS2_JAZZY)
    data = store.serialize_cdr(_message(store.types, message), MESSAGE_TYPE)

    def fill(folder):
        with Writer(folder, version=BAG_VERSION, storage_plugin=StoragePlugin[storage.upper()]) as writer:
            if metadata is not None:
                writer.set_custom_data("drumstroke", json_text(metadata, indent=None).strip())
            writer.write(writer.add_connection(topic, MESSAGE_TYPE, typestore=store), 0, data)

    write_folder_atomic(path, fill, overwrite=overwrite, what="rosbag")


def _message(types, message):
    """The typestore's JointTrajectory object of the plain-data ``message``."""
    time, duration = types["builtin_interfaces/msg/Time"], types["builtin_interfaces/msg/Duration"]
    header, point = types["std_msgs/msg/Header"], types["trajectory_msgs/msg/JointTrajectoryPoint"]
    head = message["header"]
    points = [point(positions=np.array(p["positions"], dtype=np.float64),
                    velocities=np.array(p["velocities"], dtype=np.float64),
                    accelerations=np.array(p["accelerations"], dtype=np.float64),
                    effort=np.array(p["effort"], dtype=np.float64),
                    time_from_start=duration(**p["time_from_start"]))
              for p in message["points"]]
    return types[MESSAGE_TYPE](header=header(stamp=time(**head["stamp"]), frame_id=head["frame_id"]),
                               joint_names=list(message["joint_names"]), points=points)
