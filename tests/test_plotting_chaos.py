"""Figures of the flow's chaos tests: the data of flow.json is what is drawn (issue 26)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from stickslip.plotting.chaos import decorrelation_figure, flow_ladder_figure, fsle_figure

LADDER = {
    "label": "two-blocks, N = 2",
    "ladder": [
        {"dt": 0.005, "lyapunov": 0.02545, "lyapunov_err": 0.00062},
        {"dt": 0.0025, "lyapunov": 0.02563, "lyapunov_err": 0.00046},
        {"dt": 0.00125, "lyapunov": 0.02630, "lyapunov_err": 0.00046},
    ],
    "lyapunov_dt0": 0.0261,
    "lyapunov_dt0_err": 0.0004,
    "dt2_slope": -30.0,
    "finite_size": {
        "fsle": [
            {"delta": 1e-8, "rate": 0.03, "rate_err": 0.003, "cycles": 4},
            {"delta": 2e-8, "rate": None, "rate_err": None, "cycles": 0},  # NaN as JSON writes it
            {"delta": 4e-8, "rate": 0.05, "rate_err": None, "cycles": 1},
        ]
    },
    "decorrelation": [
        {"delta": 1e-12, "events": 26, "decorrelated": True},
        {"delta": 1e-10, "events": 24, "decorrelated": True},
        {"delta": 1e-8, "events": 17, "decorrelated": True},
        {"delta": 1e-6, "events": 4, "decorrelated": True},
    ],
}
REGULAR = {
    "label": "eq. (4), N = 99, beta = 1",
    "ladder": [
        {"dt": 0.005, "lyapunov": -4e-6, "lyapunov_err": 3e-6},
        {"dt": 0.0025, "lyapunov": -5e-6, "lyapunov_err": 3e-6},
    ],
    "lyapunov_dt0": -5.3e-6,
    "lyapunov_dt0_err": 3e-6,
    "dt2_slope": 0.05,
    "decorrelation": [
        {"delta": 1e-12, "events": 70, "decorrelated": False},
        {"delta": 1e-6, "events": 70, "decorrelated": False},
    ],
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


def test_fsle_figure_is_log_log_and_leaves_out_rows_without_doublings():
    fig = fsle_figure([LADDER, REGULAR])
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    (drawn,) = [c for c in ax.containers if c.get_label() == LADDER["label"]]
    x, y = _xy(drawn.lines[0])
    assert np.allclose(x, [1e-8, 4e-8]) and np.allclose(y, [0.03, 0.05])
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [LADDER["label"]]  # REGULAR has none


def test_decorrelation_figure_marks_runs_that_never_decorrelated():
    fig = decorrelation_figure([LADDER, REGULAR])
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    lines = {(line.get_label(), line.get_marker()): _xy(line) for line in ax.get_lines()}
    x, y = lines[(LADDER["label"], "None")]
    assert np.allclose(x, [1e-12, 1e-10, 1e-8, 1e-6]) and np.allclose(y, [26, 24, 17, 4])
    open_markers = [xy for (lab, m), xy in lines.items() if m == "^" and xy[0].size]
    assert len(open_markers) == 1 and np.allclose(open_markers[0][1], [70, 70])


def test_study_draws_the_three_figures_from_the_points_flow_json(tmp_path):
    from stickslip import io
    from stickslip.experiments.studies import study
    from stickslip.experiments.study_findings import draw

    spec = study("chaos", "tiny")
    points = tmp_path / "runs" / spec.dirname / "points"
    for name, data in (("a", LADDER), ("b", REGULAR)):
        io.write_json(points / name / "flow.json", {k: v for k, v in data.items() if k != "label"})
    table = pd.DataFrame(
        [
            {
                "model": "two-blocks",
                "N": 2,
                "beta": np.nan,
                "point_dir": "a",
                "lyapunov": 0.04,
                "lyapunov_err": 0.001,
                "d0": 1e-10,
            },
            {
                "model": "sakaguchi",
                "N": 99,
                "beta": 1.0,
                "point_dir": "b",
                "lyapunov": 0.0,
                "lyapunov_err": 1e-6,
                "d0": 1e-10,
            },
        ]
    )
    figs = draw(spec, table, tmp_path / "chaos")
    names = [f["name"] for f in figs]
    assert names == ["lyapunov_beta", "flow_ladder", "fsle", "decorrelation"]
    for name in names:
        assert (tmp_path / "chaos" / f"{name}.png").stat().st_size > 1000
