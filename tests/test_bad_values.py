"""Values that overflowed into a traceback, and options that were ignored or refused late, are
refused in one line before anything runs (docs/limits.md, "Bad inputs accepted before")."""

from __future__ import annotations

import shlex

import pytest

from chain_helpers import error_lines
from stickslip.cli import main

LOCATED = "lyapunov --switches located --N 5 --t-end 200 --finite-size"

# (command, words of the one line); before, each was a traceback (OverflowError)
OVERFLOWS = [
    ("chain --start steady --perturbation 1e308 --N 5 --t-end 10", "perturbation must be >= 0 and <= 1e+300"),
    ("chain --start rest --perturbation 1e308 --N 5 --t-end 10", "perturbation must be >= 0 and <= 1e+300"),
    ("chain --start steady --perturbation 1e308 --N 5 --t-end 10 --out o", "perturbation"),
    ("lyapunov --start steady --perturbation 1e308 --N 5", "perturbation must be >= 0 and <= 1e+300"),
    (f"{LOCATED} --check 1e300", "check must be >= 0.005 and <= 200"),
    (f"{LOCATED} --delta-min 1e-300 --delta-max 1e300", "delta_max / delta_min must be <= ratio^199"),
]


def _tree(path):
    return sorted(str(p.relative_to(path)) for p in path.rglob("*"))


def _refused(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    try:
        status = main(shlex.split(argv))
    except SystemExit as exc:
        status = exc.code
    out, err = capsys.readouterr()
    assert status == 2, err
    assert out == "" and "Traceback" not in err, err
    assert len(error_lines(err)) == 1, err
    assert words in err, err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("argv, words", OVERFLOWS, ids=[c for c, _ in OVERFLOWS])
def test_huge_values_are_one_line(argv, words, tmp_path, monkeypatch, capsys):
    _refused(argv, words, tmp_path, monkeypatch, capsys)


# (command, words); before, the first ran every ladder and only then refused N, the others ran
# with the option ignored, and --loads 1e308 was refused naming an internal t_max
IGNORED = [
    ("study transition --tiny --extra-n 2000000 --out o", "extra-n must be >= 3 and <= 1e+06"),
    ("study transition --tiny --extra-n 2.5 --out o", "extra-n"),
    ("lyapunov --lifetimes 5 --betas 0.5,1", "--betas does not go with --lifetimes"),
    ("lyapunov --lifetimes 5 --switches located", "--switches located does not go with --lifetimes"),
    ("lyapunov --lifetimes 5 --convergence", "--convergence does not go with --lifetimes"),
    ("lyapunov --front-block 3", "--front-block goes with --fronts"),
    ("lyapunov --switches located --finite-size --front-block 2", "--front-block goes with --fronts"),
    ("lyapunov --switches located --delta-min 1e-8", "--delta-min goes with --finite-size"),
    ("lyapunov --delta-max 1e-3", "--delta-max goes with --finite-size"),
    ("lyapunov --cycles 3", "--cycles goes with --finite-size"),
    ("lyapunov --switches located --fronts --check 0.5", "--check goes with --finite-size"),
    ("lyapunov --loads 3", "--loads goes with --lifetimes"),
    ("lyapunov --lifetimes 5 --loads 1e308", "--loads must be <="),
]


@pytest.mark.parametrize("argv, words", IGNORED, ids=[c for c, _ in IGNORED])
def test_options_ignored_or_refused_late_are_one_line(argv, words, tmp_path, monkeypatch, capsys):
    _refused(argv, words, tmp_path, monkeypatch, capsys)
    assert "t_max" not in capsys.readouterr().err


@pytest.mark.parametrize(
    "stem, written",
    [
        ("lam_beta0.9", ["lam_beta0.9.png", "lam_beta0.9.pdf"]),  # before: lam_beta0.png
        ("x.bmp3", ["x.bmp3.png", "x.bmp3.pdf"]),  # before: x.png, where the docs promise x.bmp3.png
        ("fig3", ["fig3.png", "fig3.pdf"]),
    ],
)
def test_a_figure_keeps_its_whole_name(stem, written, tmp_path):
    from stickslip.plotting.style import new_figure, save_figure

    fig, _ = new_figure()
    paths = save_figure(fig, tmp_path / stem)
    assert [p.name for p in paths] == written
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(written)


def test_lyapunov_plot_name_with_a_dot(tmp_path, capsys):
    """`lyapunov --plot lam_beta0.9` writes lam_beta0.9.png and .pdf; a .png given is dropped."""
    argv = ["lyapunov", "--N", "3", "--t-end", "500", "--segments", "4", "--betas", "0.5,1.0"]
    assert main([*argv, "--plot", str(tmp_path / "lam_beta0.9")]) == 0
    assert main([*argv, "--plot", str(tmp_path / "b.png")]) == 0
    capsys.readouterr()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.pdf", "b.png", "lam_beta0.9.pdf", "lam_beta0.9.png"]
