"""Figures of the paper. Every function takes results and returns a matplotlib Figure; none calls show().

:mod:`stickslip.plotting.figures` draws all of them for the report of ``stickslip reproduce``,
with the data beside each image.
"""
