"""An independent reference for drumstroke: scipy's DOP853 with events and a restart at each impact.

Written from the model's equations (docs/model.md), not from drumstroke's solver. It shares with drumstroke only the
inputs: the recipe, its profiles (called at interior points of each piece) and
``drumstroke.model.coefficients`` (k, k′, D, θ_max).

* The time line is cut at every edge of a(t) and g(t); each piece is integrated by its
  own ``solve_ivp`` calls, so no step crosses a jump. On a piece C(t) = (k·g + k′·a)/D is
  linear, taken through its values at the quarter points (never at an edge).
* A terminal event θ = θ_max (direction −1) stops the integration at each impact; the
  run restarts from θ_max with ω⁺ = −c·ω⁻ (paper Eq. 6).
* ``max_step`` is a quarter of the shortest flight the current state could make under
  the largest C of the piece, so DOP853 never steps over a whole small bounce (its
  event detection only compares signs at step ends).
* Zeno: once a launch speed L is below 1e-6 rad/s and the bounce rises less than 1e-12
  rad (L²/(2A) with A = C·cos θ_max), the rest of the geometric series is summed:
  the stick rests from t + 2L/(A(1 − c)). This is drumstroke's documented rule
  (``drumstroke.solver.constants.ZENO_SPEED``/``ZENO_HEIGHT``), so both list the same
  impacts. A tail that runs into the next piece has its remaining time scaled by
  C_old/C_new (as drumstroke does; it lasts microseconds).
* Rest holds while C ≥ 0; the stick lifts off (ω = 0) when C turns negative.

The state integrated is (u, ω) with u = θ − θ_max, and the head event is u = 0. This is
the same ODE, but u keeps full relative precision near the head: integrating θ itself, a
bounce launched at 1e-6 rad/s rises only ~5e-14 rad, so an absolute error of 1e-15 rad
(or the 3e-17 rad spacing of doubles near θ_max) moves its event by ~1e-9 s. Measured on
the free-bounce at rtol/atol = 1e-13/1e-15: integrating θ, impact times off by up to
3.8e-10 s and the rest time 1.7e-9 s late; integrating u, 4.8e-13 s.

:func:`reference_flight` is the inverse the same way: the two forces of one flight (one to the apex,
one after it) found by shooting with ``solve_ivp`` and ``fsolve``, the reference for
``drumstroke.design`` (benchmarks/design.py, tests/test_design.py).

Tolerances, measured with ``python benchmarks/reference.py`` against
:func:`oracle_impacts` (the exact elliptic solution):

* rtol = 1e-10, atol = 1e-12: free-bounce max impact-time error 6.7e-11 s.
* rtol = 1e-13, atol = 1e-15: 4.8e-13 s.
* rtol = 1e-13, atol = 1e-18 (the default): free-bounce, all 98 listed impacts down to
  the Zeno tail, 3.3e-14 s, rest time off by 3.9e-14 s; 40 random constant-force
  strokes (2,272 impacts; θ₀, ω₀, c, a drawn as in the benchmark) 9.7e-13 s.
  Three orders of margin below the 1e-9 s target. (scipy clamps rtol below
  100·eps = 2.2e-14, with a warning.)
"""

import itertools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve
from scipy.special import ellipk, ellipkinc

import drumstroke
from drumstroke.model import coefficients

RTOL = 1e-13
ATOL = 1e-18

ZENO_SPEED = 1e-6
"""Launch speed (rad/s) below which the rest of a bounce series is summed (drumstroke's rule)..."""

ZENO_HEIGHT = 1e-12
"""...provided the bounce also rises less than this (rad) above the head."""

MAX_IMPACTS = 1_000_000


class ReferenceError(RuntimeError):
    """The reference could not follow the stroke (vertical, stepped-over bounce, too many impacts)."""


def _zeno_floor(c, cos_head):
    return min(ZENO_SPEED, math.sqrt(2.0 * ZENO_HEIGHT * c * cos_head))


def reference_simulate(recipe, *, rate=None, rtol=RTOL, atol=ATOL):
    """Simulate ``recipe`` with DOP853, events and an impact/restart loop.

    Parameters
    ----------
    recipe : drumstroke.Recipe
    rate : float or None
        If given, also sample θ and ω at k/rate, k = 0, 1, … up to t_end (Hz).
    rtol, atol : float
        DOP853 tolerances.

    Returns
    -------
    impact_t : ndarray
        Impact times (s), listed up to t_end.
    impact_omega : ndarray
        ω just before each impact (rad/s, ≤ 0).
    rest_time : float or None
        Start of the final rest if it lasts to t_end, else None.
    samples : (t, theta, omega) or None
        The trajectory at ``rate``.
    """
    coef = coefficients(recipe.model, recipe.stick)
    theta_max = coef.theta_max
    cos_head = math.cos(theta_max)
    cor = recipe.cor
    t_end = recipe.t_end
    edges = np.union1d(recipe.force.pieces(t_end).edges, recipe.gravity.pieces(t_end).edges)

    def head(t, y):
        return y[0]

    head.terminal = True
    head.direction = -1

    def vertical(t, y):
        return y[0] - (0.5 * math.pi - theta_max)

    vertical.terminal = True
    vertical.direction = 1

    t, u, omega = 0.0, float(recipe.theta0) - theta_max, float(recipe.omega0)  # u = θ − θ_max
    resting = False
    lifting = False
    tail_c = math.nan
    rests = []  # [start, end]
    segments = []  # (t0, t1, OdeSolution)
    impact_t, impact_omega = [], []

    for left, right in itertools.pairwise(edges.tolist()):
        q1, q3 = left + 0.25 * (right - left), left + 0.75 * (right - left)
        cq1 = float(coef.torque_rate(recipe.gravity(q1), recipe.force(q1)))
        cq3 = float(coef.torque_rate(recipe.gravity(q3), recipe.force(q3)))
        slope = (cq3 - cq1) / (q3 - q1)
        if abs(cq3 - cq1) <= 1e-14 * max(abs(cq1), 1.0):
            slope = 0.0

        def c_at(s, cq1=cq1, slope=slope, q1=q1):
            return cq1 + slope * (s - q1)

        def rhs(s, y, cq1=cq1, slope=slope, q1=q1):
            return (y[1], -math.cos(theta_max + y[0]) * (cq1 + slope * (s - q1)))

        c_max = max(c_at(left), c_at(right))

        def presses(s, c_at=c_at, slope=slope):
            c = c_at(s)
            return c > 0.0 or (c == 0.0 and slope >= 0.0)

        t = left
        if resting and rests[-1][0] > left and c_at(left) > 0.0:  # a pending Zeno tail enters this piece
            rests[-1][0] = left + (rests[-1][0] - left) * tail_c / c_at(left)
            tail_c = c_at(left)
        while t < right:
            if resting:
                lift = _lift_off(c_at, slope, t, right)
                if lift is None:
                    break
                if rests[-1][0] >= lift:
                    rests.pop()  # lifted during the Zeno tail
                else:
                    rests[-1][1] = lift
                t, u, omega = lift, 0.0, 0.0
                resting, lifting = False, True
            if u == 0.0 and not lifting:
                if omega == 0.0 and presses(t):
                    rests.append([t, math.nan])
                    resting = True
                    continue
                if omega < 0.0:
                    w, t_hit = omega, t
                else:
                    w = None
            else:
                w = None
            if w is None:
                # a quarter of the shortest flight from here to the head under C ≤ c_max
                if c_max > 0.0:
                    up = max(omega, 0.0)
                    height = max(u, 0.0) + up * up / (2.0 * c_max)
                    shortest = up / c_max + math.sqrt(2.0 * height / c_max)
                    max_step = 0.25 * shortest if shortest > 0.0 else (right - t) / 16.0
                else:
                    max_step = math.inf
                sol = solve_ivp(
                    rhs, (t, right), (u, omega), method="DOP853", rtol=rtol, atol=atol,
                    events=(head, vertical), dense_output=True, max_step=max_step,
                )
                if not sol.success:
                    raise ReferenceError(f"solve_ivp failed at t = {t!r}: {sol.message}")
                if len(sol.t_events[1]):
                    raise ReferenceError(f"the stick reaches the vertical at t = {sol.t_events[1][0]!r}")
                segments.append((t, float(sol.t[-1]), sol.sol))
                lifting = False
                if sol.status == 1:
                    t_hit, w = float(sol.t_events[0][0]), float(sol.y_events[0][0][1])
                    if t_hit <= t and omega >= 0.0:
                        raise ReferenceError(f"stepped over a bounce launched at t = {t!r}")
                    w = min(w, 0.0)
                else:
                    t, u, omega = right, max(float(sol.y[0, -1]), 0.0), float(sol.y[1, -1])
                    continue
            # an impact at t_hit with speed w
            impact_t.append(t_hit)
            impact_omega.append(w)
            if len(impact_t) > MAX_IMPACTS:
                raise ReferenceError("too many impacts")
            launch = -cor * w
            t, u, omega = t_hit, 0.0, launch
            if not presses(t_hit):
                lifting = launch == 0.0
            elif launch == 0.0:
                rests.append([t_hit, math.nan])
                resting = True
            else:
                c_hit = c_at(t_hit)
                if cor < 1.0 and c_hit > 0.0 and launch < _zeno_floor(c_hit, cos_head):
                    tail_c = c_hit
                    rests.append([t_hit + 2.0 * launch / (c_hit * cos_head * (1.0 - cor)), math.nan])
                    omega = 0.0
                    resting = True

    rest_time = None
    if resting and rests[-1][0] <= t_end:
        rest_time = float(rests[-1][0])
    impact_t = np.array(impact_t, dtype=float)
    impact_omega = np.array(impact_omega, dtype=float)
    keep = impact_t <= t_end
    samples = None if rate is None else _sample(segments, theta_max, t_end, rate)
    return impact_t[keep], impact_omega[keep], rest_time, samples


def _lift_off(c_at, slope, t, right):
    """When, in [t, right), a resting stick lifts off; None if it stays."""
    c_now = c_at(t)
    if c_now < 0.0 or (c_now == 0.0 and slope < 0.0):
        return t
    if slope < 0.0:
        zero = t - c_now / slope
        if zero < right:
            return max(zero, t)
    return None


def _sample(segments, theta_max, t_end, rate):
    n = math.floor(t_end * rate * (1.0 + 1e-12)) + 1
    ts = np.minimum(np.arange(n) / rate, t_end)
    theta = np.full(n, theta_max)
    omega = np.zeros(n)
    if segments:
        starts = np.array([s[0] for s in segments])
        ends = np.array([s[1] for s in segments])
        index = np.searchsorted(starts, ts, side="right") - 1
        for i in np.unique(index[index >= 0]):
            mask = (index == i) & (ts <= ends[i])
            if mask.any():
                y = segments[i][2](ts[mask])
                theta[mask] = theta_max + np.maximum(y[0], 0.0)
                omega[mask] = y[1]
    return ts, theta, omega


# ----------------------------------------------------------------------------------------------
# the exact oracle for constant forcing (docs/model.md, A flight in closed form)


def _time_from_apex(sin_theta, speed, c, sin_apex):
    """[K(m) − F(ψ(θ) | m)]/√C, with ψ = asin(√((1 + sin θ)/(1 + sin θ_a))) and m = (1 + sin θ_a)/2.

    ψ is computed as atan2(√(1 + sin θ), |ω|/√(2C)) — the same angle, since
    sin θ_a − sin θ = ω²/(2C) — which stays accurate near the apex of a small bounce
    where the asin of a number close to 1 would not.
    """
    m = 0.5 * (1.0 + sin_apex)
    psi = math.atan2(math.sqrt(max(1.0 + sin_theta, 0.0)), abs(speed) / math.sqrt(2.0 * c))
    return (float(ellipk(m)) - float(ellipkinc(psi, m))) / math.sqrt(c)


def oracle_impacts(theta0, omega0, cor, C, theta_max, n, *, t_end=math.inf):
    """The first ``n`` impacts under constant forcing C > 0, exactly (elliptic integrals).

    Stops early at ``t_end`` or when a launch falls below the Zeno floor (the same rule
    as the reference and drumstroke: L < 1e-6 rad/s and L²/(2A) < 1e-12 rad).

    Returns
    -------
    times : ndarray
        Impact times (s).
    speeds : ndarray
        |ω⁻| at each impact (rad/s).
    rest : float or None
        The accumulation time t + 2L/(A(1 − c)) if the series was summed, else None.
    """
    if C <= 0.0:
        raise ValueError(f"C must be > 0, got {C!r}")
    sin_head = math.sin(theta_max)
    cos_head = math.cos(theta_max)
    floor = _zeno_floor(C, cos_head)
    sin0 = math.sin(theta0)
    sin_apex = sin0 + omega0 * omega0 / (2.0 * C)
    if sin_apex >= 1.0:
        raise ValueError("the stick reaches the vertical")
    rise = _time_from_apex(sin0, omega0, C, sin_apex)
    apex = rise if omega0 > 0.0 else -rise
    speed = math.sqrt(omega0 * omega0 + 2.0 * C * (sin0 - sin_head))
    t = apex + _time_from_apex(sin_head, speed, C, sin_apex)
    times, speeds = [], []
    rest = None
    while len(times) < n and t <= t_end:
        times.append(t)
        speeds.append(speed)
        launch = cor * speed
        if launch == 0.0:
            rest = t
            break
        if cor < 1.0 and launch < floor:
            rest = t + 2.0 * launch / (C * cos_head * (1.0 - cor))
            break
        sin_apex = sin_head + launch * launch / (2.0 * C)
        if sin_apex >= 1.0:
            raise ValueError("the stick reaches the vertical")
        t += 2.0 * _time_from_apex(sin_head, launch, C, sin_apex)
        speed = launch
    return np.array(times), np.array(speeds), rest


def constant_forcing_rate(recipe):
    """C (s⁻²) of a recipe whose force and gravity are constants."""
    coef = coefficients(recipe.model, recipe.stick)
    return float(coef.torque_rate(recipe.gravity.value, recipe.force.value))


def oracle_for(recipe, n=10**7):
    """:func:`oracle_impacts` for a constant-forcing recipe, up to its t_end."""
    coef = coefficients(recipe.model, recipe.stick)
    return oracle_impacts(
        recipe.theta0, recipe.omega0, recipe.cor, constant_forcing_rate(recipe), coef.theta_max, n,
        t_end=recipe.t_end,
    )


def _self_check():  # python benchmarks/reference.py: the numbers quoted in the module docstring
    import drumstroke

    rng = np.random.default_rng(1)
    for rtol, atol in ((1e-10, 1e-12), (1e-13, 1e-15), (RTOL, ATOL)):
        recipe = drumstroke.preset("free-bounce")
        t, _, rest, _ = reference_simulate(recipe, rtol=rtol, atol=atol)
        ot, _, orest = oracle_for(recipe)
        n = min(len(t), len(ot))
        print(f"rtol={rtol:g} atol={atol:g}: free-bounce {len(t)} impacts (oracle {len(ot)}), "
              f"max |dt| = {np.max(np.abs(t[:n] - ot[:n])):.2g} s, rest {rest!r} vs {orest!r}")
    worst, count = 0.0, 0
    coef = coefficients("paper", drumstroke.Stick())
    for _ in range(40):
        while True:
            theta0 = rng.uniform(coef.theta_max, 0.5)
            omega0, cor, force = rng.uniform(-5, 5), rng.uniform(0.5, 0.95), rng.uniform(0, 250)
            c = float(coef.torque_rate(9.8, force))
            if math.sin(theta0) + omega0**2 / (2 * c) < 0.999:
                break
        recipe = drumstroke.Recipe(force=drumstroke.Constant(force), theta0=theta0, omega0=omega0, cor=cor)
        t, _, _, _ = reference_simulate(recipe)
        ot, _, _ = oracle_for(recipe)
        assert len(t) == len(ot), (len(t), len(ot))
        worst = max(worst, float(np.max(np.abs(t - ot))))
        count += len(t)
    print(f"40 random constant-force strokes, {count} impacts: max |dt| = {worst:.2g} s")


def reference_flight(duration, u, v, model):
    """The forces (m/s²) of a flight of ``duration`` from the head at ``u`` to the head at ``v`` (rad/s), by shooting.

    Unknowns: the thumb's acceleration up to the apex and after it. Each guess is simulated with
    solve_ivp (DOP853, rtol 1e-12) from the head to the apex (event ω = 0) and on to the head (event
    θ = θ_max); fsolve drives the arrival time and speed to the targets.
    """
    co = coefficients(model, drumstroke.Stick())

    def rate(a):
        return (co.k * 9.8 + co.k_thumb * a) / co.inertia_ratio

    def fly(forces):
        up, down = rate(forces[0]), rate(forces[1])

        def apex(t, y):
            return y[1]

        def head(t, y):
            return y[0] - co.theta_max

        apex.terminal, apex.direction = True, -1
        head.terminal, head.direction = True, -1
        rise = solve_ivp(lambda t, y: [y[1], -up * math.cos(y[0])], (0.0, 10.0), [co.theta_max, u], method="DOP853",
                         events=apex, rtol=1e-12, atol=1e-14)
        if not rise.t_events[0].size:
            return 10.0, 0.0
        t_apex, state = rise.t_events[0][0], rise.y_events[0][0]
        fall = solve_ivp(lambda t, y: [y[1], -down * math.cos(y[0])], (t_apex, t_apex + 10.0), state,
                         method="DOP853", events=head, first_step=1e-6, rtol=1e-12, atol=1e-14)
        if not fall.t_events[0].size:
            return 10.0, 0.0
        return fall.t_events[0][0], -fall.y_events[0][0][1]

    guess = (2.0 * u / duration * co.inertia_ratio - co.k * 9.8) / co.k_thumb  # constant deceleration
    forces = fsolve(lambda f: [fly(f)[0] - duration, fly(f)[1] - v], [guess, guess * (v / u) ** 2], xtol=1e-12)
    return forces


if __name__ == "__main__":
    _self_check()
