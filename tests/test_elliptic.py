"""The compiled elliptic functions (drumstroke.solver.elliptic) against independent oracles.

* ``jacobi`` (sn, cn, dn by the AGM) against scipy.special.ellipj on random arguments, and
  against mpmath.ellipfun at 30 digits on hard points (m near 0, m near 1 − 1e-9, u near K(m)).
  scipy wraps Cephes' ``ellpj``, the same algorithm, so it is a regression check; mpmath is the
  independent one, here and in a random sample.
* ``shift`` (the addition theorem that the sampler uses to carry sn, cn, dn from one sample to
  the next) against ``jacobi`` at u₀ + k·h, and against mpmath.
* ``time_from_apex`` and ``flight_time`` against docs/model.md's closed form written out in mpmath:
  sin θ_a = sin θ + ω²/(2C), m = (1 + sin θ_a)/2, ψ = asin(√((1 + sin θ)/(1 + sin θ_a))),
  |τ| = (K(m) − F(ψ | m))/√C, and a flight from the head lasts twice the rise.
* ``state``: energy ω²/2 + C·sin θ = C·sin θ_a = C·(2m − 1) along the orbit (from
  m = (1 + sin θ_a)/2), the apex at τ = 0, and θ(τ) = 2·asin(√m·sn(K(m) − √C·τ | m)) − π/2
  (docs/model.md's form, with sn(K − v), not the module's cd(v)) in mpmath.

Nothing here uses drumstroke's own coefficients or solver; the head angle is Table 1's.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.special import ellipj, ellipk, ellipkinc

from drumstroke.solver.elliptic import flight_time, jacobi, parameter, shift, state, time_from_apex

EPS = 2.0**-52
HEAD = -math.asin(0.07 / 0.27)  # θ_max of Table 1 (the paper's Eq. 5: −asin(h/x) = −0.2623 rad)
M_TOP = 1.0 - 1e-9  # the solver takes orbits with m ≥ 1 − 1e-9 to its Taylor path

# Tolerances (measured worst values in brackets, on the seeded draws)
JACOBI_VS_SCIPY = 1e-15  # absolute, sn, cn, dn, |u| ≤ 30 [0: the same algorithm as Cephes]
# Against mpmath the AGM's error grows with |u| (φ = 2ⁿ·aₙ·u carries aₙ's round-off):
# absolute 2e-15 + 8ε·|u| (see mpmath_tolerance) [sn 7e-15, cn 8e-15, dn 3.4e-14 at |u| ≈ 30;
# the solver only calls it with |u| ≤ K(1 − 1e-9) = 11.7]. Near u = K(m) with m → 1, dn ~ √(1 − m)
# is found from a cancelling quotient or as √(1 − m·sn²), which loses its relative accuracy
# as ε/(1 − m) (scipy's ellipj does the same, bit for bit): see dn_tolerance
# [1.4e-12 absolute at m = 1 − 1e-9, u ≈ K; 8.9e-14 in the random sample].
SHIFT_TOL = 1e-13  # absolute, 128 steps of h ≤ 0.05 carried by the addition theorem [7.6e-14 at m = 1 − 1e-6]
TIME_RTOL = 1e-12  # relative, time_from_apex and flight_time against mpmath [2.3e-14; 5.7e-16 from the head]
# state(τ) on the part of an orbit above the head. ω = −2√(m(1 − m)C)·sd(v) divides by dn(v), which
# is ~√(1 − m) there and has an absolute error of a few ε: ω's relative error and the energy's
# grow as ε/√(1 − m) toward the vertical [measured ≤ 3ε/√(1 − m)·C, e.g. 1.6e-11·C at
# 1 − m = 1e-9; ≤ 1e-13·C for 1 − m ≥ 1e-5]. θ = 2·asin(√m·cd) − π/2 near the apex has the same
# factor from asin's slope [1.25e-11 rad at 1 − m = 1e-9].
ENERGY_RTOL = 1e-13  # |E − C(2m − 1)| / C, raised to 8ε/√(1 − m) near the vertical (energy_tolerance)
THETA_TOL = 1e-13  # rad, state's θ against mpmath, plus 8ε/√(1 − m) (theta_tolerance)


def mpmath_tolerance(u):
    """Absolute bound for sn, cn, dn against mpmath at argument u."""
    return 2e-15 + 8.0 * EPS * abs(u)


def dn_tolerance(m):
    """Absolute bound for dn near u = K(m): 1e-14 plus the loss ε/√(1 − m) of dn = √(1 − m·sn²)."""
    return 1e-14 + 16.0 * EPS / math.sqrt(1.0 - m)


# ---------------------------------------------------------------------------------------------
# jacobi


def _jacobi_many(u, m):
    return np.array([jacobi(float(a), float(b)) for a, b in zip(u, m)])


def test_jacobi_matches_scipy_on_random_arguments(rng):
    """20,000 uniform (u, m) and 20,000 with m log-spread toward 0 and toward 1 − 1e-9."""
    n = 20_000
    u = rng.uniform(-30.0, 30.0, 2 * n)
    m = np.concatenate((
        rng.uniform(0.0, M_TOP, n),
        10.0 ** rng.uniform(-18.0, -0.3, n // 2),  # toward 0, both sides of the m < 1e-9 branch
        1.0 - 10.0 ** rng.uniform(-9.0, -0.3, n // 2),  # toward 1 − 1e-9
    ))
    ours = _jacobi_many(u, m)
    sn, cn, dn, _ = ellipj(u, m)
    error = np.abs(ours - np.column_stack((sn, cn, dn)))
    worst = np.unravel_index(np.argmax(error), error.shape)
    print(f"jacobi vs scipy: worst {error.max():.3g} at u = {u[worst[0]]!r}, m = {m[worst[0]]!r}")
    assert error.max() <= JACOBI_VS_SCIPY, (
        f"{('sn', 'cn', 'dn')[worst[1]]} off by {error.max():.3g} at u = {u[worst[0]]!r}, m = {m[worst[0]]!r}"
    )
    # and the identities sn² + cn² = 1, dn² + m·sn² = 1 (dn's residual grows with |u| like its error)
    assert np.max(np.abs(ours[:, 0] ** 2 + ours[:, 1] ** 2 - 1.0)) <= 4 * EPS
    assert np.max(np.abs(ours[:, 2] ** 2 + m * ours[:, 0] ** 2 - 1.0) / (1.0 + np.abs(u))) <= 16 * EPS


def _mp_jacobi(u, m):
    with mp.workdps(30):
        uu, mm = mp.mpf(float(u)), mp.mpf(float(m))
        return tuple(float(mp.ellipfun(kind, uu, m=mm)) for kind in ("sn", "cn", "dn"))


HARD_M = [0.0, 1e-300, 1e-16, 1e-12, 9.999999999e-10, 1e-9, 1.0000001e-9, 1e-6, 0.5, 0.9,
          1.0 - 1e-6, 1.0 - 1e-8, 1.0 - 2e-9, M_TOP]


@pytest.mark.parametrize("m", HARD_M)
def test_jacobi_matches_mpmath_at_hard_points(m):
    """u = 0, tiny, near K(m) from both sides, 2K, −K, and far out, for m at the branch edge 1e-9 and near 1."""
    k = float(ellipk(m))
    points = [0.0, 1e-300, 1e-12, 1e-6, 0.5, k - 1e-6, k * (1.0 - 1e-15), k, k * (1.0 + 1e-15), k + 1e-6,
              -k, 2.0 * k, 3.0 * k - 1e-9, 29.9, -30.0]
    for u in points:
        ours = jacobi(u, m)
        exact = _mp_jacobi(u, m)
        bound = mpmath_tolerance(u)
        assert abs(ours[0] - exact[0]) <= bound, ("sn", u, m, ours[0], exact[0])
        assert abs(ours[1] - exact[1]) <= bound, ("cn", u, m, ours[1], exact[1])
        assert abs(ours[2] - exact[2]) <= max(bound, dn_tolerance(m)), ("dn", u, m, ours[2], exact[2])
        # dn's relative error stays small wherever dn is (the sampler divides by it)
        assert abs(ours[2] - exact[2]) <= bound + 16.0 * EPS * exact[2] / (1.0 - m), ("dn rel", u, m)
    # known values: sn(K) = 1, cn(K) = 0, dn(K) = √(1 − m)
    sn, cn, dn = jacobi(k, m)
    assert abs(sn - 1.0) <= 4 * EPS and abs(cn) <= 1e-14
    assert abs(dn - math.sqrt(1.0 - m)) <= dn_tolerance(m)


def test_jacobi_matches_mpmath_on_random_arguments(rng):
    """1,000 random (u, m) against 30-digit mpmath: the independent check of the bulk."""
    u = rng.uniform(-30.0, 30.0, 1000)
    m = np.concatenate((
        rng.uniform(0.0, M_TOP, 500), 10.0 ** rng.uniform(-12.0, -1.0, 250), 1.0 - 10.0 ** rng.uniform(-9.0, -1.0, 250)
    ))
    worst = [0.0, 0.0, 0.0]
    for a, b in zip(u, m):
        ours, exact = jacobi(a, b), _mp_jacobi(a, b)
        common = mpmath_tolerance(a)
        for i, bound in enumerate((common, common, max(common, dn_tolerance(b)))):
            error = abs(ours[i] - exact[i])
            worst[i] = max(worst[i], error)
            assert error <= bound, (("sn", "cn", "dn")[i], a, b, ours[i], exact[i])
    print(f"jacobi vs mpmath (random): worst sn {worst[0]:.3g}, cn {worst[1]:.3g}, dn {worst[2]:.3g}")


# ---------------------------------------------------------------------------------------------
# shift


@pytest.mark.parametrize("m", [0.0, 1e-12, 0.3, 0.7, 0.9, 0.99, 0.999999])
def test_shift_carries_128_steps(m, rng):
    """sn, cn, dn carried 128 steps of h from u₀ stay within SHIFT_TOL of jacobi(u₀ + k·h).

    h is what the sampler uses, √C/rate: from 1e-5 up to 0.05 (C = 1133 s⁻², the geometry model
    at a = 2000 m/s², sampled at 777.7 Hz, gives h = 0.043).
    """
    worst = 0.0
    for _ in range(20):
        u0 = rng.uniform(-10.0, 10.0)
        h = 10.0 ** rng.uniform(-5.0, math.log10(0.05))
        step = jacobi(h, m)
        carried = jacobi(u0, m)
        for k in range(1, 129):
            carried = shift(*carried, *step, m)
            direct = jacobi(u0 + k * h, m)
            error = max(abs(a - b) for a, b in zip(carried, direct))
            worst = max(worst, error)
            assert error <= SHIFT_TOL, (m, u0, h, k, carried, direct)
    print(f"shift m = {m}: worst {worst:.3g}")


def test_shift_matches_mpmath():
    """The carried values at the 128th step against 30-digit mpmath (not only against jacobi)."""
    for m, u0, h in [(0.5, -1.3, 0.02), (0.9, 0.4, 0.013), (0.999999, -7.0, 0.05), (1e-10, 2.0, 0.01)]:
        carried = jacobi(u0, m)
        step = jacobi(h, m)
        for _ in range(128):
            carried = shift(*carried, *step, m)
        with mp.workdps(30):
            uu = mp.mpf(u0) + 128 * mp.mpf(h)
            exact = [float(mp.ellipfun(kind, uu, m=mp.mpf(m))) for kind in ("sn", "cn", "dn")]
        assert max(abs(a - b) for a, b in zip(carried, exact)) <= SHIFT_TOL, (m, u0, h, carried, exact)


def test_shift_by_zero_and_by_k_are_exact_identities():
    for m in (0.2, 0.8):
        k = float(ellipk(m))
        for u in (-0.7, 0.3, 1.9):
            here = jacobi(u, m)
            assert max(abs(a - b) for a, b in zip(shift(*here, *jacobi(0.0, m), m), here)) <= 2 * EPS
            # u + K: sn = cd(u), cn = −√(1−m)·sd(u), dn = √(1−m)/dn(u) (DLMF 22.4.3)
            sn, cn, dn = shift(*here, *jacobi(k, m), m)
            s, c, d = here
            r = math.sqrt(1.0 - m)
            assert abs(sn - c / d) <= 1e-14 and abs(cn + r * s / d) <= 1e-14 and abs(dn - r / d) <= 1e-14


# ---------------------------------------------------------------------------------------------
# time_from_apex and flight_time


def _mp_time_from_apex(sin_theta, sin_apex, c):
    """docs/model.md: [K(m) − F(ψ(θ) | m)]/√C, m = (1 + sin θ_a)/2, ψ = asin(√((1 + sin θ)/(1 + sin θ_a))).

    Arguments are mpf (exact); evaluated at 60 digits, which leaves ≥ 30 after the cancellation
    K − F at ψ → π/2 (launches of 1e-8 rad/s: 1 − sin²ψ ~ 1e-18).
    """
    with mp.workdps(60):
        m = (1 + sin_apex) / 2
        psi = mp.asin(mp.sqrt((1 + sin_theta) / (1 + sin_apex)))
        return (mp.ellipk(m) - mp.ellipf(psi, m)) / mp.sqrt(c)


def _exact_orbit(sin_theta, omega, c):
    """sin θ_a = sin θ + ω²/(2C) (docs/model.md), exact from the float inputs."""
    with mp.workdps(60):
        return mp.mpf(sin_theta) + mp.mpf(omega) ** 2 / (2 * mp.mpf(c))


def _relative(ours, exact):
    return abs(float((mp.mpf(ours) - exact) / exact))


def _draw_state(rng):
    """A state (sin θ, ω, C) in flight, θ in [θ_max, 1.5], with 1 − m ≥ 1e-4.

    Closer to the vertical the time from the apex is ill-conditioned in the state: m rounded to
    double moves it by ~ε/(2(1 − m)·K(m)) relative (5e-9 at 1 − m = 1e-9), whichever way it is
    computed; test_time_from_apex_near_vertical_orbits covers those orbits, fixed by m.
    """
    while True:
        c = 10.0 ** rng.uniform(0.0, 4.0)  # s⁻²: the paper model's 10.3 to well past the geometry model's 1133
        theta = rng.uniform(HEAD, 1.5)
        omega = rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-6.0, 2.0)
        if parameter(math.sin(theta), omega, c) <= 1.0 - 1e-4:
            return math.sin(theta), omega, c


def test_parameter_is_spec_m_to_round_off(rng):
    for _ in range(2000):
        sin_theta, omega, c = _draw_state(rng)
        exact = (1 + _exact_orbit(sin_theta, omega, c)) / 2
        assert _relative(parameter(sin_theta, omega, c), exact) <= 4 * EPS


def test_time_from_apex_matches_mpmath_on_random_states(rng):
    worst = 0.0
    for _ in range(400):
        sin_theta, omega, c = _draw_state(rng)
        m = parameter(sin_theta, omega, c)
        exact = _mp_time_from_apex(mp.mpf(sin_theta), _exact_orbit(sin_theta, omega, c), mp.mpf(c))
        error = _relative(time_from_apex(sin_theta, omega, c, m), exact)
        worst = max(worst, error)
        assert error <= TIME_RTOL, (sin_theta, omega, c, m, time_from_apex(sin_theta, omega, c, m), exact)
    print(f"time_from_apex random: worst relative {worst:.3g}")


@pytest.mark.parametrize("c", [10.294117647058822, 40.16393442622951, 1133.0601092896175, 5e5])
@pytest.mark.parametrize("launch", [1e-8, 1e-6, 1e-4, 1e-2, 1.0, 5.0])
def test_flight_time_matches_mpmath_for_small_and_tiny_launches(c, launch):
    """Launches from the head down to 1e-8 rad/s (the Zeno floor is 1e-6): K − F cancels to ~1e-14 of K."""
    sin_head = math.sin(HEAD)
    if parameter(sin_head, launch, c) >= M_TOP:
        launch = 0.5 * launch  # (5 rad/s under C = 10 reaches the vertical)
    duration, m = flight_time(launch, c, sin_head)
    sin_apex = _exact_orbit(sin_head, launch, c)
    exact = 2 * _mp_time_from_apex(mp.mpf(sin_head), sin_apex, mp.mpf(c))
    assert _relative(duration, exact) <= TIME_RTOL, (launch, c, duration, exact)
    print(f"flight_time L = {launch:g}, C = {c:g}: relative {_relative(duration, exact):.3g}")
    assert _relative(m, (1 + sin_apex) / 2) <= 2 * EPS
    # and the rise alone, from the head and from the apex side (ω > 0 and ω < 0 give the same |τ|)
    for omega in (launch, -launch):
        assert _relative(time_from_apex(sin_head, omega, c, m), exact / 2) <= TIME_RTOL
    # small-bounce limit: 2L/(C·cos θ_max)·(1 + O(L²))
    if launch <= 1e-4:
        assert abs(duration / (2 * launch / (c * math.cos(HEAD))) - 1.0) < 1e-6


@pytest.mark.parametrize("gap", [1e-9, 3e-9, 1e-8, 1e-7, 1e-5, 1e-3])
def test_time_from_apex_near_vertical_orbits(gap, rng):
    """Orbits with 1 − m = gap down to 1e-9, the solver's limit, from the head and from random θ.

    Near the vertical |τ| depends on the orbit through K(m) ~ ln(4/√(1 − m)): a change of m by
    one ulp changes |τ| by ~ε/(1 − m), 1e-7 relative at 1 − m = 1e-9. That is the conditioning of
    the state itself, not an error of the function, so here the orbit is fixed by the float m
    (the input the function trusts for the distance to the vertical) and ω is its speed at θ,
    √(2C(2m − 1 − sin θ)) rounded to double; the oracle uses sin θ_a = 2m − 1 exactly.
    """
    m = 1.0 - gap
    worst = 0.0
    for i in range(20):
        c = 10.0 ** rng.uniform(0.0, 4.0)
        sin_theta = math.sin(HEAD) if i == 0 else math.sin(rng.uniform(HEAD, 1.5))
        sin_apex = 2 * mp.mpf(m) - 1
        if sin_theta >= sin_apex:
            continue
        with mp.workdps(40):
            omega = float(mp.sqrt(2 * mp.mpf(c) * (sin_apex - mp.mpf(sin_theta))))
        exact = _mp_time_from_apex(mp.mpf(sin_theta), sin_apex, mp.mpf(c))
        error = _relative(time_from_apex(sin_theta, omega, c, m), exact)
        worst = max(worst, error)
        assert error <= TIME_RTOL, (gap, sin_theta, omega, c, error)
    # flight_time from the head: its m is computed, so the oracle is the orbit it reports, and that
    # m must be the launch's to round-off.
    c = 40.16393442622951
    sin_head = math.sin(HEAD)
    with mp.workdps(40):
        launch = float(mp.sqrt(2 * mp.mpf(c) * (2 * mp.mpf(m) - 1 - mp.mpf(sin_head))))
    duration, m_used = flight_time(launch, c, sin_head)
    assert _relative(m_used, (1 + _exact_orbit(sin_head, launch, c)) / 2) <= 2 * EPS
    exact = 2 * _mp_time_from_apex(mp.mpf(sin_head), 2 * mp.mpf(m_used) - 1, mp.mpf(c))
    assert _relative(duration, exact) <= TIME_RTOL, (gap, duration, exact)
    print(f"time_from_apex 1 − m = {gap:g}: worst relative {worst:.3g}, flight {_relative(duration, exact):.3g}")


# ---------------------------------------------------------------------------------------------
# state


def _mp_theta(tau, c, m):
    """docs/model.md: θ(τ) = 2·asin(√m·sn(K(m) − √C·τ | m)) − π/2 and its derivative, at 40 digits.

    dθ/dτ = −2√(mC)·cn·dn/√(1 − m·sn²) = −2√(mC)·cn(K − √C·τ | m), since dn² = 1 − m·sn².
    """
    with mp.workdps(40):
        mm, cc = mp.mpf(m), mp.mpf(c)
        v = mp.ellipk(mm) - mp.sqrt(cc) * mp.mpf(tau)
        theta = 2 * mp.asin(mp.sqrt(mm) * mp.ellipfun("sn", v, m=mm)) - mp.pi / 2
        return theta, -2 * mp.sqrt(mm * cc) * mp.ellipfun("cn", v, m=mm)


def theta_tolerance(m):
    """θ = 2·asin(x) − π/2 with x = √m·cd ≤ √m: near the apex of an orbit close to the vertical
    d asin/dx = 1/√(1 − x²) ≥ 1/√(1 − m) magnifies x's round-off."""
    return THETA_TOL + 8.0 * EPS / math.sqrt(1.0 - m)


def energy_tolerance(m):
    return max(ENERGY_RTOL, 8.0 * EPS / math.sqrt(1.0 - m))


def _to_head(c, m):
    """Time (s) from the apex to the head on orbit m (scipy, docs/model.md), or K(m)/√C if it never rises above it."""
    sin_head, sin_apex = math.sin(HEAD), 2.0 * m - 1.0
    if sin_apex <= sin_head:
        return float(ellipk(m)) / math.sqrt(c)
    psi = math.asin(math.sqrt((1.0 + sin_head) / (1.0 + sin_apex)))
    return float(ellipk(m) - ellipkinc(psi, m)) / math.sqrt(c)


def _draw_orbit(rng):
    c = 10.0 ** rng.uniform(0.0, 4.0)
    m = rng.choice([rng.uniform(0.0, M_TOP), 1.0 - 10.0 ** rng.uniform(-9.0, -1.0), 10.0 ** rng.uniform(-12, -1)])
    return c, m


def test_state_conserves_energy_and_starts_at_the_apex(rng):
    worst_energy = worst_apex = 0.0
    for _ in range(500):
        c, m = _draw_orbit(rng)
        # the apex: θ = θ_a with sin θ_a = 2m − 1, i.e. θ_a = 2·asin(√m) − π/2, and ω = 0
        theta, omega = state(0.0, c, m)
        with mp.workdps(40):
            apex = 2 * mp.asin(mp.sqrt(mp.mpf(m))) - mp.pi / 2
            assert abs(mp.sin(apex) - (2 * mp.mpf(m) - 1)) < mp.mpf(10) ** -35  # the algebra of docs/model.md
        error = abs(float(theta - apex))
        worst_apex = max(worst_apex, error)
        assert error <= theta_tolerance(m), (c, m, theta, apex)
        assert omega == 0.0
        # energy along the orbit above the head, |τ| ≤ the time from the apex to the head
        # (the whole half-orbit |τ| ≤ K/√C for the orbits below the head)
        span = _to_head(c, m)
        for tau in [span, -span, *rng.uniform(-span, span, 8)]:
            theta, omega = state(tau, c, m)
            energy = 0.5 * omega * omega + c * math.sin(theta)
            error = abs(energy - c * (2.0 * m - 1.0)) / c  # relative to C: E itself is 0 at m = 1/2
            worst_energy = max(worst_energy, error)
            assert error <= energy_tolerance(m), (c, m, tau, theta, omega, error)
            # ω < 0 after the apex (falling), > 0 before
            assert omega * tau <= 0.0
    print(f"state: worst energy {worst_energy:.3g}·C, worst apex {worst_apex:.3g} rad")


def test_state_matches_spec_theta_in_mpmath(rng):
    """θ(τ) against docs/model.md's sn(K − √C·τ) form on the part of each orbit above the head, and ω
    against its derivative, ω = −2√(mC)·cn(K − √C·τ | m)."""
    worst = worst_omega = 0.0
    for _ in range(150):
        c, m = _draw_orbit(rng)
        if 2.0 * m - 1.0 <= math.sin(HEAD):
            continue  # the orbit never rises above the head
        # time from the apex to the head on this orbit (the mpmath oracle above)
        to_head = float(_mp_time_from_apex(mp.mpf(math.sin(HEAD)), 2 * mp.mpf(m) - 1, mp.mpf(c)))
        for tau in [0.0, to_head, -to_head, *rng.uniform(-to_head, to_head, 4)]:
            theta, omega = state(tau, c, m)
            exact, exact_omega = _mp_theta(tau, c, m)
            error = abs(float(theta - exact))
            worst = max(worst, error)
            assert error <= theta_tolerance(m), (c, m, tau, theta, exact)
            # ω's absolute error scales with √C (the time scale) and the same ε/√(1 − m) near the vertical
            error = abs(float(omega - exact_omega)) / math.sqrt(c)
            worst_omega = max(worst_omega, error)
            assert error <= 2.0 * theta_tolerance(m), (c, m, tau, omega, exact_omega)
        # at ±to_head the stick is at the head
        assert abs(state(to_head, c, m)[0] - HEAD) <= theta_tolerance(m) + 1e-13
    print(f"state vs the docs' θ(τ): worst θ {worst:.3g} rad, ω {worst_omega:.3g}·√C rad/s")


def test_jacobi_pair_is_two_calls_of_jacobi_with_to_the_bit(rng):
    """The sampler's two descents side by side give each one's numbers (m near 0, mid, near 1; u large and small)."""
    from drumstroke.solver.elliptic import agm_scratch, jacobi_pair, jacobi_with

    agm = agm_scratch()
    for _ in range(2000):
        m = float(rng.choice([rng.uniform(0.0, 1e-9), rng.uniform(0.0, 1.0), 1.0 - 10.0 ** rng.uniform(-9.0, -1.0)]))
        u, w = rng.uniform(-12.0, 12.0), rng.uniform(-0.1, 0.1)
        pair = jacobi_pair(u, w, m, agm)
        alone = jacobi_with(u, m, agm_scratch()) + jacobi_with(w, m, agm_scratch())
        assert np.array_equal(np.array(pair).view(np.uint64), np.array(alone).view(np.uint64)), (u, w, m)
