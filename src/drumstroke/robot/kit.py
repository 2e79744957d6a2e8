"""The robot plays the whole kit: two arms and two pedals tracking a :class:`~drumstroke.compose.KitComposition`.

The robot
---------
Each hand is an arm, a chain of hinges: ``yaw`` about the vertical through the drummer's body (at
the shoulder), ``lift`` raising the arm about a horizontal axis there, then at the arm's end, the
fulcrum, the stick's motor ``theta``, the paper's joint (:class:`ArmPlant`; the stick is the kit's
``[stick]``). θ is the stick's angle to the horizontal, as the composition gives it: the motor turns
the stick against the arm, so the arm's lift adds to it, and θ is read as lift + the motor's angle
(the sum of the two encoders). Each foot works its pedal: the beater a hinge at the pedal's axle
(θ = −φ, :mod:`drumstroke.kit.pedal`), with the pedal's inertia, gravity torque and spring, and a
motor on the axle standing for the foot. Joint ranges are the kit's limits; a positioning motor's
rotor, N²·J_rotor, is its joint's armature as the stick's motor's is the single joint's.

Every piece a hand plays is a thin square pad where the stick's tip meets it at that piece's
θ_max = −asin(h/x) when the arm is at its place; a pedal's head a vertical pad where the beater's
head meets it at φ_head. Only a tip and a pad collide, a beater and its pedal's pad, and a hand's
pad only with the tips of the hands at its place (within :data:`AT_PLACE`): the kit places its
pieces in each hand's joints (a place and a height under the fulcrum there), not as solids in space,
and a pad met from elsewhere would be an artefact of the arm's dimensions. Each pad's contact is the
single joint's head (:func:`drumstroke.robot.mujoco_plant.contact_solref`: the stick on that piece
with its c; a beater as a hinge of its inertia and lever, with the pedal's c, the restitution of the
pedal's model's impact), carried over to the kit's model so that it presses with the same force at
the same penetration and speed: MuJoCo weighs a contact's stiffness by its own estimate of the
contact's inverse inertia (the bodies' ``invweight0``), which a stick at the end of an arm does not
share with the single joint. The arm gives a little under a strike: a stick rebounds about 1 % below
its piece's c (:func:`kit_drop_test`).

Playing
-------
:func:`track_kit` steps one control loop over every joint at the composition's rate, as
:class:`~drumstroke.robot.loop.ControlLoop` steps one joint: each joint's encoder read, its speed
estimated, its own law (:mod:`drumstroke.robot.controllers`), its motor's torque–speed line. A
positioning joint's or a beater's law is the sticks' with its gains scaled by its inertia over a
stick's (:func:`scaled_law`), a beater's fed forward its spring and gravity besides. A stick's law
is the one for the piece its reference is at or nearest to (its head: the impedance controller's
soft band is near it), and the law steers by the hand's θ with its impacts (each held at its own
piece's head by the impedance controller's lead). ``engine="mujoco"`` steps the kit's model
(:func:`kit_model`). ``engine="simple"`` gives every joint its own
:class:`~drumstroke.robot.plant.SimpleJoint`, uncoupled: a stick's joint has the head of the piece
its arm is at (within :data:`AT_PLACE`), none while it moves; a positioning joint is the simple
plant's equation with its own inertia and gravity torque (the arm as a rod, the rest in its rotor)
and no head; a beater's has its pedal's spring and gravity added to its motor's torque each period.
What was played: every joint's angle, and the onsets, a tip or a beater coming into contact with a
pad (MuJoCo) or a stick's joint with its piece's head (simple), each on its piece.

:func:`kit_scores` scores the onsets per piece against the notes the reference played
(:func:`score_onsets`).

Examples
--------
>>> from drumstroke.compose import compose_kit
>>> from drumstroke.score import parse_pattern
>>> piece = compose_kit(parse_pattern("tempo 120\\n0 auto 100 auto kick\\n1 auto 90 auto hihat\\n"))
>>> played = track_kit(piece, engine="simple")
>>> scores = kit_scores(played)
>>> [(s.piece, s.matched, s.notes) for s in scores.pieces], scores.fraction
([('kick', 1, 1), ('hihat', 1, 1)], 1.0)
"""

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from .._checks import check_int, check_real, shown
from ..errors import ParameterError
from ..kit.pieces import FEET, HANDS
from ..kit.play import THETA, kit_pedals
from ..model import Stick
from ..trajectory import DEFAULT_RATE, Impacts, Trajectory
from . import ENGINES
from .controllers import CONTROLLERS, Controller
from .controllers import controller as named_controller
from .kernel import estimate_speed, limit_torque, quantize
from .metrics import AUDIBLE_SPEED, WINDOW, OnsetScores, match_onsets, pool
from .plant import GRAVITY, Plant, SimpleJoint, contact_gains
from .track import check_tracking

AT_PLACE = 5e-3
"""rad: an arm is at a piece's place when every positioning joint is this near it (half the kit's default
``place_tolerance``: two places a hand plays are farther apart than that in some joint)."""

PAD_SIZE = 0.025
"""m: half the side of a piece's pad (the tip tracks its place within a millimetre)."""

PAD_THICKNESS = 0.005
"""m: half a pad's thickness."""

KIT_SUBSTEPS = 10
"""Integration steps per control period on the kit by default: 100 µs at 1 kHz, a 3.5 ms contact in 35 RK4 steps
(each pad calibrated at that step); the single joint's 40 would take four times as long."""

ARM_JOINTS = ("yaw", "lift")
"""The positioning joints an arm has, in the chain's order from the shoulder: a kit's hands have these or the yaw."""

FOOT_PLACES = {"right-foot": (0.35, -0.15), "left-foot": (0.35, 0.25)}
"""m: where each foot's pedal axle stands on the floor, (ahead, to the left) of the body's axis."""


@dataclass(frozen=True)
class ArmPlant:
    """A hand's arm: from the shoulder (the yaw and lift axes) to the stick's fulcrum, and its positioning motors.

    Parameters
    ----------
    reach : float in (0, 2]
        R, m: shoulder to fulcrum (the hand about 0.45 m from the body's axis).
    shoulder_height : float in (0, 3]
        m above the floor.
    mass : float in (0, 20]
        kg: the arm, with the stick's motor, a uniform rod from the shoulder to the fulcrum.
    gear_ratio : float in [1, 1000]
        Of both positioning motors.
    rotor_inertia : float in [0, 1e-2]
        kg·m², motor side (each positioning motor's reflected inertia N²·J_rotor dominates its joint's).
    max_torque : float in (0, 100]
        N·m at the joint: stall torque.
    max_speed : float in (0, 1000]
        rad/s at the joint: no-load speed.
    viscous : float in [0, 100]
        N·m·s/rad.
    encoder_counts : int in [16, 2**24]
        Counts per motor revolution.
    """

    reach: float = 0.45
    shoulder_height: float = 1.0
    mass: float = 0.5
    gear_ratio: float = 100.0
    rotor_inertia: float = 2e-5
    max_torque: float = 100.0
    max_speed: float = 30.0
    viscous: float = 0.0
    encoder_counts: int = 8192

    def __post_init__(self):
        check_real("arm.reach", self.reach, low=0.0, high=2.0, low_open=True, unit="m")
        check_real("arm.shoulder_height", self.shoulder_height, low=0.0, high=3.0, low_open=True, unit="m")
        check_real("arm.mass", self.mass, low=0.0, high=20.0, low_open=True, unit="kg")
        check_real("arm.gear_ratio", self.gear_ratio, low=1.0, high=1000.0)
        check_real("arm.rotor_inertia", self.rotor_inertia, low=0.0, high=1e-2, unit="kg m^2")
        check_real("arm.max_torque", self.max_torque, low=0.0, high=100.0, low_open=True, unit="N m")
        check_real("arm.max_speed", self.max_speed, low=0.0, high=1000.0, low_open=True, unit="rad/s")
        check_real("arm.viscous", self.viscous, low=0.0, high=100.0, unit="N m s/rad")
        check_int("arm.encoder_counts", self.encoder_counts, low=16, high=2**24)

    @property
    def armature(self):
        """N²·J_rotor, a positioning motor's inertia at its joint (kg·m²)."""
        return self.gear_ratio**2 * self.rotor_inertia


class LawPlant(NamedTuple):
    """A joint as a control law reads it (:meth:`~drumstroke.robot.controllers.Controller.law`): J (kg·m²),
    m·g·k (N·m, the gravity torque at 0 rad), the head (rad; −inf: none), τ_max (N·m), the encoder's step (rad)."""

    inertia: float
    gravity_torque: float
    head: float
    max_torque: float
    resolution: float


@dataclass(frozen=True, repr=False)
class KitRobot:
    """The robot that plays a kit: its joints, each piece's pad, the laws' view of each joint.

    Made by :func:`kit_robot`. Joints are named as the composition's columns (``right.yaw``,
    ``left.theta``, ``right-foot.theta``...), limbs in the kit's order.

    Attributes
    ----------
    kit : Kit
    plant : Plant
        The sticks' joint (motor, gearbox, friction, contact time, substeps); its stick the kit's.
    arm : ArmPlant
    pedals : dict of str to Pedal
        Each pedal by name.
    rate : float
        The control rate (Hz).
    joints : tuple of str
        Every joint.
    sticks : dict of str to dict of str to Plant
        Each hand's stick joint on each piece it may play (its stick's fulcrum h above it).
    surfaces : dict of str to Surface
        Each surface a limb strikes: a hand's piece's (named as the piece), a pedal's head (named as its foot).
    """

    kit: object
    plant: Plant
    arm: ArmPlant
    pedals: dict
    rate: float
    joints: tuple
    sticks: dict
    surfaces: dict

    def __repr__(self):
        return f"KitRobot({len(self.joints)} joints, {len(self.surfaces)} surfaces at {self.rate:g} Hz)"

    def limb_of(self, joint):
        """The limb a joint belongs to."""
        return joint.rsplit(".", 1)[0]

    def pedal_piece(self, foot):
        """The piece ``foot``'s pedal plays (the kick, the hi-hat's pedal), or None."""
        return next((p.name for p in self.kit.pieces if foot in p.feet), None)

    def pedal_of(self, foot):
        """The :class:`~drumstroke.kit.pedal.Pedal` ``foot`` works."""
        return self.pedals[self.kit.piece(self.pedal_piece(foot)).pedal]

    def place(self, piece):
        """The positioning joints' angles (rad) at ``piece``'s place, in the hands' joint order."""
        hand = self.kit.hands[0]
        return np.array([self.kit.piece(piece).place[j] for j in self.kit.limbs[hand]])

    def law_plants(self):
        """Each joint's :class:`LawPlant` (a stick's joint: one per piece it may play, by piece; else one)."""
        plants = {}
        for joint in self.joints:
            limb, name = self.limb_of(joint), joint.rsplit(".", 1)[1]
            if limb in HANDS and name == THETA:
                plants[joint] = {piece: LawPlant(p.inertia, p.gravity_torque, p.head, p.max_torque, p.resolution)
                                 for piece, p in self.sticks[limb].items()}
            elif limb in HANDS:
                inertia, gravity = arm_inertia(self.arm, self.kit.stick, name)
                plants[joint] = LawPlant(inertia, gravity, -math.inf, self.arm.max_torque, self._arm_resolution)
            else:
                pedal = self.pedal_of(limb)
                plants[joint] = LawPlant(pedal.inertia, 0.0, -pedal.phi_head, _foot_torque(pedal),
                                         self.plant.resolution)
        return plants

    @property
    def _arm_resolution(self):
        return 2.0 * math.pi / (self.arm.encoder_counts * self.arm.gear_ratio)


def kit_robot(kit, *, plant=None, arm=None, pedals=None, rate=DEFAULT_RATE):
    """The :class:`KitRobot` for ``kit``.

    Parameters
    ----------
    kit : Kit
    plant : Plant, optional
        The sticks' joint; its stick is replaced by the kit's. Default ``Plant(substeps=KIT_SUBSTEPS)``.
    arm : ArmPlant, optional
        Default ``ArmPlant()``.
    pedals : dict of str to Pedal, optional
        As :func:`~drumstroke.kit.play.play_kit` takes them; default ``Pedal()`` for each.
    rate : float in [10, 1e5]
        The control rate (Hz).
    """
    from ..kit.pieces import Kit

    if not isinstance(kit, Kit):
        raise ParameterError(f"kit must be a drumstroke.kit.pieces.Kit, got {shown(kit)}")
    plant = Plant(substeps=KIT_SUBSTEPS) if plant is None else plant
    if not isinstance(plant, Plant):
        raise ParameterError(f"plant must be a drumstroke.robot.plant.Plant, got {shown(plant)}")
    arm = ArmPlant() if arm is None else arm
    if not isinstance(arm, ArmPlant):
        raise ParameterError(f"arm must be a drumstroke.robot.kit.ArmPlant, got {shown(arm)}")
    rate = check_real("rate", rate, low=10.0, high=1e5, unit="Hz")
    pedals = kit_pedals(pedals, kit)
    for hand in kit.hands:
        extra = [joint for joint in kit.limbs[hand] if joint not in ARM_JOINTS]
        if extra:
            raise ParameterError(f"limbs.{hand}.joints: the robot's arm has the joints {', '.join(ARM_JOINTS)}, not "
                                 f"{', '.join(map(repr, extra))}", parameter=f"limbs.{hand}.joints", value=extra[0],
                                 allowed=", ".join(ARM_JOINTS))
    plant = replace(plant, stick=kit.stick)
    joints = tuple(f"{hand}.{j}" for hand in kit.hands for j in (*kit.limbs[hand], THETA))
    feet = tuple(foot for foot in kit.feet if any(foot in p.feet for p in kit.pieces))
    joints += tuple(f"{foot}.{THETA}" for foot in feet)
    sticks = {hand: {p.name: replace(plant, stick=p.stick(kit.stick)) for p in kit.pieces if hand in p.hands}
              for hand in kit.hands}
    surfaces = {p.name: Surface(p.name, p.cor, None) for p in kit.pieces if p.hands}
    for foot in feet:
        piece = next(p for p in kit.pieces if foot in p.feet)
        surfaces[foot] = Surface(piece.name, pedals[piece.pedal].cor, foot)
    return KitRobot(kit, plant, arm, pedals, rate, joints, sticks, surfaces)


class Surface(NamedTuple):
    """A surface a limb strikes: the piece it sounds as, its c, and the foot whose pedal's head it is (None: a pad
    the sticks strike)."""

    piece: str
    cor: float
    foot: str | None


def arm_inertia(arm, stick, joint):
    """A positioning joint's inertia (kg·m²) and gravity torque m·g·k (N·m) with the arm level, the stick level.

    Yaw: the motor's N²·J_rotor, the arm (m·R²/3) and the stick about the vertical (its mass at
    R + k, its own inertia across it); no gravity. Lift: the same about the shoulder's horizontal axis, and
    the gravity of the arm's centre (R/2) and the stick's (R + k).
    """
    from ..model import inertia_ratio

    reach, m = arm.reach, stick.mass
    k = stick.pivot_to_com
    own = m * (inertia_ratio("geometry", stick) - k**2)  # the stick about its centre, across it
    inertia = arm.armature + arm.mass * reach**2 / 3.0 + m * (reach + k) ** 2 + own
    gravity = 0.0 if joint == "yaw" else GRAVITY * (arm.mass * reach / 2.0 + m * (reach + k))
    return inertia, gravity


def _foot_torque(pedal):
    """The beater's motor's stall torque (N·m): the foot's strongest press through the linkage, and the spring's
    and gravity's pull at rest held besides."""
    return pedal.arm * pedal.max_force + pedal.spring * (pedal.phi_head - pedal.phi_rest) + pedal.gravity


def _beater_mass(pedal):
    """The beater's mass (kg) and centre's distance from the axle (m): any pair with the pedal's inertia about the
    axle and gravity torque, within a rod of its length (so the single joint's model of it is sound)."""
    length, inertia, weight = pedal.length, pedal.inertia, pedal.gravity / GRAVITY
    low, high = math.sqrt(3.0) * weight / length, 3.0 * inertia / length**2
    if not low < high:
        raise ParameterError(f"pedal gravity {pedal.gravity!r} N m is too much for its inertia {inertia!r} kg m^2 "
                             f"and length {length!r} m: its centre would lie beyond a rod's (the model needs "
                             f"gravity < {high * GRAVITY * length / math.sqrt(3.0):.4g} N m)")
    mass = 0.5 * (low + high)
    return mass, weight / mass


BEATER_TILT = 0.1
"""rad: the angle from the head the single joint standing for a beater is calibrated at (a stick's head must be
below its fulcrum); its lever then is the beater's times cos 0.1, 0.5 % short."""


def beater_plant(pedal, plant):
    """The beater as the single joint sees it, for calibrating its head: a rod of the pedal's length and inertia
    (the rest of it in the rotor), its head ``BEATER_TILT`` below level, next to no gravity (the pedal's model's
    impact is the head's restitution alone); ``plant``'s contact time and substeps."""
    length = pedal.length
    mass = 1.5 * pedal.inertia / length**2  # the rod holds half the inertia
    stick = Stick(length=length, pivot_to_tip=length, pivot_to_com=1e-3 * length, pivot_to_thumb=0.0,
                  pivot_height=length * math.sin(BEATER_TILT), mass=mass)
    return replace(plant, stick=stick, gear_ratio=1.0, rotor_inertia=pedal.inertia / 2.0, viscous=0.0, coulomb=0.0,
                   max_torque=_foot_torque(pedal), max_speed=1000.0)


# --- MuJoCo ---------------------------------------------------------------------------------------------------------


def kit_model(robot):
    """The robot as a compiled MuJoCo model, each pad's contact calibrated (see the module's docstring).

    Returns
    -------
    mujoco.MjModel
        Joints and motors named as :attr:`KitRobot.joints` (a stick's motor turns it against its arm), geoms
        ``pad:PIECE`` and ``tip:LIMB`` (a beater's head too).
    """
    import mujoco

    model = mujoco.MjModel.from_xml_string(_mjcf(robot, {name: (-1.0, -1.0) for name in robot.surfaces}))
    for name, solref in _calibrated(robot, model).items():
        model.geom_solref[model.geom(f"pad:{name}").id] = solref
    return model


def _calibrated(robot, model):
    """Each pad's solref: the single joint's for that piece (or the beater), scaled to the kit model's weighing."""
    from .mujoco_plant import IMPEDANCE, contact_solref, mujoco_model

    d = IMPEDANCE
    solrefs = {}
    for name, surface in robot.surfaces.items():
        limb, single = _calibration_plant(robot, name)
        cor = surface.cor
        own = mujoco_model(single, cor, rate=robot.rate)
        estimate = float(own.body_invweight0[own.body("stick").id, 0])
        lever = single.stick.pivot_to_tip * math.cos(single.head)
        reach = lever**2 / single.inertia
        kit_estimate = float(model.body_invweight0[model.body(f"{limb}.stick").id, 0])
        kit_reach = _contact_inverse_inertia(robot, model, limb, surface.piece)
        scale = ((1.0 - d) * kit_estimate + d * kit_reach) / ((1.0 - d) * estimate + d * reach)
        stiffness, damping = contact_solref(single, cor, rate=robot.rate)
        solrefs[name] = (stiffness * scale, damping * scale)
    return solrefs


def _calibration_plant(robot, name):
    """(the limb whose body strikes the surface ``name`` in the calibration, the single joint standing for it)."""
    surface = robot.surfaces[name]
    if surface.foot is not None:
        return surface.foot, beater_plant(robot.pedal_of(surface.foot), robot.plant)
    hand = robot.kit.piece(surface.piece).hands[0]
    return hand, robot.sticks[hand][surface.piece]


def _contact_inverse_inertia(robot, model, limb, piece):
    """The kit model's inverse inertia along the pad's normal at the contact point (1/kg), the limb on the pad."""
    import mujoco

    data = mujoco.MjData(model)
    _pose(robot, model, data, limb, piece)
    mujoco.mj_forward(model, data)
    tip = model.geom(f"tip:{limb}").id
    jac = np.zeros((3, model.nv))
    mujoco.mj_jacGeom(model, data, jac, None, tip)
    normal = np.array([0.0, 0.0, 1.0]) if limb in HANDS else np.array([1.0, 0.0, 0.0])
    row = normal @ jac
    solved = np.zeros(model.nv)
    mujoco.mj_solveM(model, data, solved.reshape(1, -1), row.reshape(1, -1))
    return float(row @ solved)


def _pose(robot, model, data, limb, piece):
    """Put ``limb`` on ``piece``: a hand's joints at its place, its stick at θ_max; a beater at φ_head."""
    if limb in HANDS:
        place = robot.kit.piece(piece).place
        for joint in robot.kit.limbs[limb]:
            data.qpos[model.joint(f"{limb}.{joint}").qposadr[0]] = place[joint]
        lift = place.get("lift", 0.0)
        data.qpos[model.joint(f"{limb}.{THETA}").qposadr[0]] = robot.sticks[limb][piece].head - lift
    else:
        data.qpos[model.joint(f"{limb}.{THETA}").qposadr[0]] = -robot.pedal_of(limb).phi_head


def _mjcf(robot, solrefs):
    """The MJCF text of the robot and the kit's pads (SI units, radians)."""
    from .mujoco_plant import IMPEDANCE, TIP_RADIUS

    timestep = 1.0 / (robot.rate * robot.plant.substeps)
    d = IMPEDANCE
    solimp = f'solimp="{d!r} {d!r} 0.001 0.5 2"'
    pads, bodies = [], []
    for name, solref in solrefs.items():
        surface = robot.surfaces[name]
        if surface.foot is None:
            centre = _hand_contact(robot, name) - np.array([0.0, 0.0, TIP_RADIUS + PAD_THICKNESS])
            # every hand's bit, for MuJoCo's broadphase (it keeps each body's at compile time); while playing, the
            # bits of the hands at its place only (_MujocoKit._place_pads)
            size, affinity = f"{PAD_SIZE!r} {PAD_SIZE!r} {PAD_THICKNESS!r}", sum(_bit(robot, h) for h in robot.kit.hands)
            yaw = robot.kit.piece(name).place["yaw"]
        else:
            centre = _foot_contact(robot, surface.foot) + np.array([TIP_RADIUS + PAD_THICKNESS, 0.0, 0.0])
            size, affinity, yaw = f"{PAD_THICKNESS!r} {PAD_SIZE!r} {PAD_SIZE!r}", _bit(robot, surface.foot), 0.0
        pads.append(f'<geom name="pad:{name}" type="box" size="{size}" pos="{_xyz(centre)}" euler="0 0 {yaw!r}" '
                    f'condim="1" priority="1" contype="0" conaffinity="{affinity}" '
                    f'solref="{solref[0]!r} {solref[1]!r}" {solimp}/>')
    for hand in robot.kit.hands:
        bodies.append(_arm_body(robot, hand))
    for joint in robot.joints:
        limb = robot.limb_of(joint)
        if limb in FEET:
            bodies.append(_beater_body(robot, limb))
    motors = "\n    ".join(_motor(robot, joint) for joint in robot.joints)
    return f"""<mujoco model="drumstroke-kit">
  <compiler angle="radian"/>
  <option timestep="{timestep!r}" integrator="RK4" gravity="0 0 {-GRAVITY!r}"/>
  <worldbody>
    {chr(10).join(pads)}
    {chr(10).join(bodies)}
  </worldbody>
  <actuator>
    {motors}
  </actuator>
</mujoco>
"""


def _bit(robot, limb):
    """The collision bit of ``limb``'s tip (or beater): a pad collides with the limbs whose bits its conaffinity has."""
    limbs = [*robot.kit.hands, *(robot.limb_of(j) for j in robot.joints if robot.limb_of(j) in FEET)]
    return 1 << limbs.index(limb)


def _xyz(v):
    return " ".join(repr(float(x)) for x in v)


def _hand_contact(robot, piece):
    """Where the tip's centre is (m) when the arm is at ``piece``'s place and the stick at its θ_max."""
    arm, kit_piece = robot.arm, robot.kit.piece(piece)
    yaw, lift = kit_piece.place["yaw"], kit_piece.place.get("lift", 0.0)
    head = -math.asin(kit_piece.height / robot.kit.stick.pivot_to_tip)
    out = arm.reach * math.cos(lift) + robot.kit.stick.pivot_to_tip * math.cos(head)
    up = arm.shoulder_height + arm.reach * math.sin(lift) - kit_piece.height
    return np.array([out * math.cos(yaw), out * math.sin(yaw), up])


def _foot_contact(robot, foot):
    """Where the beater's head's centre is (m) at φ_head."""
    pedal = robot.pedal_of(foot)
    x, y = FOOT_PLACES[foot]
    return np.array([x + pedal.length * math.sin(pedal.phi_head), y, pedal.length * math.cos(pedal.phi_head)])


def _range(low, high):
    return f'range="{low!r} {high!r}" limited="true"'


def _arm_body(robot, hand):
    from ..model import inertia_ratio
    from .mujoco_plant import TIP_RADIUS

    plant, arm, stick = robot.plant, robot.arm, robot.kit.stick
    limits = robot.kit.limbs[hand]
    reach, mass = arm.reach, arm.mass
    across = mass * reach**2 / 12.0
    positioning = []
    for joint in (j for j in ARM_JOINTS if j in limits):  # yaw first: lift turns about the yawed arm's axis
        limit = limits[joint]
        axis = "0 0 1" if joint == "yaw" else "0 -1 0"
        positioning.append(f'<joint name="{hand}.{joint}" type="hinge" axis="{axis}" armature="{arm.armature!r}" '
                           f'damping="{arm.viscous!r}" {_range(limit.theta_low, limit.theta_high)}/>')
    lift_low = min((limits[j].theta_low for j in limits if j != "yaw"), default=0.0)
    lift_high = max((limits[j].theta_high for j in limits if j != "yaw"), default=0.0)
    theta_low = min(robot.sticks[hand][p].head for p in robot.sticks[hand]) - lift_high
    theta_high = math.pi / 2 - lift_low
    m, com, tip = stick.mass, stick.pivot_to_com, stick.pivot_to_tip
    hinge = m * inertia_ratio("geometry", stick)
    stick_across = hinge - m * com**2
    butt = stick.length - tip
    armature = plant.gear_ratio**2 * plant.rotor_inertia
    return f"""<body name="{hand}" pos="0 0 {arm.shoulder_height!r}">
      {chr(10).join(positioning)}
      <inertial pos="{reach / 2.0!r} 0 0" mass="{mass!r}" diaginertia="{1e-3 * across!r} {across!r} {across!r}"/>
      <body name="{hand}.stick" pos="{reach!r} 0 0">
        <joint name="{hand}.{THETA}" type="hinge" axis="0 -1 0" armature="{armature!r}" damping="{plant.viscous!r}"
               {_range(theta_low - 0.2, theta_high)}/>
        <inertial pos="{com!r} 0 0" mass="{m!r}" diaginertia="{1e-3 * stick_across!r} {stick_across!r} {stick_across!r}"/>
        <geom name="shaft:{hand}" type="capsule" fromto="{-butt!r} 0 0 {tip!r} 0 0" size="0.006" contype="0"
              conaffinity="0" group="1"/>
        <geom name="tip:{hand}" type="sphere" size="{TIP_RADIUS!r}" pos="{tip!r} 0 0" condim="1"
              contype="{_bit(robot, hand)}" conaffinity="0"/>
      </body>
    </body>"""


def _beater_body(robot, foot):
    from .mujoco_plant import TIP_RADIUS

    pedal = robot.pedal_of(foot)
    mass, com = _beater_mass(pedal)
    across = pedal.inertia - mass * com**2
    x, y = FOOT_PLACES[foot]
    rest = -pedal.phi_rest
    return f"""<body name="{foot}.stick" pos="{x!r} {y!r} 0">
      <joint name="{foot}.{THETA}" type="hinge" axis="0 -1 0" stiffness="{pedal.spring!r}" springref="{rest!r}"
             {_range(-pedal.phi_head - 0.2, math.pi / 2)}/>
      <inertial pos="0 0 {com!r}" mass="{mass!r}" diaginertia="{across!r} {across!r} {1e-3 * across!r}"/>
      <geom name="shaft:{foot}" type="capsule" fromto="0 0 0 0 0 {pedal.length!r}" size="0.004" contype="0"
            conaffinity="0" group="1"/>
      <geom name="tip:{foot}" type="sphere" size="{TIP_RADIUS!r}" pos="0 0 {pedal.length!r}" condim="1"
            contype="{_bit(robot, foot)}" conaffinity="0"/>
    </body>"""


def _motor(robot, joint):
    limb = robot.limb_of(joint)
    if limb in FEET:
        top = _foot_torque(robot.pedal_of(limb))
    elif joint.endswith(f".{THETA}"):
        top = robot.plant.max_torque
    else:
        top = robot.arm.max_torque
    return (f'<motor name="{joint}" joint="{joint}" gear="1" ctrllimited="true" '
            f'ctrlrange="{-top!r} {top!r}"/>')


class _MujocoKit:
    """The kit's model stepped one control period at a time; contacts of a tip (or beater) with a pad are onsets."""

    def __init__(self, robot, positions, velocities, start):
        import mujoco

        self._mujoco = mujoco
        self.robot = robot
        self.model = model = kit_model(robot)
        self.data = mujoco.MjData(model)
        self._q = np.array([model.joint(j).qposadr[0] for j in robot.joints])
        self._v = np.array([model.joint(j).dofadr[0] for j in robot.joints])
        self._act = np.array([model.actuator(j).id for j in robot.joints])
        # a stick's angle to the horizontal is its arm's lift plus its motor's angle
        self._lift = np.array([robot.joints.index(f"{robot.limb_of(j)}.lift")
                               if j.endswith(f".{THETA}") and f"{robot.limb_of(j)}.lift" in robot.joints else -1
                               for j in robot.joints])
        self._top = np.array([abs(model.actuator_ctrlrange[a, 1]) for a in self._act])
        self._speed = np.array([_max_speed(robot, j) for j in robot.joints])
        self.data.qpos[self._q] = self._relative(positions)
        self.data.qvel[self._v] = self._relative(velocities)
        mujoco.mj_forward(model, self.data)
        self._pads = {model.geom(f"pad:{name}").id: s.piece for name, s in robot.surfaces.items()}
        self._reach = _PlaceReach(robot)
        self._geoms = {name: model.geom(f"pad:{name}").id for name in robot.surfaces}
        self._reach_names = [name for name, surface in robot.surfaces.items() if surface.foot is None]
        self._at = None
        self._tips = {model.geom(f"tip:{robot.limb_of(j)}").id: robot.limb_of(j) for j in robot.joints
                      if j.endswith(f".{THETA}")}
        self._touching = set()
        self._time, self._period = start, 1.0 / robot.rate
        self.onsets = []

    def _relative(self, values):
        out = np.array(values, dtype=float)
        has = self._lift >= 0
        out[has] -= out[self._lift[has]]
        return out

    def state(self):
        """Every joint's angle (rad) and speed (rad/s) now, a stick's to the horizontal."""
        q, v = self.data.qpos[self._q].copy(), self.data.qvel[self._v].copy()
        has = self._lift >= 0
        q[has] += q[self._lift[has]]
        v[has] += v[self._lift[has]]
        return q, v

    def advance(self, torques, speeds):
        """One control period under ``torques`` (N·m, limited by each motor's line at ``speeds``): the torques applied."""
        applied = np.array([limit_torque(tau, w, top, w_max) for tau, w, top, w_max in
                            zip(torques.tolist(), speeds.tolist(), self._top.tolist(), self._speed.tolist())])
        before = self.state()
        self._place_pads(before[0])
        self.data.ctrl[self._act] = applied
        self._mujoco.mj_step(self.model, self.data, nstep=self.robot.plant.substeps)
        self._contacts(before)
        self._time += self._period
        return applied

    def _place_pads(self, positions):
        """Each hand's pad collides with the tips of the hands at its piece's place: the kit's pieces are surfaces in
        each hand's joints, at its θ_max over its place, not a set of solids an arm might reach from elsewhere."""
        at = self._reach(positions)
        if at == self._at:
            return
        for name in self._reach_names:
            bits = sum(_bit(self.robot, hand) for hand, piece in at.items() if piece == name)
            self.model.geom_conaffinity[self._geoms[name]] = bits
        self._at = at

    def _contacts(self, before):
        """Log each tip–pad pair that came into contact during the period: when (from the period's start state, its
        gap closing at its speed), the piece, the limb, its speed (m/s)."""
        contact = self.data.contact
        now = set()
        for g1, g2, dist in zip(contact.geom1.tolist(), contact.geom2.tolist(), contact.dist.tolist()):
            pair = (g1, g2) if g1 in self._pads else (g2, g1)
            if dist < 0.0 and pair[0] in self._pads and pair[1] in self._tips:
                now.add(pair)
        for pad, tip in now - self._touching:
            limb, piece = self._tips[tip], self._pads[pad]
            when, speed = _meeting(self.robot, limb, piece, before, self._period)
            self.onsets.append(KitOnset(float(self._time + when), piece, limb, speed))
        self._touching = now


def _max_speed(robot, joint):
    limb = robot.limb_of(joint)
    if limb in FEET:
        return 1000.0
    return robot.plant.max_speed if joint.endswith(f".{THETA}") else robot.arm.max_speed


def _meeting(robot, limb, piece, state, period):
    """When (s after the period's start, within it) a limb that started it in ``state`` met ``piece``'s surface, and
    its striking speed (m/s): the gap closed at the speed it had."""
    q, v = state
    joints = robot.joints
    theta = joints.index(f"{limb}.{THETA}")
    if limb in HANDS:
        stick = robot.sticks[limb][piece].stick
        lift = joints.index(f"{limb}.lift") if f"{limb}.lift" in joints else None
        place = robot.kit.piece(piece).place
        # height of the tip above the piece's surface at its place: the arm's lift and the stick's angle
        rise = robot.arm.reach * (math.sin(q[lift]) - math.sin(place.get("lift", 0.0))) if lift is not None else 0.0
        rate = robot.arm.reach * math.cos(q[lift]) * v[lift] if lift is not None else 0.0
        x = stick.pivot_to_tip
        gap = rise + stick.pivot_height + x * math.sin(q[theta])
        closing = -(rate + x * math.cos(q[theta]) * v[theta])
        speed = abs(v[theta]) * x
    else:
        pedal = robot.pedal_of(limb)
        x = pedal.length
        gap = x * (math.sin(pedal.phi_head) + math.sin(q[theta]))  # θ = −φ: the head's side moves with −sin θ
        closing = -x * math.cos(q[theta]) * v[theta]
        speed = abs(v[theta]) * x
    # a contact that began in the period's last substep shows in the next one's list: it may start before it
    when = gap / closing if closing > 0.0 else 0.0
    return min(max(when, -period), period), float(speed)


class _PlaceReach:
    """Which piece each hand's arm is at: the nearest place with every positioning joint within :data:`AT_PLACE`."""

    def __init__(self, robot):
        self.hands = robot.kit.hands
        self._joints = {hand: [robot.joints.index(f"{hand}.{j}") for j in robot.kit.limbs[hand]] for hand in self.hands}
        self._names = {hand: list(robot.sticks[hand]) for hand in self.hands}
        self._places = {hand: np.array([robot.place(p) for p in self._names[hand]]) for hand in self.hands}

    def __call__(self, positions):
        """{hand: the piece it is at, or None} for every joint's angle ``positions`` (rad)."""
        at = {}
        for hand in self.hands:
            distance = np.max(np.abs(self._places[hand] - positions[self._joints[hand]]), axis=1)
            nearest = int(np.argmin(distance))
            at[hand] = self._names[hand][nearest] if distance[nearest] <= AT_PLACE else None
        return at


class KitOnset(NamedTuple):
    """A limb meeting a piece: when (s), the piece, the limb, its striking speed (m/s: a tip's or a beater head's)."""

    t: float
    piece: str
    limb: str
    speed: float


class _SimpleKit:
    """Every joint its own simple joint (see the module's docstring), stepped one control period at a time."""

    def __init__(self, robot, positions, velocities, start):
        self.robot = robot
        self._joints, self._heads, self._external = [], {}, {}
        for j, joint in enumerate(robot.joints):
            limb, name = robot.limb_of(joint), joint.rsplit(".", 1)[1]
            state = {"theta0": float(positions[j]), "omega0": float(velocities[j]), "start": start}
            if limb in HANDS and name == THETA:
                sticks = robot.sticks[limb]
                self._heads[j] = {piece: (p.head, *contact_gains(p, robot.surfaces[piece].cor))
                                  for piece, p in sticks.items()}
                simple = SimpleJoint(next(iter(sticks.values())), stiffness=0.0, damping=0.0, **state)
                simple.set_head(None, 0.0, 0.0)
            elif limb in HANDS:
                simple = SimpleJoint(_arm_plant(robot, name), stiffness=0.0, damping=0.0, **state)
                simple.set_head(None, 0.0, 0.0)
            else:
                pedal = robot.pedal_of(limb)
                calibration = beater_plant(pedal, robot.plant)
                stiffness, damping = contact_gains(calibration, pedal.cor)
                # the pedal's spring and the beater's gravity act as a torque added each period, not the stick's
                free = replace(calibration, stick=replace(calibration.stick, pivot_to_com=0.0))
                simple = SimpleJoint(free, stiffness=stiffness, damping=damping, **state)
                simple.set_head(-pedal.phi_head, stiffness, damping)
                self._external[j] = pedal
            self._joints.append(simple)
        self._reach = _PlaceReach(robot)
        self._at = {j: None for j in self._heads}
        self._seen = [0] * len(self._joints)
        self.onsets = []

    def state(self):
        return (np.array([s.theta for s in self._joints]), np.array([s.omega for s in self._joints]))

    def advance(self, torques, speeds):
        period = 1.0 / self.robot.rate
        self._place_heads()
        applied = np.empty(len(self._joints))
        for j, (simple, tau) in enumerate(zip(self._joints, torques.tolist())):
            pedal = self._external.get(j)
            extra = 0.0 if pedal is None else _pedal_torque(pedal, simple.theta)
            applied[j] = simple.advance(tau + extra, period) - extra
        self._log()
        return applied

    def _place_heads(self):
        """Each stick's joint gets the head of the piece its arm is at (within :data:`AT_PLACE`), or none."""
        at = self._reach(self.state()[0])
        for j, heads in self._heads.items():
            piece = at[self.robot.limb_of(self.robot.joints[j])]
            if piece != self._at[j]:
                self._joints[j].set_head(*(heads[piece] if piece is not None else (None, 0.0, 0.0)))
                self._at[j] = piece

    def _log(self):
        for j, simple in enumerate(self._joints):
            contacts = simple.contacts(self._seen[j])
            if not len(contacts):
                continue
            self._seen[j] += len(contacts)
            limb = self.robot.limb_of(self.robot.joints[j])
            piece = self._at.get(j) if limb in HANDS else self.robot.pedal_piece(limb)
            for t, speed in zip(contacts.t.tolist(), contacts.tip_speed.tolist()):
                self.onsets.append(KitOnset(t, piece, limb, speed))


def _pedal_torque(pedal, theta):
    """The spring's and gravity's torque on the beater at θ = −φ (N·m, in θ's sense): −κ·(θ − θ_rest) + m·g·l·sin θ."""
    return -pedal.spring * (theta + pedal.phi_rest) + pedal.gravity * np.sin(theta)


def _arm_plant(robot, joint):
    """A positioning joint as the simple plant: a rod standing for its gravity torque (none for the yaw), the rest of
    its inertia in its motor's rotor, no head."""
    inertia, gravity = arm_inertia(robot.arm, robot.kit.stick, joint)
    arm = robot.arm
    if gravity > 0.0:
        length = min(1.0, 0.75 * GRAVITY * inertia / gravity)  # so the rod's own inertia is at most half the joint's
        mass, com = 2.0 * gravity / (GRAVITY * length), length / 2.0
    else:
        length, mass, com = 1.0, 1e-6, 0.0
    stick = Stick(length=length, pivot_to_tip=length, pivot_to_com=com, pivot_to_thumb=0.0,
                  pivot_height=length / 2.0, mass=mass)
    rotor = (inertia - mass * length**2 / 3.0) / arm.gear_ratio**2
    return Plant(stick=stick, rotor_inertia=rotor, gear_ratio=arm.gear_ratio, max_torque=arm.max_torque,
                 max_speed=arm.max_speed, viscous=arm.viscous, coulomb=0.0, encoder_counts=arm.encoder_counts,
                 substeps=robot.plant.substeps)


# --- playing --------------------------------------------------------------------------------------------------------


@dataclass(frozen=True, repr=False)
class KitPlayed:
    """A kit composition played by the robot.

    Attributes
    ----------
    composition : KitComposition
    robot : KitRobot
    controller : str
    engine : str
        "simple" or "mujoco".
    t : ndarray [shape=(n,)]
        s: the control periods' starts.
    angles, reference : dict of str to ndarray [shape=(n,)]
        Each joint's angle (rad) at each period's start (a stick's to the horizontal), and the reference's.
    torque : dict of str to ndarray [shape=(n,)]
        N·m: each joint's mean torque over each period.
    onsets : tuple of KitOnset
        Every contact of a tip or a beater with a piece, in time order.
    """

    composition: object
    robot: KitRobot
    controller: str
    engine: str
    t: np.ndarray
    angles: dict
    reference: dict
    torque: dict
    onsets: tuple

    def __repr__(self):
        return (f"KitPlayed(by {self.controller!r} on the {self.engine} engine: {len(self.t)} periods at "
                f"{self.robot.rate:g} Hz, {len(self.onsets)} onsets)")

    @property
    def notes(self):
        """The notes the reference played within the run, each ``(impact time s, piece, level dB)``, in time order.

        A note within :data:`~drumstroke.robot.metrics.WINDOW` of the run's end is left out: the robot
        may strike it just after.
        """
        end = self.t[-1] - WINDOW
        notes = [(o.impact, o.piece, o.impact_level) for o in self.composition.performance.outcomes
                 if o.played and o.impact <= end]
        return tuple(sorted(notes))


def track_kit(composition, controller="impedance", engine="mujoco", seconds=None, *, plant=None, arm=None,
              progress=None):
    """Play a kit composition on the robot: every joint tracks its column of the composition's reference.

    Parameters
    ----------
    composition : KitComposition
    controller : str or Controller
        A name of :data:`~drumstroke.robot.controllers.CONTROLLERS` (its default gains) or a controller: the
        sticks' gains; every other joint's gains in N·m are scaled by its inertia over a stick's (:func:`scaled_law`).
    engine : {"mujoco", "simple"}
    seconds : float > 0 or None
        Play the first ``seconds`` of the composition's timeline (default all of it).
    plant : Plant, optional
        The sticks' joint (its stick is the kit's). Default ``Plant(substeps=KIT_SUBSTEPS)``.
    arm : ArmPlant, optional
        Default ``ArmPlant()``.
    progress : callable or None
        Called with the fraction played, every second of it and at the end.

    Returns
    -------
    KitPlayed
    """
    from ..compose import KitComposition

    if not isinstance(composition, KitComposition):
        raise ParameterError(f"composition must be a drumstroke.compose.KitComposition, got {shown(composition)}")
    law = _controller(controller)
    if engine not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(ENGINES)}, got {shown(engine)}",
                             parameter="engine", value=engine, allowed=", ".join(ENGINES))
    performance = composition.performance
    pedals = {m.pedal: m.design.stroke.pedal for m in performance.feet.values() if m.design is not None}
    robot = kit_robot(composition.kit, plant=plant, arm=arm, pedals=pedals, rate=composition.rate)
    if seconds is not None:
        last = math.floor(composition.t_end * robot.rate + 1e-9) / robot.rate  # the last sample's time
        seconds = check_real("seconds", seconds, low=0.0, high=last, low_open=True, unit="s")
    check_tracking(composition.t_end if seconds is None else seconds, robot.rate, joints=len(robot.joints))
    t, columns = composition.sample()
    if seconds is not None:
        t = t[:math.floor(seconds * robot.rate + 1e-9) + 1]
    reference = _reference(robot, composition, law, t, columns)
    start = {j: (float(reference[j][0][0]), float(reference[j][1][0])) for j in robot.joints}
    positions = np.array([start[j][0] for j in robot.joints])
    velocities = np.array([start[j][1] for j in robot.joints])
    if engine == "mujoco":
        kit = _MujocoKit(robot, positions, velocities, float(t[0]))
    else:
        kit = _SimpleKit(robot, positions, velocities, float(t[0]))
    angles, torque = _run(robot, kit, law, reference, _pieces(robot, composition, t), progress)
    return KitPlayed(composition, robot, law.name, engine, t, {j: angles[:, i] for i, j in enumerate(robot.joints)},
                     {j: reference[j][0] for j in robot.joints}, {j: torque[:, i] for i, j in enumerate(robot.joints)},
                     tuple(sorted(kit.onsets)))


def _controller(controller):
    if isinstance(controller, Controller):
        return controller
    if not isinstance(controller, str) or controller not in CONTROLLERS:
        raise ParameterError(f"controller must be one of {', '.join(CONTROLLERS)} or a Controller, got "
                             f"{shown(controller)}", parameter="controller", value=controller,
                             allowed=", ".join(CONTROLLERS))
    return named_controller(controller)


def scaled_law(controller, plant, ratio, rate):
    """``controller``'s law for a joint ``ratio`` times a stick's inertia, its gains in N·m ``ratio`` times theirs.

    Run on the joint scaled down by ``ratio`` (its inertia, gravity torque and torque limit over it) and its
    torque scaled back up: τ = ratio·law(θ_ref, ω_ref, α_ref, θ̂, ω̂) is the law with every torque-per-error gain
    times ``ratio`` (the same closed-loop bandwidth), its feedforward the joint's own, its gains in their
    declared ranges.

    Parameters
    ----------
    controller : Controller
    plant : LawPlant
        The joint.
    ratio : float > 0
    rate : float
        Hz.
    """
    small = plant._replace(inertia=plant.inertia / ratio, gravity_torque=plant.gravity_torque / ratio,
                           max_torque=plant.max_torque / ratio)
    command = controller.law(small, rate)
    if ratio == 1.0:
        return command
    return lambda *readings: ratio * command(*readings)


def _reference(robot, composition, law, t, columns):
    """Each joint's reference θ (rad), ω (rad/s), α (rad/s²) at ``t``: a stick's and a beater's as ``law`` steers by
    them (:meth:`~drumstroke.robot.controllers.Controller.steer`), the positioning joints' as they are."""
    motions = composition.performance.motions
    reference = {}
    for limb in {robot.limb_of(j) for j in robot.joints}:
        joints = [j for j in robot.joints if robot.limb_of(j) == limb]
        if limb not in motions:  # a hand with no note: held still, its stick up
            for j in joints:
                rest = math.pi / 4 if j.endswith(f".{THETA}") else 0.0
                reference[j] = (np.full(len(t), rest), np.zeros(len(t)), np.zeros(len(t)))
            continue
        names, curve = motions[limb]
        alpha = curve.acceleration(t)
        alpha = alpha.reshape(len(t), -1)
        for k, name in enumerate(names):
            j = f"{limb}.{name}"
            reference[j] = (columns[j][:len(t)], columns[f"{j}.velocity"][:len(t)], alpha[:, k])
        theta = f"{limb}.{THETA}"
        reference[theta] = _steered(robot, composition, law, limb, curve, len(names) - 1, t)
    return reference


def _steered(robot, composition, law, limb, curve, column, t):
    """The stick's (or beater's) θ, ω, α to steer by: ``law.steer`` of its motion as a one-stick trajectory."""
    performance = composition.performance
    if limb in HANDS:
        hits = performance.hands[limb].hits
        times = np.array([h.t for h in hits])
        stick = robot.kit.stick
        speeds = np.array([10.0 ** (h.level / 20.0) for h in hits]) / stick.pivot_to_tip
        after = np.array([robot.surfaces[h.piece].cor for h in hits]) * speeds
        heads = np.array([robot.sticks[limb][h.piece].head for h in hits])
        impacts, head, x = Impacts(times, -speeds, stick.pivot_to_tip), math.nan, stick.pivot_to_tip
    else:
        motion = performance.feet[limb]
        stroke = motion.design.stroke if motion.design is not None else None
        pedal = robot.pedal_of(limb)
        x = pedal.length
        impacts = stroke.impacts if stroke is not None else Impacts(np.empty(0), np.empty(0), x)
        after = stroke.omega_after if stroke is not None else np.empty(0)
        head, heads = -pedal.phi_head, None

    def path(s):
        theta, omega = curve(s)
        return (theta, omega) if np.ndim(theta) == 1 else (theta[:, column], omega[:, column])

    # the held part after an impact takes the trajectory's head: NaN, then each impact's piece's (a hand's)
    one = Trajectory.single(path, impacts, after, theta_max=head, t_end=float(composition.t_end),
                            rate=composition.rate, stick=limb, name=limb)
    theta, omega, alpha = (np.array(a[:len(t)]) for a in law.steer(one))
    if heads is not None and len(heads):
        held = np.isnan(theta)
        which = np.searchsorted(impacts.t, t[held], side="right") - 1
        theta[held] = heads[np.clip(which, 0, len(heads) - 1)]
    return theta, omega, alpha


def _pieces(robot, composition, t):
    """For each hand, the index (into its sticks' pieces) of the piece its reference is at or nearest to, per period."""
    motions = composition.performance.motions
    pieces = {}
    for hand in robot.kit.hands:
        names = list(robot.sticks[hand])
        if hand not in motions:
            pieces[hand] = (names, np.zeros(len(t), dtype=int))
            continue
        positions, _ = motions[hand][1](t)
        positions = positions.reshape(len(t), -1)[:, :-1]
        distance = np.stack([np.max(np.abs(positions - robot.place(p)), axis=1) for p in names])
        pieces[hand] = (names, np.argmin(distance, axis=0))
    return pieces


def _run(robot, kit, law, reference, pieces, progress):
    """The control loop over every joint: read the encoders, each joint's law, the motors; θ and torque logged."""
    joints = robot.joints
    rate = robot.rate
    plants = robot.law_plants()
    stick_inertia = robot.plant.inertia
    laws = []
    for j in joints:
        if isinstance(plants[j], dict):
            laws.append({piece: law.law(p, rate) for piece, p in plants[j].items()})
        else:
            laws.append(scaled_law(law, plants[j], plants[j].inertia / stick_inertia, rate))
    resolution = [next(iter(p.values())).resolution if isinstance(p, dict) else p.resolution
                  for p in (plants[j] for j in joints)]
    choose = {}
    for i, j in enumerate(joints):
        if isinstance(laws[i], dict):
            names, index = pieces[robot.limb_of(j)]
            choose[i] = ([laws[i][name] for name in names], index.tolist())
    # a beater's law is fed forward the torque that holds its spring and gravity at the reference's angle too
    held = [(-_pedal_torque(robot.pedal_of(robot.limb_of(j)), reference[j][0])).tolist()
            if robot.limb_of(j) in FEET else None for j in joints]
    refs = [tuple(a.tolist() for a in reference[j]) for j in joints]
    n = len(refs[0][0])
    angles, torque = np.empty((n, len(joints))), np.empty((n, len(joints)))
    q, v = kit.state()
    measured = [quantize(a, r) for a, r in zip(q.tolist(), resolution)]
    omega_hat = v.tolist()
    commands = np.empty(len(joints))
    step = max(1, int(rate))
    for k in range(n):
        q, v = kit.state()
        angles[k] = q
        for i, (a, r) in enumerate(zip(q.tolist(), resolution)):
            reading = quantize(a, r)
            if k:
                omega_hat[i] = estimate_speed(omega_hat[i], reading, measured[i], rate)
            measured[i] = reading
            theta, omega, alpha = refs[i][0][k], refs[i][1][k], refs[i][2][k]
            command = choose[i][0][choose[i][1][k]] if i in choose else laws[i]
            commands[i] = command(theta, omega, alpha, reading, omega_hat[i]) + (held[i][k] if held[i] else 0.0)
        torque[k] = kit.advance(commands, v)
        if progress and ((k + 1) % step == 0 or k + 1 == n):
            progress((k + 1) / n)
    return angles, torque


# --- scoring --------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class KitScores:
    """Onsets scored per piece within one window (:func:`score_onsets`).

    Attributes
    ----------
    window : float
        s.
    pieces : tuple of PieceScores
        Each piece with a note or an onset, in the kit's order.
    total : OnsetScores
        Every piece's counts summed (:func:`~drumstroke.robot.metrics.pool`).
    """

    window: float
    pieces: tuple
    total: OnsetScores

    @property
    def fraction(self):
        """The notes struck on their piece within the window, of all notes (1 with no note)."""
        return self.total.recall

    def piece(self, name):
        """The :class:`PieceScores` of ``name``."""
        for scores in self.pieces:
            if scores.piece == name:
                return scores
        raise ParameterError(f"piece must be one of those scored ({', '.join(s.piece for s in self.pieces)}), "
                             f"got {shown(name)}")

    def to_dict(self):
        """Plain data for JSON."""
        return {"window": self.window, "total": self.total.to_dict(),
                "pieces": {s.piece: s.scores.to_dict() for s in self.pieces}}


class PieceScores(NamedTuple):
    """One piece's notes and onsets: its name, its notes' count, the robot's onsets on it, the :class:`OnsetScores`."""

    piece: str
    notes: int
    onsets: int
    scores: OnsetScores

    @property
    def matched(self):
        """Notes struck on it within the window."""
        return self.scores.matched

    @property
    def fraction(self):
        """matched / notes (1 with no note)."""
        return self.scores.recall


def score_onsets(notes, onsets, *, window=WINDOW, order=None):
    """Score the robot's onsets against the notes per piece: a note counts when its piece was struck within ±window.

    On each piece the notes and the onsets on it are matched one to one as
    :func:`~drumstroke.robot.metrics.match_onsets` matches them (as ``mir_eval.onset`` does, so each piece's
    precision, recall and F-measure are ``mir_eval.onset.f_measure``'s but where it has no note or no onset).
    An onset on another piece than the note's is no match: the note is missed and the onset is extra.

    Parameters
    ----------
    notes : sequence of (float, str, float)
        Each note's impact time (s), piece and level (dB re 1 m/s).
    onsets : sequence of KitOnset or (float, str, ...)
        Each onset's time (s) and piece, and its speed (m/s) as the fourth field.
    window : float in (0, 1]
        s.
    order : sequence of str, optional
        The pieces' order in the result (default as they first appear in the notes, then the onsets).

    Returns
    -------
    KitScores
    """
    window = check_real("window", window, low=0.0, high=1.0, low_open=True, unit="s")
    notes = sorted((float(t), piece, float(level)) for t, piece, level in notes)
    onsets = sorted((float(o[0]), o[1], float(o[3])) for o in onsets)
    names = list(order) if order is not None else []
    for piece in [n[1] for n in notes] + [o[1] for o in onsets]:
        if piece not in names:
            names.append(piece)
    pieces = []
    for piece in names:
        ref = np.array([n[0] for n in notes if n[1] == piece])
        level = np.array([n[2] for n in notes if n[1] == piece])
        got = np.array([o[0] for o in onsets if o[1] == piece])
        speed = np.array([o[2] for o in onsets if o[1] == piece])
        if not len(ref) and not len(got):
            continue
        match = match_onsets(ref, got, window=window)
        kept = match >= 0
        timing = got[match[kept]] - ref[kept]
        with np.errstate(divide="ignore"):  # an onset at no speed is −inf dB
            levels = 20.0 * np.log10(speed[match[kept]]) - level[kept]
        scores = OnsetScores.from_pairs(window, timing, levels, played=len(got), reference=len(ref))
        pieces.append(PieceScores(piece, len(ref), len(got), scores))
    total = pool([p.scores for p in pieces]) if pieces else OnsetScores.from_pairs(
        window, np.empty(0), np.empty(0), played=0, reference=0)
    return KitScores(window, tuple(pieces), total)


def kit_scores(played, *, window=WINDOW):
    """:func:`score_onsets` of what the robot played: the notes the reference played within the run
    (:attr:`KitPlayed.notes`) against the audible onsets (tip or beater speed at least
    :data:`~drumstroke.robot.metrics.AUDIBLE_SPEED`).

    Parameters
    ----------
    played : KitPlayed
    window : float in (0, 1]
        s.
    """
    if not isinstance(played, KitPlayed):
        raise ParameterError(f"played must be a drumstroke.robot.kit.KitPlayed, got {shown(played)}")
    audible = [o for o in played.onsets if o.speed >= AUDIBLE_SPEED]
    order = [p.name for p in played.robot.kit.pieces]
    return score_onsets(played.notes, audible, window=window, order=order)


def kit_drop_test(robot, surface, *, model=None):
    """Drop a stick (or a beater) onto ``surface`` in the kit's model, its arm at the place, every motor off.

    A stick starts touching its pad at the speed it would have dropped to from level, every other joint
    at rest (a 3.5 ms contact is too short for an arm to sag); a beater at 1 m/s at its head, with its
    spring and gravity off (the pedal's model's impact is the head's restitution alone). The first
    contact is measured as the single joint's drop is (:func:`~drumstroke.robot.mujoco_plant.mujoco_drop_test`).

    Parameters
    ----------
    robot : KitRobot
    surface : str
        One of ``robot.surfaces``.
    model : mujoco.MjModel, optional
        :func:`kit_model` of ``robot``, if made already (the test changes it: a fresh one for each).

    Returns
    -------
    Drop
        The limb's speeds into and out of the contact (rad/s, a stick's to the horizontal) and how long it lasted (s).
    """
    import mujoco

    from .plant import Drop

    if surface not in robot.surfaces:
        raise ParameterError(f"surface must be one of {', '.join(robot.surfaces)}, got {shown(surface)}",
                             parameter="surface", value=surface, allowed=", ".join(robot.surfaces))
    model = kit_model(robot) if model is None else model
    limb, single = _calibration_plant(robot, surface)
    piece = robot.surfaces[surface].piece
    data = mujoco.MjData(model)
    _pose(robot, model, data, limb, piece)
    theta = model.joint(f"{limb}.{THETA}")
    if limb in HANDS:
        speed = math.sqrt(2.0 * single.gravity_torque * -math.sin(single.head) / single.inertia)
    else:  # the head's restitution alone: the spring's pull over the contact would add to a slow rebound
        speed = 1.0 / robot.pedal_of(limb).length
        model.opt.gravity[:] = 0.0
        model.jnt_stiffness[theta.id] = 0.0
    data.qpos[theta.qposadr[0]] -= 1e-12  # just in: the first step sees the contact from its start
    data.qvel[theta.dofadr[0]] = -speed
    pad, tip = model.geom(f"pad:{surface}").id, model.geom(f"tip:{limb}").id
    model.geom_conaffinity[pad] = _bit(robot, limb)
    step, touching = model.opt.timestep, False
    for n in range(1, int(0.05 / step)):
        mujoco.mj_step(model, data)
        now = any({c.geom1, c.geom2} == {pad, tip} and c.dist < 0.0 for c in data.contact)
        if touching and not now:
            return Drop(speed, float(_speed(model, data, limb)), n * step)
        touching = touching or now
    return Drop(speed, 0.0, math.inf)


def _speed(model, data, limb):
    """A limb's θ speed (rad/s): a stick's to the horizontal (its arm's lift's and its own)."""
    speed = data.qvel[model.joint(f"{limb}.{THETA}").dofadr[0]]
    if limb in HANDS and f"{limb}.lift" in [model.joint(i).name for i in range(model.njnt)]:
        speed += data.qvel[model.joint(f"{limb}.lift").dofadr[0]]
    return speed


def first_seconds(score, seconds):
    """The notes of ``score`` within ``seconds`` of its first note, moved to start at 0 s.

    A song's drums may come in late (after 78 s, 120 s): its first seconds of drumming are these.

    Parameters
    ----------
    score : Score
    seconds : float > 0
        s.

    Returns
    -------
    Score
        Its notes from the first to the last before ``seconds`` after it, each ``first`` s earlier; the same
        tempo map and report.
    """
    from ..score import Score

    if not isinstance(score, Score):
        raise ParameterError(f"score must be a drumstroke.score.Score, got {shown(score)}")
    seconds = check_real("seconds", seconds, low=0.0, low_open=True, unit="s")
    if not score.notes:
        return score
    first = min(note.time for note in score.notes)
    notes = tuple(replace(note, time=note.time - first) for note in score.notes if note.time < first + seconds)
    return replace(score, notes=notes)
