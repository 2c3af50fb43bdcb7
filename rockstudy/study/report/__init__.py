"""Reports: one self-contained HTML page of a result cube, with its figures and tables.

``sampled`` holds :func:`make_report` (the entry point for every cube) and the sections of a
sampled study; ``records`` the page of a record design; ``_page`` the page they share.
"""

from .records import record_report
from .sampled import make_report

__all__ = ["make_report", "record_report"]
