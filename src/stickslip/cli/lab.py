"""`stickslip lab step|shs|fit|invert|bench`: the rock-friction laboratory's protocols (:mod:`stickslip.lab`).

``lab step`` runs the quasi-static spring-slider through steps of the load-point velocity and
reports each step's peak and new steady state; ``lab shs`` runs a slide-hold-slide test and
reports the peak friction against hold time and the healing rate d(Delta mu)/d log10 t_hold;
``lab fit DATA.csv ...`` fits rate-and-state parameters to records, with standard errors and
correlations; ``lab invert DATA.csv`` fits the inertial spring-slider to the periods, stress
drops and peak slip rates of a stick-slip record or a table of its cycles; ``lab bench``
measures the quasi-static solver against a plain-Python odeint model and the CPU time of a
four-parameter fit. The friction parameters are the lab's (docs/lab.md):
each of --a, --b, --Dc, --mu0, --V0, --k is required, none has a default.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from stickslip.cli._common import (
    OUT_FILES,
    CommandError,
    Result,
    add_json_option,
    add_overwrite_option,
    float_arg,
    int_arg,
    owned_out_dir,
)


def _floats(name: str):
    """An argparse type for a comma-separated list of numbers."""

    def convert(text: str):
        try:
            return [float(x) for x in text.split(",") if x.strip()]
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be numbers separated by commas (got {text!r})") from None

    convert.__name__ = name
    return convert


def _words(text: str) -> list[str]:
    return [x.strip() for x in text.split(",") if x.strip()]


def _lab_laws() -> list[str]:
    """The lab's names of the friction laws that declare a lab form, in the registry's order
    (:data:`stickslip.lab.LAWS`, read from the pieces without compiling anything)."""
    from stickslip.models.pieces import PIECES

    return [p.lab.name for p in PIECES["friction"] if p.lab is not None]


def _add_law_options(p: argparse.ArgumentParser, *, k_help: str) -> None:
    g = p.add_argument_group("friction (lab conventions, docs/lab.md; required unless marked)")
    g.add_argument("--a", type=float_arg("a"), help="direct effect a (> 0)")
    g.add_argument("--b", type=_floats("b"), help="evolution effect b of each state variable (comma-separated)")
    g.add_argument("--Dc", type=_floats("Dc"), help="critical slip distance D_c of each state variable (> 0)")
    g.add_argument("--mu0", type=float_arg("mu0"), help="steady-state friction at V0")
    g.add_argument("--V0", type=float_arg("V0"), help="reference velocity V0 (> 0)")
    g.add_argument("--k", type=float_arg("k"), help=k_help)
    g.add_argument("--law", type=_words, default=["aging"],
                   help=f"evolution law of each state variable: {', '.join(_lab_laws())} (default aging)")  # fmt: skip
    g.add_argument("--c", type=_floats("c"), default=[0.0], help="Nagata's c of each state variable (default 0)")
    g.add_argument("--eta", type=float_arg("eta"), default=0.0, help="radiation damping eta (default 0)")
    g.add_argument("--form", choices=("log", "asinh"), default="log", help="friction form (default log)")
    g.add_argument("--method", choices=("auto", "dop853", "LSODA", "Radau", "BDF"), default="auto",
                   help="integrator (default auto: the compiled dop853, LSODA for a very stiff spring)")  # fmt: skip
    g.add_argument("--rtol", type=float_arg("rtol"), default=1e-10, help="relative tolerance (default 1e-10)")


def _model(args):
    from stickslip.lab import RateState

    return RateState(
        a=args.a, b=args.b, Dc=args.Dc, mu0=args.mu0, V0=args.V0, k=args.k,
        law=args.law, c=args.c, eta=args.eta, form=args.form,
    )  # fmt: skip


def _mass_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--M", type=float_arg("M"), default=0.0,
                   help="mass per unit normal stress: 0 (default) for the quasi-static spring-slider, > 0 for the "
                        "inertial one (any number of state variables; docs/lab.md)")  # fmt: skip


def _out_options(p: argparse.ArgumentParser, stem: str) -> None:
    p.add_argument("--out", default=None, metavar="DIR",
                   help=f"write {stem}.nc, {stem}.json, the figure {stem}.png/.pdf and the page "
                        "index.html to DIR")  # fmt: skip
    add_overwrite_option(p)
    add_json_option(p)


def register(sub) -> None:
    """Add ``lab`` with ``step``, ``shs``, ``fit``, ``invert`` and ``bench`` to the parser."""
    lab = sub.add_parser(
        "lab",
        help="the rock-friction laboratory: velocity steps, slide-hold-slide, fits (quasi-static spring-slider)",
        description="Rate-and-state friction as the laboratory uses it (docs/lab.md).",
    )
    ls = lab.add_subparsers(dest="lab_command", metavar="PROTOCOL", parser_class=type(lab))
    ls.required = True

    s = ls.add_parser(
        "step",
        help="velocity steps of the load point",
        description="The spring-slider (quasi-static, or inertial with --M) through steps of the load-point velocity.",
    )
    _add_law_options(s, k_help="stiffness k in friction per unit displacement (> 0)")
    s.add_argument("--V", type=_floats("V"), default=[1.0, 10.0], help="load-point velocities in turn (default 1,10)")
    s.add_argument("--displacement", type=float_arg("displacement"), default=None,
                   help="load-point displacement at each velocity (default 20 D_c)")  # fmt: skip
    _mass_option(s)
    _out_options(s, "step")
    s.set_defaults(handler=run_step)

    h = ls.add_parser("shs", help="slide-hold-slide: peak friction against hold time, healing rate",
                      description="Slides at V around holds at V = 0; healing d(Delta mu)/d log10 t_hold.")  # fmt: skip
    _add_law_options(h, k_help="stiffness k in friction per unit displacement (> 0)")
    h.add_argument("--V", type=float_arg("V"), default=10.0, help="sliding velocity (default 10)")
    h.add_argument("--holds", type=_floats("holds"), default=[1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0],
                   help="hold times (default 1,3,10,30,100,300,1000)")  # fmt: skip
    h.add_argument("--slide", type=float_arg("slide"), default=None,
                   help="load-point displacement of each slide (default 20 D_c)")  # fmt: skip
    _mass_option(h)
    _out_options(h, "shs")
    h.set_defaults(handler=run_shs)

    f = ls.add_parser("fit", help="fit a, b, D_c, mu0, k ... to records (CSV), with standard errors",
                      description="Least-squares fit of rate-and-state parameters to friction records; the "
                                  "friction options give the starting values and the fixed parameters.")  # fmt: skip
    f.add_argument("data", nargs="+", metavar="DATA.csv",
                   help="records: columns time, mu (or friction) and load_point (or velocity)")  # fmt: skip
    _add_law_options(f, k_help="stiffness k in friction per unit displacement (> 0; fitted if in --free)")
    f.add_argument("--free", type=_words, default=["a", "b", "Dc"],
                   help="parameters fitted: a, b, Dc, b2, Dc2, mu0, k, eta, trend (default a,b,Dc)")  # fmt: skip
    f.add_argument("--per-record", dest="per_record", type=_words, default=[],
                   help="free parameters with one value per record (e.g. mu0)")  # fmt: skip
    f.add_argument("--window", type=_floats("window"), default=None, help="fit only t0 <= t <= t1 (T0,T1)")
    f.add_argument("--detrend", type=_floats("detrend"), default=None,
                   help="remove a linear trend of mu with load-point displacement fitted over T0,T1")  # fmt: skip
    f.add_argument("--posterior", type=int_arg("posterior"), default=None, metavar="STEPS",
                   help="also sample the posterior by MCMC (emcee) for STEPS steps of each walker")  # fmt: skip
    f.add_argument("--seed", type=int_arg("seed"), default=0, help="seed of the posterior's chain (default 0)")
    f.add_argument("--time", default="time", help="time column (default time)")
    f.add_argument("--friction", default=None, help="friction column (default mu or friction)")
    f.add_argument("--displacement", default=None, help="load-point displacement column")
    f.add_argument("--velocity", default=None, help="load-point velocity column")
    _out_options(f, "fit")
    f.set_defaults(handler=run_fit)

    v = ls.add_parser(
        "invert",
        help="fit the inertial spring-slider to stick-slip cycles: periods, stress drops, peak slip rates",
        description="Least-squares inversion of a stick-slip record (or a table of its cycles) with the inertial "
        "spring-slider (the chain's single block with a mass, docs/lab.md); the friction options give the "
        "starting values and the fixed parameters. A fit costs 10 to 30 runs of the model: 2-5 s of CPU "
        "for a record of 400 time units sampled every 0.2 at dt = 2.5e-3.",
    )  # fmt: skip
    v.add_argument("data", metavar="DATA.csv",
                   help="a record (columns time, mu or friction, load_point or velocity) or, with --cycles, "
                        "a table of cycles (columns period, stress_drop, peak_slip_rate, peak_friction)")  # fmt: skip
    _add_law_options(v, k_help="stiffness k in friction per unit displacement (> 0; fitted if in --free)")
    v.add_argument("--M", type=float_arg("M"), default=None, help="mass per unit normal stress (> 0; required)")
    v.add_argument("--dt", type=float_arg("dt"), default=None, help="the integrator's step (default M / 4)")
    v.add_argument("--free", type=_words, default=["a", "b", "Dc"],
                   help="parameters fitted: a, b, Dc, b2, Dc2, mu0, k, eta, M (default a,b,Dc)")  # fmt: skip
    v.add_argument("--observables", type=_words, default=None,
                   help="observables compared: period, stress_drop, peak_slip_rate, peak_friction "
                        "(default all four, or a table's columns)")  # fmt: skip
    v.add_argument("--cycles", action="store_true", help="DATA.csv is a table of cycles, one row per cycle")
    v.add_argument("--V", type=float_arg("V"), default=None,
                   help="load-point velocity (with --cycles; default a record's mean in the window)")  # fmt: skip
    v.add_argument("--window", type=_floats("window"), default=None,
                   help="read only t0 <= t <= t1 of data and model (T0,T1; default a record's 2nd half)")  # fmt: skip
    v.add_argument("--t-end", dest="t_end", type=float_arg("t-end"), default=None,
                   help="with --cycles: length of the model run (default 12 observed periods)")  # fmt: skip
    v.add_argument("--sample-interval", dest="sample_interval", type=float_arg("sample-interval"), default=None,
                   help="with --cycles: sampling of the model run (default the observed period / 200)")  # fmt: skip
    v.add_argument("--floor", type=float_arg("floor"), default=1e-3,
                   help="relative floor of the observables' standard errors (default 1e-3)")  # fmt: skip
    v.add_argument("--time", default="time", help="time column (default time)")
    v.add_argument("--friction", default=None, help="friction column (default mu or friction)")
    v.add_argument("--displacement", default=None, help="load-point displacement column")
    v.add_argument("--velocity", default=None, help="load-point velocity column")
    _out_options(v, "invert")
    v.set_defaults(handler=run_invert)

    b = ls.add_parser(
        "bench",
        help="speed: quasi-static solver against plain-Python odeint; a fit's CPU time",
        description="Times a standard velocity step both ways and a four-parameter fit, in one run.",
    )
    b.add_argument("--repeats", type=int_arg("repeats"), default=5, help="timings per measure, least kept (default 5)")
    add_json_option(b)
    b.set_defaults(handler=run_bench)


def _pair(name: str, values) -> tuple[float, float] | None:
    if values is None:
        return None
    if len(values) != 2 or not values[0] < values[1]:
        raise CommandError(f"{name} must be two times T0,T1 with T0 < T1 (got {values})")
    return values[0], values[1]


def _integration(fn, *args, **kw):
    from stickslip.lab.integrate import IntegrationError

    try:
        return fn(*args, **kw)
    except IntegrationError as exc:
        raise CommandError(str(exc)) from None


def _write(out: Path, stem: str, ds, data: dict, fig) -> list[str]:
    from stickslip import io
    from stickslip.plotting.style import save_figure

    written = [io.write_dataset(out / f"{stem}.nc", _netcdf_safe(ds))]
    written += save_figure(fig, out / stem)
    written.append(io.write_json(out / f"{stem}.json", data))
    return [str(p) for p in written]


def _page(args, out: Path, protocol: str, data: dict, lines: list[str], figures: list[str]) -> None:
    """The run's page, ``out/index.html``, listed last in ``data["outputs"]``."""
    from stickslip.report.lab_page import PAGE, write_lab_page

    outputs = [*data["outputs"], str(out / PAGE)]
    command = getattr(args, "command_line", f"stickslip lab {protocol}")
    write_lab_page(out, protocol, data, command=command, statements=lines, figures=figures, outputs=outputs)
    data["outputs"] = outputs


def _netcdf_safe(ds):
    """Attributes NetCDF can hold: lists of numbers stay, anything else as text."""
    ds = ds.copy()
    for key, value in list(ds.attrs.items()):
        if isinstance(value, bool) or value is None or isinstance(value, dict):
            ds.attrs[key] = str(value)
    return ds


def run_step(args) -> Result:
    """Handler of ``stickslip lab step``."""
    from stickslip.lab.protocols import velocity_step

    model = _model(args)
    model.require_k()
    own = OUT_FILES["lab step"]
    with owned_out_dir(args.out, own, "stickslip lab step", overwrite=args.overwrite) as out:
        ds, data = _integration(
            velocity_step, model, args.V, displacement=args.displacement, rtol=args.rtol, method=args.method, M=args.M
        )
        lines = _step_lines(data)
        if out is not None:
            from stickslip.plotting.lab import plot_step

            data["outputs"] = _write(out, "step", ds, data, plot_step(ds, data))
            _page(args, out, "step", data, lines, ["step"])
    lines += [f"wrote {p}" for p in data.get("outputs", [])]
    return Result(data=data, text="\n".join(lines))


def _step_lines(data: dict) -> list[str]:
    mass = f"; inertial, M = {data['M']:g}" if data.get("M") else ""
    lines = [f"velocity steps {', '.join(f'{v:g}' for v in data['velocities'])}; k_c = {data['k_c']:.6g}{mass}"]
    for st in data["steps"]:
        lines.append(
            f"V {st['V_before']:g} -> {st['V_after']:g} at t = {st['t']:g}: mu {st['mu_before']:.6f}, "
            f"peak {st['mu_peak']:.6f}, end {st['mu_end']:.6f} (mu_ss {st['mu_ss_closed_form']:.6f}); "
            f"a - b from the run {st['a_minus_b_from_run']:.5g}"
        )
    return lines


def run_shs(args) -> Result:
    """Handler of ``stickslip lab shs``."""
    from stickslip.lab.protocols import slide_hold_slide

    model = _model(args)
    model.require_k()
    own = OUT_FILES["lab shs"]
    with owned_out_dir(args.out, own, "stickslip lab shs", overwrite=args.overwrite) as out:
        ds, data = _integration(
            slide_hold_slide, model, args.V, args.holds, slide=args.slide, rtol=args.rtol, method=args.method, M=args.M
        )
        lines = _shs_lines(data)
        if out is not None:
            from stickslip.plotting.lab import plot_shs

            data["outputs"] = _write(out, "shs", ds, data, plot_shs(ds, data))
            page_lines = [lines[0], *lines[len(data["holds"]) + 2 :]]  # the holds are the page's table
            _page(args, out, "shs", data, page_lines, ["shs"])
    lines += [f"wrote {p}" for p in data.get("outputs", [])]
    return Result(data=data, text="\n".join(lines))


def _shs_lines(data: dict) -> list[str]:
    mass = f"; inertial, M = {data['M']:g}" if data.get("M") else ""
    lines = [f"slide-hold-slide at V = {data['V']:g}{mass}", "   t_hold     mu_peak    Delta mu   relaxation"]
    for r in data["holds"]:
        lines.append(f"{r['t_hold']:9.4g}  {r['mu_peak']:.6f}  {r['delta_mu']:.6f}  {r['relaxation']:.6f}")
    if data["healing_rate"] is not None:
        se = data["healing_rate_stderr"]
        lines.append(
            f"healing rate d(Delta mu)/d log10 t_hold = {data['healing_rate']:.5g}"
            + (f" +- {se:.2g}" if se is not None else "")
            + " per decade"
            + (
                f" (aging law, stiff machine, long holds: b ln 10 = {data['aging_long_hold_rate']:.5g})"
                if data["aging_long_hold_rate"]
                else ""
            )
        )
    return lines


def run_fit(args) -> Result:
    """Handler of ``stickslip lab fit``."""
    from dataclasses import replace

    from stickslip.lab.fitting import fit
    from stickslip.lab.records import Record, detrend

    model = _model(args)
    model.require_k()
    window = _pair("--window", args.window)
    trend_window = _pair("--detrend", args.detrend)
    records = []
    for path in args.data:
        if not Path(path).is_file():
            raise CommandError(f"DATA {path}: no such file")
        rec = Record.from_csv(
            path, time=args.time, friction=args.friction, displacement=args.displacement, velocity=args.velocity
        )
        if trend_window is not None:
            rec = detrend(rec, window=trend_window)
        if window is not None:
            rec = replace(rec, window=window)
        records.append(rec)
    own = OUT_FILES["lab fit"]
    with owned_out_dir(args.out, own, "stickslip lab fit", overwrite=args.overwrite) as out:
        res = fit(records, model, args.free, per_record=args.per_record, rtol=args.rtol, method=args.method)
        data = res.summary()
        post = None
        if args.posterior is not None:
            from stickslip.lab.posterior import posterior

            post = posterior(res, steps=args.posterior, rng=args.seed)
            data["posterior"] = post.summary()
        lines = _fit_lines(res, data, len(records))
        if out is not None:
            from stickslip import io
            from stickslip.plotting.lab import plot_fit, plot_posterior
            from stickslip.plotting.style import save_figure

            written = [io.write_dataset(out / "fit.nc", res.to_dataset())]
            written += save_figure(plot_fit(res), out / "fit")
            if post is not None:
                written.append(io.write_dataset(out / "posterior.nc", post.to_dataset()))
                written += save_figure(plot_posterior(post, res), out / "posterior")
            written.append(io.write_json(out / "fit.json", data))
            data["outputs"] = [str(p) for p in written]
            figures = ["fit"] if post is None else ["fit", "posterior"]
            _page(args, out, "fit", data, lines, figures)
    lines += [f"wrote {p}" for p in data.get("outputs", [])]
    return Result(data=data, text="\n".join(lines))


def _fit_lines(res, data: dict, n_records: int) -> list[str]:
    lines = [f"fit of {n_records} record(s), {res.n} samples, rms residual {res.rms:.3g}: {res.message}"]
    for name, v in data["parameters"].items():
        lines.append(f"  {name:>8} = {v['value']:.6g} +- {v['stderr']:.2g}")
    lines.append(f"CPU {res.cpu_seconds:.3g} s, {res.evaluations} model evaluations")
    if "posterior" in data:
        lines.append(f"posterior ({data['posterior']['samples']} samples): mean +- std, 95% interval")
        for name, v in data["posterior"]["parameters"].items():
            lo, hi = v["interval_95"]
            lines.append(f"  {name:>8} = {v['mean']:.6g} +- {v['std']:.2g}  [{lo:.6g}, {hi:.6g}]")
    return lines


def _cycles_csv(path: str):
    """A table of cycles from a CSV file (a header line, one row per cycle)."""
    import pandas as pd

    try:
        table = pd.read_csv(path)
    except (ValueError, OSError) as exc:
        raise CommandError(f"DATA {path}: not a table of cycles ({str(exc).splitlines()[0]})") from None
    if len(table) == 0:
        raise CommandError(f"DATA {path}: no cycles")
    return table


def run_invert(args) -> Result:
    """Handler of ``stickslip lab invert``."""
    from dataclasses import replace

    from stickslip.lab.inversion import invert_stick_slip
    from stickslip.lab.records import Record

    if args.M is None:
        raise CommandError("--M is required: the mass per unit normal stress (> 0)")
    model = replace(_model(args), form="asinh")
    model.require_k()
    window = _pair("--window", args.window)
    if not Path(args.data).is_file():
        raise CommandError(f"DATA {args.data}: no such file")
    if args.cycles:
        data = _cycles_csv(args.data)
    else:
        data = Record.from_csv(
            args.data, time=args.time, friction=args.friction, displacement=args.displacement, velocity=args.velocity
        )
    own = OUT_FILES["lab invert"]
    with owned_out_dir(args.out, own, "stickslip lab invert", overwrite=args.overwrite) as out:
        res = invert_stick_slip(
            data, model, args.M, args.free, observables_=args.observables, dt=args.dt, V=args.V, window=window,
            t_end=args.t_end, sample_interval=args.sample_interval, floor=args.floor,
        )  # fmt: skip
        data_out = res.summary()
        lines = _invert_lines(res, data_out)
        if out is not None:
            from stickslip import io
            from stickslip.plotting.lab import plot_stick_slip
            from stickslip.plotting.style import save_figure

            written = [io.write_dataset(out / "invert.nc", res.to_dataset())]
            written += save_figure(plot_stick_slip(res), out / "invert")
            written.append(io.write_json(out / "invert.json", data_out))
            data_out["outputs"] = [str(p) for p in written]
            _page(args, out, "invert", data_out, lines, ["invert"])
    lines += [f"wrote {p}" for p in data_out.get("outputs", [])]
    return Result(data=data_out, text="\n".join(lines))


def _invert_lines(res, data: dict) -> list[str]:
    lines = [f"stick-slip inversion: {len(res.cycles)} cycles, chi2 {res.chi2:.3g} ({res.dof} dof): {res.message}"]
    for name, o in data["observables"].items():
        lines.append(f"  {name:>15}: observed {o['observed']:.6g} +- {o['stderr']:.2g}, model {o['model']:.6g}")
    for name, p in data["parameters"].items():
        lines.append(f"  {name:>8} = {p['value']:.6g} +- {p['stderr']:.2g}")
    lines.append(f"CPU {res.cpu_seconds:.3g} s, {res.evaluations} model runs")
    return lines


def run_bench(args) -> Result:
    """Handler of ``stickslip lab bench``."""
    from stickslip.lab.bench import bench
    from stickslip.models.params import check_number

    data = bench(int(check_number("--repeats", args.repeats, low=1, high=100, integer=True)))
    ih = data["inertial_history"]
    text = (
        "velocity step 1 -> 10 (aging law, rtol 1e-10, 1001 outputs): "
        f"quasi-static {data['quasi_static_s'] * 1e3:.3g} ms "
        f"(arrays {data['arrays_s'] * 1e3:.3g} ms), plain-Python odeint {data['odeint_s'] * 1e3:.3g} ms: "
        f"{data['speed_ratio']:.3g}x faster ({data['speed_ratio_arrays']:.3g}x without the Dataset); "
        f"max |mu - mu_odeint| = {data['max_abs_mu_difference']:.2g}\n"
        f"four-parameter fit (a, b, Dc, mu0; 500 noisy samples): {data['fit_cpu_s']:.3g} s CPU, "
        f"{data['fit_evaluations']} model evaluations\n"
        f"inertial route (N = 1, M = 1e-3, {ih['steps']} steps, CPU time): slide-hold-slide history "
        f"{ih['history_s'] * 1e3:.3g} ms, a history at one V {ih['flat_history_s'] * 1e3:.3g} ms, constant V "
        f"{ih['constant_s'] * 1e3:.3g} ms: {ih['ratio']:.3g}x and {ih['flat_ratio']:.3g}x (medians "
        f"{ih['ratio_median']:.3g}x, {ih['flat_ratio_median']:.3g}x)"
    )
    return Result(data=data, text=text)
