"""How an experiment is described and cached, for ``reproduce``, sweeps and studies alike.

An experiment (a :class:`~stickslip.experiments.studies.Study`, or one point of a sweep) is a
*spec*: a plain JSON document of everything its result depends on, the package version included,
in one form (:func:`canonical`) and named by :func:`spec_key`. A stored result (``done.json`` of
a sweep's point, ``rung.json`` of a ladder's rung) is reused only if it was made from the same
spec, carries its own checksum (:func:`sealed`) and every file it wrote still matches the
checksum it recorded (:func:`read_done`); otherwise it is computed again and the table and the
study's page say why.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from stickslip.io import read_json
from stickslip.jsonable import to_jsonable

__all__ = ["canonical", "spec_key", "read_done", "spec_before", "file_digests", "damage", "sealed", "file_sha256"]

#: The separators of :func:`spec_key`'s JSON text: compact, as ``reproduce`` and the studies use.
COMPACT = (",", ":")


def canonical(value: Any) -> Any:
    """A JSON round trip with sorted keys: tuples become lists, whole floats become ints.

    So ``K = 10`` and ``K = 10.0``, or ``(0.5, 1.0)`` and ``[0.5, 1]``, give the same spec.
    """

    def whole(v: Any) -> Any:
        if isinstance(v, dict):
            return {k: whole(x) for k, x in v.items()}
        if isinstance(v, list):
            return [whole(x) for x in v]
        if isinstance(v, float) and v.is_integer() and abs(v) < 2**53:
            return int(v)
        return v

    return whole(json.loads(json.dumps(to_jsonable(value), sort_keys=True)))


def spec_key(spec: dict[str, Any]) -> str:
    """First 12 hex digits of the SHA-256 of ``spec`` as compact JSON with sorted keys."""
    return hashlib.sha256(json.dumps(spec, sort_keys=True, separators=COMPACT).encode()).hexdigest()[:12]


#: Files of a point's folder that are not part of its result (the sweep's own bookkeeping).
BOOKKEEPING = frozenset({"done.json", "error.json", "point.json"})


def read_done(
    path: str | Path, spec: dict[str, Any], field: str = "summary"
) -> tuple[dict[str, Any] | None, str | None]:
    """The sealed record at ``path`` (a point's done.json, a rung's rung.json, a part of a point)
    made from ``spec``, with its ``field``, itself as written and its files whole, or None; and why
    a record of this spec is not reused (:func:`damage`; None when there is none)."""
    path = Path(path)
    if not path.is_file():
        return None, None
    try:
        record = read_json(path)
    except (OSError, ValueError):
        return None, f"{path.name} is unreadable"
    if not isinstance(record, dict) or record.get("spec") != spec:
        return None, None
    reason = damage(path.parent, record, field)
    return (None, reason) if reason else (record, None)


def spec_before(point_dir: Path) -> dict[str, Any] | None:
    """The spec in the point's point.json (that of the sweep that last ran it), or None."""
    try:
        record = read_json(point_dir / "point.json")
    except (OSError, ValueError):
        return None
    return record.get("spec") if isinstance(record, dict) else None


def file_sha256(path: Path) -> str:
    """SHA-256 of the file at ``path``."""
    with open(path, "rb") as fh:
        return hashlib.file_digest(fh, "sha256").hexdigest()


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
        digests[rel] = file_sha256(path)
    return digests


def record_digest(record: dict[str, Any]) -> str:
    """SHA-256 of a record's :func:`canonical` JSON text, its own ``sha256`` field left out: what
    :func:`sealed` stores and :func:`damage` compares, so an edited record is not reused."""
    body = {k: v for k, v in record.items() if k != "sha256"}
    return hashlib.sha256(json.dumps(canonical(body), sort_keys=True, separators=COMPACT).encode()).hexdigest()


def sealed(record: dict[str, Any]) -> dict[str, Any]:
    """``record`` with its :func:`record_digest` under ``sha256`` (done.json, rung.json)."""
    return {**record, "sha256": record_digest(record)}


def damage(point_dir: str | Path, record: dict[str, Any], field: str = "summary") -> str | None:
    """Why the finished point in ``point_dir`` (its done.json ``record``) cannot be reused, or None
    when its ``field`` is there, the record is as written (:func:`sealed`) and every file it
    recorded is present with its checksum."""
    result, files = record.get(field), record.get("files")
    if not isinstance(result, dict):
        return f"its {field} is missing"
    if not isinstance(files, dict):
        return "it records no checksums of its files"
    if not isinstance(record.get("sha256"), str):
        return "it records no checksum of itself"
    if record["sha256"] != record_digest(record):
        return "its record was changed after it was written (checksum)"
    for rel, digest in sorted(files.items()):
        path = Path(point_dir) / rel
        if not path.is_file():
            return f"{rel} is missing"
        try:
            if file_sha256(path) != digest:
                return f"{rel} does not match its checksum"
        except OSError as exc:
            return f"{rel} cannot be read ({exc.strerror})"
    return None
