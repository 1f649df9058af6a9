"""The package from Python: help with numpydoc sections and running examples, short reprs,
plotting into given Axes, ``run.save`` writing what the command writes, labels that fit the model."""

from __future__ import annotations

import doctest
import importlib
import inspect
import json
import pkgutil
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from matplotlib.figure import Figure

import stickslip
import stickslip.plotting as ssp
from stickslip import ChainParams, chain_params, load_run, run_chain
from stickslip.models.params import ParameterError
from stickslip.models.presets import is_paper_run, model_name, model_title

#: Modules whose Examples run here as doctests.
DOCTEST_MODULES = (
    "stickslip.models.params",
    "stickslip.models.presets",
    "stickslip.run.driver",
    "stickslip.run.options",
    "stickslip.run.loop",
    "stickslip.run.outputs",
    "stickslip.run.rundir",
    "stickslip.run.block",
    "stickslip.lab.cycles",
    "stickslip.lab.spring_slider",
    "stickslip.lab.inertial_ode",
    "stickslip.plotting",
    "stickslip.experiments.studies.transition",
    "stickslip.experiments.sweep",
    "stickslip.analysis.dynamics.adaptive",
    "stickslip.analysis.stats.chain_runs",
    "stickslip.analysis.stats.fronts",
    "stickslip.analysis.stats.magnitudes",
    "stickslip.analysis.stats.order",
    "stickslip.analysis.stats.recurrence",
    "stickslip.analysis.dynamics.slip_limit",
    "stickslip.analysis.dynamics.stability",
    "stickslip.analysis.dynamics.stable_chaos",
    "stickslip.analysis.stats.statistics",
    "stickslip.models.physics",
    "stickslip.analysis.dynamics.lyapunov",
)


@pytest.mark.parametrize("name", DOCTEST_MODULES)
def test_examples_in_the_docstrings_run(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.attempted > 0 and result.failed == 0, result


GALLERY = Path(__file__).resolve().parent.parent / "docs"


def public_names() -> list[tuple[str, str]]:
    """(module, name) of every public function and class: the names in ``__all__`` of
    ``stickslip``, ``stickslip.plotting`` and every ``stickslip.analysis`` module, and every
    ``stickslip`` name a gallery page or the tutorial imports."""
    import stickslip.analysis

    modules = ["stickslip", "stickslip.plotting"]
    found_modules = pkgutil.walk_packages(stickslip.analysis.__path__, "stickslip.analysis.")
    analysis = [m.name for m in found_modules if not m.ispkg]
    assert {"stickslip.analysis.dynamics.lyapunov", "stickslip.analysis.stats.catalog"} <= set(analysis)
    modules += analysis
    names = [(m, n) for m in modules for n in getattr(importlib.import_module(m), "__all__", ())]
    for page in [*GALLERY.glob("gallery/*.md"), GALLERY / "tutorial.md"]:
        for module, imported in re.findall(r"^from (stickslip[\w.]*) import (.+)$", page.read_text(), re.M):
            names += [(module, n.strip()) for n in imported.split(",")]
    found = {}
    for module, name in names:
        obj = getattr(importlib.import_module(module), name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            found.setdefault(id(obj), (module, name))
    return sorted(found.values())


def _sections(doc: str) -> set[str]:
    return set(re.findall(r"\n(\w[\w ]*)\n-{3,}\n", "\n" + doc))


def test_the_public_names_are_those_of_the_api():
    names = {f"{m}.{n}" for m, n in public_names()}
    assert len(names) > 90
    for name in ("stickslip.largest_lyapunov", "stickslip.run_chain", "stickslip.plotting.sizes",
                 "stickslip.analysis.stats.statistics.fit_power_law",
                 "stickslip.analysis.dynamics.stability.critical_stiffness",
                 "stickslip.experiments.studies.transition.transition_loop"):  # fmt: skip
        assert name in names, name


@pytest.mark.parametrize(("module", "name"), public_names(), ids=lambda x: x)
def test_public_names_have_numpydoc_sections(module, name):
    """Functions say what they take and give (Parameters, Returns); classes their fields or
    arguments (Attributes or Parameters)."""
    obj = getattr(importlib.import_module(module), name)
    sections = _sections(inspect.getdoc(obj) or "")
    if inspect.isclass(obj):
        assert sections & {"Parameters", "Attributes"}, (module, name, sections)
        # the reference's variable lists take one field to an entry ("a, b : float" reads as one)
        doc = inspect.getdoc(obj)
        if "Attributes" in sections:
            fields = doc.split("\nAttributes\n----------\n", 1)[1]
            assert not re.search(r"^\w+, \w+.* : ", fields, re.M), (module, name)
    else:
        assert {"Parameters", "Returns"} <= sections, (module, name, sections)


#: The names a notebook user meets first carry examples too.
EXAMPLES = ("run_chain", "load_run", "simulate_block", "chain_params", "ChainParams", "BlockParams", "largest_lyapunov")


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_first_names_have_examples(name):
    assert "Examples" in _sections(inspect.getdoc(getattr(stickslip, name))), name


@pytest.mark.parametrize("name", ["length", "snapshot", "sizes", "fronts"])
def test_plotting_functions_say_what_they_take_and_give(name):
    doc = inspect.getdoc(getattr(ssp, name))
    assert "\nParameters\n----------\n" in doc and "\nReturns\n-------\n" in doc and "ax :" in doc


def test_chain_run_documents_every_event_column_with_units():
    doc = inspect.getdoc(stickslip.run.outputs.ChainRun)
    table = doc[doc.index("events : ") : doc.index("first_move : ")]
    for column in stickslip.run.outputs.EVENT_COLUMNS:
        assert f"\n    {column} " in table, column
    for timed in ("t_start", "t_end", "duration"):
        line = next(ln for ln in table.splitlines() if ln.strip().startswith(timed))
        assert "model time units" in line


@pytest.fixture(scope="module")
def run():
    """A chain of 12 blocks past its loading time (L_ss / V = 6.6e3), events enough for a fit."""
    return run_chain(chain_params(N=12), 6e4, snapshot_times=(3e4,), profile_window=20.0, profile_min_blocks=6)


def test_reprs_are_short(run):
    for obj in (run, run.params, chain_params("carlson-langer"), chain_params(friction="rate-state")):
        text = repr(obj)
        assert len(text.splitlines()) < 10 and "array" not in text, text
    # the parameters the model ignores are not shown, and the repr builds the same parameters
    cl = chain_params("carlson-langer")
    assert "beta" not in repr(cl) and "D=" not in repr(cl)
    assert eval(repr(cl), {"ChainParams": ChainParams}) == cl
    assert repr(run).startswith("ChainRun(eq. (4): N=12, K=10, V=0.001")
    assert run.summary["state_sha256"][:16] in repr(run)


def test_save_writes_the_run_directory_the_command_writes(run, tmp_path):
    folder = run.save(tmp_path / "saved")
    direct = tmp_path / "direct"
    run_chain(chain_params(N=12), 6e4, snapshot_times=(3e4,), profile_window=20.0, profile_min_blocks=6, out_dir=direct)
    assert sorted(p.name for p in folder.iterdir()) == sorted(p.name for p in direct.iterdir())
    back = load_run(folder)
    assert back.summary["state_sha256"] == run.summary["state_sha256"] == load_run(direct).summary["state_sha256"]
    pd.testing.assert_frame_equal(back.events, run.events)
    pd.testing.assert_frame_equal(back.first_move.reset_index(drop=True), run.first_move, check_dtype=False)
    np.testing.assert_array_equal(back.samples["L"].values, run.samples["L"].values)
    np.testing.assert_array_equal(back.snapshots.values, run.snapshots.values)
    np.testing.assert_array_equal(back.profiles["profile_dx"].values, run.profiles["profile_dx"].values)
    assert back.params == run.params and back.options == run.options
    meta = json.loads((folder / "run.json").read_text())
    assert meta["summary"]["n_events"] == len(run.events)
    # a folder holding a run already is refused, as the command refuses it
    with pytest.raises(ParameterError, match="already holds a finished run"):
        run.save(folder)
    # ... unless told to replace it, as `stickslip chain --overwrite` does; a user's file stays
    (folder / "notes.txt").write_text("mine")
    old_id = (folder / ".run_id").read_text()
    assert run.save(folder, overwrite=True) == folder
    assert (folder / "notes.txt").read_text() == "mine" and (folder / ".run_id").read_text() != old_id
    assert stickslip.load_run(folder).summary["state_sha256"] == run.summary["state_sha256"]


def test_a_missing_run_directory_is_a_file_not_found_error(tmp_path):
    """As Python code expects of a missing path (and still a RunDirDamaged, as before)."""
    from stickslip.run.rundir import RunDirDamaged

    with pytest.raises(FileNotFoundError, match="no such run directory") as info:
        stickslip.load_run(tmp_path / "nowhere")
    assert isinstance(info.value, RunDirDamaged) and info.value.filename == str(tmp_path / "nowhere")
    (tmp_path / "half").mkdir()
    with pytest.raises(FileNotFoundError, match="run.json is missing"):
        stickslip.load_run(tmp_path / "half")


def test_a_non_finite_state_is_an_arithmetic_error():
    from stickslip.run.errors import NonFiniteState

    assert issubclass(NonFiniteState, ArithmeticError)


def test_plot_methods_draw_into_the_given_axes(run):
    """Given ``ax``, a plot method returns that Axes (as pandas' and seaborn's do); without, its
    new Figure."""
    fig = Figure()
    axes = fig.subplots(2, 2)
    assert run.plot_length(ax=axes[0, 0]) is axes[0, 0]
    assert run.plot_snapshot(ax=axes[0, 1]) is axes[0, 1]
    assert run.plot_sizes(ax=axes[1, 0]) is axes[1, 0]
    assert run.plot_fronts(ax=axes[1, 1]) is axes[1, 1]
    assert isinstance(run.plot_length(), Figure)
    assert len(fig.axes) == 4
    (L,) = [ln for ln in axes[0, 0].get_lines() if ln.get_label().startswith("$L(t)")]
    np.testing.assert_array_equal(L.get_ydata(), run.samples["L"].values)
    # one panel: no panel letter, and the model in the title
    title = axes[0, 1].get_title(loc="left")
    assert "(a)" not in title and "\neq. (4)" in title and "$N=12$" in title and "Fig." not in title
    # without Axes each makes its own Figure; a stored snapshot is found by its time
    assert isinstance(ssp.snapshot(run, 3e4), Figure)
    with pytest.raises(ValueError, match="no snapshot stored at t = 1234"):
        ssp.snapshot(run, 1234.0)


def test_labels_come_from_the_model():
    cl = chain_params("carlson-langer")
    assert model_name(cl) == "Carlson-Langer"
    title = model_title(cl)
    assert r"\beta" not in title and "$D=" not in title and "$K_p=1$" in title and r"$\sigma=0.01$" in title
    assert model_name(chain_params(friction="rate-state")) == "eq. (4), friction rate-state"
    assert "$a=0.01$" in model_title(chain_params(friction="rate-state"))
    assert is_paper_run(ChainParams(beta=0.2)) and not is_paper_run(ChainParams(N=49))
    assert not is_paper_run(cl)


def test_figures_of_carlson_langer_carry_its_name_and_no_paper_figure():
    """A size distribution and a waterfall of a Carlson-Langer run: its name and parameters,
    no beta, no "Fig. N", no paper's front speed."""
    from stickslip.analysis.stats.statistics import fit_power_law, front_speed
    from stickslip.plotting.chain import fronts_figure, sizes_figure

    cl = chain_params("carlson-langer", N=30)
    rng = np.random.default_rng(5)
    S = np.exp(rng.uniform(0.0, 5.0, 400))
    events = pd.DataFrame({"event": np.arange(S.size), "t_start": np.arange(S.size) * 10.0, "S": S})
    fig = sizes_figure(events, fit_power_law(S, 1.0, 100.0, bootstrap=0), params=cl)
    title = fig._suptitle.get_text()
    assert title.startswith("slip sizes") and "Carlson-Langer" in title and "beta" not in title
    i = np.arange(1, 31)
    first_move = pd.DataFrame({"event": 0, "block": i, "t_first": 100.0 + i / 2.0})
    dx = np.tile(np.linspace(0.0, 1.0, 30), (4, 1))
    profiles = xr.Dataset(
        {"profile_dx": (("profile_row", "block"), dx)},
        coords={
            "profile_event": ("profile_row", np.zeros(4, dtype=int)),
            "profile_t": ("profile_row", 100.0 + 20.0 * np.arange(4)),
            "block": i,
        },
    )
    fig = fronts_figure(profiles, first_move, [front_speed(first_move, 0)], cl)
    assert not fig._suptitle.get_text().startswith("Fig.") and "Carlson-Langer" in fig._suptitle.get_text()
    labels = [ln.get_label() for ln in fig.axes[1].get_lines()]
    assert not any(lb.startswith("paper:") for lb in labels) and any(lb.startswith("sound speed") for lb in labels)
    # the waterfall's y axis means one thing: the window's start
    assert fig.axes[0].get_ylabel() == "window start $t - t_s$"


def test_old_plotting_names_still_work():
    from stickslip.plotting import chain

    assert chain.fig5a_snapshot is ssp.snapshot_figure and chain.fig7_8_sizes is ssp.sizes_figure
    assert chain.fig5b_length is ssp.length_against_beta and chain.fig6_fronts is ssp.fronts_figure


def test_fig4_has_its_title_and_panel_letters():
    from stickslip.analysis.dynamics.stability import fig4_data
    from stickslip.plotting.stability import plot_fig4

    fig = plot_fig4(fig4_data(ChainParams(), k=np.linspace(0.0, np.pi, 40)))
    assert fig._suptitle.get_text().startswith("Fig. 4: growth rates")
    letters = [ax.get_title(loc="left")[:3] for ax in fig.axes]
    assert letters == ["(a)", "(b)"]


def test_state_nc_names_quantities_as_python_does_and_old_files_still_load(run, tmp_path):
    folder = run.save(tmp_path / "run")
    ds = xr.load_dataset(folder / "state.nc")
    # L over t, as run.samples has it; no other t; the final state's time is t_end
    assert ds["L"].dims == ("t",) and "t_sample" not in ds.variables and "t" not in ds.attrs
    assert ds.attrs["t_end"] == run.summary["t_end"] and ds["profile_t"].dims == ("profile_row",)
    # a run directory of the former layout: L over t_sample, the window starts also as coordinate t
    old = ds.rename({"t": "t_sample"}).assign_coords(t=("profile_row", ds["profile_t"].values))
    old.attrs["t"] = old.attrs.pop("t_end")
    (folder / "state.nc").unlink()
    old.to_netcdf(folder / "state.nc")
    back = load_run(folder)
    np.testing.assert_array_equal(back.samples["t"].values, run.samples["t"].values)
    np.testing.assert_array_equal(back.samples["L"].values, run.samples["L"].values)
    np.testing.assert_array_equal(back.profiles["profile_t"].values, run.profiles["profile_t"].values)


#: The quantities of the stored windows of events (Fig. 6), in ChainRun.profiles and state.nc.
PROFILE_NAMES = ("profile_dx", "profile_event", "profile_t", "profile_t_next")


def test_every_quantity_has_one_name_in_memory_and_on_disk(run, tmp_path):
    """Each array of run.samples, .snapshots and .profiles is in state.nc under its own name,
    over the same dimensions and with the same values; a loaded run has the same names again; the
    tables' columns are the Parquet files' columns."""
    folder = run.save(tmp_path / "named")
    ds = xr.load_dataset(folder / "state.nc")
    back = load_run(folder)
    assert run.profiles.sizes["profile_row"] > 0 and run.snapshots.sizes["snapshot_time"] == 2
    for held in (run, back):
        arrays = {**held.samples.variables, **held.profiles.variables, **held.snapshots.coords}
        arrays[held.snapshots.name] = held.snapshots.variable
        assert set(arrays) == {"t", "L", "block", "snapshot_time", "snapshot_x", *PROFILE_NAMES}
        for name, array in arrays.items():
            assert ds[name].dims == array.dims, name
            np.testing.assert_array_equal(ds[name].values, array.values, err_msg=name)
    for table in ("events", "first_move"):
        on_disk = pd.read_parquet(folder / f"{table}.parquet")
        assert list(on_disk.columns) == list(getattr(run, table).columns) == list(getattr(back, table).columns)


def test_a_snapshot_of_a_model_without_a_steady_profile_is_refused_in_one_line():
    from types import SimpleNamespace

    with pytest.raises(ValueError, match=r"no steady sliding profile .* \(Carlson-Langer\)$"):
        ssp.snapshot(SimpleNamespace(params=chain_params("carlson-langer")))


def test_a_states_public_arrays_hold_the_blocks(run):
    """run.state.x, .v and .theta are x_1..x_N (no ghost cells), views of the kernels' arrays:
    their means are the blocks' (before, run.state.v had N + 2 entries)."""
    s = run.state
    b = s.blocks()
    assert s.x.shape == s.v.shape == s.theta.shape == (run.params.N,)
    np.testing.assert_array_equal(s.x, b["x"])
    np.testing.assert_array_equal(s.v, b["v"])
    np.testing.assert_array_equal(s.theta, b["theta"])
    assert s.v.mean() == sum(b["v"]) / run.params.N
    assert s.x[0] - s.x[-1] == run.summary["L_final"]  # L = x_1 - x_N
    assert np.shares_memory(s.x, s.xg) and s.xg.shape == (run.params.N + 2,)
