"""The table of the paper's stated numbers (docs/model.md, last table) as rows of the report.

One :class:`~stickslip.report.writer.ReportRow` per stated number: section 2 (Hopf point,
stability at beta = 1, the inverse transition), eq. (3) (duration and force at stop), Fig. 3
(the period law), Fig. 4 (long-wave instability), section 3 (final states) and Figs. 5-8 from
the chain runs, each with the paper's value, this run's, whether they agree and the command:
:func:`section2_rows` and :func:`chain_rows`, the findings of the paper's two studies
(:data:`stickslip.experiments.studies.PAPER`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from stickslip.analysis.stats.chain_runs import fig6_start_note, sweep_table
from stickslip.analysis.stats.statistics import central_interval
from stickslip.models.physics import chain_steady_state
from stickslip.outcome import Outcome
from stickslip.report.commands import chain_command, hysteresis_command, sweep_command
from stickslip.report.commands import g as _g
from stickslip.report.writer import ReportRow

#: The paper's stated numbers (docs/model.md, last table) that the report compares with.
PAPER = {
    "hopf_V": 0.106,
    "V_up": 0.345,
    "duration": 1.035,
    "force_at_stop": -0.432,
    "law_a": 1.035,
    "law_b": 3.432,
    "critical_beta": 1.0,
    "front_speed": 1.43,
    "tau_beta1": 1.5,
    "tau_beta02": 1.6,
}


def _f(x: Any, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def section2_rows(o: dict[str, Outcome]) -> list[ReportRow]:
    """Rows of section 2, eq. (3) and Figs. 3 and 4 (the same computation in every mode), from the
    outcomes of the experiments of :mod:`stickslip.experiments.studies.figs1_4` by name."""
    rows = []
    st = o["stability-block"].summary
    Vc = st["hopf_V"]
    rows.append(
        ReportRow(
            "sec. 2",
            "Hopf point of steady sliding, K = 10, beta = 0.08",
            "V_c = 0.106",
            f"V_c = {_f(Vc, 5)}",
            None if Vc is None else abs(Vc - PAPER["hopf_V"]) <= 1e-3,
            "|V_c - 0.106| <= 0.001",
            "stickslip stability block --K 10 --beta 0.08 --json",
            na_reason="no Hopf point found" if Vc is None else "",
            note=f"Routh-Hurwitz closed form {_f(st['hopf_V_closed_form'], 5)}; truncated to three "
            "digits it is the paper's 0.106",
        )
    )
    stable = st["hopf_V_stable"] is None and st["max_growth_stable"] < 0.0
    lo, hi, n = st["V_scan"]
    rows.append(
        ReportRow(
            "sec. 2",
            "steady sliding linearly stable for all V > 0, K = 10, beta = 1",
            "stable for all V",
            f"{st['regime_stable']}; largest Re(lambda) over {n} V in [{_g(lo)}, {_g(hi)}]: "
            f"{_f(st['max_growth_stable'], 3)}",
            stable,
            "no Hopf point and Re(lambda) < 0 at every V of the grid",
            "stickslip stability block --K 10 --beta 1 --json",
        )
    )
    hy = o["hysteresis"].summary
    V_up = hy["V_up"]
    dV = hy["sweep"]["dV"]
    rows.append(
        ReportRow(
            "sec. 2",
            "inverse transition stick-slip -> sliding as V is raised slowly, beta = 1, Fs = 3",
            "V = 0.345",
            f"V_up = {_f(V_up)}",
            None if V_up is None else abs(V_up - PAPER["V_up"]) <= dV + 1e-12,
            f"|V_up - 0.345| <= dV = {_g(dV)}",
            hysteresis_command(o["hysteresis"]),
            na_reason="stick-slip did not end in the swept range" if V_up is None else "",
            note=f"V raised in steps of {_g(dV)}, {_g(hy['sweep']['time_per_step'])} time units per value; going "
            + (
                "down, the block keeps sliding steadily down to V = " + _g(hy["sweep"]["V_min"])
                if hy["V_down"] is None
                else f"down, stick-slip returns at V_down = {_f(hy['V_down'])}"
            ),
        )
    )
    sl = o["slip-limit"].summary
    rows.append(
        ReportRow(
            "eq. 3",
            "slip duration t_e - t_c in the limit V -> 0",
            "1.035",
            f"{sl['duration']:.4f}",
            abs(sl["duration"] - PAPER["duration"]) <= sl["heun_dt"] + 1e-12,
            f"|t_e - t_c - 1.035| <= dt = {_g(sl['heun_dt'])} (the paper's number is from a Heun run with that step)",
            "stickslip slip-limit --json",
            note=f"DOP853 with event location; Heun with dt = {_g(sl['heun_dt'])} and the stop rule gives "
            f"{sl['heun_duration']:.4f}",
        )
    )
    rows.append(
        ReportRow(
            "eq. 3",
            "spring force Fs - K x' when the block stops",
            "-0.432",
            f"{sl['force_at_stop']:.5f}",
            abs(sl["force_at_stop"] - PAPER["force_at_stop"]) <= 5e-4,
            "|f - (-0.432)| <= 0.0005 (rounding)",
            "stickslip slip-limit --json",
            note=f"Heun, dt = {_g(sl['heun_dt'])}: {sl['heun_force_at_stop']:.5f}",
        )
    )
    law = o["slip-limit"].data["law"]
    ps = o["period-sweep"].summary
    ok = (
        abs(law.law_a - PAPER["law_a"]) <= sl["heun_dt"] + 1e-12
        and abs(law.law_b - PAPER["law_b"]) <= 5e-4
        and ps["max_abs_rel_dev"] <= 0.03
    )
    rows.append(
        ReportRow(
            "Fig. 3",
            "period law T(V) = a + b / (K V), and the simulated periods",
            "T = 1.035 + 3.432 / (K V)",
            f"T = {law.law_a:.4f} + {law.law_b:.4f} / (K V); simulated periods within "
            f"{100 * ps['max_abs_rel_dev']:.1f}% of it for V in [1e-3, 1e-1]",
            ok,
            "|a - 1.035| <= dt, |b - 3.432| <= 0.0005, simulated periods within 3% of the law",
            "stickslip slip-limit --json && stickslip block --fig3 --out DIR",
        )
    )
    cm = o["chain-modes"].summary
    per = {round(r["beta"], 6): r for r in cm["per_beta"]}

    def state(r):
        return "unstable" if r["unstable"] else ("marginal" if r["marginal"] else "stable")

    ok4 = abs(cm["critical_beta_numeric"] - PAPER["critical_beta"]) <= 1e-3 and all(
        r["unstable"] == (r["beta"] < 1.0) for r in cm["per_beta"]
    )
    rows.append(
        ReportRow(
            "Fig. 4",
            "long-wave instability of steady sliding of the chain, K = 10, D = 5",
            "for beta <= 1 (beta = 1 critical)",
            f"critical beta {cm['critical_beta']:g} (closed form), {cm['critical_beta_numeric']:.6f} (Fourier modes); "
            + ", ".join(f"beta = {b:g}: {state(r)}" for b, r in sorted(per.items())),
            ok4,
            "|beta_c - 1| <= 0.001; unstable exactly for the betas below 1",
            "stickslip stability chain --K 10 --D 5 --beta 1 --json",
            note="at beta = 1 the long-wave growth rate tends to 0 from below as k -> 0 (marginal); the paper "
            "counts beta = 1 with the unstable side",
        )
    )
    return rows


def _final_state_row(o: Outcome, a: dict[str, Any], mode: str) -> ReportRow:
    t = a["table"].sort_values(["N", "beta"])
    parts, contradicts, unsettled = [], [], []
    for r in t.itertuples():
        state = r.final_state
        tag = f"beta = {r.beta:g} (N = {r.N}): {state}"
        if state == "steady sliding" and isinstance(r.t_steady, (int, float)) and math.isfinite(r.t_steady):
            tag += f" from t = {r.t_steady:.3g}"
        elif state == "steady sliding" and isinstance(r.t_last_event, (int, float)):
            tag += f" at the end (last event ended at t = {r.t_last_event:.3g})"
        parts.append(tag)
        if r.beta <= 1.0 and state != "stick-slip":
            contradicts.append(r.beta)
        if r.beta > 1.0 and state != "steady sliding":
            t_run = float(o.settings["t_end_by_N"][str(int(r.N))])
            unsettled.append(f"{r.beta:g} (N = {r.N}, t = {_g(t_run)})")
    if mode == "tiny":
        agrees, reason = None, "tiny run: tiny chains"
    elif contradicts:
        agrees, reason = False, ""
    elif unsettled:
        agrees = None
        reason = (
            f"beta = {', '.join(unsettled)} has not settled into steady sliding by the end of its run; "
            "the paper reaches steady sliding 'after a long run'"
        )
    else:
        agrees, reason = True, ""
    return ReportRow(
        "sec. 3",
        "final state of the chain from the paper's initial state",
        "steady sliding for beta > 1, stick-slip for beta <= 1",
        "; ".join(parts),
        agrees,
        "every run at beta <= 1 stick-slips in its second half; every run at beta > 1 slides steadily at the end",
        sweep_command(o, mode),
        na_reason=reason,
        note=f"runs at beta > {_g(o.settings['until_steady_above'])} stop once every block slides within "
        f"{_g(o.settings['until_steady'])} of steady sliding (v, theta and spring extensions); "
        "from there on nothing changes",
    )


#: Fig. 6's row: the paper's c agrees if it lies inside this central share of the per-event speeds.
FRONT_LEVEL = 0.9
FRONT_DEFINITIONS = (
    ("c_first_move", "first motion over the far half"),
    ("c_leading_edge", "leading edge of the Delta x windows"),
)


def front_speed_verdict(
    per_event: pd.DataFrame, *, K: float, level: float = FRONT_LEVEL, paper: float = PAPER["front_speed"]
) -> tuple[bool | None, str]:
    """Agreement of the paper's front speed with the per-event distribution of c (Fig. 6).

    For each definition (``c_first_move``, ``c_leading_edge`` columns of ``per_event``) with at
    least one finite value: where the paper's c lies (percentile) and whether it is inside the
    central ``level`` of the events. Agrees: inside for every definition with values, and every
    median below the sound speed sqrt(K). None when no definition has a value. Returns the
    verdict and the row's text.
    """
    parts, verdicts = [], []
    for col, name in FRONT_DEFINITIONS:
        x = per_event[col].to_numpy(dtype=float) if col in per_event else np.array([])
        x = x[np.isfinite(x)]
        if x.size == 0:
            parts.append(f"{name}: no event")
            continue
        ci = central_interval(x, paper, level=level)
        verdicts.append(ci.inside and ci.median < math.sqrt(K))
        parts.append(
            f"{name}: median {ci.median:.3g}, quartiles {ci.quartiles[0]:.3g}-{ci.quartiles[1]:.3g}, "
            f"central {100 * level:.0f}% {ci.lo:.3g}-{ci.hi:.3g} over {ci.n} events; "
            f"{paper:g} at percentile {ci.percentile:.0f} ({'inside' if ci.inside else 'outside'})"
        )
    return (all(verdicts) if verdicts else None), "; ".join(parts)


def front_speed_row(
    per_event: pd.DataFrame, *, K: float, mode: str, command: str, quick_reason: str = "", note_extra: str = ""
) -> ReportRow:
    """The row of Fig. 6: the paper's c = 1.43 against the per-event distribution of front speeds."""
    agrees, value = front_speed_verdict(per_event, K=K)
    settled = mode == "full" and agrees is not None
    if agrees is None:
        reason = "no event reached block N"
    elif mode == "tiny":
        reason = "tiny run: tiny chain"
    else:
        reason = "" if settled else quick_reason
    return ReportRow(
        "Fig. 6",
        "rupture front speed in large events, beta = 1",
        "c = 1.43 (sound speed sqrt(K) = 3.16)",
        f"per event reaching block N: {value}",
        agrees if settled else None,
        f"1.43 inside the central {100 * FRONT_LEVEL:.0f}% (5th-95th percentile) of the per-event front speeds "
        "by both definitions, and the medians below sqrt(K)",
        command,
        na_reason=reason,
        note="a distribution over events, not one number: each event's speed is fitted over the far half of "
        "the chain, by the first motion of each block and by the leading edge of the windows of 20 time "
        "units (as the paper's figure). " + note_extra,
    )


def chain_rows(o: Outcome, a: dict[str, Any], mode: str) -> list[ReportRow]:
    """Rows of section 3 and Figs. 5-8 from the chain runs (``o``) and their analysis ``a``
    (:func:`stickslip.analysis.stats.chain_runs.chain_analysis`)."""
    rows = [_final_state_row(o, a, mode)]
    tiny = mode == "tiny"

    def quick_reason(events: pd.DataFrame) -> str:
        return (
            f"quick run: N = {a['figure_N']} to t = {_g(a['t_fig'])} ({len(events)} events in the second half), "
            "the paper: N = 399 to t = 2e7"
        )

    # Fig. 5(a)
    run = a["run1"]
    snap = run.snapshots.isel(snapshot_time=-1)
    t = float(snap["snapshot_time"])
    ss = chain_steady_state(run.params, t)["x"]
    L_ss = float(run.summary["L_steady"])
    dev = float(np.max(np.abs(snap.values - ss))) / L_ss
    rows.append(
        ReportRow(
            "Fig. 5(a)",
            f"snapshot of x_i at beta = 1 against steady sliding (t = {t:.3g}, N = {run.params.N})",
            "close to the steady sliding profile",
            f"max_i |x_i - x_i^ss| = {100 * dev:.2f}% of L_ss = {L_ss:.5g}",
            None if tiny else dev <= 0.05,
            "max_i |x_i - x_i^ss| <= 5% of L_ss",
            chain_command(o, run.params.N, 1.0),
            na_reason="tiny run: tiny chain" if tiny else "",
        )
    )
    # Fig. 5(b)
    sw = sweep_table(a)
    below = sw[sw["beta"] <= 1.0]
    ratio = below["L_mean"] / below["L_steady"]
    err = below["L_err"].fillna(0.0).to_numpy()
    L = below["L_mean"].to_numpy()
    increasing = bool(np.all(np.diff(L) > -2.0 * np.hypot(err[1:], err[:-1]))) if len(L) > 1 else False
    under = bool(
        np.all(
            (below["L_mean"] < below["L_steady"] + 2 * below["L_err"].fillna(0.0)).to_numpy()[
                below["beta"].to_numpy() < 1.0
            ]
        )
    )
    at1 = below[np.isclose(below["beta"], 1.0)]
    meets = bool(len(at1) and abs(float(at1["L_mean"].iloc[0] / at1["L_steady"].iloc[0]) - 1.0) <= 0.03)
    above = sw[sw["beta"] > 1.0]
    rows.append(
        ReportRow(
            "Fig. 5(b)",
            f"<L> against beta (N = {a['sweep_N']})",
            "continuous decrease below beta = 1",
            "<L>/L_ss = " + ", ".join(f"{r:.3f} (beta = {b:g})" for b, r in zip(below["beta"], ratio, strict=False)),
            None if tiny else (increasing and under and meets),
            "<L> increases with beta up to 1 (within 2 sigma), stays below L_ss, and is within 3% of L_ss at beta = 1",
            sweep_command(o, mode),
            na_reason="tiny run: tiny chains" if tiny else "",
            note="above beta = 1: "
            + (
                ", ".join(
                    f"<L>/L_ss = {r.L_mean / r.L_steady:.3f} at beta = {r.beta:g} ({r.final_state})"
                    for r in above.itertuples()
                )
                or "no runs"
            ),
        )
    )
    # Fig. 6
    rows.append(
        front_speed_row(
            a["fronts"]["per_event"],
            K=float(a["run1"].params.K),
            mode=mode,
            command=chain_command(o, a["figure_N"], 1.0),
            quick_reason=quick_reason(a["events1"]),
            note_extra=fig6_start_note(a),
        )
    )
    # Fig. 7
    s1 = a["sizes1"]
    if s1 is None:
        rows.append(
            ReportRow(
                "Fig. 7",
                "slip-size distribution, beta = 1",
                "power law, exponent about 1.5, cut off by N",
                None,
                None,
                "|tau - 1.5| <= 0.1",
                chain_command(o, a["figure_N"], 1.0),
                na_reason="too few events",
            )
        )
    else:
        fit = s1["fit"]
        rows.append(
            ReportRow(
                "Fig. 7",
                "slip-size distribution, beta = 1",
                "power law, exponent about 1.5, cut off by N",
                f"tau = {fit.tau:.2f} ± {fit.tau_err:.2f} on S in [{fit.s_min:.3g}, {fit.s_max:.3g}] ({fit.n} events); "
                f"largest S = {s1['S_max']:.3g}, {'reached' if s1['largest_reaches_N'] else 'did not reach'} block N "
                f"({s1['n_spanning']} events reached it)",
                (abs(fit.tau - PAPER["tau_beta1"]) <= 0.1 and s1["largest_reaches_N"]) if mode == "full" else None,
                "|tau - 1.5| <= 0.1 and the largest events span the chain",
                chain_command(o, a["figure_N"], 1.0),
                na_reason="" if mode == "full" else ("tiny run: tiny chain" if tiny else quick_reason(a["events1"])),
                note="maximum likelihood for a power law truncated to the fit range; s_min by least KS distance; "
                "error: bootstrap",
            )
        )
    # Fig. 8
    s2 = a["sizes02"]
    if s2 is None:
        rows.append(
            ReportRow(
                "Fig. 8",
                "slip-size distribution, beta = 0.2",
                "about 1.6 for small S, excess of large events",
                None,
                None,
                "|tau - 1.6| <= 0.15 and excess >= 2",
                chain_command(o, a["figure_N"], 0.2),
                na_reason="too few events",
            )
        )
    else:
        fit = s2["fit"]
        ex = s2["excess"]
        ex1 = a["sizes1"]["excess"] if a["sizes1"] else math.nan
        rows.append(
            ReportRow(
                "Fig. 8",
                "slip-size distribution, beta = 0.2",
                "about 1.6 for small S, excess of large events",
                f"tau = {fit.tau:.2f} ± {fit.tau_err:.2f} on S in [{fit.s_min:.3g}, {fit.s_max:.3g}] ({fit.n} events); "
                f"events with S >= {_f(s2['s_span'], 3)}: {_f(ex, 3)} times the power law's count",
                (abs(fit.tau - PAPER["tau_beta02"]) <= 0.15 and ex >= 2.0) if mode == "full" else None,
                "|tau - 1.6| <= 0.15 and at least twice the power law's count of large events",
                chain_command(o, a["figure_N"], 0.2),
                na_reason=("" if mode == "full" else "tiny run: tiny chain" if tiny else quick_reason(a["events02"])),
                note="large: S at least that of the smallest event that reached block N; "
                f"the same ratio at beta = 1 is {_f(ex1, 3)}",
            )
        )
    return rows


#: The columns of the stated numbers on a study's page.
ROW_COLUMNS = ("where", "quantity", "paper", "value", "agreement")


def findings_of(rows: list[ReportRow] | None) -> dict[str, Any]:
    """The findings of one of the paper's studies: its ``rows`` of stated numbers (as dicts) and a
    statement per row; without rows (an experiment did not finish), a statement that says so."""
    if rows is None:
        return {"statements": ["not every experiment finished: no stated numbers"], "rows": []}
    return {
        "statements": [f"{r.where}: {r.quantity}: {r.agreement}" for r in rows],
        "rows": [r.to_dict() for r in rows],
    }


def stated_numbers(found: dict[str, Any]) -> list[tuple[str, list[str], list[dict[str, Any]]]]:
    """The table of stated numbers on the page of one of the paper's studies (its findings' rows)."""
    return [("The paper's stated numbers", list(ROW_COLUMNS), found.get("rows", []))]
