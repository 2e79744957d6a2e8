"""The ``drumstroke`` command: a thin layer over the API, and the only place that prints.

Sub-commands: ``simulate``, ``presets``, ``figures``, ``sweep``, ``demo``. Bad input ends
with exit status 2 and one line naming the parameter, the value and the
allowed range.
"""

import argparse
import contextlib
import dataclasses
import io
import math
import os
import sys
import time
from pathlib import Path

from . import __version__
from ._checks import check_real
from .errors import DrumstrokeError, ParameterError
from .model import MODELS, inertia_ratio
from .presets import PRESETS
from .stroke import simulate
from .trajectory import DEFAULT_RATE

FIGURES = {p.figure: name for name, p in PRESETS.items() if p.figure}
"""The paper's figures and the presets that reproduce them."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def main(argv=None):
    """Run the command line with ``argv`` (default: ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        return args.run(args) or 0
    except DrumstrokeError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head: stop quietly, as other tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as error:
        where = f" {error.filename!r}" if error.filename else ""
        print(f"drumstroke {args.command}: error:{where} {error.strerror or error}", file=sys.stderr)
        return 2
    except ImportError as error:
        print(f"drumstroke {args.command}: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"drumstroke {args.command}: interrupted", file=sys.stderr)
        return 130


def build_parser():
    parser = _Parser(prog="drumstroke", description="Drum strokes from a physical model of a bouncing stick.")
    parser.add_argument("--version", action="version", version=f"drumstroke {__version__}")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")

    sim = commands.add_parser("simulate", help="simulate one stroke from a recipe file or a preset")
    sim.add_argument("recipe", metavar="RECIPE", help="a recipe .toml file or a preset name (see 'drumstroke presets')")
    sim.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ",
                     help=f"sampling rate of --csv in Hz (default {DEFAULT_RATE:g})")
    sim.add_argument("--model", choices=MODELS, help="override the recipe's model")
    sim.add_argument("--json", type=Path, metavar="PATH", help="write recipe, impacts and rests as JSON")
    sim.add_argument("--csv", type=Path, metavar="PATH", help="write t,theta,omega at --rate as CSV")
    sim.add_argument("--plot", type=Path, metavar="PATH", help="write a PNG of theta(t), impacts and a(t)")
    _add_sound_options(sim)
    steps = sim.add_argument_group("post-processing, applied in the order given")
    steps.add_argument("--stretch", action=_Step, type=float, metavar="F", help="play F times slower (F < 1: faster)")
    steps.add_argument("--compress", action=_Step, type=float, metavar="F",
                       help="scale the height above the head by F (louder or softer)")
    steps.add_argument("--reverse", action=_Step, nargs=0, help="play backwards")
    steps.add_argument("--trim", action=_Step, metavar="T0:T1", help="keep the part from T0 to T1 s (either may be empty)")
    steps.add_argument("--catch", action=_Step, type=int, metavar="N", help="end at the top of the rebound after impact N")
    sim.set_defaults(run=_simulate, steps=[])

    lib = commands.add_parser("library", help="build or list a stroke library (text files a robot host loads)")
    lib_commands = lib.add_subparsers(dest="library_command", parser_class=_Parser, metavar="ACTION", required=True)
    build = lib_commands.add_parser("build", help="simulate a palette and write it as a library folder")
    build.add_argument("directory", type=Path, metavar="DIR")
    build.add_argument("--rate", type=float, default=DEFAULT_RATE, metavar="HZ",
                       help=f"samples per second of the trajectories (default {DEFAULT_RATE:g})")
    build.add_argument("--palette", type=Path, metavar="FILE", help="a palette .toml file (default: the shipped 20 strokes)")
    build.set_defaults(run=_library_build)
    listing = lib_commands.add_parser("list", help="list a library's strokes")
    listing.add_argument("directory", type=Path, metavar="DIR")
    listing.set_defaults(run=_library_list)

    comp = commands.add_parser("compose", help="turn a score (MIDI file or text pattern) into one trajectory per stick")
    comp.add_argument("score", type=Path, metavar="SCORE", help="a .mid/.midi file or a text pattern (see the README)")
    comp.add_argument("--library", type=Path, required=True, metavar="DIR", help="a library folder ('library build')")
    comp.add_argument("--rate", type=float, metavar="HZ", help="control rate of the result (default: the library's)")
    comp.add_argument("--mapping", type=Path, metavar="FILE", help="MIDI note -> stroke mapping .toml (default: see README)")
    comp.add_argument("--csv", type=Path, metavar="PATH", help="write t and theta, omega per stick as CSV")
    comp.add_argument("--json", type=Path, metavar="PATH", help="write the notes, placements and impacts as JSON")
    comp.add_argument("--plot", type=Path, metavar="PATH", help="write a PNG of theta(t) per stick with the notes")
    _add_sound_options(comp)
    comp.add_argument("--strict", action="store_true", help="exit with status 3 if any note was left out")
    comp.set_defaults(run=_compose)

    pre = commands.add_parser("presets", help="list the named recipes")
    pre.set_defaults(run=_presets)

    fig = commands.add_parser("figures", help="draw the paper's Figs. 4-7 as PNG files")
    fig.add_argument("outdir", type=Path, metavar="OUTDIR")
    fig.add_argument("--model", choices=MODELS, default="paper", help="model to draw them with (default paper)")
    fig.set_defaults(run=_figures)

    swp = commands.add_parser("sweep", help="simulate a grid or random sample of recipes; one row of features each")
    swp.add_argument("grid", type=Path, metavar="GRID", help="a sweep .toml file (see the README)")
    swp.add_argument("--out", type=Path, required=True, metavar="TABLE", help="the table to write: .csv or .parquet")
    swp.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler (tcp://host:8786) to run on")
    swp.add_argument("--audible-db", type=float, metavar="DB",
                     help="override the file's audibility threshold (dB below the loudest impact)")
    swp.set_defaults(run=_sweep)

    sts = commands.add_parser("stats", help="listening-test statistics: Tryon's ICIs, Rg, TOST, correlations")
    sts.add_argument("responses", type=Path, nargs="?", metavar="RESPONSES",
                     help="a CSV with subject,pair,robot,answer,confidence,similarity")
    sts.add_argument("--summary", metavar="MEAN_A,SD_A,MEAN_B,SD_B,N",
                     help="use two groups' summary numbers instead (e.g. the paper's 4.227,2.654,4.999,1.564,22)")
    sts.add_argument("--pairs", type=int, default=10, help="pairs per subject for --summary (default 10)")
    sts.add_argument("--delta", type=float, metavar="D", help="equivalence margin in answers")
    sts.add_argument("--alpha", type=float, default=0.05, help="significance level (default 0.05)")
    sts.add_argument("--seed", type=int, default=0, help="seed of the simulated Group B (default 0)")
    sts.add_argument("--json", type=Path, metavar="OUT", help="write the statistics as JSON")
    sts.set_defaults(run=_stats)

    lis = commands.add_parser("listen", help="the listening-test web app: serve it, analyse it, make its stimuli")
    lis_commands = lis.add_subparsers(dest="listen_command", parser_class=_Parser, metavar="ACTION", required=True)
    srv = lis_commands.add_parser("serve", help="serve the listening test in a browser")
    srv.add_argument("config", type=Path, metavar="CONFIG", help="the test's .toml (title, admin_token, seed, pairs)")
    srv.add_argument("--db", type=Path, required=True, metavar="SQLITE", help="where answers are stored")
    srv.add_argument("--host", default="127.0.0.1")
    srv.add_argument("--port", type=int, default=8000)
    srv.set_defaults(run=_listen_serve)
    ana = lis_commands.add_parser("analyze", help="run the statistics on the answers collected")
    ana.add_argument("--db", type=Path, required=True, metavar="SQLITE")
    ana.add_argument("--delta", type=float, metavar="D", help="equivalence margin in answers")
    ana.add_argument("--json", type=Path, metavar="OUT", help="write the statistics as JSON")
    ana.set_defaults(run=_listen_analyze)
    mks = lis_commands.add_parser("make-stimuli", help="render the robot's side of each pair from library strokes")
    mks.add_argument("--library", type=Path, required=True, metavar="DIR")
    mks.add_argument("--out", type=Path, required=True, metavar="DIR")
    mks.add_argument("--strokes", metavar="A,B,...", help="which strokes (default: all)")
    mks.set_defaults(run=_listen_make_stimuli)

    robot = commands.add_parser("robot", help="play strokes on a simulated robot joint; validate and export trajectories")
    robot_commands = robot.add_subparsers(dest="robot_command", parser_class=_Parser, metavar="ACTION", required=True)
    trk = robot_commands.add_parser("track", help="play a stroke with one controller or all, and score it")
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
    trk.set_defaults(run=_robot_track)
    tun = robot_commands.add_parser("tune", help="tune a controller's gains over a library, before/after table")
    tun.add_argument("--library", type=Path, required=True, metavar="DIR")
    tun.add_argument("--controller", default="pi", metavar="NAME", help="pi (default), pid-ff or impedance")
    tun.add_argument("--per-stroke", action="store_true", help="one gain set per stroke (gain scheduling)")
    tun.add_argument("--evaluations", type=int, default=100, metavar="N", help="objective evaluations (default 100)")
    tun.add_argument("--config", type=Path, metavar="TOML", help="robot config: [plant], starting gains")
    tun.add_argument("--report", type=Path, metavar="JSON", help="write gains and metrics as JSON")
    tun.set_defaults(run=_robot_tune)
    val = robot_commands.add_parser("validate", help="check a trajectory CSV before it goes to hardware")
    val.add_argument("trajectory", type=Path, metavar="TRAJECTORY")
    val.add_argument("--stick", help="the stick of a composition CSV")
    val.add_argument("--config", type=Path, metavar="TOML", help="robot config with a [limits] table")
    val.set_defaults(run=_robot_validate)
    exp = robot_commands.add_parser("export", help="validate and export a trajectory CSV for a robot stack")
    exp.add_argument("trajectory", type=Path, metavar="TRAJECTORY")
    exp.add_argument("--format", choices=("csv", "ros-json"), required=True)
    exp.add_argument("--out", type=Path, required=True, metavar="PATH")
    exp.add_argument("--stick", help="the stick of a composition CSV")
    exp.add_argument("--config", type=Path, metavar="TOML", help="robot config with a [limits] table")
    exp.set_defaults(run=_robot_export)

    demo = commands.add_parser("demo", help="build the library, render every stroke, compose a groove, write index.html")
    demo.add_argument("outdir", type=Path, metavar="OUTDIR")
    demo.set_defaults(run=_demo)
    return parser


def _simulate(args):
    rate = check_real("--rate", args.rate, low=0.0, high=1e6, low_open=True, unit="Hz")
    bar = _Bar("simulating", delay=1.0)
    stroke = simulate(args.recipe, model=args.model, progress=bar.update)
    bar.close()
    _print_summary(stroke)
    if args.steps:
        from .palette.transforms import apply_step

        for op, value in args.steps:
            try:
                stroke = apply_step(stroke, op, value)
            except DrumstrokeError as error:
                raise type(error)(f"--{op}: {error}") from None
        impacts = stroke.impacts
        print(f"after {', '.join(stroke.history[1:])}: {len(impacts)} impacts over {stroke.t_end:.6g} s")
    _write_outputs(stroke, json_path=args.json, csv_path=args.csv, plot_path=args.plot, wav_path=args.wav,
                   midi_path=args.midi, rate=rate, snares=not args.no_snares)


def _write_outputs(stroke, *, json_path=None, csv_path=None, plot_path=None, wav_path=None, midi_path=None,
                   rate=DEFAULT_RATE, title=None, snares=True):
    """Write a Stroke's or a Trajectory's files; return the paths written."""
    from .render.data import write_csv, write_json

    written = []
    if json_path:
        write_json(stroke, json_path)
        written.append(json_path)
    if csv_path:
        write_csv(stroke, csv_path, rate=rate)
        written.append(csv_path)
    if plot_path:
        from .render.plot import save_stroke_plot

        save_stroke_plot(stroke, plot_path, title=title)
        written.append(plot_path)
    _write_sound(stroke.impacts.t, stroke.impacts.tip_speed, stroke.impacts.level_db, wav_path=wav_path,
                 midi_path=midi_path, duration=None, title=f"{stroke.name} (model {stroke.model})",
                 snares=snares, written=written)
    for path in written:
        print(f"wrote {path}")
    return written


def _add_sound_options(parser):
    parser.add_argument("--wav", type=Path, metavar="PATH", help="write 48 kHz mono audio of the impacts")
    parser.add_argument("--no-snares", action="store_true", help="render --wav with the snare wires off")
    parser.add_argument("--midi", type=Path, metavar="PATH",
                        help="write the impacts as General MIDI percussion (channel 10, note 38)")


def _write_sound(times, tip_speeds, levels, *, wav_path, midi_path, duration, title, snares, written):
    if wav_path:
        from .render.audio import Drum, render_wav

        render_wav(wav_path, times, tip_speeds, duration=duration, drum=Drum(snares=snares))
        written.append(wav_path)
    if midi_path:
        from .render.midi import write_midi

        write_midi(midi_path, times, levels, title=title)
        written.append(midi_path)


def _print_summary(stroke, *, rows=10):
    recipe = stroke.recipe
    d = inertia_ratio(recipe.model, recipe.stick)
    print(
        f"stroke {recipe.name or 'custom'}: model {recipe.model} (D = {d:.4f} m^2), "
        f"theta_max = {recipe.theta_max:.4f} rad, c = {recipe.cor:g}, {recipe.t_end:g} s"
    )
    impacts = stroke.impacts
    rest = f"at rest from {stroke.rest_time:.6f} s" if stroke.rest_time is not None else "still moving at the end"
    print(f"{len(impacts)} impacts; {rest}")
    if len(impacts):
        print(f"{'#':>5} {'t (s)':>11} {'omega (rad/s)':>14} {'tip (m/s)':>10} {'level (dB)':>10}")
        for i in range(min(rows, len(impacts))):
            print(
                f"{i + 1:>5} {impacts.t[i]:>11.6f} {impacts.omega[i]:>14.6f} "
                f"{impacts.tip_speed[i]:>10.6f} {impacts.level_db[i]:>10.2f}"
            )
        if len(impacts) > rows:
            print(f"{'...':>5} ({len(impacts) - rows} more; level re 1 m/s tip speed)")


def _sweep(args):
    from .sweep import Grid, check_table_path, run_sweep, write_table

    grid = Grid.from_toml(args.grid)
    if args.audible_db is not None:
        grid = dataclasses.replace(grid, audible_db=args.audible_db)
    check_table_path(args.out, name="--out")  # before the work, not after it
    where = f"on {args.scheduler}" if args.scheduler else "here"
    print(f"sweep {args.grid}: {len(grid)} points ({grid.mode}), {where}")
    started = time.monotonic()
    bar = _Bar("sweeping")
    table = run_sweep(grid, scheduler=args.scheduler, progress=bar.update)
    bar.close()
    write_table(table, args.out)
    failed = int(sum(1 for error in table["error"] if error))
    note = f"; {failed} could not be simulated (see the error column)" if failed else ""
    print(f"wrote {args.out}: {len(table['point'])} rows in {time.monotonic() - started:.1f} s{note}")


def _library_build(args):
    from .palette.library import build_library

    rate = check_real("--rate", args.rate, low=1.0, high=1e5, unit="Hz")
    started = time.monotonic()
    bar = _Bar("building")
    library = build_library(args.directory, rate=rate, palette=args.palette, progress=bar.update)
    bar.close()
    print(f"wrote {args.directory}/: {len(library)} strokes at {rate:g} Hz in {time.monotonic() - started:.1f} s")


def _library_list(args):
    from .dynamics import level_to_velocity
    from .palette.library import load_library
    from .score import default_mapping

    library = load_library(args.directory)
    notes = {stroke: note for note, (stroke, _) in sorted(default_mapping(list(library)).items(), reverse=True)}
    width = max(len(name) for name in library)
    print(f"{library.path}: {len(library)} strokes at {library.rate:g} Hz")
    print(f"{'stroke':<{width}}  {'note':>4}  {'impacts':>7}  {'length':>7}  {'vel':>3}  category: description")
    for name, entry in library.items():
        impacts = entry.trajectory.impacts
        velocity = level_to_velocity(impacts.level_db[0]) if len(impacts) else "-"
        print(f"{name:<{width}}  {notes.get(name, '-'):>4}  {len(impacts):>7}  {entry.trajectory.t_end:>6.3f}s  "
              f"{velocity:>3}  {entry.category}: {entry.description}")


def _compose(args):
    from .compose import compose
    from .palette.library import load_library

    library = load_library(args.library)
    notes, unmapped = _read_score(args.score, args.mapping, library)
    rate = None if args.rate is None else check_real("--rate", args.rate, low=1.0, high=1e5, unit="Hz")
    piece = compose(notes, library, rate=rate)
    played = sum(p.played for p in piece.placements)
    sticks = ", ".join(f"{name} ({len(s.impacts)} impacts)" for name, s in piece.sticks.items())
    print(f"composed {played} of {len(notes)} notes from {args.score} (model {piece.model}): {piece.t_end:.3f} s at "
          f"{piece.rate:g} Hz, score time 0 at {piece.offset:g} s; sticks: {sticks}")
    for note, count in sorted(unmapped.items()):
        print(f"warning: {count} MIDI notes with number {note} have no mapping; left out", file=sys.stderr)
    for problem in piece.problems:
        print(f"warning: {problem}", file=sys.stderr)
    _write_composition(piece, title=args.score.stem, csv=args.csv, json=args.json, plot=args.plot, wav=args.wav,
                       midi=args.midi, snares=not args.no_snares)
    if args.strict and (unmapped or played < len(notes)):
        print("drumstroke compose: error: notes were left out (--strict)", file=sys.stderr)
        return 3
    return 0


def _read_score(path, mapping_path, library):
    from .score import default_mapping, from_midi_notes, read_mapping, read_pattern

    if path.suffix.lower() in (".mid", ".midi"):
        from .render.midi import read_midi_notes

        mapping = read_mapping(mapping_path) if mapping_path else default_mapping(list(library))
        return from_midi_notes(read_midi_notes(path), mapping)
    if mapping_path:
        raise ParameterError(f"--mapping applies to MIDI scores (.mid, .midi); {str(path)!r} is a text pattern, "
                             "which names its strokes")
    return read_pattern(path), {}


def _write_composition(piece, *, title, csv=None, json=None, plot=None, wav=None, midi=None, snares=True):
    from .render.data import write_composition_csv, write_composition_json

    written = []
    if csv:
        write_composition_csv(piece, csv)
        written.append(csv)
    if json:
        write_composition_json(piece, json)
        written.append(json)
    if plot:
        from .render.plot import composition_figure, save_figure

        save_figure(composition_figure(piece, title=title), plot)
        written.append(plot)
    times, speeds, levels = piece.impacts()
    _write_sound(times, speeds, levels, wav_path=wav, midi_path=midi, duration=None,
                 title=f"{title} (model {piece.model})", snares=snares, written=written)
    for path in written:
        print(f"wrote {path}")


def _robot_setup(config):
    """The plant and the controllers' starting gains from a robot config file (or the defaults)."""
    from ._checks import check_keys, read_toml
    from .robot.controllers import CONTROLLERS, controller_from_dict
    from .robot.plant import Plant

    data = read_toml(config, "robot config") if config else {}
    check_keys("robot config", data, ("plant", "controller", "limits"))
    plant = Plant.from_dict(data.get("plant", {}))
    tables = data.get("controller", {})
    if not isinstance(tables, dict):
        raise ParameterError(f"controller must be a table of [controller.NAME] tables, got {tables!r}")
    check_keys("controller", tables, list(CONTROLLERS))
    controllers = {name: controller_from_dict(name, tables.get(name, {})) for name in CONTROLLERS}
    return plant, controllers, data


def _robot_limits(data):
    from .robot.validate import JointLimits

    return JointLimits.from_dict(data.get("limits", {}))


def _robot_source(args, plant):
    """The stroke SOURCE names, as a Trajectory."""
    from .stroke import as_trajectory

    source = args.source
    if args.library:
        from .palette.library import load_library

        return load_library(args.library)[source].trajectory
    if source.lower().endswith(".csv"):
        from .palette.trajectory import read_trajectory_csv
        from .robot.track import trajectory_from_samples

        t, theta, omega, model = read_trajectory_csv(source, stick=args.stick)
        return trajectory_from_samples(t, theta, omega, head=plant.head, tip_distance=plant.stick.pivot_to_tip,
                                       name=Path(source).stem, model=model)
    return as_trajectory(simulate(source))


def _robot_track(args):
    from .robot.metrics import metrics
    from .robot.track import reference, track

    plant, controllers, _ = _robot_setup(args.config)
    names = list(controllers) if args.controller == "all" else [args.controller]
    for name in names:
        if name not in controllers:
            raise ParameterError(f"--controller must be one of {', '.join(controllers)} or all, got {name!r}")
    rate = check_real("--rate", args.rate, low=10.0, high=1e5, unit="Hz")
    ref = reference(_robot_source(args, plant), rate)
    if args.plant == "mujoco":
        from .robot.mujoco_plant import track_mujoco as run
    else:
        run = track
    played = [run(ref, controllers[name], plant) for name in names]
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
        from ._atomic import write_json
        from .robot.controllers import to_dict

        report = {"reference": ref.name, "model": ref.model, "plant": args.plant, "rate": rate,
                  "plant_parameters": plant.to_dict(),
                  "controllers": [{"name": p.controller, "gains": to_dict(controllers[p.controller]),
                                   "metrics": m.to_dict()} for p, m in zip(played, scores)]}
        write_json(args.report, report)
        written.append(args.report)
    if args.plot:
        from .render.plot import save_figure, tracking_figure

        save_figure(tracking_figure(played), args.plot)
        written.append(args.plot)
    for path in written:
        print(f"wrote {path}")


def _robot_tune(args):
    from .palette.library import load_library
    from .robot.track import reference
    from .robot.tune import tune

    plant, controllers, _ = _robot_setup(args.config)
    if args.controller not in controllers:
        raise ParameterError(f"--controller must be one of {', '.join(controllers)}, got {args.controller!r}")
    library = load_library(args.library)
    refs = [reference(s.trajectory, library.rate) for s in library.values()]
    start = controllers[args.controller]
    scope = "one gain set per stroke" if args.per_stroke else "one gain set for all"
    print(f"tuning {args.controller} on {len(refs)} strokes of {args.library} ({scope}, "
          f"{args.evaluations} evaluations each)")
    bar = _Bar("tuning")
    result = tune(refs, start, plant=plant, per_stroke=args.per_stroke, evaluations=args.evaluations,
                  progress=bar.update)
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
        from ._atomic import write_json
        from .robot.controllers import to_dict

        report = {"controller": args.controller, "per_stroke": args.per_stroke, "evaluations": result.evaluations,
                  "strokes": [{"name": r.name, "gains": to_dict(c), "before": b.to_dict(), "after": a.to_dict()}
                              for r, c, b, a in zip(refs, result.controllers, result.before, result.after)]}
        write_json(args.report, report)
        print(f"wrote {args.report}")


def _robot_validate(args):
    from .robot.validate import validate_file

    plant, _, data = _robot_setup(args.config)
    checked = validate_file(args.trajectory, stick=args.stick, head=plant.head, limits=_robot_limits(data))
    print(f"{args.trajectory}: valid: {_peaks(checked)}")


def _robot_export(args):
    from .palette.trajectory import read_trajectory_csv
    from .robot.export import export_csv, export_ros_json
    from .robot.validate import validate_file

    plant, _, data = _robot_setup(args.config)
    limits = _robot_limits(data)
    checked = validate_file(args.trajectory, stick=args.stick, head=plant.head, limits=limits)  # the file's rate too
    model = read_trajectory_csv(args.trajectory, stick=args.stick)[3]
    name = args.trajectory.stem + (f"-{args.stick}" if args.stick else "")
    write = export_csv if args.format == "csv" else export_ros_json
    write(args.out, checked.t, checked.theta, checked.omega, rate=checked.rate, model=model, name=name,
          head=plant.head, limits=limits)
    print(f"wrote {args.out} ({args.format}): {_peaks(checked)}")


def _peaks(checked):
    return (f"{len(checked.t)} samples at {checked.rate:g} Hz, theta {checked.lowest_angle:.4f} to "
            f"{checked.highest_angle:.4f} rad, peak speed {checked.peak_speed:.3g} rad/s, acceleration "
            f"{checked.peak_acceleration:.3g} rad/s^2, jerk {checked.peak_jerk:.3g} rad/s^3 (head {checked.head:.4f} rad)")


def _listen_serve(args):
    from .evaluation.app import Config, Store, make_server

    config = Config.from_toml(args.config)
    store = Store(args.db)
    server = make_server(config, store, host=args.host, port=args.port)
    host, port = server.server_address[:2]
    print(f"serving {config.title!r} ({len(config.pairs)} pairs, seed {config.seed}) on http://{host}:{port}/ ; "
          f"answers in {args.db}; export: http://{host}:{port}/admin/export.csv?token=...; Ctrl-C stops")
    try:
        server.serve_forever()
    finally:
        server.server_close()


def _listen_analyze(args):
    from .evaluation.app import Store
    from .evaluation.stats import parse_responses

    if not args.db.is_file():
        raise ParameterError(f"--db {str(args.db)!r} does not exist")
    rows = [[str(v) for v in row] for row in Store(args.db).rows()]
    if not rows:
        raise ParameterError(f"--db {str(args.db)!r} holds no answers yet")
    _print_stats(args, responses=parse_responses(rows, name=str(args.db)))


def _listen_make_stimuli(args):
    from .palette.library import load_library
    from .render.audio import render_wav
    from .robot.controllers import controller
    from .robot.track import reference, track

    library = load_library(args.library)
    names = args.strokes.split(",") if args.strokes else list(library)
    lines = ['title = "Robot or human?"', 'admin_token = "change-this-token"', "seed = 1", ""]
    for name in names:
        played = track(reference(library[name].trajectory, library.rate), controller("impedance"))
        wav = args.out / f"robot-{name}.wav"
        render_wav(wav, played.onsets, played.onset_speed)
        print(f"wrote {wav} ({len(played.onsets)} onsets played by the simulated robot)")
        lines += ["[[pair]]", f'id = "{name}"', f'human = "human-{name}.wav"   # record this', f'robot = "robot-{name}.wav"', ""]
    from ._atomic import write_atomic

    write_atomic(args.out / "listening-test.toml", "\n".join(lines))
    print(f"wrote {args.out / 'listening-test.toml'}: add the human recordings it names, set admin_token and seed")


def _stats(args):
    from .evaluation import stats

    if (args.responses is None) == (args.summary is None):
        raise ParameterError("give either RESPONSES (a CSV) or --summary MEAN_A,SD_A,MEAN_B,SD_B,N")
    if args.summary:
        try:
            mean_a, sd_a, mean_b, sd_b, n = (float(x) for x in args.summary.split(","))
        except ValueError:
            raise ParameterError(f"--summary must be MEAN_A,SD_A,MEAN_B,SD_B,N, got {args.summary!r}") from None
        if not n.is_integer():
            raise ParameterError(f"--summary's N must be a whole number of subjects, got {n:g}")
        result = stats.from_summary(mean_a, sd_a, mean_b, sd_b, int(n), pairs=args.pairs, alpha=args.alpha)
        data = result.to_dict()
    else:
        return _print_stats(args, responses=stats.read_responses(args.responses))
    _print_result(args, result, data)
    _write_stats_json(args, data)


def _print_stats(args, *, responses):
    from .evaluation import stats

    analysis = stats.analyze(responses, alpha=getattr(args, "alpha", stats.ALPHA), seed=getattr(args, "seed", 0))
    data = analysis.to_dict()
    _print_result(args, analysis.tryon, data)
    for key, value in data["correlations"].items():
        r = "n/a" if value["r"] is None else f"r = {value['r']:+.3f}, p = {value['p']:.3g}"
        print(f"incorrect answers vs {key.replace('_', ' ')}: {r}")
    _write_stats_json(args, data)


def _print_result(args, result, data):
    a, b = result.a, result.b
    print(f"{'':<26}{'Group A':>10}{'Group B':>10}")
    for label, x, y in (("mean incorrect answers", a.mean, b.mean), ("SD", a.sd, b.sd), ("SE", a.se, b.se)):
        print(f"{label:<26}{x:>10.3f}{y:>10.3f}")
    print(f"{'N':<26}{a.n:>10}{b.n:>10}")
    ici_a, ici_b = (f"{lo:.3f}-{hi:.3f}" for lo, hi in (result.ici_a, result.ici_b))
    print(f"{'inferential CI':<26}{ici_a:>12}{ici_b:>12}")
    print(f"t_pq = {result.t_pq:.4f}, t_p = {result.t_p:.4f} (alpha {result.alpha:g}); E = {result.e:.4f}")
    print(f"maximum probable difference Rg = {result.rg:.4f} answers = {result.rg_percent:.2f} % of {result.pairs} "
          "pairs")
    if args.delta is not None:
        p_low, p_high, same = result.tost(args.delta)
        verdict = "equivalent" if result.equivalent(args.delta) else "not shown equivalent"
        print(f"delta = {args.delta:g} answers: {verdict} (Rg {'<' if result.rg < args.delta else '>='} delta); "
              f"TOST p = {p_low:.4g}, {p_high:.4g} at alpha/2 each: {'equivalent' if same else 'not equivalent'}")
        data["delta"] = {"delta": args.delta, "equivalent": result.equivalent(args.delta),
                         "tost_p": [p_low, p_high], "tost_equivalent": same}


def _write_stats_json(args, data):
    if args.json:
        from ._atomic import write_json

        write_json(args.json, data)
        print(f"wrote {args.json}")


def _presets(args):
    width = max(len(name) for name in PRESETS)
    for name, p in PRESETS.items():
        figure = f" [{p.figure}]" if p.figure else ""
        print(f"{name:<{width}}  {p.category}{figure}: {p.description}")


def _figures(args):
    bar = _Bar("drawing figures")
    for i, (figure, name) in enumerate(FIGURES.items()):
        stroke = simulate(name, model=args.model)
        path = args.outdir / f"{_slug(figure)}-{name}.png"
        _write_outputs(stroke, plot_path=path, title=f"{figure} {name}")
        bar.update((i + 1) / len(FIGURES))
    bar.close()


def _demo(args):
    from .compose import compose
    from .palette.library import DEMO_PATTERN, build_library
    from .render.page import Card, write_index
    from .score import read_pattern

    out = args.outdir
    bar = _Bar("demo")
    for i, (figure, name) in enumerate(FIGURES.items()):
        stroke = simulate(name)
        stem = out / f"{_slug(figure)}-{name}"
        print()
        _print_summary(stroke, rows=3)
        _write_outputs(stroke, json_path=stem.with_suffix(".json"), csv_path=stem.with_suffix(".csv"),
                       plot_path=stem.with_suffix(".png"), title=f"{figure} {name}")
        bar.update(0.2 * (i + 1) / len(FIGURES))
    library = build_library(out / "library", progress=lambda f: bar.update(0.2 + 0.2 * f))
    print(f"\nwrote {out / 'library'}/: {len(library)} strokes at {library.rate:g} Hz")
    cards = []
    for i, (name, entry) in enumerate(library.items()):
        stem = out / "strokes" / name
        trajectory = entry.trajectory
        _quietly(_write_outputs, trajectory, plot_path=stem.with_suffix(".png"), wav_path=stem.with_suffix(".wav"),
                 midi_path=stem.with_suffix(".mid"))
        impacts = trajectory.impacts
        facts = (f"{len(impacts)} impacts in {trajectory.t_end:.2f} s; first at {impacts.t[0]:.3f} s, "
                 f"{impacts.tip_speed[0]:.2f} m/s tip speed; model {trajectory.model}.")
        cards.append(Card(name, entry.category, entry.description, f"strokes/{name}.png", f"strokes/{name}.wav",
                          f"strokes/{name}.mid", facts))
        bar.update(0.4 + 0.5 * (i + 1) / len(library))
    piece = compose(read_pattern(DEMO_PATTERN), library)
    (out / "groove.pattern").write_text(DEMO_PATTERN.read_text())
    _quietly(_write_composition, piece, title="groove", csv=out / "groove.csv", json=out / "groove.json",
             plot=out / "groove.png", wav=out / "groove.wav", midi=out / "groove.mid")
    played = sum(p.played for p in piece.placements)
    print(f"composed groove.pattern: {played} of {len(piece.placements)} notes on {len(piece.sticks)} sticks, "
          f"{piece.t_end:.2f} s")
    facts = f"{played} notes on the sticks {', '.join(piece.sticks)}; {piece.t_end:.2f} s at {piece.rate:g} Hz."
    groove_card = Card("groove", "composition", "Four bars at 96 bpm composed from the library (groove.pattern): "
                       "backbeat singles, ghost taps, a double, a triplet ruff, rolls and a free bounce.",
                       "groove.png", "groove.wav", "groove.mid", facts)
    write_index(out / "index.html", title="drumstroke: the stroke palette",
                intro="Each stroke of the shipped library as the robot's motor angle θ(t) with its impacts, "
                      "and as it sounds on a synthesized snare drum; first a groove composed from them.",
                cards=[groove_card, *cards])
    bar.update(1.0)
    bar.close()
    print(f"\ndemo written to {out}/: open {out / 'index.html'} in a browser")


def _quietly(function, *args, **kwargs):
    """Call ``function`` without its 'wrote ...' lines (the demo writes too many files to list)."""
    with contextlib.redirect_stdout(io.StringIO()):
        return function(*args, **kwargs)


def _slug(figure):
    return figure.lower().replace(". ", "").replace(" ", "")


class _Step(argparse.Action):
    """Record a post-processing option and its value in ``steps``, in command-line order."""

    def __call__(self, parser, namespace, values, option_string=None):
        if self.dest == "reverse":
            values = True
        elif self.dest == "trim":
            values = _trim_value(parser, values)
        namespace.steps = [*namespace.steps, (self.dest, values)]


def _trim_value(parser, text):
    start, sep, end = text.partition(":")
    try:
        return [float(start) if start else 0.0, float(end) if end else None] if sep else parser.error("")
    except (ValueError, SystemExit):
        parser.error(f"argument --trim: must be START:END in seconds (either may be empty), got {text!r}")


class _Bar:
    """A progress bar on stderr, drawn only on a terminal and only after ``delay`` seconds."""

    def __init__(self, label, *, delay=0.0):
        self.label = label
        self.start = time.monotonic()
        self.delay = delay
        self.drawn = False
        self.enabled = sys.stderr.isatty()

    def update(self, fraction):
        if not self.enabled or time.monotonic() - self.start < self.delay:
            return
        filled = math.floor(30 * min(max(fraction, 0.0), 1.0))
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (30 - filled)}] {100 * fraction:5.1f}%")
        sys.stderr.flush()
        self.drawn = True

    def close(self):
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
