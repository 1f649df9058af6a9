"""Running the model: the single block (eq. 1) and the chain (eq. 4).

:mod:`~stickslip.run.driver` runs and resumes the chain (:func:`~stickslip.run.driver.run_chain`),
through its run loop (:mod:`~stickslip.run.loop`), from its state (:mod:`~stickslip.run.state`),
output buffers and results
(:mod:`~stickslip.run.outputs`), checkpoints (:mod:`~stickslip.run.checkpoint`) and run
directories (:mod:`~stickslip.run.rundir`); :mod:`~stickslip.run.block` runs the single block;
:mod:`~stickslip.run.bench` times the chain's integrators.

Public here: :func:`~stickslip.run.driver.run_chain` and :func:`~stickslip.run.driver.resume_chain`,
their options (:class:`~stickslip.run.options.RunOptions`), and the hooks a caller adds to a
run's loop (:class:`~stickslip.run.loop.Hook`, which sees a :class:`~stickslip.run.loop.Loop`;
:class:`~stickslip.run.errors.HookError` when one breaks its contract).
"""

from stickslip.lazy import lazy_names

#: Names loaded on first use (the loop loads the compiled kernels), and the module of each; no
#: ``__all__``, so that the reference documents each once, in its own module.
_LAZY = {
    "run_chain": "stickslip.run.driver",
    "resume_chain": "stickslip.run.driver",
    "RunOptions": "stickslip.run.options",
    "Hook": "stickslip.run.loop",
    "Loop": "stickslip.run.loop",
    "HookError": "stickslip.run.errors",
}


__getattr__, __dir__ = lazy_names(__name__, _LAZY)
