"""The fields of a lattice run's largest events (docs/lattice.md, "Slip maps and rupture
fronts"): the slip of every block, x(end) - x(first move), and the step of its first move, over
(event, row, col), for ``run_lattice(..., slip_maps=K)``.

The kernels keep an event's first-move steps only while it lasts, so the run keeps, for the K
largest events so far (by moment, among those of at least ``slip_min_area`` blocks), the state
before the kernel call in which each ended; at the run's end each is run again through its end
by the dense reference (:func:`stickslip.run.lattice._replay`), which gives the same bits as
either integrator, and its fields are read on the way. The slip field sums, in row-major order,
to the event's moment bit for bit. Nothing is kept or replayed unless asked for.
"""

from __future__ import annotations

import heapq
from typing import Any

import numpy as np
import xarray as xr

from stickslip.models.params import check_number

__all__ = ["MAX_SLIP_MAPS", "EventFields"]

#: The most events whose fields a run records (each keeps a copy of the state until the end).
MAX_SLIP_MAPS = 256


class EventFields:
    """The ``largest`` events by moment of at least ``min_area`` blocks, each with the state
    before the kernel call in which it ended; :meth:`dataset` replays them."""

    def __init__(self, p: Any, largest: int, min_area: int = 1):
        self.p = p
        self.largest = int(check_number("slip_maps", largest, low=0, high=MAX_SLIP_MAPS, integer=True))
        self.min_area = int(check_number("slip_min_area", min_area, low=1, integer=True))
        self.heap: list[tuple[float, int, int, int, Any]] = []

    def offer(self, pre, row: np.ndarray, moment: float) -> None:
        """An event that ended (its row of the kernel's event buffer, its moment) and the state
        before the call in which it ended: kept if among the largest so far."""
        from stickslip.kernels import lattice as kl

        if int(row[kl.L_AREA]) < self.min_area:
            return
        item = (moment, int(row[kl.L_ID]), int(row[kl.L_START_STEP]), int(row[kl.L_END_STEP]), pre)
        if len(self.heap) < self.largest:
            heapq.heappush(self.heap, item)
        elif item[:2] > self.heap[0][:2]:
            heapq.heapreplace(self.heap, item)

    def dataset(self, replay) -> xr.Dataset:
        """``slip`` (float) and ``first_step`` (int, -1 where the block did not move) over
        (event, row, col), in the order of the events, with each event's ``step_start``,
        ``step_end`` and ``moment`` (the replay's, equal to the event table's)."""
        lat = self.p.lattice
        rows, cols = lat.shape
        kept = sorted(self.heap, key=lambda item: item[1])
        slip = np.zeros((len(kept), rows, cols))
        first = np.full((len(kept), rows, cols), -1, dtype=np.int64)
        moment = np.zeros(len(kept))
        for j, (_, _, _, step_end, pre) in enumerate(kept):
            s, fs, moment[j] = replay(self.p, pre, step_end)
            moved = fs >= 0
            slip[j] = lat.grid(np.where(moved, s.xg - np.where(moved, s.x0ev, 0.0), 0.0))
            first[j] = lat.grid(fs)
        ids = np.array([item[1] for item in kept], dtype=np.int64)
        return xr.Dataset(
            {
                "slip": (("event", "row", "col"), slip),
                "first_step": (("event", "row", "col"), first),
            },
            coords={
                "event": ids,
                "row": np.arange(1, rows + 1),
                "col": np.arange(1, cols + 1),
                "step_start": ("event", np.array([item[2] for item in kept], dtype=np.int64)),
                "step_end": ("event", np.array([item[3] for item in kept], dtype=np.int64)),
                "moment": ("event", moment),
            },
            attrs={
                "dt": float(self.p.dt),
                "selection": f"the {self.largest} largest by moment, area >= {self.min_area}",
            },
        )
