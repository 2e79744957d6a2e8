"""``drumstroke listen serve``, ``analyze`` and ``make-stimuli``: the listening-test web app."""

from pathlib import Path

from ..errors import ParameterError
from ._common import Bar, Parser
from .stats import print_analysis


def add_listen(commands):
    """Register ``listen`` and its actions."""
    lis = commands.add_parser("listen", help="the listening-test web app: serve it, analyse it, make its stimuli")
    actions = lis.add_subparsers(dest="listen_command", parser_class=Parser, metavar="ACTION", required=True)
    srv = actions.add_parser("serve", help="serve the listening test in a browser")
    srv.add_argument("config", type=Path, metavar="CONFIG", help="the test's .toml (title, admin_token, seed, pairs)")
    srv.add_argument("--db", type=Path, required=True, metavar="SQLITE", help="where answers are stored")
    srv.add_argument("--host", default="127.0.0.1")
    srv.add_argument("--port", type=int, default=8000)
    srv.set_defaults(run=_serve)
    ana = actions.add_parser("analyze", help="run the statistics on the answers collected")
    ana.add_argument("--db", type=Path, required=True, metavar="SQLITE")
    ana.add_argument("--delta", type=float, metavar="D", help="equivalence margin in answers")
    ana.add_argument("--json", type=Path, metavar="OUT", help="write the statistics as JSON")
    ana.set_defaults(run=_analyze)
    mks = actions.add_parser("make-stimuli", help="render the robot's side of each pair from library strokes")
    mks.add_argument("--library", type=Path, required=True, metavar="DIR")
    mks.add_argument("--out", type=Path, required=True, metavar="DIR")
    mks.add_argument("--strokes", metavar="A,B,...", help="which strokes (default: all)")
    mks.set_defaults(run=_make_stimuli)


def _serve(args):
    from ..evaluation.app import Config, Store, make_server

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


def _analyze(args):
    from ..evaluation.app import Store
    from ..evaluation.stats import parse_responses

    if not args.db.is_file():
        raise ParameterError(f"--db {str(args.db)!r} does not exist")
    rows = [[str(v) for v in row] for row in Store(args.db).rows()]
    if not rows:
        raise ParameterError(f"--db {str(args.db)!r} holds no answers yet")
    print_analysis(args, parse_responses(rows, name=str(args.db)))


def _make_stimuli(args):
    from ..evaluation.stimuli import make_stimuli

    bar = Bar("making stimuli", delay=1.0)
    made = make_stimuli(args.library, args.out, strokes=args.strokes.split(",") if args.strokes else None,
                        progress=bar.update)
    bar.close()
    for stimulus in made.stimuli:
        print(f"wrote {stimulus.path} ({stimulus.onsets} onsets played by the simulated robot)")
    print(f"wrote {made.config}: add the human recordings it names, set admin_token and seed")
