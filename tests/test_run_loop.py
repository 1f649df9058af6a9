"""The run loop of a chain run: its hooks, the checked advance it shares with Stepper, RunOptions
as run_chain's options and as the command line's run options."""

from __future__ import annotations

import re

import pytest

from chain_helpers import oracle_run
from stickslip.cli import build_parser
from stickslip.cli._common import run_options_from_args
from stickslip.kernels import layout
from stickslip.models.params import ChainParams, ParameterError
from stickslip.models.presets import chain_params
from stickslip.run import Hook, Loop, RunOptions, resume_chain, run_chain
from stickslip.run.driver import Interrupted, NonFiniteState, Stepper, initial_state, load_run
from stickslip.run.loop import NEVER, CheckedAdvance, ChunkTuning, _par, _scratch, run_loop
from stickslip.run.outputs import _Outputs

# The final state of the chain of N = 10 blocks run to t = 2e4 (ChainRun's docstring example).
SHA_N10_2E4 = "ef0a3122809af663"


def test_options_given_as_run_options_are_the_keywords_run():
    """options=RunOptions(...) records what the same keywords record, and ends on the state of
    the documented example run."""
    p = chain_params(N=10)
    fields = dict(sample_interval=2.5, snapshot_times=(5000.0, 1.5e4), profile_window=20.0, sample_moving=True)
    by_options = run_chain(p, 2e4, options=RunOptions(**fields))
    by_keywords = run_chain(p, 2e4, **fields)
    assert by_options.summary["state_sha256"].startswith(SHA_N10_2E4)
    assert by_options.summary["state_sha256"] == by_keywords.summary["state_sha256"]
    assert by_options.events.equals(by_keywords.events)
    assert by_options.samples.equals(by_keywords.samples)
    assert by_options.snapshots.equals(by_keywords.snapshots)
    assert by_options.profiles.equals(by_keywords.profiles)
    assert list(by_options.snapshots["snapshot_time"].values) == [5000.0, 1.5e4, 2e4]
    assert by_options.options == RunOptions(t_end=2e4, **fields)


def test_keywords_replace_the_fields_of_run_options_and_bad_ones_are_refused():
    p = chain_params(N=4)
    run = run_chain(p, 10.0, options=RunOptions(sample_interval=2.0, integrator="dense"), sample_interval=5.0)
    assert run.options == RunOptions(t_end=10.0, sample_interval=5.0, integrator="dense")
    assert list(run.samples["t"].values) == [0.0, 5.0, 10.0]
    with pytest.raises(ParameterError, match="differs"):
        run_chain(p, 10.0, options=RunOptions(t_end=20.0))
    with pytest.raises(TypeError, match="sample_every"):
        run_chain(p, 10.0, sample_every=5)
    with pytest.raises(ParameterError, match="t_end must be given"):
        RunOptions().validated(0.005)
    with pytest.raises(ParameterError, match="integrator must be one of exact, dense"):
        run_chain(p, 10.0, integrator="euler")
    with pytest.raises(ParameterError, match="checkpoint_interval"):
        run_chain(p, 10.0, options=RunOptions(checkpoint_interval=0.0))
    with pytest.raises(ParameterError, match="hooks must be Hook instances"):
        run_chain(p, 10.0, hooks=[print])


def test_a_run_keeps_what_it_recorded_not_how_it_ran(tmp_path):
    """A ChainRun's options, fresh or read back from its run directory, are what the run recorded
    and its integrator; where it wrote, its progress and its hooks are not kept."""
    p = chain_params(N=4)
    how = RunOptions(integrator="dense", out_dir=tmp_path / "run", progress=False, hooks=[Hook()], run_id=None)
    run = run_chain(p, 10.0, options=how, sample_interval=2.5)
    assert run.options == RunOptions(t_end=10.0, sample_interval=2.5, integrator="dense")
    assert load_run(tmp_path / "run").options == run.options
    assert run.summary["integrator"] == "dense"


class _Stops(Hook):
    """Asks for the kernel to stop at fixed steps and notes the steps it acts at."""

    def __init__(self, steps):
        self.steps, self.seen = steps, []

    def stop_at(self, n):
        return min((s for s in self.steps if s > n), default=NEVER)

    def at(self, loop, n):
        self.seen.append(n)
        return False


def test_hooks_stop_the_kernel_where_they_ask_and_change_no_bit():
    """A hook is served at each step it asks for (the kernel stops there), and the run ends on
    the bits of a run without it (t = 50: 10000 steps of dt = 0.005)."""
    p = chain_params(N=10)
    state = initial_state(p, "paper")
    state.ist[layout.NEXT_SAMPLE] = 0
    outputs = _Outputs(p.N, False)
    advance = CheckedAdvance("exact", p, state, _scratch(p.N), _par(p), outputs, (2000, 0, 0, 0))
    stops = _Stops([1234, 5678, 5679])
    run_loop(Loop(p, state, outputs, 10000), advance, [stops, ChunkTuning()])
    assert {0, 1234, 5678, 5679, 10000} <= set(stops.seen)
    assert state.step == 10000
    assert state.sha256() == run_chain(p, 50.0).state.sha256()


class _Every(Hook):
    """A caller's hook: the kernel stops at the multiples of ``every`` steps, and x, v, theta are
    kept there; an ``end`` step ends the run."""

    def __init__(self, every, end=None):
        self.every, self.end, self.kept, self.closed = every, end, {}, 0

    def stop_at(self, n):
        return (n // self.every + 1) * self.every

    def at(self, loop, n):
        if n % self.every == 0:
            s = loop.state
            self.kept[n] = (s.xg.copy(), s.vg.copy(), s.thg.copy(), s.mov.copy())
        return n == self.end

    def close(self):
        self.closed += 1


def _same_bits(kept, state):
    now = (state.xg, state.vg, state.thg, state.mov)
    return all(a[1:-1].tobytes() == b[1:-1].tobytes() for a, b in zip(kept, now, strict=True))


@pytest.mark.parametrize("integrator", ["exact", "dense"])
def test_a_callers_hook_acts_at_its_steps_on_the_state_of_a_run_that_ends_there(integrator):
    """A hook given as RunOptions(hooks=...) acts at each multiple of 1234 steps (off L's grid of
    2000) and there sees, bit for bit, the final state of a run to that time; the run itself ends
    on the bits of a run without it, and the hook is closed once."""
    p = chain_params(N=10)
    hook = _Every(1234)
    run = run_chain(p, 50.0, options=RunOptions(integrator=integrator, hooks=[hook]))
    assert sorted(hook.kept) == [0, 1234, 2468, 3702, 4936, 6170, 7404, 8638, 9872]
    for n in (1234, 6170, 9872):
        assert _same_bits(hook.kept[n], run_chain(p, n * p.dt, integrator=integrator).state), n
    assert run.summary["state_sha256"] == run_chain(p, 50.0).summary["state_sha256"]
    assert hook.closed == 1


def test_a_hook_ends_a_run_and_serves_a_resumed_one(tmp_path):
    """A hook's True ends the run at its step; resume_chain serves a hook given to it from the
    checkpoint's step on, and ends where an uninterrupted run ends."""
    p = chain_params(N=10)
    early = run_chain(p, 50.0, hooks=[_Every(1000, end=3000)])
    assert early.steps == 3000 and early.state.sha256() == run_chain(p, 15.0).state.sha256()
    asked = iter([False, True])
    with pytest.raises(Interrupted):
        run_chain(p, 2e4, out_dir=tmp_path / "r", stop_requested=lambda: next(asked, True))
    hook = _Every(500_000)
    resumed = resume_chain(tmp_path / "r", hooks=[hook])
    assert min(hook.kept) > 0 and sorted(hook.kept) == list(range(min(hook.kept), 4_000_001, 500_000))
    assert resumed.summary["state_sha256"].startswith(SHA_N10_2E4)


@pytest.mark.parametrize("integrator", ["dense", "exact"])
def test_stepper_reports_a_nonfinite_state_at_the_oracles_step_and_block(integrator):
    """Stepper goes through run_chain's checked advance: a stiff spring blows the explicit step
    up, and the error names the step and block of the plain-Python oracle."""
    N, K = 5, 1e6
    p = ChainParams(N=N, K=K)
    step, block = oracle_run([0.0] * N, [0.1] * N, [0.1] * N, [True] * N, p, 2000).nonfinite
    with pytest.raises(NonFiniteState) as info:
        Stepper(p, integrator).advance(initial_state(p, "paper"), 2000)
    msg = str(info.value)
    t = re.search(r"t = ([-+0-9.eE]+)", msg)
    assert float(t.group(1)) == pytest.approx(step * p.dt, rel=1e-5)
    assert int(re.search(r"block (\d+)", msg).group(1)) == block


def test_a_replay_restores_the_state_in_place():
    """The exact kernel's non-finite call is replayed with dense from the values before it, in
    the state's own arrays: a holder of those arrays (the loop's outputs, a hook) sees the replay,
    and the arrays' values before the call are the ones dense starts from (the replay ends at the
    oracle's step, as a dense run from the start does)."""
    N, K = 5, 1e6
    p = ChainParams(N=N, K=K)
    step, _ = oracle_run([0.0] * N, [0.1] * N, [0.1] * N, [True] * N, p, 2000).nonfinite
    state = initial_state(p, "paper")
    held = (state.xg, state.vg, state.thg, state.mov, state.ist)
    advance = CheckedAdvance("exact", p, state, _scratch(N), _par(p), _Outputs(N, False), (2000, 0, 0, 0))
    with pytest.raises(NonFiniteState):
        advance(state, 2000)
    assert all(a is b for a, b in zip(held, (state.xg, state.vg, state.thg, state.mov, state.ist), strict=True))
    assert state.step == step  # where a dense run from the start stops


def test_stepper_ends_where_run_chain_ends():
    p = chain_params(N=10)
    state, events = Stepper(p).advance(initial_state(p, "paper"), 4_000_000)
    assert state.sha256().startswith(SHA_N10_2E4) and events == 69


def test_command_line_run_options_are_run_options_fields(capsys):
    """`stickslip chain` has one option per RunOptions field with a command-line spelling, and
    they build the RunOptions the run gets (the field's default where not given)."""
    parser = build_parser()
    args = parser.parse_args(
        ["chain", "--sample-interval", "2.5", "--snapshot", "5", "--snapshot", "7", "--profile-min-blocks", "3"]
    )
    options = run_options_from_args(args, 100.0)
    assert options == RunOptions(t_end=100.0, sample_interval=2.5, snapshot_times=(5.0, 7.0), profile_min_blocks=3)
    with pytest.raises(SystemExit):
        parser.parse_args(["chain", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    for flag in ("--sample-interval T", "--average-from T", "--snapshot T", "--profile-window W"):
        assert flag in help_text
    assert "--profile-min-blocks M" in help_text and "--until-steady TOL" in help_text
    assert "--sample-moving" not in help_text


def test_command_line_run_control_options_are_run_options_fields(capsys, monkeypatch):
    """--integrator, --out, --checkpoint-interval, --keep-checkpoint and --no-progress are made
    from RunOptions' fields too: the parsed options are the fields, and --help gives each the
    help its field carries."""
    import dataclasses

    parser = build_parser()
    control = ["--integrator", "dense", "--out", "d", "--checkpoint-interval", "5", "--keep-checkpoint"]
    options = run_options_from_args(parser.parse_args(["chain", *control, "--no-progress"]), 100.0)
    expected = dict(integrator="dense", out_dir="d", checkpoint_interval=5.0, keep_checkpoint=True, progress=False)
    assert options == RunOptions(t_end=100.0, **expected)
    assert run_options_from_args(parser.parse_args(["chain"]), 100.0) == RunOptions(t_end=100.0)
    with pytest.raises(SystemExit):
        parser.parse_args(["chain", "--integrator", "euler"])
    assert "invalid choice: 'euler'" in capsys.readouterr().err
    monkeypatch.setenv("COLUMNS", "1000")  # one line per option: no help text broken across lines
    with pytest.raises(SystemExit):
        build_parser().parse_args(["chain", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    spelled = {
        "integrator": "--integrator {exact,dense}",
        "out_dir": "--out DIR",
        "checkpoint_interval": "--checkpoint-interval SECONDS",
        "keep_checkpoint": "--keep-checkpoint",
        "progress": "--no-progress",
    }
    fields = {f.name: f for f in dataclasses.fields(RunOptions)}
    for name, flag in spelled.items():
        assert f"{flag} {fields[name].metadata['cli']['help']}" in help_text, name
