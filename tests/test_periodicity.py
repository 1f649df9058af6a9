"""The periodicity detector of slip sequences (issue 51, item 1): planted periods found exactly,
the single block periodic from its first slip, sequences that never repeat, linear cost, the hook
that stops a run and the commands."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tests.chain_helpers import run_cli

import stickslip
from stickslip.analysis.stats.periodicity import PeriodicStop, find_period, periodicity
from stickslip.models.params import ParameterError


def _brute_force(sb, nb, S, *, rtol, max_period, repeats):
    """The rule of the module docstring by its letter, in plain Python: for each p in order, every
    pair (i, i + p) compared, the earliest s after the last mismatch; O(n P)."""
    n = len(sb)
    longest = min(max_period, n // repeats)
    for p in range(1, longest + 1):
        s = 0
        for i in range(n - p):
            same = sb[i] == sb[i + p] and nb[i] == nb[i + p]
            if not (same and abs(S[i] - S[i + p]) <= rtol * max(abs(S[i]), abs(S[i + p]))):
                s = i + 1
        if n - s >= max(repeats * p, p + longest):
            return p, s
    return None, None


def _planted(rng, transient: int, period: int, n: int):
    """A random transient, then a random orbit of ``period`` slips (sizes drawn anew, so its
    smallest period is ``period``) repeated to ``n`` slips; times from random intervals."""
    blocks = rng.integers(1, 4, size=transient + period)
    widths = rng.integers(1, 6, size=transient + period)
    sizes = rng.uniform(0.1, 10.0, size=transient + period)
    gaps = rng.uniform(1.0, 3.0, size=transient + period)
    idx = np.concatenate([np.arange(transient), transient + np.arange(n - transient) % period])
    return blocks[idx], widths[idx], sizes[idx], np.cumsum(gaps[idx]), gaps[transient:].sum()


@pytest.mark.parametrize(("transient", "period", "n"), [(0, 1, 50), (37, 1, 200), (100, 7, 400), (5, 23, 311)])
def test_a_planted_period_and_transient_are_found_exactly(transient, period, n):
    rng = np.random.default_rng(transient + period)
    sb, nb, S, t, period_t = _planted(rng, transient, period, n)
    r = find_period(sb, nb, S, t)
    assert (r.period_slips, r.settled_from_slip) == (period, transient)
    assert r.settled_from_t == t[transient]
    assert r.period_t == pytest.approx(period_t, rel=1e-12)
    assert r.periods_seen == pytest.approx((n - transient) / period)


def test_a_sequence_with_a_short_run_inside_a_long_period_has_the_long_period():
    # nine equal slips and one other, repeated: the tail has a stretch of equal slips, but the
    # sequence's period is 10 (the stretch must hold p + P slips: Fine and Wilf)
    S = ([1.0] * 9 + [2.0]) * 40
    r = find_period(np.ones(400), np.ones(400), S)
    assert r.period_slips == 10 and r.settled_from_slip == 0


def test_sequences_that_never_repeat_have_no_period():
    rng = np.random.default_rng(3)
    n = 2000
    for S in (
        rng.uniform(1.0, 2.0, n),
        1.0 + 0.5 * np.sin(2 * np.pi * 0.6180339887 * np.arange(n)),
        1.0 + np.arange(n),
    ):
        r = find_period(np.ones(n, dtype=int), np.ones(n, dtype=int), S, np.arange(n) * 2.0)
        assert r.period_slips is None and r.settled_from_slip is None and r.settled_from_t is None
        assert r.period_t is None and r.longest_period_searched == 500
    # the same blocks in a period-2 pattern, the sizes drifting by 1e-4 each slip: no period at 1e-6
    S = (1.0 + 1e-4 * np.arange(n)) * np.where(np.arange(n) % 2, 1.0, 3.0)
    assert find_period(np.arange(n) % 2, np.ones(n), S).period_slips is None
    assert find_period(np.arange(n) % 2, np.ones(n), S, rtol=1e-3).period_slips == 2
    assert find_period([], [], []).period_slips is None


def test_the_search_agrees_with_the_rule_by_its_letter_on_coarse_alphabets():
    # few distinct slips: coincidences are frequent, the rule's every clause is exercised
    rng = np.random.default_rng(11)
    for k in range(300):
        n = int(rng.integers(1, 90))
        if k % 3 == 0:
            sb, nb, S = rng.integers(1, 3, n), np.ones(n, dtype=int), rng.integers(1, 3, n).astype(float)
        else:
            transient, period = int(rng.integers(0, n)), int(rng.integers(1, 12))
            base = rng.integers(1, 3, transient + period)
            idx = np.concatenate([np.arange(transient), transient + np.arange(max(n - transient, 0)) % period])[:n]
            sb, nb, S = base[idx], np.ones(n, dtype=int), base[idx].astype(float)
        rule = {"rtol": 1e-6, "max_period": int(rng.integers(1, 30)), "repeats": int(rng.integers(2, 5))}
        r = find_period(sb, nb, S, **rule)
        assert (r.period_slips, r.settled_from_slip) == _brute_force(sb, nb, S, **rule)


def test_the_cost_is_linear_in_the_number_of_slips():
    rng = np.random.default_rng(5)
    counts = {}
    for n in (100_000, 1_000_000):
        sb, nb, S, t, _ = _planted(rng, n // 2, 7, n)
        r = find_period(sb, nb, S, t)
        assert (r.period_slips, r.settled_from_slip) == (7, n // 2)
        counts[n] = r.comparisons
        # the whole stretch once or twice (chunks of doubling length), plus the search over p
        assert r.comparisons <= 2 * n + 5 * r.longest_period_searched**2
    assert counts[1_000_000] <= 11 * counts[100_000]
    # a sequence that never repeats costs the search over p only, whatever its length
    for n in (10_000, 1_000_000):
        r = find_period(np.ones(n), np.ones(n), rng.uniform(1.0, 2.0, n))
        assert r.period_slips is None and r.comparisons <= 10 * 500


def test_bad_rules_are_refused():
    with pytest.raises(ParameterError, match="repeats"):
        find_period([1], [1], [1.0], repeats=1)
    with pytest.raises(ParameterError, match="rtol"):
        find_period([1], [1], [1.0], rtol=-1.0)
    with pytest.raises(ParameterError, match="one entry per slip"):
        find_period([1, 1], [1], [1.0])


def test_a_single_block_is_periodic_from_its_first_slip():
    # one block pulled by its spring (eq. 1 as a chain of one): every slip alike, the sizes to ~4e-7
    run = stickslip.run_chain(stickslip.chain_params(N=1), 2e4, progress=False)
    r = periodicity(run.events)
    assert len(run.events) > 40
    assert r.period_slips == 1 and r.settled_from_slip == 0 and r.settled_from_t == run.events["t_start"][0]
    gaps = np.diff(run.events["t_start"].to_numpy())
    assert r.period_t == pytest.approx(gaps.mean(), rel=1e-9)


def test_the_hook_stops_the_run_where_the_whole_run_is_periodic_and_changes_no_slip():
    params = stickslip.chain_params(N=5)
    full = stickslip.run_chain(params, 1e6, progress=False)
    whole = periodicity(full.events)
    assert whole.period_slips == 16 and whole.settled_from_slip > 0
    hook = PeriodicStop()
    run = stickslip.run_chain(params, 1e6, hooks=[hook], progress=False)
    assert hook.result is not None
    assert (hook.result.period_slips, hook.result.settled_from_slip) == (16, whole.settled_from_slip)
    assert hook.result.settled_from_t == whole.settled_from_t
    assert run.summary["t_reached"] < 1e6 and len(run.events) < len(full.events)
    head = full.events.iloc[: len(run.events)].reset_index(drop=True)
    assert run.events.equals(head)
    assert hook.finish().period_slips == 16


def test_the_commands(tmp_path, capsys):
    out = tmp_path / "run"
    code, stdout, _ = run_cli(
        capsys, "chain", "--N", "5", "--t-end", "1e6", "--until-periodic", "--out", str(out), "--json", "--no-progress"
    )
    assert code == 0
    data = json.loads(stdout)
    assert data["periodicity"]["period_slips"] == 16 and data["t_end"] < 1e6
    code, stdout, _ = run_cli(capsys, "period", str(out), "--json")
    assert code == 0
    found = json.loads(stdout)
    assert found["period_slips"] == 16 and found["settled_from_slip"] == data["periodicity"]["settled_from_slip"]
    assert "start_block and n_blocks are equal" in found["rule"] and found["longest_period_searched"] >= 16
    code, _, stderr = run_cli(capsys, "period", str(out), "--repeats", "1")
    assert code == 2 and "repeats" in stderr and len(stderr.strip().splitlines()) <= 2
    code, _, stderr = run_cli(capsys, "period", str(tmp_path / "none"))
    assert code == 2 and "not a finished chain run directory" in stderr


def test_a_resumed_run_reads_the_slips_of_its_checkpoint(tmp_path):
    from stickslip.run.driver import resume_chain
    from stickslip.run.errors import Interrupted

    params = stickslip.chain_params(N=5)
    calls = []

    def stop_soon():  # asked after each kernel call: stop after a few, long before the orbit
        calls.append(1)
        return len(calls) == 3

    with pytest.raises(Interrupted):
        stickslip.run_chain(params, 1e6, out_dir=tmp_path / "run", stop_requested=stop_soon, progress=False)
    hook = PeriodicStop()
    run = resume_chain(tmp_path / "run", hooks=[hook])
    assert hook.result is not None and hook.result.settled_from_slip > 0
    whole = periodicity(stickslip.run_chain(params, 1e6, progress=False).events)
    assert (hook.result.period_slips, hook.result.settled_from_slip) == (16, whole.settled_from_slip)
    assert run.summary["t_reached"] < 1e6


@pytest.mark.slow
def test_a_small_chain_settles_on_an_orbit_longer_than_500_slips():
    """N = 7, beta = 0.5 from a perturbed paper start: the orbit reached has 2474 slips (8e5 time
    units), which a detector capped at 500 slips records as never settling."""
    from stickslip.experiments.studies.lifetimes_points import lifetime_point
    from stickslip.experiments.sweep_points import point_params

    cfg = {"model": "sakaguchi", "N": 7, "beta": 0.5, "start": "paper", "seed": 0, "budget": 4e6}
    cfg |= {"perturbation": 0.05, "until_steady": 1e-6, "rtol": 1e-6, "repeats": 3}
    capped = lifetime_point(cfg | {"max_period": 500}, point_params("chain", cfg))
    found = lifetime_point(cfg | {"max_period": 100_000}, point_params("chain", cfg))
    assert capped["end"] == "censored" and capped["lifetime"] == 4e6
    assert (found["end"], found["period_slips"], found["settled_from_slip"]) == ("periodic", 2474, 1344)
    assert found["lifetime"] < 5e5
