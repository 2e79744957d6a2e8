"""The studio on the web (Starlette): the page, its static files and the operations, each request checked.

Imported when serving (:func:`drumstroke.studio.app.make_studio`). What a request meets, beyond the listening
test's guard (:class:`~drumstroke.evaluation.web.Guard`: the head's size, a ``Host`` that is one of the served
names, the security headers on every response):

- **Paths**: ``GET /``, ``GET /static/NAME`` (the files of :data:`STATIC` only) and ``POST /api/NAME`` (an
  operation of :data:`OPERATIONS`); anything else 404, another method 405.
- **Bodies**: a JSON object (``Content-Type: application/json``, else 415: a page elsewhere cannot send one
  without the browser asking first, which this server never allows) of at most ``max_body`` bytes, refused
  with 413 by its ``Content-Length`` before it is read, whole within ``body_timeout`` s (else 408), UTF-8,
  nesting at most 64 levels (else 400). A request whose ``Sec-Fetch-Site`` is not same-origin or whose
  ``Origin`` is another origin is refused (403) before its body is read.
- **Work**: an operation runs in a worker thread, at most :data:`WORKERS` at once (one more is answered 503
  with ``Retry-After``), and is answered within ``work_timeout`` s or with 503 (what it was doing finishes
  unseen; its inputs are bounded so that none runs long).
- **Answers**: a JSON object, or a file (audio, CSV, MIDI, ...) with its name; an input the operation refuses
  is 400 with ``{"error": "one line naming the field, the value and what is allowed"}``, and so is a recipe
  whose motion the model does not cover (:class:`~drumstroke.errors.SimulationError`: the stick past the
  vertical); a failure of the studio itself 500, its traceback logged.
"""

import json
import logging
import threading
from importlib import resources

import anyio
from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from ..errors import DrumstrokeError, ParameterError
from ..evaluation.web import Guard, changing_body
from ..formats.json import loads
from ..formats.reading import check_document
from . import palette, parts, strokes
from .session import File

log = logging.getLogger(__name__)

STATIC = {
    "studio.html": "text/html; charset=utf-8",
    "studio.css": "text/css; charset=utf-8",
    "studio.js": "text/javascript; charset=utf-8",
    "common.js": "text/javascript; charset=utf-8",
    "designer.js": "text/javascript; charset=utf-8",
    "palette.js": "text/javascript; charset=utf-8",
    "part.js": "text/javascript; charset=utf-8",
    "robot.js": "text/javascript; charset=utf-8",
}
"""The page's files (in the package's ``static`` folder) and their media types."""

OPERATIONS = {**strokes.OPERATIONS, **palette.OPERATIONS, **parts.OPERATIONS}
"""Every operation the page may ask for: name -> function(studio, request object) -> dict or File."""

WORKERS = 2
"""Operations run at once (the studio is one person's: the page asks one thing at a time per view)."""


def make_app(studio, limits, *, hosts=None, work_timeout=30.0):
    """The ASGI application serving ``studio`` (a :class:`~drumstroke.studio.session.Studio`).

    ``limits``: the :class:`~drumstroke.evaluation.limits.Limits` whose ``max_body`` and ``body_timeout`` bound
    a request's body; ``hosts``: the names a request's ``Host`` may give (None: any); ``work_timeout``: the
    seconds an operation has to answer.
    """
    site = _Site(studio, limits, work_timeout)
    routes = [
        Route("/", site.page),
        Route("/static/{name}", site.static),
        Route("/api/{operation}", site.operation, methods=["POST"]),
    ]
    return Guard(Starlette(routes=routes, exception_handlers={HTTPException: _refused, Exception: _failed}), hosts)


class _Site:
    def __init__(self, studio, limits, work_timeout):
        self.studio, self.limits, self.work_timeout = studio, limits, work_timeout
        self.files = {name: resources.files(__package__).joinpath("static", name).read_bytes() for name in STATIC}
        self.slots = threading.BoundedSemaphore(WORKERS)

    async def page(self, request):
        return Response(self.files["studio.html"], media_type=STATIC["studio.html"])

    async def static(self, request):
        name = request.path_params["name"]
        if name not in self.files:
            raise HTTPException(404, "no such file")
        return Response(self.files[name], media_type=STATIC[name], headers={"Cache-Control": "no-cache"})

    async def operation(self, request):
        name = request.path_params["operation"]
        if name not in OPERATIONS:
            raise HTTPException(404, f"no operation {name[:40]!r}; the studio's: {', '.join(sorted(OPERATIONS))}")
        data = await self._json(request)
        answer = await self._work(OPERATIONS[name], data)
        if isinstance(answer, File):
            return Response(answer.data, media_type=answer.media_type,
                            headers={"Content-Disposition": f'attachment; filename="{answer.filename}"'})
        return Response(json.dumps(answer, allow_nan=False, separators=(",", ":"), default=_plain),
                        media_type="application/json")

    async def _json(self, request):
        body = await changing_body(request, "application/json", self.limits, "a request")
        try:
            text = body.decode("utf-8")
        except UnicodeDecodeError:
            raise HTTPException(400, "the request is not UTF-8 text") from None
        try:
            data = loads(text, "the request")
            check_document(data, "the request")
        except ParameterError as error:
            raise HTTPException(400, str(error)) from None
        if not isinstance(data, dict):
            raise HTTPException(400, f"the request must be a JSON object, got {type(data).__name__}")
        return data

    async def _work(self, operation, data):
        if not self.slots.acquire(blocking=False):
            raise HTTPException(503, f"the studio is busy with {WORKERS} requests: try again in a moment",
                                headers={"Retry-After": "1"})

        def run():
            try:
                return operation(self.studio, data)
            finally:
                self.slots.release()

        try:
            with anyio.fail_after(self.work_timeout):
                return await anyio.to_thread.run_sync(run, abandon_on_cancel=True)
        except TimeoutError:
            raise HTTPException(503, f"the request took longer than {self.work_timeout:g} s; ask for less "
                                     "(a shorter stroke or part)") from None
        except DrumstrokeError as error:  # an input refused, or motion the model does not cover (SimulationError)
            raise HTTPException(400, str(error)) from None


def _plain(value):
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    raise TypeError(f"cannot send {type(value).__name__} as JSON")


async def _refused(request, error):
    return JSONResponse({"error": error.detail}, status_code=error.status_code, headers=error.headers)


async def _failed(request, error):
    # Starlette raises the error again once this is sent, and uvicorn logs it with its traceback
    return JSONResponse({"error": "the studio failed to answer; the reason is in its log"}, status_code=500)
