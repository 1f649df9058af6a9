"""Start states are checked before any kernel sees them (docs/limits.md, "Start states"):
``chain --from``, ``run_chain(start=ChainState)`` and the transition study's rung replay refuse a
state of the wrong shape, type, values, bookkeeping or model in one line, and run a good one."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from chain_helpers import error_lines, run_cli
from stickslip.kernels import layout
from stickslip.models.params import ParameterError
from stickslip.models.presets import chain_params
from stickslip.run.driver import run_chain
from stickslip.run.rundir import read_state_file, write_state_file
from stickslip.run.state import ChainState, model_of

N = 6
ARGS = ("--N", str(N), "--V", "0.01", "--no-progress")


def _params(**kw):
    return chain_params("sakaguchi", N=N, V=0.01, **kw)


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A rung-like folder with a good state of eq. (4) at t = 300, and a finished run directory."""
    base = tmp_path_factory.mktemp("start")
    run = run_chain(_params(), 300.0)
    write_state_file(base / "rung" / "state.npz", run.state)
    assert run_cli_ok("chain", *ARGS, "--t-end", "300", "--out", str(base / "run"))
    return base, run.state


def run_cli_ok(*argv):
    from stickslip.cli import main

    return main(list(argv)) == 0


def _arrays(state):
    return {k: a.copy() for k, a in state.arrays().items()}


def _set(name, index, value):
    def f(a):
        a[name][index] = value

    return f


def _replace(name, make):
    def f(a):
        a[name] = make(a[name])

    return f


def _all_stuck_one_moving(a):
    """Every block stuck but block 1 moving, with N_MOVING right: valid except for what follows."""
    a["mov"][1:-1] = 0.0
    a["v"][1:-1] = 0.0
    a["mov"][1], a["v"][1] = 1.0, 0.1
    a["ist"][layout.N_MOVING] = 1


def _moving_outside_act(a):
    _all_stuck_one_moving(a)
    a["ist"][layout.ACT_LO], a["ist"][layout.ACT_HI] = 3, N


def _stuck_with_velocity(a):
    _all_stuck_one_moving(a)
    a["v"][2] = 0.5


# (case, damage of the state's arrays, words of the one line); each is a state the kernels must
# never see: before, the first two aborted the process (heap corruption, a segfault), the rest ran
# without a word.
BAD_ARRAYS = [
    ("v shorter than x", _replace("v", lambda v: v[:3]), "v has shape (3,)"),
    ("ist short", _replace("ist", lambda i: i[:5]), "ist has shape (5,)"),
    ("ACT bound 10**6", _set("ist", layout.ACT_HI, 10**6), "ACT interval [1, 1000000]"),
    ("MECH bound -3", _set("ist", layout.MECH_LO, -3), "MECH interval"),
    ("x float32", _replace("x", lambda x: x.astype(np.float32)), "type float32"),
    ("first_step float", _replace("first_step", lambda f: f.astype(np.float64)), "first_step has shape"),
    ("ist float", _replace("ist", lambda i: i.astype(np.float64)), "ist has shape"),
    ("x 2-d", _replace("x", lambda x: np.zeros((2, N + 2))), "x has shape (2, 8)"),
    ("x NaN", _set("x", 2, np.nan), "x is not finite"),
    ("v inf", _set("v", 3, np.inf), "v is not finite"),
    ("theta 2", _set("th", 2, 2.0), "theta must be >= 0 and <= 1"),
    ("theta negative", _set("th", 4, -0.5), "theta must be >= 0 and <= 1"),
    ("x0ev NaN", _set("x0ev", 1, np.nan), "x0ev is not finite"),
    ("negative step", _set("ist", layout.STEP, -5), "step -5 outside"),
    ("step past the limit", _set("ist", layout.STEP, 10**13), "step 10000000000000 outside"),
    ("moving mask 7", _set("mov", 2, 7.0), "moving mask"),
    ("N_MOVING wrong", _set("ist", layout.N_MOVING, 5), "N_MOVING 5"),
    ("moving block outside ACT", _moving_outside_act, "outside the ACT interval"),
    ("stopped block with a velocity", _stuck_with_velocity, "stopped block has a velocity"),
    ("EV_COUNT not flushed", _set("ist", layout.EV_COUNT, 7), "EV_COUNT is 7"),
    ("EV_ACTIVE 3", _set("ist", layout.EV_ACTIVE, 3), "EV_ACTIVE is 3"),
    ("first_step after the step", _set("first_step", 2, 10**9), "first_step outside"),
    ("first move without an event", _set("first_step", 2, 0), "no event is in progress"),
    ("BAD_BLOCK 10**6", _set("ist", layout.BAD_BLOCK, 10**6), "BAD_BLOCK"),
    ("N_EVENTS negative", _set("ist", layout.N_EVENTS, -1), "N_EVENTS is negative"),
    ("NEXT_PROFILE negative", _set("ist", layout.NEXT_PROFILE, -1), "NEXT_PROFILE is negative"),
]


def _assert_refused(status, out, err, words):
    assert status == 2, err
    assert out == "" and "Traceback" not in err, err
    assert len(error_lines(err)) == 1, err
    assert words in err, err


@pytest.mark.parametrize("case, damage, words", BAD_ARRAYS, ids=[c[0] for c in BAD_ARRAYS])
def test_chain_from_a_bad_state_is_one_line(case, damage, words, good, tmp_path, capsys):
    base, state = good
    arrays = _arrays(state)
    damage(arrays)
    np.savez(tmp_path / "state.npz", **arrays)
    capsys.readouterr()
    status, out, err = run_cli(capsys, "chain", "--from", str(tmp_path), *ARGS, "--t-end", "600")
    _assert_refused(status, out, err, words)
    assert "--from" in err


@pytest.mark.parametrize("case, damage, words", BAD_ARRAYS, ids=[c[0] for c in BAD_ARRAYS])
def test_run_chain_refuses_a_bad_start_state(case, damage, words, good):
    _, state = good
    arrays = _arrays(state)
    damage(arrays)
    bad = ChainState(**{ChainState.FIELDS.get(k, k): a for k, a in arrays.items()})
    with pytest.raises(ParameterError) as info:
        run_chain(_params(), 600.0, start=bad)
    assert words in str(info.value) and "\n" not in str(info.value)


def _write_text(text):
    def f(path):
        path.write_bytes(text)

    return f


def _truncate(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def _without_ist(path):
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files if k != "ist"}
    np.savez(path, **arrays)


def _pickled(path):
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["x"] = np.array([object()] * (N + 2), dtype=object)
    np.savez(path, **arrays)


def _model(model):
    def f(path):
        state = read_state_file(path)
        state.model = model
        write_state_file(path, state)

    return f


def _garbled_model(path):
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["__model__"] = np.frombuffer(b"\xff{not json", dtype=np.uint8)
    np.savez(path, **arrays)


def _row_sha(path):
    (path.parent / "rung.json").write_text(json.dumps({"row": {"final_sha256": "0" * 64}}))


CARLSON_LANGER = model_of(chain_params("carlson-langer", N=N))
RATE_STATE = model_of(chain_params("sakaguchi", N=N, friction="rate-state"))

# (case, damage of the file state.npz, words): before, the first three were tracebacks
# (BadZipFile, EOFError), the model cases ran as eq. (4) without a word.
BAD_FILES = [
    ("truncated", _truncate, "is damaged or not a state file"),
    ("empty", _write_text(b""), "is damaged or not a state file"),
    ("not npz", _write_text(b"x,v\n1,2\n"), "is damaged or not a state file"),
    ("an array missing", _without_ist, "lacks ist"),
    ("pickled objects", _pickled, "is damaged or not a state file"),
    ("a state of Carlson-Langer", _model(CARLSON_LANGER), "it is a state of carlson-langer"),
    ("a state of rate-and-state", _model(RATE_STATE), "friction rate-state"),
    ("model record garbled", _garbled_model, "model record"),
    ("not the rung's final state", _row_sha, "does not match the final state its rung.json records"),
]


@pytest.mark.parametrize("case, damage, words", BAD_FILES, ids=[c[0] for c in BAD_FILES])
def test_chain_from_a_damaged_state_file_is_one_line(case, damage, words, good, tmp_path, capsys):
    base, _ = good
    shutil.copy(base / "rung" / "state.npz", tmp_path / "state.npz")
    damage(tmp_path / "state.npz")
    capsys.readouterr()
    status, out, err = run_cli(capsys, "chain", "--from", str(tmp_path), *ARGS, "--t-end", "600")
    _assert_refused(status, out, err, words)


def _run_of(params):
    def f(run_dir):
        meta = json.loads((run_dir / "run.json").read_text())
        meta["params"] = params
        (run_dir / "run.json").write_text(json.dumps(meta))

    return f


def _steps(value):
    def f(run_dir):
        meta = json.loads((run_dir / "run.json").read_text())
        meta["summary"]["steps"] = value
        (run_dir / "run.json").write_text(json.dumps(meta))

    return f


BAD_RUNS = [
    ("a run of Carlson-Langer", _run_of(chain_params("carlson-langer", N=N).to_dict()), "carlson-langer"),
    ("a run of rate-and-state", _run_of(chain_params("sakaguchi", N=N, friction="rate-state").to_dict()), "rate-state"),
    ("steps 1e30", _steps(10**30), "does not hold a whole chain run"),
    ("steps negative", _steps(-5), "step -5 outside"),
    ("run.json of another N", _run_of(chain_params("sakaguchi", N=N + 1, V=0.01).to_dict()), "holds 6 blocks"),
]


@pytest.mark.parametrize("case, damage, words", BAD_RUNS, ids=[c[0] for c in BAD_RUNS])
def test_chain_from_a_foreign_run_is_one_line(case, damage, words, good, tmp_path, capsys):
    base, _ = good
    shutil.copytree(base / "run", tmp_path / "run")
    damage(tmp_path / "run")
    capsys.readouterr()
    status, out, err = run_cli(capsys, "chain", "--from", str(tmp_path / "run"), *ARGS, "--t-end", "600")
    _assert_refused(status, out, err, words)


def test_run_chain_refuses_a_state_of_another_model(good):
    """A state knows its model once a run made it: eq. (4)'s final state is refused by Carlson-Langer,
    and a state of unknown model (built from blocks) is accepted."""
    _, state = good
    assert state.model == model_of(_params())
    cl = chain_params("carlson-langer", N=N)
    with pytest.raises(ParameterError, match="it is a state of sakaguchi"):
        run_chain(cl, 10.0, start=state)
    with pytest.raises(ParameterError, match="must be a ChainState or a start name"):
        from stickslip.run.validate import check_start_state

        check_start_state(42, _params())
    blocks = state.blocks()
    plain = ChainState.from_blocks(blocks["x"], blocks["v"], blocks["theta"], blocks["stopped"])
    assert plain.model is None
    with pytest.raises(ValueError, match="differ in shape"):
        ChainState.from_blocks(blocks["x"], blocks["v"][:1], blocks["theta"], blocks["stopped"])


def test_good_states_still_run(good, tmp_path, capsys):
    """A good rung state and a good run directory are taken, and the run goes on in time."""
    base, state = good
    for source in (base / "rung", base / "run"):
        capsys.readouterr()
        status, out, err = run_cli(capsys, "chain", "--from", str(source), *ARGS, "--t-end", "400", "--json")
        assert status == 0, err
        assert json.loads(out)["t_end"] == pytest.approx(400.0)
    run = run_chain(_params(), 400.0, start=read_state_file(base / "rung" / "state.npz"))
    assert run.state.step == 80000 and run.state.model == model_of(_params())
