"""``drumstroke demo``: the library built, every stroke rendered, a groove composed, index.html written."""

from pathlib import Path

from ._common import Bar, print_summary, print_written


def add_demo(commands):
    """Register ``demo``."""
    demo = commands.add_parser("demo", help="build the library, render every stroke, compose a groove, write index.html")
    demo.add_argument("outdir", type=Path, metavar="OUTDIR")
    demo.set_defaults(run=_demo)


def _demo(args):
    from ..demo import run_demo

    bar = Bar("demo")
    demo = run_demo(args.outdir, progress=bar.update)
    bar.close()
    for figure in demo.figures:
        print()
        print_summary(figure.stroke, rows=3)
        print_written(figure.paths)
    library, piece, out = demo.library, demo.piece, demo.outdir
    print(f"\nwrote {library.path}/: {len(library)} strokes at {library.rate:g} Hz")
    print(f"composed groove.pattern: {demo.played} of {len(piece.placements)} notes on {len(piece.sticks)} sticks, "
          f"{piece.t_end:.2f} s")
    print(f"\ndemo written to {out}/: open {demo.index} in a browser")
