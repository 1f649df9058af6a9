"""Rate-and-state friction as a rock-friction laboratory writes it, with any number of state variables.

Friction at slip rate v with state variables theta_1 .. theta_m (Dieterich 1979, Ruina 1983):

    mu(v, theta) = mu0 + a ln(v / V0) + sum_k b_k ln(V0 theta_k / (s_k D_c,k))     (log form)
    mu(v, theta) = a asinh( v / (2 V0) exp(psi / a) ),  psi = mu0 + sum_k b_k ln(...)  (asinh form)

(the asinh form is the log form regularised at v = 0: Rice and Ben-Zion 1996, Lapusta et al. 2000).
Each state variable has its own evolution law, with x_k = v theta_k / (s_k D_c,k):

- ``aging`` (Dieterich):  dtheta/dt = 1 - x,  s = 1;
- ``slip`` (Ruina):       dtheta/dt = -x ln x,  s = 1;
- ``prz`` (Perrin, Rice and Zheng 1995): dtheta/dt = 1 - x^2,  s = 2 (friction term
  b ln(V0 theta / 2 D_c));
- ``nagata`` (Nagata, Nakatani and Yoshida 2012): dtheta/dt = 1 - x - (c / b) theta dtau/dt,
  s = 1, with tau the shear stress (friction) the spring applies.

At steady sliding x_k = 1, theta_k = s_k D_c,k / V, and every law gives
mu_ss = mu0 + (a - sum_k b_k) ln(V / V0).

The parameters are the lab's: friction mu (shear over normal stress), a, b_k, D_c,k (a length, e.g.
um), mu0 at the reference velocity V0, and, for the spring-slider of :mod:`stickslip.lab.spring_slider`,
the stiffness k in friction per unit displacement and an optional radiation damping eta (friction
per unit slip rate). The compiled friction and right-hand side (:func:`stickslip.lab.compiled.rhs`)
are what the integrators evaluate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from stickslip.lab.compiled import friction, lab_laws, rhs
from stickslip.models.params import ParameterError, check_number

__all__ = ["LAWS", "RateState", "friction_of", "rhs", "steady_friction", "steady_theta"]


@dataclass(frozen=True)
class Law:
    """One state-evolution law as the lab names it: its code in :func:`rhs` (its place among
    :func:`~stickslip.lab.compiled.lab_laws`), its friction module (whose ``lab_rate`` :func:`rhs`
    calls), the scale s of D_c, its equation and reference, and whether its rate reads the stress
    rate (:class:`~stickslip.models.piece.LabLaw`)."""

    name: str
    code: int
    module: str
    scale: float
    equation: str
    reference: str
    reads_stress_rate: bool


#: The evolution laws by name: the friction laws that declare their lab form, each its own module
#: (:data:`stickslip.models.pieces.FRICTIONS`).
LAWS = {
    p.lab.name: Law(p.lab.name, code, p.module, p.lab.scale, p.lab.equation, p.lab.reference, bool(p.context))
    for code, p in enumerate(lab_laws())
}

#: The friction forms by name, and their code in :func:`rhs`.
FORMS = {"log": 0, "asinh": 1}


def _tuple(name: str, value, n: int | None = None) -> tuple:
    if value is None:
        return ()
    if isinstance(value, str) or not isinstance(value, Sequence | np.ndarray):
        value = (value,)
    value = tuple(value)
    if n is not None and len(value) != n:
        raise ParameterError(f"{name} needs one value per state variable ({n}; got {len(value)})")
    return value


@dataclass(frozen=True)
class RateState:
    """Rate-and-state friction and the spring-slider it sits in, in the lab's conventions
    (module docstring): mu = mu0 + a ln(v / V0) + sum_k b_k ln(V0 theta_k / (s_k D_c,k)).

    Parameters
    ----------
    a : float
        Direct-effect coefficient a > 0.
    b : float or sequence of float
        Evolution-effect coefficient b_k of each state variable (one number: one state variable).
    Dc : float or sequence of float
        Critical slip distance D_c,k > 0 of each state variable (length, e.g. um).
    mu0 : float
        Steady-state friction at V0.
    V0 : float
        Reference velocity V0 > 0 (length per time, e.g. um/s).
    k : float, optional
        Spring stiffness in friction per unit displacement (> 0); needed by the spring-slider.
        ``math.inf`` is a rigid machine: the slip rate is the load point's, v = V(t), and only
        the state variables evolve (the closed forms of the laws at imposed v).
    law : str or sequence of str
        Evolution law of each state variable: ``aging``, ``slip``, ``prz`` or ``nagata``.
    c : float or sequence of float
        Nagata's stress-rate coefficient c_k (used by ``nagata`` only; default 0).
    eta : float
        Radiation damping: the spring's friction k (p - x) = mu + eta v (default 0).
    form : str
        ``log`` (default) or ``asinh`` (regularised at v = 0).

    Raises
    ------
    ParameterError
        A required parameter left out (a, b, Dc, mu0, V0), or one out of range.

    Examples
    --------
    >>> m = RateState(a=0.005, b=0.01, Dc=10.0, mu0=0.6, V0=1.0, k=1e-3)
    >>> round(steady_friction(m, 10.0), 6)
    0.588487
    """

    a: float | None = None
    b: float | Sequence[float] | None = None
    Dc: float | Sequence[float] | None = None
    mu0: float | None = None
    V0: float | None = None
    k: float | None = None
    law: str | Sequence[str] = "aging"
    c: float | Sequence[float] = 0.0
    eta: float = 0.0
    form: str = "log"

    def __post_init__(self):
        for name in ("a", "b", "Dc", "mu0", "V0"):
            if getattr(self, name) is None:
                raise ParameterError(f"{name} is required ({PARAM_TEXT[name]}); no default is assumed")
        b = _tuple("b", self.b)
        m = len(b)
        if m == 0:
            raise ParameterError("b needs at least one value (one per state variable)")
        dc = _tuple("Dc", self.Dc, m)
        law = _tuple("law", self.law)
        law = law * m if len(law) == 1 else law
        if len(law) != m:
            raise ParameterError(f"law needs one name per state variable ({m}; got {len(law)})")
        c = _tuple("c", self.c)
        c = c * m if len(c) == 1 else c
        if len(c) != m:
            raise ParameterError(f"c needs one value per state variable ({m}; got {len(c)})")
        for name in law:
            if name not in LAWS:
                raise ParameterError(f"law must be one of {', '.join(LAWS)} (got {name!r})")
        if self.form not in FORMS:
            raise ParameterError(f"form must be one of {', '.join(FORMS)} (got {self.form!r})")
        put = lambda name, value: object.__setattr__(self, name, value)
        put("a", check_number("a", self.a, low=0.0, low_open=True))
        put("mu0", check_number("mu0", self.mu0))
        put("V0", check_number("V0", self.V0, low=0.0, low_open=True))
        put("b", tuple(check_number(f"b[{i}]" if m > 1 else "b", x) for i, x in enumerate(b)))
        put(
            "Dc",
            tuple(check_number(f"Dc[{i}]" if m > 1 else "Dc", x, low=0.0, low_open=True) for i, x in enumerate(dc)),
        )
        put("law", law)
        put("c", tuple(check_number("c", x) for x in c))
        put("eta", check_number("eta", self.eta, low=0.0))
        if self.k is not None and not (isinstance(self.k, float | int) and self.k == math.inf):
            put("k", check_number("k", self.k, low=0.0, low_open=True))
        for i, (name, bk) in enumerate(zip(law, self.b, strict=True)):
            if not LAWS[name].reads_stress_rate:
                continue
            if self.k == math.inf:
                raise ParameterError(f"{name}'s law needs a finite k (its rate reads the stress rate k (V - v))")
            if bk == 0.0 and self.c[i] != 0.0:
                raise ParameterError(f"{name}'s law needs b != 0 where c != 0 (its term is (c / b) theta dtau/dt)")

    @property
    def n_states(self) -> int:
        """The number m of state variables."""
        return len(self.b)

    def with_values(self, **values) -> RateState:
        """A copy with some parameters changed (``b2``, ``Dc2`` name the second state variable's)."""
        kw = {f.name: getattr(self, f.name) for f in fields(self)}
        b, dc = list(kw["b"]), list(kw["Dc"])
        for name, value in values.items():
            if name[:-1] in ("b", "Dc") and name[-1].isdigit():
                idx = int(name[-1]) - 1
                if not 0 <= idx < len(b):
                    raise ParameterError(f"{name}: there are {len(b)} state variables")
                (b if name[0] == "b" else dc)[idx] = value
            elif name in ("b", "Dc") and np.ndim(value) == 0:
                (b if name == "b" else dc)[0] = value
            elif name in kw:
                kw[name] = value
                if name == "b":
                    b = list(_tuple("b", value))
                if name == "Dc":
                    dc = list(_tuple("Dc", value))
            else:
                raise ParameterError(f"{name} is not a parameter of the friction law")
        kw["b"], kw["Dc"] = tuple(b), tuple(dc)
        return RateState(**kw)

    def require_k(self) -> float:
        """The stiffness k, or a ParameterError that says the spring-slider needs it."""
        if self.k is None:
            raise ParameterError(f"k is required by the spring-slider ({PARAM_TEXT['k']}); no default is assumed")
        return self.k

    def arrays(self, M: float = 0.0):
        """The arguments of :func:`rhs` after ``t, y, out, vlp``, for the quasi-static spring-slider
        (M = 0) or the inertial one of mass M per unit normal stress."""
        codes = np.array([LAWS[n].code for n in self.law], dtype=np.int64)
        scale = np.array([LAWS[n].scale for n in self.law])
        b = np.array(self.b, dtype=float)
        cb = np.array([c / bk if c != 0.0 else 0.0 for c, bk in zip(self.c, self.b, strict=True)])
        return (
            self.a, self.mu0, self.V0, 0.0 if self.k is None else self.k, self.eta, FORMS[self.form],
            b, np.array(self.Dc, dtype=float) * scale, cb, codes, float(M),
        )  # fmt: skip

    def summary(self) -> dict:
        """The parameters by name, for JSON."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


#: What each required parameter is, for the error that names it.
PARAM_TEXT = {
    "a": "direct-effect coefficient, > 0",
    "b": "evolution-effect coefficient of each state variable",
    "Dc": "critical slip distance of each state variable, > 0",
    "mu0": "steady-state friction at V0",
    "V0": "reference velocity, > 0",
    "k": "stiffness in friction per unit displacement, > 0",
}


def steady_theta(m: RateState, V: float) -> np.ndarray:
    """theta_k = s_k D_c,k / V of steady sliding at V > 0 (x_k = 1 for every law; module docstring).

    Parameters
    ----------
    m : RateState
    V : float

    Returns
    -------
    numpy.ndarray
        One theta per state variable.
    """
    V = check_number("V", V, low=0.0, low_open=True)
    return np.array([LAWS[n].scale * dc / V for n, dc in zip(m.law, m.Dc, strict=True)])


def friction_of(m: RateState, v: float, theta) -> float:
    """mu(v, theta) of the model ``m`` (module docstring; -inf at v = 0 in the log form).

    Parameters
    ----------
    m : RateState
    v : float
        Slip rate.
    theta : float or array
        One state per state variable.

    Returns
    -------
    float
    """
    a, mu0, V0, _, _, form, b, sdc, *_ = m.arrays()
    return float(friction(float(v), np.asarray(theta, dtype=float).reshape(-1), a, mu0, V0, form, b, sdc))


def steady_friction(m: RateState, V: float) -> float:
    """mu_ss(V) = mu0 + (a - sum b) ln(V / V0) (log form; the asinh form differs by terms of
    relative size exp(-2 mu_ss / a)), as :func:`friction` evaluates it at steady state.

    Parameters
    ----------
    m : RateState
    V : float

    Returns
    -------
    float
    """
    return friction_of(m, V, steady_theta(m, V))
