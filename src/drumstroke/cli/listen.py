"""``drumstroke listen serve``, ``analyze`` and ``make-stimuli``: the listening-test web app."""

from ..errors import ParameterError
from ..formats import json
from ._common import Bar, Parser, add_cor, add_model, print_recording_notes
from ._options import Output, add_mkdir, existing_file, existing_folder, number, whole
from .stats import print_analysis


def add_listen(lis):
    """Give ``listen``'s parser ``lis`` its description and actions."""
    lis.description = ("The listening test of the paper as a web app: make the robot's "
                       "recordings, serve the test, analyse the answers.")
    actions = lis.add_subparsers(dest="listen_command", parser_class=Parser, metavar="ACTION", required=True)
    srv = actions.add_parser("serve", help="serve the listening test in a browser",
                             description="Serve the listening test over HTTP (uvicorn) until Ctrl-C; each answer is "
                                         "stored in the SQLite file --db as it is given. On the internet, serve it "
                                         "behind a reverse proxy with TLS (see the docs).")
    srv.add_argument("config", type=existing_file, metavar="CONFIG",
                     help="the test's .toml (title, admin_token, seed, pairs)")
    srv.add_argument("--db", action=Output, required=True, metavar="SQLITE",
                     help="the SQLite file the answers are stored in (created if missing)")
    srv.add_argument("--host", default="127.0.0.1", help="the address to listen on (default 127.0.0.1: this machine)")
    srv.add_argument("--port", type=whole(low=1, high=65535), default=8000,
                     help="the TCP port, in [1, 65535] (default 8000)")
    srv.add_argument("--forwarded-allow-ips", metavar="IPS",
                     help="comma-separated addresses or networks of trusted reverse proxies, whose X-Forwarded-For and "
                          "X-Forwarded-Proto are believed (default: none)")
    srv.add_argument("--allowed-host", action="append", default=[], metavar="NAME",
                     help="a name browsers reach the test by (the reverse proxy's, e.g. study.example.org), "
                          "repeatable; a request for another host is answered 400 (default: on loopback, its "
                          "loopback names only; on another address, any)")
    add_mkdir(srv)
    srv.set_defaults(run=_serve)
    ana = actions.add_parser("analyze", help="run the statistics on the answers collected",
                             description="Tryon's inferential confidence intervals, Rg, TOST and correlations on the "
                                         "answers stored in --db; writes them as JSON if asked.")
    ana.add_argument("--db", type=existing_file, required=True, metavar="SQLITE",
                     help="the SQLite file 'listen serve' stored the answers in")
    ana.add_argument("--delta", type=number(low=0.0, low_open=True, unit="answers"), metavar="D",
                     help="equivalence margin in answers, > 0 (default: no equivalence test)")
    ana.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="OUT", help="write the statistics as .json")
    add_mkdir(ana)
    ana.set_defaults(run=_analyze)
    mks = actions.add_parser("make-stimuli", help="render the robot's side of each pair (library strokes or recordings)",
                             description="Play library strokes on the simulated robot and write each as "
                                         "OUT/robot-NAME.wav, with OUT/listening-test.toml naming the pairs; or, with "
                                         "--recordings, fit a recipe to each recorded human stroke and write the "
                                         "robot's version of it beside the recording.")
    source = mks.add_mutually_exclusive_group(required=True)
    source.add_argument("--library", type=existing_folder, metavar="DIR", help="a library folder ('library build')")
    source.add_argument("--recordings", type=existing_file, nargs="+", metavar="FILE",
                        help="recordings of one human stroke each (.wav, .flac, .ogg); a pair is named by the file's "
                             "name without a leading 'human-'")
    mks.add_argument("--out", action=Output, folder=True, required=True, metavar="DIR",
                     help="the folder to write the recordings and the config to (created if missing)")
    mks.add_argument("--strokes", metavar="A,B,...", help="with --library: which strokes, comma-separated (default: all)")
    fitting = mks.add_argument_group("with --recordings: the fit")
    add_model(fitting, default=None, what="the model the recordings are fitted on")
    cor = fitting.add_mutually_exclusive_group()
    add_cor(cor, default=None, hint="; measure it: drumstroke measure-cor")
    cor.add_argument("--fit-cor", action="store_true", help="fit c to each recording too")
    add_mkdir(mks)
    mks.set_defaults(run=_make_stimuli)


def _serve(args):
    import logging

    from ..evaluation.app import Config, Store, make_server

    config = Config.from_toml(args.config)
    new = not args.db.exists()
    store = Store(args.db)
    proxies = args.forwarded_allow_ips.split(",") if args.forwarded_allow_ips else ()
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    try:
        server = make_server(config, store, host=args.host, port=args.port, forwarded_allow_ips=proxies,
                             allowed_hosts=args.allowed_host)
    except (ParameterError, ImportError):
        if new:  # a refused --host, --port or proxy, or a missing extra, leaves no database behind
            args.db.unlink()
        raise
    print(f"serving {config.title!r} ({len(config.pairs)} pairs, seed {config.seed}) on {server.url} ; answers in "
          f"{args.db}; export: curl -H 'Authorization: Bearer TOKEN' {server.url}admin/export.csv; Ctrl-C stops",
          flush=True)
    server.serve()
    print(f"stopped; the answers are in {args.db}")


def _analyze(args):
    from ..evaluation.app import Store
    from ..evaluation.stats import parse_responses

    rows = [[str(v) for v in row] for row in Store(args.db, create=False).rows()]
    if not rows:
        raise ParameterError(f"--db {str(args.db)!r} holds no answers yet")
    print_analysis(args, parse_responses(rows, name=str(args.db)))


def _make_stimuli(args):
    from ..evaluation.stimuli import fit_stimuli, make_stimuli

    if args.recordings and args.strokes:
        raise ParameterError("--strokes picks library strokes: give it with --library, not --recordings")
    if args.library and (args.cor is not None or args.fit_cor or args.model is not None):
        raise ParameterError("--model, --cor and --fit-cor fit recordings: give them with --recordings, not --library")
    with Bar("making stimuli", delay=1.0) as bar:
        if args.recordings:
            made = fit_stimuli(args.recordings, args.out, model=args.model or "paper", cor=args.cor,
                               fit_cor=args.fit_cor, progress=bar.update)
        else:
            made = make_stimuli(args.library, args.out, strokes=args.strokes.split(",") if args.strokes else None,
                                progress=bar.update)
    for stimulus in made.stimuli:
        print(f"wrote {stimulus.path} ({stimulus.onsets} onsets played by the simulated robot)")
        if stimulus.fit is not None:
            fit = stimulus.fit
            print_recording_notes(fit.onsets)
            print(f"  fitted on the {fit.model} model with c = {fit.cor:.4g}: {int(fit.played.sum())} of "
                  f"{len(fit.onsets)} onsets played, largest residuals {fit.time_error * 1e3:.3f} ms, "
                  f"{fit.level_error:.3f} dB; recipe {stimulus.recipe}")
    if args.recordings:
        print(f"wrote {made.config}: the pairs are complete (each recording beside its robot's version); set the "
              "seed; its admin_token is new and secret (the file is readable by you only)")
    else:
        print(f"wrote {made.config}: add the human recordings it names and set the seed; its admin_token is new and "
              "secret (the file is readable by you only)")
