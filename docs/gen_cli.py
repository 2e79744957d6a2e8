"""Write cli.md, the command-line reference, from the argument parsers themselves (run by mkdocs-gen-files).

Every command and sub-command's ``--help`` text, walked recursively through argparse's sub-parsers, so
the page cannot drift from what ``drumstroke ... --help`` prints.
"""

import argparse
import os

import mkdocs_gen_files

from drumstroke.cli import build_parser

WIDTH = "80"  # columns of the help text, whatever terminal builds the site


def commands(parser, path=()):
    """Yield (words after 'drumstroke', one-line help, parser) for the parser and every sub-command below it."""
    yield path, None, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help for choice in action._choices_actions}
            for name, sub in action.choices.items():
                for words, summary, found in commands(sub, (*path, name)):
                    yield words, summary if words != (*path, name) else helps.get(name), found


def page():
    lines = [
        "# Command line",
        "",
        "`drumstroke COMMAND ...` (or `python -m drumstroke COMMAND ...`) runs one job and prints what it did",
        "and every file it wrote; every command is a thin layer over the Python API.",
        "",
        "- **Everything is checked before any work.** Numbers against their ranges, input files and folders",
        "  for existence, each output's extension against the formats written (audio: `.wav`, `.flac`,",
        "  `.ogg`; pictures: `.png`, `.pdf`, `.svg`; `.csv`, `.json`, `.mid`/`.midi` as named) and its",
        "  folder. Bad input ends with exit status 2 and one line naming the option, the value and what is",
        "  allowed, with nothing simulated and nothing written; `compose --strict` exits with 3 when a note",
        "  was left out.",
        "- **No folder is created unless asked**: an output in a missing folder is an error, or, with",
        "  `--mkdir`, the folder is made. A folder argument (`demo OUTDIR`, `library build DIR`) is created",
        "  itself, in a folder that exists. A write that fails names the option, the file and the system's",
        "  reason (a directory in the way, no permission, a full disk); writes are atomic.",
        "- **One error path, never a traceback.** Whatever your input can cause — a bad value, a file that",
        "  cannot be read (named with the system's reason), text that is not UTF-8, a number too large, a",
        "  document nested too deep, a file that is not a database — is one line on stderr and exit status 2.",
        "  Anything else is a bug: one line with exit status 1 says so, where to report it and which log file",
        "  holds its traceback (`drumstroke --debug COMMAND ...` prints tracebacks as well). An interrupt",
        "  exits with 130, and a closed output pipe with 141, quietly.",
        "- **Resource budgets.** What an input asks for is estimated before the work, from the input alone,",
        "  and refused beyond the budget in one line naming the input, the estimate and the option that raises",
        "  it: `--budget-gb GB` (default 1: GB of arrays) and `--budget-minutes MIN` (default 10: minutes of",
        "  work), on every command. Estimated: an audio file's samples from its header (the frames libsndfile",
        "  counts, never more than an uncompressed file's size holds) with the detector's three working copies",
        "  of them; a profile's breakpoints before `t_end` (a recipe's, named by its file); a trajectory's",
        "  samples at its rate, and the time to write its CSV (some 1.5 µs a number): `simulate --rate` from",
        "  the recipe's `t_end` (and its stretches) before it is simulated, `compose --rate` from the last",
        "  note's time before composing and from the piece's length after, naming `--rate`; the audio",
        "  `--audio` synthesizes (some 48 bytes a sample at 48 kHz, a drum's or a kit's) and the points a",
        "  `--plot` of a composition draws (some 100 bytes each), naming the file; the kit's joints sampled",
        "  whole (`compose --kit --csv`, its picture, `robot track --kit`); `robot track`'s control periods",
        "  (the reference's samples and some 48 bytes a period a joint a controller, some 10 µs each on",
        "  the simple plant), naming `--rate`; a sweep's points (some",
        "  8 kB and 0.2 ms each); the triples of onsets `measure-cor` tries (some 0.2 ms each), an onsets",
        "  CSV of plain numbers read at once (a million rows in under a second). A long CSV",
        "  (a song at 100 kHz) is written as it is sampled, a chunk at a time, in bounded memory; the limits",
        "  that were there before stay (600 s of audio analysed, 50 million samples a trajectory, 200,000",
        "  pieces a profile, 10 million points a sweep). `live` keeps its record readable: past 40 MiB of",
        "  notes it plans no more (each later note dropped, the record saying it is full; see docs/live.md).",
        "- **Options are never abbreviated**: `--rat` is an error, not `--rate`.",
        "- **Progress bars** (tqdm, on stderr) show on a terminal for the commands that take more than a",
        "  second (`library build`, `sweep`, `figures`, `demo`, `compose`, `robot track`/`tune`,",
        "  `listen make-stimuli`), and nothing is drawn when stderr is a file or a pipe.",
        "",
        "This page is generated when the site is built, from the same argument parsers the command uses",
        "(`drumstroke.cli.build_parser()`): it is exactly what `--help` prints.",
        "",
    ]
    for words, summary, parser in commands(build_parser()):
        name = " ".join(("drumstroke", *words))
        lines += [f"## `{name}`", ""]
        if summary:
            lines += [summary[0].upper() + summary[1:] + ".", ""]
        lines += ["```text", parser.format_help().rstrip(), "```", ""]
    return "\n".join(lines)


def main():
    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = WIDTH
    try:
        text = page()
    finally:
        if before is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = before
    with mkdocs_gen_files.open("cli.md", "w") as out:
        out.write(text)
    mkdocs_gen_files.set_edit_path("cli.md", "gen_cli.py")


main()
