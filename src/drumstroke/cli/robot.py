"""``drumstroke robot track``, ``tune``, ``validate`` and ``export``: strokes on a simulated robot joint."""

from pathlib import Path

from .._checks import check_real
from ..errors import ParameterError
from ..formats.ros_json import metadata_path
from ..formats.rosbag import DEFAULT_TOPIC, STORAGES, check_topic
from ..trajectory import DEFAULT_RATE, Trajectory
from ._common import Bar, Parser, print_written


def add_robot(commands):
    """Register ``robot`` and its actions."""
    robot = commands.add_parser("robot", help="play strokes on a simulated robot joint; validate and export trajectories")
    actions = robot.add_subparsers(dest="robot_command", parser_class=Parser, metavar="ACTION", required=True)
    trk = actions.add_parser("track", help="play a stroke with one controller or all, and score it")
    trk.add_argument("source", metavar="SOURCE",
                     help="a recipe .toml, a preset, a library stroke (with --library) or a trajectory .csv")
    trk.add_argument("--library", type=Path, metavar="DIR", help="the library SOURCE names a stroke of")
    trk.add_argument("--stick", help="the stick to play from a composition CSV")
    trk.add_argument("--controller", default="all", metavar="NAME", help="pi, pid-ff, impedance or all (default)")
    trk.add_argument("--plant", choices=("simple", "mujoco"), default="simple", help="the joint model (default simple)")
    trk.add_argument("--config", type=Path, metavar="TOML", help="robot config: [plant], [controller.NAME] gains")
    trk.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ", help="control rate (default 1000)")
    trk.add_argument("--report", type=Path, metavar="JSON", help="write the metrics as JSON")
    trk.add_argument("--plot", type=Path, metavar="PNG", help="draw reference and played theta(t) with their onsets")
    trk.set_defaults(run=_track)
    tun = actions.add_parser("tune", help="tune a controller's gains over a library, before/after table")
    tun.add_argument("--library", type=Path, required=True, metavar="DIR")
    tun.add_argument("--controller", default="pi", metavar="NAME", help="pi (default), pid-ff or impedance")
    tun.add_argument("--per-stroke", action="store_true", help="one gain set per stroke (gain scheduling)")
    tun.add_argument("--evaluations", type=int, default=100, metavar="N", help="objective evaluations (default 100)")
    tun.add_argument("--config", type=Path, metavar="TOML", help="robot config: [plant], starting gains")
    tun.add_argument("--report", type=Path, metavar="JSON", help="write gains and metrics as JSON")
    tun.set_defaults(run=_tune)
    val = actions.add_parser("validate", help="check a trajectory CSV before it goes to hardware")
    val.add_argument("trajectory", type=Path, metavar="TRAJECTORY")
    val.add_argument("--stick", help="the stick of a composition CSV")
    val.add_argument("--config", type=Path, metavar="TOML", help="robot config with a [limits] table")
    val.set_defaults(run=_validate)
    exp = actions.add_parser("export", help="validate and export a trajectory CSV for a robot stack")
    exp.add_argument("trajectory", type=Path, metavar="TRAJECTORY")
    exp.add_argument("--format", choices=("csv", "ros-json"), help="--out's format (ros-json: metadata in X.meta.json)")
    exp.add_argument("--out", type=Path, metavar="PATH", help="the file to write (with --format)")
    exp.add_argument("--rosbag", type=Path, metavar="DIR", help="write a rosbag2 folder of one JointTrajectory")
    exp.add_argument("--storage", choices=STORAGES, default="mcap", help="the rosbag2 storage (default mcap)")
    exp.add_argument("--topic", default=DEFAULT_TOPIC, help=f"the rosbag2 topic (default {DEFAULT_TOPIC})")
    exp.add_argument("--overwrite", action="store_true", help="replace an existing --rosbag folder")
    exp.add_argument("--stick", help="the stick of a composition CSV to export (csv: needed; ROS: default every stick)")
    exp.add_argument("--joint-names", metavar="A,B", help="ROS joint names, one per stick in the file's order")
    exp.add_argument("--config", type=Path, metavar="TOML", help="robot config with a [limits] table")
    exp.set_defaults(run=_export)


def _config(path):
    from ..robot.config import RobotConfig

    return RobotConfig.from_toml(path) if path else RobotConfig()


def _track(args):
    from ..robot.config import load_source
    from ..robot.metrics import metrics
    from ..robot.track import reference, track

    config = _config(args.config)
    controllers = config.controllers
    names = list(controllers) if args.controller == "all" else [args.controller]
    for name in names:
        if name not in controllers:
            raise ParameterError(f"--controller must be one of {', '.join(controllers)} or all, got {name!r}")
    rate = check_real("--rate", args.rate, low=10.0, high=1e5, unit="Hz")
    source = load_source(args.source, library=args.library, stick=args.stick, plant=config.plant)
    ref = reference(source, rate)
    bar = Bar(f"playing {ref.name}", delay=1.0)
    played = [track(ref, controllers[name], config.plant, engine=args.plant,
                    progress=lambda done, i=i: bar.update((i + done) / len(names))) for i, name in enumerate(names)]
    bar.close()
    scores = [metrics(p) for p in played]
    print(f"{ref.name} (model {ref.model}) on the {args.plant} plant at {rate:g} Hz: "
          f"{scores[0].reference_onsets} reference onsets (audible impacts)")
    print(f"{'controller':<10} {'window':>7} {'matched':>9} {'extra':>5} {'P':>5} {'R':>5} {'F':>5}  timing |error| "
          f"median/p95, mean (ms)  level |error| median/p95 (dB)")
    for p, m in zip(played, scores):
        for k, w in enumerate(m.windows):
            timing, level = (f"{w.timing_median * 1e3:>6.2f} /{w.timing_p95 * 1e3:>6.2f}, {w.timing_mean_signed * 1e3:+.2f}",
                             f"{w.level_median:.2f} / {w.level_p95:.2f}") if w.matched else ("-", "-")
            print(f"{p.controller if not k else '':<10} {f'±{w.window * 1e3:g} ms':>7} {w.matched:>4}/{m.reference_onsets:<4} "
                  f"{w.extra:>5} {w.precision:>5.2f} {w.recall:>5.2f} {w.f_measure:>5.2f}  {timing:<34} {level}")
    print(f"{'controller':<10} {'tail kept (±2 ms)':>17} {'shortfall (s)':>13} {'rms (rad)':>10} {'peak torque':>14}")
    for p, m in zip(played, scores):
        print(f"{p.controller:<10} {100 * m.tail_kept_fraction:>16.0f}% {m.tail_shortfall:>13.3f} {m.rms_error:>10.4f} "
              f"{m.peak_torque:>6.2f}/{m.torque_limit:g} N m")
    written = []
    if args.report:
        from ..formats.json import write_json
        from ..robot.controllers import to_dict

        report = {"reference": ref.name, "model": ref.model, "plant": args.plant, "rate": rate,
                  "plant_parameters": config.plant.to_dict(),
                  "controllers": [{"name": p.controller, "gains": to_dict(controllers[p.controller]),
                                   "metrics": m.to_dict()} for p, m in zip(played, scores)]}
        write_json(args.report, report)
        written.append(args.report)
    if args.plot:
        from ..render.plot import save_figure, tracking_figure

        save_figure(tracking_figure(played), args.plot)
        written.append(args.plot)
    print_written(written)


def _tune(args):
    from ..palette.library import load_library
    from ..robot.track import reference
    from ..robot.tune import tune

    config = _config(args.config)
    if args.controller not in config.controllers:
        raise ParameterError(f"--controller must be one of {', '.join(config.controllers)}, got {args.controller!r}")
    library = load_library(args.library)
    refs = [reference(s.trajectory, library.rate) for s in library.values()]
    scope = "one gain set per stroke" if args.per_stroke else "one gain set for all"
    print(f"tuning {args.controller} on {len(refs)} strokes of {args.library} ({scope}, "
          f"{args.evaluations} evaluations each)")
    bar = Bar("tuning")
    result = tune(refs, config.controllers[args.controller], plant=config.plant, per_stroke=args.per_stroke,
                  evaluations=args.evaluations, progress=bar.update)
    bar.close()
    print(f"{'stroke':<18} {'before':>9} {'after':>9} {'shortfall before/after (s)':>27}")
    for ref, b, a in zip(refs, result.before, result.after):
        print(f"{ref.name:<18} {b.kept:>4}/{b.reference_onsets:<4} {a.kept:>4}/{a.reference_onsets:<4} "
              f"{b.tail_shortfall:>13.3f} / {a.tail_shortfall:.3f}")
    total = sum(m.reference_onsets for m in result.before)
    before, after = (sum(m.kept for m in ms) for ms in (result.before, result.after))
    print(f"{'all':<18} {before:>4}/{total:<4} {after:>4}/{total:<4}  kept within 2 ms: "
          f"{100 * before / total:.1f}% -> {100 * after / total:.1f}%")
    if not args.per_stroke:
        print(f"tuned gains: {result.controllers[0]}")
    if args.report:
        from ..formats.json import write_json
        from ..robot.controllers import to_dict

        report = {"controller": args.controller, "per_stroke": args.per_stroke, "evaluations": result.evaluations,
                  "strokes": [{"name": r.name, "gains": to_dict(c), "before": b.to_dict(), "after": a.to_dict()}
                              for r, c, b, a in zip(refs, result.controllers, result.before, result.after)]}
        write_json(args.report, report)
        print(f"wrote {args.report}")


def _validate(args):
    from ..robot.validate import validate_file

    config = _config(args.config)
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
    config = _config(args.config)
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
