"""Statistics of a run's outputs (its events, samples and profiles), computed without running
the engine: slip sizes and their truncated power law (Figs. 7, 8), rupture fronts (Fig. 6), the
order parameter, catalogues, magnitudes and the comparison of size distributions, recurrence of
slips, periodicity of slip sequences and survival of censored lifetimes."""
