"""Named models: the paper's chain and the relatives it cites (docs/model.md, "Preset defaults").

A preset is data (:mod:`stickslip.models.preset_table`): its four pieces
(:mod:`stickslip.models.pieces`), its parameters, its start and the equations in words.
:func:`chain_params` turns a preset plus overrides into validated
:class:`~stickslip.models.params.ChainParams`; any composition docs/model.md allows can be built the
same way by overriding the pieces. Adding a model means adding an entry to
:data:`~stickslip.models.preset_table.PRESETS`.
"""

from __future__ import annotations

from typing import Any

# The presets themselves are data in preset_table (which ChainParams reads its model names from).
from stickslip.models.preset_table import PAPER, PRESETS, Preset, is_paper, paper_parameters  # noqa: F401


def preset(name: str) -> Preset:
    """The preset called ``name``; a ValueError lists the presets."""
    if name not in PRESETS:
        raise ValueError(f"model must be one of {', '.join(PRESETS)} (got {name!r})")
    return PRESETS[name]


def chain_params(
    model: str = "sakaguchi", *, lattice: str | None = None, shape: Any = None, edges: Any = None, **overrides: Any
):
    """Validated parameters of preset ``model`` with ``overrides`` (pieces or parameters).

    For the Carlson-Langer family ``l`` and ``nu`` are accepted in the model's own symbols
    (K = l^2, V = nu). A parameter the composition does not read (``beta`` of Carlson-Langer,
    say) is refused with :class:`~stickslip.models.params.ParameterError`, as the commands refuse
    its option, rather than silently ignored (:func:`refuse_unread`).

    Parameters
    ----------
    model : str
        A preset (``stickslip models`` lists them): ``sakaguchi`` (the paper's chain of eq. 4,
        the default), ``carlson-langer``, ``train``, ``batista-carlson``, ``two-blocks``.
    lattice, shape, edges : optional
        The lattice the blocks sit on (docs/lattice.md): ``"chain"`` (eq. 4's line, ``shape`` its
        N) or ``"square"`` with ``shape`` (rows, cols) or ``"RxC"`` and ``edges`` per side
        (:func:`stickslip.models.lattice.edges.parse_edges`; default: the ends piece's kind, the
        left side pulled by an edge drive).
    **overrides
        Pieces (``drive``, ``friction``, ``threshold``, ``ends``) or parameters (``N``,
        ``beta``, ...) that replace the preset's. A parameter may differ from block to block
        (docs/model.md, "Per-block parameters"); on the square, an array over (rows, cols) or of
        rows cols values in row-major order, or a drawn :class:`~stickslip.models.disorder.Quenched`.

    Returns
    -------
    ChainParams or LatticeParams
        Every parameter checked; a bad one raises ParameterError naming it and its range. On the
        square, a :class:`~stickslip.models.lattice.params.LatticeParams`.

    Examples
    --------
    >>> from stickslip import chain_params
    >>> chain_params(N=49, beta=0.5)
    ChainParams(model='sakaguchi', N=49, K=10.0, D=5.0, V=0.001, beta=0.5, alpha=1.0, Fs=3.0, dt=0.005)
    >>> chain_params("carlson-langer", l=10, nu=0.01).K
    100.0
    >>> chain_params("carlson-langer", beta=2.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stickslip.models.params.ParameterError: beta is not a parameter of this model (carlson-langer: ...
    """
    from stickslip.models.params import ParameterError

    if lattice is None and (shape is not None or edges is not None):
        raise ParameterError("shape and edges go with lattice (lattice='square', shape=(rows, cols))")
    if lattice not in (None, "chain"):
        if shape is None:
            raise ParameterError(f"lattice {lattice} needs shape (rows, cols), e.g. shape=(64, 64)")
        if "N" in overrides:
            raise ParameterError("N goes with the chain; the square's size is shape (rows, cols)")
    elif shape is not None:
        overrides = {**overrides, "N": shape}
    given = overrides
    if lattice not in (None, "chain"):
        overrides = on_square(overrides, shape)
    params = build_chain_params(model, **overrides)
    refuse_unread(params, given)
    if lattice in (None, "chain"):
        if edges is not None:
            raise ParameterError("edges go with lattice square (the chain's ends are the ends piece)")
        return params
    from stickslip.models.lattice.params import on_lattice

    return on_lattice(params, lattice, shape, edges)


def on_square(overrides: dict[str, Any], shape: Any) -> dict[str, Any]:
    """``overrides`` for a model on the square of ``shape``: N = rows cols, and each per-block
    value given over (rows, cols) in row-major order
    (:func:`~stickslip.models.lattice.params.row_major`); a bad shape raises ParameterError."""
    from stickslip.models.lattice import LatticeError, parse_shape
    from stickslip.models.lattice.params import row_major
    from stickslip.models.params import ParameterError

    try:
        rows, cols = parse_shape(shape)
    except LatticeError as exc:
        raise ParameterError(str(exc)) from None
    from stickslip.models.params import MAX_BLOCKS

    out = {k: row_major(k, v, (rows, cols)) for k, v in overrides.items()}
    # The wrapped chain's N is the lattice's count up to a chain's largest (on_lattice's rule);
    # per-block values need every block, so they bound the square to a chain's largest.
    per_block = any(not isinstance(v, (int, float, str, type(None))) for v in out.values())
    out["N"] = rows * cols if per_block else min(rows * cols, MAX_BLOCKS)
    return out


def build_chain_params(model: str = "sakaguchi", **overrides: Any):
    """:func:`chain_params` without the refusal of parameters the composition does not read."""
    from stickslip.models.params import ChainParams, ParameterError, check_number

    if not isinstance(model, str):
        raise ParameterError(f"model must be a preset's name, one of {', '.join(PRESETS)} (got {model!r})")
    try:
        pr = preset(model)
    except ValueError as exc:
        raise ParameterError(str(exc)) from None
    values: dict[str, Any] = {**pr.pieces, **pr.params}
    overrides = dict(overrides)
    if "l" in overrides:
        values["K"] = check_number("l", overrides.pop("l"), low=0.0, low_open=True) ** 2
    if "nu" in overrides:
        values["V"] = overrides.pop("nu")
    values.update(overrides)
    return ChainParams(model=model, **values)


def refuse_unread(params, given, prefix: str = "", spell=None) -> None:
    """Raise ParameterError for the first of the names ``given`` that the composition of ``params``
    does not read (docs/model.md's family table), naming it as ``prefix`` + name (``--`` for an
    option) or as ``spell(name)`` spells it, and for Carlson-Langer's symbols ``l`` and ``nu``
    without the plate drive."""
    from stickslip.models.params import ParameterError

    used = set(params.used()) | {"l", "nu", "model"}
    unused = [k for k in given if k not in used and k not in params.pieces]
    if unused:
        shown = spell(unused[0]) if spell is not None else f"{prefix}{unused[0]}"
        raise ParameterError(
            f"{shown} is not a parameter of this model ({params.model}: "
            f"{', '.join(f'{k} {v}' for k, v in params.pieces.items())}); it reads {', '.join(params.used())}"
        )
    if ("l" in given or "nu" in given) and not params.drive_piece.leaf_spring:
        raise ParameterError(f"{prefix}l and {prefix}nu are Carlson-Langer's symbols: they need drive plate")


def model_name(params) -> str:
    """The model of ``params`` as a figure title names it: its preset's short name when the pieces
    are the preset's (eq. (4), Carlson-Langer), else that name and the pieces that differ.

    >>> model_name(chain_params("carlson-langer"))
    'Carlson-Langer'
    >>> model_name(chain_params(friction="weakening", ends="fixed"))
    'eq. (4), friction weakening, ends fixed'
    """
    pr = PRESETS[params.model]
    changed = [f"{k} {v}" for k, v in params.pieces.items() if pr.pieces[k] != v]
    return ", ".join([pr.label or pr.name, *changed])


def model_title(params, *, skip: tuple[str, ...] = ("dt",)) -> str:
    """The model and the values of every parameter it reads (but ``skip``), as matplotlib
    mathtext for a figure title: what tells two runs apart, and nothing the model ignores.

    >>> print(model_title(chain_params("carlson-langer")))
    Carlson-Langer: $N=100$, $K=100$, $V=0.01$, $K_p=1$, $\\alpha=2.5$, $\\sigma=0.01$, $F_s=1$
    """
    values = ", ".join(f"${params.symbol(k)}={getattr(params, k):g}$" for k in params.used() if k not in skip)
    return f"{model_name(params)}: {values}"


def is_paper_model(params) -> bool:
    """Whether ``params`` are of the paper's chain, eq. (4) (its preset and pieces, any values):
    the runs the paper's own numbers (its front speed, its exponents) are drawn beside.

    >>> is_paper_model(chain_params(N=49)), is_paper_model(chain_params(ends="fixed"))
    (True, False)
    """
    return params.model == PAPER and params.pieces == PRESETS[PAPER].pieces


def is_paper_run(params) -> bool:
    """Whether ``params`` are the paper's chain with the paper's parameters (section 3), beta
    aside: the runs whose figures are the paper's Figs. 5-8.

    >>> is_paper_run(chain_params(beta=0.2)), is_paper_run(chain_params(N=49))
    (True, False)
    """
    from stickslip.models.params import ChainParams

    pr = PRESETS[PAPER]
    return params.model == PAPER and params.replace(beta=1.0) == ChainParams(**pr.pieces, **pr.params)


# Presets that are a single block of eq. (1): their chain form has N = 1, the end drive, state
# friction and a free end, which is eq. (1) with M = sigma = 1.
SINGLE_BLOCK = ("sakaguchi", "batista-carlson")


def block_params(model: str = "sakaguchi", **overrides: Any):
    """Validated :class:`~stickslip.models.params.BlockParams` of a single-block preset.

    ``sakaguchi`` is the paper's block of section 2 (its defaults); ``batista-carlson`` the same
    equations with the state threshold sigma theta and its preset's K, V, beta, alpha.
    """
    from stickslip.models.params import BlockParams, ParameterError

    if model not in SINGLE_BLOCK:
        raise ParameterError(
            f"model must be one of {', '.join(SINGLE_BLOCK)} for a single block (got {model!r}); "
            "run the others with `stickslip chain --model NAME`"
        )
    values: dict[str, Any] = {}
    if model == "batista-carlson":
        pr = PRESETS[model]
        values = {k: pr.params[k] for k in ("K", "V", "beta", "alpha", "dt")}
        values["threshold"] = "state"
    values.update(overrides)
    return BlockParams(**values)
