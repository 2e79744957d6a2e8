"""``drumstroke studio``: the studio, a local web application, served until Ctrl-C."""

from ._options import existing_folder, number, whole


def add_studio(stu):
    """Give ``studio``'s parser ``stu`` its description and options."""
    stu.description = ("Serve the studio on this machine and print its address: open it in a browser to design "
                       "strokes (drag the force, hear the stroke, ask for the notes you want), shape the palette and "
                       "plan parts on a step grid, hear and download them. Ctrl-C stops it.")
    stu.add_argument("--library", type=existing_folder, metavar="DIR",
                     help="a library folder ('library build', or a new empty folder): the palette shows its strokes "
                          "and strokes are saved into it (default: the shipped palette; saving is off)")
    stu.add_argument("--host", default="127.0.0.1",
                     help="the address to listen on (default 127.0.0.1: this machine only; the studio has no "
                          "accounts, so serve it elsewhere only on a network you trust)")
    stu.add_argument("--port", type=whole(low=0, high=65535), default=8765,
                     help="the TCP port, in [0, 65535]; 0 picks a free one (default 8765)")
    stu.add_argument("--allowed-host", action="append", default=[], metavar="NAME",
                     help="a name browsers reach the studio by besides the loopback names, repeatable; a request for "
                          "another host is answered 400")
    stu.add_argument("--work-timeout", type=number(low=0.1, high=600.0, unit="s"), default=30.0, metavar="S",
                     help="the seconds one request may compute before it is answered 503, in [0.1, 600] (default 30)")
    stu.set_defaults(run=_studio)


def _studio(args):
    import logging

    from ..studio.app import make_studio

    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    server = make_studio(library=args.library, host=args.host, port=args.port, allowed_hosts=args.allowed_host,
                         work_timeout=args.work_timeout)
    where = f"strokes saved into {args.library}" if args.library else "the shipped palette; --library DIR saves strokes"
    print(f"the studio is at {server.url} ({where}); open it in a browser; Ctrl-C stops it", flush=True)
    server.serve()
    print("stopped")
