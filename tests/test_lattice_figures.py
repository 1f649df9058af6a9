"""Slip maps, rupture fronts and snapshot images of lattice runs (docs/lattice.md, "Slip maps and
rupture fronts", "Figures"): the recorded fields against the events and against the state
before and after each event; the figures' images; `stickslip plot` on a lattice run directory."""

from __future__ import annotations

import numpy as np
import pytest

from chain_helpers import one_line_error, run_cli
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.lattice import run_lattice

SHAPE = (5, 7)
T_END = 120.0


@pytest.fixture(scope="module")
def model():
    return chain_params("carlson-langer", lattice="square", shape=SHAPE)


@pytest.fixture(scope="module")
def runs(model):
    plain = run_lattice(model, T_END, start="rest", perturbation=0.01, snapshot_every=40.0)
    mapped = run_lattice(model, T_END, start="rest", perturbation=0.01, snapshot_every=40.0, slip_maps=3)
    return plain, mapped


def test_recording_leaves_the_run_as_it_is(runs):
    plain, mapped = runs
    assert plain.event_fields is None
    assert mapped.summary["state_sha256"] == plain.summary["state_sha256"]
    assert mapped.events.equals(plain.events)


def test_the_largest_events_are_recorded_and_their_slip_sums_to_the_moment(runs):
    _, run = runs
    f = run.event_fields
    largest = run.events.nlargest(3, "moment")
    assert sorted(f["event"].values.tolist()) == sorted(largest["event"].tolist())
    for j, e in enumerate(f["event"].values):
        row = run.events.set_index("event").loc[e]
        slip, first = f["slip"].values[j], f["first_step"].values[j]
        assert float(f["moment"].values[j]) == row["moment"]
        total = 0.0
        for value, moved in zip(slip.ravel(), first.ravel() >= 0, strict=True):  # the kernel's order
            if moved:
                total += value
        assert total == row["moment"]
        assert np.count_nonzero(first >= 0) == row["area"]
        assert first[int(row["epicentre_row"]) - 1, int(row["epicentre_col"]) - 1] == row["step_start"]
        assert first[first >= 0].min() == row["step_start"] and first.max() <= row["step_end"]
        assert np.all(slip[first < 0] == 0.0)


def test_slip_field_is_the_state_after_less_the_state_before(model, runs):
    """Between events every block is stopped and keeps its x: an event's slip is x after it
    less x before it, from two plain runs that end at its start and at its end."""
    _, run = runs
    f = run.event_fields
    j = int(np.argmax(f["moment"].values))
    start, end = int(f["step_start"].values[j]), int(f["step_end"].values[j])
    before = run_lattice(model, start * model.dt, start="rest", perturbation=0.01).final()["x"].values
    after = run_lattice(model, (end + 1) * model.dt, start="rest", perturbation=0.01).final()["x"].values
    np.testing.assert_array_equal(f["slip"].values[j], after - before)


def _images(fig):
    return [im.get_array() for ax in fig.axes for im in ax.get_images()]


def test_snapshot_images(runs):
    _, run = runs
    fig = run.plot_snapshot()
    images = _images(fig)
    assert len(images) == 3 and all(im.shape == SHAPE for im in images)
    np.testing.assert_array_equal(images[0], run.final()["x"].values)
    fig = run.plot_snapshot(40.0, fields=("v",))
    (image,) = _images(fig)
    np.testing.assert_array_equal(image, run.snapshots["v"].sel(time=40.0).values)
    with pytest.raises(ParameterError, match="fields"):
        run.plot_snapshot(fields=("y",))


def test_slip_map_and_rupture_frames(runs):
    _, run = runs
    f = run.event_fields
    j = int(np.argmax(f["moment"].values))
    (image,) = _images(run.plot_event())
    assert image.shape == SHAPE
    np.testing.assert_allclose(float(np.sum(image)), float(f["moment"].values[j]), rtol=1e-13)
    fig = run.plot_rupture(frames=4)
    images = _images(fig)
    assert len(images) == 4 and all(im.shape == SHAPE for im in images)
    # the last frame shows every block that moved, the first no more than the later ones
    assert np.count_nonzero(~np.isnan(np.asarray(images[-1], dtype=float))) == np.count_nonzero(
        f["first_step"].values[j] >= 0
    )
    counts = [np.count_nonzero(~np.isnan(np.asarray(im, dtype=float))) for im in images]
    assert counts == sorted(counts)


def test_no_fields_no_slip_map(runs):
    plain, _ = runs
    with pytest.raises(ParameterError, match="slip_maps"):
        plain.plot_event()


def test_slip_maps_out_of_range(model):
    with pytest.raises(ParameterError, match="slip_maps"):
        run_lattice(model, 1.0, slip_maps=1000)
    with pytest.raises(ParameterError, match="slip_min_area"):
        run_lattice(model, 1.0, slip_min_area=0)


def test_chain_and_plot_commands_on_a_lattice(tmp_path, capsys):
    out = tmp_path / "run"
    status, _, err = run_cli(
        capsys, "chain", "--model", "carlson-langer", "--lattice", "square", "--shape", "4x5",
        "--t-end", "60", "--slip-maps", "2", "--slip-min-area", "2", "--out", str(out),
    )  # fmt: skip
    assert status == 0, err
    assert (out / "event_fields.nc").is_file()
    status, _, err = run_cli(capsys, "plot", str(out), "--format", "png")
    assert status == 0, err
    names = sorted(p.name for p in (out / "figures").iterdir())
    assert "snapshot_final.png" in names
    assert any(n.startswith("slip_map_e") for n in names) and any(n.startswith("rupture_e") for n in names)


def test_slip_maps_go_with_a_lattice(capsys):
    from stickslip.cli import main

    assert main(["chain", "--N", "5", "--t-end", "1", "--slip-maps", "2"]) == 2
    one_line_error(capsys, "--slip-maps", "--lattice square")


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        (["--slip-maps", "999"], ["--slip-maps", "256"]),
        (["--slip-maps", "2", "--slip-min-area", "0"], ["--slip-min-area"]),
    ],
)
def test_slip_map_options_out_of_range(capsys, argv, names):
    from stickslip.cli import main

    assert main(["chain", "--lattice", "square", "--shape", "3x3", "--t-end", "1", *argv]) == 2
    one_line_error(capsys, *names)
