"""``drumstroke robot track`` and ``tune``: strokes on a simulated robot joint (``validate`` and ``export``: :mod:`.hardware`)."""

from ..errors import ParameterError
from ..formats import json
from ..render import plot
from ..trajectory import DEFAULT_RATE
from ._common import Bar, Parser, print_written, robot_config
from ._options import Output, add_mkdir, existing_file, existing_folder, number, whole
from .hardware import add_hardware_actions
from .robot_kit import add_kit_track_options, check_kit_track, track_kit_command


def add_robot(robot):
    """Give ``robot``'s parser ``robot`` its description and actions."""
    robot.description = "Play, score, tune, validate and export strokes for a robot joint."
    actions = robot.add_subparsers(dest="robot_command", parser_class=Parser, metavar="ACTION", required=True)
    trk = actions.add_parser("track", help="play a stroke (or a song on the kit) with one controller or all, and score it",
                             description="Play a stroke with each controller asked for; print what each kept. With "
                                         "--kit, play a song's drum part on the kit robot; print what each piece kept.")
    trk.add_argument("source", metavar="SOURCE", help="a recipe .toml, a preset, a palette or library (--library) "
                     "stroke, or a trajectory .csv; with --kit a song (.mid or a pattern)")
    trk.add_argument("--library", type=existing_folder, metavar="DIR", help="the library SOURCE names a stroke of")
    trk.add_argument("--stick", help="the stick to play from a composition CSV")
    trk.add_argument("--controller", default="all", metavar="NAME", help="pi, pid-ff, impedance or all (default)")
    trk.add_argument("--plant", "--engine", dest="plant", choices=("simple", "mujoco"), default="simple",
                     help="the joint model (default simple)")
    trk.add_argument("--config", type=existing_file, metavar="TOML", help="robot config: [plant], [controller.NAME] gains")
    trk.add_argument("--rate", type=number(low=10.0, high=1e5, unit="Hz"), default=DEFAULT_RATE, metavar="HZ",
                     help=f"control rate, in [10, 1e5] Hz (default {DEFAULT_RATE:g})")
    trk.add_argument("--report", action=Output, suffixes=json.SUFFIXES, metavar="JSON", help="write the metrics as .json")
    trk.add_argument("--plot", action=Output, suffixes=plot.SUFFIXES, metavar="PNG", help="draw theta(t) and onsets")
    add_kit_track_options(trk)
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
    add_hardware_actions(actions)


def _track(args):
    from ..robot.config import load_source
    from ..robot.metrics import metrics
    from ..robot.track import check_tracking, reference, track
    from ..stroke import as_trajectory

    check_kit_track(args)
    config = robot_config(args.config)
    controllers = config.controllers
    names = list(controllers) if args.controller == "all" else [args.controller]
    for name in names:
        if name not in controllers:
            raise ParameterError(f"--controller must be one of {', '.join(controllers)} or all, got {name!r}")
    if args.kit is not None:
        return track_kit_command(args, config, names)
    rate = args.rate
    source = load_source(args.source, library=args.library, stick=args.stick, plant=config.plant)
    span = as_trajectory(source)
    check_tracking(span.t_end - span.start, rate, controllers=len(names), name="--rate")
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

    config = robot_config(args.config)
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
