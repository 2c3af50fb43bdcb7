"""Verification: what compares models and solvers with each other.

This layer sits above the physics packages (``dynamics``, ``closedform``, ``similarity``,
``structures``, ``motions``) and below the study layer; nothing in the physics imports it.

- :mod:`.validity`: the closed forms of paper [000] against the exact linear solver and the
  nonlinear kernel (where each closed form holds).
- :mod:`.equivalent_errors`: the equivalent blocks of paper [003] against their mechanisms
  (period, overturning time, uplift error maps).
- :mod:`.accuracy`: failure maps of the linearization and of loose tolerances, and the table of
  linearization error bounds that ``method="auto"`` reads (``python -m
  rockstudy.verification.accuracy`` regenerates it).

The modules are imported on demand (``from rockstudy.verification.validity import
validity_map``) so that ``import rockstudy`` does not pay for them.
"""

__all__: list[str] = []  # the modules are imported by name
