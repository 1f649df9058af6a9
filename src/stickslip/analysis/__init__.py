"""Analysis of the model and of its runs: linear stability (eqs. 2, 5; Fig. 4), the slip in the
limit V -> 0 (eq. 3; Fig. 3), the hysteresis of the single block, and the statistics of chain
runs (Figs. 5-8)."""
