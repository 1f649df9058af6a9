"""What a newcomer meets first: the first look of `stickslip chain`, the word on compilation, the
heartbeat off a terminal, `stickslip compile`, and argument errors with argparse's usage line."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import stickslip
from stickslip import heartbeat
from stickslip.cli import main
from stickslip.kernels._cache import COMPILE_NOTICE, cache_dir
from stickslip.models import physics
from stickslip.models.presets import chain_params

_SCRIPT = """
import numpy as np
from stickslip.kernels import triggers
from stickslip.kernels.entry import specialise_call
from stickslip.models.drive import end
args = (np.zeros(5), 3, 1.0, 0.01, 1.0, 0.5, 0, 1000, end.Params(), end.__name__, "stickslip.models.ends.free")
print(specialise_call(triggers._first_trigger, args, {9, 10}))
"""


def _kernel_call(cache: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(Path(stickslip.__file__).parent.parent))
    return subprocess.run([sys.executable, "-c", _SCRIPT], env=env, capture_output=True, text=True)


def test_compiling_says_so_once_and_loading_from_the_cache_says_nothing(tmp_path):
    first = _kernel_call(tmp_path)
    assert first.returncode == 0, first.stderr
    assert first.stdout.strip() == "51"
    assert first.stderr.count(COMPILE_NOTICE) == 1
    again = _kernel_call(tmp_path)
    assert again.returncode == 0 and again.stdout.strip() == "51"
    assert COMPILE_NOTICE not in again.stderr
    # The kernels are cached in a directory of this version of the kernel modules, under the user's setting.
    assert [p.name for p in tmp_path.iterdir()] == [f"stickslip-{stickslip.kernels._cache.DIGEST[:20]}"]


def test_cache_dir_follows_numba_cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert cache_dir().parent == tmp_path


def test_heartbeat_writes_the_latest_note_at_each_interval():
    out = io.StringIO()
    with heartbeat.heartbeat("sweep", interval=0.05, enabled=True, stream=out):
        heartbeat.note("3 of 12 points done")
        time.sleep(0.3)
    lines = out.getvalue().splitlines()
    assert len(lines) >= 2
    assert all(line.startswith("stickslip sweep: running for ") for line in lines)
    assert lines[-1].endswith("; 3 of 12 points done")


def test_heartbeat_is_silent_on_a_terminal():
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    out = Terminal()
    with heartbeat.heartbeat("chain", interval=0.01, stream=out):
        time.sleep(0.1)
    assert out.getvalue() == ""


@pytest.mark.slow  # a long chain off a terminal (13 s, measured)
def test_a_long_chain_off_a_terminal_beats(monkeypatch, capsys):
    monkeypatch.setattr(heartbeat, "INTERVAL", 0.05)
    assert main(["chain", "--N", "49", "--t-end", "2e6", "--json"]) == 0
    err = capsys.readouterr().err
    beats = [line for line in err.splitlines() if line.startswith("stickslip chain: running for ")]
    assert beats and "events" in beats[-1] and "chain t = " in beats[-1]


@pytest.mark.filterwarnings("always::stickslip.run.errors.ShortRunWarning")
def test_chain_without_options_is_a_first_look_with_events(capsys):
    assert main(["chain", "--json"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    p = chain_params("sakaguchi", N=physics.FIRST_LOOK_N)
    assert data["L_steady"] == pytest.approx(physics.chain_steady_length(p))
    assert data["t_end"] == 5e5 >= 4 * physics.loading_time(p)
    assert data["n_events"] > 100
    assert abs(data["L_mean"] - data["L_steady"]) < 0.1 * data["L_steady"]  # past the loading
    assert "warning" not in err


@pytest.mark.filterwarnings("ignore::stickslip.run.errors.ShortRunWarning")
def test_with_t_end_the_defaults_are_the_papers(capsys):
    # N = 399: the floor `stickslip chain --beta 1 --t-end 2e7` keeps its answer.
    assert main(["chain", "--beta", "1", "--t-end", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["L_steady"] == pytest.approx(physics.chain_steady_length(chain_params("sakaguchi")))
    assert data["L_steady"] == pytest.approx(7940.1)


def test_first_look_t_end_is_four_loading_times_rounded_up():
    assert physics.first_look_t_end(chain_params("sakaguchi", N=49)) == 5e5
    assert physics.first_look_t_end(chain_params("sakaguchi")) == 4e7
    assert physics.first_look_t_end(chain_params("carlson-langer")) != physics.first_look_t_end(
        chain_params("carlson-langer")
    )  # NaN: the plate drive loads every block at once


def test_compile_command(capsys):
    assert main(["compile", "--model", "two-blocks", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data["models"]) == ["two-blocks"]
    assert data["cache"] == str(cache_dir())


@pytest.mark.parametrize(
    "argv, usage, hint",
    [
        (["chian"], "usage: stickslip [-h]", "did you mean 'chain'?"),
        (["chain", "--model", "sakaguch"], "usage: stickslip chain [-h]", "did you mean 'sakaguchi'?"),
        (["chain", "--modle", "train"], "usage: stickslip chain [-h]", "did you mean '--model'?"),
        (["block", "--t-endd", "3"], "usage: stickslip block [-h]", "did you mean '--t-end'?"),
    ],
)
def test_argument_errors_keep_the_usage_line_and_suggest(argv, usage, hint, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(usage)
    last = err.rstrip("\n").splitlines()[-1]
    assert last.startswith("stickslip") and ": error: " in last and last.endswith(hint)
