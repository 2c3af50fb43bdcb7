"""The study file: its TOML schema, its parameter distributions, and what it can run.

``schema`` holds the pydantic models of a study file and reads, validates and exports them
(:func:`load_study`, :func:`validate_text`, :func:`json_schema`); ``distributions`` the
distributions a parameter is drawn from; ``feasibility`` the checks of what a study can run
(memory, record files, scale factors) that need more than one field.
"""

from .schema import Study, StudyError, json_schema, load_study, validate_text

__all__ = ["Study", "StudyError", "json_schema", "load_study", "validate_text"]
