"""Event-driven rocking kernels (private): Housner's block, nonlinear or linearized.

State machine per scene: rest, rocking on side s = +1 or -1, overturned. The side is carried
explicitly (never sgn(theta)), so the right-hand side is smooth across theta = 0 and an impact
is a root of theta on the quintic Hermite interpolant of an accepted DOP853 step. After the
excitation ends nothing is integrated unless the block overturns: the free-rocking map
(energy conservation between impacts, eta per impact) gives the peaks and the decision.

A block at rest lifts off where its own acceleration on the side pushed towards turns
positive (:func:`_lift`, the right-hand side itself), found on the motion's monotone pieces
between analytic extrema; the Zeno rule restarts a settling block by the same test, so a
block said to lift always rises and a chatter at the threshold cannot go on without end.

A record's vertical component u_v'' (``vsamples`` of the motion tuple, empty for none) turns
gravity into g + u_v'' in every model (:func:`_accel`), in the lift test and so in the uplift
search and the Zeno rule; the solvers refuse u_v'' <= -g (free fall) before calling a kernel.

The kernels live in modules of one job each; this module is the facade that the solvers and
the tests import (the names they use): :mod:`.constants` (models, phase codes, tolerances),
:mod:`._rhs` (the right-hand side :func:`_accel`, the only one, and the lift test),
:mod:`._tables` (a mechanism's tables), :mod:`._uplift` (uplift search), :mod:`._events`
(impacts, peaks and overturning on a step, the impact and Zeno rules), :mod:`._steps` (one
DOP853 or Taylor step), :mod:`._logs` (tallies, history, peaks, dense output), :mod:`._phase`
(the phase loop), :mod:`._free_map` (the free-rocking map) and :mod:`._scene` (the scene and
batch drivers).
"""

from __future__ import annotations

from ._free_map import (
    free_rocking_map,
    free_tail_end,
)
from ._logs import (
    TALLIES,
    new_tallies,
    tally_impact,
)
from ._phase import (
    PhaseState,
    Stepping,
    _phase,
    _phase_trig,
    _variant_named,
)
from ._rhs import (
    _accel,
    _ground_after,
    _lift,
)
from ._scene import (
    BATCH_COLUMNS,
    Body,
    Controls,
    SceneOutcome,
    Start,
    scene,
    scene_batch,
    scene_batch_serial,
    scene_batch_trig,
    scene_batch_trig_serial,
    scene_trig,
)
from ._steps import (
    TRIG_STEP_CAP,
)
from ._tables import (
    _free_map_table,
)
from ._uplift import (
    QUIET_MARGIN,
    _next_break,
    next_uplift,
)
from .constants import (
    MODEL_LINEAR,
    MODEL_NONLINEAR,
    MODEL_TABLE,
    NO_STOP,
    NO_TABLE,
    PH_END,
    PH_OVER,
    PH_REST,
    REST_FRACTION,
    STATUS_HISTORY_FULL,
    STATUS_MAX_STEPS,
    STATUS_OK,
    STEP_GROW_LIMIT,
    STEP_SAFETY,
    STEP_SHRINK_LIMIT,
    TAB_B,
    TAB_DB,
    TAB_DG,
    TAB_DI,
    TAB_DV,
    TAB_G,
    TAB_I,
    TAB_PHI,
    TAB_V,
)

__all__ = [
    "BATCH_COLUMNS",
    "Body",
    "Controls",
    "MODEL_LINEAR",
    "MODEL_NONLINEAR",
    "MODEL_TABLE",
    "NO_STOP",
    "NO_TABLE",
    "PH_END",
    "PH_OVER",
    "PH_REST",
    "PhaseState",
    "QUIET_MARGIN",
    "REST_FRACTION",
    "STATUS_HISTORY_FULL",
    "STATUS_MAX_STEPS",
    "STATUS_OK",
    "STEP_GROW_LIMIT",
    "STEP_SAFETY",
    "STEP_SHRINK_LIMIT",
    "SceneOutcome",
    "Start",
    "Stepping",
    "TAB_B",
    "TAB_DB",
    "TAB_DG",
    "TAB_DI",
    "TAB_DV",
    "TAB_G",
    "TAB_I",
    "TAB_PHI",
    "TAB_V",
    "TALLIES",
    "TRIG_STEP_CAP",
    "_accel",
    "_free_map_table",
    "_ground_after",
    "_lift",
    "_next_break",
    "_phase",
    "_phase_trig",
    "_variant_named",
    "free_rocking_map",
    "free_tail_end",
    "new_tallies",
    "next_uplift",
    "scene",
    "scene_batch",
    "scene_batch_serial",
    "scene_batch_trig",
    "scene_batch_trig_serial",
    "scene_trig",
    "tally_impact",
]
