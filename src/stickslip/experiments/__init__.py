"""The paper's experiments: their specs, parameter sweeps on Dask, and ``stickslip reproduce``."""
