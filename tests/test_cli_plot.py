"""`stickslip plot RUN_DIR`: the figures a chain run directory supports."""

import json

import pytest

from stickslip.cli import main


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("plot") / "run"
    assert (
        main(
            [
                "chain",
                "--N",
                "20",
                "--t-end",
                "1e5",
                "--average-from",
                "5e4",
                "--profile-window",
                "20",
                "--profile-min-blocks",
                "10",
                "--snapshot",
                "5e4",
                "--out",
                str(out),
                "--no-progress",
            ]
        )
        == 0
    )
    return out


@pytest.mark.slow  # every figure drawn (about 50 s, measured)
def test_plot_draws_every_supported_figure(run_dir, capsys):
    capsys.readouterr()
    assert main(["plot", str(run_dir), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    drawn = {r["figure"]: r for r in data["figures"]}
    for stem in ("length", "snapshot_final", "snapshot_t50000", "sizes", "fronts"):
        assert stem in drawn and "files" in drawn[stem], drawn.get(stem)
        for ext in ("png", "pdf"):
            assert (run_dir / "figures" / f"{stem}.{ext}").stat().st_size > 1000


def test_plot_says_what_it_cannot_draw(tmp_path, capsys):
    out = tmp_path / "short"
    assert main(["chain", "--N", "5", "--t-end", "200", "--out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["plot", str(out), "--out", str(tmp_path / "figs"), "--format", "png"]) == 0
    text = capsys.readouterr().out
    assert "fronts" in text and "not drawn: no displacement profiles stored" in text
    assert "sizes            not drawn" in text
    assert (tmp_path / "figs" / "length.png").exists() and not (tmp_path / "figs" / "length.pdf").exists()


def test_plot_refuses_a_directory_without_a_run(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) == 2
    assert "not a finished chain run directory" in capsys.readouterr().err
