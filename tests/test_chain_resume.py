"""Stopping and resuming chain runs, and refusing damaged or mismatched checkpoints.

A run split into pieces (run to t1 in a directory, then resume_chain to t2, ...) must end bit
for bit where one uninterrupted run does, with the same events, first moves, L samples,
snapshots and profiles. A checkpoint that is damaged, of another format, or made with other
parameters must be refused with ChainRunError and never used.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from chain_helpers import assert_bits_equal, assert_same_run, assert_same_state, run_cli, run_cli_subprocess
from stickslip.kernels import layout
from stickslip.models.params import ChainParams, ParameterError
from stickslip.run import driver as C
from stickslip.run.driver import ChainRunError, resume_chain, run_chain

P = ChainParams(N=5)
T2 = 3000.0
OPTS = dict(sample_interval=10.0, snapshot_times=(500.0,), profile_window=0.5, profile_min_blocks=2)


@pytest.fixture(scope="module")
def full():
    """One uninterrupted run to T2 (about ten slips of up to five blocks)."""
    run = run_chain(P, T2, **OPTS)
    assert run.summary["n_events"] >= 5 and run.events["n_blocks"].max() >= 3
    assert len(run.profiles["profile_dx"]) > 0
    return run


@pytest.fixture(scope="module")
def full_dense():
    return run_chain(P, T2, integrator="dense", **OPTS)


def _mid_event_time(run, which: int = -1) -> float:
    ev = run.events[run.events["n_blocks"] >= 2].iloc[which]
    assert ev["step_end"] - ev["step_start"] >= 4
    return (ev["step_start"] + ev["step_end"]) // 2 * P.dt


@pytest.mark.parametrize("integrator", ["exact", "dense"])
@pytest.mark.parametrize("split", ["off-grid", "on-grid", "mid-event", "three-pieces"])
def test_resume_in_pieces_equals_uninterrupted(tmp_path, full, full_dense, integrator, split):
    ref = full if integrator == "exact" else full_dense
    if split == "off-grid":
        times = [1234.567]
    elif split == "on-grid":
        times = [1230.0]
    elif split == "mid-event":
        times = [_mid_event_time(full, -2)]
    else:
        times = [700.0, _mid_event_time(full, -1)]
    first = run_chain(P, times[0], integrator=integrator, out_dir=tmp_path, **OPTS, keep_checkpoint=True)
    if split == "mid-event":
        assert first.summary["event_in_progress"]
    for t in times[1:]:
        resume_chain(tmp_path, t_end=t)
    run = resume_chain(tmp_path, t_end=T2)
    assert run.integrator == integrator
    assert_same_run(run, ref)
    # what was written is the same as what was returned
    loaded = C.load_run(tmp_path)
    assert loaded.summary["state_sha256"] == ref.summary["state_sha256"]
    assert loaded.events.equals(ref.events)
    assert loaded.first_move.equals(ref.first_move)


def test_resume_of_a_finished_run_changes_nothing(tmp_path, full):
    run_chain(P, T2, out_dir=tmp_path, **OPTS, keep_checkpoint=True)
    again = resume_chain(tmp_path)
    assert_same_run(again, full)
    assert again.steps == full.steps


def test_frequent_checkpoints_do_not_change_the_result(tmp_path, full):
    """A checkpoint after every kernel call (many flushes of the output buffers)."""
    times = tuple(float(t) for t in np.arange(50.0, T2, 50.0))
    opts = dict(OPTS, snapshot_times=times)
    ref = run_chain(P, T2, **opts)
    run = run_chain(P, T2, out_dir=tmp_path, checkpoint_interval=1e-9, **opts, keep_checkpoint=True)
    assert_same_run(run, ref)
    assert len(list((tmp_path / "checkpoint").glob("part-*.npz"))) >= len(times)
    assert_same_run(resume_chain(tmp_path), ref)


def test_a_run_stopped_on_request_checkpoints_and_resumes_to_the_same_bits(tmp_path, full):
    """``stop_requested`` (how a study's point learns that the study was interrupted) stops the
    run as a signal does: a checkpoint at the step reached, Interrupted, then a resume that ends
    exactly where the uninterrupted run does."""
    calls = []

    def stop_on_the_third_call() -> bool:
        calls.append(1)
        return len(calls) == 3

    opts = dict(OPTS, snapshot_times=tuple(float(t) for t in np.arange(50.0, T2, 50.0)))
    ref = run_chain(P, T2, **opts)
    with pytest.raises(C.Interrupted) as stopped:
        run_chain(P, T2, out_dir=tmp_path, stop_requested=stop_on_the_third_call, **opts)
    assert 0 < stopped.value.t < T2
    assert (tmp_path / "checkpoint" / "state.npz").is_file()
    assert not (tmp_path / "run.json").exists()
    assert len(calls) == 3
    assert_same_run(C.continue_or_run(P, T2, tmp_path, checkpoint_interval=60.0, **opts), ref)


def test_continue_from_a_returned_state(full):
    t1 = 1230.0
    first = run_chain(P, t1, **OPTS)
    sha_before = first.state.sha256()
    ist_before = first.state.ist.copy()
    second = run_chain(P, T2, start=first.state, **dict(OPTS, snapshot_times=()))
    # the caller's state is not touched
    assert first.state.sha256() == sha_before
    assert np.array_equal(first.state.ist, ist_before)
    assert_same_state(second.state, full.state)
    assert second.summary["state_sha256"] == full.summary["state_sha256"]
    events = pd.concat([first.events, second.events], ignore_index=True)
    assert events.equals(full.events)
    moves = pd.concat([first.first_move, second.first_move], ignore_index=True)
    assert moves.equals(full.first_move)
    # the second piece samples L on the same grid from t1 on
    t_full = full.samples["t"].values
    keep = t_full >= t1 - 0.5 * P.dt
    assert_bits_equal(second.samples["t"].values, t_full[keep], "sample times")
    assert_bits_equal(second.samples["L"].values, full.samples["L"].values[keep], "L")
    assert second.start["kind"] == "state" and second.start["sha256"] == sha_before


def test_continue_from_a_state_inside_an_event(full):
    t1 = _mid_event_time(full, -1)
    first = run_chain(P, t1, **OPTS)
    assert first.state.ist[layout.EV_ACTIVE] == 1
    second = run_chain(P, T2, start=first.state, **dict(OPTS, snapshot_times=()))
    # a new run samples L from its own start (t1 is off the grid here): all else carries over
    assert_same_state(second.state, full.state, skip=("NEXT_SAMPLE",))
    assert pd.concat([first.events, second.events], ignore_index=True).equals(full.events)
    assert pd.concat([first.first_move, second.first_move], ignore_index=True).equals(full.first_move)


def test_resume_refuses_an_earlier_end_time(tmp_path):
    run_chain(P, 100.0, out_dir=tmp_path, keep_checkpoint=True)
    with pytest.raises(ParameterError, match="t_end"):
        resume_chain(tmp_path, t_end=50.0)


def test_resume_without_checkpoint(tmp_path):
    with pytest.raises(ChainRunError, match="no checkpoint"):
        resume_chain(tmp_path)


# --------------------------------------------------------------------------------------
# Damaged and mismatched checkpoints

SMALL = ChainParams(N=5, V=0.05)


def _digest_tree(d: Path) -> dict[str, str]:
    return {str(f.relative_to(d)): hashlib.sha256(f.read_bytes()).hexdigest()
            for f in sorted(d.rglob("*")) if f.is_file()}  # fmt: skip


@pytest.fixture
def run_dir(tmp_path):
    """A finished run of 100 time units with slips, its checkpoint kept in tmp_path/run."""
    d = tmp_path / "run"
    run = run_chain(SMALL, 100.0, out_dir=d, profile_window=0.5, keep_checkpoint=True)
    assert run.summary["n_events"] > 0
    return d


@pytest.fixture(scope="module")
def resumed_reference():
    return run_chain(SMALL, 200.0, profile_window=0.5)


def _flip(path: Path, offset: int) -> None:
    data = bytearray(path.read_bytes())
    data[offset] ^= 0xFF
    path.write_bytes(bytes(data))


def _array_offset(path: Path, array: np.ndarray) -> int:
    """Where the bytes of ``array`` are stored in an (uncompressed) npz file."""
    offset = path.read_bytes().find(np.ascontiguousarray(array).tobytes())
    assert offset >= 0
    return offset + array.nbytes // 2


def _refused(run_dir: Path, **kw) -> ChainRunError:
    before = _digest_tree(run_dir)
    with pytest.raises(ChainRunError) as info:
        resume_chain(run_dir, t_end=200.0, **kw)
    assert _digest_tree(run_dir) == before, "a refused checkpoint must leave the directory untouched"
    msg = str(info.value)
    assert "\n" not in msg and "checkpoint" in msg
    return info.value


@pytest.mark.parametrize("target", ["state.npz", "part-000000.npz"])
def test_flipped_array_bytes_are_refused(run_dir, target):
    path = run_dir / "checkpoint" / target
    arrays, _, _ = C.read_npz(path)
    name = "x" if target == "state.npz" else "ev_int"
    assert arrays[name].size > 0
    _flip(path, _array_offset(path, arrays[name]))
    msg = str(_refused(run_dir))
    assert target in msg and "corrupt" in msg


@pytest.mark.parametrize("target", ["state.npz", "part-000000.npz"])
@pytest.mark.parametrize("fraction", [0.05, 0.3, 0.6, 0.97])
def test_flipped_bytes_anywhere_are_refused_or_harmless(run_dir, resumed_reference, target, fraction):
    """Flipping a byte of the zip container may hit bytes that carry no data (a timestamp):
    then the checksummed content is intact and may be used; otherwise it must be refused."""
    path = run_dir / "checkpoint" / target
    _flip(path, int(fraction * path.stat().st_size))
    try:
        run = resume_chain(run_dir, t_end=200.0)
    except ChainRunError as exc:
        assert "corrupt" in str(exc) or "unreadable" in str(exc)
    else:
        assert_same_run(run, resumed_reference)


@pytest.mark.parametrize("target", ["state.npz", "part-000000.npz"])
@pytest.mark.parametrize("keep", [0, 0.5, 0.99])
def test_truncated_files_are_refused(run_dir, target, keep):
    path = run_dir / "checkpoint" / target
    data = path.read_bytes()
    path.write_bytes(data[: int(keep * len(data))])
    assert target in str(_refused(run_dir))


def test_missing_part_file_is_refused(run_dir):
    (run_dir / "checkpoint" / "part-000000.npz").unlink()
    assert "part-000000.npz" in str(_refused(run_dir))


def test_other_checkpoint_format_is_refused(run_dir):
    path = run_dir / "checkpoint" / "state.npz"
    arrays, header, _ = C.read_npz(path)
    C.write_npz(path, arrays, dict(header, format=C.CHECKPOINT_FORMAT + 1))
    msg = str(_refused(run_dir))
    assert "format" in msg and str(C.CHECKPOINT_FORMAT + 1) in msg


def test_checkpoint_with_other_parameters_is_refused(run_dir):
    msg = str(_refused(run_dir, expect_params=SMALL.replace(K=5.0)))
    assert "parameters" in msg
    # the right parameters are accepted
    assert resume_chain(run_dir, t_end=200.0, expect_params=SMALL).steps == 40000


def test_a_point_continues_a_usable_checkpoint_and_reruns_past_a_damaged_one(run_dir, monkeypatch):
    """continue_or_run, the step of every sweep, study and reproduction point."""
    reference = run_chain(SMALL, 100.0, profile_window=0.5)
    with monkeypatch.context() as m:
        m.setattr(C, "run_chain", lambda *a, **k: pytest.fail("a usable checkpoint must be continued"))
        assert_same_run(C.continue_or_run(SMALL, 100.0, run_dir, checkpoint_interval=60.0), reference)
    path = run_dir / "checkpoint" / "state.npz"
    arrays, _, _ = C.read_npz(path)
    _flip(path, _array_offset(path, arrays["x"]))
    fresh = []
    monkeypatch.setattr(C, "run_chain", lambda *a, **k: fresh.append(1) or run_chain(*a, **k))
    run = C.continue_or_run(SMALL, 100.0, run_dir, checkpoint_interval=60.0, profile_window=0.5)
    assert fresh == [1], "a damaged checkpoint is refused and the point run afresh"
    assert_same_run(run, reference)
    assert not (run_dir / "checkpoint").exists(), "the damaged checkpoint is gone"


@pytest.mark.parametrize("mismatch", ["arrays-of-N=4", "ist-one-entry-short"])
def test_checkpoint_arrays_that_do_not_fit_are_refused(tmp_path, run_dir, mismatch):
    """A checksum-valid state file whose arrays do not fit its parameters or the kernels'
    state layout must be refused before any kernel touches them (the kernels do not check
    bounds). 'ist-one-entry-short' is a state vector of an earlier layout under the same
    format number."""
    path = run_dir / "checkpoint" / "state.npz"
    arrays, header, _ = C.read_npz(path)
    if mismatch == "arrays-of-N=4":
        other = tmp_path / "other"
        run_chain(SMALL.replace(N=4), 100.0, out_dir=other, keep_checkpoint=True)
        arrays, _, _ = C.read_npz(other / "checkpoint" / "state.npz")
        C.write_npz(path, arrays, header)
        _refused(run_dir)
    else:
        # in a separate process: until refused, the kernels write past the end of this array
        arrays["ist"] = arrays["ist"][:-1].copy()
        C.write_npz(path, arrays, header)
        before = _digest_tree(run_dir)
        proc = run_cli_subprocess("chain", "--resume", str(run_dir), "--t-end", "200", "--no-progress")
        assert proc.returncode == 2, proc.stderr
        assert proc.stderr.count("\n") == 1 and "checkpoint" in proc.stderr
        assert _digest_tree(run_dir) == before


def test_stray_part_files_are_ignored(run_dir, resumed_reference):
    """A part written by a checkpoint that was killed before its state file is not used."""
    ckpt = run_dir / "checkpoint"
    bogus = {"ev_int": np.zeros((3, layout.EV_INT_COLS), dtype=np.int64), "ev_S": np.ones(3)}
    C.write_npz(ckpt / "part-000001.npz", bogus, {"format": C.CHECKPOINT_FORMAT})
    assert_same_run(resume_chain(run_dir, t_end=200.0), resumed_reference)


def test_cli_refuses_a_corrupt_checkpoint(capsys, run_dir):
    path = run_dir / "checkpoint" / "state.npz"
    arrays, _, _ = C.read_npz(path)
    _flip(path, _array_offset(path, arrays["x"]))
    before = _digest_tree(run_dir)
    status, out, err = run_cli(capsys, "chain", "--resume", str(run_dir), "--json", "--no-progress")
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and "corrupt" in err
    assert _digest_tree(run_dir) == before


def test_cli_refuses_resume_with_other_model_parameters(capsys, run_dir):
    """`--resume DIR --K 5` for a run made with K = 10 must not silently run with K = 10."""
    before = _digest_tree(run_dir)
    status, out, err = run_cli(capsys, "chain", "--resume", str(run_dir), "--K", "5", "--t-end", "200",
                            "--no-progress")  # fmt: skip
    assert status == 2, "model parameters given with --resume were ignored"
    assert err.count("\n") == 1 and "K" in err
    assert _digest_tree(run_dir) == before


@pytest.mark.parametrize("split", [1234.567, 1230.0])
def test_moving_samples_resume_to_those_of_one_run(tmp_path, split):
    """sample_moving across a checkpoint (off and on the sampling grid): the same samples as one run."""
    opts = dict(OPTS, sample_moving=True)
    ref = run_chain(P, T2, **opts)
    run_chain(P, split, out_dir=tmp_path, **opts, keep_checkpoint=True)
    run = resume_chain(tmp_path, t_end=T2)
    assert_same_run(run, ref)
    for key in ("t_moving", "n_moving"):
        assert np.array_equal(run.samples[key].values, ref.samples[key].values)
    assert len(ref.samples["n_moving"]) == T2 / 10.0 + 1 and ref.samples["n_moving"].values.max() > 0
