"""Inversion of inertial stick-slip records: rate-and-state parameters from periods, stress drops
and peak slip rates.

The data are a friction record of a stick-slip test (a :class:`~stickslip.lab.records.Record`:
time, friction, load history) or a table of its cycles (one row per cycle: ``period``,
``stress_drop``, ``peak_slip_rate``, ``peak_friction``, any of them). Their observables
(:mod:`stickslip.lab.cycles`) are averaged over the cycles, each mean with its standard error s_j
(the scatter between cycles over the square root of their number) widened by a floor
``floor`` ``|mean_j|`` (``floor`` times the stress drop for the peak friction, a level) that
stands for the model's own error. The forward model is the inertial
spring-slider (:mod:`stickslip.lab.inertial`: the chain's single block with a mass M, no static
threshold), run over the record's load history (or at the table's V for ``t_end``) and sampled at
the record's times (or every ``sample_interval``), its cycles measured the same way in the same
window. :func:`scipy.optimize.least_squares` minimises sum_j ((model_j - mean_j) / s_j)^2 over
the free parameters (any of a, b, Dc, mu0, k, M), each scaled by its starting value.

The residuals are in units of the data's standard errors, so the covariance of the parameters is
(J^T J)^-1 with J the Jacobian of the residuals at the solution (:func:`scipy.optimize.curve_fit`
with ``absolute_sigma=True``), through the pseudo-inverse of J; chi^2 = sum of squared residuals
says whether the model explains the data within their errors (about the degrees of freedom
n - p where n > p).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import least_squares

from stickslip.lab.cycles import OBSERVABLES, cycle_table, observables
from stickslip.lab.fitting import base_name, standard_errors, start_value
from stickslip.lab.history import LoadHistory
from stickslip.lab.inertial import check_route, sample
from stickslip.lab.laws import RateState
from stickslip.lab.records import Record
from stickslip.models.params import ParameterError, check_number

__all__ = ["FREE", "StickSlipResult", "invert_stick_slip"]

#: The parameters an inversion may fit, each with its lower bound.
FREE = {"a": 0.0, "b": -math.inf, "Dc": 0.0, "mu0": -math.inf, "k": 0.0, "M": 0.0, "eta": 0.0}


@dataclass
class StickSlipResult:
    """What :func:`invert_stick_slip` found.

    Attributes
    ----------
    names : list of str
        The free parameters.
    values, errors : arrays
        Their fitted values and standard errors.
    correlation : array (p, p)
    model : RateState
        The fitted friction law and k.
    M : float
        The fitted (or fixed) mass.
    observables : list of str
    observed, stderr, predicted : arrays
        The data's means and their standard errors (with the floor), and the fitted model's.
    cycles : pandas.DataFrame
        The data's cycles (:func:`stickslip.lab.cycles.cycle_table`).
    model_cycles : pandas.DataFrame
        The fitted model's cycles.
    series : dict
        The fitted model's samples (``t``, ``mu``, ``v``) and, for a record, the data's (``data_t``,
        ``data_mu``); the window read (``window``).
    chi2 : float
        Sum of squared residuals (in standard errors).
    dof : int
        Observables less free parameters.
    success : bool
    message : str
    evaluations : int
        Forward-model runs by least_squares.
    cpu_seconds : float
        CPU time of the inversion (process time).
    settings : dict
        dt, V, window, sampling and the fixed parameters.
    """

    names: list[str]
    values: np.ndarray
    errors: np.ndarray
    correlation: np.ndarray
    model: RateState
    M: float
    observables: list[str]
    observed: np.ndarray
    stderr: np.ndarray
    predicted: np.ndarray
    cycles: pd.DataFrame
    model_cycles: pd.DataFrame
    series: dict
    chi2: float
    dof: int
    success: bool
    message: str
    evaluations: int
    cpu_seconds: float
    settings: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> tuple[float, float]:
        """(value, standard error) of a fitted parameter."""
        i = self.names.index(name)
        return float(self.values[i]), float(self.errors[i])

    def summary(self) -> dict:
        """A JSON-able summary: values, errors, correlations, observables, fit statistics."""
        return {
            "kind": "stick-slip",
            "parameters": {
                n: {"value": float(v), "stderr": float(e)}
                for n, v, e in zip(self.names, self.values, self.errors, strict=True)
            },
            "correlation": {
                a: {b: float(self.correlation[i, j]) for j, b in enumerate(self.names)}
                for i, a in enumerate(self.names)
            },
            "observables": {
                o: {"observed": float(m), "stderr": float(s), "model": float(p)}
                for o, m, s, p in zip(self.observables, self.observed, self.stderr, self.predicted, strict=True)
            },
            "cycles": len(self.cycles),
            "model": {**self.model.summary(), "M": self.M},
            "chi2": self.chi2,
            "dof": self.dof,
            "success": self.success,
            "message": self.message,
            "evaluations": self.evaluations,
            "cpu_seconds": self.cpu_seconds,
            "settings": self.settings,
        }

    def to_dataset(self) -> xr.Dataset:
        """The observables (``observable`` dimension: observed, stderr, model), the parameters
        (``parameter``: value, stderr, correlation) and the fitted model's friction over ``t``."""
        s = self.series
        return xr.Dataset(
            {
                "observed": ("observable", self.observed),
                "observed_stderr": ("observable", self.stderr),
                "model": ("observable", self.predicted),
                "value": ("parameter", self.values),
                "stderr": ("parameter", self.errors),
                "correlation": (("parameter", "parameter2"), self.correlation),
                "model_mu": ("t", s["mu"], {"long_name": "fitted model's friction k (p - x)"}),
                "model_v": ("t", s["v"], {"long_name": "fitted model's slip rate"}),
            },
            coords={
                "observable": self.observables,
                "parameter": self.names,
                "parameter2": self.names,
                "t": ("t", s["t"], {"long_name": "time"}),
            },
            attrs={"kind": "stick-slip inversion", "chi2": self.chi2, "dof": self.dof, "M": self.M},
        )

    def __repr__(self) -> str:
        body = ", ".join(f"{n}={v:.5g}+-{e:.2g}" for n, v, e in zip(self.names, self.values, self.errors, strict=True))
        return f"StickSlipResult({len(self.cycles)} cycles, chi2 {self.chi2:.3g}: {body})"


def _read_table(table: pd.DataFrame) -> pd.DataFrame:
    known = [c for c in OBSERVABLES if c in table]
    if not known:
        raise ParameterError(f"a table of cycles needs at least one of the columns {', '.join(OBSERVABLES)}")
    return table


class _Forward:
    """The forward model of one inversion: the run, its samples and its cycles at given parameters."""

    def __init__(self, data, model, M, *, dt, V, window, t_end, sample_interval, kick):
        self.model, self.M, self.dt, self.kick = model, M, dt, kick
        if isinstance(data, Record):
            self.history = data.history
            self.t = data.t if window is None else data.t[(data.t >= window[0]) & (data.t <= window[1])]
            self.window = window
        else:
            self.history = LoadHistory.steps([V], [t_end])
            self.window = (0.4 * t_end, t_end) if window is None else window
            n = int(math.floor((self.window[1] - self.window[0]) / sample_interval)) + 1
            self.t = self.window[0] + sample_interval * np.arange(n)
        self.V = V

    def run(self, model: RateState, M: float) -> tuple[dict, pd.DataFrame]:
        s = sample(model, M, self.history, self.t, dt=self.dt, kick=self.kick)
        table = cycle_table(s["t"], s["mu"], V=self.V, k=model.k)
        return s, table


def _means(table: pd.DataFrame, names, k: float, V: float, from_record: bool) -> tuple[np.ndarray, np.ndarray]:
    """The observables' means and standard errors; from a record, the peak slip rate is
    V + (peak drop rate) / k with the k of the model compared (dmu/dt = k (V - v) holds for the
    spring), so that a fitted k reads the record as the model does."""
    mean, err, _ = observables(table, names)
    if from_record and "peak_slip_rate" in names:
        i = list(names).index("peak_slip_rate")
        rate, rate_err, _ = observables(table.drop(columns="peak_slip_rate").rename(
            columns={"peak_drop_rate": "peak_slip_rate"}), ["peak_slip_rate"])  # fmt: skip
        mean[i], err[i] = V + rate[0] / k, rate_err[0] / k
    return mean, err


def invert_stick_slip(
    data: Record | pd.DataFrame,
    model: RateState,
    M: float,
    free: Sequence[str] = ("a", "b", "Dc"),
    *,
    observables_: Sequence[str] | None = None,
    dt: float | None = None,
    V: float | None = None,
    window: tuple[float, float] | None = None,
    t_end: float | None = None,
    sample_interval: float | None = None,
    floor: float = 1e-3,
    kick: float = 0.5,
    diff_step: float = 1e-2,
    max_evaluations: int | None = 60,
) -> StickSlipResult:
    """Fit the inertial spring-slider to the cycles of a stick-slip record (module docstring).

    Parameters
    ----------
    data : Record or pandas.DataFrame
        A friction record of the test, or a table of its cycles (columns of
        :data:`~stickslip.lab.cycles.OBSERVABLES`).
    model : RateState
        Starting values of the free parameters and values of the fixed ones: a, b, D_c, mu0, V0,
        k, eta (any number of state variables, each its law; the inertial route reads the asinh
        form: :func:`stickslip.lab.inertial.sample`).
    M : float
        Mass per unit normal stress (starting value where ``M`` is free).
    free : sequence of str
        The parameters fitted, of a, b, Dc (b2, Dc2, ... for further state variables), mu0, k, eta, M.
    observables_ : sequence of str
        The observables compared (of :data:`~stickslip.lab.cycles.OBSERVABLES`), at least as many
        as free parameters; default all four for a record, the table's columns for a table.
    dt : float, optional
        The integrator's step (default M / 4 at the starting M, kept through the fit).
    V : float, optional
        Load-point velocity: for a table, required; for a record, default the load point's mean
        velocity over the window.
    window : (t0, t1), optional
        The times read (data and model alike); default for a record its second half, for a table
        the last 60% of the model run.
    t_end, sample_interval : float, optional
        For a table: the model run's length (default 12 observed periods) and its sampling (default
        the observed period / 200).
    floor : float
        Relative floor of each observable's standard error (default 1e-3).
    kick : float
        Relative kick of the model's start from steady sliding (:func:`stickslip.lab.inertial.sample`).
    diff_step : float
        Relative step of the finite-difference Jacobian.
    max_evaluations : int, optional
        Bound on the forward-model runs of least_squares.

    Returns
    -------
    StickSlipResult

    Raises
    ------
    ParameterError
        An unknown or repeated name, fewer observables than free parameters, a table without V,
        fewer than two cycles in the data's window, a model the inertial route lacks.

    Examples
    --------
    >>> from stickslip.lab import LoadHistory, RateState
    >>> from stickslip.lab.inversion import invert_stick_slip, synthetic_stick_slip
    >>> true = RateState(a=0.005, b=0.01, Dc=1.0, mu0=0.6, V0=1.0, k=2.5e-3)
    >>> rec = synthetic_stick_slip(true, 1e-2, LoadHistory.steps([1.0], [250.0]), sample_interval=0.1)
    >>> res = invert_stick_slip(rec, true.with_values(a=0.0055, b=0.0095), 1e-2, ("a", "b"))
    >>> [round(float(v), 4) for v in res.values]
    [0.005, 0.01]
    """
    free = list(free)
    if not free or len(set(free)) != len(free):
        raise ParameterError(f"free must name each parameter once, at least one (got {free})")
    for name in free:
        if base_name(name) not in FREE:
            raise ParameterError(
                f"cannot fit {name!r} to stick-slip cycles: choose from {', '.join(FREE)} (b2, Dc2, ... for the "
                "further state variables)"
            )
        if name != "M":
            start_value(model, name)  # a state variable the model lacks, a start it cannot take
    if observables_ is None:
        present = data.columns if isinstance(data, pd.DataFrame) else OBSERVABLES
        observables_ = [o for o in OBSERVABLES if o in present]
    names = list(observables_)
    if len(set(names)) != len(names) or any(n not in OBSERVABLES for n in names):
        raise ParameterError(f"observables must be distinct names of {', '.join(OBSERVABLES)} (got {names})")
    if len(names) < len(free):
        raise ParameterError(f"{len(free)} free parameters need at least as many observables (got {len(names)})")
    k0 = check_route(model)
    M = check_number("M", M, low=0.0, low_open=True)
    dt = M / 4.0 if dt is None else check_number("dt", dt, low=0.0, low_open=True)
    floor = check_number("floor", floor, low=0.0)
    from_record = isinstance(data, Record)
    if from_record:
        h, t = data.history, data.t
        if window is None:
            window = (0.5 * (t[0] + t[-1]), float(t[-1]))
        if not window[0] < window[1]:
            raise ParameterError(f"window must be (t0, t1) with t0 < t1 (got {window!r})")
        if V is None:
            V = float((h.position(window[1]) - h.position(window[0])) / (window[1] - window[0]))
        V = check_number("V", V, low=0.0, low_open=True)
        cycles = cycle_table(t, data.mu, V=V, k=k0, window=window)
    else:
        if not isinstance(data, pd.DataFrame):
            raise ParameterError("data must be a Record or a table of cycles (a pandas DataFrame)")
        cycles = _read_table(data)
        missing = [n for n in names if n not in cycles]
        if missing:
            raise ParameterError(f"the table of cycles has no column {', '.join(missing)}: leave it out of observables")
        if V is None:
            raise ParameterError("a table of cycles needs the load-point velocity V (> 0)")
        V = check_number("V", V, low=0.0, low_open=True)
        if "period" in cycles:
            period = float(np.nanmean(cycles["period"]))
        elif t_end is None or sample_interval is None:
            raise ParameterError("without a period column, give t_end and sample_interval")
        t_end = 12.0 * period if t_end is None else check_number("t_end", t_end, low=0.0, low_open=True)
        if sample_interval is None:
            sample_interval = period / 200.0
        sample_interval = check_number("sample_interval", sample_interval, low=dt)
    fwd = _Forward(data, model, M, dt=dt, V=V, window=window, t_end=t_end, sample_interval=sample_interval, kick=kick)

    # the floor's scale: each observable's size, the stress drop for a friction level
    drop = float(np.nanmean(cycles["stress_drop"])) if "stress_drop" in cycles else np.nan

    def observed_at(k):
        mean, err = _means(cycles, names, k, V, from_record)
        size = np.array(
            [drop if (n == "peak_friction" and np.isfinite(drop)) else abs(m) for n, m in zip(names, mean, strict=True)]
        )
        return mean, np.sqrt(np.nan_to_num(err) ** 2 + (floor * size) ** 2)

    start = np.array([M if n == "M" else start_value(model, n) for n in free], dtype=float)
    scale = np.where(start != 0.0, np.abs(start), 1.0)
    lower = np.array([FREE[base_name(n)] for n in free]) / scale
    calls = [0]

    def at(x):
        vals = dict(zip(free, np.asarray(x) * scale, strict=True))
        m_ = vals.pop("M", M)
        return (model.with_values(**vals) if vals else model), m_

    def predicted(mod, m_):
        s, table = fwd.run(mod, m_)
        mean, _ = _means(table, names, mod.k, V, False)
        return s, table, mean

    def residuals(x):
        calls[0] += 1
        mod, m_ = at(x)
        obs, se = observed_at(mod.k)
        try:
            _, _, pred = predicted(mod, m_)
        except Exception as exc:  # noqa: BLE001 - a trial point without stick-slip, or a blow-up
            from stickslip.run.errors import NonFiniteState

            if not isinstance(exc, (ParameterError, NonFiniteState, FloatingPointError)):
                raise
            return np.full(len(names), 1e4)
        r = (pred - obs) / se
        return np.where(np.isfinite(r), r, 1e4)

    cpu0 = time.process_time()
    sol = least_squares(
        residuals,
        start / scale,
        bounds=(np.where(np.isfinite(lower), lower + 1e-12, -np.inf), np.inf),
        method="trf",
        x_scale="jac",
        diff_step=diff_step,
        max_nfev=max_evaluations,
        ftol=1e-4,
        xtol=1e-6,
    )
    cpu = time.process_time() - cpu0
    err, corr = standard_errors(sol.jac, scale)
    mod, m_ = at(sol.x)
    series, model_cycles, pred = predicted(mod, m_)
    obs, se = observed_at(mod.k)
    if from_record:
        series = {**series, "data_t": data.t, "data_mu": data.mu, "window": fwd.window}
    else:
        series = {**series, "window": fwd.window}
    return StickSlipResult(
        names=free,
        values=sol.x * scale,
        errors=err,
        correlation=corr,
        model=mod,
        M=float(m_),
        observables=names,
        observed=obs,
        stderr=se,
        predicted=pred,
        cycles=cycles,
        model_cycles=model_cycles,
        series=series,
        chi2=float(2.0 * sol.cost),
        dof=len(names) - len(free),
        success=bool(sol.success),
        message=str(sol.message),
        evaluations=calls[0],
        cpu_seconds=cpu,
        settings={"dt": dt, "V": V, "window": list(fwd.window), "floor": floor, "kick": kick,
                  "samples": int(fwd.t.size), "data": "record" if from_record else "table of cycles"},
    )  # fmt: skip


def synthetic_stick_slip(
    model: RateState,
    M: float,
    history: LoadHistory,
    *,
    sample_interval: float,
    dt: float | None = None,
    noise: float = 0.0,
    rng=None,
    kick: float = 0.5,
    name: str = "",
) -> Record:
    """A stick-slip record of the inertial spring-slider with known parameters
    (:func:`stickslip.lab.inertial.sample`), sampled every ``sample_interval`` over the history,
    with Gaussian noise of standard deviation ``noise`` added to the friction.

    Parameters
    ----------
    model : RateState
    M : float
    history : LoadHistory
    sample_interval : float
    dt : float, optional
        The integrator's step (default M / 4).
    noise : float
    rng : numpy.random.Generator or int, optional
    kick : float
    name : str

    Returns
    -------
    Record
    """
    sample_interval = check_number("sample_interval", sample_interval, low=0.0, low_open=True)
    n = int(math.floor((history.t_end - history.times[0]) / sample_interval + 1e-9)) + 1
    t = history.times[0] + sample_interval * np.arange(n)
    s = sample(model, M, history, t, dt=M / 4.0 if dt is None else dt, kick=kick)
    mu = s["mu"].copy()
    if noise > 0.0:
        mu += np.random.default_rng(rng).normal(0.0, noise, mu.size)
    return Record(t, mu, history, name=name or "synthetic stick-slip")
