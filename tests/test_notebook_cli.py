"""Nothing lost silently, one spelling per option, progress where a person watches."""

from __future__ import annotations

import io
import sys

import pytest

from stickslip.cli import main
from stickslip.run import progress

SHORT = ["--N", "5", "--t-end", "1e3", "--no-progress"]


def test_chain_without_out_says_that_nothing_was_saved(capsys):
    assert main(["chain", *SHORT]) == 0
    out = capsys.readouterr().out
    assert "not written" in out and "--out DIR" in out
    assert "written to" not in out


def test_overwrite_treats_the_figures_plot_drew_as_the_runs_own(tmp_path, capsys):
    run = tmp_path / "run1"
    assert main(["chain", *SHORT, "--out", str(run)]) == 0
    assert main(["plot", str(run), "--format", "png"]) == 0
    assert (run / "figures" / "length.png").is_file()
    capsys.readouterr()
    # without --overwrite the finished run is kept, and the refusal says how to replace it
    assert main(["chain", *SHORT, "--out", str(run)]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert main(["chain", *SHORT, "--beta", "0.5", "--out", str(run), "--overwrite"]) == 0
    assert not (run / "figures").exists()  # the figures of the run they were drawn from went with it
    assert '"beta": 0.5' in (run / "run.json").read_text()


def test_a_figures_folder_with_other_files_is_not_the_runs(tmp_path, capsys):
    run = tmp_path / "run1"
    assert main(["chain", *SHORT, "--out", str(run)]) == 0
    (run / "figures").mkdir()
    (run / "figures" / "mine.txt").write_text("kept")
    capsys.readouterr()
    assert main(["chain", *SHORT, "--out", str(run)]) == 2
    assert "figures" in capsys.readouterr().err
    assert main(["chain", *SHORT, "--out", str(run), "--overwrite"]) == 0
    assert (run / "figures" / "mine.txt").read_text() == "kept"


def test_parameter_options_are_spelled_with_hyphens_and_the_old_spelling_still_works(capsys):
    with pytest.raises(SystemExit):
        main(["chain", "--help"])
    helptext = capsys.readouterr().out
    assert "--rs-a" in helptext and "--sigma-n" in helptext
    assert "--rs_a" not in helptext and "--sigma_n" not in helptext and "PARAM_L" not in helptext
    args = ["chain", "--friction", "rate-state", "--N", "3", "--t-end", "20", "--no-progress", "--json"]
    assert main([*args, "--rs-a", "0.02"]) == 0
    new = capsys.readouterr()
    assert "old spelling" not in new.err
    assert main([*args, "--rs_a", "0.02"]) == 0
    old = capsys.readouterr()
    assert "--rs_a is the old spelling of --rs-a" in old.err
    assert old.out.split('"wall_seconds"')[0] == new.out.split('"wall_seconds"')[0]
    # an option the model does not read is named as it is spelled
    assert main(["chain", *SHORT, "--sigma-n", "3"]) == 2
    assert "--sigma-n is not a parameter of this model" in capsys.readouterr().err


def test_help_gives_each_models_default():
    from stickslip.cli._common import model_defaults

    # written out from the presets' tables (docs/model.md, "Preset defaults")
    assert model_defaults("sigma", 0.01) == "0.01 (carlson-langer, two-blocks)"
    assert model_defaults("K", 10.0) == "10 (sakaguchi, train, batista-carlson), 100 (carlson-langer, two-blocks)"
    assert model_defaults("dt", 0.005) == "0.005"
    assert model_defaults("rs_a", 0.01).startswith("0.01; read by friction rate-state")


def _commands(parser, prefix=()):
    """Every command of the command line with its parser (sub-commands walked)."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*prefix, name))
    if prefix:
        yield prefix, parser


#: Each model's default, written out from the presets' tables (docs/model.md, "Preset defaults";
#: the single block's from its table there too): the chain's relatives, and the block's two models.
CHAIN_DEFAULTS = {
    "--K": "10 (sakaguchi, train, batista-carlson), 100 (carlson-langer, two-blocks)",
    "--beta": "1 (sakaguchi, train), 0.08 (batista-carlson)",
    "--sigma": "0.01 (carlson-langer, two-blocks)",
    "--V": "0.001 (sakaguchi, train), 0.01 (carlson-langer, two-blocks), 0.05 (batista-carlson)",
}
BLOCK_DEFAULTS = {
    "--V": "0.001 (sakaguchi), 0.05 (batista-carlson)",
    "--beta": "1 (sakaguchi), 0.08 (batista-carlson)",
    "--Fs": "3 (sakaguchi); not read by batista-carlson",
    "--sigma": "(default 1)",
}


def test_every_command_with_models_gives_each_models_defaults(monkeypatch):
    """A command that takes ``--model`` shows, for a parameter the models differ in, each model's
    default; one that runs only the paper's block shows its own."""
    from stickslip.cli import build_parser

    monkeypatch.setenv("COLUMNS", "1000")  # one line per option: no hyphen broken across lines
    checked = set()
    for command, parser in _commands(build_parser()):
        helps = {opt: a.help for a in parser._actions for opt in a.option_strings}
        if "--model" not in helps or "--beta" not in helps:
            continue
        chain = "--nu" in helps  # the chain's relatives (Carlson-Langer's symbols)
        for option, text in (CHAIN_DEFAULTS if chain else BLOCK_DEFAULTS).items():
            if option in helps:
                assert text in parser.format_help(), (command, option, helps[option])
        checked.add(" ".join(command))
    assert {"chain", "lyapunov", "stability chain", "block", "hysteresis"} <= checked
    slip = dict(_commands(build_parser()))[("slip-limit",)].format_help()
    assert "spring constant K (default 10)" in slip and "(sakaguchi)" not in slip


def test_progress_shows_only_where_someone_watches(monkeypatch):
    # under the tests stderr is no terminal and no notebook runs: the default shows nothing
    assert progress.show_progress(None) is False and progress.show_progress(False) is False
    monkeypatch.setattr(progress, "in_notebook", lambda: True)
    assert progress.show_progress(None) is True and progress.show_progress(False) is False
    # in a notebook without ipywidgets the text bar goes to stderr, which the notebook shows
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    bar = progress.Progress(100.0, True)
    bar.update(50.0, 3)
    bar.close()
    assert "t = 50/100" in err.getvalue() and "events=3" in err.getvalue()


@pytest.mark.slow  # a notebook in a real kernel (about 12 s, measured)
def test_a_notebook_shows_the_figures_and_the_progress_of_a_run(monkeypatch):
    """In a Jupyter kernel (the test extra installs one): a Figure that ends a cell is shown as an
    image though no pyplot figure came before it, and a run's bar goes to the cell's output."""
    from pathlib import Path

    import nbclient  # declared in the test extra, with ipykernel
    import nbformat

    import stickslip

    cells = [
        "import stickslip\nrun = stickslip.run_chain(stickslip.chain_params(N=10), 2e4, progress=True)",
        "run.plot_length()",
    ]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    src = str(Path(stickslip.__file__).resolve().parent.parent)
    code = f"import sys; sys.path.insert(0, {src!r})\n"
    nb.cells.insert(0, nbformat.v4.new_code_cell(code))
    monkeypatch.delenv("MPLBACKEND", raising=False)  # the tests' Agg; a notebook has its own
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3").execute()
    ran, drew = nb.cells[1], nb.cells[2]
    assert any(o.get("name") == "stderr" and "chain:" in o.get("text", "") for o in ran.outputs)
    assert any("image/png" in o.get("data", {}) for o in drew.outputs)
