"""The listening-test app: a study's config, each participant's plan, answers stored exactly once in SQLite.

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
    admin_token = "..."                # 16+ characters; make-stimuli writes a random one
    seed = 20261122                    # recorded; shuffles orders and sides
    [[pair]]
    id = "buzz-1"
    human = "stimuli/human-buzz-1.wav" # paths relative to the config file
    robot = "stimuli/robot-buzz-1.wav"
    [limits]                           # optional: see limits.Limits
    sessions_per_minute_per_client = 10

This module holds what needs no web library: :class:`Config` (its limits a
:class:`~drumstroke.evaluation.limits.Limits`),
:func:`plan` and :class:`Store` (SQLite, one connection per call, ``BEGIN
IMMEDIATE`` transactions). :func:`make_server` serves the test on the web
(:mod:`drumstroke.evaluation.web`, Starlette, under
:mod:`drumstroke.evaluation.server`, uvicorn: the ``listen`` extra), imported
when called.
"""

import hashlib
import json
import os
import random
import re
import sqlite3
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

from .._checks import check_int, check_keys
from ..errors import ParameterError
from ..formats.reading import check_regular
from ..formats.responses_csv import responses_text
from ..formats.toml import reading_toml
from .limits import Limits, served_hosts

QUESTIONS = ("answer", "confidence", "similarity")
EXAMPLE_TOKENS = frozenset({"change-this-token", "change-me", "Xq3v0m8-H2kS1pLrT9yWcE4nB7uJ6dFa_Zo5RiMtGbN"})
"""Admin tokens printed in drumstroke's documentation (now or before): public, so refused."""

_ID = re.compile(r"[A-Za-z0-9._-]{1,64}")
_TOKEN = re.compile(r"[\x21-\x7e]{16,512}")  # printable ASCII, no space: it travels in an HTTP header
_TABLES = {"participants", "plays", "answers"}
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
    """A listening test: its title, admin token, seed, pairs and the server's limits.

    Attributes
    ----------
    title : str
        Shown on every page (1-200 characters).
    admin_token : str
        The export's bearer token: 16-512 printable ASCII characters without spaces, not one printed in
        the documentation (:data:`EXAMPLE_TOKENS`). Left out of the ``repr``.
    seed : int in [-2**63, 2**63 - 1]
        Recorded with each participant; with their id it shuffles their order and sides.
    pairs : tuple of Pair
    limits : Limits
    """

    title: str
    admin_token: str = field(repr=False)
    seed: int
    pairs: tuple
    limits: Limits = field(default_factory=Limits)

    def __post_init__(self):
        if not isinstance(self.title, str) or not 1 <= len(self.title) <= 200:
            raise ParameterError(f"config title must be text of 1-200 characters, got {self.title!r}")
        token = self.admin_token
        if not isinstance(token, str) or not _TOKEN.fullmatch(token):
            got = f"{len(token)} characters" if isinstance(token, str) else type(token).__name__
            raise ParameterError("config admin_token must be 16-512 printable ASCII characters without spaces "
                                 f"(as 'listen make-stimuli' writes), got {got}")
        if token in EXAMPLE_TOKENS:
            raise ParameterError("config admin_token is an example printed in the documentation, so anyone may know "
                                 "it: use a random one, e.g. python -c 'import secrets; "
                                 "print(secrets.token_urlsafe(32))'")
        check_int("config seed", self.seed, low=-(1 << 63), high=(1 << 63) - 1)
        if not isinstance(self.limits, Limits):
            raise ParameterError(f"config limits must be a Limits, got {type(self.limits).__name__}")

    @classmethod
    def from_toml(cls, path):
        """Read and check a config file; stimulus paths are relative to it and must exist."""
        path = Path(path)
        with reading_toml(path, "listening-test config") as data:
            check_keys("config", data, ("title", "admin_token", "seed", "pair", "limits"))
            limits = data.get("limits", {})
            if not isinstance(limits, dict):
                raise ParameterError("config limits must be a [limits] table")
            check_keys("config [limits]", limits, tuple(Limits.__dataclass_fields__))
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
                if not isinstance(pid, str) or not _ID.fullmatch(pid) or pid in seen:
                    raise ParameterError(f"{where}.id must be a unique name of 1-64 letters, digits, '.', '_', '-', "
                                         f"got {pid!r}")
                seen.add(pid)
                files = {}
                for side in ("human", "robot"):
                    name = table.get(side)
                    if not isinstance(name, str):
                        raise ParameterError(f"{where}.{side} must be a file path, got {name!r}")
                    file = Path(os.path.realpath(path.parent / name))
                    check_regular(file, f"{where}.{side}")  # a FIFO or a device would block or never end when served
                    files[side] = file
                pairs.append(Pair(pid, files["human"], files["robot"]))
            return cls(data.get("title", "Robot or human?"), data.get("admin_token"), data.get("seed"), tuple(pairs),
                       Limits(**limits))


def plan(config, participant):
    """The participant's pairs in their order, and the robot's side (A or B) for each: [(pair id, side)]."""
    digest = hashlib.sha256(f"{config.seed}:{participant}".encode()).hexdigest()
    rng = random.Random(int(digest, 16))
    order = [p.id for p in config.pairs]
    rng.shuffle(order)
    return [(pid, rng.choice("AB")) for pid in order]


class Store:
    """The SQLite database of participants, plays and answers.

    Parameters
    ----------
    path : str or Path
        The database file: created with its tables if missing (an empty file too); an existing file must
        be a SQLite database holding no other tables. A FIFO, a device or a directory is refused.
    create : bool
        False to read a database ``listen serve`` wrote, opened read-only: it must exist and hold the tables.

    Raises
    ------
    ParameterError
        Naming the path and the reason when it cannot be used.
    """

    def __init__(self, path, *, create=True):
        self.path = str(path)
        self._uri = None if create else f"file:{quote(os.path.realpath(path))}?mode=ro"
        where = f"database {self.path!r}"
        if Path(path).exists():
            check_regular(path, "database")
        if not create and not Path(path).exists():
            raise ParameterError(f"{where} does not exist")
        db = None
        try:
            db = self._connect()
            tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
            if create and not tables - _TABLES:
                db.executescript(_SCHEMA)
        except sqlite3.Error as error:
            raise ParameterError(f"{where} cannot be used as SQLite: {error}") from None
        finally:
            if db is not None:
                db.close()
        if create and tables - _TABLES:
            raise ParameterError(f"{where} holds other tables ({', '.join(sorted(tables - _TABLES))}): it is not a "
                                 "listening-test database")
        if not create and not _TABLES <= tables:
            raise ParameterError(f"{where} is not a listening-test database (no table "
                                 f"{min(_TABLES - tables)!r}): give the file 'listen serve' wrote")

    def _connect(self):
        if self._uri:
            db = sqlite3.connect(self._uri, uri=True, timeout=30.0, isolation_level=None)
        else:
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


def make_server(config, store, *, host="127.0.0.1", port=8000, forwarded_allow_ips=(), allowed_hosts=()):
    """The test's web server, its socket bound: ``serve()`` it until Ctrl-C, or ``start()``/``stop()`` it in a thread.

    Parameters
    ----------
    config : Config
    store : Store
    host : str
        The address or name to listen on (default 127.0.0.1: this machine only).
    port : int in [0, 65535]
        The TCP port; 0 picks a free one (the server's ``url`` tells which).
    forwarded_allow_ips : sequence of str
        The addresses or networks of trusted reverse proxies (e.g. ``["127.0.0.1"]``), whose
        ``X-Forwarded-For`` and ``X-Forwarded-Proto`` are believed: the client's address for the limits,
        https for ``Secure`` cookies. Empty (the default): none is.
    allowed_hosts : sequence of str
        The names browsers reach the test by (e.g. ``["study.example.org"]``, the reverse proxy's); a
        request whose ``Host`` names another is answered 400. Empty (the default): a server listening on
        loopback answers its loopback names only (``localhost``, ``127.0.0.1``, ``[::1]``: a page elsewhere
        cannot reach it by DNS rebinding), one listening on another address any name.

    Returns
    -------
    drumstroke.evaluation.server.Server

    Raises
    ------
    ParameterError
        A host that cannot be resolved, a port out of range or taken, a proxy that is not an address, an
        allowed host that is not a host name.
    ImportError
        Without the ``listen`` extra (Starlette and uvicorn).
    """
    check_int("port", port, low=0, high=65535)
    hosts = served_hosts(host, allowed_hosts)
    try:
        from .server import Server
        from .web import make_app
    except ImportError as error:
        raise ImportError(f"serving the listening test needs {error.name}: pip install 'drumstroke[listen]'") from None

    return Server(make_app(config, store, hosts=hosts), config.limits, host=host, port=port,
                  forwarded_allow_ips=forwarded_allow_ips)
