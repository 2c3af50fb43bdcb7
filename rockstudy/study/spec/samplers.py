"""The samplers of a study file, in one registry: each kind's layout, what ``n`` must be, and
its points in the unit hypercube.

A new sampler is one :class:`Sampler` entry in :data:`SAMPLERS`: the schema's ``kind``
(``sampler.kind``), its checks of ``n``, and the design's points
(:func:`rockstudy.study.designs.sampling.unit_samples`) all read it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

__all__ = ["LAYOUTS", "SAMPLERS", "Sampler", "kinds_laid_out", "salib_problem"]

#: The layouts of samples: ``"random"`` (n independent draws: replicated group points allowed,
#: and a ``[design]`` may draw its structures with it), ``"saltelli"`` (Sobol' points in SALib's
#: Saltelli layout) or ``"grid"`` (each parameter's own points).
LAYOUTS = ("random", "saltelli", "grid")


def salib_problem(study) -> dict:
    """The SALib problem of a study: its distributed parameters on the unit hypercube."""
    names = list(study.parameters())
    return {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}


def _monte_carlo(study, d: int) -> np.ndarray:
    """Plain Monte Carlo: independent uniform points from the study's root seed."""
    return np.random.default_rng(np.random.SeedSequence(study.seed)).random((study.sampler.n, d))


def _latin_hypercube(study, d: int) -> np.ndarray:
    """A scrambled Latin hypercube (``scipy.stats.qmc``) from the study's root seed."""
    rng = np.random.default_rng(np.random.SeedSequence(study.seed))
    return qmc.LatinHypercube(d=d, seed=rng).random(study.sampler.n)


def _saltelli(study, d: int) -> np.ndarray:
    """Scrambled Sobol' points in SALib's Saltelli layout (N (D + 2) rows, or N (2 D + 2)
    with second-order indices)."""
    from SALib.sample import sobol

    s = study.sampler
    x = sobol.sample(
        salib_problem(study), s.n, calc_second_order=s.second_order, scramble=True, seed=study.seed
    )
    return np.clip(x, 0.0, np.nextafter(1.0, 0.0))


def _power_of_two(n: int) -> str | None:
    return None if n & (n - 1) == 0 else f"sobol needs n = 2^k, got {n}"


@dataclass(frozen=True)
class Sampler:
    """One sampler kind.

    Attributes
    ----------
    layout : str
        One of :data:`LAYOUTS`.
    points : callable or None
        ``(study, D) -> array`` of points in [0, 1)^D, one row a sample; None for the grid,
        whose points are each distribution's own.
    n_rule : callable or None
        ``n -> message or None``: what ``n`` must be beyond a positive whole number (the grid
        takes no ``n``).
    """

    layout: str
    points: Callable | None
    n_rule: Callable[[int], str | None] | None = None

    @property
    def takes_n(self) -> bool:
        return self.points is not None


#: Sampler kind -> :class:`Sampler`, in the order the messages list them.
SAMPLERS = {
    "monte_carlo": Sampler("random", _monte_carlo),
    "lhs": Sampler("random", _latin_hypercube),
    "sobol": Sampler("saltelli", _saltelli, _power_of_two),
    "grid": Sampler("grid", None),
}


def kinds_laid_out(*layouts) -> list[str]:
    """The sampler kinds of the given layouts, in the order of :data:`SAMPLERS`."""
    return [kind for kind, s in SAMPLERS.items() if s.layout in layouts]
