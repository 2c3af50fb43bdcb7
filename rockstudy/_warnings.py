"""The warning classes, under the name the package's modules import them by (private); they
are defined in :mod:`rockstudy.warnings`."""

from .warnings import *  # noqa: F403
from .warnings import __all__  # noqa: F401
