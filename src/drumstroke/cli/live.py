"""``drumstroke live``: notes in over OSC, MIDI or a score; a validated setpoint stream out, until interrupted."""

import sys
from datetime import datetime

from ..errors import ParameterError
from ..formats import json
from ..render.page import plural
from ..robot import ENGINES
from ._common import add_cor, add_model, robot_config
from ._options import Output, add_mkdir, existing_file, number


def add_live(live):
    """Give ``live``'s parser ``live`` its description and options."""
    live.description = ("Take notes as they arrive (OSC, MIDI, or a score played against the clock), design each stroke "
                        "into each stick's running motion within the latency, and stream setpoints t, theta, omega, "
                        "alpha per stick (with --kit: every joint of every limb) at the control rate (OSC, CSV on "
                        "stdout, a simulated robot), each chunk "
                        "validated against the joint's limits. Ctrl-C, SIGTERM or --duration stops within a second: each stick "
                        "finishes the stroke in progress, the notes not yet begun are given up, the sticks move to "
                        "rest and the session's record is written; a second signal stops at once. Messages go to "
                        "stderr, at most 20 problems a second (the rest counted).")
    ins = live.add_argument_group("notes in (at least one)")
    ins.add_argument("--osc-in", type=_address(default_host="127.0.0.1", port_low=0), metavar="[HOST:]PORT",
                     help="listen for /drum/note and /drum/note/at over UDP (host default 127.0.0.1: this machine)")
    ins.add_argument("--midi-in", metavar="NAME", help="read notes from the MIDI input port NAME (channel 10, keys "
                                                        "37, 38, 40)")
    ins.add_argument("--midi-virtual", metavar="NAME", help="open a virtual MIDI input port NAME for other programs "
                                                             "(where the platform allows)")
    ins.add_argument("--score", type=existing_file, metavar="FILE",
                     help="play a score (.mid or a pattern) against the clock: each note arrives at its time, after "
                          "the count-in")
    ins.add_argument("--count-in", type=number(low=0.0, high=60.0, unit="s"), default=1.0, metavar="S",
                     help="s into the session the score starts, in [0, 60] (default 1)")
    outs = live.add_argument_group("setpoints out (at least one)")
    outs.add_argument("--osc-out", type=_address(default_host=None, port_low=1), metavar="HOST:PORT",
                      help="send /drum/setpoint stick t theta omega alpha (64-bit floats) over UDP")
    outs.add_argument("--csv", action="store_true", help="write the setpoints as CSV to stdout")
    outs.add_argument("--simulate-robot", choices=ENGINES, metavar="ENGINE",
                      help=f"play the stream on a simulated joint ({', '.join(ENGINES)}) and report each onset")
    live.add_argument("--controller", default="pid-ff", help="the simulated robot's controller (default pid-ff)")
    live.add_argument("--config", type=existing_file, metavar="TOML",
                      help="robot config: [plant] for the simulated joint, [limits] the stream keeps")
    live.add_argument("--latency", type=number(low=1.0, high=10_000.0, unit="ms"), default=50.0, metavar="MS",
                      help="ms between a note's arrival and its sound, in [1, 10000] (default 50)")
    live.add_argument("--horizon", type=number(low=0.0, high=60.0, low_open=True, unit="s"), metavar="S",
                      help="s: a note heard further ahead of its arrival is dropped, in [--latency, 60] (default 4, or "
                           "the latency if longer)")
    live.add_argument("--rate", type=number(low=10.0, high=1e5, unit="Hz"), default=1000.0,
                      help="the control rate, Hz, in [10, 1e5] (default 1000)")
    add_model(live)
    live.add_argument("--sticks", default="right,left", metavar="A,B",
                      help="the sticks' names, comma-separated (default right,left)")
    live.add_argument("--kit", nargs="?", const="", metavar="FILE",
                      help="play a kit: each note on its piece (OSC's piece, MIDI's keys, a score's pieces), every "
                           "joint of every limb streamed (alone: the shipped kit; FILE: a kit .toml)")
    live.add_argument("--lead", choices=("right", "left"), default="right",
                      help="with --kit: the hand that keeps time on the hi-hat or ride (default right)")
    add_cor(live)
    live.add_argument("--force-max", type=number(low=0.0, high=1e6, low_open=True, unit="m/s^2"), default=3000.0,
                      metavar="A", help="the strongest thumb acceleration allowed, m/s^2 (default 3000)")
    live.add_argument("--duration", type=number(low=0.0, high=1e6, low_open=True, unit="s"), metavar="S",
                      help="stop after S seconds (default: at the score's end, or when interrupted)")
    live.add_argument("--log", action=Output, suffixes=json.SUFFIXES, metavar="PATH",
                      help="the session's record (default session-DATE-TIME.json here), written when it ends")
    live.add_argument("--quiet", action="store_true", help="do not print each dropped note and robot onset")
    add_mkdir(live)
    live.set_defaults(run=_live)


def _address(*, default_host, port_low):
    def parse(text):
        import argparse

        host, colon, port = text.rpartition(":")
        if not colon:
            host = default_host
        if not host:
            raise argparse.ArgumentTypeError(f"{text!r} must be HOST:PORT")
        try:
            value = int(port)
        except ValueError:
            raise argparse.ArgumentTypeError(f"port must be an integer in [{port_low}, 65535], got {port!r}") from None
        if not port_low <= value <= 65535:
            raise argparse.ArgumentTypeError(f"port must be an integer in [{port_low}, 65535], got {value}")
        return host.strip("[]"), value

    return parse


def _live(args):
    from ..design import ForceRange, Setup
    from ..kit.pieces import default_kit, read_kit
    from ..live import KitPerformer, Performer
    from ..live.stage import perform

    if not (args.osc_in or args.midi_in or args.midi_virtual or args.score):
        raise ParameterError("give the notes in: --osc-in, --midi-in, --midi-virtual or --score")
    if not (args.osc_out or args.csv or args.simulate_robot):
        raise ParameterError("give where the setpoints go: --osc-out, --csv or --simulate-robot")
    config = robot_config(args.config)
    setup = Setup(model=args.model, cor=args.cor, forces=ForceRange(high=args.force_max), limits=config.limits,
                  moves=config.limits)
    kit = None if args.kit is None else read_kit(args.kit) if args.kit else default_kit()
    if kit is not None and args.simulate_robot:
        raise ParameterError("--simulate-robot plays sticks, one joint each: not --kit (give --osc-out or --csv)")
    if kit is not None:
        performer = KitPerformer(kit, lead=args.lead, setup=setup, rate=args.rate, latency=args.latency / 1e3,
                                 horizon=args.horizon)
    else:
        performer = Performer(sticks=tuple(name.strip() for name in args.sticks.split(",")), setup=setup,
                              rate=args.rate, latency=args.latency / 1e3, horizon=args.horizon)
    log = args.log or f"session-{datetime.now().strftime('%Y%m%d-%H%M%S')}.json"
    robot = {"engine": args.simulate_robot, "control": args.controller, "plant": config.plant} \
        if args.simulate_robot else None
    record, status = perform(performer, osc_in=args.osc_in, midi_in=args.midi_in, midi_virtual=args.midi_virtual,
                             score=_score(args.score, kit), count_in=args.count_in,
                             osc_out=args.osc_out, csv=sys.stdout if args.csv else None, robot=robot,
                             duration=args.duration, report=None if args.quiet else _say,
                             listening=lambda host, port: _say(f"listening for OSC notes on {host}:{port}"))
    json.write_json(log, record, indent=None)  # compact: a flood's record is written within the stop's second
    if record["failure"]:
        _say(f"drumstroke live: error: {record['failure']}")
    notes, timing = record["notes"], record["timing"]
    late = timing["lateness_ms"]
    _say(f"played {sum(note['planned'] for note in notes)} of {len(notes)} notes on the {performer.model} model; "
         f"{timing['setpoints']} setpoints at {performer.rate:g} Hz, sent late by {late['median'] or 0:.3f} ms "
         f"(median), {late['p99'] or 0:.3f} ms (p99); {plural(record['problem_count'], 'problem')}")
    if record["robot"]:
        robot = record["robot"]
        _say(f"robot ({robot['engine']}, {robot['controller']}): {robot['onsets']} onsets for {robot['notes']} "
             f"notes, {robot['within_2ms']} within 2 ms")
    _say(f"wrote {log}")
    return status


def _score(path, kit):
    """The score to play: a MIDI file read with the kit's keys (or the snare's), a pattern's pieces as it names them."""
    from ..score import read_score

    if path is None:
        return None
    return read_score(path, kit=kit if kit is not None and path.suffix.lower() in (".mid", ".midi") else None)


def _say(line):
    sys.stderr.write(line + "\n")  # one write: lines from several threads never interleave
    sys.stderr.flush()
