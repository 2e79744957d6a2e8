"""What the listening-test server sends: its HTML pages, its static files and the headers on every response.

The pages hold no script and no style: the pair page's script and the style sheet are static files
(``static/listen.js``, ``static/listen.css``), so the Content-Security-Policy allows scripts and styles
from the server's own origin only. Every form carries its token in a hidden ``csrf`` field, last: a body
cut short by a lying ``Content-Length`` loses (part of) it and is refused.
"""

import html
from importlib import resources

SECURITY_HEADERS = (
    ("X-Content-Type-Options", "nosniff"),
    ("Content-Security-Policy", ("default-src 'none'; script-src 'self'; style-src 'self'; media-src 'self'; "
                                 "connect-src 'self'; img-src 'self'; form-action 'self'; base-uri 'none'; "
                                 "frame-ancestors 'none'")),
    ("Referrer-Policy", "no-referrer"),
    ("X-Frame-Options", "DENY"),
    ("Cross-Origin-Opener-Policy", "same-origin"),
    ("Cross-Origin-Resource-Policy", "same-origin"),
)
"""The headers every response carries, the server's own errors included: (name, value) pairs."""

STATIC = {"listen.js": "text/javascript; charset=utf-8", "listen.css": "text/css; charset=utf-8"}
"""The static files (in the package's ``static`` folder) and their media types."""


def static(name):
    """The bytes of the static file ``name`` (a key of :data:`STATIC`)."""
    return resources.files(__package__).joinpath("static", name).read_bytes()


def consent(config, token):
    """The first page: what the test is, and the consent form that starts a session."""
    return _shell(config.title, f"""<p>You will hear {len(config.pairs)} pairs of drum strokes. In each pair one
stroke was played by a human and one by a robot. Listen to both, then say which you think is the robot, how
sure you are, and how similar the two sound. Your answers are stored without your name.</p>
<form method="post" action="/start">
<label><input type="checkbox" name="consent" value="yes" id="consent" required> I agree to take part.</label>
<input type="hidden" name="csrf" value="{html.escape(token)}">
<p><button type="submit" id="start">Start</button></p>
</form>""")


def pair_page(config, participant, position, total, token):
    """The page of the pair at ``position``: the two stimuli and the three questions."""
    base = f"/p/{participant}"
    scale = "".join(f'<label><input type="radio" name="{{name}}" value="{v}" required> {v}</label> '
                    for v in range(1, 6))
    return _shell(config.title, f"""<p>Pair {position + 1} of {total} <small>(participant
<span id="participant">{participant}</span>)</small></p>
<p>A <audio id="audio-A" controls preload="none" src="{base}/audio/{position}/A"></audio></p>
<p>B <audio id="audio-B" controls preload="none" src="{base}/audio/{position}/B"></audio></p>
<form method="post" action="{base}/pair/{position}/answer" id="answer-form" data-played="{base}/pair/{position}/played">
<fieldset><legend>Which one is the robot?</legend>
<label><input type="radio" name="answer" value="A" required> A</label>
<label><input type="radio" name="answer" value="B" required> B</label></fieldset>
<fieldset><legend>How sure are you? (1 = guessing, 5 = certain)</legend>{scale.format(name="confidence")}</fieldset>
<fieldset><legend>How similar do they sound? (1 = very different, 5 = the same)</legend>
{scale.format(name="similarity")}</fieldset>
<input type="hidden" name="csrf" value="{html.escape(token)}">
<p><button type="submit" id="submit" disabled>Next</button> <span id="hint">Play both A and B first.</span></p>
</form>""", script=True)


def finish(config, participant):
    """The last page: the answers are saved."""
    return _shell(config.title, f"""<p id="finished">Thank you: your answers are saved (participant
{participant}). You can close this page.</p>""")


def _shell(title, body, *, script=False):
    tag = '\n<script src="/static/listen.js" defer></script>' if script else ""
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<link rel="stylesheet" href="/static/listen.css">{tag}
</head><body><h1>{html.escape(title)}</h1>
{body}
</body></html>
"""
