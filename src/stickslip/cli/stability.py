"""`stickslip stability block|chain` and `stickslip hysteresis` (eqs. 2 and 5, Fig. 4, section 2).

``stability block`` gives the Hopf point V_c of steady sliding of the block (eq. 2) and, with
``--V``, the eigenvalues there; ``--out DIR`` writes the stability map V_c(beta).
``stability chain`` gives the long-wave critical beta of the chain (eq. 5), the largest growth
rate over Fourier modes and, with ``--N``, the check against the finite 3N x 3N chain;
``--out DIR`` writes Fig. 4. With ``--model`` (or the pieces) a chain without state variable, the
plate drive of Carlson-Langer or the train model, gets its growth rates mode by mode
(lambda^2 + phi'(V) lambda + w_k^2 = 0) and ``--out DIR`` the growth rate against k.
``hysteresis`` sweeps V up and down for the single block and gives
V_up and V_down; ``--out DIR`` writes the bifurcation diagram.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip import io
from stickslip.cli._common import (
    OUT_FILES,
    CommandError,
    Result,
    add_block_model_option,
    add_json_option,
    add_model_options,
    add_overwrite_option,
    add_param_options,
    block_params_from_args,
    chain_params_from_args,
    check_out_owned,
    float_arg,
    owned_out_dir,
    params_from_args,
)
from stickslip.models.params import BlockParams, ChainParams, ParameterError, check_number

if TYPE_CHECKING:  # loaded where used: `stickslip --help` loads no numba, scipy or xarray
    import numpy as np

    from stickslip.analysis.dynamics import hysteresis as hy

#: Points of the stability map (beta x V) and of the Hopf curve.
MAP_BETAS = 121
MAP_VS = 200
#: Largest N of the finite-chain check (a dense 3N x 3N eigenvalue problem).
MAX_FINITE_N = 2000

# What --out of each analysis may hold (stickslip.cli._common.OUT_FILES).
_BLOCK_MAP = OUT_FILES["stability block"]
_CHAIN_MAP = OUT_FILES["stability chain"]
_LINEAR = "linearisation about steady sliding, numpy.linalg.eigvals; Hopf point by Brent's method"


def register(sub) -> None:
    """Add ``stability`` (with ``block`` and ``chain``) and ``hysteresis`` to the parser."""
    from stickslip.analysis.dynamics import hysteresis as hy

    s = sub.add_parser(
        "stability",
        help="linear stability of steady sliding: the block (eq. 2) and the chain (eq. 5, Fig. 4)",
        description="Linear stability of steady sliding, eqs. (2) and (5).",
    )
    ss = s.add_subparsers(dest="stability_command", metavar="SYSTEM", parser_class=type(s))
    ss.required = True

    b = ss.add_parser(
        "block",
        help="Hopf point V_c of the single block (eq. 2); eigenvalues at --V",
        description=(
            "Hopf point V_c(K, beta) of steady sliding of the single block, eq. (2), by root "
            "finding, with its Routh-Hurwitz closed form; with --V the eigenvalues there. "
            "--out DIR writes the stability map V_c(beta) at this K."
        ),
    )
    add_param_options(b, BlockParams, skip=("Fs", "dt"))
    b.add_argument("--out", default=None, metavar="DIR",
                   help="write stability_map.png, .nc and stability_block.json to DIR")  # fmt: skip
    add_overwrite_option(b)
    add_json_option(b)
    b.set_defaults(handler=run_stability_block)

    c = ss.add_parser(
        "chain",
        help="long-wave instability of the chain (eq. 5, Fig. 4); growth rates of the relatives (--model)",
        description=(
            "Fourier modes of the linearised chain, eq. (5): critical beta (closed form and "
            "numerical), largest growth rate over 0 < k <= pi; with --N the eigenvalues of the "
            "finite chain with the ends of docs/model.md. --out DIR writes Fig. 4. With --model "
            "carlson-langer, train or two-blocks (or friction weakening/strengthening composed "
            "with the pieces): the growth rate of each normal mode of the finite chain, "
            "lambda^2 + phi'(V) lambda + w_k^2 = 0; --out DIR writes the growth rate against k."
        ),
    )
    add_model_options(c)
    from stickslip.cli.lattice import add_lattice_options

    add_lattice_options(c, run=False)
    c.add_argument("--out", default=None, metavar="DIR",
                   help="write fig4.png, fig4.nc and stability_chain.json to DIR (the relatives: "
                        "mode_growth.png, mode_growth.nc, stability_chain.json)")  # fmt: skip
    add_overwrite_option(c)
    add_json_option(c)
    c.set_defaults(handler=run_stability_chain)

    h = sub.add_parser(
        "hysteresis",
        help="sweep V up and down for the single block: the subcritical transition (section 2)",
        description=(
            "Raise V from V_min to V_max in steps dV and lower it back, carrying the state over, "
            "holding each V for --time-per-step time units (the first --transient fraction is "
            "discarded). Reports V_up, where stick-slip ends going up (paper: 0.345 at beta = 1, "
            "Fs = 3, K = 10), and V_down, where it starts again going down."
        ),
    )
    add_block_model_option(h)
    add_param_options(h, BlockParams, skip=("V",), block_models=True)
    h.add_argument("--V-min", dest="V_min", type=float_arg("V_min"), default=hy.DEFAULT_V_MIN,
                   help=f"lowest V (default {hy.DEFAULT_V_MIN:g})")  # fmt: skip
    h.add_argument("--V-max", dest="V_max", type=float_arg("V_max"), default=hy.DEFAULT_V_MAX,
                   help=f"highest V (default {hy.DEFAULT_V_MAX:g})")  # fmt: skip
    h.add_argument("--dV", dest="dV", type=float_arg("dV"), default=hy.DEFAULT_DV,
                   help=f"step of V (default {hy.DEFAULT_DV:g})")  # fmt: skip
    h.add_argument("--time-per-step", dest="time_per_step", type=float_arg("time_per_step"),
                   default=hy.DEFAULT_TIME_PER_STEP,
                   help=f"time units at each V (default {hy.DEFAULT_TIME_PER_STEP:g})")  # fmt: skip
    h.add_argument("--transient", type=float_arg("transient"), default=hy.DEFAULT_TRANSIENT,
                   help="fraction of each step discarded before measuring "
                        f"(default {hy.DEFAULT_TRANSIENT:g})")  # fmt: skip
    h.add_argument("--out", default=None, metavar="DIR",
                   help="write hysteresis.png, hysteresis.nc and hysteresis.json to DIR")  # fmt: skip
    add_overwrite_option(h)
    add_json_option(h)
    h.set_defaults(handler=run_hysteresis)


def _eig_list(eig: np.ndarray) -> list[dict[str, float]]:
    return [{"real": float(z.real), "imag": float(z.imag)} for z in eig]


def _is_paper_block(p: BlockParams) -> bool:
    return (p.K, p.beta, p.alpha, p.M, p.sigma) == (10.0, 0.08, 1.0, 1.0, 1.0)


# ---------------------------------------------------------------------------------------------
# stability block
# ---------------------------------------------------------------------------------------------


def run_stability_block(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip stability block``: Hopf point and eigenvalues of eq. (2)."""
    import numpy as np

    from stickslip.analysis.dynamics import stability as st

    with_V = args.param_V is not None
    p = params_from_args(BlockParams, args)
    check_out_owned(args.out, _BLOCK_MAP, "stickslip stability block", overwrite=args.overwrite)
    if args.out is not None:
        with np.errstate(all="ignore"):
            beta_limit = st.hopf_beta_limit(p)
        if not math.isfinite(beta_limit):
            raise CommandError(
                f"K must be small enough for the stability map's beta range to be finite "
                f"(got K={p.K:g}: the Hopf limit of beta overflows)"
            )
    try:
        hopf = st.hopf_point(p)
    except ParameterError as exc:
        raise CommandError(
            f"no Hopf point at K={p.K:g}, beta={p.beta:g}, alpha={p.alpha:g} "
            f"(steady sliding cannot be linearised there: {exc})"
        ) from None
    params = {k: v for k, v in p.to_dict().items() if k not in ("Fs", "dt") and (with_V or k != "V")}
    data: dict[str, Any] = {
        "params": params,
        "hopf_V": hopf.V,
        "hopf_V_closed_form": st.hopf_point_closed_form(p),
        "hopf_theta0": hopf.theta0,
        "hopf_omega": hopf.omega,
        "regime": hopf.regime,
    }
    if _is_paper_block(p):
        data["paper_hopf_V"] = 0.106
    if with_V:
        s = st.block_stability(p)
        data.update(V=p.V, theta0=s.theta0, eigenvalues=_eig_list(s.eigenvalues),
                    growth_rate=s.growth_rate, stable=s.stable)  # fmt: skip
    with owned_out_dir(args.out, _BLOCK_MAP, "stickslip stability block", overwrite=args.overwrite) as out:
        if out is not None:
            data["outputs"] = [str(path) for path in _write_block_map(out, p, data, with_V)]
    return Result(data=data, text=_block_text(data))


def _write_block_map(out: Path, p: BlockParams, data: dict, with_V: bool) -> list[Path]:
    import numpy as np

    from stickslip.analysis.dynamics import stability as st
    from stickslip.plotting.stability import plot_stability_map
    from stickslip.plotting.style import save_figure

    beta_top = 1.5 * st.hopf_beta_limit(p)
    if p.beta > beta_top:
        beta_top = 1.1 * p.beta
    betas = np.linspace(0.0, beta_top, MAP_BETAS)
    V_top = 1.0 / p.alpha if p.alpha > 0.0 else 1.0
    if with_V and p.V >= V_top:
        V_top = 1.1 * p.V
    Vs = np.linspace(0.0, V_top, MAP_VS + 1)[1:]
    curve = st.hopf_curve(p, betas)
    growth = st.block_growth_map(p, betas, Vs)
    ds = curve.assign(growth_rate=growth)
    mark = {"beta": p.beta, "V": p.V} if with_V else None
    written = [io.write_dataset(out / "stability_map.nc", ds)]
    written += save_figure(plot_stability_map(curve, growth, mark=mark), out / "stability_map")
    meta = io.run_metadata(p, integrator=_LINEAR, command="stability block", result=data)
    written.append(io.write_json(out / "stability_block.json", meta))
    return written


def _block_text(d: dict[str, Any]) -> str:
    p = d["params"]
    lines = ["steady sliding of the single block, eq. (2): " + " ".join(f"{k}={v:g}" for k, v in p.items())]
    if d["hopf_V"] is None:
        lines.append(d["regime"])
    else:
        lines.append(f"Hopf point V_c = {d['hopf_V']:.6f} (closed form {d['hopf_V_closed_form']:.6f}), "
                     f"omega = {d['hopf_omega']:.4f}; {d['regime']}")  # fmt: skip
    if "paper_hopf_V" in d:
        lines.append(f"paper: V_c = {d['paper_hopf_V']}")
    if "eigenvalues" in d:
        eig = ", ".join(f"{e['real']:.5g}{e['imag']:+.5g}i" for e in d["eigenvalues"])
        lines.append(f"at V = {d['V']:g}: eigenvalues {eig}; {'stable' if d['stable'] else 'unstable'}")
    for path in d.get("outputs", []):
        lines.append(f"wrote {path}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# stability chain
# ---------------------------------------------------------------------------------------------


def run_stability_chain(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip stability chain``: Fourier modes of eq. (5), Fig. 4; the relatives
    without state variable mode by mode (:func:`run_stability_modes`)."""
    from stickslip.analysis.dynamics import stability as st
    from stickslip.cli.lattice import run_stability_lattice, wants_lattice

    if wants_lattice(args):
        return run_stability_lattice(args)
    for name in ("Fs", "dt"):
        if getattr(args, f"param_{name}", None) is not None:
            raise CommandError(f"--{name} is not read by the linear stability of steady sliding")
    with_N = args.param_N is not None
    D = args.param_D
    # dt is never read by the linear analysis; keep ChainParams' explicit-step check out of the way.
    overrides = {"dt": 1.0 / (2.0 * D + 1.0)} if D is not None and D > 0.0 and (2.0 * D + 1.0) * 0.005 > 1.0 else {}
    p = chain_params_from_args(args, **overrides)
    if not p.friction_piece.has_state:
        return run_stability_modes(args, p)
    if not p.friction_piece.eq5:
        return run_stability_law(args, p, with_N)
    if p.drive_piece.leaf_spring:
        raise CommandError(
            f"friction state with drive {p.drive} is not covered: use friction weakening or "
            f"strengthening with the {p.drive} drive"
        )
    if with_N:
        check_number("N", p.N, low=1, high=MAX_FINITE_N, integer=True)
    check_out_owned(args.out, _CHAIN_MAP, "stickslip stability chain", overwrite=args.overwrite)

    s = st.chain_stability(p)
    long_wave = st.chain_long_wave(p)
    keep = ("K", "D", "V", "beta", "alpha") + (("N",) if with_N else ())
    data: dict[str, Any] = {
        "params": {k: v for k, v in p.to_dict().items() if k in keep},
        "critical_beta": s.critical_beta,
        "critical_beta_numeric": s.critical_beta_numeric,
        "max_growth_rate": s.max_growth_rate,
        "k_at_max": s.k_at_max,
        "unstable": s.unstable,
        "marginal": s.marginal,
        "long_wave": long_wave,
    }
    if (p.K, p.D, p.alpha) == (10.0, 5.0, 1.0):
        data["paper_critical_beta"] = 1.0
    if with_N:
        row = st.compare_fourier_finite(p, [p.N]).iloc[0]
        data["finite_chain"] = {
            "N": int(row["N"]),
            "max_real": float(row["finite_max_real"]),
            "fourier_at_k1": float(row["fourier_k1"]),
            "k1": float(st.finite_chain_wavenumbers(p.N)[0]),
            "unstable": bool(row["finite_max_real"] > st.GROWTH_TOL),
        }
    with owned_out_dir(args.out, _CHAIN_MAP, "stickslip stability chain", overwrite=args.overwrite) as out:
        if out is not None:
            data["outputs"] = [str(path) for path in _write_fig4(out, p, data)]
    return Result(data=data, text=_chain_text(data))


def run_stability_law(args: argparse.Namespace, p: ChainParams, with_N: bool) -> Result:
    """Steady sliding of a chain whose law has a state variable other than eq. (4)'s (rate-and-state):
    the 3 x 3 mode matrices and the finite chain's Jacobian from the law's linearisation, and the
    critical spring constant K_c (analysis.dynamics.stability.critical_stiffness). Without --N: the
    spring-slider, N = 1."""
    from stickslip.analysis.dynamics import stability as st

    if p.drive_piece.leaf_spring or not p.ends_piece.steady_sliding:
        raise CommandError(f"friction {p.friction} is covered with drive end and ends free only")
    if p.V <= 0.0:
        raise CommandError(f"steady sliding needs V > 0 (got V={p.V:g})")
    if not with_N:
        p = p.replace(N=1)
    check_number("N", p.N, low=1, high=MAX_FINITE_N, integer=True)
    if args.out is not None:
        raise CommandError(f"--out writes Fig. 4 of eq. (4)'s law; friction {p.friction} has no figure here")
    lin = p.friction_piece.linear(p)
    growth, k_max = st._max_fourier_growth(p, st.chain_k_grid())
    finite = float(st.chain_finite_eigenvalues(p)[0].real)
    data: dict[str, Any] = {
        "params": {k: v for k, v in p.to_dict().items() if k not in ("Fs", "dt")},
        "linearisation": dataclasses.asdict(lin),
        "max_growth_rate": growth,
        "k_at_max": k_max,
        "finite_chain": {"N": p.N, "max_real": finite, "unstable": finite > st.GROWTH_TOL},
        "critical_K": st.critical_stiffness(p),
    }
    extras = p.friction_piece.stability_extras
    if extras is not None:
        data.update(extras(p))
    return Result(data=data, text=_law_text(data))


def _law_text(d: dict[str, Any]) -> str:
    p = d["params"]
    f = d["finite_chain"]
    lines = [
        f"steady sliding of the chain, {p['friction']} friction: "
        + " ".join(f"{k}={v:g}" for k, v in p.items() if not isinstance(v, str)),
        "linearised: " + " ".join(f"{k}={v:.6g}" for k, v in d["linearisation"].items()),
        f"N = {f['N']}: largest Re(lambda) {f['max_real']:.6g}: {'unstable' if f['unstable'] else 'stable'}; "
        f"critical K = {d['critical_K']:.8g} (unstable below)",
        f"Fourier modes 0 < k <= pi: largest Re(lambda) {d['max_growth_rate']:.6g} at k = {d['k_at_max']:.4g}",
    ]
    closed = {k: v for k, v in d.items() if k.startswith("k_c")}
    if closed:
        lines.append("closed forms: " + " ".join(f"{k} = {v:.8g}" for k, v in closed.items()))
    return "\n".join(lines)


def _write_fig4(out: Path, p: ChainParams, data: dict) -> list[Path]:
    import numpy as np
    import xarray as xr

    from stickslip.analysis.dynamics import stability as st
    from stickslip.plotting.stability import plot_fig4
    from stickslip.plotting.style import save_figure

    betas = list(st.FIG4_BETAS)
    if not any(np.isclose(p.beta, b) for b in betas):
        betas.append(p.beta)
    ds: xr.Dataset = st.fig4_data(p, betas=sorted(betas))
    written = [io.write_dataset(out / "fig4.nc", ds)]
    written += save_figure(plot_fig4(ds), out / "fig4")
    meta = io.run_metadata(p, integrator=_LINEAR, command="stability chain", result=data)
    written.append(io.write_json(out / "stability_chain.json", meta))
    return written


def _chain_text(d: dict[str, Any]) -> str:
    p = d["params"]
    state = "unstable" if d["unstable"] else ("marginal" if d["marginal"] else "stable")
    lines = [
        "steady sliding of the chain, eq. (5): " + " ".join(f"{k}={v:g}" for k, v in p.items()),
        f"critical beta = {d['critical_beta']:g} (closed form), {d['critical_beta_numeric']:.8f} (numerical)",
        f"largest Re(lambda) over 0 < k <= pi: {d['max_growth_rate']:.6g} at k = {d['k_at_max']:.4g}: {state}",
    ]
    if "finite_chain" in d:
        f = d["finite_chain"]
        lines.append(f"finite chain N = {f['N']}: largest Re(lambda) {f['max_real']:.6g} "
                     f"(Fourier at k1 = {f['k1']:.4g}: {f['fourier_at_k1']:.6g})")  # fmt: skip
    for path in d.get("outputs", []):
        lines.append(f"wrote {path}")
    return "\n".join(lines)


def run_stability_modes(args: argparse.Namespace, p: ChainParams) -> Result:
    """Growth rates of steady sliding mode by mode: plate drive (CL) or train model.

    Each normal mode obeys lambda^2 + phi'(V) lambda + w_k^2 = 0 (analysis.dynamics.stability).
    """
    from stickslip.analysis.dynamics import stability as st

    if p.V <= 0.0:
        raise CommandError(f"steady sliding needs V > 0 (got V={p.V:g})")
    if not p.ends_piece.steady_sliding:
        raise CommandError(f"ends {p.ends} have no steady sliding (the springs to the walls stretch without bound)")
    if not p.drive_piece.steady_sliding:
        raise CommandError(f"drive {p.drive} has no steady sliding (the force never stops growing)")
    if p.N > MAX_FINITE_N:
        raise CommandError(f"N must be <= {MAX_FINITE_N} for the mode table (got N={p.N})")
    check_out_owned(args.out, _CHAIN_MAP, "stickslip stability chain", overwrite=args.overwrite)

    try:
        s = st.mode_stability(p)
    except ValueError as exc:  # a force drive's force that no steady velocity balances
        raise CommandError(str(exc)) from None
    data: dict[str, Any] = {
        "params": {k: v for k, v in p.to_dict().items() if k not in ("Fs", "dt")},
        "friction_slope": s.friction_slope,
        "modes": s.modes,
        "all_unstable": s.all_unstable,
        "stable": s.stable,
        "max_growth_rate": s.max_growth_rate,
        "k_at_max": s.k_at_max,
        "min_growth_rate": s.min_growth_rate,
        "k_at_min": s.k_at_min,
    }
    extras = p.friction_piece.stability_extras
    if extras is not None:
        data.update(extras(p))
    data["mode_table"] = s.growth.to_dict(orient="records")
    with owned_out_dir(args.out, _CHAIN_MAP, "stickslip stability chain", overwrite=args.overwrite) as out:
        if out is not None:
            data["outputs"] = [str(path) for path in _write_mode_growth(out, p, data)]
    return Result(data=data, text=_modes_text(data))


def _write_mode_growth(out: Path, p: ChainParams, data: dict) -> list[Path]:
    from stickslip.analysis.dynamics import stability as st
    from stickslip.plotting.stability import plot_mode_growth
    from stickslip.plotting.style import save_figure

    ds = st.mode_dispersion(p)
    written = [io.write_dataset(out / "mode_growth.nc", ds)]
    written += save_figure(plot_mode_growth(ds, st.mode_growth_rates(p)), out / "mode_growth")
    meta = io.run_metadata(p, integrator=_LINEAR, command="stability chain", result=data)
    written.append(io.write_json(out / "stability_chain.json", meta))
    return written


def _modes_text(d: dict[str, Any]) -> str:
    p = d["params"]
    state = "every mode grows" if d["all_unstable"] else ("stable" if d["stable"] else "some modes grow")
    lines = [
        f"steady sliding of {p['model']} ({p['drive']} drive, {p['friction']} friction, {p['ends']} ends): "
        + " ".join(f"{k}={v:g}" for k, v in p.items() if not isinstance(v, str)),
        f"lambda^2 + phi'(V) lambda + w_k^2 = 0 with phi'(V) = {d['friction_slope']:.6g}"
        + (f" (alpha g = {d['alpha_g']:.6g})" if "alpha_g" in d else ""),
        f"modes: {d['modes']}",
        f"growth rate over modes: max {d['max_growth_rate']:.6g} at k = {d['k_at_max']:.4g}, "
        f"min {d['min_growth_rate']:.6g} at k = {d['k_at_min']:.4g}: {state}",
    ]
    for path in d.get("outputs", []):
        lines.append(f"wrote {path}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# hysteresis
# ---------------------------------------------------------------------------------------------


def run_hysteresis(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip hysteresis``: the adiabatic sweep of V of section 2."""
    from stickslip.analysis.dynamics import hysteresis as hy

    p = block_params_from_args(args)
    settings = hy.SweepSettings(
        V_min=args.V_min, V_max=args.V_max, dV=args.dV,
        time_per_step=args.time_per_step, transient=args.transient,
    )  # fmt: skip
    from stickslip.cli.block import MAX_BLOCK_STEPS

    if settings.time_per_step + settings.transient > MAX_BLOCK_STEPS * p.dt:
        raise CommandError(
            f"time_per_step + transient must be <= {MAX_BLOCK_STEPS * p.dt:g} (at most "
            f"{MAX_BLOCK_STEPS:.0e} steps of dt = {p.dt:g} per value of V)"
        )
    own = OUT_FILES["hysteresis"]
    with owned_out_dir(args.out, own, "stickslip hysteresis", overwrite=args.overwrite) as out:
        result = hy.hysteresis_sweep(p, settings)
        data = result.summary()
        if (p.K, p.beta, p.Fs, p.alpha, p.M, p.sigma) == (10.0, 1.0, 3.0, 1.0, 1.0, 1.0):
            data["paper_V_up"] = 0.345
        if out is not None:
            data["outputs"] = [str(path) for path in _write_hysteresis(out, result, data)]
    return Result(data=data, text=_hysteresis_text(data))


def _write_hysteresis(out: Path, result: hy.HysteresisResult, data: dict) -> list[Path]:
    from stickslip.plotting.stability import plot_hysteresis
    from stickslip.plotting.style import save_figure
    from stickslip.run.block import INTEGRATOR

    written = [io.write_dataset(out / "hysteresis.nc", result.data)]
    written += save_figure(plot_hysteresis(result.data), out / "hysteresis")
    meta = io.run_metadata(result.params, integrator=INTEGRATOR, command="hysteresis", result=data)
    written.append(io.write_json(out / "hysteresis.json", meta))
    return written


def _hysteresis_text(d: dict[str, Any]) -> str:
    s = d["sweep"]

    def fmt(v):
        return "none in range" if v is None else f"{v:g}"

    lines = [
        "single block, adiabatic sweep of V: "
        + " ".join(f"{k}={v}" if isinstance(v, str) else f"{k}={v:g}" for k, v in d["params"].items() if k != "dt"),
        f"V from {s['V_min']:g} to {s['V_max']:g} and back, dV = {s['dV']:g}, "
        f"{s['time_per_step']:g} time units per V (first {s['transient']:g} discarded)",
        f"V_up (stick-slip ends going up) = {fmt(d['V_up'])}"
        + (f"   paper: {d['paper_V_up']}" if "paper_V_up" in d else ""),
        f"V_down (stick-slip starts again going down) = {fmt(d['V_down'])}",
    ]
    for path in d.get("outputs", []):
        lines.append(f"wrote {path}")
    return "\n".join(lines)
