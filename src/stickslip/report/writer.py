"""The reproduction report: ``report.json`` and a self-contained ``report.html``.

The report holds the figures of a reproduction run (each panel's image, with links to its
PDF and data) and a table with one row per number the paper states (docs/model.md, last table):
where the paper states it, the quantity, the paper's value, this run's value, whether they
agree within the stated tolerance, and the command that reproduces the row. A row whose
number is not settled at the run's length (a quick run) says so ("n/a (...)") rather than
claiming agreement or disagreement.
"""

from __future__ import annotations

import datetime as _dt
import math
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

from stickslip import __version__
from stickslip.io import read_json, write_json
from stickslip.jsonable import to_jsonable
from stickslip.pages import image_src, write_page

__all__ = ["ReportRow", "ReportFigure", "Report", "write_report", "read_report", "agreement_text"]


@dataclass(frozen=True)
class ReportRow:
    """One number the paper states (docs/model.md, last table) and how this run compares.

    - ``where``: the place in the paper ("sec. 2", "eq. 3", "Fig. 6");
    - ``quantity``: what is measured ("rupture front speed in large events, beta = 1");
    - ``paper``: the paper's value as printed ("c = 1.43"); ``value``: this run's value
      (text or a number; None when not computed);
    - ``agrees``: True / False, or None when the comparison is not settled at this run length;
    - ``tolerance``: the tolerance used (``"|c - 1.43| <= 0.15"``); ``na_reason``: why ``agrees`` is
      None ("quick run"); ``command``: the shell command that reproduces the row;
    - ``note``: anything a reader needs to judge the row (e.g. a slip of the paper).
    """

    where: str
    quantity: str
    paper: str
    value: str | float | int | None
    agrees: bool | None
    tolerance: str
    command: str
    na_reason: str = ""
    note: str = ""

    @property
    def agreement(self) -> str:
        """``yes (tolerance)``, ``no (tolerance)`` or ``n/a (reason)``."""
        return agreement_text(self.agrees, self.tolerance, self.na_reason)

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["agreement"] = self.agreement
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ReportRow:
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in names})


@dataclass(frozen=True)
class ReportFigure:
    """One figure panel: its PNG (path relative to the report), caption, PDF and data files."""

    figure: str
    image: str
    caption: str
    pdf: str | None = None
    data: tuple[str, ...] = ()
    command: str = ""

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["data"] = list(self.data)
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ReportFigure:
        names = {f.name for f in fields(cls)}
        values = {k: v for k, v in data.items() if k in names}
        values["data"] = tuple(values.get("data") or ())
        return cls(**values)


@dataclass(frozen=True)
class Report:
    """What ``report.json`` holds: ``meta`` (version, mode, times, ...), ``rows``, ``figures``."""

    meta: dict[str, Any]
    rows: tuple[ReportRow, ...]
    figures: tuple[ReportFigure, ...] = field(default_factory=tuple)

    def to_dict(self) -> dict[str, Any]:
        return {
            "meta": self.meta,
            "rows": [r.to_dict() for r in self.rows],
            "figures": [f.to_dict() for f in self.figures],
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Report:
        return cls(
            meta=dict(data.get("meta") or {}),
            rows=tuple(ReportRow.from_dict(r) for r in data.get("rows") or ()),
            figures=tuple(ReportFigure.from_dict(f) for f in data.get("figures") or ()),
        )


def agreement_text(agrees: bool | None, tolerance: str, na_reason: str = "") -> str:
    """The agreement column: ``yes (tol)``, ``no (tol)`` or ``n/a (reason)``."""
    if agrees is None:
        return f"n/a ({na_reason})" if na_reason else "n/a"
    word = "yes" if agrees else "no"
    return f"{word} ({tolerance})" if tolerance else word


def _as_row(row: ReportRow | Mapping[str, Any]) -> ReportRow:
    return row if isinstance(row, ReportRow) else ReportRow.from_dict(row)


def _as_figure(figure: ReportFigure | Mapping[str, Any]) -> ReportFigure:
    return figure if isinstance(figure, ReportFigure) else ReportFigure.from_dict(figure)


def write_report(
    out_dir: str | Path,
    rows: Iterable[ReportRow | Mapping[str, Any]],
    figures: Iterable[ReportFigure | Mapping[str, Any]],
    meta: Mapping[str, Any] | None = None,
    *,
    embed: bool = True,
    title: str = "Reproduction of Sakaguchi, Stick-Slip Motion and Phase Transition in a Block-Spring System",
) -> dict[str, Path]:
    """Write ``report.json`` and ``report.html`` into ``out_dir`` (the report of ``stickslip reproduce``).

    Figure paths are relative to ``out_dir``. With ``embed`` (default) each PNG is embedded in
    the HTML, so the page stands alone; otherwise it is linked by its relative path. PDF and
    data files are always linked. ``meta`` gets the package version and the time written if
    it lacks them. Returns the paths written.
    """
    out = Path(out_dir)
    meta = dict(meta or {})
    meta.setdefault("package", "stickslip")
    meta.setdefault("version", __version__)
    meta.setdefault("written", _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"))
    report = Report(
        meta=meta,
        rows=tuple(_as_row(r) for r in rows),
        figures=tuple(_as_figure(f) for f in figures),
    )
    json_path = write_json(out / "report.json", report.to_dict())
    html_path = out / "report.html"
    write_page(html_path, "report.html.j2", **_page_context(report, out, embed=embed, title=title))
    return {"json": json_path, "html": html_path}


def read_report(path: str | Path) -> Report:
    """Read ``report.json`` (a file, or the directory holding it) back into a :class:`Report`."""
    path = Path(path)
    if path.is_dir():
        path = path / "report.json"
    return Report.from_dict(read_json(path))


# ---------------------------------------------------------------------------------------------
# HTML: stickslip/templates/report.html.j2 (see stickslip.pages)


def _format_value(value: Any) -> str:
    if value is None:
        return "not computed"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "n/a" if not math.isfinite(value) else f"{value:.4g}"
    return str(value)


def _agreement_class(agrees: bool | None) -> str:
    return "na" if agrees is None else ("yes" if agrees else "no")


def _meta_text(value: Any) -> str | list[str]:
    """A header entry as the page shows it: text as it is, a list (the experiments, the notes)
    as one line per item, a mapping as ``key: value`` lines, other values as JSON."""
    if isinstance(value, str):
        return value
    if isinstance(value, Mapping):
        return [f"{k}: {v if isinstance(v, str) else _json_text(v)}" for k, v in value.items()]
    if isinstance(value, (list, tuple)):
        return [v if isinstance(v, str) else _json_text(v) for v in value]
    return _json_text(value)


def _json_text(value: Any) -> str:
    import json

    return json.dumps(to_jsonable(value), allow_nan=False)


def _page_context(report: Report, out: Path, *, embed: bool, title: str) -> dict[str, Any]:
    """What report.html.j2 shows: the meta list, the verdict line, the rows and the figures."""
    counts = {"yes": 0, "no": 0, "na": 0}
    for row in report.rows:
        counts[_agreement_class(row.agrees)] += 1
    verdict = (
        f"{len(report.rows)} stated numbers: {counts['yes']} agree, {counts['no']} disagree, "
        f"{counts['na']} not settled at this run length."
    )
    meta = [(str(k), _meta_text(v)) for k, v in report.meta.items()]
    rows = [
        {
            "where": r.where,
            "quantity": r.quantity,
            "note": r.note,
            "paper": r.paper,
            "value": _format_value(r.value),
            "cls": _agreement_class(r.agrees),
            "agreement": r.agreement,
            "command": r.command,
        }
        for r in report.rows
    ]
    figures = []
    for fig in report.figures:
        links = [{"href": fig.pdf, "text": "PDF"}] if fig.pdf else []
        links += [{"href": d, "text": Path(d).name} for d in fig.data]
        figures.append(
            {
                "src": image_src(fig.image, out, embed),
                "figure": fig.figure,
                "caption": fig.caption,
                "links": links,
                "command": fig.command,
            }
        )
    head = ("where", "quantity", "paper", "this run", "agreement", "command")
    return {"title": title, "meta": meta, "verdict": verdict, "head": head, "rows": rows, "figures": figures}
