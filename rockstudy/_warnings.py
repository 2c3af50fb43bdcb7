"""The warning classes, under the name the package's modules import them by (private; they
are defined in :mod:`rockstudy.warnings`), and where a warning should point."""

import os
import sys

from .warnings import *  # noqa: F403
from .warnings import __all__  # noqa: F401


def caller_stacklevel() -> int:
    """The ``stacklevel`` of :func:`warnings.warn` that points at the first caller outside
    the package, counted from the function that calls this one: the user's own call however
    many of the package's calls lie between (a wrapper such as
    :func:`~rockstudy.study.analysis.motion_axes.per_motion`, an accessor, one public function
    calling another)."""
    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame, level = sys._getframe(1), 1
    while frame.f_back is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    return level
