"""The study file: its TOML schema, its parameter distributions, and what it can run.

``schema`` reads, validates and exports a study file (:func:`load_study`,
:func:`validate_text`, :func:`json_schema`) and names every model of it; the models live by
the file's sections: ``parameters`` (the strict model, a parameter and the checks of its span),
``structure_spec`` and ``objects_spec`` (``[structure]``), ``motion_spec``, ``sampler_spec``,
``design_spec``, ``hazard_spec``, ``run_spec``, and ``study_model`` (:class:`Study`, the whole
file); ``messages`` words pydantic's errors. ``distributions`` holds the distributions a
parameter is drawn from; ``structures`` and ``samplers`` the registries of structure kinds and
samplers; ``ida_options`` the options of an IDA; ``feasibility`` the checks of what a study
can run (memory, record files, scale factors) that need more than one field.
"""

from .schema import Study, StudyError, json_schema, load_study, validate_text

__all__ = ["Study", "StudyError", "json_schema", "load_study", "validate_text"]
