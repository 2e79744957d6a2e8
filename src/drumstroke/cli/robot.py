"""``drumstroke robot track``, ``tune``, ``validate`` and ``export``: strokes on a simulated robot joint."""

from ..errors import ParameterError
from ..formats import json
from ..render import plot
from ..trajectory import DEFAULT_RATE
from ._common import Bar, Parser, print_written
from ._options import Output, add_mkdir, existing_file, existing_folder, number, whole


def add_robot(commands):
    """Register ``robot`` and its actions."""
    robot = commands.add_parser("robot", help="play strokes on a simulated robot joint; validate and export trajectories",
                                description="Play, score, tune, validate and export strokes for a robot joint.")
    actions = robot.add_subparsers(dest="robot_command", parser_class=Parser, metavar="ACTION", required=True)
    trk = actions.add_parser("track", help="play a stroke with one controller or all, and score it",
                             description="Play a stroke with each controller asked for; print what each kept.")
    trk.add_argument("source", metavar="SOURCE",
                     help="a recipe .toml, a preset, a palette or library (--library) stroke, or a trajectory .csv")
    trk.add_argument("--library", type=existing_folder, metavar="DIR", help="the library SOURCE names a stroke of")
    trk.add_argument("--stick", help="the stick to play from a composition CSV")
    trk.add_argument("--controller", default="all", metavar="NAME", help="pi, pid-ff, impedance or all (default)")
    trk.add_argument("--plant", choices=("simple", "mujoco"), default="simple", help="the joint model (default simple)")
    trk.add_argument("--config", type=existing_file, metavar="TOML", help="robot config: [plant], [controller.NAME] gains")
    trk.add_argument("--rate", type=number(low=10.0, high=1e5, unit="Hz"), default=DEFAULT_RATE, metavar="HZ",
                     help=f"control rate, in [10, 1e5] Hz (default {DEFAULT_RATE:g})")
    trk.add_argument("--report", action=Output, suffixes=json.SUFFIXES, metavar="JSON", help="write the metrics as .json")
    trk.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PNG", help="draw theta(t) and onsets")
    add_mkdir(trk)
    trk.set_defaults(run=_track)
    tun = actions.add_parser("tune", help="tune a controller's gains over a library, before/after table",
                             description="Tune a controller's gains to keep a library's onsets; print before/after.")
    tun.add_argument("--library", type=existing_folder, required=True, metavar="DIR",
                     help="the library folder ('library build') to tune on")
    tun.add_argument("--controller", default="pi", metavar="NAME", help="pi (default), pid-ff or impedance")
    tun.add_argument("--per-stroke", action="store_true", help="one gain set per stroke (gain scheduling)")
    tun.add_argument("--evaluations", type=whole(low=1), default=100, metavar="N",
                     help="objective evaluations, >= 1 (default 100)")
    tun.add_argument("--config", type=existing_file, metavar="TOML", help="robot config: [plant], starting gains")
    tun.add_argument("--report", action=Output, suffixes=json.SUFFIXES, metavar="JSON",
                     help="write gains and metrics as .json")
    add_mkdir(tun)
    tun.set_defaults(run=_tune)
    val = actions.add_parser("validate", help="check a trajectory CSV before it goes to hardware",
                             description="Check a trajectory CSV against the robot's limits; print its peaks.")
    val.add_argument("trajectory", type=existing_file, metavar="TRAJECTORY", help="a trajectory .csv to check")
    val.add_argument("--stick", help="the stick of a composition CSV")
    val.add_argument("--config", type=existing_file, metavar="TOML", help="robot config with a [limits] table")
    val.set_defaults(run=_validate)
    exp = actions.add_parser("export", help="validate and export a trajectory CSV for a robot stack",
                             description="Validate a trajectory CSV, then write it for a robot stack.")
    exp.add_argument("trajectory", type=existing_file, metavar="TRAJECTORY", help="a trajectory .csv to export")
    exp.add_argument("--format", choices=("csv", "ros-json"), required=True,
                     help="csv: t, theta, omega, alpha at the control rate; ros-json: a ROS 2 JointTrajectory as JSON")
    exp.add_argument("--out", action=Output, required=True, metavar="PATH", help="the file to write")
    exp.add_argument("--stick", help="the stick of a composition CSV")
    exp.add_argument("--config", type=existing_file, metavar="TOML", help="robot config with a [limits] table")
    add_mkdir(exp)
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
    rate = args.rate
    source = load_source(args.source, library=args.library, stick=args.stick, plant=config.plant)
    ref = reference(source, rate)
    played = [track(ref, controllers[name], config.plant, engine=args.plant) for name in names]
    scores = [metrics(p) for p in played]
    print(f"{ref.name} (model {ref.model}) on the {args.plant} plant at {rate:g} Hz: "
          f"{scores[0].reference_onsets} reference onsets (audible impacts)")
    print(f"{'controller':<10} {'kept':>9} {'tail':>6} {'timing mean/p95 (ms)':>21} {'rms (rad)':>10} "
          f"{'shortfall (s)':>13} {'peak torque':>14}")
    for p, m in zip(played, scores):
        timing = f"{1e3 * m.timing_mean:>10.2f} /{1e3 * m.timing_p95:>5.2f}" if m.kept else f"{'- /  -':>17}"
        print(f"{p.controller:<10} {m.kept:>4}/{m.reference_onsets:<4} {100 * m.tail_kept_fraction:>5.0f}% "
              f"{timing}    {m.rms_error:>10.4f} "
              f"{m.tail_shortfall:>13.3f} {m.peak_torque:>6.2f}/{m.torque_limit:g} N m")
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
    from ..formats.trajectory_csv import read_stick, stated_model
    from ..robot.export import export_csv, export_ros_json
    from ..robot.validate import validate_file

    config = _config(args.config)
    head, limits = config.plant.head, config.limits
    checked = validate_file(args.trajectory, stick=args.stick, head=head, limits=limits)  # the file's rate too
    model = stated_model(read_stick(args.trajectory, stick=args.stick)[4])
    name = args.trajectory.stem + (f"-{args.stick}" if args.stick else "")
    write = export_csv if args.format == "csv" else export_ros_json
    write(args.out, checked.t, checked.theta, checked.omega, rate=checked.rate, model=model, name=name, head=head,
          limits=limits)
    print(f"wrote {args.out} ({args.format}): {_peaks(checked)}")


def _peaks(checked):
    return (f"{len(checked.t)} samples at {checked.rate:g} Hz, theta {checked.lowest_angle:.4f} to "
            f"{checked.highest_angle:.4f} rad, peak speed {checked.peak_speed:.3g} rad/s, acceleration "
            f"{checked.peak_acceleration:.3g} rad/s^2, jerk {checked.peak_jerk:.3g} rad/s^3 (head {checked.head:.4f} rad)")
