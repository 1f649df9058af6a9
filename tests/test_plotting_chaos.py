"""Figures of the chaos study: the data of flow.json is what is drawn (issues 26 and 35)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from stickslip.plotting.chaos import decorrelation_figure, flow_ladder_figure, threshold_figure


def _dec(rows):
    return {"decorrelation": [{"delta": d, "seed": s, "events": n, "decorrelated": f} for d, s, n, f in rows]}


LADDER = {
    "label": "two-blocks, N = 2",
    "N": 2,
    "beta": None,
    "ladder": [
        {"dt": 0.005, "lyapunov": 0.02545, "lyapunov_err": 0.00062},
        {"dt": 0.0025, "lyapunov": 0.02563, "lyapunov_err": 0.00046},
        {"dt": 0.00125, "lyapunov": 0.02630, "lyapunov_err": 0.00046},
    ],
    "lyapunov_dt0": 0.0261,
    "lyapunov_dt0_err": 0.0004,
    "dt2_slope": -30.0,
    "decorrelation": {"state": _dec([(1e-12, 0, 26, True), (1e-10, 0, 24, True), (1e-8, 0, 17, True)])},
}
REGULAR = {
    "label": "eq. (4), N = 99, beta = 1",
    "N": 99,
    "beta": 1.0,
    "ladder": [
        {"dt": 0.005, "lyapunov": -4e-6, "lyapunov_err": 3e-6},
        {"dt": 0.0025, "lyapunov": -5e-6, "lyapunov_err": 3e-6},
    ],
    "lyapunov_dt0": -5.3e-6,
    "lyapunov_dt0_err": 3e-6,
    "dt2_slope": 0.05,
    "decorrelation": {
        "state": _dec([(1e-6, 0, 1000, False), (1e-2, 0, 56, True), (1e-6, 1, 1000, False), (1e-2, 1, 1000, False)]),
        "Fs": _dec([(1e-6, 0, 300, True), (1e-2, 0, 4, True)]),
    },
}


def _xy(line):
    return np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)


def test_flow_ladder_figure_draws_the_rungs_and_the_fit_down_to_zero():
    fig = flow_ladder_figure([LADDER, REGULAR])
    ax = fig.axes[0]
    xs = [_xy(line) for line in ax.get_lines()]
    rungs = [xy for xy in xs if xy[0].size == 3]
    assert any(
        np.allclose(x, [0.005, 0.0025, 0.00125]) and np.allclose(y, [0.02545, 0.02563, 0.0263]) for x, y in rungs
    )
    fit = next(xy for xy in xs if xy[0].size == 50)
    assert fit[0][0] == 0.0 and fit[1][0] == 0.0261
    assert np.isclose(fit[1][-1], 0.0261 - 30.0 * 0.005**2)  # lambda_0 + c dt^2 at the largest dt
    assert any(x.size == 1 and x[0] == 0.0 and y[0] == 0.0261 for x, y in xs)  # lambda_0 at dt = 0
    assert [a.get_title() for a in fig.axes if a.get_visible()] == [LADDER["label"], REGULAR["label"]]


def test_decorrelation_figure_has_a_panel_per_kind_and_N_and_marks_runs_that_never_decorrelated():
    fig = decorrelation_figure([LADDER, REGULAR])
    visible = [a.get_title() for a in fig.axes if a.get_visible()]
    assert visible == ["state, N = 99", "state, relatives", "Fs, N = 99"]  # no Fs of the relatives
    ax = next(a for a in fig.axes if a.get_title() == "state, N = 99")
    assert ax.get_xscale() == "log"
    lines = [_xy(line) + (line.get_marker(), line.get_markerfacecolor()) for line in ax.get_lines()]
    # window 0: a line through both deltas, a filled marker at 1e-2 (56 slips), an open one at 1e-6
    assert any(np.allclose(x, [1e-6, 1e-2]) and np.allclose(y, [1000, 56]) and m == "None" for x, y, m, _ in lines)
    filled = [(x, y) for x, y, m, fc in lines if m == "o" and fc != "none" and x.size]
    opened = [(x, y) for x, y, m, fc in lines if m in ("o", "s") and fc == "none" and x.size]
    assert len(filled) == 1 and np.allclose(filled[0][0], [1e-2]) and np.allclose(filled[0][1], [56])
    assert sorted(float(v) for x, _ in opened for v in x) == [1e-6, 1e-6, 1e-2]  # window 1 never


def test_threshold_figure_draws_each_window_the_mean_and_the_fit():
    points = [
        {"N": 49, "beta": 0.5, "kind": "state", "per_seed": [1e-4, 1e-2, None], "geometric_mean": 1e-3}
        | {"log10_err": 1.0},
        {"N": 199, "beta": 0.5, "kind": "state", "per_seed": [1e-3, 1e-3], "geometric_mean": 1e-3, "log10_err": 0.0},
    ]
    fit = {"beta": 0.5, "kind": "state", "slope": -0.5, "slope_err": 0.3, "intercept": -2.0, "Ns": [49, 199]}
    fig = threshold_figure(points, [fit])
    (ax,) = [a for a in fig.axes if a.get_visible()]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    dots = [_xy(line) for line in ax.get_lines() if line.get_marker() == "."]
    assert sorted(y for _, ys in dots for y in ys) == [1e-4, 1e-3, 1e-3, 1e-2]  # the censored window left out
    (dashed,) = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    x, y = _xy(dashed)
    assert np.allclose(y, 10.0 ** (-2.0 - 0.5 * np.log10(x))) and x[0] == 49 and np.isclose(x[-1], 199)
    (bars, *_), *_ = [c for c in ax.containers]
    assert np.isclose(_xy(bars)[1][0], 1e-3)
    assert "beta = 0.5: -0.50 +- 0.30" in [t.get_text() for t in ax.get_legend().get_texts()]


@pytest.mark.slow  # a chaos study's figures (about 15 s, measured)
def test_study_draws_its_figures_and_the_rows_of_n_from_the_points_flow_json(tmp_path):
    from stickslip import io
    from stickslip.experiments.studies import design, study
    from stickslip.experiments.study_run import _draw

    spec = study("chaos", "tiny")
    points = tmp_path / "runs" / spec.dirname / "points"
    for name, data in (("a", LADDER), ("b", REGULAR)):
        io.write_json(points / name / "flow.json", {k: v for k, v in data.items() if k != "label"})
    seeds = {"delta_star_state_seed0": 1e-2, "delta_star_state_seed1": np.nan, "delta_star_state": 1e-2}
    seeds |= {"delta_star_state_err_log10": np.nan, "delta_star_state_low": 1e-2, "delta_star_state_high": 1e-2}
    table = pd.DataFrame(
        [
            {"model": "two-blocks", "N": 2, "beta": np.nan, "point_dir": "a", "seeds": 1},
            {"model": "sakaguchi", "N": 99, "beta": 1.0, "point_dir": "b", "seeds": 2}
            | seeds
            | {"delta_star_state_censored": 1},
        ]
    )
    (tmp_path / "chaos").mkdir()
    figs, not_drawn = _draw(spec, design("chaos"), table, tmp_path / "chaos")
    assert not_drawn == {}
    names = [f["name"] for f in figs]
    assert names == ["decorrelation", "flow_ladder", "threshold"]
    for name in names:
        assert (tmp_path / "chaos" / f"{name}.png").stat().st_size > 1000
    rows = pd.read_csv(tmp_path / "chaos" / "decorrelation.csv")
    assert len(rows) == 3 + 4 + 2  # every n(delta) row of both points
    assert rows[(rows["N"] == 99) & (rows["kind"] == "state") & (rows["delta"] == 0.01)]["events"].tolist() == [
        56,
        1000,
    ]
