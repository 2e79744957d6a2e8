"""Trajectory CSV, both ways: the samples of one stick or several at a control rate.

A file starts with its header, then one row per sample at full precision (17 significant
digits, never ``-0``), so any CSV reader reads it as it is (``pandas.read_csv(path)``)::

    t,theta,omega
    0,0,0
    0.001,-5.1470588231516956e-06,-0.010294117647031554
    ...

One stick has the columns ``t,theta,omega`` (an export adds ``alpha``, rad/s²); several have
``t`` then ``theta_<stick>,omega_<stick>`` for each stick in turn. What the header cannot say
— the drumstroke version, the model, the name, the rate, the units, the sticks — is in the
JSON beside the file (:mod:`.sidecar`; :func:`metadata` makes it).

A kit's trajectory (a song on the kit) has ``t``, then every joint's angle ``LIMB.JOINT``, then
each one's ``LIMB.JOINT.velocity`` (and an export's ``LIMB.JOINT.acceleration``); its JSON, needed
to read it back, adds each joint's limits and each limb's hits (:func:`write_kit`, :func:`read_kit`,
:class:`KitSamples`).

Reading accepts files of older drumstroke versions too, whose first line was a ``#`` comment
(``# drumstroke 0.1.0; model=paper; stroke=free-bounce; rate=1000 Hz; units s, rad, rad/s``).
:func:`file_metadata` takes the model and the rate from the JSON beside the file, else from
such a comment, else the rate from the ``t`` column.

Examples
--------
>>> import pathlib, tempfile
>>> import numpy as np
>>> path = pathlib.Path(tempfile.mkdtemp()) / "move.csv"
>>> t = np.arange(3) / 1000.0
>>> write_columns(path, ("t", "theta", "omega"), (t, -0.1 * t, np.full(3, -0.1)))
>>> print(path.read_text(), end="")
t,theta,omega
0,0,-0.10000000000000001
0.001,-0.0001,-0.10000000000000001
0.002,-0.00020000000000000001,-0.10000000000000001
>>> comment, columns = read_columns(path)
>>> file_metadata(path, comment, columns)
{'model': 'unknown', 'rate': 1000.0, 'rate_from': 'its t column'}
"""

import io
import re
from typing import NamedTuple

import numpy as np

from .._atomic import bundled, write_atomic
from ..errors import ParameterError
from .json import impact_columns
from .reading import MIB, read_text
from .sidecar import describe, read_sidecar, read_sidecar_document, sidecar_for, sidecar_path, write_sidecar

MAX_BYTES = 1024 * MIB
"""The largest trajectory file read (bytes): an hour of four sticks at 1 kHz is some 700 MB."""

SUFFIXES = (".csv",)
"""The extension of the trajectory files written."""

UNITS = {"t": "s", "theta": "rad", "omega": "rad/s", "alpha": "rad/s^2"}
"""The unit of each kind of column (a several-stick file's ``theta_<stick>`` is a ``theta``)."""

_RATE = re.compile(r"(?:^|; )rate=([^ ;]+) Hz(?:;|$)")


def column_names(sticks, *, alpha=False):
    """The header of a trajectory of ``sticks``: ``t,theta,omega[,alpha]``, or per stick ``theta_<stick>``, …"""
    kinds = ("theta", "omega", "alpha") if alpha else ("theta", "omega")
    if len(sticks) == 1:
        return ["t", *kinds]
    return ["t", *(f"{kind}_{stick}" for stick in sticks for kind in kinds)]


def metadata(path, names, *, model, name, rate, sticks, extra=None):
    """The metadata of the trajectory CSV at ``path`` with the header ``names``, for the JSON beside it.

    Parameters
    ----------
    path : str or Path
    names : sequence of str
        The header (:func:`column_names`).
    model, name : str
        What made it and what it is called.
    rate : float
        Samples per second (Hz).
    sticks : sequence of str
    extra : dict or None
        More fields, written after these (a composition's ``offset``, an export's ``note``).
    """
    units = {column: UNITS[column.split("_", 1)[0]] for column in names}
    fields = {"model": model, "name": name or "custom", "rate": float(rate), "sticks": list(sticks), **(extra or {})}
    return describe(path, names, units, fields)


def columns_text(names, columns):
    """CSV text: the header of ``names`` (none if None), then the columns (1-D arrays of one length) at full precision."""
    # Adding 0 turns -0.0 into 0.0, which other tools would otherwise read as a distinct "-0".
    table = np.column_stack(columns) + 0.0
    header = "" if names is None else ",".join(names) + "\n"
    # One format of the whole table (numpy's savetxt, a row at a time into a StringIO, left the process some
    # 100 bytes a row larger each call: a long trajectory streamed in chunks grew without bound).
    return header + (",".join(["%.17g"] * table.shape[1]) + "\n") * len(table) % tuple(table.ravel().tolist())


def write_columns(path, names, columns, *, bundle=None):
    """Write columns (1-D arrays of one length) under the header ``names``, atomically (in ``bundle``, if given)."""
    write_atomic(path, columns_text(names, columns), bundle=bundle)


def write_column_chunks(path, names, chunks, *, bundle=None):
    """Write the rows of ``chunks`` (each columns as :func:`write_columns` takes them), each written as it comes.

    The file is the one :func:`write_columns` writes of the chunks put end to end, and is put in
    place as atomically; only one chunk is held at a time, so a long trajectory streams to its file.
    """
    def text():
        yield ",".join(names) + "\n"
        for columns in chunks:
            yield columns_text(None, columns)

    write_atomic(path, text(), bundle=bundle)


def stick_columns(sticks, theta, omega, alpha=None):
    """Column names and arrays for θ, ω (and α) of one stick (``theta``) or several (``theta_<stick>``).

    ``theta``, ``omega``, ``alpha`` are [shape=(n,)] for one stick, (n, sticks) for several.
    """
    names = column_names(sticks, alpha=alpha is not None)[1:]
    arrays = [a for a in (theta, omega, alpha) if a is not None]
    if len(sticks) == 1:
        return names, [np.reshape(a, -1) for a in arrays]
    return names, [a[:, j] for j in range(len(sticks)) for a in arrays]


def read_columns(path, *, what="trajectory file"):
    """Read a trajectory CSV: its old ``#`` comment ("" if it has none), column names and columns (finite numbers).

    The header comes first; a file of an older drumstroke has one ``#`` comment line before it.

    Returns
    -------
    comment : str
    columns : dict of str to ndarray [shape=(n,)]
        In file order; n ≥ 2.
    """
    where = f"{what} {str(path)!r}"
    text = read_text(path, what, limit=MAX_BYTES)
    comment = ""
    if text.startswith("#"):
        first, _, text = text.partition("\n")
        comment = first[1:].strip()
    header, _, rows = text.partition("\n")
    if not header.startswith("t,") or not rows:
        raise ParameterError(f"{where} is corrupt: it must start with a header such as t,theta,omega, then rows")
    names = header.strip().split(",")
    try:
        data = np.loadtxt(io.StringIO(rows), delimiter=",", ndmin=2)
    except ValueError as error:
        raise ParameterError(f"{where} is corrupt: {error}") from None
    if data.shape[1] != len(names) or len(data) < 2:
        raise ParameterError(f"{where} is corrupt: {len(data)} rows of {data.shape[1]} columns under the header "
                             f"{','.join(names)} (at least 2 rows needed)")
    finite = np.isfinite(data)
    if not finite.all():
        row, column = (int(i) for i in np.argwhere(~finite)[0])
        line = row + 2 + bool(comment)  # the header's line, then the rows
        raise ParameterError(f"{where} is corrupt: row {row} is not finite (line {line}, column {column + 1} "
                             f"{names[column]!r}: {float(data[row, column])!r})")
    return comment, dict(zip(names, data.T))


def file_metadata(path, comment, columns):
    """The model and rate of a trajectory CSV read by :func:`read_columns`, and where the rate came from.

    From the JSON beside the file when it has the file's metadata; else from an old ``#``
    comment line; else the model is "unknown" and the rate (Hz) is the one of the ``t``
    column's mean step, (n − 1)/(t[-1] − t[0]) (None when that is not positive).

    Returns
    -------
    dict
        ``model`` (str), ``rate`` (float or None), ``rate_from`` (words: which of the three).

    Raises
    ------
    ParameterError
        When the JSON beside the file describes other columns, or a rate or model that is not one.
    """
    block = read_sidecar(path)
    if block is not None:
        return _from_sidecar(block, sidecar_path(path), columns)
    rate = _stated_rate(comment)
    if rate is not None:
        return {"model": _stated_model(comment), "rate": rate, "rate_from": "comment line"}
    t = columns["t"]
    span = float(t[-1] - t[0])
    return {"model": _stated_model(comment), "rate": (len(t) - 1) / span if span > 0.0 else None,
            "rate_from": "its t column"}


def _from_sidecar(block, side, columns):
    where = f"metadata {str(side)!r}"
    if block.get("columns") != list(columns):
        raise ParameterError(f"{where} describes the columns {block.get('columns')!r}, but the CSV beside it has "
                             f"{list(columns)!r}; remove or rewrite the JSON")
    rate, model = block.get("rate"), block.get("model")
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0.0 < rate <= 1e6:
        raise ParameterError(f"{where}: csv.rate must be a number in (0, 1e6] Hz, got {rate!r}")
    if not isinstance(model, str):
        raise ParameterError(f"{where}: csv.model must be text, got {model!r}")
    return {"model": model, "rate": float(rate), "rate_from": where}


def recorded_impacts(path, columns):
    """The impacts the JSON beside a trajectory CSV records, by stick; None when it records none.

    A run that writes its own JSON beside its CSV records there every impact as the solver found
    it: ``simulate --json s.json --csv s.csv``, ``design`` and ``compose`` or ``rudiment`` likewise, a
    library's ``NAME.json``, the demo's and ``figures``' files. A stroke's JSON has ``"impacts"``, one
    row each, and ``"tip_distance"``; a composition's has ``"impacts"`` by stick. Any other JSON
    beside the CSV (the metadata alone, as :meth:`drumstroke.Trajectory.write_csv` writes it) records none.

    Parameters
    ----------
    path : str or Path
        The CSV.
    columns : dict of str to ndarray
        Its columns (:func:`read_columns`): the impacts must lie within its ``t``.

    Returns
    -------
    dict or None
        ``{stick: (t, omega, omega_after, tip_distance)}``: s, rad/s before and after each impact
        (after: None when the JSON does not say), m (None when the JSON does not say); the stick
        None for a stroke's one stick.

    Raises
    ------
    ParameterError
        When the JSON records impacts that are not valid for the samples (see
        :func:`drumstroke.formats.json.impact_columns`): remove or rewrite it.
    """
    side = sidecar_path(path)
    if read_sidecar(path) is None:  # no JSON beside the CSV, or not this kind
        return None
    data = read_sidecar_document(path)
    rows = data.get("impacts")
    start, end = float(columns["t"][0]), float(columns["t"][-1])
    where = f"metadata {str(side)!r}"
    if isinstance(rows, list):
        rows = {None: rows}
    if not isinstance(rows, dict) or not rows:
        return None
    return {stick: (*impact_columns(stick_rows, where if stick is None else f"{where} impacts[{stick!r}]",
                                    start=start, end=end), _tip_distance(stick_rows, data.get("tip_distance")))
            for stick, stick_rows in rows.items()}


def _tip_distance(rows, stated):
    """x (m): as the JSON states it, else from the first impact that moves (its tip speed over |ω|), else None."""
    if isinstance(stated, (int, float)) and not isinstance(stated, bool) and stated > 0:
        return float(stated)
    for row in rows:
        speed = row.get("tip_speed")
        if isinstance(speed, (int, float)) and not isinstance(speed, bool) and speed > 0 and row["omega"] < 0:
            return speed / -row["omega"]
    return None


def sticks_in(columns):
    """The stick names of a several-stick file's columns (``theta_<stick>``), or () for one stick."""
    return tuple(name[len("theta_"):] for name in columns if name.startswith("theta_"))


def read_stick(path, *, stick=None):
    """t (s), θ (rad), ω (rad/s), α (rad/s², or None), the :func:`file_metadata` of one stick of a trajectory CSV,
    and the times (s) of its impacts that the JSON beside it records (:func:`recorded_impacts`), or None.

    A file with several sticks has ``theta_<stick>`` columns: name the ``stick`` to read.
    """
    comment, columns = read_columns(path)
    samples = stick_of(columns, stick, path)
    recorded = recorded_impacts(path, columns) or {}
    if not sticks_in(columns) and len(recorded) == 1:  # a stroke's, or a one-stick piece's under its stick's name
        recorded = {stick: next(iter(recorded.values()))}
    impacts = recorded.get(stick)
    return (*samples, file_metadata(path, comment, columns), None if impacts is None else impacts[0])


def stick_of(columns, stick, path):
    """t, θ, ω and α (or None) of one stick from a file's ``columns`` (see :func:`read_stick`)."""
    sticks = sticks_in(columns)
    if stick is None and not sticks:
        keys = ("theta", "omega", "alpha")
    elif stick is None:
        raise ParameterError(f"trajectory file {str(path)!r} has the sticks {', '.join(sticks)}; name one (stick)")
    elif stick in sticks:
        keys = (f"theta_{stick}", f"omega_{stick}", f"alpha_{stick}")
    else:
        raise ParameterError(f"stick must be one of {', '.join(sticks) or '(none: one stick)'}, got {stick!r}")
    if not all(key in columns for key in keys[:2]):
        raise ParameterError(f"trajectory file {str(path)!r} needs the columns t,{','.join(keys[:2])}")
    return columns["t"], columns[keys[0]], columns[keys[1]], columns.get(keys[2])


def _stated_model(comment):
    """The ``model=`` of an old comment line, or "unknown"."""
    return next((part.split("=", 1)[1] for part in comment.split("; ") if part.startswith("model=")), "unknown")


def _stated_rate(comment):
    """The ``rate=… Hz`` of an old comment line (Hz), or None when it states none."""
    match = _RATE.search(comment)
    if match is None:
        return None
    try:
        return float(match.group(1))
    except ValueError:
        return None


# --- a kit's trajectory: every joint of every limb -----------------------------------------------------------------

KIT_KINDS = ("", ".velocity", ".acceleration")
"""The suffixes of a kit file's columns after a joint's name: its angle (rad), speed (rad/s), an export's
acceleration (rad/s²)."""

_KIT_UNITS = dict(zip(KIT_KINDS, ("rad", "rad/s", "rad/s^2")))
_KIT_FIELDS = ("rate", "model", "limbs", "offset", "limits", "hits")


class KitSamples(NamedTuple):
    """A kit's trajectory at its control rate: every joint's angle and speed, and what it was composed within.

    :meth:`drumstroke.compose.KitComposition.samples` makes one; :func:`read_kit` reads one from a file.

    Attributes
    ----------
    t : ndarray [shape=(n,)]
        s, strictly increasing.
    positions, velocities : dict of str to ndarray [shape=(n,)]
        Each joint's angle (rad) and speed (rad/s), by its column name ``LIMB.JOINT``, in the limbs' order.
    limbs : dict of str to tuple of str
        Each limb's joints, in order (a hand's positioning joints then ``theta``; a foot's ``theta``).
    rate : float
        Hz.
    model : str
        The model the sticks' strokes were designed with.
    offset : float
        s: where the score's time 0 is on ``t``.
    limits : dict of str to dict
        Each joint's limits as a ``[limits]`` table (:class:`drumstroke.palette.motion.Limits`' fields); a
        table of ``theta_low`` and ``theta_high`` alone (a pedal's beater) bounds the range only.
    hits : dict of str to ndarray
        Each limb's impact times (s, on ``t``), where its stick or beater is reversed by what it strikes.
    name : str
    """

    t: np.ndarray
    positions: dict
    velocities: dict
    limbs: dict
    rate: float
    model: str
    offset: float
    limits: dict
    hits: dict
    name: str = "kit"


def range_only(table):
    """Whether a kit joint's limits ``table`` bounds its range alone (``theta_low``, ``theta_high``: a pedal's beater).

    Examples
    --------
    >>> range_only({"theta_low": 0.0, "theta_high": 1.0}), range_only({"theta_low": 0.0, "max_speed": 12.0})
    (True, False)
    """
    return set(table) <= {"theta_low", "theta_high"}


def kit_column_names(limbs, *, accelerations=False):
    """The header of a kit's trajectory after ``t``: ``LIMB.JOINT`` for every joint of every limb of ``limbs``
    (a dict of limb to joints), then ``LIMB.JOINT.velocity``, then (``accelerations``) ``LIMB.JOINT.acceleration``.

    Examples
    --------
    >>> kit_column_names({"right": ("yaw", "theta"), "left-foot": ("theta",)})[:4]
    ['right.yaw', 'right.theta', 'left-foot.theta', 'right.yaw.velocity']
    """
    joints = [f"{limb}.{joint}" for limb, names in limbs.items() for joint in names]
    return [f"{joint}{kind}" for kind in KIT_KINDS[:3 if accelerations else 2] for joint in joints]


def kit_metadata(path, samples, *, accelerations=False, extra=None):
    """The metadata of the kit trajectory CSV at ``path`` holding ``samples`` (a :class:`KitSamples`), for the
    JSON beside it: the rate, the model, the limbs, the offset, each joint's limits and each limb's hits."""
    names = ["t", *kit_column_names(samples.limbs, accelerations=accelerations)]
    units = {"t": "s"} | {name: _KIT_UNITS[_kind(name)] for name in names[1:]}
    fields = {"model": samples.model, "name": samples.name, "rate": float(samples.rate),
              "limbs": list(samples.limbs), "offset": float(samples.offset), "limits": samples.limits,
              "hits": {limb: [float(t) for t in times] for limb, times in samples.hits.items()}, **(extra or {})}
    return describe(path, names, units, fields)


def write_kit(path, samples, *, accelerations=None, extra=None, sidecar=True, bundle=None):
    """Write a kit's trajectory as CSV, header first, atomically; its :func:`kit_metadata` in the JSON beside it.

    Parameters
    ----------
    path : str or Path
    samples : KitSamples
    accelerations : dict of str to ndarray or None
        Each joint's acceleration (rad/s²) by its column name, written after the speeds.
    extra : dict or None
        More metadata fields (an export's ``note``).
    sidecar : bool
        Write the metadata to the JSON beside the CSV; False returns it only, for the caller's own JSON there.
    bundle : Bundle or None

    Returns
    -------
    dict
        The metadata.
    """
    side = sidecar_for(path) if sidecar else None
    block = kit_metadata(path, samples, accelerations=accelerations is not None, extra=extra)
    columns = [samples.t, *samples.positions.values(), *samples.velocities.values(),
               *(accelerations.values() if accelerations is not None else ())]
    with bundled(bundle) as files:
        write_columns(path, block["columns"], columns, bundle=files)
        if side is not None:
            write_sidecar(side, block, bundle=files)
    return block


def is_kit_file(path):
    """Whether the CSV at ``path`` is a kit's trajectory: its header (first line) names ``LIMB.JOINT`` columns."""
    try:
        with open(path, encoding="utf-8-sig", errors="replace") as file:
            header = file.readline(1 << 16)
    except OSError:
        return False  # the reader says why
    return header.startswith("t,") and "." in header


def read_kit(path):
    """Read a kit's trajectory CSV and the JSON beside it, every value checked.

    The header comes first: ``t``, ``LIMB.JOINT`` for every joint, ``LIMB.JOINT.velocity`` for each, and
    (an export's) ``LIMB.JOINT.acceleration``; every value is a finite number, ``t`` strictly increases.
    The JSON beside it (written with it) gives the rate, the model, the limbs in order, the offset, each
    joint's limits and each limb's hits.

    Returns
    -------
    KitSamples

    Raises
    ------
    ParameterError
        Naming the file and the line, the column or the metadata field: no JSON beside the CSV, columns
        missing, out of order or not the JSON's, a value not finite, a time not after the one before.
    """
    where = f"kit trajectory file {str(path)!r}"
    side = sidecar_path(path)
    block = read_sidecar(path)
    if block is None:
        raise ParameterError(f"{where} has no metadata beside it: {str(side)!r} (its rate, limbs, joint limits and "
                             "hits) is missing or not drumstroke's; write the CSV and its JSON together "
                             "(compose --kit --csv, robot export --format csv)")
    comment, columns = read_columns(path, what="kit trajectory file")
    _from_sidecar(block, side, columns)
    missing = [key for key in _KIT_FIELDS if key not in block]
    if missing:
        raise ParameterError(f"metadata {str(side)!r} lacks {', '.join(missing)}: it is not a kit trajectory's; "
                             "compose the song again")
    names = list(columns)[1:]
    limbs = _kit_limbs(names, block["limbs"], where)
    t = columns["t"]
    back = np.flatnonzero(np.diff(t) <= 0.0)
    if len(back):
        i = int(back[0]) + 1
        line = i + 2 + bool(comment)
        raise ParameterError(f"{where}, line {line}: t = {float(t[i])!r} s does not come after {float(t[i - 1])!r} s "
                             f"(line {line - 1}); times must increase strictly")
    joints = kit_column_names(limbs)[:sum(len(j) for j in limbs.values())]
    at = f"metadata {str(side)!r}"
    return KitSamples(t, {j: columns[j] for j in joints}, {j: columns[f"{j}.velocity"] for j in joints}, limbs,
                      float(block["rate"]), block["model"], _number(at, "offset", block["offset"]),
                      _kit_limits(at, block["limits"], joints), _kit_hits(at, block["hits"], limbs, t),
                      str(block.get("name", "kit")))


def _kind(name):
    """The suffix of a kit column (of :data:`KIT_KINDS`)."""
    return next((kind for kind in KIT_KINDS[1:] if name.endswith(kind)), "")


def _kit_limbs(names, stated, where):
    """Each limb's joints from a kit file's header (after ``t``), checked against the limbs its JSON states."""
    if not isinstance(stated, list) or not stated or not all(isinstance(limb, str) for limb in stated):
        raise ParameterError(f"{where}: its JSON's limbs must be a list of limb names, got {stated!r}")
    limbs = {}
    for name in (name for name in names if not _kind(name)):
        limb, _, joint = name.partition(".")
        if limb not in stated or not joint or "." in joint:
            raise ParameterError(f"{where}: column {name!r} is not LIMB.JOINT for a limb of {', '.join(stated)}")
        limbs.setdefault(limb, []).append(joint)
    limbs = {limb: tuple(joints) for limb, joints in limbs.items()}
    if list(limbs) != stated:
        raise ParameterError(f"{where}: its columns are the joints of {', '.join(limbs) or 'no limb'}, in that order; "
                             f"its JSON says {', '.join(stated)}")
    expected = kit_column_names(limbs, accelerations=names[-1].endswith(".acceleration"))
    if names == expected:
        return limbs
    missing = [name for name in expected if name not in names]
    extra = [name for name in names if name not in expected]
    if missing or extra:
        raise ParameterError(f"{where} " + (f"has no column {missing[0]!r}" if missing else
                                            f"has the column {extra[0]!r}, not one of its joints'") +
                             ": after t, every joint's LIMB.JOINT, then each one's LIMB.JOINT.velocity (and "
                             "LIMB.JOINT.acceleration)")
    i = next(i for i, (name, wanted) in enumerate(zip(names, expected)) if name != wanted)
    raise ParameterError(f"{where} has {names[i]!r} as column {i + 2}, where {expected[i]!r} belongs: after t, every "
                         "joint's LIMB.JOINT, then each one's LIMB.JOINT.velocity, in the same order")


def _number(where, key, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise ParameterError(f"{where}: {key} must be a finite number, got {value!r}")
    return float(value)


def _kit_limits(where, limits, joints):
    """Each joint's limits table, checked to hold numbers only (their meaning is the robot's to check)."""
    if not isinstance(limits, dict) or sorted(limits) != sorted(joints):
        raise ParameterError(f"{where}: limits must be a table for each joint ({', '.join(joints)}), got "
                             f"{sorted(limits) if isinstance(limits, dict) else limits!r}")
    checked = {}
    for joint in joints:
        table = limits[joint]
        if not isinstance(table, dict) or not table:
            raise ParameterError(f"{where}: limits[{joint!r}] must be a table of limits, got {table!r}")
        checked[joint] = {key: _number(where, f"limits[{joint!r}].{key}", value) for key, value in table.items()}
    return checked


def _kit_hits(where, hits, limbs, t):
    """Each limb's impact times, checked: finite, ascending, within ``t``."""
    if not isinstance(hits, dict) or not set(hits) <= set(limbs):
        raise ParameterError(f"{where}: hits must be a table of limb ({', '.join(limbs)}) to impact times, got "
                             f"{sorted(hits) if isinstance(hits, dict) else hits!r}")
    checked = {}
    for limb, times in hits.items():
        if not isinstance(times, list):
            raise ParameterError(f"{where}: hits[{limb!r}] must be a list of times (s), got {times!r}")
        values = np.array([_number(where, f"hits[{limb!r}][{i}]", v) for i, v in enumerate(times)], dtype=float)
        if np.any(np.diff(values) < 0.0) or (len(values) and not t[0] <= values[0] <= values[-1] <= t[-1]):
            raise ParameterError(f"{where}: hits[{limb!r}] must be ascending times within [{t[0]:g}, {t[-1]:g}] s")
        checked[limb] = values
    return checked
