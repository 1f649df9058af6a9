"""The experiments behind the paper's figures and stated numbers, as data (``stickslip reproduce``).

Each :class:`Experiment` names one computation: its kind (which runner of
:mod:`stickslip.experiments.reproduce` carries it out), the model parameters, the run length and the run
options. Nothing else goes into its result, so the spec and the package version fix the result:
:meth:`Experiment.key` hashes them, and ``reproduce`` stores the result under
``runs/<name>-<key>/`` and reuses it whenever the same spec comes round again.

:func:`experiments` gives the spec set of a mode:

* ``full``: the paper's parameters and lengths: the single block of section 2 (Figs. 1-3,
  eq. 3, the Hopf point, the hysteresis sweep), the Fourier modes of Fig. 4, and chains of
  N = 399 blocks run to t = 2e7 at the values of beta of Fig. 5(b), with more points near
  beta = 1; the beta = 1 run also gives Figs. 5(a), 6 and 7, the beta = 0.2 run Fig. 8.
* ``quick``: the same pipeline with shorter chain runs (about five minutes on two cores):
  Fig. 5(b) on chains of N = 99 to t = 2e6 (a chain loads in about L_ss / V time units and
  L_ss grows like N^2), Figs. 5(a), 6, 7 and 8 on chains of N = 199 to t = 4e6. The sections 2
  and Fig. 4 parts are as in ``full`` (they take seconds).
* ``smoke``: a tiny set (chains of N = 19 to t = 4e4, a coarse hysteresis sweep) used by the
  tests to exercise the whole pipeline in seconds; its numbers mean nothing.

Chain runs at beta > 1 stop once the chain slides steadily (``until_steady``): from then on
every block moves every step and nothing changes but the position of the pulling point. In
``full`` mode beta = 1.2 is the exception: it runs its whole length.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from stickslip import __version__
from stickslip.experiments.cache import canonical, spec_key
from stickslip.models.physics import UNTIL_STEADY
from stickslip.models.presets import block_params, paper_parameters

__all__ = [
    "Experiment",
    "MODES",
    "KINDS",
    "experiments",
    "experiment",
    "chain_points",
    "FIGURES",
]

MODES = ("quick", "full", "smoke")

#: The runners of :mod:`stickslip.experiments.reproduce`, one per kind of experiment.
KINDS = (
    "block_run",  # eq. (1) at the paper's parameters: Figs. 1, 2
    "slip_limit",  # eq. (3): duration, force at stop, the period law
    "period_sweep",  # Fig. 3: simulated period against V
    "block_stability",  # eq. (2): Hopf point, stability for all V at beta = 1, stability map
    "hysteresis",  # section 2: V raised slowly and lowered again
    "chain_modes",  # eq. (5), Fig. 4: Fourier modes, critical beta
    "chain_runs",  # eq. (4): chain runs on Dask, Figs. 5-8
)

#: The figures of a reproduction, in report order: (file stem, what the paper shows).
FIGURES = (
    ("fig1", "Fig. 1"),
    ("fig2", "Fig. 2"),
    ("fig3", "Fig. 3"),
    ("stability_map", "Sec. 2 (stability map)"),
    ("hysteresis", "Sec. 2 (inverse transition)"),
    ("fig4", "Fig. 4"),
    ("fig5a", "Fig. 5(a)"),
    ("fig5b", "Fig. 5(b)"),
    ("fig6", "Fig. 6"),
    ("fig7", "Fig. 7"),
    ("fig8", "Fig. 8"),
)


@dataclass(frozen=True)
class Experiment:
    """One computation of the reproduction, as data.

    - ``name``: short name, the stem of its run directory (``block``, ``chain-runs``, ...);
    - ``kind``: one of :data:`KINDS`, the runner that computes it;
    - ``params``: model parameters (fields of :class:`~stickslip.models.params.BlockParams` or
      :class:`~stickslip.models.params.ChainParams`) shared by the whole experiment;
    - ``t_end``: run length in model time units (None where the kind has none);
    - ``options``: everything else the result depends on (grids, sweep protocol, points);
    - ``figures``: the figures (stems of :data:`FIGURES`) drawn from it, for the report;
    - ``note``: a line for the report on what this mode leaves out.

    The result depends on ``kind``, ``params``, ``t_end``, ``options`` and the package
    version only; ``name``, ``figures`` and ``note`` are labels.
    """

    name: str
    kind: str
    params: Mapping[str, Any] = field(default_factory=dict)
    t_end: float | None = None
    options: Mapping[str, Any] = field(default_factory=dict)
    figures: tuple[str, ...] = ()
    note: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {', '.join(KINDS)} (got {self.kind!r})")
        # Store plain, canonical copies: the spec cannot change behind the caller's back.
        object.__setattr__(self, "params", canonical(dict(self.params)))
        object.__setattr__(self, "options", canonical(dict(self.options)))

    def spec(self) -> dict[str, Any]:
        """What the result depends on: kind, parameters, run length, options, package version."""
        return canonical(
            {
                "kind": self.kind,
                "params": self.params,
                "t_end": self.t_end,
                "options": self.options,
                "version": __version__,
            }
        )

    def key(self) -> str:
        """First 12 hex digits of the SHA-256 of :meth:`spec` as canonical JSON
        (:func:`stickslip.experiments.cache.spec_key`).

        ``options["points"]`` (the chain runs of a sweep) is left out of the key: each point is
        stored and reused on its own (:func:`stickslip.experiments.sweep.run_sweep`), so adding a point to a
        spec keeps the run directory and runs only the new point.
        """
        spec = self.spec()
        spec["options"] = {k: v for k, v in spec["options"].items() if k != "points"}
        return spec_key(spec)

    @property
    def dirname(self) -> str:
        """Run directory name: ``<name>-<key>``."""
        return f"{self.name}-{self.key()}"

    def to_dict(self) -> dict[str, Any]:
        """The spec with its labels, for report.json."""
        return {"name": self.name, "key": self.key(), "figures": list(self.figures), "note": self.note, **self.spec()}


# ---------------------------------------------------------------------------------------------
# The spec sets


#: The paper's chain (section 3) apart from beta and N, and its single block (section 2, Fig. 1).
_CHAIN = paper_parameters("N", "beta")
_BLOCK = {k: v for k, v in dataclasses.asdict(block_params()).items() if k != "threshold"}

# Just above beta = 1 (1.025 to 1.1) the chain stick-slips for a very long time: at N = 99 it
# still does at t = 1e7, so such a point at N = 399 costs a whole run of the sliding regime
# (an hour on one core) and ends without settling. The full set therefore jumps to 1.2.
_FULL_BETAS = (0.2, 0.4, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 0.975, 0.99, 1.0, 1.2, 1.5)
_QUICK_BETAS = (0.2, 0.4, 0.6, 0.8, 0.9, 0.95, 1.0, 1.1, 1.2, 1.5)


def chain_points(
    sweep_N: int,
    betas: tuple[float, ...],
    figure_N: int,
    figure_betas: tuple[float, ...] = (1.0, 0.2),
) -> list[dict[str, Any]]:
    """The chain runs of a mode: ``{"N", "beta"}`` for Fig. 5(b) and for Figs. 5(a), 6, 7, 8.

    The Fig. 5(b) sweep is ``betas`` at ``sweep_N``; the figure runs (beta = 1 for Figs. 5a, 6
    and 7, beta = 0.2 for Fig. 8) are at ``figure_N``, shared with the sweep where N agrees.
    The figure runs come first, then the sweep from the largest beta down: the longest runs
    start first, which shortens the wall time on a few workers.
    """
    points = [{"N": int(figure_N), "beta": float(b)} for b in figure_betas]
    for b in sorted(betas, reverse=True):
        p = {"N": int(sweep_N), "beta": float(b)}
        if p not in points:
            points.append(p)
    return points


def _section2(mode: str) -> list[Experiment]:
    """Section 2 and Fig. 4: seconds in every mode; the smoke mode shortens the hysteresis sweep."""
    smoke = mode == "smoke"
    hysteresis = (
        {"V_min": 0.25, "V_max": 0.45, "dV": 0.05, "time_per_step": 50.0, "transient": 0.5}
        if smoke
        else {"V_min": 0.25, "V_max": 0.45, "dV": 0.005, "time_per_step": 400.0, "transient": 0.5}
    )
    return [
        # Fig. 1: the first slip at t = Fs / (K V) = 300, then one every T = 344.3: six slips.
        Experiment("block", "block_run", _BLOCK, t_end=600.0 if smoke else 2000.0, figures=("fig1", "fig2")),
        Experiment("slip-limit", "slip_limit", _BLOCK, options={"rtol": 1e-10, "atol": 1e-12}),
        Experiment(
            "period-sweep",
            "period_sweep",
            _BLOCK,
            options={"V_min": 1e-3, "V_max": 1e-1, "n": 4 if smoke else 13, "periods": 4},
            figures=("fig3",),
        ),
        Experiment(
            "stability-block",
            "block_stability",
            {**_BLOCK, "beta": 0.08},
            options={"beta_stable": 1.0, "map_betas": 31 if smoke else 121, "map_Vs": 40 if smoke else 200},
            figures=("stability_map",),
        ),
        Experiment(
            "hysteresis",
            "hysteresis",
            {k: v for k, v in _BLOCK.items() if k != "V"},
            options=hysteresis,
            figures=("hysteresis",),
        ),
        Experiment(
            "chain-modes",
            "chain_modes",
            {**_CHAIN, "N": 399, "beta": 1.0},
            options={"betas": [0.5, 1.0, 1.5], "n_k": 629},
            figures=("fig4",),
        ),
    ]


def _chain(mode: str) -> Experiment:
    if mode == "full":
        sweep_N = figure_N = 399
        t_sweep = t_fig = 2e7
        betas = _FULL_BETAS
        steady_above = 1.3
        note = (
            "full: beta = 1.2 runs its whole length (the paper's run of the sliding regime); "
            "beta = 1.5 stops at steady sliding"
        )
    elif mode == "quick":
        sweep_N, figure_N = 99, 199
        t_sweep, t_fig = 2e6, 4e6
        betas = _QUICK_BETAS
        steady_above = 1.0
        note = (
            "quick: Fig. 5(b) on N = 99 chains to t = 2e6, Figs. 5(a), 6, 7, 8 on N = 199 chains "
            "to t = 4e6 (the paper: N = 399 to t = 2e7)"
        )
    else:  # smoke
        sweep_N = figure_N = 19
        t_sweep = t_fig = 4e4
        betas = (0.2, 1.0, 1.5)
        steady_above = 1.0
        note = "smoke: tiny chains for tests; the numbers mean nothing"
    points = chain_points(sweep_N, betas, figure_N)
    # A chain loads in about L_ss / V: average and count events over the second half only.
    t_end = {str(sweep_N): t_sweep, str(figure_N): t_fig}
    return Experiment(
        "chain-runs",
        "chain_runs",
        _CHAIN,
        t_end=max(t_sweep, t_fig),
        options={
            "points": points,
            "t_end_by_N": t_end,
            "average_fraction": 0.5,
            "sample_interval": 100.0 if mode != "smoke" else 10.0,
            "until_steady": UNTIL_STEADY,
            "until_steady_above": steady_above,
            "profile_betas": [1.0],
            "profile_N": figure_N,
            "profile_window": 20.0,
            "profile_min_fraction": 0.25,
            "sweep_N": sweep_N,
            "figure_N": figure_N,
        },
        figures=("fig5a", "fig5b", "fig6", "fig7", "fig8"),
        note=note,
    )


def experiments(mode: str) -> list[Experiment]:
    """The experiments of a mode (``quick``, ``full`` or ``smoke``), in the order they run."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)} (got {mode!r})")
    return _section2(mode) + [_chain(mode)]


def experiment(mode: str, name: str) -> Experiment:
    """The experiment called ``name`` in ``mode``."""
    for exp in experiments(mode):
        if exp.name == name:
            return exp
    raise KeyError(f"no experiment {name!r} in mode {mode!r}")
