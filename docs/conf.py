"""Sphinx configuration of the sgc documentation site.

Build: ``.venv/bin/sphinx-build -W --keep-going -b html docs <out>`` (the ``docs`` extra).
The pages are the Markdown files of this folder (MyST), so they read the same on GitHub;
the API reference is generated from the public docstrings by autodoc and autosummary.
"""

from __future__ import annotations

import sys
from importlib import metadata
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

project = "sgc"
author = "the sgc developers"
release = metadata.version("sgc")
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "README.md"]
templates_path: list[str] = []

myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 4
"""GitHub-style anchors, so ``page.md#section`` links work on the site as on GitHub."""

autosummary_generate = True
autodoc_default_options = {"show-inheritance": True}
autodoc_typehints = "description"
autodoc_member_order = "bysource"
napoleon_google_docstring = True
napoleon_numpy_docstring = True
nitpicky = False

html_theme = "alabaster"
html_title = f"sgc {release}"
html_static_path: list[str] = []
