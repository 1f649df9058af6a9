"""Parameter sweeps on Dask: one independent task per grid point (e.g. <L> against beta, Fig. 5b).

Each point of a sweep gets its own directory under the sweep's output directory, named from its
parameters (``beta=0.9_N=399``); the task writes its outputs there and returns a summary dict.
A finished point gets ``done.json`` (written atomically), and a later sweep over the same points
skips it, so an interrupted sweep resumes where it stopped. A point whose task raises gets
``error.json`` (message and traceback), is reported in the summary table, does not stop the
others and runs again in the next sweep. With ``stop_wait`` > 0, an interrupted sweep (SIGINT, or
SIGTERM where the command turns it into one) asks its running points to stop (:data:`STOP_FILE`)
and waits for them: a task that passes :func:`stop_requested` to the chain driver writes its
checkpoint and stops, so the point loses nothing.

The points run on ``dask.distributed``: a local cluster of worker processes (one per core, one
thread each) by default, or an existing cluster given by its scheduler address (then the output
directory must be on a file system the workers share).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import re
import sys
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from stickslip import __version__, heartbeat
from stickslip.experiments.cache import file_digests, read_done, sealed, spec_before
from stickslip.experiments.sweep_points import BLOCK_RUN_OPTIONS, chain_run_args, split_point, warn_short_chain_runs
from stickslip.io import disk_full, run_metadata, write_dataset, write_json, write_table_files
from stickslip.jsonable import to_jsonable
from stickslip.models.params import BlockParams, ChainParams
from stickslip.run.errors import Interrupted, short_runs_expected
from stickslip.run.progress import SignalFlag

__all__ = [
    "run_sweep",
    "SweepResult",
    "point_name",
    "chain_task",
    "block_task",
    "demo_task",
    "DONE_FILE",
    "POINT_FILE",
    "STOP_FILE",
    "STOP_WAIT_SECONDS",
    "run_chain_point",
    "stop_requested",
]

DONE_FILE = "done.json"
ERROR_FILE = "error.json"
POINT_FILE = "point.json"  # a point's spec, written first: marks the folder as the sweep's
SUMMARY_NAME = "summary"
# In the sweep's directory while an interrupted sweep waits for its running points to stop.
STOP_FILE = "stop-requested"
# How long an interrupted study or reproduction waits for its running points to checkpoint and
# stop (each does within about a second); a second interrupt ends the wait at once.
STOP_WAIT_SECONDS = 60.0
CHECKPOINT_INTERVAL = 120.0  # wall-clock seconds between a chain point's checkpoints

# Columns of the summary table that are not parameters or task results.
_STATUS_COLUMNS = ("point_dir", "status", "reused", "error", "wall_seconds", "note")

Task = Callable[[dict[str, Any], Path], dict[str, Any]]


# ---------------------------------------------------------------------------------------------
# Naming and bookkeeping


def _format_value(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return str(int(value)) if value.is_integer() and abs(value) < 1e15 else f"{value:.10g}"
    return str(value)


def point_name(point: dict[str, Any]) -> str:
    """Directory name of a point: ``key=value`` pairs joined by ``_``, keys in case-blind order.

    The name depends only on the point's keys and values, so the same point always lands in
    the same directory (``{"N": 399, "beta": 0.9}`` -> ``beta=0.9_N=399``). Characters that do
    not belong in a file name become ``-``.
    """
    if not point:
        return "point"
    parts = [f"{key}={_format_value(point[key])}" for key in sorted(point, key=lambda k: (k.lower(), k))]
    return re.sub(r"[^A-Za-z0-9._=+-]", "-", "_".join(parts))


def _jsonable(value: Any) -> Any:
    """A JSON round trip, so that stored and requested specs compare equal (tuples -> lists, ...)."""
    return json.loads(json.dumps(to_jsonable(value)))


def _spec(task: Task, point: dict[str, Any], common: dict[str, Any]) -> dict[str, Any]:
    """What a point's result depends on; a stored result is reused only if this matches."""
    name = f"{task.__module__}.{task.__qualname__}"
    return _jsonable({"task": name, "point": point, "common": common, "version": __version__})


def stop_requested(point_dir: str | Path) -> Callable[[], bool]:
    """Whether the sweep that runs the point in ``point_dir`` was interrupted (its
    :data:`STOP_FILE` exists): a task passes this to the chain driver
    (:func:`stickslip.run.driver.continue_or_run`), which then checkpoints and stops."""
    from stickslip.experiments.worker_signals import signalled

    flag = Path(point_dir).parent / STOP_FILE
    return lambda: flag.exists() or signalled()  # or its worker got SIGINT/SIGTERM


def _failed(spec: dict[str, Any], exc: BaseException, wall_seconds: float) -> dict[str, Any]:
    """The record of a point whose task raised or whose worker died (its error.json)."""
    return {
        "spec": spec,
        "status": "failed",
        "error": f"{type(exc).__name__}: {exc}",
        "traceback": traceback.format_exc(),
        "wall_seconds": wall_seconds,
    }


def _run_point(
    task: Task, point: dict[str, Any], common: dict[str, Any], point_dir: str, spec: dict[str, Any]
) -> dict[str, Any]:
    """Run one point on a worker: call the task, record done.json or error.json, never raise.

    A point stopped because the sweep was interrupted gets neither file: the next sweep runs it.
    """
    directory = Path(point_dir)
    if stop_requested(directory)():
        return {"spec": spec, "status": "interrupted", "error": None, "wall_seconds": 0.0}
    directory.mkdir(parents=True, exist_ok=True)
    for stale in (DONE_FILE, ERROR_FILE):
        (directory / stale).unlink(missing_ok=True)
    if spec_before(directory) != spec:
        # a checkpoint of other settings (run length, start, package version) is not continued;
        # a file of the user's in it stays
        from stickslip.run.checkpoint import remove_checkpoint

        remove_checkpoint(directory)
    write_json(directory / POINT_FILE, {"spec": spec})
    start = time.perf_counter()
    try:
        summary = dict(task({**common, **point}, directory) or {})
    except Interrupted as exc:
        return {"spec": spec, "status": "interrupted", "error": str(exc), "wall_seconds": time.perf_counter() - start}
    except Exception as exc:  # a failing point is data, not a reason to stop the sweep
        if disk_full(exc) is not None:  # but a full disk stops every point: the command says so
            raise
        record = _failed(spec, exc, time.perf_counter() - start)
        write_json(directory / ERROR_FILE, record)
        return record
    record = {
        "spec": spec,
        "status": "ok",
        "error": None,
        "wall_seconds": time.perf_counter() - start,
        "summary": _jsonable(summary),
        "files": file_digests(directory),  # a later sweep reuses the point only if these match
    }
    record = sealed(record)  # and only if the record itself is as written
    write_json(directory / DONE_FILE, record)
    return record


def _row(point: dict[str, Any], name: str, record: dict[str, Any], reused: bool, common: dict[str, Any]) -> dict:
    row: dict[str, Any] = {**common, **point}  # the fixed settings (--set, t_end) besides the grid values
    row.update(
        point_dir=name,
        status=record.get("status", "failed"),
        reused=reused,
        error=record.get("error"),
        wall_seconds=record.get("wall_seconds", math.nan),
    )
    if record.get("note"):
        row["note"] = record["note"]
    for key, value in (record.get("summary") or {}).items():
        # a result named like a parameter or a status column keeps both, prefixed
        row[f"result_{key}" if key in row else key] = value
    return row


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _table(rows: list[dict[str, Any]], points: list[dict[str, Any]]) -> pd.DataFrame:
    """The summary table: parameters, status columns, results.

    Columns mixing text and numbers (or holding lists) become JSON text, so Parquet can store them.
    """
    params = list(dict.fromkeys(key for point in points for key in point))
    table = pd.DataFrame(rows)
    leading = params + [c for c in _STATUS_COLUMNS if c in table.columns]
    table = table[leading + [c for c in table.columns if c not in leading]]
    for column in table.columns:
        kinds = {type(v) for v in table[column] if not _missing(v)}
        if table[column].dtype == object and kinds and not (kinds <= {str} or kinds <= {bool}):
            table[column] = [None if _missing(v) else v if isinstance(v, str) else json.dumps(v) for v in table[column]]
    return table


@dataclass(frozen=True)
class SweepResult:
    """Outcome of :func:`run_sweep`: the summary ``table`` (one row per point) and counts."""

    table: pd.DataFrame
    out_dir: Path
    n_points: int
    n_run: int
    n_reused: int
    n_failed: int
    wall_seconds: float
    n_damaged: int = 0  # cached points run again because their files were damaged

    def to_dict(self) -> dict[str, Any]:
        """JSON-able form (the table as a list of records)."""
        data = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "table"}
        data["points"] = _jsonable(self.table.astype(object).where(self.table.notna(), None).to_dict(orient="records"))
        return data


# ---------------------------------------------------------------------------------------------
# The driver


def run_sweep(
    task: Task,
    points: Iterable[dict[str, Any]],
    out_dir: str | Path,
    *,
    common: dict[str, Any] | None = None,
    scheduler: str | None = None,
    n_workers: int | None = None,
    progress: bool = True,
    stop_wait: float = 0.0,
    dashboard: bool = False,
    names: list[str] | None = None,
) -> SweepResult:
    """Run ``task`` at every point of a parameter grid, each point an independent Dask task
    (docs/sweeps.md).

    A point whose directory under ``out_dir`` holds a ``done.json`` for the same task, point,
    common settings and package version is not run again, unless its files are damaged
    (:mod:`stickslip.experiments.cache`: then it runs again and its row's ``note`` says why).
    Writes ``summary.parquet`` and ``summary.csv`` in ``out_dir``. The local cluster listens on
    127.0.0.1 only.

    Parameters
    ----------
    task : callable
        ``task(point: dict, point_dir: Path) -> dict``, a top-level function (:func:`chain_task`,
        :func:`block_task`, ...); it receives ``{**common, **point}`` and returns the point's summary.
    points : iterable of dict
        The varying parameters of each point.
    out_dir : str or Path
        The sweep's folder.
    common : dict, optional
        Settings shared by every point (fixed parameters, run length ``t_end``).
    scheduler : str, optional
        Address of an existing Dask scheduler; else a new local cluster of ``n_workers``
        processes (default one per core, one thread each).
    progress : bool
        A bar of points done on stderr, where stderr is a terminal.
    stop_wait : float
        Interrupted (KeyboardInterrupt), how long to wait for the running points to stop on
        request (:func:`stop_requested`; they checkpoint first) before the cluster is closed and
        the interrupt goes on; a second interrupt ends the wait.
    dashboard : bool
        Serve the local cluster's dashboard on 127.0.0.1 and print its address on stderr.
    names : list of str, optional
        The points' folder names (a study's :attr:`~stickslip.experiments.studies.Design.point_name`);
        by default :func:`point_name`.

    Returns
    -------
    SweepResult
        ``table``, one row per point with its parameters, the fixed settings of ``common``,
        ``status`` ("ok"/"failed"), ``reused``, ``error``, ``wall_seconds``, ``point_dir`` and the
        task's summary fields; and the counts ``n_points``, ``n_run``, ``n_reused``, ``n_failed``.

    Examples
    --------
    >>> import tempfile
    >>> from dask.distributed import LocalCluster
    >>> from stickslip.experiments.sweep import demo_task, run_sweep
    >>> with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
    ...     result = run_sweep(demo_task, [{"x": 1.0}, {"x": 2.0}], tempfile.mkdtemp(), common={"n": 3},
    ...                        scheduler=cluster.scheduler_address, progress=False)
    >>> result.table["value"].tolist()  # sum of k^2 x over k = 1..3
    [14.0, 28.0]
    """
    from dask.distributed import as_completed, wait
    from tqdm import tqdm

    start = time.perf_counter()
    points = [dict(p) for p in points]
    common = dict(common or {})
    out = Path(out_dir)
    names = list(names) if names is not None else [point_name(p) for p in points]
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise ValueError(f"points repeat: {', '.join(duplicates)}")
    if n_workers is not None and n_workers < 1:
        raise ValueError(f"n_workers must be >= 1 (got {n_workers})")
    out.mkdir(parents=True, exist_ok=True)

    if task is chain_task:
        warn_short_chain_runs(points, common, names)
    specs = [_spec(task, p, common) for p in points]
    found = [read_done(out / n / DONE_FILE, s) for n, s in zip(names, specs, strict=False)]
    records: list[dict[str, Any] | None] = [r for r, _ in found]
    damaged = {k: why for k, (_, why) in enumerate(found) if why}
    reused = [r is not None for r in records]
    pending = [k for k, r in enumerate(records) if r is None]

    if pending:
        stop_file = out / STOP_FILE
        stop_file.unlink(missing_ok=True)  # left by a sweep that was killed while it waited
        client, cluster = _client(scheduler, n_workers or os.cpu_count() or 1, len(pending), dashboard)
        done = len(points) - len(pending)
        bar = tqdm(
            total=len(points),
            initial=done,
            desc="points",
            unit=" points",
            file=sys.stderr,
            dynamic_ncols=True,
            smoothing=0.1,
            disable=not (progress and _on_terminal()),  # a bar would garble a log file
        )
        heartbeat.note(f"{done} of {len(points)} points done in {out.parent.name}/{out.name}")
        futures = {}
        try:
            for k in pending:
                point_dir, key = str(out / names[k]), f"sweep-{names[k]}-{os.getpid()}-{time.time_ns()}"
                future = client.submit(_run_point, task, points[k], common, point_dir, specs[k], key=key, pure=False)
                futures[future] = k
            for future in as_completed(futures):
                k = futures[future]
                try:
                    records[k] = future.result()
                except Exception as exc:  # the worker itself died (memory, signal): record it here
                    if disk_full(exc) is not None:
                        raise
                    records[k] = _failed(specs[k], exc, math.nan)
                    write_json(out / names[k] / ERROR_FILE, records[k])
                done += 1
                heartbeat.note(f"{done} of {len(points)} points done in {out.parent.name}/{out.name}")
                bar.update(1)
                if records[k]["status"] != "ok" and not bar.disable:
                    bar.write(f"point {names[k]} failed: {records[k]['error']}", file=sys.stderr)
        except KeyboardInterrupt:
            if stop_wait > 0:  # the running points checkpoint and stop; those not yet started return at once
                stop_file.touch()
                try:
                    wait(list(futures), timeout=stop_wait)
                except (Exception, KeyboardInterrupt):  # a point that does not stop, a lost worker, a second interrupt
                    pass
            raise
        finally:
            # a second Ctrl-C while the cluster closes is raised after it: the closing is not cut short
            with SignalFlag(True) as second:
                bar.close()
                client.close()
                if cluster is not None:
                    cluster.close()
                stop_file.unlink(missing_ok=True)
            if second.set:
                raise KeyboardInterrupt

    for k, why in damaged.items():  # the table says why a cached point ran again
        records[k] = {**(records[k] or {"status": "failed"}), "note": f"cached result damaged ({why}): run again"}
    rows = [_row(p, n, r, u, common) for p, n, r, u in zip(points, names, records, reused, strict=False)]  # type: ignore[arg-type]
    table = _table(rows, points + [common])
    write_table_files(out / SUMMARY_NAME, table)
    return SweepResult(
        table=table,
        out_dir=out,
        n_points=len(points),
        n_run=len(pending),
        n_reused=sum(reused),
        n_failed=int((table["status"] != "ok").sum()) if len(table) else 0,
        wall_seconds=time.perf_counter() - start,
        n_damaged=len(damaged),
    )


def _client(scheduler: str | None, n_workers: int, n_pending: int, dashboard: bool):
    """A client of the cluster at ``scheduler``, else of a new local cluster (also returned, to be closed)."""
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        return Client(scheduler), None
    from stickslip.experiments.worker_signals import StopOnSignal

    cluster = LocalCluster(
        n_workers=min(n_workers, n_pending),
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",  # scheduler and workers: nothing listens beyond this machine
        # its web server on any free port (never clash with another cluster), on the loopback;
        # the dashboard's pages only when asked
        dashboard_address="127.0.0.1:0",
        scheduler_kwargs={"dashboard": dashboard},
        silence_logs=logging.CRITICAL,  # failures are in error.json; keep worker heartbeats off a Ctrl-C
    )
    client = Client(cluster)
    client.register_plugin(StopOnSignal())  # a signal to the process group stops the points cleanly
    if dashboard:
        sys.stderr.write(f"dashboard: {cluster.dashboard_link}\n")
        sys.stderr.flush()
    return client, cluster


def _on_terminal() -> bool:
    """Whether stderr is a terminal: progress bars would garble a log file."""
    return sys.stderr.isatty()


# ---------------------------------------------------------------------------------------------
# Tasks


def run_chain_point(params: ChainParams, t_end: float, point_dir: str | Path, **options: Any):
    """The chain run (eq. 4 or a relative) of one sweep point, in ``point_dir``: continued from
    its checkpoint when there is one, checkpointed every :data:`CHECKPOINT_INTERVAL` seconds, and
    stopped after a checkpoint when the sweep is interrupted (:func:`stop_requested`). ``options``
    go to :func:`stickslip.run.driver.run_chain`. The chain points of sweeps, studies and the
    reproduction all run so."""
    from stickslip.run import driver  # imported here: workers load the simulator only when needed

    return driver.continue_or_run(
        params,
        t_end,
        point_dir,
        checkpoint_interval=CHECKPOINT_INTERVAL,
        stop_requested=stop_requested(point_dir),
        **options,
    )


def chain_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """Run the chain of eq. (4), or a relative, at one sweep point.

    Parameters
    ----------
    point : dict
        :class:`~stickslip.models.params.ChainParams` fields (``model``: a preset, default the
        paper's chain), ``t_end`` and optionally the run options of
        :data:`~stickslip.experiments.sweep_points.CHAIN_RUN_OPTIONS`; without ``start``, the model's own.
    point_dir : Path
        Where the run writes run.json, state.nc and the tables, and its checkpoint while it runs
        (an interrupted point goes on from there).

    Returns
    -------
    dict
        The run's summary (``n_events``, ``L_mean``, ``L_steady``, ``state_sha256``, ...).
    """
    params, t_end, options = chain_run_args(point)
    with short_runs_expected():  # said once, by run_sweep, before the points run
        run = run_chain_point(params, t_end, point_dir, **options)  # writes run.json, as every run with a directory
    return dict(run.summary)


def block_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """Run the single block of eq. (1) at one point and return its summary.

    ``point`` holds :class:`~stickslip.models.params.BlockParams` fields, ``t_end`` and optionally
    ``every`` (the sampling stride). Writes ``series.nc`` (x, v, theta, f over t),
    ``slips.parquet`` (one row per slip) and ``run.json`` (parameters, versions, summary).
    """
    from stickslip.run import block  # imported here: workers load the simulator only when needed

    params, options = split_point(point, BlockParams, BLOCK_RUN_OPTIONS)
    t_end = options.pop("t_end")
    run = block.simulate_block(params, t_end, **options)
    summary = dict(run.summary())
    directory = Path(point_dir)
    write_dataset(directory / "series.nc", run.series)
    write_table_files(directory / "slips", run.slips)
    write_json(directory / "run.json", run_metadata(params, integrator="heun", t_end=t_end, summary=summary, **options))
    return summary


def demo_task(point: dict[str, Any], point_dir: Path) -> dict[str, Any]:
    """A cheap stand-in task with a checkable result, for tests and for trying a cluster.

    Returns ``value`` = sum_{k=1}^{n} k^2 * x (n = ``n``, default 10; x = ``x``, default 1)
    and the worker's process id; sleeps ``sleep`` seconds first; raises ``ValueError`` when
    ``fail`` is true; ends its worker process abruptly when ``crash`` is true (as a worker killed
    for memory would). Writes ``value.txt`` into its directory.
    """
    time.sleep(float(point.get("sleep", 0.0)))
    if point.get("crash", False):
        os._exit(3)
    if point.get("fail", False):
        raise ValueError(f"demo point asked to fail (x={point.get('x')})")
    n = int(point.get("n", 10))
    value = float(sum(k * k for k in range(1, n + 1)) * float(point.get("x", 1.0)))
    (Path(point_dir) / "value.txt").write_text(f"{value!r}\n")
    return {"value": value, "pid": os.getpid()}
