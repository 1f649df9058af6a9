"""Least-squares fits of rate-and-state parameters to friction records, with standard errors.

The model friction of record r at its samples is the quasi-static spring-slider's
(:func:`stickslip.lab.spring_slider.quasi_static`) plus an optional linear trend s_r (p(t) - p(t_0)) in
load-point displacement (``trend``; see also :func:`stickslip.lab.records.detrend`). The residuals
w_i (mu_model(t_i) - mu_i) of all records, inside their windows, are minimised by
:func:`scipy.optimize.least_squares` (trust-region reflective, bounds a > 0, D_c > 0, k > 0) over the
free parameters, each scaled by its starting value. Any subset of ``a``, ``b`` (``b1``), ``Dc``
(``Dc1``), ``b2``, ``Dc2``, ..., ``mu0``, ``k``, ``eta`` and ``trend`` may be free; a name in
``per_record`` takes one value per record (e.g. ``mu0`` or ``k`` of several tests fitted with shared
a, b and D_c), written ``mu0[0]``, ``mu0[1]``, ...

Standard errors and correlations come from the covariance s^2 (J^T J)^-1 at the solution, with J the
Jacobian of the residuals and s^2 = sum of squared residuals / (n - p) (as
:func:`scipy.optimize.curve_fit` without ``absolute_sigma``), through the pseudo-inverse of J.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import xarray as xr
from scipy.optimize import least_squares

from stickslip.lab.integrate import IntegrationError
from stickslip.lab.laws import RateState
from stickslip.lab.records import Record
from stickslip.lab.spring_slider import solve
from stickslip.models.params import ParameterError

__all__ = ["FitResult", "fit", "model_friction"]

#: Lower bounds of the parameters (the rest are free in sign).
_LOWER = {"a": 0.0, "Dc": 0.0, "k": 0.0, "eta": 0.0}


def base_name(name: str) -> str:
    """The parameter a fitted name sets: ``Dc2`` -> ``Dc``, ``b1`` -> ``b``, ``mu0`` -> ``mu0``.

    Parameters
    ----------
    name : str

    Returns
    -------
    str
    """
    for stem in ("Dc", "b"):
        if name.startswith(stem) and name[len(stem) :].isdigit():
            return stem
    return name


def start_value(model: RateState, name: str, trend: float = 0.0) -> float:
    """The model's value of a fitted name (``b2`` the second state variable's b; ``trend`` ``trend``).

    Parameters
    ----------
    model : RateState
    name : str
    trend : float
        The value of ``trend``.

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        An unknown name, a state variable the model lacks, an infinite or missing start.
    """
    if name == "trend":
        return trend
    base = base_name(name)
    if base in ("b", "Dc"):
        idx = int(name[len(base) :] or 1) - 1
        seq = getattr(model, base)
        if not 0 <= idx < len(seq):
            raise ParameterError(f"{name}: the model has {len(seq)} state variable(s)")
        return float(seq[idx])
    if name not in ("a", "mu0", "k", "eta"):
        raise ParameterError(
            f"cannot fit {name!r}: choose from a, b, Dc, b2, Dc2, ..., mu0, k, eta, trend (one state variable: b, Dc)"
        )
    value = getattr(model, name)
    if value is None or value == math.inf:
        raise ParameterError(f"{name} needs a finite starting value to be fitted")
    return float(value)


def model_friction(
    model: RateState, record: Record, *, trend: float = 0.0, rtol: float = 1e-10, method: str = "auto"
) -> np.ndarray:
    """The spring-slider's friction at the record's samples, plus ``trend`` times the load-point
    displacement since the first sample (the model of the module docstring).

    Parameters
    ----------
    model : RateState
    record : Record
    trend : float
    rtol : float
        Tolerance of the integration.
    method : str
        The integrator (:func:`stickslip.lab.spring_slider.quasi_static`).

    Returns
    -------
    numpy.ndarray
        mu at ``record.t``.
    """
    mu = solve(model, record.history, record.t, v_init=record.v_init, rtol=rtol, method=method)["mu"]
    if trend != 0.0:
        p = record.history.position(record.t)
        mu = mu + trend * (p - p[0])
    return mu


@dataclass
class FitResult:
    """What :func:`fit` found: the values, standard errors and correlations of the free parameters,
    the fitted model of each record and the residuals.

    Attributes
    ----------
    names : list of str
    values, errors : arrays
    correlation : array (p, p)
    models : list of RateState
        The fitted model of each record (with its own per-record values).
    trends : list of float
    records : list of Record
    predictions : list of arrays
        Model friction at each record's samples.
    cost, rms : float
        Half the sum of squared weighted residuals, and their root mean square.
    n, dof : int
        Samples fitted and degrees of freedom n - p.
    success : bool
    message : str
    evaluations : int
        Model evaluations (of all records) by least_squares.
    cpu_seconds : float
        CPU time of the fit (process time).
    """

    names: list[str]
    values: np.ndarray
    errors: np.ndarray
    correlation: np.ndarray
    models: list[RateState]
    trends: list[float]
    records: list[Record]
    predictions: list[np.ndarray]
    cost: float
    rms: float
    n: int
    dof: int
    success: bool
    message: str
    evaluations: int
    cpu_seconds: float
    extra: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> tuple[float, float]:
        """(value, standard error) of a fitted parameter."""
        i = self.names.index(name)
        return float(self.values[i]), float(self.errors[i])

    def summary(self) -> dict:
        """A JSON-able summary: values, errors, correlations, fit statistics, the fixed parameters."""
        return {
            "parameters": {
                n: {"value": float(v), "stderr": float(e)}
                for n, v, e in zip(self.names, self.values, self.errors, strict=True)
            },
            "correlation": {
                a: {b: float(self.correlation[i, j]) for j, b in enumerate(self.names)}
                for i, a in enumerate(self.names)
            },
            "model": {k: v for k, v in self.models[0].summary().items()},
            "records": [r.name for r in self.records],
            "samples": self.n,
            "dof": self.dof,
            "rms_residual": self.rms,
            "success": self.success,
            "message": self.message,
            "evaluations": self.evaluations,
            "cpu_seconds": self.cpu_seconds,
        }

    def to_dataset(self) -> xr.Dataset:
        """The data, model and residual of every sample (``sample`` dimension, with the record's
        index) and the parameters (``parameter`` dimension) with their correlation matrix."""
        rec = np.concatenate([np.full(r.t.size, i) for i, r in enumerate(self.records)])
        t = np.concatenate([r.t for r in self.records])
        mu = np.concatenate([r.mu for r in self.records])
        pred = np.concatenate(self.predictions)
        used = np.concatenate([r.mask for r in self.records])
        return xr.Dataset(
            {
                "t": ("sample", t, {"long_name": "time"}),
                "mu": ("sample", mu, {"long_name": "measured friction"}),
                "model": ("sample", pred, {"long_name": "fitted friction"}),
                "residual": ("sample", mu - pred, {"long_name": "data - model"}),
                "record": ("sample", rec),
                "fitted": ("sample", used.astype(np.int8), {"long_name": "1 where the sample is fitted"}),
                "value": ("parameter", self.values),
                "stderr": ("parameter", self.errors),
                "correlation": (("parameter", "parameter2"), self.correlation),
            },
            coords={"parameter": self.names, "parameter2": self.names},
            attrs={"records": ",".join(r.name for r in self.records), "rms_residual": self.rms, "dof": self.dof},
        )

    def __repr__(self) -> str:
        body = ", ".join(f"{n}={v:.5g}+-{e:.2g}" for n, v, e in zip(self.names, self.values, self.errors, strict=True))
        return f"FitResult({len(self.records)} record(s), {self.n} samples: {body})"


class Problem:
    """The least-squares problem of :func:`fit`: the free numbers (``slots``: name shown, parameter,
    record index or None), their scales, bounds and starting point, and the weighted residuals of
    all records at a point x of scaled parameters (each parameter over its starting value).

    Parameters
    ----------
    records, model, free, per_record, trend, rtol, method
        As for :func:`fit`.
    """

    def __init__(self, records, model, free, *, per_record=(), trend=0.0, rtol=1e-10, method="auto"):
        records = [records] if isinstance(records, Record) else list(records)
        if not records:
            raise ParameterError("fit needs at least one record")
        model.require_k()
        free = list(free)
        if len(set(free)) != len(free) or not free:
            raise ParameterError(f"free must name each parameter once, at least one (got {free})")
        for name in per_record:
            if name not in free:
                raise ParameterError(f"per_record names {name!r}, which is not free")
        slots = []
        for name in free:
            start_value(model, name, trend)
            if name in per_record:
                slots += [(f"{name}[{r}]", name, r) for r in range(len(records))]
            else:
                slots.append((name, name, None))
        start = np.array([start_value(model, name, trend) for _, name, _ in slots])
        is_trend = np.array([s[1] == "trend" for s in slots])
        self.scale = np.where(start != 0.0, np.abs(start), np.where(is_trend, 1e-4, 1e-2))
        self.lower = np.array([_LOWER.get(base_name(s[1]), -np.inf) for s in slots]) / self.scale
        self.x0 = start / self.scale
        self.records, self.model, self.slots, self.trend, self.rtol = records, model, slots, trend, rtol
        self.method = method
        self.masks = [r.mask for r in records]
        self.n = int(sum(m.sum() for m in self.masks))
        if self.n <= len(slots):
            raise ParameterError(f"fit needs more samples ({self.n}) than free parameters ({len(slots)})")
        self.calls = [0]

    def models_at(self, x) -> list[tuple[RateState, float]]:
        """The model and trend of each record at the scaled parameters x."""
        vals = np.asarray(x) * self.scale
        out = []
        for r in range(len(self.records)):
            kw, tr = {}, self.trend
            for (_, name, rr), v in zip(self.slots, vals, strict=True):
                if rr is not None and rr != r:
                    continue
                if name == "trend":
                    tr = v
                else:
                    kw[name] = v
            out.append((self.model.with_values(**kw) if kw else self.model, tr))
        return out

    def residuals(self, x) -> np.ndarray:
        """w_i (mu_model(t_i) - mu_i) of every fitted sample of every record."""
        self.calls[0] += 1
        res = []
        for (m, tr), rec, mask in zip(self.models_at(x), self.records, self.masks, strict=True):
            try:
                pred = model_friction(m, rec, trend=tr, rtol=self.rtol, method=self.method)
            except (IntegrationError, ParameterError):
                # A trial point where the slider runs away (or leaves the laws' range): a large,
                # finite residual steers the trust region back.
                pred = np.full(rec.t.size, 1e3)
            res.append((rec.weights * (pred - rec.mu))[mask])
        return np.concatenate(res)


def standard_errors(jac: np.ndarray, scale: np.ndarray, s2: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors and correlations of least-squares parameters from the covariance
    s2 (J^T J)^-1 at the solution (the pseudo-inverse of J, as scipy's curve_fit).

    Parameters
    ----------
    jac : array (n, p)
        The Jacobian of the residuals in the scaled parameters.
    scale : array (p,)
        The parameters' scales (value = scaled value * scale).
    s2 : float
        The residual variance (1 where the residuals are already divided by their errors).

    Returns
    -------
    tuple of arrays
        The standard errors (p,) and the correlation matrix (p, p).
    """
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    thresh = np.finfo(float).eps * max(jac.shape) * sv[0]
    sv = sv[sv > thresh]
    vt = vt[: sv.size]
    cov = (vt.T / sv**2) @ vt * s2 * np.outer(scale, scale)
    err = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(err, err)
    return err, corr


def fit(
    records: Record | Sequence[Record],
    model: RateState,
    free: Sequence[str] = ("a", "b", "Dc"),
    *,
    per_record: Sequence[str] = (),
    trend: float = 0.0,
    rtol: float = 1e-10,
    method: str = "auto",
    diff_step: float = 1e-6,
    max_evaluations: int | None = None,
) -> FitResult:
    """Fit rate-and-state parameters to one or several records (module docstring).

    Parameters
    ----------
    records : Record or sequence of Record
        Fitted together, with shared parameters except those in ``per_record``.
    model : RateState
        Starting values of the free parameters and values of the fixed ones (k is required).
    free : sequence of str
        The parameters fitted.
    per_record : sequence of str
        Free parameters with one value per record.
    trend : float
        Starting (or fixed) slope of a linear friction trend in load-point displacement.
    rtol : float
        Tolerance of the spring-slider's integration.
    method : str
        Its integrator (:func:`stickslip.lab.spring_slider.quasi_static`).
    diff_step : float
        Relative step of the finite-difference Jacobian.

    Returns
    -------
    FitResult

    Raises
    ------
    ParameterError
        Unknown or repeated names, a per-record name that is not free, no records, fewer samples
        than free parameters.

    Examples
    --------
    >>> from stickslip.lab import LoadHistory, RateState
    >>> from stickslip.lab.records import synthetic
    >>> true = RateState(a=0.005, b=0.008, Dc=20.0, mu0=0.6, V0=1.0, k=1e-3)
    >>> rec = synthetic(true, LoadHistory.steps([1.0, 10.0], [50.0, 50.0]), n=200)
    >>> res = fit(rec, true.with_values(a=0.006, b=0.006, Dc=10.0), ("a", "b", "Dc"))
    >>> [round(float(v), 4) for v in res.values]
    [0.005, 0.008, 20.0]
    """
    problem = Problem(records, model, free, per_record=per_record, trend=trend, rtol=rtol, method=method)
    records, slots, scale = problem.records, problem.slots, problem.scale
    x0, lower, n = problem.x0, problem.lower, problem.n
    models_at, residuals = problem.models_at, problem.residuals
    calls = problem.calls

    cpu0 = time.process_time()
    sol = least_squares(
        residuals,
        x0,
        bounds=(np.where(np.isfinite(lower), lower + 1e-12, -np.inf), np.inf),
        method="trf",
        x_scale="jac",
        diff_step=diff_step,
        max_nfev=max_evaluations,
    )
    cpu = time.process_time() - cpu0
    values = sol.x * scale
    dof = n - len(slots)
    s2 = 2.0 * sol.cost / dof
    err, corr = standard_errors(sol.jac, scale, s2)
    fitted = models_at(sol.x)
    preds = [
        model_friction(m, rec, trend=tr, rtol=rtol, method=method) for (m, tr), rec in zip(fitted, records, strict=True)
    ]
    return FitResult(
        names=[s[0] for s in slots],
        values=values,
        errors=err,
        correlation=corr,
        models=[m for m, _ in fitted],
        trends=[tr for _, tr in fitted],
        records=records,
        predictions=preds,
        cost=float(sol.cost),
        rms=float(np.sqrt(2.0 * sol.cost / n)),
        n=n,
        dof=dof,
        success=bool(sol.success),
        message=str(sol.message),
        evaluations=calls[0],
        cpu_seconds=cpu,
        extra={"problem": problem, "sigma": math.sqrt(s2)},
    )
