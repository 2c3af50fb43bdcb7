"""Sphinx configuration of the rockstudy documentation (``make docs``).

Nothing here reaches the network: no intersphinx inventories are downloaded, the theme's
fonts and scripts are bundled, and the gallery examples use only files made by rockstudy.
"""

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("ROCKSTUDY_DOCS_BUILD", "1")

import rockstudy  # noqa: E402

project = "rockstudy"
author = "the rockstudy developers"
copyright = "2026, the rockstudy developers"
release = rockstudy.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]

autosummary_generate = True
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# No math renderer: MathJax would be fetched from a CDN when a page opens, and this project
# reaches no network. Formulas show as their TeX source (docutils' plain rendering).

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "abort_on_example_error": True,
    "show_memory": False,
}

templates_path = ["_templates"]
exclude_patterns = ["_build", "examples", "auto_examples/*.ipynb", "auto_examples/*.py"]
# |theta| and |a_g| are absolute values in the docstrings, not reST substitutions
rst_prolog = """
.. |theta| unicode:: U+007C U+03B8 U+007C
.. |a_g| replace:: \\|a_g\\|
"""
html_theme = "pydata_sphinx_theme"
html_title = f"rockstudy {release}"
html_static_path = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "icon_links": [],
}
html_show_sourcelink = False
