"""The studio's server: :func:`make_studio` binds it; ``drumstroke studio`` serves it until Ctrl-C."""

from pathlib import Path

from .._checks import check_int, check_real
from ..errors import ParameterError
from ..evaluation.limits import Limits, served_hosts
from .session import Studio

MAX_BODY = 1 << 20
"""The largest request the studio accepts, in bytes (a MIDI file dropped in, sent as base64, is the largest)."""

CONNECTIONS = 256
"""The most connections the studio holds open (a browser opens about six)."""


def make_studio(*, library=None, host="127.0.0.1", port=8000, allowed_hosts=(), work_timeout=30.0):
    """The studio's web server, its socket bound: ``serve()`` it until Ctrl-C, or ``start()``/``stop()`` it in a thread.

    Parameters
    ----------
    library : path or None
        A library folder (``drumstroke library build``'s, or a new empty folder) whose strokes the palette shows
        and into which strokes are saved; None, the shipped palette only (nothing can be saved).
    host : str
        The address to listen on (default 127.0.0.1: this machine only).
    port : int in [0, 65535]
        The TCP port; 0 picks a free one (the server's ``url`` tells which).
    allowed_hosts : sequence of str
        Names browsers may reach the studio by besides the loopback names; empty (the default): a studio on
        loopback answers ``localhost``, ``127.0.0.1`` and ``[::1]`` only (a page elsewhere cannot reach it by
        DNS rebinding).
    work_timeout : float in [0.1, 600] s
        The time an operation has to answer (else 503).

    Returns
    -------
    drumstroke.evaluation.server.Server

    Raises
    ------
    ParameterError
        A library that is not a folder, a host that cannot be resolved, a port out of range or taken, an
        allowed host that is not a host name.
    ImportError
        Without the ``listen`` extra (Starlette and uvicorn).
    """
    check_int("port", port, low=0, high=65535)
    check_real("work_timeout", work_timeout, low=0.1, high=600.0, unit="s")
    hosts = served_hosts(host, allowed_hosts)
    studio = Studio(library=_folder(library))
    try:
        from ..evaluation.server import Server
        from .web import make_app
    except ImportError as error:
        raise ImportError(f"the studio needs {error.name}: pip install 'drumstroke[listen]'") from None
    limits = Limits(max_body=MAX_BODY, connections=CONNECTIONS, connections_per_client=CONNECTIONS)
    return Server(make_app(studio, limits, hosts=hosts, work_timeout=work_timeout), limits, host=host, port=port)


def _folder(library):
    if library is None:
        return None
    path = Path(library)
    if not path.is_dir():
        raise ParameterError(f"library {str(path)!r} is not a folder: give a library folder ('drumstroke library "
                             "build') or a new empty one")
    return path
