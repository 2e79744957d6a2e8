"""The listening test's statistics: Tryon's inferential confidence intervals, as in the paper.

Responses are one row per subject and pair: who answered, which pair, which
stimulus was the robot, the answer to "which is the robot?", the confidence
(1–5) and the similarity (1–5). From them:

- Group A: the number of incorrect answers per subject (answer ≠ robot).
- Group B: subjects who cannot tell robot from human, guessing 50–50 on the same
  number of pairs — simulated (seeded), its descriptive statistics averaged over
  many runs as the paper did. For n pairs its mean tends to n/2 and its SD to √(n/4).
- Tryon's reduction factor (paper Eq. 8), with S the standard errors,
  t_pq the two-sided critical t for the difference (df = N_p + N_q − 2) and t_p
  that of one group (df = N_p − 1)::

      E = √(S_p² + S_q²) / (S_p + S_q) · t_pq / t_p

  the inferential confidence intervals m ± t_p·E·S, and the maximum probable
  difference (Eq. 9) Rg = |m_q − m_p| + t_p·E·(S_p + S_q), in answers and in %
  of the pairs. The groups are equivalent within Δ when Rg < Δ.
- Two equivalence tests within ±Δ, each named for what it is. Both are two one-sided t tests
  of the difference m_b − m_a against −Δ and +Δ (df = N_a + N_b − 2); they differ in the level
  of each side (and, when N_a ≠ N_b, in the standard error):

  - **Tryon's ICI test** (the paper's): each side at α/2. It decides exactly as Rg < Δ does,
    since t_p·E·(S_p + S_q) = t_pq·√(S_p² + S_q²) is the half-width of the difference's
    two-sided 1 − α interval; its standard error is Tryon's √(S_p² + S_q²) (:meth:`Tryon.ici_test`).
  - **Schuirmann's TOST** (the standard one, as statsmodels' ``ttost_ind`` and pingouin's
    ``tost`` compute it): each side at α, i.e. the difference's 1 − 2α interval inside ±Δ, with
    Student's pooled standard error (equal to Tryon's when N_a = N_b) (:meth:`Tryon.tost`). It is the less strict of the two and can decide "equivalent" where
    Rg ≥ Δ: on the paper's Table 2 at Δ = 2 answers, Rg = 2.097 but the 90 % interval ends at 1.879.

- Pearson and Spearman correlations (with p-values) of a subject's incorrect
  answers with their mean confidence and with their mean similarity rating.

Examples
--------
>>> result = from_summary(4.227, 2.654, 4.999, 1.564, 22, pairs=10)
>>> round(result.rg_percent, 2)  # the paper's 20.99 % (see the README for the roundings)
20.97
>>> result.ici_test(2.0).equivalent, result.tost(2.0).equivalent  # Rg = 2.097 answers
(False, True)
"""

import math
from dataclasses import asdict, dataclass

import numpy as np

from .._checks import check_int, check_real
from ..errors import ParameterError
from ..formats.responses_csv import COLUMNS, read_responses_csv

ALPHA = 0.05

CHOICES = ("A", "B")


@dataclass(frozen=True)
class Group:
    """Descriptive statistics of incorrect answers per subject."""

    mean: float
    sd: float
    n: int

    @property
    def se(self):
        """Standard error of the mean, SD/√N."""
        return self.sd / math.sqrt(self.n)


@dataclass(frozen=True)
class Tryon:
    """Tryon's inferential confidence intervals for two groups and what follows from them.

    Attributes
    ----------
    a, b : Group
        Group A (the listeners) and Group B (indistinguishable, simulated).
    pairs : int
        Pairs each subject judged (for Rg in %).
    alpha : float
    t_pq, t_p, t_q : float
        Two-sided critical t values: the difference (df N_a + N_b − 2) and each group (df N − 1).
    e : float
        Tryon's reduction factor.
    ici_a, ici_b : tuple of float
        The inferential confidence intervals (answers).
    rg : float
        The maximum probable difference (answers).
    """

    a: Group
    b: Group
    pairs: int
    alpha: float
    t_pq: float
    t_p: float
    t_q: float
    e: float
    ici_a: tuple
    ici_b: tuple
    rg: float

    @property
    def rg_percent(self):
        """Rg in % of the pairs."""
        return 100.0 * self.rg / self.pairs

    def equivalent(self, delta):
        """Whether the groups are equivalent within ``delta`` (answers): Rg < Δ."""
        delta = check_real("delta", delta, low=0.0, low_open=True, unit="answers")
        return self.rg < delta

    def ici_test(self, delta):
        """Tryon's ICI test within ±``delta`` (answers), each side at α/2: the paper's Rg < Δ (an :class:`Equivalence`)."""
        se = math.sqrt(self.a.se**2 + self.b.se**2)  # Tryon's: so that it decides exactly as Rg < Δ
        return _two_one_sided(self, delta, se, side_alpha=self.alpha / 2, test="Tryon's ICI test")

    def tost(self, delta):
        """Schuirmann's standard TOST within ±``delta`` (answers), each side at α (an :class:`Equivalence`)."""
        a, b = self.a, self.b
        pooled = ((a.n - 1) * a.sd**2 + (b.n - 1) * b.sd**2) / (a.n + b.n - 2)
        se = math.sqrt(pooled * (1.0 / a.n + 1.0 / b.n))  # Student's pooled SE, as statsmodels' default
        return _two_one_sided(self, delta, se, side_alpha=self.alpha, test="Schuirmann's TOST")

    def to_dict(self):
        """Plain data for JSON."""
        data = asdict(self)
        data.update(rg_percent=self.rg_percent, se_a=self.a.se, se_b=self.b.se)
        return data


@dataclass(frozen=True)
class Equivalence:
    """The verdict of two one-sided t tests of the difference of means against ±Δ.

    Attributes
    ----------
    test : str
        "Tryon's ICI test" (each side at α/2) or "Schuirmann's TOST" (each side at α).
    delta : float
        The margin Δ (answers).
    side_alpha : float
        The level of each one-sided test.
    difference : float
        m_b − m_a (answers).
    p_lower, p_upper : float
        One-sided p-values against H0: difference ≤ −Δ and H0: difference ≥ +Δ.
    interval : tuple of float
        The difference's two-sided 1 − 2·side_alpha confidence interval (answers): equivalence
        is this interval inside (−Δ, +Δ).
    equivalent : bool
        Both one-sided tests reject: max(p_lower, p_upper) < side_alpha.
    """

    test: str
    delta: float
    side_alpha: float
    difference: float
    p_lower: float
    p_upper: float
    interval: tuple
    equivalent: bool

    @property
    def p(self):
        """The test's p-value, max(p_lower, p_upper), compared with ``side_alpha``."""
        return max(self.p_lower, self.p_upper)

    @property
    def level(self):
        """The confidence level of ``interval``, 1 − 2·side_alpha."""
        return 1.0 - 2.0 * self.side_alpha

    def to_dict(self):
        """Plain data for JSON."""
        return {**asdict(self), "p": self.p, "level": self.level}


def _two_one_sided(result, delta, se, *, side_alpha, test):
    """Two one-sided t tests of m_b − m_a against ±``delta`` with standard error ``se``, df = N_a + N_b − 2."""
    from scipy import stats

    delta = check_real("delta", delta, low=0.0, low_open=True, unit="answers")
    a, b = result.a, result.b
    df = a.n + b.n - 2
    if se == 0.0:
        raise ParameterError("both groups have SD 0: the t tests are undefined")
    diff = b.mean - a.mean
    p_lower = float(stats.t.sf((diff + delta) / se, df))
    p_upper = float(stats.t.cdf((diff - delta) / se, df))
    half = float(stats.t.ppf(1.0 - side_alpha, df)) * se
    return Equivalence(test, delta, side_alpha, diff, p_lower, p_upper, (diff - half, diff + half),
                       max(p_lower, p_upper) < side_alpha)


def tryon(a, b, *, pairs, alpha=ALPHA):
    """:class:`Tryon` statistics for Group ``a`` against Group ``b`` (each a :class:`Group`)."""
    from scipy import stats

    alpha = check_real("alpha", alpha, low=0.0, high=0.5, low_open=True, high_open=True)
    pairs = check_int("pairs", pairs, low=1)
    for name, g in (("a", a), ("b", b)):
        if g.n < 2:
            raise ParameterError(f"group {name} needs at least 2 subjects, got {g.n}")
    t_pq = float(stats.t.ppf(1 - alpha / 2, a.n + b.n - 2))
    t_p = float(stats.t.ppf(1 - alpha / 2, a.n - 1))
    t_q = float(stats.t.ppf(1 - alpha / 2, b.n - 1))
    return tryon_with(a, b, pairs=pairs, alpha=alpha, t_pq=t_pq, t_p=t_p, t_q=t_q)


def tryon_with(a, b, *, pairs, alpha, t_pq, t_p, t_q):
    """:func:`tryon` with given critical t values (the paper's rounded 2.0181 and 2.0796, say)."""
    se_a, se_b = a.se, b.se
    if se_a + se_b == 0.0:
        raise ParameterError("both groups have SD 0: Tryon's factor is undefined")
    e = math.sqrt(se_a**2 + se_b**2) / (se_a + se_b) * t_pq / t_p
    ici_a = (a.mean - t_p * e * se_a, a.mean + t_p * e * se_a)
    ici_b = (b.mean - t_q * e * se_b, b.mean + t_q * e * se_b)
    rg = abs(b.mean - a.mean) + t_p * e * (se_a + se_b)
    return Tryon(a, b, pairs, alpha, t_pq, t_p, t_q, e, ici_a, ici_b, rg)


def from_summary(mean_a, sd_a, mean_b, sd_b, n, *, pairs=10, alpha=ALPHA):
    """Tryon statistics from two groups' means and SDs with ``n`` subjects each (the paper's Table 2)."""
    n = check_int("n", n, low=1)
    a = Group(check_real("mean_a", mean_a, low=0.0), check_real("sd_a", sd_a, low=0.0), n)
    b = Group(check_real("mean_b", mean_b, low=0.0), check_real("sd_b", sd_b, low=0.0), n)
    return tryon(a, b, pairs=pairs, alpha=alpha)


def simulate_guessing(subjects, pairs, *, runs=1000, seed=0):
    """Group B: ``subjects`` guessing 50–50 on ``pairs`` pairs, averaged over ``runs`` (a Group).

    The mean is the runs' mean; the SD the square root of the runs' mean (unbiased)
    variance, which tends to √(pairs/4). (Averaging the runs' SDs instead tends to
    c₄·√(pairs/4), 1.562 for 22 subjects and 10 pairs: the paper's 1.564.)
    """
    subjects, pairs = check_int("subjects", subjects, low=1), check_int("pairs", pairs, low=1)
    runs = check_int("runs", runs, low=1)
    rng = np.random.default_rng(seed)
    wrong = rng.binomial(pairs, 0.5, size=(runs, subjects))
    variance = wrong.var(axis=1, ddof=1) if subjects > 1 else np.zeros(runs)
    return Group(float(wrong.mean(axis=1).mean()), float(math.sqrt(variance.mean())), subjects)


@dataclass(frozen=True)
class Responses:
    """Raw responses, one row per subject × pair."""

    subject: tuple
    pair: tuple
    robot: tuple
    answer: tuple
    confidence: np.ndarray
    similarity: np.ndarray

    @property
    def subjects(self):
        """The subjects in order of first appearance."""
        return tuple(dict.fromkeys(self.subject))

    def per_subject(self):
        """Per subject: incorrect answers, mean confidence, mean similarity [shape=(subjects,) each]."""
        index = {s: i for i, s in enumerate(self.subjects)}
        k = np.array([index[s] for s in self.subject])
        wrong = np.array([a != r for a, r in zip(self.answer, self.robot)], dtype=float)
        count = np.bincount(k)
        return (np.bincount(k, wrong), np.bincount(k, self.confidence) / count,
                np.bincount(k, self.similarity) / count)


def read_responses(path):
    """Read a responses CSV with the header ``subject,pair,robot,answer,confidence,similarity``.

    robot and answer are A or B; confidence and similarity integers 1–5. Every
    subject must judge the same pairs, each once. Errors name the line.
    """
    return parse_responses(read_responses_csv(path), name=str(path))


def parse_responses(rows, *, name="responses"):
    """:class:`Responses` from rows of (subject, pair, robot, answer, confidence, similarity)."""
    columns = {c: [] for c in COLUMNS}
    seen = set()
    for number, row in enumerate(rows, start=2):
        where = f"{name} line {number}"
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) != len(COLUMNS):
            raise ParameterError(f"{where}: expected {len(COLUMNS)} fields ({','.join(COLUMNS)}), got {len(row)}")
        subject, pair, robot, answer, confidence, similarity = (c.strip() for c in row)
        if not subject or not pair:
            raise ParameterError(f"{where}: subject and pair must not be empty")
        for key, value in (("robot", robot), ("answer", answer)):
            if value not in CHOICES:
                raise ParameterError(f"{where}: {key} must be A or B, got {value!r}")
        for key, value in (("confidence", confidence), ("similarity", similarity)):
            if value not in ("1", "2", "3", "4", "5"):
                raise ParameterError(f"{where}: {key} must be an integer in [1, 5], got {value!r}")
        if (subject, pair) in seen:
            raise ParameterError(f"{where}: subject {subject!r} answered pair {pair!r} twice")
        seen.add((subject, pair))
        for key, value in zip(COLUMNS, (subject, pair, robot, answer, int(confidence), int(similarity))):
            columns[key].append(value)
    if not columns["subject"]:
        raise ParameterError(f"{name} has no responses")
    pairs_of = {}
    for s, p in zip(columns["subject"], columns["pair"]):
        pairs_of.setdefault(s, set()).add(p)
    first = next(iter(pairs_of.values()))
    for s, ps in pairs_of.items():
        if ps != first:
            raise ParameterError(f"{name}: subject {s!r} judged {len(ps)} pairs, not the same {len(first)} as the "
                                 "first subject")
    return Responses(tuple(columns["subject"]), tuple(columns["pair"]), tuple(columns["robot"]),
                     tuple(columns["answer"]), np.array(columns["confidence"], float),
                     np.array(columns["similarity"], float))


@dataclass(frozen=True)
class Analysis:
    """Everything :func:`analyze` finds."""

    incorrect: np.ndarray
    tryon: Tryon
    correlations: dict
    runs: int
    seed: int

    def to_dict(self):
        """Plain data for JSON."""
        return {"incorrect": self.incorrect.tolist(), "tryon": self.tryon.to_dict(), "correlations": self.correlations,
                "group_b": {"runs": self.runs, "seed": self.seed}}


def analyze(responses, *, alpha=ALPHA, runs=1000, seed=0):
    """Group A from ``responses`` against simulated Group B; Tryon statistics and correlations."""
    from scipy import stats

    wrong, confidence, similarity = responses.per_subject()
    n = len(wrong)
    if n < 2:
        raise ParameterError(f"the responses need at least 2 subjects, got {n}")
    pairs = len(set(responses.pair))
    a = Group(float(wrong.mean()), float(wrong.std(ddof=1)), n)
    b = simulate_guessing(n, pairs, runs=runs, seed=seed)
    correlations = {}
    for name, values in (("confidence", confidence), ("similarity", similarity)):
        for method, test in (("pearson", stats.pearsonr), ("spearman", stats.spearmanr)):
            if np.ptp(values) == 0 or np.ptp(wrong) == 0:
                correlations[f"{name}_{method}"] = {"r": None, "p": None, "note": "a constant column"}
                continue
            result = test(wrong, values)
            correlations[f"{name}_{method}"] = {"r": float(result[0]), "p": float(result[1])}
    return Analysis(wrong, tryon(a, b, pairs=pairs, alpha=alpha), correlations, runs, seed)

