"""Running the model: the single block (eq. 1) and the chain (eq. 4).

:mod:`~stickslip.run.driver` runs and resumes the chain (:func:`~stickslip.run.driver.run_chain`),
through its run loop (:mod:`~stickslip.run.loop`), from its state (:mod:`~stickslip.run.state`),
output buffers and results
(:mod:`~stickslip.run.outputs`), checkpoints (:mod:`~stickslip.run.checkpoint`) and run
directories (:mod:`~stickslip.run.rundir`); :mod:`~stickslip.run.block` runs the single block;
:mod:`~stickslip.run.bench` times the chain's integrators.
"""
