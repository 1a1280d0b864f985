"""Sphinx configuration of pumpup's documentation (``python -m sphinx -W -b html docs docs/_build/html``).

The site builds offline: no intersphinx, no remote images.  The gallery (``docs/examples``) runs every example;
``PUMPUP_DOCS_QUICK=1`` is not used: the examples are sized to run in the build.
"""

from __future__ import annotations

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(HERE, "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import pumpup  # noqa: E402

project = "pumpup"
author = "the pumpup authors"
copyright = "the pumpup authors"  # noqa: A001
release = pumpup.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "pumpup_docs",
]

# literal blocks without a language (the docstrings' formulas, the generated references) are plain text
highlight_language = "text"
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# a page's own folder of data (docs/user-guide/<page>/: figures, CSV, generated Markdown tables it includes) holds
# no pages of its own
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "examples/*.md", "examples/README.rst",
                    "sg_execution_times.rst", "user-guide/*/**"]
templates_path = ["_templates"]

# myst: ``$...$`` stays literal text (the pages write formulas in plain text); anchors for ## headings
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3

# autodoc / autosummary / numpydoc
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# the gallery: every example runs in the build; they draw the figures of ``figures/`` at a smaller size
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "reference_url": {},
    "abort_on_example_error": True,
    # the computation-times pages load their table script from a CDN: the site must work offline
    "write_computation_times": False,
}

html_theme = "pydata_sphinx_theme"
html_title = f"pumpup {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 6,
    "use_edit_page_button": False,
}
html_last_updated_fmt = None
html_show_sourcelink = False
suppress_warnings = ["config.cache", "toc.empty_glob"]
autosummary_ignore_module_all = False
# the theme's colour mode on a first visit (empty, the theme logs a console error and falls back to auto)
html_context = {"default_mode": "auto"}
