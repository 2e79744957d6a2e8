"""``drumstroke library build``, ``list`` and ``check``: stroke libraries, the text files a robot host loads."""

import time

from ..trajectory import DEFAULT_RATE
from ._common import Bar, Parser
from ._options import Output, add_mkdir, existing_file, existing_folder, number


def add_library(lib):
    """Give ``library``'s parser ``lib`` its description and actions."""
    lib.description = ("Stroke libraries: folders of text files (per stroke a recipe .toml, "
                       "its samples .csv and impacts .json, and a manifest) a robot host loads.")
    actions = lib.add_subparsers(dest="library_command", parser_class=Parser, metavar="ACTION", required=True)
    build = actions.add_parser("build", help="simulate a palette and write it as a library folder",
                               description="Simulate every stroke of a palette and write them to DIR as a library; "
                                           "a library already there is replaced atomically.")
    build.add_argument("directory", action=Output, folder=True, metavar="DIR",
                       help="the library folder to write (created if missing)")
    build.add_argument("--rate", type=number(low=1.0, high=1e5, unit="Hz"), default=DEFAULT_RATE, metavar="HZ",
                       help=f"samples per second of the trajectories, in [1, 1e5] Hz (default {DEFAULT_RATE:g})")
    build.add_argument("--palette", type=existing_file, metavar="FILE",
                       help="a palette .toml file (default: the shipped palette of 20 strokes)")
    add_mkdir(build)
    build.set_defaults(run=_build)
    listing = actions.add_parser("list", help="list a library's strokes",
                                 description="List a library's strokes: MIDI note, impacts, length, first velocity, "
                                             "category and description. Writes nothing.")
    listing.add_argument("directory", type=existing_folder, metavar="DIR", help="a library folder ('library build')")
    listing.set_defaults(run=_list)
    check = actions.add_parser("check", help="check a library file by file: exit 0 when whole, 2 when damaged",
                               description="Check every file of a library against its manifest (there, a regular "
                                           "file, readable, its size and SHA-256) and its contents as 'library list' "
                                           "reads them. Prints one line per damaged file and exits 2, or one line "
                                           "saying it is whole and exits 0; leftovers beside it (old stroke folders, "
                                           "temporaries of killed builds, which the next build removes) are listed "
                                           "as notes. Writes nothing; 'library build' repairs a damaged library.")
    check.add_argument("directory", type=existing_folder, metavar="DIR", help="a library folder ('library build')")
    check.set_defaults(run=_check)


def _build(args):
    from ..palette.library import build_library

    started = time.monotonic()
    with Bar("building") as bar:
        library = build_library(args.directory, rate=args.rate, palette=args.palette, progress=bar.update)
    print(f"wrote {args.directory}/: {len(library)} strokes at {args.rate:g} Hz in {time.monotonic() - started:.1f} s")


def _list(args):
    from ..dynamics import level_to_velocity
    from ..palette.library import load_library
    from ..score import default_mapping

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


def _check(args):
    from ..palette.library import check_library

    diagnosis = check_library(args.directory)
    for problem in diagnosis.problems:
        print(problem)
    for leftover in diagnosis.leftovers:
        print(f"note: {leftover}")
    if diagnosis.problems:
        return 2
    files = sum(len(stored.record["files"]) for stored in diagnosis.strokes)
    print(f"{args.directory}: whole: {len(diagnosis.strokes)} strokes at {diagnosis.rate:g} Hz, {files} files as "
          "the manifest lists them")
    return 0
