"""The layers are one-way: stickslip.run does not import stickslip.plotting (a run's figures are
lent to it as an accessor registered by the package), and stickslip.plotting does not import
stickslip.report (the figures' command lines are handed down by the studies)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import stickslip
from stickslip.models.params import ParameterError

SRC = Path(stickslip.__file__).parent


def _imports(package: str) -> set[tuple[str, str]]:
    """(module file, imported module) of every import in a package, inside functions too."""
    found = set()
    for path in (SRC / package).rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found |= {(path.name, a.name) for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module:
                found |= {(path.name, node.module)} | {(path.name, f"{node.module}.{a.name}") for a in node.names}
    return found


@pytest.mark.parametrize(
    "package, above",
    [("run", ("plotting", "report", "experiments", "analysis")), ("plotting", ("report", "experiments"))],
)
def test_no_import_up_the_layers(package, above):
    up = sorted(
        (f, m)
        for f, m in _imports(package)
        if any(m == f"stickslip.{a}" or m.startswith(f"stickslip.{a}.") for a in above)
    )
    assert up == []


@pytest.fixture(scope="module")
def short_run():
    return stickslip.run_chain(stickslip.chain_params(N=10), 2e4)


def test_a_runs_figures_through_the_accessor_and_the_methods(short_run):
    from matplotlib.figure import Figure

    from stickslip.plotting.run import RunPlots

    assert isinstance(short_run.plot, RunPlots)
    assert isinstance(short_run.plot.length(), Figure)
    assert isinstance(short_run.plot_length(), Figure)
    assert isinstance(short_run.plot_snapshot(), Figure)


def test_plot_sizes_of_a_run_with_few_slips_is_one_line(short_run):
    """35 slips in the stationary window: TypeError from an empty scan before, now the reason."""
    with pytest.raises(ParameterError, match=r"^35 slips with S > 0 at t >= 10000 .* needs at least 50: run longer$"):
        short_run.plot_sizes()
    with pytest.raises(ParameterError, match="needs at least 50"):
        short_run.plot.sizes()
