"""Bayesian posteriors of a fit's parameters by Markov-chain Monte Carlo (emcee, optional).

The likelihood is the fit's (:func:`stickslip.lab.fitting.fit`): the weighted residuals are Gaussian
with the standard deviation s the fit estimated (sqrt(sum of squared residuals / (n - p))), so
log L = -sum r_i^2 / (2 s^2); the prior is flat within the parameters' bounds (a, D_c, k, eta > 0).
The walkers of emcee's affine-invariant ensemble sampler (Goodman and Weare 2010; Foreman-Mackey
et al. 2013) start in a small ball around the least-squares solution. For a well-determined fit
the posterior's standard deviations are the fit's standard errors; where the least-squares
covariance is a poor guide (strong correlations, few samples) the posterior says so.

emcee is an optional dependency: ``pip install stickslip[lab]`` (or ``pip install emcee``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from stickslip.models.params import ParameterError, check_number

__all__ = ["Posterior", "posterior"]


@dataclass
class Posterior:
    """Samples of the posterior of a fit's free parameters.

    Attributes
    ----------
    names : list of str
    samples : array (n, p)
        The chain after the burn-in, walkers flattened, in the parameters' own units.
    acceptance : float
        Mean acceptance fraction of the walkers.
    autocorrelation : array (p,) or None
        emcee's integrated autocorrelation time of each parameter, in steps (None where the chain
        is too short to estimate it).
    kept_steps : int
        Steps of each walker after the burn-in.
    """

    names: list[str]
    samples: np.ndarray
    acceptance: float
    autocorrelation: np.ndarray | None
    kept_steps: int = 0

    @property
    def mean(self) -> np.ndarray:
        """Posterior means."""
        return self.samples.mean(axis=0)

    @property
    def std(self) -> np.ndarray:
        """Posterior standard deviations."""
        return self.samples.std(axis=0, ddof=1)

    def interval(self, level: float = 0.95) -> np.ndarray:
        """The central credible interval of each parameter, shape (p, 2)."""
        q = (1.0 - level) / 2.0
        return np.quantile(self.samples, [q, 1.0 - q], axis=0).T

    def summary(self) -> dict:
        """JSON-able: mean, standard deviation and 95% interval of each parameter."""
        iv = self.interval()
        return {
            "parameters": {
                n: {"mean": float(m), "std": float(s), "interval_95": [float(lo), float(hi)]}
                for n, m, s, (lo, hi) in zip(self.names, self.mean, self.std, iv, strict=True)
            },
            "samples": int(self.samples.shape[0]),
            "acceptance": self.acceptance,
            "autocorrelation_steps": None if self.autocorrelation is None else self.autocorrelation.tolist(),
            # emcee's advice: a chain of at least 50 autocorrelation times
            "autocorrelation_reliable": bool(
                self.autocorrelation is not None and self.kept_steps >= 50 * np.max(self.autocorrelation)
            ),
        }

    def to_dataset(self) -> xr.Dataset:
        """The samples as a Dataset over ``sample`` and ``parameter``."""
        return xr.Dataset(
            {"samples": (("sample", "parameter"), self.samples)},
            coords={"parameter": self.names},
            attrs={"acceptance": self.acceptance},
        )


def posterior(result, *, walkers: int | None = None, steps: int = 2000, burn: int | None = None, rng=None) -> Posterior:
    """Sample the posterior of the free parameters of a fit (module docstring).

    Parameters
    ----------
    result : FitResult
        What :func:`stickslip.lab.fitting.fit` returned.
    walkers : int, optional
        Walkers of the ensemble (default 4 per parameter, at least 16).
    steps : int
        Steps of each walker.
    burn : int, optional
        Steps discarded at the start (default a quarter).
    rng : numpy.random.Generator or int, optional
        The random numbers (a seed makes the chain reproducible).

    Returns
    -------
    Posterior

    Raises
    ------
    ParameterError
        emcee is not installed, or the numbers are out of range.
    """
    try:
        import emcee
    except ImportError:
        raise ParameterError("posteriors need emcee: pip install emcee (or stickslip[lab])") from None
    problem = result.extra["problem"]
    sigma = result.extra["sigma"]
    p = len(problem.slots)
    walkers = max(16, 4 * p) if walkers is None else int(check_number("walkers", walkers, low=2 * p, integer=True))
    steps = int(check_number("steps", steps, low=10, integer=True))
    burn = steps // 4 if burn is None else int(check_number("burn", burn, low=0, high=steps - 1, integer=True))
    x_fit = result.values / problem.scale
    dx = np.maximum(result.errors / problem.scale, 1e-8 * np.abs(x_fit) + 1e-12)
    dx = np.where(np.isfinite(dx), dx, 1e-6)
    gen = np.random.default_rng(rng)
    start = x_fit + 0.1 * dx * gen.standard_normal((walkers, p))
    start = np.maximum(start, problem.lower + 1e-9 * np.abs(x_fit))

    def log_prob(x):
        if np.any(x <= problem.lower):
            return -np.inf
        r = problem.residuals(x)
        return -0.5 * float(r @ r) / sigma**2

    sampler = emcee.EnsembleSampler(walkers, p, log_prob)
    # emcee draws its moves from a RandomState of its own: seed it from rng too.
    sampler.random_state = np.random.RandomState(int(gen.integers(2**31))).get_state()
    sampler.run_mcmc(start, steps, progress=False)
    chain = sampler.get_chain(discard=burn, flat=True) * problem.scale
    import logging

    # emcee logs a warning where the chain is short of 50 autocorrelation times; the summary
    # says so itself (``autocorrelation_reliable``).
    logging.disable(logging.WARNING)
    try:
        tau = sampler.get_autocorr_time(discard=burn, quiet=True)
    except Exception:  # emcee raises where the chain is too short for any estimate
        tau = None
    finally:
        logging.disable(logging.NOTSET)
    return Posterior(
        [s[0] for s in problem.slots], chain, float(np.mean(sampler.acceptance_fraction)), tau, steps - burn
    )
