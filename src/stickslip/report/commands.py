"""The ``stickslip`` command lines that reproduce a row or a figure of the report.

Each takes the :class:`~stickslip.outcome.Outcome` of the experiment behind the row
or figure and names the command (and its options) that computes the same thing.
"""

from __future__ import annotations

from stickslip.outcome import Outcome, point_settings


def g(x: float) -> str:
    """A number as the commands write it (``%g``)."""
    return f"{x:g}"


def block_command(o: Outcome) -> str:
    """The ``stickslip block`` command of the block run (Figs. 1, 2)."""
    return f"stickslip block --t-end {g(o.settings['t_end'])} --out DIR"


def hysteresis_command(o: Outcome, *, draw: bool = False) -> str:
    """The ``stickslip hysteresis`` command of the sweep of V (section 2): printing its numbers,
    or with ``draw`` writing its figure (hysteresis.png) into DIR."""
    s = o.settings["options"]
    return (
        f"stickslip hysteresis --K 10 --beta 1 --Fs 3 --V-min {g(s['V_min'])} --V-max {g(s['V_max'])} "
        f"--dV {g(s['dV'])} --time-per-step {g(s['time_per_step'])} --transient {g(s['transient'])} "
        + ("--out DIR" if draw else "--json")
    )


def chain_command(o: Outcome, N: int, beta: float, *, plot: str | None = None) -> str:
    """The ``stickslip chain`` command of one chain run of the experiment; with ``plot`` (a figure
    of ``stickslip plot``: snapshot_final, sizes, fronts, ...) followed by the command that draws
    it from the run directory."""
    cfg = {**o.settings, "N": N, "beta": beta}
    params, t_end, opts = point_settings(cfg)
    parts = [
        f"stickslip chain --N {N} --beta {g(beta)} --t-end {g(t_end)}",
        f"--sample-interval {g(opts['sample_interval'])} --average-from {g(opts['average_from'])}",
    ]
    if opts.get("profile_window"):
        parts.append(f"--profile-window {g(opts['profile_window'])} --profile-min-blocks {opts['profile_min_blocks']}")
    if opts.get("until_steady"):
        parts.append(f"--until-steady {g(opts['until_steady'])}")
    parts.append("--out DIR")
    if plot is not None:
        parts.append(f"&& stickslip plot DIR  (DIR/figures/{plot}.png)")
    return " ".join(parts)


def reproduce_command(mode: str) -> str:
    """The ``stickslip reproduce`` command of a mode."""
    return f"stickslip reproduce --{mode} --out DIR"


def sweep_command(o: Outcome, mode: str) -> str:
    """The reproduce command whose Dask sweep gives the chain runs of Fig. 5(b) (``o.run_dir``:
    the folder of their points)."""
    return f"{reproduce_command(mode)}  (chain runs on Dask: runs/{o.run_dir.parent.name}/{o.run_dir.name})"
