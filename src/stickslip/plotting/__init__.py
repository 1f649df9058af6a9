"""Figures of the block and the chain: every function returns a matplotlib Figure; none calls show().

The chain's figures, from a run (:func:`~stickslip.run.driver.run_chain`, or a run directory read
back with :func:`~stickslip.run.rundir.load_run`), each drawn into ``ax`` when one is given:

=========================  ===============================================================
:func:`length`             L(t) = x_1 - x_N against steady sliding and the loading time
:func:`snapshot`           the state (or a stored snapshot) against steady sliding (Fig. 5a)
:func:`sizes`              slip-size distribution with its power-law fit (Figs. 7, 8)
:func:`fronts`             rupture fronts of the largest events (Fig. 6)
:func:`run_figures`        every figure a run supports (what ``stickslip plot`` draws)
:func:`save_figure`        a Figure as PNG and PDF, written atomically
=========================  ===============================================================

and from tables: :func:`length_against_beta` (Fig. 5b), :func:`snapshot_figure`,
:func:`sizes_figure`, :func:`fronts_figure`, and :func:`loops_figure` (the hysteresis loops of the
transition at beta_c = 1, from
:func:`~stickslip.experiments.studies.transition.transition_loop`). The paper's names (``fig5a_snapshot``,
``fig5b_length``, ``fig6_fronts``, ``fig7_8_sizes``) stay as aliases. Titles name the model and
the parameters it reads; "Fig. N" appears only on the paper's own runs.
:mod:`stickslip.plotting.figures` draws the report of ``stickslip reproduce``.

Examples
--------
>>> import stickslip, stickslip.plotting as ssp
>>> run = stickslip.run_chain(stickslip.chain_params(N=10), 2e4)
>>> fig = ssp.length(run)
>>> print(fig.axes[0].get_title(loc="left"))
$L(t)$
eq. (4): $N=10$, $K=10$, $V=0.001$, $\\beta=1$, $\\alpha=1$, $D=5$, $F_s=3$
"""

from stickslip.lazy import lazy_names

#: Names loaded on first use (matplotlib and the analysis load with them), and their modules.
_LAZY = {
    "length": "stickslip.plotting.run",
    "snapshot": "stickslip.plotting.run",
    "sizes": "stickslip.plotting.run",
    "fronts": "stickslip.plotting.run",
    "run_figures": "stickslip.plotting.run",
    "draw_run_figures": "stickslip.plotting.run",
    "length_against_beta": "stickslip.plotting.chain",
    "snapshot_figure": "stickslip.plotting.chain",
    "sizes_figure": "stickslip.plotting.chain",
    "fronts_figure": "stickslip.plotting.chain",
    "fig5a_snapshot": "stickslip.plotting.chain",
    "fig5b_length": "stickslip.plotting.chain",
    "fig6_fronts": "stickslip.plotting.chain",
    "fig7_8_sizes": "stickslip.plotting.chain",
    "loops_figure": "stickslip.plotting.ladders",
    "save_figure": "stickslip.plotting.style",
    "new_figure": "stickslip.plotting.style",
}

__all__ = list(_LAZY)


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
