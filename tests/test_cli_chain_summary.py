"""The text summary of `stickslip chain`: a sliding chain is said to slide; a resumed run's wall times."""

from stickslip.cli import main


def test_a_chain_with_every_block_moving_is_said_to_slide(capsys):
    args = ["chain", "--N", "20", "--beta", "1.5", "--start", "steady", "--t-end", "1e3", "--no-progress"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "the chain slides" in out and "--until-steady" in out
    assert "one in progress" not in out


def test_a_resumed_run_reports_this_run_and_the_total(tmp_path, capsys):
    out = tmp_path / "run"
    # a finished run keeps its checkpoint only on request, and a longer resume needs it
    first = ["chain", "--N", "20", "--t-end", "3e4", "--out", str(out), "--keep-checkpoint", "--no-progress"]
    assert main(first) == 0
    assert main(["chain", "--resume", str(out), "--t-end", "6e4", "--no-progress"]) == 0
    text = capsys.readouterr().out.splitlines()
    wall = [line for line in text if line.startswith("wall time")]
    assert "s in all (resumed)" in wall[-1] and "this run" in wall[-1]
