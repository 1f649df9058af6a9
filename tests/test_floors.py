"""The floors as tests: the final state hash and event count of short runs, pinned.

Each row is a model of the family (the five presets and the compositions whose fast paths differ:
the rate-and-state laws with the end and the plate drive, Carlson-Langer with the end drive, the
state threshold with free and fixed ends, the ring with the plate and the state threshold), run
by both integrators from the start given, to the end given. The hashes were taken from the code
before per-block parameters entered the kernels; a change to any kernel that moves a bit of any
of these runs fails here. The bench workload (``stickslip bench``) and the located integrator's
fast form are pinned too, and the paper's beta = 1 run to t = 2e7 (``567924f9...``, 71,867 events;
docs/performance.md) is the slow test at the end.

The default run pins the rows whose composition is a preset's (the kernels ``stickslip compile``
has compiled ahead), the bench workload and the located floor; the rows of the other
compositions are pinned by the slow run (``pytest -m slow``), so that the default run compiles
none of their kernels for these rows.
"""

from __future__ import annotations

import pytest

from stickslip.models.presets import PRESETS, chain_params
from stickslip.run.driver import run_chain

# id: (preset, overrides, t_end, start, perturbation, seed, state sha256, events)
FLOORS = {
    "sakaguchi": (
        "sakaguchi", dict(N=49), 5e4, "paper", 0.0, 0,
        "17532aef30eda4bccbe435aea12e651065e7de4a63fcd73c97349bc51b3d3ffe", 174,
    ),
    "sakaguchi-beta0.5": (
        "sakaguchi", dict(N=49, beta=0.5), 5e4, "paper", 0.0, 0,
        "07c7bfda07c3953339a504cfa1b5f5e181503d636a687e3f97c02b3dec196925", 165,
    ),
    "sakaguchi-steady-beta1.3": (
        "sakaguchi", dict(N=49, beta=1.3), 2e4, "steady", 0.01, 3,
        "1f9f3023a1ae26bbb8c3cc71061e28e9875fa0959ac53285676bfe6ed2b47e4c", 73,
    ),
    "carlson-langer": (
        "carlson-langer", dict(), 2e3, "rest", 0.01, 0,
        "4fb03026e42151bccf7c4ac81d803a4cdc2829173952ac3beba9528885622073", 1150,
    ),
    "train": (
        "train", dict(N=49), 5e4, "paper", 0.0, 0,
        "96345d40901a04407366efed3b31dcd616ec19ae2d8a9c672f3ce162f36523cf", 183,
    ),
    "batista-carlson": (
        "batista-carlson", dict(), 2e3, "rest", 0.0, 0,
        "4ba550af701a2189b0fb2f22ac2f8343846ef776084fa7aee2191aa510dfbb92", 886,
    ),
    "two-blocks": (
        "two-blocks", dict(), 2e3, "rest", 0.01, 0,
        "ce16240870aa0ffe0062b415d84459b5379b27a68c3a173b3fb3158c94ce3f57", 84,
    ),
    "rate-state-end": (
        "sakaguchi", dict(N=25, friction="rate-state", K=5.0), 2e4, "paper", 0.0, 0,
        "461921e5f788c4d8f989289ae1c588f000bcfd959bc6ecefdf954ecdb4eb34af", 3220,
    ),
    "rate-state-plate": (
        "sakaguchi", dict(N=25, friction="rate-state", drive="plate", K=5.0), 2e4, "paper", 0.0, 0,
        "d496d19318f4025e229e88b1aae3fc2969fdcc2e9d3fe656ed5266086028f8ed", 1926,
    ),
    "rate-state-slip-end": (
        "sakaguchi", dict(N=5, friction="rate-state-slip", K=5.0), 2e4, "steady", 0.01, 1,
        "ffe9e6a8842bf8bff3f8f7be7217e399eee1dfe0baba0eadeb146af26a02eac5", 231,
    ),
    "carlson-langer-end": (
        "carlson-langer", dict(drive="end", ends="free", N=49), 2e3, "rest", 0.01, 0,
        "a2b8852fe976a5f15dffdda118949cb2119002cfc7c75a38c4ca9ec972127442", 346,
    ),
    "state-threshold": (
        "sakaguchi", dict(N=49, beta=0.9, threshold="state"), 2e4, "steady", 0.05, 0,
        "4d9ef60ab8f6429e15b6e8f3df8ef8c80bd0a3190133d350162acbba5057b9b7", 0,
    ),
    "state-threshold-fixed": (
        "sakaguchi", dict(N=49, threshold="state", ends="fixed"), 2e4, "paper", 0.0, 0,
        "bda051e2af44560a90d3dde5f7288ce41ae0cdab94061d9233954874aa3064d0", 0,
    ),
    "weakening-end-fixed": (
        "carlson-langer", dict(N=49, drive="end", ends="fixed"), 2e3, "rest", 0.01, 0,
        "78fa006742064248a667e1ff40f764abbf7088eb40c6ff5fa47019e8878d15e5", 276,
    ),
    "plate-state-periodic": (
        "sakaguchi", dict(N=49, beta=0.5, drive="plate", threshold="state", ends="periodic"), 2e4, "rest", 0.01, 0,
        "863f40ed8845df2f2818324f9dbce697ae7662f6484e130a07c489cf923ec014", 1306,
    ),
    "plate-weakening-free": (
        "carlson-langer", dict(ends="free"), 2e3, "rest", 0.01, 0,
        "15adc14d132d68b47e6dfc0bbb4541c7e2f61beb6aeca18c5df774e403c2e101", 1286,
    ),
    "strengthening-end-free-steady": (
        "train", dict(N=49, beta=0.5), 2e4, "steady", 0.01, 2,
        "70a71b43906a9a488fcc5b226501b3d5666d993e73f444923a0310da39c5a1bd", 68,
    ),
}  # fmt: skip


def _preset_composition(case: str) -> bool:
    """Whether the row's pieces are those of a preset (compiled by ``stickslip compile``)."""
    model, overrides = FLOORS[case][:2]
    return chain_params(model, **overrides).pieces in [chain_params(name).pieces for name in PRESETS]


@pytest.mark.parametrize("integrator", ["exact", "dense"])
@pytest.mark.parametrize(
    "case", [c if _preset_composition(c) else pytest.param(c, marks=pytest.mark.slow) for c in sorted(FLOORS)]
)
def test_short_run_hash_is_pinned(case, integrator):
    model, overrides, t_end, start, perturbation, seed, sha, events = FLOORS[case]
    params = chain_params(model, **overrides)
    run = run_chain(params, t_end, start=start, perturbation=perturbation, seed=seed, integrator=integrator)
    assert (run.summary["state_sha256"], run.summary["n_events"]) == (sha, events)


def test_bench_workload_hash_is_pinned():
    """`stickslip bench`'s default workload (the paper's chain, N = 399, beta = 1, t = 2e5), exact."""
    run = run_chain(chain_params("sakaguchi", beta=1.0), 2e5, start="paper")
    assert run.summary["state_sha256"] == "34c373bce05995147702f85e8006504dafc2476b331735136c29ea6889615045"
    assert run.summary["n_events"] == 718


def test_located_fast_and_dense_forms_are_pinned():
    """The located-switch integrator's two forms on the bench's located workload, shortened."""
    from stickslip.run import bench

    result = bench.located(chain_params("sakaguchi", N=99, beta=0.5), t_prepare=5e4, t_timed=2000.0)
    assert result["identical"]
    assert result["state_sha256"] == "6613840eaf6b46efdea1f08d4fe23d4d9b9e368414f8fe1cad5114116d5502f7"
    assert result["n_events"] == 6


@pytest.mark.slow
def test_paper_beta_one_run_is_pinned():
    """`stickslip chain --beta 1 --t-end 2e7`: state hash 567924f9...26adf and 71,867 events."""
    run = run_chain(chain_params("sakaguchi", beta=1.0), 2e7, start="paper")
    assert run.summary["state_sha256"].startswith("567924f9")
    assert run.summary["state_sha256"].endswith("26adf")
    assert run.summary["n_events"] == 71867
