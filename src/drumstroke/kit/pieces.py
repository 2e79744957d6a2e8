"""The kit's description: its pieces, where each sits for the hands, and the joints that put a hand there.

A :class:`Piece` is one thing a limb strikes — a drum, a cymbal, the hi-hat, the kick — with the
General MIDI percussion keys it answers, the limbs that may play it, its place (the angles of the
hands' positioning joints that put the stick's fulcrum over it), the height h of its surface below
the fulcrum there (so the stick meets it at θ_max = −asin(h/x)), its coefficient of restitution c and
the kind of sound it makes. A :class:`Kit` holds the pieces and the limbs with their positioning
joints' limits, checks that the whole is playable, and finds the piece a key is played on.

The hands' positioning joints are named by the kit; every kit has ``yaw``, the turn about the
vertical through the drummer's body (rad, 0 straight ahead, positive to the drummer's left), which
orders the pieces from left to right; the shipped kit adds ``lift``, the shoulder's raise of the
fulcrum (rad, positive up), so that a cymbal above the snare still lies below the fulcrum by an h in
(0, x): the stick's geometry is the same on every piece, only h changes. The feet have no
positioning joint: each stays on its pedal.

The hi-hat is one piece in several states, set by the foot on its pedal and named by the notes' keys:
closed (42: the foot down, the top plate clamped onto the bottom one), half open, open (46: the foot
up, the top plate loose on its clutch, above the bottom one) and the pedal (44: the foot closing it,
no stick). Each state a hand plays is a surface of its own, with its c and h (a :class:`Surface`),
as the kit file gives them (the shipped kit: its own c, the closed hat's h): :meth:`Piece.setup` takes the
state.

:func:`read_kit` reads a kit from a TOML file a person writes (the format is the shipped
:data:`DEFAULT_KIT`'s, documented in ``docs/kit.md``); :func:`default_kit` is the shipped five-piece
kit; :func:`write_kit` writes one back.

Examples
--------
>>> kit = default_kit()
>>> [p.name for p in kit.pieces][:3]
['snare', 'kick', 'hihat']
>>> piece, state = kit.piece_for_key(46)
>>> piece.name, state
('hihat', 'open')
>>> kit.piece_for_key(81) is None
True
>>> round(kit.piece("snare").setup(Setup()).head, 4)
-0.2623
>>> [kit.piece("hihat").setup(Setup(), state=s).cor for s in ("closed", "half", "open")]
[0.55, 0.45, 0.35]
"""

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

from .._checks import check_choice, check_keys, check_real, shown
from ..design.setup import Setup
from ..errors import ParameterError
from ..formats.toml import reading_toml, write_toml
from ..model import Stick
from ..palette.motion import Limits

HANDS = ("right", "left")
"""The hands' limb names."""
FEET = ("right-foot", "left-foot")
"""The feet's limb names."""
LIMBS = HANDS + FEET
"""Every limb a kit may name."""

KINDS = ("membrane", "cymbal", "hihat", "kick")
"""The sound a piece makes, for rendering: a drumhead, a cymbal, the hi-hat's pair of cymbals, the kick drum."""

ROLES = ("time", "backbeat", "accent", "drum")
"""What a piece is for, to the limb assignment (:mod:`.limbs`): keeping time (the hi-hat, the ride: the lead
hand's), the backbeat (the snare: the other hand's), accents (crashes: the free hand's), any other drum."""

KIND_ROLES = {"membrane": "drum", "cymbal": "accent", "hihat": "time", "kick": "drum"}
"""A piece's role when its table names none, by its kind."""

HIHAT_STATES = ("closed", "half", "open", "pedal")
"""What the hi-hat's keys mean: struck closed, half open or open, or closed by the foot alone (the pedal)."""

PEDAL_STATE = "pedal"
"""The state a foot plays (the hi-hat's pedal); a hand plays the others."""

HAND_STATES = tuple(state for state in HIHAT_STATES if state != PEDAL_STATE)
"""The hi-hat's states a hand plays: each is a surface of its own (:class:`Surface`)."""

YAW = "yaw"
"""The positioning joint every kit's hands have: the turn about the vertical (rad, 0 ahead, + to the left)."""

PLACE_TOLERANCE = 0.01
"""Default: two places of one hand closer than this in every joint (rad) are one place."""

DEFAULT_KIT = Path(__file__).with_name("default.toml")
"""The shipped kit: a five-piece right-handed kit with hi-hat, ride (and its bell) and crash."""

_NAME = re.compile(r"^[a-z0-9][a-z0-9_-]{0,31}$")
_PIECE_KEYS = ("kind", "role", "keys", "states", "limbs", "place", "height", "cor", "pedal")
_STATE_KEYS = ("keys", "cor", "height")
_KIT_KEYS = ("stick", "place_tolerance", "limbs", "pieces")
_LIMB_KEYS = ("joints",)


class Surface(NamedTuple):
    """What a stick meets on one state of the hi-hat: its c and its h (m, below the fulcrum at the piece's place)."""

    cor: float
    height: float


@dataclass(frozen=True)
class Piece:
    """One piece of the kit.

    Parameters
    ----------
    name : str
        1-32 of a-z, 0-9, ``_``, ``-`` ("snare", "hihat", "floor-tom").
    kind : {"membrane", "cymbal", "hihat", "kick"}
        The sound it makes, for rendering.
    keys : tuple of int in [0, 127]
        The General MIDI percussion keys it answers (at least one).
    limbs : tuple of str
        The limbs that may play it, of :data:`LIMBS`.
    cor : float in [0, 1)
        c, the coefficient of restitution of the stick (or the kick's beater) on it; a hi-hat's state
        may have its own (``surfaces``).
    height : float in (0, 10) or None
        h, m: how far its surface lies below the stick's fulcrum at its place; needed when a hand
        plays it (the kit checks h < x, the stick's fulcrum to tip); a hi-hat's state may have its own.
    place : dict of str to float
        rad: the hands' positioning joints' angles that put the fulcrum over it; needed when a hand plays it.
    pedal : str or None
        The pedal a foot works to play it ("kick", "hihat"); needed when a foot plays it.
    states : dict of int to str
        The hi-hat's keys' meanings, each of :data:`HIHAT_STATES` (every key of a hi-hat has one; only
        a hi-hat has them).
    role : {"time", "backbeat", "accent", "drum"} or None
        What it is for, to the limb assignment; None: by its kind (:data:`KIND_ROLES`).
    surfaces : dict of str to Surface
        A hand-played hi-hat's states (of :data:`HAND_STATES` its keys name), each with the c and h a
        stick meets in it; a state not given, or a field None, is the piece's ``cor`` and ``height``.
        Kept resolved: every hand state its keys name, with both numbers.
    """

    name: str
    kind: str
    keys: tuple
    limbs: tuple
    cor: float
    height: float | None = None
    place: dict = field(default_factory=dict)
    pedal: str | None = None
    states: dict = field(default_factory=dict)
    role: str | None = None
    surfaces: dict = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.name, str) or not _NAME.match(self.name):
            raise ParameterError(f"piece name must be 1-32 of a-z, 0-9, '_', '-' (starting with a letter or digit), "
                                 f"got {shown(self.name)}")
        at = f"pieces.{self.name}"
        check_choice(f"{at}.kind", self.kind, KINDS)
        object.__setattr__(self, "role", check_choice(f"{at}.role", self.role or KIND_ROLES[self.kind], ROLES))
        object.__setattr__(self, "keys", _keys(f"{at}.keys", self.keys))
        object.__setattr__(self, "limbs", _limbs(f"{at}.limbs", self.limbs))
        object.__setattr__(self, "cor", check_real(f"{at}.cor", self.cor, low=0.0, high=1.0, high_open=True))
        self._check_hands(at)
        self._check_feet(at)
        self._check_states(at)
        self._check_surfaces(at)

    def _check_hands(self, at):
        if not isinstance(self.place, dict):
            raise ParameterError(f"{at}.place must be a table of joint angles (rad), got {shown(self.place)}")
        if not self.hands:
            for name in ("height", "place"):
                if getattr(self, name):
                    raise ParameterError(f"{at}.{name} is only for a piece a hand plays; its limbs are "
                                         f"{', '.join(self.limbs)}")
            return
        if self.height is None:
            raise ParameterError(f"{at}.height is missing: h (m), its surface below the fulcrum, for the hands")
        object.__setattr__(self, "height", check_real(f"{at}.height", self.height, low=0.0, high=10.0,
                                                      low_open=True, high_open=True, unit="m"))
        if YAW not in self.place:
            raise ParameterError(f"{at}.place.{YAW} is missing: the hands' angle (rad) that puts the fulcrum over it")
        place = {}
        for joint, angle in self.place.items():
            place[joint] = check_real(f"{at}.place.{joint}", angle, low=-math.pi / 2, high=math.pi / 2, unit="rad")
        object.__setattr__(self, "place", place)

    def _check_feet(self, at):
        if not self.feet:
            if self.pedal is not None:
                raise ParameterError(f"{at}.pedal is only for a piece a foot plays; its limbs are "
                                     f"{', '.join(self.limbs)}")
            return
        if self.pedal is None:
            raise ParameterError(f"{at}.pedal is missing: the pedal a foot works to play it")
        if not isinstance(self.pedal, str) or not _NAME.match(self.pedal):
            raise ParameterError(f"{at}.pedal must be a pedal's name (1-32 of a-z, 0-9, '_', '-'), "
                                 f"got {shown(self.pedal)}")

    def _check_states(self, at):
        if not isinstance(self.states, dict):
            raise ParameterError(f"{at}.keys' states must be a table of key to state, got {shown(self.states)}")
        if self.kind != "hihat":
            if self.states:
                raise ParameterError(f"{at}.keys: only a hi-hat's keys have states ({', '.join(HIHAT_STATES)}); "
                                     f"give a list of keys")
            return
        for key in self.keys:
            if key not in self.states:
                raise ParameterError(f"{at}.keys: key {key} has no state; a hi-hat gives its keys by state "
                                     f"([{at}.states.closed] keys = 42, and so on)")
        for key, state in self.states.items():
            if key not in self.keys:
                raise ParameterError(f"{at}.keys: state {state!r} names key {key!r}, not one of its keys")
            check_choice(f"{at}.keys.{state}", state, HIHAT_STATES)
        if PEDAL_STATE in self.states.values() and not self.feet:
            raise ParameterError(f"{at}.limbs must name a foot to play its pedal key; its limbs are "
                                 f"{', '.join(self.limbs)}")

    def _check_surfaces(self, at):
        """Each hand state's c and h, checked, the piece's where not given (kept resolved)."""
        if not isinstance(self.surfaces, dict):
            raise ParameterError(f"{at}.states must be a table of state to Surface (c, h), got {shown(self.surfaces)}")
        played = [state for state in HAND_STATES if state in self.states.values()] if self.hands else []
        for state in self.surfaces:
            if state not in played:
                raise ParameterError(f"{at}.states.{state}: only the states a hand plays on a hi-hat, those its keys "
                                     f"name, have a c and h of their own ({', '.join(played) or 'none here'})")
        resolved = {}
        for state in played:
            given = self.surfaces.get(state, (None, None))
            if not isinstance(given, tuple) or len(given) != 2:
                raise ParameterError(f"{at}.states.{state} must be a Surface (cor, height), got {shown(given)}")
            cor, height = given
            cor = self.cor if cor is None else check_real(f"{at}.states.{state}.cor", cor, low=0.0, high=1.0,
                                                          high_open=True)
            height = self.height if height is None else check_real(
                f"{at}.states.{state}.height", height, low=0.0, high=10.0, low_open=True, high_open=True, unit="m")
            resolved[state] = Surface(cor, height)
        object.__setattr__(self, "surfaces", resolved)

    @property
    def hands(self):
        """The hands that may play it (of :data:`HANDS`)."""
        return tuple(limb for limb in self.limbs if limb in HANDS)

    @property
    def feet(self):
        """The feet that may play it (of :data:`FEET`)."""
        return tuple(limb for limb in self.limbs if limb in FEET)

    def state(self, key):
        """What ``key`` means on it: the hi-hat's state (:data:`HIHAT_STATES`), None for any other piece."""
        return self.states.get(key)

    def limbs_for(self, state=None):
        """The limbs that play a note of ``state`` on it: the feet the pedal, the hands the rest (or the feet
        when no hand plays it)."""
        if state == PEDAL_STATE:
            return self.feet
        return self.hands or self.feet

    def surface(self, state=None):
        """The c and h (m) a stick meets on it: in ``state`` (a hi-hat's, of :data:`HAND_STATES` its keys name),
        or with None its own ``cor`` and ``height``."""
        if not self.hands:
            raise ParameterError(f"pieces.{self.name} is played by {', '.join(self.limbs)}, not by a stick")
        if state is None:
            return Surface(self.cor, self.height)
        if state not in self.surfaces:
            raise ParameterError(f"state must be None or one of the states a hand plays on pieces.{self.name} "
                                 f"({', '.join(self.surfaces) or 'none: it has no states'}), got {shown(state)}")
        return self.surfaces[state]

    def stick(self, base, state=None):
        """The Stick ``base`` (a :class:`~drumstroke.model.Stick`) with its fulcrum h above this piece (in ``state``)."""
        return replace(base, pivot_height=self.surface(state).height)

    def setup(self, base, state=None):
        """The :class:`~drumstroke.design.Setup` for playing this piece: ``base`` with its stick's fulcrum h
        above it (so ``setup.head`` = −asin(h/x)), c its own, and the joint's lowest angle at its surface.

        Parameters
        ----------
        base : Setup
            The setup the kit's sticks are played with (its model, forces, limits, moves, and the stick
            whose fulcrum-to-tip x the kit was checked with).
        state : str or None
            The hi-hat's state the note is played in (of :data:`HAND_STATES` its keys name): its own c and h
            (:attr:`surfaces`); None, or a piece without states: the piece's.
        """
        if not isinstance(base, Setup):
            raise ParameterError(f"base must be a drumstroke.design.Setup, got {shown(base)}")
        surface = self.surface(state)
        stick = replace(base.stick, pivot_height=surface.height)
        # the joint's range starts at the surface: the head the stick meets is this piece's, not the base's
        limits = replace(base.limits, theta_low=stick.theta_max)
        return base.replace(stick=stick, cor=surface.cor, limits=limits)

    def to_dict(self):
        """The piece as a TOML table (a dict), keys as :func:`read_kit` reads them (the name is the table's)."""
        table = {"kind": self.kind, "role": self.role}
        if not self.states:
            table["keys"] = list(self.keys)
        table["limbs"] = list(self.limbs)
        if self.hands:
            table["place"] = dict(self.place)
            table["height"] = self.height
        if self.pedal is not None:
            table["pedal"] = self.pedal
        table["cor"] = self.cor
        if self.states:
            table["states"] = {state: self._state_table(state) for state in dict.fromkeys(self.states[k] for k in self.keys)}
        return table

    def _state_table(self, state):
        """One hi-hat state's table: its keys, and its c and h where they are not the piece's."""
        keys = [key for key in self.keys if self.states[key] == state]
        table = {"keys": keys[0] if len(keys) == 1 else keys}
        surface = self.surfaces.get(state)
        if surface is not None:
            table |= {name: value for name, value, own in zip(Surface._fields, surface, (self.cor, self.height))
                      if value != own}
        return table


@dataclass(frozen=True)
class Kit:
    """A drum kit: its pieces and the limbs that play them.

    Parameters
    ----------
    pieces : tuple of Piece
        At least one; names unique, every key on one piece only.
    limbs : dict of str to dict of str to Limits
        Each limb (of :data:`LIMBS`) and its positioning joints' limits: range (rad), speed (rad/s),
        acceleration (rad/s²), jerk (rad/s³). The hands have the same joints, ``yaw`` among them; the
        feet have none (each stays on its pedal).
    stick : Stick
        The stick the hands hold; its fulcrum to tip x bounds every piece's h (its own h is each piece's).
    place_tolerance : float in [0, 0.5]
        rad: two pieces one hand plays closer than this in every joint are in one place (refused).
    """

    pieces: tuple
    limbs: dict
    stick: Stick = field(default_factory=Stick)
    place_tolerance: float = PLACE_TOLERANCE

    def __post_init__(self):
        if not isinstance(self.stick, Stick):
            raise ParameterError(f"stick must be a drumstroke.Stick, got {shown(self.stick)}")
        tolerance = check_real("place_tolerance", self.place_tolerance, low=0.0, high=0.5, unit="rad")
        object.__setattr__(self, "place_tolerance", tolerance)
        object.__setattr__(self, "limbs", _kit_limbs(self.limbs))
        pieces = tuple(self.pieces) if isinstance(self.pieces, (list, tuple)) else None
        if not pieces:
            raise ParameterError(f"pieces must be a non-empty sequence of Piece, got {shown(self.pieces)}")
        for i, piece in enumerate(pieces):
            if not isinstance(piece, Piece):
                raise ParameterError(f"pieces[{i}] must be a drumstroke.kit.pieces.Piece, got {shown(piece)}")
        object.__setattr__(self, "pieces", pieces)
        self._check_names_and_keys()
        for piece in pieces:
            self._check_piece(piece)
        self._check_places()

    def _check_names_and_keys(self):
        owner = {}
        names = set()
        for piece in self.pieces:
            if piece.name in names:
                raise ParameterError(f"pieces.{piece.name} appears twice in the kit")
            names.add(piece.name)
            for key in piece.keys:
                if key in owner:
                    raise ParameterError(f"pieces.{piece.name}.keys: key {key} is also pieces.{owner[key]}'s; "
                                         "a key is played on one piece")
                owner[key] = piece.name
        object.__setattr__(self, "_by_key", owner)
        object.__setattr__(self, "_by_name", {piece.name: piece for piece in self.pieces})

    def _check_piece(self, piece):
        at = f"pieces.{piece.name}"
        for limb in piece.limbs:
            if limb not in self.limbs:
                raise ParameterError(f"{at}.limbs names {limb!r}, not a limb of the kit ({', '.join(self.limbs)})")
        if not piece.hands:
            return
        x = self.stick.pivot_to_tip
        heights = {f"{at}.height": piece.height} | {f"{at}.states.{state}.height": surface.height
                                                    for state, surface in piece.surfaces.items()}
        for name, height in heights.items():
            if height >= x:
                raise ParameterError(f"{name} must be in (0, {x:g}) m, below the stick's fulcrum to tip x so "
                                     f"the tip reaches it (θ_max = -asin(h/x)), got {height!r}")
        joints = self.limbs[piece.hands[0]]
        for joint in joints:
            if joint not in piece.place:
                raise ParameterError(f"{at}.place.{joint} is missing: the hands' {joint} angle (rad) over it")
        for joint in piece.place:
            if joint not in joints:
                raise ParameterError(f"{at}.place.{joint}: the hands have no joint {joint!r} (they have "
                                     f"{', '.join(joints)})")
        for hand in piece.hands:
            for joint, limits in self.limbs[hand].items():
                angle = piece.place[joint]
                if not limits.theta_low <= angle <= limits.theta_high:
                    raise ParameterError(
                        f"{at}.place.{joint} = {angle:g} rad is out of the {hand} hand's reach: its {joint} joint "
                        f"moves in [{limits.theta_low:g}, {limits.theta_high:g}] rad")

    def _check_places(self):
        seen = {}
        for piece in self.pieces:
            for hand in piece.hands:
                for other in seen.get(hand, ()):
                    if all(abs(piece.place[j] - other.place[j]) <= self.place_tolerance for j in piece.place):
                        raise ParameterError(
                            f"pieces.{piece.name}.place is pieces.{other.name}'s place for the {hand} hand (every "
                            f"joint within {self.place_tolerance:g} rad): two pieces cannot be in one place")
                seen.setdefault(hand, []).append(piece)
            for foot in piece.feet:
                for other in seen.get(foot, ()):
                    if other.pedal == piece.pedal:
                        raise ParameterError(f"pieces.{piece.name}.pedal {piece.pedal!r} is also "
                                             f"pieces.{other.name}'s for the {foot}: two pieces cannot be one pedal")
                seen.setdefault(foot, []).append(piece)

    @property
    def hands(self):
        """The kit's hands (of :data:`HANDS`), in that order."""
        return tuple(limb for limb in HANDS if limb in self.limbs)

    @property
    def feet(self):
        """The kit's feet (of :data:`FEET`), in that order."""
        return tuple(limb for limb in FEET if limb in self.limbs)

    @property
    def keys(self):
        """Every key the kit answers, ascending."""
        return tuple(sorted(self._by_key))

    def piece(self, name):
        """The piece called ``name``."""
        try:
            return self._by_name[name]
        except (KeyError, TypeError):
            raise ParameterError(f"piece must be one of the kit's pieces ({', '.join(self._by_name)}), "
                                 f"got {shown(name)}") from None

    def piece_for_key(self, key):
        """The piece that answers MIDI key ``key`` and what the key means on it, as (Piece, state), or None.

        The state is the hi-hat's (:data:`HIHAT_STATES`), None on any other piece; a key the kit does
        not answer gives None, for the caller to report.
        """
        name = self._by_key.get(key) if isinstance(key, int) and not isinstance(key, bool) else None
        if name is None:
            return None
        piece = self._by_name[name]
        return piece, piece.state(key)

    def to_dict(self):
        """The kit as TOML data, as :func:`read_kit` reads it."""
        return {
            "stick": {k: v for k, v in self.stick.to_dict().items() if k != "pivot_height"},
            "place_tolerance": self.place_tolerance,
            "limbs": {limb: {"joints": {name: limits.to_dict() for name, limits in joints.items()}}
                      for limb, joints in self.limbs.items()},
            "pieces": {piece.name: piece.to_dict() for piece in self.pieces},
        }

    @classmethod
    def from_dict(cls, data):
        """A kit from TOML data (a dict) as :func:`read_kit` reads a file."""
        if not isinstance(data, dict):
            raise ParameterError(f"a kit must be a table, got {shown(data)}")
        check_keys("kit", data, _KIT_KEYS)
        for name in ("limbs", "pieces"):
            if not isinstance(data.get(name), dict) or not data[name]:
                raise ParameterError(f"{name} is missing: a kit needs a [{name}.NAME] table for each of its {name}")
        limbs = {}
        for limb, table in data["limbs"].items():
            if not isinstance(table, dict):
                raise ParameterError(f"limbs.{limb} must be a table, got {shown(table)}")
            check_keys(f"limbs.{limb}", table, _LIMB_KEYS)
            joints = table.get("joints", {})
            if not isinstance(joints, dict):
                raise ParameterError(f"limbs.{limb}.joints must be a table of joint tables, got {shown(joints)}")
            limbs[limb] = {joint: _joint_limits(f"limbs.{limb}.joints.{joint}", limits)
                           for joint, limits in joints.items()}
        pieces = tuple(_piece_from(name, table) for name, table in data["pieces"].items())
        stick = data.get("stick", {})
        if not isinstance(stick, dict):
            raise ParameterError(f"stick must be a table, got {shown(stick)}")
        check_keys("stick", stick, [k for k in Stick().to_dict() if k != "pivot_height"])
        # the fulcrum's height is each piece's; the stick's own is any valid one, below its tip
        tip = check_real("stick.pivot_to_tip", stick.get("pivot_to_tip", Stick().pivot_to_tip), low=0.0,
                         high=10.0, low_open=True, unit="m")
        stick = Stick(**stick, pivot_height=min(Stick().pivot_height, 0.5 * tip))
        return cls(pieces, limbs, stick=stick, place_tolerance=data.get("place_tolerance", PLACE_TOLERANCE))


def read_kit(path):
    """The kit in the TOML file at ``path`` (:meth:`Kit.from_dict`'s tables); an error names the file,
    the piece (or limb) and the field."""
    with reading_toml(path, "kit") as data:
        return Kit.from_dict(data)


def write_kit(path, kit):
    """Write ``kit`` to ``path`` as TOML (:func:`read_kit` reads it back to an equal kit)."""
    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    write_toml(path, kit.to_dict())


def default_kit():
    """The shipped kit, :data:`DEFAULT_KIT`: snare, kick, hi-hat with its pedal, two rack toms and a floor
    tom, ride (and its bell), crash, for a right-handed drummer."""
    return read_kit(DEFAULT_KIT)


def _piece_from(name, table):
    if not isinstance(table, dict):
        raise ParameterError(f"pieces.{name} must be a table, got {shown(table)}")
    at = f"pieces.{name}"
    check_keys(at, table, _PIECE_KEYS)
    if "states" in table and "keys" in table:
        raise ParameterError(f"{at}.keys: a hi-hat with [{at}.states.STATE] tables gives its keys there "
                             f"(keys = 42 under [{at}.states.closed]), not both")
    for required in ("kind", "keys" if "states" not in table else "states", "limbs", "cor"):
        if required not in table:
            raise ParameterError(f"{at}.{required} is missing")
    if "states" in table:
        keys, states, surfaces = _states_from(f"{at}.states", table["states"])
    else:
        (keys, states), surfaces = _keys_and_states(f"{at}.keys", table["keys"]), {}
    return Piece(name=name, kind=table["kind"], keys=keys, limbs=table["limbs"], cor=table["cor"],
                 height=table.get("height"), place=table.get("place", {}), pedal=table.get("pedal"),
                 states=states, role=table.get("role"), surfaces=surfaces)


def _keys_and_states(at, spec):
    """A piece's keys (a list, or the older form of a hi-hat's: a table of state to key or keys) as (keys, states)."""
    if not isinstance(spec, dict):
        return spec, {}
    pairs = []
    for state, value in spec.items():
        check_choice(f"{at}.{state}", state, HIHAT_STATES)
        pairs += [(key, state) for key in (value if isinstance(value, list) else [value])]
    keys = _keys(at, [key for key, _ in pairs])  # checked before they key a table
    return keys, dict(pairs)


def _states_from(at, spec):
    """A hi-hat's ``[states.STATE]`` tables (each its keys, and a hand state's own c and h) as (keys, states,
    surfaces)."""
    if not isinstance(spec, dict) or not spec:
        raise ParameterError(f"{at} must be a table of the hi-hat's states ({', '.join(HIHAT_STATES)}), each a "
                             f"table with its keys, got {shown(spec)}")
    keys, states, surfaces = [], {}, {}
    for state, table in spec.items():
        check_choice(at, state, HIHAT_STATES)
        where = f"{at}.{state}"
        if not isinstance(table, dict):
            raise ParameterError(f"{where} must be a table (its keys; a hand's state its cor and height), "
                                 f"got {shown(table)}")
        if state == PEDAL_STATE and set(table) & {"cor", "height"}:
            raise ParameterError(f"{where}.{min(set(table) & {'cor', 'height'})}: the pedal state is the foot's, "
                                 "not a stick's: only a hand's states have a c and h")
        check_keys(where, table, _STATE_KEYS)
        if "keys" not in table:
            raise ParameterError(f"{where}.keys is missing: the MIDI keys that play it in this state")
        value = table["keys"]
        mine = _keys(f"{where}.keys", value if isinstance(value, list) else [value])
        keys += mine
        states |= dict.fromkeys(mine, state)
        if state != PEDAL_STATE:
            surfaces[state] = Surface(table.get("cor"), table.get("height"))
    return _keys(at, keys), states, surfaces


def _keys(at, keys):
    if isinstance(keys, (str, bytes)) or not isinstance(keys, (list, tuple)) or not keys:
        raise ParameterError(f"{at} must be a non-empty list of MIDI keys (integers in [0, 127]), got {shown(keys)}")
    for key in keys:
        if isinstance(key, bool) or not isinstance(key, int) or not 0 <= key <= 127:
            raise ParameterError(f"{at} must be MIDI keys, integers in [0, 127], got {shown(key)}")
    if len(set(keys)) != len(keys):
        raise ParameterError(f"{at} names a key twice: {list(keys)}")
    return tuple(keys)


def _limbs(at, limbs):
    if isinstance(limbs, (str, bytes)) or not isinstance(limbs, (list, tuple)) or not limbs:
        raise ParameterError(f"{at} must be a non-empty list of limbs ({', '.join(LIMBS)}), got {shown(limbs)}")
    for limb in limbs:
        check_choice(at, limb, LIMBS)
    if len(set(limbs)) != len(limbs):
        raise ParameterError(f"{at} names a limb twice: {list(limbs)}")
    return tuple(limbs)


def _kit_limbs(limbs):
    if not isinstance(limbs, dict) or not limbs:
        raise ParameterError(f"limbs must be a table of limb to joints, got {shown(limbs)}")
    checked = {}
    for limb, joints in limbs.items():
        check_choice("limbs", limb, LIMBS)
        if not isinstance(joints, dict):
            raise ParameterError(f"limbs.{limb}.joints must be a table of joint to Limits, got {shown(joints)}")
        for joint, limits in joints.items():
            if not isinstance(joint, str) or not _NAME.match(joint):
                raise ParameterError(f"limbs.{limb}.joints: a joint's name must be 1-32 of a-z, 0-9, '_', '-', "
                                     f"got {shown(joint)}")
            if not isinstance(limits, Limits):
                raise ParameterError(f"limbs.{limb}.joints.{joint} must be a drumstroke.palette.motion.Limits, "
                                     f"got {shown(limits)}")
        if limb in FEET and joints:
            raise ParameterError(f"limbs.{limb}.joints must be empty: a foot stays on its pedal")
        if limb in HANDS and YAW not in joints:
            raise ParameterError(f"limbs.{limb}.joints.{YAW} is missing: every hand turns about the vertical")
        checked[limb] = dict(joints)
    hands = [limb for limb in HANDS if limb in checked]
    if len(hands) == 2 and set(checked[hands[0]]) != set(checked[hands[1]]):
        raise ParameterError(f"limbs.left.joints must name the right hand's joints ({', '.join(checked['right'])}): "
                             f"a piece's place is one angle per joint, got {', '.join(checked['left'])}")
    return checked


def _joint_limits(at, table):
    if not isinstance(table, dict):
        raise ParameterError(f"{at} must be a table of limits, got {shown(table)}")
    try:
        return Limits.from_dict(table)
    except ParameterError as error:  # Limits names itself "limits": the reader names the joint
        raise ParameterError(str(error).replace("limits", at, 1)) from None
