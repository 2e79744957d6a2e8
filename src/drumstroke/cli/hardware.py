"""``drumstroke robot validate`` and ``export``: trajectories checked and written for hardware and robot stacks."""

from pathlib import Path

from ..errors import ParameterError
from ..formats.ros_json import metadata_path
from ..formats.rosbag import DEFAULT_TOPIC, STORAGES, check_topic
from ..formats.trajectory_csv import is_kit_file
from ..trajectory import Trajectory
from ._common import robot_config
from ._options import Output, add_mkdir, existing_file
from .robot_kit_export import export_kit_file, validate_kit_file


def add_hardware_actions(actions):
    """Register ``robot validate`` and ``robot export`` on the ``robot`` command's ``actions``."""
    val = actions.add_parser("validate", help="check a trajectory CSV before it goes to hardware",
                             description="Check a trajectory CSV against the robot's limits (a kit's: every joint "
                                         "against its own); print its peaks.")
    val.add_argument("trajectory", type=existing_file, metavar="TRAJECTORY",
                     help="a trajectory .csv to check (a kit's, from compose --kit --csv, with its JSON)")
    val.add_argument("--stick", help="the stick of a composition CSV")
    val.add_argument("--config", type=existing_file, metavar="TOML",
                     help="robot config with a [limits] table (a kit's: its sticks' theta limits)")
    val.set_defaults(run=_validate)
    exp = actions.add_parser("export", help="validate and export a trajectory CSV for a robot stack",
                             description="Validate a trajectory CSV, then write it for a robot stack: a CSV, a ROS 2 "
                                         "JointTrajectory as JSON, or a rosbag2 of that message.")
    exp.add_argument("trajectory", type=existing_file, metavar="TRAJECTORY",
                     help="a trajectory .csv to export (a kit's: every joint, one ROS joint per column)")
    exp.add_argument("--format", choices=("csv", "ros-json"),
                     help="--out's format: csv (t, theta, omega, alpha; a kit's: every joint's angle, speed and "
                          "acceleration; metadata in X.json) or ros-json (metadata in X.meta.json)")
    exp.add_argument("--out", action=Output, metavar="PATH", help="the file to write (with --format)")
    exp.add_argument("--rosbag", type=Path, metavar="DIR", help="write a rosbag2 folder of one JointTrajectory")
    exp.add_argument("--storage", choices=STORAGES, default="mcap", help="the rosbag2 storage (default mcap)")
    exp.add_argument("--topic", default=DEFAULT_TOPIC, help=f"the rosbag2 topic (default {DEFAULT_TOPIC})")
    exp.add_argument("--overwrite", action="store_true", help="replace an existing --rosbag folder")
    exp.add_argument("--stick", help="the stick of a composition CSV to export (csv: needed; ROS: default every stick)")
    exp.add_argument("--joint-names", metavar="A,B",
                     help="ROS joint names, one per stick (a kit's: per joint, default LIMB_JOINT) in the file's order")
    exp.add_argument("--config", type=existing_file, metavar="TOML", help="robot config with a [limits] table")
    add_mkdir(exp)
    exp.set_defaults(run=_export)


def _validate(args):
    from ..robot.validate import validate_file

    config = robot_config(args.config)
    if is_kit_file(args.trajectory):
        return validate_kit_file(args, config)
    checked = validate_file(args.trajectory, stick=args.stick, head=config.plant.head, limits=config.limits)
    print(f"{args.trajectory}: valid: {_peaks(checked)}")


def _export(args):
    from ..formats.sidecar import sidecar_path
    from ..robot.export import check_joint_names, export_csv, export_ros_json, export_rosbag

    if (args.out is None) != (args.format is None) or not (args.out or args.rosbag):
        raise ParameterError("give --out with its --format, or --rosbag DIR, or both")
    if args.rosbag and args.rosbag.exists() and not args.overwrite:
        raise ParameterError(f"--rosbag {str(args.rosbag)!r} exists: choose a new folder, or replace it with --overwrite")
    topic = check_topic(args.topic, name="--topic")
    config = robot_config(args.config)
    if is_kit_file(args.trajectory):
        return export_kit_file(args, config, topic)
    options = {"head": config.plant.head, "limits": config.limits}
    trajectory = Trajectory.read_csv(args.trajectory, theta_max=config.plant.head)
    sticks = trajectory.sticks  # in the file's order, as --joint-names names them
    if len(sticks) == 1 and args.stick not in (None, *sticks):
        raise ParameterError(f"--stick names a composition's stick; {args.trajectory} has one: leave it out")
    if len(sticks) > 1 and (args.stick not in (None, *sticks) or args.stick is None and args.format == "csv"):
        got = " for CSV" if args.stick is None else f", got {args.stick!r}"
        raise ParameterError(f"--stick must name one of the sticks of {args.trajectory} ({', '.join(sticks)}){got}")
    ros = trajectory.stick(args.stick) if args.stick else trajectory
    names = check_joint_names(None if args.joint_names is None else args.joint_names.split(","), sticks=ros.sticks,
                              name="--joint-names")
    if args.format == "csv":
        checked = export_csv(args.out, trajectory, stick=args.stick, **options)
        print(f"wrote {args.out} (CSV{f' of stick {args.stick}' if args.stick else ''}): {_peaks(checked)}")
        print(f"wrote {sidecar_path(args.out)} (with the metadata of {args.out.name})")
    elif args.format == "ros-json":
        checked = export_ros_json(args.out, ros, joint_names=names, **options)
        print(f"wrote {args.out} (a ROS 2 JointTrajectory) and its metadata {metadata_path(args.out)}")
    if args.rosbag:
        checked = export_rosbag(args.rosbag, ros, joint_names=names, topic=topic, storage=args.storage,
                                overwrite=args.overwrite, **options)
        print(f"wrote {args.rosbag} (a rosbag2, {args.storage}: one ROS 2 JointTrajectory on {topic})")
    if args.format != "csv" or args.rosbag:
        for joint, stick, c in zip(names, ros.sticks, checked):
            print(f"  joint {joint}{f' (stick {stick})' if len(sticks) > 1 else ''}: {_peaks(c)}")


def _peaks(checked):
    return (f"{len(checked.t)} samples at {checked.rate:g} Hz, theta {checked.lowest_angle:.4f} to "
            f"{checked.highest_angle:.4f} rad, peak speed {checked.peak_speed:.3g} rad/s, acceleration "
            f"{checked.peak_acceleration:.3g} rad/s^2, jerk {checked.peak_jerk:.3g} rad/s^3 (head {checked.head:.4f} rad)")
