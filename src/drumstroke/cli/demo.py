"""``drumstroke demo``: the library built, every stroke rendered, a groove composed, index.html written."""

from ._common import Bar, print_summary, print_written
from ._options import Output, add_mkdir


def add_demo(demo):
    """Give ``demo``'s parser ``demo`` its description and options."""
    demo.description = ("Write the demo into OUTDIR: the paper's Figs. 4-7 (PNG, JSON, CSV each), the shipped library "
                        "(library/), every library stroke's picture, sound and MIDI file (strokes/), six PAS rudiments "
                        "the planner plays (rudiments/: picture, sound, MIDI and JSON each), a groove composed from the "
                        "library (groove.*), and index.html, a page showing and playing it all.")
    demo.add_argument("outdir", action=Output, folder=True, metavar="OUTDIR",
                      help="the folder to write the demo to (created if missing)")
    add_mkdir(demo)
    demo.set_defaults(run=_demo)


def _demo(args):
    from ..demo import run_demo

    with Bar("demo") as bar:
        demo = run_demo(args.outdir, progress=bar.update)
    for figure in demo.figures:
        print()
        print_summary(figure.stroke, rows=3)
        print_written(figure.paths)
    library, piece, out = demo.library, demo.piece, demo.outdir
    print(f"\nwrote {library.path}/: {len(library)} strokes at {library.rate:g} Hz")
    print(f"wrote {out / 'strokes'}/: {len(demo.strokes)} files, a picture, a sound and a MIDI file for each stroke")
    print(f"wrote {out / 'rudiments'}/: {len(demo.rudiments)} files, a picture, a sound, a MIDI and a JSON file for "
          "each rudiment the planner played")
    print(f"composed groove.pattern: {demo.played} of {len(piece.placements)} notes on {len(piece.sticks)} sticks, "
          f"{piece.t_end:.2f} s")
    print_written(demo.groove)
    print_written([demo.index])
    print(f"\ndemo written to {out}/: open {demo.index} in a browser")
