"""The named models as data: the paper's chain and the relatives it cites (docs/model.md, "Preset
defaults"), each a :class:`Preset` of :data:`PRESETS`.

The one list of the models' names (``ChainParams.model`` takes its choices from here);
:mod:`stickslip.models.presets` builds parameters from them. Adding a model means adding an entry here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Preset:
    """A named model: pieces, parameter defaults, start, and what it is in words."""

    name: str
    title: str
    pieces: dict[str, str]
    params: dict[str, Any]
    start: str
    start_options: dict[str, Any] = field(default_factory=dict)
    equations: str = ""
    source: str = ""
    note: str = ""
    #: the note is a caveat on the model itself, so every run of it records the note
    note_in_runs: bool = False
    symbols: dict[str, str] = field(default_factory=dict)  # the model's own names -> ChainParams fields
    #: a short name for tables and figure labels (the preset's name when empty)
    label: str = ""

    def reads(self) -> tuple[str, ...]:
        """Parameters the preset's pieces read besides N, K, V and dt (docs/model.md's family table)."""
        from stickslip.models.pieces import reads

        return reads(**self.pieces)

    def point_label(self, beta: float, N: int, *, with_N: bool = True) -> str:
        """How a study names one of its points: by beta where the friction reads beta (eq. 4, the
        train model), else by the model's short name, with N."""
        if "beta" in self.reads():
            return f"beta = {beta:g}" + (f" (N = {int(N)})" if with_N else "")
        return f"{self.label or self.name} (N = {int(N)})"

    def describe(self) -> dict[str, Any]:
        """Everything ``stickslip models`` prints about the preset (JSON-able)."""
        return {
            "name": self.name,
            "title": self.title,
            "pieces": dict(self.pieces),
            "params": dict(self.params),
            "start": self.start,
            "start_options": dict(self.start_options),
            "equations": self.equations,
            "source": self.source,
            "note": self.note,
            "symbols": dict(self.symbols),
        }


_SAKAGUCHI = dict(drive="end", friction="state", threshold="constant", ends="free")
_CL = dict(drive="plate", friction="weakening", threshold="constant", ends="periodic")
_CL_PARAMS = dict(N=100, K=100.0, Kp=1.0, V=0.01, alpha=2.5, sigma=0.01, Fs=1.0, dt=0.005)
_BC_NOTE = (
    "the paper's reading of Batista-Carlson (a stuck block starts when K (V t - x) > theta), "
    "not Batista and Carlson's published model, which could not be consulted"
)

#: The paper's chain (eq. 4): the model whose beta the studies scan, beside its relatives.
PAPER = "sakaguchi"


def paper_parameters(*omit: str) -> dict[str, Any]:
    """The parameters of the paper's chain (eq. 4, section 3: K = 10, D = 5, V = 0.001, beta = 1,
    alpha = 1, Fs = 3, dt = 0.005, N = 399) as its preset holds them, less the fields in ``omit``.

    >>> paper_parameters("N", "beta")
    {'K': 10.0, 'D': 5.0, 'V': 0.001, 'alpha': 1.0, 'Fs': 3.0, 'dt': 0.005}
    """
    return {k: v for k, v in PRESETS[PAPER].params.items() if k not in omit}


def is_paper(model: str) -> bool:
    """Whether a study's row is of the paper's chain (eq. 4) rather than one of its relatives."""
    return model == PAPER


PRESETS: dict[str, Preset] = {
    "sakaguchi": Preset(
        "sakaguchi",
        "the chain of eq. (4) (Sakaguchi)",
        _SAKAGUCHI,
        dict(N=399, K=10.0, D=5.0, V=0.001, beta=1.0, alpha=1.0, Fs=3.0, dt=0.005),
        "paper",
        equations=(
            "dv_i/dt = K (x_{i+1} - 2 x_i + x_{i-1}) - theta_i - beta v_i while moving, x_0 = V t, "
            "free end; dtheta_i/dt = theta_i (1 - theta_i) - alpha theta_i v_i + D (theta_{i+1} - "
            "2 theta_i + theta_{i-1}); a stuck block starts when its force exceeds Fs"
        ),
        source="H. Sakaguchi, Stick-Slip Motion and Phase Transition in a Block-Spring System, eq. (4)",
        label="eq. (4)",
    ),
    "carlson-langer": Preset(
        "carlson-langer",
        "Carlson-Langer (Burridge-Knopoff with velocity weakening)",
        _CL,
        _CL_PARAMS,
        "rest",
        {"amplitude": 0.01, "seed": 0},
        equations=(
            "dv_i/dt = l^2 (x_{i+1} - 2 x_i + x_{i-1}) + (nu t - x_i) - phi(v_i) while moving, "
            "phi(v) = (1 - sigma) / (1 + 2 alpha v / (1 - sigma)); a stuck block starts when its "
            "force exceeds 1; periodic ends; start x_i = -A u_i, u_i uniform in [0, 1)"
        ),
        source="J. M. Carlson, J. S. Langer, B. E. Shaw and C. Tang, Phys. Rev. A 44, 884 (1991)",
        note="units of the leaf spring and of the static friction: Kp = 1, Fs = 1; K = l^2, V = nu",
        symbols={"l": "sqrt(K)", "nu": "V", "alpha": "alpha", "sigma": "sigma"},
        label="Carlson-Langer",
    ),
    "train": Preset(
        "train",
        "the train model (de Sousa Vieira; Elmer's velocity strengthening): the paper's chain with F0 + beta v",
        dict(drive="end", friction="strengthening", threshold="constant", ends="free"),
        dict(N=399, K=10.0, V=0.001, beta=1.0, F0=1.0, Fs=3.0, dt=0.005),
        "paper",
        equations=(
            "dv_i/dt = K (x_{i+1} - 2 x_i + x_{i-1}) - F0 - beta v_i while moving, x_0 = V t, free "
            "end; a stuck block starts when its force exceeds Fs"
        ),
        source=(
            "M. de Sousa Vieira, Phys. Rev. A 46, 6288 (1992) (the model); F.-J. Elmer, arXiv:adap-org/9710002 "
            "(1997) (velocity-strengthening friction); here the paper's chain with alpha = 0 and theta = F0 = 1"
        ),
        note="the published parametrisations were not available; this is one member of the model",
        note_in_runs=True,
        label="train model",
    ),
    "batista-carlson": Preset(
        "batista-carlson",
        "a single block with a state-dependent threshold",
        dict(drive="end", friction="state", threshold="state", ends="free"),
        dict(N=1, K=10.0, D=0.0, V=0.05, beta=0.08, alpha=1.0, dt=0.005),
        "rest",
        {"amplitude": 0.0, "seed": 0},
        equations=(
            "eq. (1) with M = sigma = 1: dv/dt = K (V t - x) - theta - beta v while moving; "
            "dtheta/dt = theta (1 - theta) - alpha theta v; a stuck block starts when "
            "K (V t - x) > theta"
        ),
        source="after A. A. Batista and J. M. Carlson, Phys. Rev. E 57, 4986 (1998)",
        note=_BC_NOTE,
        note_in_runs=True,
        label="Batista-Carlson (the paper's reading)",
    ),
    "two-blocks": Preset(
        "two-blocks",
        "two blocks (de Sousa Vieira): Carlson-Langer with N = 2, free ends",
        dict(_CL, ends="free"),
        dict(_CL_PARAMS, N=2),
        "rest",
        {"amplitude": 0.01, "seed": 0},
        equations="as carlson-langer with N = 2 and free ends (x_0 = x_1, x_3 = x_2)",
        source=(
            'M. de Sousa Vieira, "Chaos in a homogeneous model for earthquakes", cond-mat/9312072 '
            "(Phys. Lett. A 198, 407 (1995)); "
            "H. Sakaguchi and S. Morita, arXiv:1309.4583 (2013)"
        ),
        symbols={"l": "sqrt(K)", "nu": "V", "alpha": "alpha", "sigma": "sigma"},
        label="two blocks",
    ),
}
