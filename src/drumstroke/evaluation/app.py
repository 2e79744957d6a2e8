"""The listening-test web app: pairs of stimuli in a browser, answers stored exactly once in SQLite (SPEC §6).

A participant gives consent, gets a generated id, and hears the configured
pairs in an order shuffled for them from the config's recorded seed and their
id, with the robot on side A or B at random per pair. They must play both
stimuli (the server records each play) before they can answer the paper's
three questions: which is the robot, how sure (1–5), how similar (1–5). Each
answer is one row of SQLite, keyed by participant and pair, written in one
transaction: a reload, a double click or a resubmission never stores it twice
nor loses it (the first answer stands). The experimenter exports the answers as
CSV — the format ``drumstroke stats`` reads — with the config's admin token.

Config (TOML)::

    title = "Robot or human?"
    admin_token = "change-me"          # for /admin/export.csv?token=...
    seed = 20261122                    # recorded; shuffles orders and sides
    [[pair]]
    id = "buzz-1"
    human = "stimuli/human-buzz-1.wav" # paths relative to the config file
    robot = "stimuli/robot-buzz-1.wav"

The server is the standard library's threading HTTP server; SQLite is used
with one connection per request and ``BEGIN IMMEDIATE`` transactions.
"""

import hashlib
import html
import json
import random
import re
import sqlite3
import time
import uuid
from dataclasses import dataclass
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

from .._checks import check_keys
from ..errors import ParameterError
from ..formats.responses_csv import responses_text
from ..formats.toml import read_toml

QUESTIONS = ("answer", "confidence", "similarity")
_ID = re.compile(r"^[A-Za-z0-9._-]{1,64}$")
_SCHEMA = """
CREATE TABLE IF NOT EXISTS participants (
    id TEXT PRIMARY KEY, created REAL NOT NULL, seed INTEGER NOT NULL, plan TEXT NOT NULL, finished REAL);
CREATE TABLE IF NOT EXISTS plays (
    participant TEXT NOT NULL, position INTEGER NOT NULL, side TEXT NOT NULL, at REAL NOT NULL,
    PRIMARY KEY (participant, position, side));
CREATE TABLE IF NOT EXISTS answers (
    participant TEXT NOT NULL, position INTEGER NOT NULL, pair TEXT NOT NULL, robot TEXT NOT NULL,
    answer TEXT NOT NULL, confidence INTEGER NOT NULL, similarity INTEGER NOT NULL, at REAL NOT NULL,
    PRIMARY KEY (participant, position));
"""


@dataclass(frozen=True)
class Pair:
    """One pair: its id and the human and robot stimulus files."""

    id: str
    human: Path
    robot: Path


@dataclass(frozen=True)
class Config:
    """A listening test: its title, admin token, seed and pairs."""

    title: str
    admin_token: str
    seed: int
    pairs: tuple

    @classmethod
    def from_toml(cls, path):
        """Read and check a config file; stimulus paths are relative to it and must exist."""
        path = Path(path)
        data = read_toml(path, "listening-test config")
        check_keys("config", data, ("title", "admin_token", "seed", "pair"))
        title = data.get("title", "Robot or human?")
        token = data.get("admin_token")
        seed = data.get("seed")
        if not isinstance(title, str):
            raise ParameterError(f"config title must be text, got {title!r}")
        if not isinstance(token, str) or len(token) < 8:
            raise ParameterError("config admin_token must be text of at least 8 characters")
        if isinstance(seed, bool) or not isinstance(seed, int):
            raise ParameterError(f"config seed must be an integer, got {seed!r}")
        tables = data.get("pair")
        if not isinstance(tables, list) or not tables:
            raise ParameterError("config needs at least one [[pair]] table with id, human and robot")
        pairs, seen = [], set()
        for i, table in enumerate(tables):
            where = f"pair[{i}]"
            if not isinstance(table, dict):
                raise ParameterError(f"{where} must be a table")
            check_keys(where, table, ("id", "human", "robot"))
            pid = table.get("id")
            if not isinstance(pid, str) or not _ID.match(pid) or pid in seen:
                raise ParameterError(f"{where}.id must be a unique name of 1-64 letters, digits, '.', '_', '-', "
                                     f"got {pid!r}")
            seen.add(pid)
            files = {}
            for side in ("human", "robot"):
                name = table.get(side)
                if not isinstance(name, str):
                    raise ParameterError(f"{where}.{side} must be a file path, got {name!r}")
                file = (path.parent / name).resolve()
                if not file.is_file():
                    raise ParameterError(f"{where}.{side} {str(file)!r} does not exist")
                files[side] = file
            pairs.append(Pair(pid, files["human"], files["robot"]))
        return cls(title, token, seed, tuple(pairs))


def plan(config, participant):
    """The participant's pairs in their order, and the robot's side (A or B) for each: [(pair id, side)]."""
    digest = hashlib.sha256(f"{config.seed}:{participant}".encode()).hexdigest()
    rng = random.Random(int(digest, 16))
    order = [p.id for p in config.pairs]
    rng.shuffle(order)
    return [(pid, rng.choice("AB")) for pid in order]


class Store:
    """The SQLite database of participants, plays and answers."""

    def __init__(self, path):
        self.path = str(path)
        with self._connect() as db:
            db.executescript(_SCHEMA)

    def _connect(self):
        db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
        db.execute("PRAGMA busy_timeout = 30000")
        return db

    def _transaction(self, work):
        db = self._connect()
        try:
            db.execute("BEGIN IMMEDIATE")
            try:
                result = work(db)
            except BaseException:
                db.execute("ROLLBACK")
                raise
            db.execute("COMMIT")
            return result
        finally:
            db.close()

    def new_participant(self, config):
        """Create a participant with a fresh id and their plan; return the id."""
        participant = uuid.uuid4().hex
        order = plan(config, participant)
        self._transaction(lambda db: db.execute(
            "INSERT INTO participants (id, created, seed, plan) VALUES (?, ?, ?, ?)",
            (participant, time.time(), config.seed, json.dumps(order))))
        return participant

    def _read(self, sql, args=()):
        db = self._connect()
        try:
            return db.execute(sql, args).fetchall()
        finally:
            db.close()

    def plan_of(self, participant):
        """The participant's stored plan, or None for an unknown id."""
        rows = self._read("SELECT plan FROM participants WHERE id = ?", (participant,))
        return [tuple(x) for x in json.loads(rows[0][0])] if rows else None

    def played(self, participant, position, side):
        """Record that a stimulus was played (idempotent)."""
        self._transaction(lambda db: db.execute(
            "INSERT OR IGNORE INTO plays VALUES (?, ?, ?, ?)", (participant, position, side, time.time())))

    def sides_played(self, participant, position):
        """The sides (A, B) the participant has played of the pair at ``position``."""
        rows = self._read("SELECT side FROM plays WHERE participant = ? AND position = ?", (participant, position))
        return {r[0] for r in rows}

    def answer(self, participant, position, pair, robot, answer, confidence, similarity):
        """Store an answer once; return True if this call stored it, False if one was there already."""
        def work(db):
            cursor = db.execute("INSERT OR IGNORE INTO answers VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                                (participant, position, pair, robot, answer, confidence, similarity, time.time()))
            return cursor.rowcount == 1

        return self._transaction(work)

    def answered(self, participant):
        """The positions the participant has answered."""
        return {r[0] for r in self._read("SELECT position FROM answers WHERE participant = ?", (participant,))}

    def rows(self):
        """Every answer as (subject, pair, robot, answer, confidence, similarity), in a stable order."""
        return self._read("SELECT participant, pair, robot, answer, confidence, similarity FROM answers "
                          "ORDER BY participant, position")

    def export_csv(self):
        """The answers as CSV text with the header ``drumstroke stats`` reads."""
        return responses_text(self.rows())


def make_server(config, store, *, host="127.0.0.1", port=8000):
    """A ThreadingHTTPServer serving the test; call ``serve_forever()`` (port 0 picks a free one)."""
    handler = type("Handler", (_Handler,), {"config": config, "store": store,
                                             "pairs": {p.id: p for p in config.pairs}})
    return _Server((host, port), handler)


class _Server(ThreadingHTTPServer):
    daemon_threads = True
    request_queue_size = 256  # many participants may connect at once


class _Handler(BaseHTTPRequestHandler):
    config = None
    store = None
    pairs = None
    protocol_version = "HTTP/1.1"

    def log_message(self, format, *args):  # quiet: the CLI prints what matters
        pass

    # --- routing -----------------------------------------------------------------------------------------------
    def do_GET(self):
        url = urlsplit(self.path)
        parts = [p for p in url.path.split("/") if p]
        if not parts:
            return self._page(_consent(self.config))
        if parts == ["admin", "export.csv"]:
            token = parse_qs(url.query).get("token", [""])[0]
            if token != self.config.admin_token:
                return self._error(HTTPStatus.FORBIDDEN, "the export needs the admin token (?token=...)")
            return self._send(HTTPStatus.OK, self.store.export_csv().encode(), "text/csv; charset=utf-8")
        if len(parts) >= 2 and parts[0] == "p":
            participant = parts[1]
            steps = self.store.plan_of(participant)
            if steps is None:
                return self._error(HTTPStatus.NOT_FOUND, "unknown participant")
            if parts[2:] == ["done"]:
                return self._page(_finish(self.config, participant))
            if len(parts) == 4 and parts[2] == "pair" and parts[3].isdigit():
                position = int(parts[3])
                if position >= len(steps):
                    return self._redirect(f"/p/{participant}/done")
                answered = self.store.answered(participant)
                if position in answered:
                    return self._redirect(self._next(participant, steps, answered))
                return self._page(_pair_page(self.config, participant, position, len(steps)))
            if len(parts) == 5 and parts[2] == "audio" and parts[3].isdigit() and parts[4] in ("A", "B"):
                position = int(parts[3])
                if position >= len(steps):
                    return self._error(HTTPStatus.NOT_FOUND, "no such pair")
                pair_id, robot = steps[position]
                pair = self.pairs[pair_id]
                file = pair.robot if parts[4] == robot else pair.human
                return self._send(HTTPStatus.OK, file.read_bytes(), "audio/wav")
        return self._error(HTTPStatus.NOT_FOUND, "no such page")

    def do_POST(self):
        url = urlsplit(self.path)
        parts = [p for p in url.path.split("/") if p]
        try:
            form = self._form()
        except ValueError as error:
            return self._error(HTTPStatus.BAD_REQUEST, str(error))
        if parts == ["start"]:
            if form.get("consent") != "yes":
                return self._error(HTTPStatus.BAD_REQUEST, "consent is needed to take part")
            participant = self.store.new_participant(self.config)
            return self._redirect(f"/p/{participant}/pair/0")
        if len(parts) == 5 and parts[0] == "p" and parts[2] == "pair" and parts[3].isdigit():
            participant, position = parts[1], int(parts[3])
            steps = self.store.plan_of(participant)
            if steps is None or position >= len(steps):
                return self._error(HTTPStatus.NOT_FOUND, "unknown participant or pair")
            if parts[4] == "played":
                side = form.get("side")
                if side not in ("A", "B"):
                    return self._error(HTTPStatus.BAD_REQUEST, f"side must be A or B, got {side!r}")
                self.store.played(participant, position, side)
                return self._send(HTTPStatus.NO_CONTENT, b"", "text/plain")
            if parts[4] == "answer":
                return self._answer(participant, position, steps, form)
        return self._error(HTTPStatus.NOT_FOUND, "no such action")

    # --- actions -----------------------------------------------------------------------------------------------
    def _answer(self, participant, position, steps, form):
        answer = form.get("answer")
        if answer not in ("A", "B"):
            return self._error(HTTPStatus.BAD_REQUEST, f"answer must be A or B, got {answer!r}")
        values = {}
        for key in ("confidence", "similarity"):
            value = form.get(key, "")
            if value not in ("1", "2", "3", "4", "5"):
                return self._error(HTTPStatus.BAD_REQUEST, f"{key} must be an integer in [1, 5], got {value!r}")
            values[key] = int(value)
        answered = self.store.answered(participant)
        if position not in answered:
            if self.store.sides_played(participant, position) != {"A", "B"}:
                return self._error(HTTPStatus.CONFLICT, "play both stimuli, A and B, before answering")
            pair_id, robot = steps[position]
            self.store.answer(participant, position, pair_id, robot, answer, values["confidence"],
                              values["similarity"])
            answered = self.store.answered(participant)
        return self._redirect(self._next(participant, steps, answered))

    def _next(self, participant, steps, answered):
        todo = [k for k in range(len(steps)) if k not in answered]
        return f"/p/{participant}/pair/{todo[0]}" if todo else f"/p/{participant}/done"

    # --- plumbing ----------------------------------------------------------------------------------------------
    def _form(self):
        length = int(self.headers.get("Content-Length") or 0)
        if length > 10_000:
            raise ValueError("the form is too large")
        body = self.rfile.read(length).decode("utf-8", "replace")
        fields = parse_qs(body, keep_blank_values=True)
        if any(len(v) > 1 for v in fields.values()):
            raise ValueError("a field was given twice")
        return {k: v[0] for k, v in fields.items()}

    def _send(self, status, body, kind):
        self.send_response(status)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _page(self, text):
        self._send(HTTPStatus.OK, text.encode(), "text/html; charset=utf-8")

    def _redirect(self, location):
        self.send_response(HTTPStatus.SEE_OTHER)
        self.send_header("Location", location)
        self.send_header("Content-Length", "0")
        self.end_headers()

    def _error(self, status, message):
        self._send(status, f"{status.value} {status.phrase}: {message}\n".encode(), "text/plain; charset=utf-8")


def _shell(title, body):
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body {{ font-family: system-ui, sans-serif; max-width: 720px; margin: 2rem auto; padding: 0 1rem; }}
fieldset {{ margin: 1rem 0; }} audio {{ width: 100%; }} button {{ font-size: 1rem; padding: 0.4rem 1rem; }}</style>
</head><body><h1>{html.escape(title)}</h1>
{body}
</body></html>
"""


def _consent(config):
    return _shell(config.title, f"""<p>You will hear {len(config.pairs)} pairs of drum strokes. In each pair one
stroke was played by a human and one by a robot. Listen to both, then say which you think is the robot, how
sure you are, and how similar the two sound. Your answers are stored without your name.</p>
<form method="post" action="/start">
<label><input type="checkbox" name="consent" value="yes" id="consent" required> I agree to take part.</label>
<p><button type="submit" id="start">Start</button></p>
</form>""")


def _pair_page(config, participant, position, total):
    base = f"/p/{participant}"
    scale = "".join(f'<label><input type="radio" name="{{name}}" value="{v}" required> {v}</label> '
                    for v in range(1, 6))
    return _shell(config.title, f"""<p>Pair {position + 1} of {total} <small>(participant
<span id="participant">{participant}</span>)</small></p>
<p>A <audio id="audio-A" controls preload="none" src="{base}/audio/{position}/A"></audio></p>
<p>B <audio id="audio-B" controls preload="none" src="{base}/audio/{position}/B"></audio></p>
<form method="post" action="{base}/pair/{position}/answer" id="answer-form">
<fieldset><legend>Which one is the robot?</legend>
<label><input type="radio" name="answer" value="A" required> A</label>
<label><input type="radio" name="answer" value="B" required> B</label></fieldset>
<fieldset><legend>How sure are you? (1 = guessing, 5 = certain)</legend>{scale.format(name="confidence")}</fieldset>
<fieldset><legend>How similar do they sound? (1 = very different, 5 = the same)</legend>
{scale.format(name="similarity")}</fieldset>
<p><button type="submit" id="submit" disabled>Next</button> <span id="hint">Play both A and B first.</span></p>
</form>
<script>
const played = new Set();
for (const side of ["A", "B"]) {{
  document.getElementById("audio-" + side).addEventListener("play", () => {{
    fetch("{base}/pair/{position}/played", {{method: "POST",
      headers: {{"Content-Type": "application/x-www-form-urlencoded"}}, body: "side=" + side}})
      .then(() => {{ played.add(side);
        if (played.size === 2) {{ document.getElementById("submit").disabled = false;
          document.getElementById("hint").textContent = ""; }} }});
  }});
}}
document.getElementById("answer-form").addEventListener("submit", () => {{
  document.getElementById("submit").disabled = true;  // one click, one answer
}});
</script>""")


def _finish(config, participant):
    return _shell(config.title, f"""<p id="finished">Thank you: your answers are saved (participant
{participant}). You can close this page.</p>""")
