"""The rock-friction laboratory: load histories, the quasi-static spring-slider, fitting.

A layer of its own beside :mod:`stickslip.analysis`: it imports :mod:`stickslip.models`, the
chain's runs (:mod:`stickslip.run`, for the inertial route) and the shared helpers, never the
plotting, the reports or the command line.

- :class:`LoadHistory`: velocity steps, holds, tables and lab records (CSV) of the load point;
- :class:`RateState`: rate-and-state friction in the lab's conventions, any number of state
  variables, each with its own law (aging, slip, PRZ, Nagata), log or asinh form;
- :func:`quasi_static`: the massless spring-slider k (p - x) = mu + eta v over a history;
- :func:`inertial_slider`: the spring-slider with a mass M, any number of state variables, adaptive;
- :func:`critical_stiffness`: k_c of steady sliding, one or more state variables;
- :func:`fit`: least-squares fits of records, with standard errors and correlations;
- :mod:`stickslip.lab.protocols`: velocity steps and slide-hold-slide tests as one call;
- :func:`invert_stick_slip`: the inertial spring-slider (:mod:`stickslip.lab.inertial`) fitted
  to the periods, stress drops and peak slip rates of a stick-slip record
  (:mod:`stickslip.lab.cycles`).
"""

from stickslip.lab.fitting import FitResult, fit
from stickslip.lab.history import LoadHistory
from stickslip.lab.inertial_ode import inertial_slider
from stickslip.lab.inversion import StickSlipResult, invert_stick_slip
from stickslip.lab.laws import LAWS, RateState, steady_friction, steady_theta
from stickslip.lab.protocols import slide_hold_slide, velocity_step
from stickslip.lab.records import Record, detrend, synthetic
from stickslip.lab.spring_slider import quasi_static
from stickslip.lab.stability import critical_stiffness

__all__ = [
    "LAWS",
    "FitResult",
    "LoadHistory",
    "RateState",
    "Record",
    "StickSlipResult",
    "critical_stiffness",
    "detrend",
    "fit",
    "inertial_slider",
    "invert_stick_slip",
    "quasi_static",
    "slide_hold_slide",
    "steady_friction",
    "steady_theta",
    "synthetic",
    "velocity_step",
]
