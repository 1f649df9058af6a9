"""Figures of the paper. Every function takes results and returns a matplotlib Figure; none calls show()."""
