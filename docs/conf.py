"""Sphinx configuration of foldopt's documentation: ``sphinx-build -W -b html docs docs/_build/html``."""

import foldopt

project = "foldopt"
author = "foldopt developers"
release = version = foldopt.__version__
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "matplotlib.sphinxext.plot_directive",  # the worked examples run at build time
]
autosummary_generate = True
autodoc_default_options = {"members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks = set()
plot_include_source = True
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 90)]
plot_rcparams = {"figure.autolayout": True}
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path = ["_static"]
html_theme_options = {"description": "Design-space optimiser for twofold PV panels", "page_width": "1100px"}
nitpicky = False
