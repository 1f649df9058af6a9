"""Analysis of the model and of its runs, in two parts.

- :mod:`stickslip.analysis.dynamics`: methods that drive the engine or linearise its equations:
  linear stability (eqs. 2, 5; Fig. 4), the slip in the limit V -> 0 (eq. 3; Fig. 3), the
  hysteresis of the single block, Lyapunov exponents, decorrelation, finite-size exponents,
  stable chaos and the adaptive runs of the transition study.
- :mod:`stickslip.analysis.stats`: statistics of a run's outputs: slip sizes (Figs. 7, 8),
  rupture fronts (Fig. 6), the order parameter, catalogues and magnitudes, recurrence,
  periodicity of slip sequences and survival of censored lifetimes.

The statistics never run the engine; the dynamics may read the statistics.
"""
