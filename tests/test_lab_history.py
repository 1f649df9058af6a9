"""LoadHistory: steps, holds, tables and CSV records; continuity; bad input refused in one line."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from stickslip.lab import LoadHistory
from stickslip.models.params import ParameterError


def test_steps_are_continuous_in_position_with_breakpoints():
    h = LoadHistory.steps([1.0, 10.0, 0.0, 3.0], [10.0, 5.0, 20.0, 2.0])
    assert h.breakpoints.tolist() == [0.0, 10.0, 15.0, 35.0, 37.0]
    # by hand: 10 um at 1, 50 um at 10, a hold, 6 um at 3
    assert h.positions.tolist() == [0.0, 10.0, 60.0, 60.0, 66.0]
    eps = 1e-9
    for tb in h.breakpoints[1:-1]:
        assert abs(float(h.position(tb - eps)) - float(h.position(tb + eps))) < 1e-7
    assert float(h.velocity(12.0)) == 10.0 and float(h.velocity(20.0)) == 0.0
    assert float(h.velocity(10.0)) == 10.0  # the right-hand value at a breakpoint
    assert float(h.position(36.0)) == 63.0


def test_slide_hold_slide_layout():
    h = LoadHistory.slide_hold_slide(10.0, 100.0, [1.0, 10.0], t_reslide=50.0)
    assert h.velocities.tolist() == [10.0, 0.0, 10.0, 0.0, 10.0]
    assert np.diff(h.breakpoints).tolist() == [100.0, 1.0, 50.0, 10.0, 50.0]


def test_table_and_velocity_forms_agree():
    t = [0.0, 2.0, 5.0, 6.0]
    a = LoadHistory.from_velocities(t, [1.0, 0.0, 4.0])
    b = LoadHistory.table(t, [0.0, 2.0, 2.0, 6.0])
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.velocities, b.velocities)


def test_csv_displacement_and_velocity(tmp_path):
    p = tmp_path / "rec.csv"
    p.write_text("time,load_point,mu\n0,0,0.6\n1,1,0.6\n2,11,0.61\n")
    h = LoadHistory.from_csv(p)
    assert h.velocities.tolist() == [1.0, 10.0]
    q = tmp_path / "vel.csv"
    q.write_text("time,vlp\n0,1\n1,10\n2,10\n")
    assert LoadHistory.from_csv(q).positions.tolist() == [0.0, 1.0, 11.0]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("time,load_point\n0,0\n1,nan\n", "no number in data row 2"),
        ("time,load_point\n0,0\n1,x\n", "no number in data row 2"),
        ("t,load_point\n0,0\n1,1\n", "no column 'time'"),
        ("time,mu\n0,0.6\n1,0.6\n", "no load-point column"),
        ("time,load_point\n0,0\n0,1\n", "times must increase"),
        ("time,load_point\n0,0\n1,2\n2,1\n", "velocity must be >= 0"),
        ("time,velocity\n0,1\n1,-1\n2,1\n", "velocities must be >= 0"),
    ],
)
def test_bad_records_refused_in_one_line(tmp_path, text, match):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ParameterError, match=match) as err:
        LoadHistory.from_csv(p)
    assert "\n" not in str(err.value)


def test_bad_steps_refused():
    with pytest.raises(ParameterError, match="velocities must be >= 0"):
        LoadHistory.steps([1.0, -1.0], [1.0, 1.0])
    with pytest.raises(ParameterError, match="durations must be > 0"):
        LoadHistory.steps([1.0], [0.0])
    with pytest.raises(ParameterError, match="times must be >= 0"):
        LoadHistory.table([-1.0, 1.0], [0.0, 1.0])
    with pytest.raises(ParameterError, match="times must increase"):
        LoadHistory.table([0.0, 2.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(ParameterError, match="finite"):
        LoadHistory.table([0.0, np.nan], [0.0, 1.0])


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.0, 1e3), st.floats(1e-3, 1e3)), min_size=1, max_size=12))
@example([(2.225073858507203e-309, 0.25)])  # a subnormal displacement: found in a test run
def test_any_steps_are_continuous_and_their_slope_is_the_velocity(segments):
    v, d = zip(*segments, strict=True)
    h = LoadHistory.steps(v, d)
    assert h.breakpoints.size == len(v) + 1
    # V_i from the summed positions and times: exact up to their rounding, (n + 2) eps of each
    # (a short step after long ones keeps fewer digits), and below the normal numbers (a velocity
    # of 2e-309) to the subnormals' absolute spacing.
    p, t, dt = np.abs(h.positions), h.times, np.diff(h.times)
    finfo = np.finfo(float)
    relative = finfo.eps * (p[:-1] + p[1:] + np.abs(v) * (t[:-1] + t[1:]))
    bound = (len(v) + 2) * (relative + finfo.smallest_subnormal) / dt
    assert np.all(np.abs(h.velocities - np.asarray(v)) <= bound)
    mid = 0.5 * (h.times[:-1] + h.times[1:])
    np.testing.assert_array_equal(h.velocity(mid), h.velocities)
    # p(t) at each breakpoint is the sum of the displacements before it, from either side
    np.testing.assert_allclose(h.position(h.times), np.concatenate([[0.0], np.cumsum(np.multiply(v, d))]), rtol=1e-12)
    merged = h.merged()
    np.testing.assert_allclose(merged.position(mid), h.position(mid), rtol=1e-9, atol=1e-9)
