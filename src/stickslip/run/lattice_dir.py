"""Lattice run directories (docs/lattice.md, "Outputs"): what ``stickslip chain --lattice square
--out DIR`` and :meth:`stickslip.run.lattice.LatticeRun.write` leave, read back as a
:class:`~stickslip.run.lattice.LatticeRun` for ``stickslip catalog`` and ``stickslip plot``."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from stickslip.models.params import ChainParams, ParameterError

__all__ = ["is_lattice_run_dir", "lattice_params_from_dict", "load_lattice_run"]

#: The keys of a lattice run's parameters that are the lattice's, not the model's.
_LATTICE_KEYS = ("lattice", "shape", "edges")


def is_lattice_run_dir(run_dir: str | Path) -> bool:
    """Whether ``run_dir`` holds a lattice run: a run.json whose parameters name a lattice
    other than the chain, and events.csv."""
    from stickslip import io

    run_dir = Path(run_dir)
    if not (run_dir / "run.json").is_file() or not (run_dir / "events.csv").is_file():
        return False
    try:
        params = io.read_json(run_dir / "run.json").get("params", {})
    except (ValueError, OSError, AttributeError):
        return False
    return isinstance(params, dict) and params.get("lattice") not in (None, "chain")


def lattice_params_from_dict(d: dict):
    """The :class:`~stickslip.models.lattice.params.LatticeParams` of
    :meth:`~stickslip.models.lattice.params.LatticeParams.to_dict` (the model's parameters with
    the lattice's name, shape and edges)."""
    from stickslip.models.lattice.params import on_lattice

    model = {k: v for k, v in d.items() if k not in _LATTICE_KEYS}
    edges = d.get("edges")
    edges = ",".join(f"{side}={kind}" for side, kind in edges.items()) if isinstance(edges, dict) else edges
    return on_lattice(ChainParams(**model), d["lattice"], d["shape"], edges)


def load_lattice_run(run_dir: str | Path):
    """The lattice run of a run directory.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``stickslip chain --lattice square ... --out DIR``.

    Returns
    -------
    LatticeRun
        Its parameters, events, final state (at the run's last step), snapshots, samples and
        recorded event fields where the run kept them.

    Raises
    ------
    ParameterError
        In one line, where the folder holds no lattice run.
    """
    from stickslip import io
    from stickslip.kernels import layout
    from stickslip.run.lattice import LatticeRun, LatticeState

    run_dir = Path(run_dir)
    if not is_lattice_run_dir(run_dir) or not (run_dir / "state.nc").is_file():
        raise ParameterError(
            f"{run_dir} is not a lattice run directory (run.json naming a lattice, events.csv, state.nc; "
            "write one with stickslip chain --lattice square --shape RxC --out DIR)"
        )
    meta = io.read_json(run_dir / "run.json")
    p = lattice_params_from_dict(meta["params"])
    events = pd.read_csv(run_dir / "events.csv")
    ds = io.read_dataset(run_dir / "state.nc")
    state = LatticeState.from_blocks(
        p.lattice, ds["x"].values, ds["v"].values, ds["theta"].values, ds["stopped"].values.astype(bool)
    )
    state.ist[layout.STEP] = int(meta["summary"].get("steps", 0))
    snaps = [k for k in ds.data_vars if k.startswith("snapshot_")]
    snapshots = ds[snaps].rename({k: k.removeprefix("snapshot_") for k in snaps}) if snaps else None
    samples = pd.read_csv(run_dir / "samples.csv") if (run_dir / "samples.csv").is_file() else None
    fields = io.read_dataset(run_dir / "event_fields.nc") if (run_dir / "event_fields.nc").is_file() else None
    return LatticeRun(p, events, state, snapshots, dict(meta["summary"]), samples, fields)
