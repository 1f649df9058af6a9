"""The studies (``stickslip study NAME``): one module each.

A study's module says everything about it in one :class:`Design`: its points in each mode (a
:class:`Study`), the task that runs one point on a Dask worker, its findings and figures from the
table of its finished points, the columns of its page and the text of ``stickslip study NAME
--help``. :func:`stickslip.experiments.study_run.run_study` runs any of them (points on Dask with
the cache, resume and folder ownership of :func:`stickslip.experiments.sweep.run_sweep`) without
naming one.

:data:`STUDIES` are the questions the paper leaves open: the stick-slip transition at beta = 1 as
N grows (``transition``), the final state and m over (alpha, beta) and (D, beta)
(``phase-diagram``), the slip-size exponent tau (``exponents``), whether the chain is chaotic
at the onset (``chaos``), how long its irregular motion lasts against N (``lifetimes``), and the
chain with random thresholds: the transition, avalanches under a force ramp beside qEW,
depinning under a constant force (``disorder``), and eq. (4) on the square lattice: its
transition against beta, its slip sizes and magnitudes beside the chain's, Carlson-Langer's on
the square (``lattice``). :data:`PAPER` are the paper's own figures and
stated numbers, each with one page: the single block of section 2 and the Fourier modes of Fig. 4
(``figs1-4``) and the chain runs of section 3 (``figs5-8``); ``stickslip reproduce`` gathers them
into one report
(:mod:`stickslip.experiments.reproduce`).

A :class:`Study`'s key hashes its name, the settings every point shares and the package version
(not the point list, so a point added to a study keeps the directory and runs only the new point).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from stickslip import __version__
from stickslip.experiments.cache import canonical, spec_key

__all__ = [
    "Study",
    "Design",
    "Option",
    "STUDIES",
    "PAPER",
    "MANIFEST",
    "MODES",
    "design",
    "study",
    "study_command",
    "finite",
    "short",
]

#: The studies, each the module of its name (``-`` read as ``_``) in this package.
STUDIES = ("transition", "phase-diagram", "exponents", "chaos", "lifetimes", "disorder", "lattice")
#: The studies of ``stickslip reproduce`` (the paper's figures and stated numbers), in report order.
PAPER = ("figs1-4", "figs5-8")
#: The record, at the top of a study's output folder, of every page file its studies wrote.
MANIFEST = ".stickslip-study.json"
#: ``tiny`` runs every study on chains of a few blocks in seconds (tests); its numbers mean nothing.
MODES = ("quick", "full", "tiny")


@dataclass(frozen=True)
class Study:
    """One study in one mode as data: ``name`` (one of :data:`STUDIES`), ``mode``, ``common``
    (settings every point shares: model parameters, run options, analysis), ``points`` (the
    varying settings of each point) and a ``note`` for the page. The result depends on ``name``,
    ``common``, the points and the package version only."""

    name: str
    mode: str
    common: dict[str, Any] = field(default_factory=dict)
    points: tuple[dict[str, Any], ...] = ()
    note: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "common", canonical(dict(self.common)))
        object.__setattr__(self, "points", tuple(canonical(dict(p)) for p in self.points))

    def spec(self) -> dict[str, Any]:
        """What the results depend on: name, shared settings, points, package version."""
        return canonical(
            {"study": self.name, "common": self.common, "points": list(self.points), "version": __version__}
        )

    def key(self) -> str:
        """First 12 hex digits of the SHA-256 of the spec without its points."""
        return spec_key({k: v for k, v in self.spec().items() if k != "points"})

    @property
    def dirname(self) -> str:
        """The study's runs folder: ``<name>-<key>``."""
        return f"{self.name}-{self.key()}"

    def runs_dir(self, out: str | Path) -> Path:
        """The study's runs folder under the output folder ``out``: ``out/runs/<name>-<key>``
        (its points in ``points/``, each study's page in ``out/<name>``)."""
        return Path(out) / "runs" / self.dirname


def finite(x: Any) -> bool:
    """Whether ``x`` is a finite number (None, NaN, text: not), for the studies' tables."""
    try:
        return x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def short(x: Any, digits: int = 3) -> str:
    """``x`` to ``digits`` significant digits for a study's statements, "n/a" unless :func:`finite`."""
    return f"{float(x):.{digits}g}" if finite(x) else "n/a"


@dataclass(frozen=True)
class Option:
    """A command-line option of one study (repeatable, an integer each time): ``flag``, the
    keyword ``dest`` of its :attr:`Design.build`, ``metavar`` and ``help``."""

    flag: str
    dest: str
    metavar: str
    help: str


@dataclass(frozen=True)
class Design:
    """What a study's module says of it.

    - ``name``, ``summary`` (one line for ``stickslip study --help``) and ``describe`` (the text
      of ``stickslip study NAME --help``: what it measures, its grid, its cost, its outputs);
    - ``cost``: the wall time of each mode, as ``describe`` and the README state it (one text);
    - ``build(mode, **options)``: the :class:`Study` of a mode;
    - ``task(point, point_dir)``: one point on a worker (a task of ``run_sweep``);
    - ``check(cfg)``: refuse a point's merged settings (ParameterError) before any work starts;
    - ``findings(study, table)``: what the table of finished rows says (``statements`` first);
    - ``figures(study, table, page_dir)``: (name, Figure, caption) for each figure, and may add a
      dict of further fields of its entry (its data files, the command that draws it); (name,
      None, reason) for a figure the results cannot give;
    - ``columns``: the leading columns of its table and page;
    - ``rows(table)``: the study's table from the sweep's (one row per point when None);
    - ``tables(findings)``: further tables of its page, as (title, columns, records);
    - ``options``: its own command-line options;
    - ``point_entry(path, rel)``: for a study whose points write a known layout, whether an
      entry of a point's folder is the point's (True, False, or for a folder the test of its
      entries); without it a point's folder is the point's;
    - ``load(study, table, points_dir)``: for a study whose findings and figures read its
      points' files, what they read in place of the table (loaded once);
    - ``point_name(point)``: a point's folder name (default :func:`~stickslip.experiments.sweep.point_name`);
    - ``command(mode)``: the command line that computes the study (default ``stickslip study
      NAME --MODE --out DIR``).
    """

    name: str
    summary: str
    describe: Callable[[], str]
    build: Callable[..., Study]
    task: Callable[..., dict[str, Any]]
    check: Callable[[dict[str, Any]], None]
    findings: Callable[[Study, Any], dict[str, Any]]
    figures: Callable[..., list[tuple[str, Any, str]]]
    columns: tuple[str, ...]
    rows: Callable[[Any], Any] | None = None
    tables: Callable[[dict[str, Any]], list[tuple[str, list[str], list[dict[str, Any]]]]] | None = None
    options: tuple[Option, ...] = ()
    point_entry: Callable[..., Any] | None = None
    load: Callable[..., Any] | None = None
    point_name: Callable[[dict[str, Any]], str] | None = None
    command: Callable[[str], str] | None = None
    cost: dict[str, str] = field(default_factory=dict)


def design(name: str) -> Design:
    """The :class:`Design` of study ``name`` (one of :data:`STUDIES` or :data:`PAPER`): its module's ``DESIGN``."""
    if name not in STUDIES + PAPER:
        raise ValueError(f"study must be one of {', '.join(STUDIES + PAPER)} (got {name!r})")
    return importlib.import_module(f"{__name__}.{name.replace('-', '_')}").DESIGN


def study(name: str, mode: str = "quick", **options: Any) -> Study:
    """The :class:`Study` (shared settings and points) of study ``name`` (:data:`STUDIES` or
    :data:`PAPER`) in ``mode`` (:data:`MODES`), with the study's own ``options``
    (:attr:`Design.options`, e.g. ``extra_Ns`` of the transition)."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)} (got {mode!r})")
    return design(name).build(mode, **options)


def study_command(name: str, mode: str) -> str:
    """The command line that computes study ``name`` in ``mode`` (shown beside each figure)."""
    command = design(name).command
    return command(mode) if command else f"stickslip study {name} --{mode} --out DIR"
