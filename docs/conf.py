"""Sphinx configuration of the jkr/dt manual (``./run docs``; built with warnings as
errors by tests/test_docs.py)."""

project = "jkr/dt"
author = "the jkr/dt developers"
extensions = ["myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
myst_heading_anchors = 3
html_theme = "alabaster"
html_theme_options = {"description": "dust-aggregate collisions in LAMMPS"}
# the LAMMPS manual's code-block language is not a Pygments lexer: plain text
highlight_language = "none"
suppress_warnings = ["misc.highlighting_failure"]
