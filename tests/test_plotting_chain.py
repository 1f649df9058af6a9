"""Figures 5-8 from synthetic chain results: they draw what they are given, and render."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from matplotlib.figure import Figure

from stickslip.analysis.stats.statistics import fit_power_law, front_speed
from stickslip.models.params import ChainParams
from stickslip.plotting.chain import fig5a_snapshot, fig5b_length, fig6_fronts, fig7_8_sizes
from stickslip.plotting.style import save_figure

P = ChainParams(N=99)


def line(ax, label_part: str):
    matches = [ln for ln in ax.get_lines() if ln.get_label().startswith(label_part)]
    assert len(matches) == 1, [ln.get_label() for ln in ax.get_lines()]
    return matches[0]


def steady_x(p: ChainParams, t: float) -> np.ndarray:
    """x_i = V t - (c/K) sum_{j<=i} (N - j + 1), written out from docs/model.md."""
    c = 1.0 - (1.0 - p.beta) * p.V
    return np.array([p.V * t - c / p.K * sum(p.N - j + 1 for j in range(1, i + 1)) for i in range(1, p.N + 1)])


def test_fig5a_draws_the_snapshot_and_both_steady_profiles(tmp_path):
    t = 1e5
    x = steady_x(P, t) + np.linspace(-3.0, 2.0, P.N)
    fig = fig5a_snapshot(x, P, t)
    assert isinstance(fig, Figure)
    top, bottom = fig.axes[:2]
    i = np.arange(1, P.N + 1)
    np.testing.assert_allclose(line(top, "$x_i$ at t").get_ydata(), x - P.V * t)
    np.testing.assert_allclose(line(top, "steady sliding, exact").get_ydata(), steady_x(P, t) - P.V * t, rtol=1e-12)
    c = 1.0 - (1.0 - P.beta) * P.V
    continuum = -c / P.K * (P.N**2 - (i - P.N) ** 2) / 2.0
    np.testing.assert_allclose(line(top, "steady sliding, paper").get_ydata(), continuum, rtol=1e-12)
    np.testing.assert_allclose(line(bottom, "run - exact").get_ydata(), np.linspace(-3.0, 2.0, P.N), atol=1e-9)
    # the continuum form lies c i / (2K) above the exact discrete profile
    np.testing.assert_allclose(line(bottom, "continuum - exact").get_ydata(), c * i / (2 * P.K), rtol=1e-9)
    assert save_figure(fig, tmp_path / "fig5a")[0].stat().st_size > 10_000
    with pytest.raises(ValueError):
        fig5a_snapshot(x[:-1], P, t)


def test_fig5b_draws_the_exact_steady_length():
    table = pd.DataFrame(
        {"beta": [1.2, 0.4, 0.8, 1.0], "L_mean": [480.0, 300.0, 420.0, 484.0], "L_err": [1.0, 5.0, 4.0, 2.0]}
    )
    fig = fig5b_length(table, P)
    ax = fig.axes[0]
    steady = line(ax, "steady sliding")
    beta = np.asarray(steady.get_xdata())
    expected = (1.0 - (1.0 - beta) * P.V) / P.K * P.N * (P.N - 1) / 2.0
    np.testing.assert_allclose(steady.get_ydata(), expected, rtol=1e-12)
    assert "1/K" in steady.get_label()
    (bars,) = ax.containers
    assert "run" in bars.get_label()
    run = bars.lines[0]
    np.testing.assert_allclose(run.get_xdata(), [0.4, 0.8, 1.0, 1.2])  # sorted by beta
    np.testing.assert_allclose(run.get_ydata(), [300.0, 420.0, 484.0, 480.0])


def synthetic_event(event: int, reach: int, t0: float, speed: float, window: float = 20.0):
    """A front at constant ``speed``; each moved block slides at v = 0.05 for 30 time units."""
    i = np.arange(1, reach + 1)
    t_first = t0 + i / speed
    first_move = pd.DataFrame({"event": event, "block": i, "t_first": t_first})
    starts = np.arange(t0, t_first.max() + 30.0, window)
    dx = np.zeros((starts.size, P.N))
    for k, s in enumerate(starts):
        overlap = np.clip(np.minimum(s + window, t_first + 30.0) - np.maximum(s, t_first), 0.0, None)
        dx[k, :reach] = 0.05 * overlap
    profiles = xr.Dataset(
        {"profile_dx": (("profile_row", "block"), dx)},
        coords={
            "profile_event": ("profile_row", np.full(starts.size, event)),
            "profile_t": ("profile_row", starts),
            "block": np.arange(1, P.N + 1),
        },
    )
    return first_move, profiles


def test_fig6_draws_stacked_windows_and_the_fitted_front(tmp_path):
    fm_a, pr_a = synthetic_event(3, P.N, 19_100.0, 1.43)
    fm_b, pr_b = synthetic_event(8, 50, 40_400.0, 1.43)
    first_move = pd.concat([fm_a, fm_b], ignore_index=True)
    profiles = xr.concat([pr_a, pr_b], dim="profile_row")
    fronts = [front_speed(first_move, 3), front_speed(first_move, 8)]
    assert fronts[0].speed == pytest.approx(1.43, rel=1e-9)
    fig = fig6_fronts(profiles, first_move, fronts, P, labels=["large event", "intermediate event"])
    assert len(fig.axes) == 4
    waterfall, arrivals = fig.axes[0], fig.axes[1]
    assert len(waterfall.get_lines()) == pr_a.sizes["profile_row"]
    # each window's curve is its displacement lifted by a constant
    lifted = [ln.get_ydata() - pr_a["profile_dx"].values[k] for k, ln in enumerate(waterfall.get_lines())]
    assert all(np.ptp(v) < 1e-12 for v in lifted)
    assert np.all(np.diff([v[0] for v in lifted]) > 0)
    fit = line(arrivals, "fit:")
    slope = np.diff(fit.get_ydata()) / np.diff(fit.get_xdata())
    assert slope[0] == pytest.approx(1 / 1.43, rel=1e-9)
    sound = line(arrivals, "sound speed")
    assert (np.diff(sound.get_ydata()) / np.diff(sound.get_xdata()))[0] == pytest.approx(1 / np.sqrt(10.0))
    assert "1.43" in line(arrivals, "paper:").get_label()
    save_figure(fig, tmp_path / "fig6")
    with pytest.raises(ValueError):
        fig6_fronts(profiles.isel(row=slice(0, 2)), first_move, fronts[1:], P)


def test_fig7_8_draws_the_density_and_the_fitted_law(tmp_path):
    rng = np.random.default_rng(2)
    e = 1.0 - 1.5
    S = (0.5**e + rng.random(4000) * ((0.5e3) ** e - 0.5**e)) ** (1 / e)
    events = pd.DataFrame({"event": np.arange(S.size), "t_start": np.sort(rng.uniform(0, 1e6, S.size)), "S": S})
    fit = fit_power_law(S, 0.5, 500.0, bootstrap=50)
    fig = fig7_8_sizes(events, fit, params=ChainParams(), bins=20, paper_tau=1.5)
    ax_a, ax_b = fig.axes
    assert fig._suptitle.get_text().startswith("Fig. 7: slip sizes")
    points = line(ax_a, "simulation")
    # the binned density: share of events per bin over bin width, computed here from the edges
    edges = np.geomspace(S.min(), S.max(), 21)
    counts, _ = np.histogram(S, edges)
    keep = counts > 0
    np.testing.assert_allclose(points.get_ydata(), (counts / (S.size * np.diff(edges)))[keep])
    law = line(ax_a, "fit:")
    s = np.asarray(law.get_xdata())
    slope = np.diff(np.log(law.get_ydata())) / np.diff(np.log(s))
    np.testing.assert_allclose(slope, -fit.tau, rtol=1e-9)
    assert "1.50" in law.get_label() or "1.49" in law.get_label() or "1.51" in law.get_label()
    np.testing.assert_allclose(ax_b.get_lines()[0].get_ydata(), S)
    # the paper's slope is drawn a factor 3 under the fit at the middle of the range, not on it
    guide = line(ax_a, "paper: slope")
    mid = len(s) // 2
    assert guide.get_ydata()[mid] == pytest.approx(
        law.get_ydata()[mid] / 3.0 * (s[mid] / np.sqrt(0.5 * 500.0)) ** (fit.tau - 1.5), rel=1e-6
    )
    assert fig7_8_sizes(events, fit, params=ChainParams(beta=0.2))._suptitle.get_text().startswith("Fig. 8")
    # only the paper's runs carry its figure numbers; others their model and parameters
    assert "Fig." not in fig7_8_sizes(events, fit, params=ChainParams(N=99, beta=0.5))._suptitle.get_text()
    assert "Fig." not in fig7_8_sizes(events, fit, 1.0)._suptitle.get_text()
    save_figure(fig, tmp_path / "fig7")
