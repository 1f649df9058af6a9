"""`stickslip block` and `stickslip slip-limit`: the single block of section 2 (eqs. 1-3, Figs. 1-3).

``stickslip block`` runs eq. (1) and reports its slips; with ``--out DIR`` it writes the series
(series.nc), the slip table (slips.parquet), run.json and Figs. 1 and 2 of the run; ``--fig3``
adds the period sweep of Fig. 3 (fig3.png and .pdf; its table fig3.parquet and .csv).
``stickslip slip-limit`` integrates eq. (3) and prints the slip duration, the force at stop and
the period law T(V) = a + b / (K V).
"""

from __future__ import annotations

import argparse
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
    add_overwrite_option,
    add_param_options,
    block_params_from_args,
    float_arg,
    owned_out_dir,
    params_from_args,
)
from stickslip.models.params import MAX_STEPS, BlockParams, ParameterError, check_number, steps_for

if TYPE_CHECKING:  # loaded where used: `stickslip --help` loads no numba, scipy or xarray
    from stickslip.analysis.dynamics.slip_limit import SlipLimit
    from stickslip.run.block import BlockRun

#: Periods of the law simulated after the first slip when --t-end is not given.
DEFAULT_PERIODS = 3.5
#: Largest series a command writes or holds (samples); beyond it --every must be raised.
MAX_SAMPLES = 20_000_000
#: Fig. 3: number of pulling velocities (log-spaced in [1e-3, 1e-1]) and periods per velocity.
FIG3_POINTS = 13
FIG3_PERIODS = 4
#: Largest single-block run (steps); its slip table is sized for one slip per 1000 steps.
MAX_BLOCK_STEPS = 10**10
#: What ``block --out`` writes (its run directory may hold only these).
BLOCK_FILES = OUT_FILES["block"]


def register(sub) -> None:
    """Add the subcommands ``block`` and ``slip-limit`` to the parser."""
    p = sub.add_parser(
        "block",
        help="run the single block and spring, eq. (1); Figs. 1-3",
        description=(
            "Integrate eq. (1) (Heun, start/stop rules of docs/model.md) from x = v = 0, theta = 0.1 "
            "and report the slips. Without --t-end the run lasts until the first start plus "
            f"{DEFAULT_PERIODS:g} periods of the law T(V) of eq. (3)."
        ),
    )
    add_block_model_option(p)
    add_param_options(p, BlockParams, block_models=True)
    p.add_argument("--t-end", type=float_arg("t_end"), default=None, metavar="T",
                   help="end time of the run (default: first slip + 3.5 periods of T(V))")  # fmt: skip
    p.add_argument("--every", type=float_arg("every"), default=1, metavar="N",
                   help="keep every N-th step in the series (default 1)")  # fmt: skip
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write series.nc, slips.parquet, run.json, fig1.png, fig2.png (+ data) to DIR")  # fmt: skip
    p.add_argument("--fig3", action="store_true",
                   help=f"also simulate the period at {FIG3_POINTS} values of V in [1e-3, 1e-1] and "
                        "write fig3.png, fig3.pdf and the table fig3.parquet, fig3.csv (needs --out)")  # fmt: skip
    add_overwrite_option(p)
    add_json_option(p)
    p.set_defaults(handler=run_block)

    q = sub.add_parser(
        "slip-limit",
        help="the slip in the limit V -> 0, eq. (3), and the period law of Fig. 3",
        description=(
            "Integrate eq. (3) from x' = v = 0, theta = 1 (DOP853 with event location of v = 0) "
            "and print the slip duration, the force Fs - K x' at the stop, and the period law "
            "T(V) = a + b / (K V); also the same slip with the Heun step of eq. (1) at dt."
        ),
    )
    add_param_options(q, BlockParams, skip=("V",))
    q.add_argument("--rtol", type=float_arg("rtol"), default=1e-10, help="relative tolerance (default 1e-10)")
    q.add_argument("--atol", type=float_arg("atol"), default=1e-12, help="absolute tolerance (default 1e-12)")
    add_json_option(q)
    q.set_defaults(handler=run_slip_limit)


def _law_or_none(p: BlockParams) -> SlipLimit | None:
    """The accurate eq. (3) at these parameters, or None where it has no slip that ends (or one
    too stiff or too long to resolve: sqrt(K/M) > 1e4 or Fs > 1000 sigma; or where the threshold
    is not the constant Fs that eq. (3) starts from)."""
    from stickslip.analysis.dynamics.slip_limit import NoStopError, solve_slip_limit

    if p.threshold_piece.has_state or math.sqrt(p.K / p.M) > 1e4 or p.Fs / p.sigma > 1e3:
        return None
    try:
        return solve_slip_limit(p)
    except (ParameterError, NoStopError):
        return None


def default_t_end(p: BlockParams, law: SlipLimit | None) -> float:
    """First start plus 3.5 periods of the law (2 Fs / (K V) per period where eq. (3) has none)."""
    from stickslip.run.block import first_start_time

    if p.V <= 0.0:
        raise ParameterError("t_end must be given when V = 0 (the block never starts)")
    # Without eq. (3): the spring must be loaded by about twice the threshold per cycle.
    threshold = p.sigma if p.threshold_piece.has_state else p.Fs
    period = law.period(p.V) if law is not None else 2.0 * threshold / (p.K * p.V)
    # A state threshold sigma theta is at most sigma: the first start comes no later than that.
    if not p.threshold_piece.has_state:
        return first_start_time(p) + DEFAULT_PERIODS * float(period)
    return p.sigma / (p.K * p.V) + 20 * DEFAULT_PERIODS * float(period)


def run_block(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip block``: eq. (1), its slips, Figs. 1-3."""
    from stickslip.run.block import n_samples, simulate_block

    # Everything is validated before --out is created, so bad input writes nothing.
    p = block_params_from_args(args)
    every = int(check_number("every", args.every, low=1, high=MAX_STEPS, integer=True))
    if args.t_end is not None:
        check_number("t_end", args.t_end, low=0.0, low_open=True)
    if args.fig3 and args.out is None:
        raise CommandError("--fig3 writes figures and needs --out DIR")
    law = _law_or_none(p)
    t_end = float(args.t_end) if args.t_end is not None else default_t_end(p, law)
    steps = steps_for(t_end, p.dt, "t_end")
    if steps > MAX_BLOCK_STEPS:
        raise CommandError(
            f"t_end must be <= {MAX_BLOCK_STEPS * p.dt:g} for the single block (at most "
            f"{MAX_BLOCK_STEPS:.0e} steps of dt = {p.dt:g}, for the memory of its slip table)"
        )
    if n_samples(steps, every) > MAX_SAMPLES:
        raise CommandError(
            f"every must be >= {math.ceil(steps / MAX_SAMPLES)} for a run of {steps} steps "
            f"(a series is limited to {MAX_SAMPLES} samples)"
        )
    if args.fig3 and law is None:
        raise CommandError("--fig3 needs the period law: eq. (3) has no slip that ends at these parameters")
    with owned_out_dir(args.out, BLOCK_FILES, "stickslip block", overwrite=args.overwrite) as out:
        run = simulate_block(p, t_end, every=every)
        data = block_report(run, law)
        if out is not None:
            data["outputs"] = [str(path) for path in write_block_outputs(out, run, law, fig3=args.fig3)]
    return Result(data=data, text=block_text(data))


def block_report(run: BlockRun, law: SlipLimit | None) -> dict[str, Any]:
    """The JSON document of ``stickslip block``: summary, period law, slips, parameters."""
    from stickslip.run.block import INTEGRATOR

    data: dict[str, Any] = run.summary()
    data["params"] = run.params.to_dict()
    data["integrator"] = INTEGRATOR
    if run.params.threshold_piece.has_state:
        from stickslip.models.presets import PRESETS

        data["model"] = "batista-carlson"
        data["note"] = PRESETS["batista-carlson"].note
    if law is not None and run.params.V > 0.0:
        T = float(law.period(run.params.V))
        data["period_law"] = {"a": law.law_a, "b": law.law_b, "T": T}
        data["period_rel_dev"] = data["period"] / T - 1.0
    data["slips"] = run.slips.to_dict(orient="records")
    return data


def block_text(d: dict[str, Any]) -> str:
    """The human summary of ``stickslip block``."""
    p = d["params"]
    lines = [
        "single block, eq. (1): "
        + " ".join(f"{k}={v}" if isinstance(v, str) else f"{k}={v:g}" for k, v in p.items() if k != "dt"),
        f"Heun dt={d['dt']:g}, t_end={d['t_end']:g} ({d['steps']} steps)",
        f"slips: {d['events']} (starts {d['n_starts']}, stops {d['n_stops']}); "
        f"v in [{d['v_min']:.4g}, {d['v_max']:.4g}]",
    ]
    if d.get("note"):
        lines.append(f"note: {d['model']} is {d['note']}")
    if d["events"] > 1:
        law = d.get("period_law")
        vs = f" (law {law['T']:.6g}, {100 * d['period_rel_dev']:+.3f}%)" if law else ""
        lines.append(f"mean period {d['period']:.6g}{vs}")
        lines.append(
            f"slip duration {d['slip_duration']:.5g}, force at stop {d['force_at_stop']:.5g}, "
            f"slip {d['slip']:.5g} (means over slips after the first)"
        )
    for path in d.get("outputs", []):
        lines.append(f"wrote {path}")
    return "\n".join(lines)


def _fig2_source(run: BlockRun) -> tuple[BlockRun, int] | None:
    """A run with every step stored around the second slip of ``run`` (the first if it has one
    slip), and that slip's row in it; None without slips (Fig. 2)."""
    from stickslip.run.block import simulate_block

    if len(run.slips) == 0:
        return None
    index = 1 if len(run.slips) > 1 else 0
    if run.every == 1:
        return run, index
    # Re-run to just before the slip without storing, then store every step through it.
    p = run.params
    lead = max(0.0, float(run.slips["t_c"].iloc[index]) - 10 * p.dt)
    before = simulate_block(p, lead, initial=run.initial, every=max(1, steps_for(lead, p.dt, "t_end")))
    span = 2.0 * float(run.slips["duration"].iloc[index]) + 20 * p.dt
    fine = simulate_block(p, span, initial=before.restart_state())
    return (fine, 0) if len(fine.slips) else None


def write_block_outputs(out: Path, run: BlockRun, law: SlipLimit | None, *, fig3: bool = False) -> list[Path]:
    """Write a run's series, slip table, run.json and Figs. 1-2 (and Fig. 3) to ``out``."""
    import xarray as xr

    from stickslip.analysis.dynamics.slip_limit import paper_V_values, period_sweep
    from stickslip.plotting.block import fig1_position, fig2_slip, fig3_period, slip_window
    from stickslip.plotting.style import save_figure
    from stickslip.run.block import INTEGRATOR

    written = [
        io.write_dataset(out / "series.nc", run.series),
        *io.write_table_files(out / "slips", run.slips),
    ]
    written += save_figure(fig1_position(run), out / "fig1")
    source = _fig2_source(run) if law is not None else None
    if source is not None:
        fine, index = source
        window = slip_window(fine, index)
        fig2_data = xr.Dataset(
            {
                "eq1_v": ("t_eq1", window["v"].values),
                "eq1_theta": ("t_eq1", window["theta"].values),
                "eq3_v": ("t_eq3", law.curve["v"].values),
                "eq3_theta": ("t_eq3", law.curve["theta"].values),
            },
            coords={"t_eq1": window["t"].values, "t_eq3": law.curve["t"].values},
            attrs={"description": "Fig. 2: v and theta against t - t_c, eq. (1) (Heun) and eq. (3)"},
        )
        written.append(io.write_dataset(out / "fig2.nc", fig2_data))
        written += save_figure(fig2_slip(fine, law, index), out / "fig2")
    sweep = None
    if fig3 and law is not None:
        sweep = period_sweep(run.params, paper_V_values(FIG3_POINTS), periods=FIG3_PERIODS)
        written += io.write_table_files(out / "fig3", sweep)
        written += save_figure(fig3_period(sweep, law), out / "fig3")
    meta = io.run_metadata(
        run.params,
        integrator=INTEGRATOR,
        command="block",
        t_end=run.t_end,
        every=run.every,
        initial=run.initial,
        summary=run.summary(),
        period_law=law.summary() if law is not None else None,
        fig3=None if sweep is None else {"V": sweep["V"].tolist(), "rel_dev": sweep["rel_dev"].tolist()},
    )
    written.append(io.write_json(out / "run.json", meta))
    return written


def run_slip_limit(args: argparse.Namespace) -> Result:
    """Handler of ``stickslip slip-limit``: eq. (3), the Heun comparison and the period law."""
    from stickslip.analysis.dynamics.slip_limit import (
        PAPER_DURATION,
        PAPER_FORCE_AT_STOP,
        NoStopError,
        heun_slip_limit,
        matches_paper,
        solve_slip_limit,
    )

    p = params_from_args(BlockParams, args)
    rtol = check_number("rtol", args.rtol, low=1e-13, high=1e-2)
    atol = check_number("atol", args.atol, low=0.0, low_open=True, high=1e-2)
    # Heun resolves the oscillation of the spring only for omega dt = dt sqrt(K/M) well below 1.
    if p.dt * math.sqrt(p.K / p.M) > 0.5:
        raise CommandError(
            f"dt must be <= 0.5 sqrt(M/K) = {0.5 * math.sqrt(p.M / p.K):.3g} for the Heun slip (got dt={p.dt:g})"
        )
    # eq. (3) is solved for a slip of a few periods 2 pi sqrt(M/K); huge Fs/sigma slips for ever.
    if p.Fs / p.sigma > 1e3:
        raise CommandError(f"Fs must be <= 1000 sigma for eq. (3) (got Fs={p.Fs:g}, sigma={p.sigma:g})")
    try:
        law = solve_slip_limit(p, rtol=rtol, atol=atol)
        heun = heun_slip_limit(p)
    except NoStopError as exc:
        raise CommandError(str(exc)) from None
    data: dict[str, Any] = law.summary()
    data["params"] = {k: v for k, v in p.to_dict().items() if k != "V"}
    data["heun"] = {"dt": p.dt, "duration": heun.duration, "force_at_stop": heun.force_at_stop}
    if matches_paper(p):
        data["paper"] = {"duration": PAPER_DURATION, "force_at_stop": PAPER_FORCE_AT_STOP}
    text = [
        "slip in the limit V -> 0, eq. (3): " + " ".join(f"{k}={v:g}" for k, v in data["params"].items() if k != "dt"),
        f"accurate ({law.method}): duration t_e - t_c = {law.duration:.6f}, "
        f"force at stop Fs - K x' = {law.force_at_stop:.6f}",
        f"Heun dt={p.dt:g} with the stop rule of eq. (1): duration {heun.duration:.6f}, "
        f"force at stop {heun.force_at_stop:.6f}",
    ]
    if "paper" in data:
        text.append(f"paper: duration {PAPER_DURATION}, force at stop {PAPER_FORCE_AT_STOP}")
    text.append(f"period law: T(V) = {law.law_a:.6f} + {law.law_b:.6f} / (K V)")
    return Result(data=data, text="\n".join(text))
