"""``drumstroke robot validate`` and ``export`` of a kit's trajectory CSV: every joint of every limb."""

from contextlib import contextmanager

from ..errors import ParameterError, TrajectoryError
from ..formats.ros_json import metadata_path
from ..formats.sidecar import sidecar_path


def validate_kit_file(args, config):
    """``robot validate KIT.csv``: every joint checked against its limits; one line per joint."""
    from ..formats.trajectory_csv import read_kit
    from ..robot.validate import validate_kit

    _no_stick(args)
    samples = read_kit(args.trajectory)
    with _naming(args.trajectory):
        checked = validate_kit(samples, limits=_sticks(args, config))
    print(f"{args.trajectory}: valid: {len(checked)} joints, {len(samples.t)} samples at {samples.rate:g} Hz")
    _report(checked, samples)


def export_kit_file(args, config, topic):
    """``robot export KIT.csv``: every joint, validated, to a kit CSV, a ROS 2 JointTrajectory (JSON) or a rosbag2."""
    from ..formats.trajectory_csv import read_kit
    from ..robot.export import check_joint_names, export_csv, export_ros_json, export_rosbag, ros_joint_name

    _no_stick(args)
    samples = read_kit(args.trajectory)
    columns = tuple(samples.positions)
    given = None if args.joint_names is None else args.joint_names.split(",")
    names = check_joint_names([ros_joint_name(c) for c in columns] if given is None else given, sticks=columns,
                              name="--joint-names", what="joint")
    limits = _sticks(args, config)
    if given is not None and args.format != "ros-json" and not args.rosbag:
        raise ParameterError("--joint-names names the joints of a ROS export, not of --format csv's columns")
    with _naming(args.trajectory):  # each export validates first, the same way: a failure writes nothing
        if args.format == "csv":
            checked = export_csv(args.out, samples, limits=limits)
            print(f"wrote {args.out} (a kit CSV: every joint's angle, speed and acceleration)")
            print(f"wrote {sidecar_path(args.out)} (with the metadata of {args.out.name})")
        elif args.format == "ros-json":
            checked = export_ros_json(args.out, samples, joint_names=names, limits=limits)
            print(f"wrote {args.out} (a ROS 2 JointTrajectory of {len(names)} joints) and its metadata "
                  f"{metadata_path(args.out)}")
        if args.rosbag:
            checked = export_rosbag(args.rosbag, samples, joint_names=names, topic=topic, storage=args.storage,
                                    overwrite=args.overwrite, limits=limits)
            print(f"wrote {args.rosbag} (a rosbag2, {args.storage}: one ROS 2 JointTrajectory of {len(names)} "
                  f"joints on {topic})")
    _report(dict(zip(columns, checked)), samples, names if args.format != "csv" or args.rosbag else None)


@contextmanager
def _naming(path):
    """A trajectory error names the file."""
    try:
        yield
    except TrajectoryError as error:
        raise TrajectoryError(f"kit trajectory file {str(path)!r}: {error}") from None


def _no_stick(args):
    if args.stick is not None:
        raise ParameterError(f"--stick names a stick of a composition CSV; {args.trajectory} is a kit's trajectory, "
                             "every joint of which goes together: leave it out")


def _sticks(args, config):
    """The sticks' θ limits: --config's [limits] when a config is given, else those the kit file records."""
    return config.limits if args.config else None


def _report(checked, samples, names=None):
    """One line per joint: its range and peaks against its limits (a beater's range alone)."""
    from ..formats.trajectory_csv import range_only

    for i, (column, c) in enumerate(checked.items()):
        joint = f"  {column}" + (f" (ROS {names[i]})" if names else "") + ":"
        table = samples.limits[column]
        span = (f"{c.lowest_angle:.4f} to {c.highest_angle:.4f} rad (range {c.limits.theta_low:.4g} to "
                f"{c.limits.theta_high:.4g})")
        if range_only(table):
            print(f"{joint} {span}; a beater: its range only")
            continue
        lim = c.limits
        print(f"{joint} {span}, peak speed {c.peak_speed:.3g} rad/s ({lim.max_speed:.3g}), acceleration "
              f"{c.peak_acceleration:.3g} rad/s^2 ({lim.max_acceleration:.3g}), jerk {c.peak_jerk:.3g} rad/s^3 "
              f"({lim.max_jerk:.3g})")
