"""Checkpoints of a chain run (eq. 4): checksummed npz files and :class:`Checkpointer`.

A checkpoint is the state file ``checkpoint/state.npz`` plus append-only part files of the
outputs; every file is written atomically with a SHA-256 over its arrays and header.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from stickslip import __version__
from stickslip.kernels import layout
from stickslip.run.errors import ChainRunError
from stickslip.run.outputs import PART_KEYS, _Outputs
from stickslip.run.state import ChainState

# Bump whenever the layout of the state arrays (kernels.layout.IST_SIZE included) changes.
CHECKPOINT_FORMAT = 2


def _checksum(arrays: dict[str, np.ndarray], header: dict[str, Any]) -> str:
    h = hashlib.sha256(json.dumps(header, sort_keys=True).encode())
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def write_npz(path: Path, arrays: dict[str, np.ndarray], header: dict[str, Any]) -> str:
    """Write arrays + a JSON header + their checksum to ``path`` atomically; returns the checksum."""
    from stickslip.io import atomic_path

    digest = _checksum(arrays, header)
    payload = dict(arrays)
    payload["__header__"] = np.frombuffer(json.dumps(header, sort_keys=True).encode(), dtype=np.uint8)
    payload["__checksum__"] = np.frombuffer(digest.encode(), dtype=np.uint8)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **payload)
            fh.flush()
            os.fsync(fh.fileno())
    return digest


def read_npz(path: Path) -> tuple[dict[str, np.ndarray], dict[str, Any], str]:
    """Read and verify a file written by :func:`write_npz`; raises ChainRunError if corrupt."""
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
        header = json.loads(arrays.pop("__header__").tobytes().decode())
        stored = arrays.pop("__checksum__").tobytes().decode()
    except Exception as exc:  # any damage to the file: refuse it
        raise ChainRunError(f"checkpoint file {path} is unreadable or corrupt ({type(exc).__name__})") from None
    if _checksum(arrays, header) != stored:
        raise ChainRunError(f"checkpoint file {path} is corrupt (checksum mismatch)")
    return arrays, header, stored


def write_state_npz(
    path: Path, state: ChainState, header: dict[str, Any], arrays: dict[str, np.ndarray] | None = None
) -> None:
    """A chain state kept with what it was made from (``header["spec"]``) and further ``arrays``
    (a loaded state, a rung's progress), by :func:`write_npz`."""
    write_npz(path, state.arrays() | dict(arrays or {}), header)


def read_state_npz(
    path: Path, spec: dict[str, Any], params
) -> tuple[ChainState, dict[str, Any], dict[str, np.ndarray]] | None:
    """The state, header and further arrays that :func:`write_state_npz` kept at ``path``, if the
    file is intact, was made from ``spec`` and holds a state of the chain ``params``' size; else
    None (the caller computes it again)."""
    from stickslip.run.state import model_of

    if not path.is_file():
        return None
    try:
        arrays, header, _ = read_npz(path)
    except ChainRunError:
        return None
    if header.get("spec") != spec:
        return None
    shapes = {k: (params.N + 2,) for k in ChainState.ARRAYS if k != "ist"} | {"ist": (layout.IST_SIZE,)}
    if any(k not in arrays or arrays[k].shape != s for k, s in shapes.items()):
        return None
    state = ChainState.from_arrays(arrays, model=model_of(params))
    for k in ChainState.ARRAYS:
        arrays.pop(k)
    return state, header, arrays


def _check_layout(arrays: dict[str, np.ndarray], header: dict[str, Any]) -> None:
    """Refuse state arrays that do not fit the header's N or this version's layout."""
    try:
        N = int(header["params"]["N"])
    except (KeyError, TypeError, ValueError):
        raise ChainRunError("checkpoint header has no valid N") from None
    expected = {
        "x": (np.float64, (N + 2,)),
        "v": (np.float64, (N + 2,)),
        "th": (np.float64, (N + 2,)),
        "mov": (np.float64, (N + 2,)),
        "x0ev": (np.float64, (N + 2,)),
        "first_step": (np.int64, (N + 2,)),
        "ist": (np.int64, (layout.IST_SIZE,)),
    }
    for name, (dtype, shape) in expected.items():
        a = arrays[name]
        if a.dtype != dtype or a.shape != shape:
            raise ChainRunError(
                f"checkpoint array {name} has shape {a.shape} and type {a.dtype}, "
                f"expected {shape} and {np.dtype(dtype)} for N = {N}"
            )


#: The files of a checkpoint folder: its state file and its parts (and files of a killed write).
CHECKPOINT_FILE = re.compile(r"state\.npz|part-\d{6}\.npz|\..+\.tmp")


def remove_checkpoint(run_dir: str | Path) -> list[str]:
    """Remove the checkpoint of ``run_dir``: its state file first (a kill part way leaves no
    checkpoint that lists missing parts), then its parts, then the folder if that leaves it
    empty. A file that is not a checkpoint's (:data:`CHECKPOINT_FILE`) is never removed; returns
    the names of those left."""
    path = Path(run_dir) / "checkpoint"
    if not path.is_dir():
        return []
    (path / "state.npz").unlink(missing_ok=True)
    kept = []
    for entry in sorted(path.iterdir()):
        if entry.is_file() and CHECKPOINT_FILE.fullmatch(entry.name):
            entry.unlink(missing_ok=True)
        else:
            kept.append(entry.name)
    if not kept:
        path.rmdir()
    return kept


class Checkpointer:
    """Checkpoints of one run directory: ``checkpoint/state.npz`` plus append-only output parts.

    Each checkpoint first writes the outputs produced since the last one as a new part file,
    then atomically replaces the state file, which lists the parts (with their checksums)
    that belong to it. A kill at any moment leaves the previous checkpoint intact; parts not
    listed by the state file are ignored and removed on resume.
    """

    def __init__(self, run_dir: Path):
        self.dir = Path(run_dir) / "checkpoint"
        self.parts: list[dict[str, str]] = []
        self.since: dict[str, int] = {}

    @property
    def state_path(self) -> Path:
        return self.dir / "state.npz"

    def write(self, state: ChainState, outputs: _Outputs, header: dict[str, Any]) -> Path:
        self.dir.mkdir(parents=True, exist_ok=True)
        new = outputs.take_new(self.since)
        name = f"part-{len(self.parts):06d}.npz"
        digest = write_npz(self.dir / name, new, {"format": CHECKPOINT_FORMAT})
        self.parts.append({"file": name, "sha256": digest})
        arrays = state.arrays()
        full_header = dict(
            header, format=CHECKPOINT_FORMAT, parts=self.parts, version=__version__, ist_size=layout.IST_SIZE
        )
        write_npz(self.state_path, arrays, full_header)
        return self.state_path

    def load(self) -> tuple[ChainState, dict[str, Any], dict[str, list[np.ndarray]]]:
        if not self.state_path.exists():
            raise ChainRunError(f"no checkpoint in {self.dir.parent} (missing {self.state_path.name})")
        arrays, header, _ = read_npz(self.state_path)
        if header.get("format") != CHECKPOINT_FORMAT:
            raise ChainRunError(
                f"checkpoint format {header.get('format')} is not supported (this version reads {CHECKPOINT_FORMAT})"
            )
        missing = [k for k in ChainState.ARRAYS if k not in arrays]
        if missing:
            raise ChainRunError(f"checkpoint is missing arrays {missing}")
        _check_layout(arrays, header)
        state = ChainState.from_arrays(arrays)
        parts: dict[str, list[np.ndarray]] = {k: [] for k in PART_KEYS}
        listed = header.get("parts", [])
        if not isinstance(listed, list) or not all(
            isinstance(e, dict)
            and isinstance(e.get("sha256"), str)
            and re.fullmatch(r"part-\d{6}\.npz", str(e.get("file")))
            for e in listed
        ):
            raise ChainRunError(f"checkpoint in {self.dir.parent} lists its parts wrongly")
        for entry in listed:
            part_arrays, _, digest = read_npz(self.dir / entry["file"])
            if digest != entry["sha256"]:
                raise ChainRunError(f"checkpoint part {entry['file']} does not match the state file")
            for key in PART_KEYS:
                if key in part_arrays and part_arrays[key].shape[0]:
                    parts[key].append(part_arrays[key])
        keep = {entry["file"] for entry in listed}
        for stray in self.dir.glob("part-*.npz"):
            if stray.name not in keep:
                stray.unlink()
        for tmp in self.dir.glob(".*.tmp"):  # left by a write that was killed
            tmp.unlink()
        self.parts = list(listed)
        return state, header, parts
