"""Integrity of a sweep's finished points: the files of a point and their SHA-256 checksums.

When a point finishes, its ``done.json`` records the checksum of every file in its folder
(:func:`file_digests`); a later sweep (or study) reuses the point only if its summary is there
and every recorded file is present with the same checksum (:func:`damage`). Otherwise the point
runs again, and the table and the study's page say why.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from stickslip.io import read_json

#: Files of a point's folder that are not part of its result (the sweep's own bookkeeping).
BOOKKEEPING = frozenset({"done.json", "error.json", "point.json"})


def read_done(point_dir: Path, spec: dict[str, Any]) -> tuple[dict[str, Any] | None, str | None]:
    """The stored record of a finished point with this spec, or None; and why a record of this
    spec is not reused (its files damaged, :func:`stickslip.experiments.point_cache.damage`)."""
    path = point_dir / "done.json"
    if not path.is_file():
        return None, None
    try:
        record = read_json(path)
    except (OSError, ValueError):
        return None, "done.json is unreadable"
    if not isinstance(record, dict) or record.get("spec") != spec:
        return None, None
    reason = damage(point_dir, record)
    return (None, reason) if reason else (record, None)


def spec_before(point_dir: Path) -> dict[str, Any] | None:
    """The spec in the point's point.json (that of the sweep that last ran it), or None."""
    try:
        record = read_json(point_dir / "point.json")
    except (OSError, ValueError):
        return None
    return record.get("spec") if isinstance(record, dict) else None


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def file_digests(point_dir: str | Path) -> dict[str, str]:
    """SHA-256 of every file under ``point_dir`` (relative paths with ``/``), the sweep's
    bookkeeping and files of killed writes left out."""
    from stickslip.run.rundir import LOCK_FILES, is_temporary

    root = Path(point_dir)
    digests = {}
    for path in sorted(root.rglob("*")):
        rel = path.relative_to(root).as_posix()
        if not path.is_file() or rel in BOOKKEEPING or path.name in LOCK_FILES or is_temporary(path.name):
            continue
        digests[rel] = _sha256(path)
    return digests


def damage(point_dir: str | Path, record: dict[str, Any]) -> str | None:
    """Why the finished point in ``point_dir`` (its done.json ``record``) cannot be reused, or None
    when its summary is there and every file it recorded is present with its checksum."""
    summary, files = record.get("summary"), record.get("files")
    if not isinstance(summary, dict):
        return "its summary is missing"
    if not isinstance(files, dict):
        return "it records no checksums of its files"
    root = Path(point_dir)
    for rel, digest in sorted(files.items()):
        path = root / rel
        if not path.is_file():
            return f"{rel} is missing"
        try:
            if _sha256(path) != digest:
                return f"{rel} does not match its checksum"
        except OSError as exc:
            return f"{rel} cannot be read ({exc.strerror})"
    return None
