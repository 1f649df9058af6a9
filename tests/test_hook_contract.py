"""A hook's contract (stickslip.run.Hook) is checked where the loop calls it: a stop_at that does
not move on, or an at() that returns garbage, raises HookError naming the hook instead of hanging
or being ignored; a caller's stop from after() is kept."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stickslip.models.presets import chain_params
from stickslip.run import Hook, HookError, run_chain
from stickslip.run.errors import Interrupted


class StopsWhereItStands(Hook):
    def __init__(self, answer):
        self.answer = answer
        self.calls = 0

    def stop_at(self, n):
        self.calls += 1
        return self.answer(n)


@pytest.mark.timeout(120)
@pytest.mark.parametrize(
    "answer, says",
    [
        (lambda n: n, "must return a step after n"),
        (lambda n: 0, "must return a step after n"),
        (lambda n: n - 5, "must return a step after n"),
        (lambda n: math.nan, "integer step"),
        (lambda n: float(n + 10), "integer step"),
        (lambda n: None, "integer step"),
        (lambda n: True, "integer step"),
    ],
    ids=["n", "zero", "negative", "nan", "float", "none", "bool"],
)
def test_a_stop_at_that_does_not_move_on_is_refused_at_its_first_call(answer, says):
    hook = StopsWhereItStands(answer)
    with pytest.raises(HookError, match=rf"StopsWhereItStands\.stop_at\(0\) returned .*{says}"):
        run_chain(chain_params(N=4), 10.0, start="steady", hooks=[hook])
    # refused at the first call, not after spinning: the loop asked it once
    assert hook.calls == 1


class Garbage(Hook):
    def __init__(self, value):
        self.value = value

    def at(self, loop, n):
        return self.value


@pytest.mark.timeout(120)
@pytest.mark.parametrize("value", ["no", 1, 0.0, [], np.array([True])], ids=["str", "int", "float", "list", "array"])
def test_garbage_from_at_is_refused_naming_the_hook(value):
    with pytest.raises(HookError, match=r"hook Garbage\.at\(loop, 0\) returned .* must return True"):
        run_chain(chain_params(N=4), 10.0, start="steady", hooks=[Garbage(value)])


@pytest.mark.timeout(120)
@pytest.mark.parametrize("value", [None, False, np.bool_(False)])
def test_false_and_none_from_at_go_on(value):
    run = run_chain(chain_params(N=4), 10.0, start="steady", hooks=[Garbage(value)])
    assert run.state.step == 2000  # t_end / dt, dt = 0.005


class StopAfter(Hook):
    """Asks the run to stop, through loop.stopping, after its first kernel call past step 1000."""

    def stop_at(self, n):
        return (n // 1000 + 1) * 1000

    def after(self, loop, status, elapsed, now):
        if loop.state.step >= 1000:
            loop.stopping = True


@pytest.mark.timeout(120)
def test_a_hooks_stop_from_after_is_kept_and_stops_the_run():
    with pytest.raises(Interrupted) as info:
        run_chain(chain_params(N=4), 50.0, start="steady", hooks=[StopAfter()])
    # stopped at the first call that reached step 1000 (t = 5), long before t_end = 50
    assert info.value.t == pytest.approx(5.0)
