"""The studio: a local web application where a person designs strokes, shapes the palette and plans parts, and hears
and sees each change at once (``drumstroke studio``; Starlette and uvicorn come with the ``listen`` extra).

The page (``static/``: HTML, CSS and JavaScript shipped in the package, nothing from elsewhere) asks the server
through one kind of request: ``POST /api/NAME`` with a JSON object, answered with a JSON object or a file. What
each ``NAME`` does is an *operation*: a plain function of the studio and the request's object
(:mod:`drumstroke.studio.strokes`, :mod:`drumstroke.studio.parts`), checked and served by
:mod:`drumstroke.studio.web`, with the listening test's server and its limits (:mod:`drumstroke.evaluation.server`).
"""
