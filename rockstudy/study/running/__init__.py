"""Running a study: dask tasks over chunks of the design, written into a zarr cube.

``runner`` drives the run (:func:`~rockstudy.study.running.runner.run_study`); ``evaluate``
is the function each task runs on a chunk of rows; ``store`` writes, resumes, verifies and
opens the cube (its parts: ``_marker``, ``_lock``, ``_checksums``, ``_verify``, ``export``,
``_files``); ``_warmup`` compiles the numba kernels before the workers need them.
"""

__all__: list[str] = []  # the modules are imported by name
