"""Constants of the rocking kernels (internal, not API): the models, a mechanism's table
columns, the codes of a phase's end and of a scene's status, and the tolerances and step
controls.

Some are numpy scalars, not Python ints: numba types a literal argument as Literal[int] and
compiles a specialization of the callee for each value. numba compiles these values into
the kernels of other files: the warm-up fingerprints every file named ``constants.py``
(:func:`rockstudy.study.running._warmup._kernel_sources`), so a change here empties a stale cache.
"""

from __future__ import annotations

import numpy as np

from ..motions._kernels import KIND_TRIG

__all__ = [
    "ATOL_FRACTION",
    "FIRST",
    "FIRST_STEP",
    "IMPACT_RETRY_SHRINK",
    "MIN_STEP",
    "MODEL_LINEAR",
    "MODEL_NONLINEAR",
    "MODEL_TABLE",
    "NEVER_AT_REST",
    "NO_STOP",
    "NO_TABLE",
    "PH_END",
    "PH_FAIL",
    "PH_IMPACT",
    "PH_OVER",
    "PH_REST",
    "REST_FRACTION",
    "STATUS_HISTORY_FULL",
    "STATUS_MAX_STEPS",
    "STATUS_OK",
    "STEP_GROW_LIMIT",
    "STEP_SAFETY",
    "STEP_SHRINK_LIMIT",
    "TAB_B",
    "TAB_DB",
    "TAB_DG",
    "TAB_DI",
    "TAB_DV",
    "TAB_G",
    "TAB_I",
    "TAB_PHI",
    "TAB_V",
    "TABLE_BISECTIONS",
    "TAYLOR_TOL_FRACTION",
    "TOL_SAFETY",
    "TRIG",
    "UNDAMPED_WINDOW",
]

MODEL_NONLINEAR = 0
MODEL_LINEAR = 1
MODEL_TABLE = 2  # a mechanism, eq. (8) of [003], from tabulated I, G, B (structures/mechanism)

#: Columns of a mechanism table, on a uniform grid of the amplitude phi in [0, fall].
TAB_PHI, TAB_I, TAB_DI, TAB_G, TAB_DG, TAB_B, TAB_DB, TAB_V, TAB_DV = range(9)
NO_TABLE = np.empty((2, 0, 9))  # [direction + (0), direction - (1)], node, column
# read-only, as numba types a global array inside a kernel: a kernel called from Python with
# it and from a kernel (the batch kernels) then compiles once, not for both array types
NO_TABLE.flags.writeable = False

PH_END = 0
PH_REST = 1
PH_OVER = 2
PH_FAIL = 3
PH_IMPACT = 4
# numpy scalars, not Python ints: numba types a literal argument as Literal[int] and compiles a
# specialization of the callee for each value (a phase, an uplift test compiled twice)
NO_STOP = np.int64(-1)  # a phase's stop_at_impacts: never

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_HISTORY_FULL = 2
#: A batch row of the contact model whose answer did not converge with rtol (the kernel's
#: ``converged`` flag: a friction decision within 10 rtol of its threshold with mu_s > mu_k,
#: or an answer that moves by more than 10 rtol at rtol / 100).
STATUS_UNCONVERGED = 4

#: Post-impact speed below which the block is taken to be at rest, as a fraction of p*alpha.
REST_FRACTION = 1e-4
#: Local error target as a fraction of rtol, so that global errors (peaks, impact times over
#: tens of cycles) stay below rtol; calibrated against the scipy reference at rtol 1e-12.
TOL_SAFETY = 0.1
#: Local error target of the Taylor record step, as a fraction of TOL_SAFETY * rtol. Rocking
#: through hundreds of impacts amplifies local errors by up to 1e4-1e6, and DOP853 on steps
#: cut at every sample was far more accurate than its rtol. Measured on 1000 record scenes
#: (bench_records' blocks) at rtol 1e-6 against rtol 1e-12: at 1, 12 of 200 Arcadia scenes
#: erred by more than 1e-6 and one overturning decision flipped; at 1e-4, p99 4.5e-7 (the
#: old kernel 1.1e-6), no decision wrong, for two or three more terms per step (~3 % time).
TAYLOR_TOL_FRACTION = 1e-4
#: Shortest step (in units of 1/p) retried when an impact falls outside its step.
MIN_STEP = 1e-9
#: A DOP853 step whose impact the interpolant placed outside it is retried this much shorter.
IMPACT_RETRY_SHRINK = 0.25
#: Step-size control of the DOP853 steps (Hairer, Norsett and Wanner's; also the complex
#: formulation's RK45 steps, with err^(-1/5)): the next step is h STEP_SAFETY err^(-1/8),
#: aimed below the tolerance so that it is rarely rejected ...
STEP_SAFETY = 0.9
#: ... and at least STEP_SHRINK_LIMIT h (in DOP853 also after a NaN error), at most
#: STEP_GROW_LIMIT h (also after a zero error), so that one odd error estimate cannot swing it
#: further.
STEP_SHRINK_LIMIT = 0.2
STEP_GROW_LIMIT = 5.0
#: The first step tried in a scene, in units of 1/p (the controller adapts it from there).
FIRST_STEP = 0.01
#: Cap on the halvings of the bisections on a mechanism's table, which stop at adjacent
#: doubles: 100 halve a bracket of rotations below 1e-30 rad.
TABLE_BISECTIONS = 100
#: Absolute error scales of theta and theta_dot, as fractions of alpha and p*alpha.
ATOL_FRACTION = 1e-3
#: Impact count of :func:`free_rocking_map` when eta = 1 (the block never comes to rest).
#: The solvers do not report it: they count the impacts up to :func:`free_tail_end` instead.
NEVER_AT_REST = 2**31 - 1
#: Length of the free rocking followed after the motion when eta = 1, in units of 1/p.
UNDAMPED_WINDOW = 100.0

TRIG, FIRST = np.int64(KIND_TRIG), np.int64(0)  # the motion kind and segment index, not literals
