"""``drumstroke stats``: the listening test's statistics — Tryon's inferential CIs, Rg, two equivalence tests."""

from ..errors import ParameterError
from ..formats import json
from ._options import Output, add_mkdir, existing_file, number, whole


def add_stats(sts):
    """Give ``stats``'s parser ``sts`` its description and options."""
    sts.description = ("The listening test's statistics from its answers (a CSV) or from two groups' summary numbers: "
                       "Group A (incorrect answers per subject) against Group B (subjects guessing 50-50), Tryon's "
                       "inferential confidence intervals and the maximum probable difference Rg (the paper's Table 2); "
                       "with --delta, Tryon's ICI test (each side at alpha/2, the paper's Rg < delta) and Schuirmann's "
                       "standard TOST (each side at alpha), each with its p-value; correlations of the answers with "
                       "confidence and similarity.")
    sts.add_argument("responses", type=existing_file, nargs="?", metavar="RESPONSES",
                     help="a CSV with subject,pair,robot,answer,confidence,similarity")
    sts.add_argument("--summary", metavar="MEAN_A,SD_A,MEAN_B,SD_B,N",
                     help="use two groups' summary numbers instead (e.g. the paper's 4.227,2.654,4.999,1.564,22)")
    sts.add_argument("--pairs", type=whole(low=1), default=10, help="pairs per subject for --summary (default 10)")
    sts.add_argument("--delta", type=number(low=0.0, low_open=True, unit="answers"), metavar="D",
                     help="equivalence margin in answers, > 0: run both equivalence tests (default: none)")
    sts.add_argument("--alpha", type=number(low=0.0, high=0.5, low_open=True, high_open=True), default=0.05,
                     help="significance level, in (0, 0.5) (default 0.05)")
    sts.add_argument("--seed", type=whole(low=0), default=0, help="seed of the simulated Group B, >= 0 (default 0)")
    sts.add_argument("--json", action=Output, suffixes=json.SUFFIXES, metavar="OUT", help="write the statistics as .json")
    add_mkdir(sts)
    sts.set_defaults(run=_stats)


def _stats(args):
    from ..evaluation import stats

    if (args.responses is None) == (args.summary is None):
        raise ParameterError("give either RESPONSES (a CSV) or --summary MEAN_A,SD_A,MEAN_B,SD_B,N")
    if not args.summary:
        return print_analysis(args, stats.read_responses(args.responses))
    try:
        mean_a, sd_a, mean_b, sd_b, n = (float(x) for x in args.summary.split(","))
    except ValueError:
        raise ParameterError(f"--summary must be MEAN_A,SD_A,MEAN_B,SD_B,N, got {args.summary!r}") from None
    if not n.is_integer():
        raise ParameterError(f"--summary's N must be a whole number of subjects, got {n:g}")
    try:
        result = stats.from_summary(mean_a, sd_a, mean_b, sd_b, int(n), pairs=args.pairs, alpha=args.alpha)
    except ParameterError as error:
        raise ParameterError(f"--summary: {error}") from None
    data = result.to_dict()
    _print_result(args, result, data)
    _write_json(args, data)


def print_analysis(args, responses):
    """Analyse ``responses`` and print the two groups, Rg, TOST (with ``args.delta``) and the correlations.

    ``args`` may lack ``alpha`` and ``seed`` (``listen analyze`` has neither): the defaults are used.
    """
    from ..evaluation import stats

    analysis = stats.analyze(responses, alpha=getattr(args, "alpha", stats.ALPHA), seed=getattr(args, "seed", 0))
    data = analysis.to_dict()
    _print_result(args, analysis.tryon, data)
    for key, value in data["correlations"].items():
        r = "n/a" if value["r"] is None else f"r = {value['r']:+.3f}, p = {value['p']:.3g}"
        print(f"incorrect answers vs {key.replace('_', ' ')}: {r}")
    _write_json(args, data)


def _print_result(args, result, data):
    a, b = result.a, result.b
    print(f"{'':<26}{'Group A':>10}{'Group B':>10}")
    for label, x, y in (("mean incorrect answers", a.mean, b.mean), ("SD", a.sd, b.sd), ("SE = SD/sqrt(N)", a.se, b.se)):
        print(f"{label:<26}{x:>10.3f}{y:>10.3f}")
    print(f"{'N':<26}{a.n:>10}{b.n:>10}")
    ici_a, ici_b = (f"{lo:.3f}-{hi:.3f}" for lo, hi in (result.ici_a, result.ici_b))
    print(f"{'inferential CI':<26}{ici_a:>12}{ici_b:>12}")
    print(f"t_pq = {result.t_pq:.4f}, t_p = {result.t_p:.4f} (alpha {result.alpha:g}); E = {result.e:.4f}")
    print(f"maximum probable difference Rg = {result.rg:.4f} answers = {result.rg_percent:.2f} % of {result.pairs} "
          "pairs")
    if args.delta is not None:
        ici, tost = result.ici_test(args.delta), result.tost(args.delta)
        print(f"equivalence within delta = {args.delta:g} answers (difference B - A = {ici.difference:.3f}):")
        for test, how in ((ici, "the paper's: Rg < delta"), (tost, "the standard one")):
            low, high = test.interval
            verdict = "equivalent" if test.equivalent else "not shown equivalent"
            print(f"  {test.test} ({how}; each side at {test.side_alpha:g}): {verdict}, p = {test.p:.4g} "
                  f"({'<' if test.equivalent else '>='} {test.side_alpha:g}); {100 * test.level:g} % CI of the "
                  f"difference {low:.3f} to {high:.3f}")
        # tost_p and tost_equivalent keep their first meaning: the one-sided p-values and Tryon's decision
        data["delta"] = {"delta": args.delta, "equivalent": result.equivalent(args.delta),
                         "tost_p": [ici.p_lower, ici.p_upper], "tost_equivalent": ici.equivalent,
                         "ici_test": ici.to_dict(), "schuirmann_tost": tost.to_dict()}


def _write_json(args, data):
    if args.json:
        from ..formats.json import write_json

        write_json(args.json, data)
        print(f"wrote {args.json}")
