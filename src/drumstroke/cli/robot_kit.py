"""``drumstroke robot track SONG --kit``: a song's drum part played by the kit robot, scored per piece."""

from pathlib import Path

from ..errors import ParameterError


def add_kit_track_options(trk):
    """Give ``robot track``'s parser ``trk`` the kit's options."""
    kit = trk.add_argument_group("the whole kit (--kit)")
    kit.add_argument("--kit", nargs="?", const="", type=str, metavar="FILE",
                     help="SOURCE is a song (.mid or a pattern): play its drum part on the kit robot, two arms and "
                          "two pedals (alone: the shipped kit; FILE: a kit .toml)")
    kit.add_argument("--seconds", type=_positive_seconds, metavar="S",
                     help="with --kit: play the drum part's first S seconds, from its first note (default all of it)")


def _positive_seconds(text):
    from ._options import number

    return number(low=0.0, low_open=True, unit="s")(text)


def check_kit_track(args):
    """Refuse the options that do not go together with --kit or without it, before any work."""
    if args.kit is None:
        if args.seconds is not None:
            raise ParameterError(f"--seconds is for a song played on the kit (--kit), got --seconds {args.seconds:g} "
                                 "without --kit", parameter="--seconds", value=args.seconds, allowed="with --kit")
        return
    for option, value in (("--library", args.library), ("--stick", args.stick), ("--plot", args.plot)):
        if value is not None:
            raise ParameterError(f"{option} is for one stroke, not a song on the kit (--kit), got {option} {value}",
                                 parameter=option, value=value, allowed="without --kit")
    suffix = Path(args.source).suffix.lower()
    if not Path(args.source).is_file():
        raise ParameterError(f"SOURCE must be a song file (.mid, .midi or a pattern) with --kit, got {args.source!r} "
                             "(no such file)", parameter="SOURCE", value=args.source, allowed="a song file")
    if suffix in (".toml", ".csv"):
        raise ParameterError(f"SOURCE must be a song (.mid, .midi or a pattern) with --kit, got {args.source!r}",
                             parameter="SOURCE", value=args.source, allowed="a .mid, .midi or pattern file")


def track_kit_command(args, config, names):
    """Compose the song on the kit, play it with each controller in ``names``, print each piece's figures."""
    from ..compose import compose_kit
    from ..kit.pieces import default_kit, read_kit
    from ..robot.kit import first_seconds, kit_scores, track_kit
    from ..robot.track import check_tracking
    from ..score import read_score
    from ._common import Bar, print_written

    kit = read_kit(args.kit) if args.kit else default_kit()
    midi = Path(args.source).suffix.lower() in (".mid", ".midi")
    score = read_score(args.source, kit=kit if midi else None)
    if not score.notes:
        raise ParameterError(f"{args.source} has no notes the kit answers", parameter="SOURCE", value=args.source,
                             allowed="a song with drum notes")
    if args.seconds is not None:
        score = first_seconds(score, args.seconds)
    piece = compose_kit(score, kit, rate=args.rate)
    check_tracking(piece.t_end if args.seconds is None else min(args.seconds, piece.t_end), args.rate,
                   joints=len(piece.columns) // 2, controllers=len(names), name="--rate")
    span = "all of its drum part" if args.seconds is None else f"the first {args.seconds:g} s of its drum part"
    print(f"{args.source}, {span} on {'kit ' + args.kit if args.kit else 'the shipped kit'}: {piece.summary()}")
    plant = config.plant if args.config else None
    report = []
    for name in names:
        with Bar(f"playing the kit ({name})", delay=1.0) as bar:
            played = track_kit(piece, config.controllers[name], args.plant, plant=plant, progress=bar.update)
        scores = kit_scores(played)
        _print_scores(played, scores)
        report.append({"name": name, "scores": scores.to_dict()})
    if args.report:
        from ..formats.json import write_json

        write_json(args.report, {"source": str(args.source), "seconds": args.seconds, "engine": args.plant,
                                 "rate": args.rate, "controllers": report})
        print_written([args.report])


def _print_scores(played, scores):
    total = scores.total
    notes = total.matched + total.missed
    print(f"{played.controller} on the {played.engine} engine at {played.robot.rate:g} Hz: {total.matched} of {notes} "
          f"notes struck on their piece within ±{scores.window * 1e3:g} ms ({100 * scores.fraction:.1f}%), "
          f"{total.extra} extra onsets, F {total.f_measure:.3f}")
    print(f"  {'piece':<10} {'notes':>5} {'struck':>6} {'extra':>5} {'kept':>7} {'F':>6}  timing |error| median/p95 (ms)")
    for row in (*scores.pieces, None):
        name, s = ("all", total) if row is None else (row.piece, row.scores)
        timing = f"{s.timing_median * 1e3:.2f} / {s.timing_p95 * 1e3:.2f}" if s.matched else "-"
        print(f"  {name:<10} {s.matched + s.missed:>5} {s.matched:>6} {s.extra:>5} {100 * s.recall:>6.1f}% "
              f"{s.f_measure:>6.3f}  {timing}")
