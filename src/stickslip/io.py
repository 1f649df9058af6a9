"""Writing and reading results: JSON metadata, labelled arrays (NetCDF/HDF5), event tables (Parquet).

Every write is atomic (written to a temporary file in the same directory, then renamed), so an
interrupted run, or one that meets a full disk, never leaves a half-written file under the final
name. NetCDF files are built in memory and written as plain bytes, so that no HDF5 library state
is left to flush onto a full disk at close or in a finalizer. A full disk surfaces as
:class:`OSError` with errno ``ENOSPC`` naming the file (:func:`disk_full`).
"""

from __future__ import annotations

import errno
import json
import os
import platform
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from stickslip import __version__
from stickslip.jsonable import to_jsonable

if TYPE_CHECKING:  # loaded where a table or dataset is read, so that `stickslip --help` loads neither
    import pandas as pd
    import xarray as xr


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    # mkstemp makes the file private (0600); results are meant to be shared.
    os.chmod(tmp_path, 0o644)
    try:
        yield tmp_path
        os.replace(tmp_path, path)
    except OSError as exc:
        if disk_full(exc) is not None and not exc.filename:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path)) from exc
        raise
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


#: errno values that mean the disk (or the user's quota) is full.
FULL_DISK_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT})


def disk_full(exc: BaseException) -> OSError | None:
    """The OSError meaning "no space left" in ``exc`` or in the exceptions it was raised from
    (HDF5, PIL and Dask wrap it), or None."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and (
            exc.errno in FULL_DISK_ERRNOS or "No space left on device" in str(exc) or "Disk quota exceeded" in str(exc)
        ):
            return exc
        exc = exc.__cause__ or exc.__context__
    return None


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically, flushed to the disk before the rename."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return Path(path)


def write_json(path: str | Path, data: Any) -> Path:
    """Write one JSON document atomically (NaN and inf become null)."""
    return write_bytes(path, (json.dumps(to_jsonable(data), indent=2, allow_nan=False) + "\n").encode())


def read_json(path: str | Path) -> Any:
    return json.loads(Path(path).read_text())


def write_dataset(path: str | Path, ds: xr.Dataset) -> Path:
    """Write labelled arrays to NetCDF4/HDF5 (h5netcdf engine), atomically: the file is built in
    memory, so HDF5 never writes to the disk itself (a full disk is then a plain OSError)."""
    import dask

    # On a Dask worker xarray would take a cluster-wide lock named after the in-memory target,
    # which the cluster does not know; the data are in memory, so no lock is needed.
    with dask.config.set(scheduler="synchronous"):
        data = bytes(ds.to_netcdf(engine="h5netcdf"))
    return write_bytes(path, data)


def read_dataset(path: str | Path) -> xr.Dataset:
    """Read a dataset written by :func:`write_dataset` fully into memory."""
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as ds:
        return ds.load()


def write_table(
    path: str | Path,
    table: pd.DataFrame,
    descriptions: dict[str, str] | None = None,
    metadata: dict[str, Any] | None = None,
) -> Path:
    """Write a table (events, sweep summaries) to Parquet, atomically.

    ``descriptions`` (column -> text) go into the Parquet schema as each field's metadata
    (key ``description``), readable with ``pyarrow.parquet.read_schema(path).field(name).metadata``;
    ``metadata`` (JSON-able) goes into the schema's own metadata under key ``stickslip``.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrow = pa.Table.from_pandas(table, preserve_index=False)
    if descriptions:
        fields = [
            f.with_metadata({**(f.metadata or {}), b"description": descriptions[f.name].encode()})
            if f.name in descriptions
            else f
            for f in arrow.schema
        ]
        arrow = arrow.cast(pa.schema(fields, metadata=arrow.schema.metadata))
    if metadata:
        arrow = arrow.replace_schema_metadata(
            {**(arrow.schema.metadata or {}), b"stickslip": json.dumps(to_jsonable(metadata)).encode()}
        )
    sink = pa.BufferOutputStream()
    pq.write_table(arrow, sink)
    return write_bytes(path, sink.getvalue().to_pybytes())


def write_csv(path: str | Path, table: pd.DataFrame) -> Path:
    """Write a table as CSV (no index), atomically."""
    return write_bytes(path, table.to_csv(index=False).encode())


def write_table_files(
    stem: str | Path,
    table: pd.DataFrame,
    descriptions: dict[str, str] | None = None,
    metadata: dict[str, Any] | None = None,
) -> list[Path]:
    """Write a table the way every command writes one: STEM.parquet (typed, its columns described,
    :func:`write_table`) and STEM.csv (for any tool); returns both paths."""
    stem = Path(stem)
    return [
        write_table(stem.with_suffix(".parquet"), table, descriptions, metadata),
        write_csv(stem.with_suffix(".csv"), table),
    ]


def read_table(path: str | Path) -> pd.DataFrame:
    import pandas as pd

    return pd.read_parquet(path, engine="pyarrow")


def run_metadata(params: Any, *, integrator: str, **extra: Any) -> dict[str, Any]:
    """The record written next to every run's outputs: parameters, integrator, versions."""
    import numba
    import numpy

    meta = {
        "package": "stickslip",
        "version": __version__,
        "integrator": integrator,
        "params": params.to_dict() if hasattr(params, "to_dict") else dict(params),
        "params_type": type(params).__name__,
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "numba": numba.__version__,
    }
    meta.update(extra)
    return meta
