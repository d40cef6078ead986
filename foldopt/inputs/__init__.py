"""Inputs: what a user hands in, read and validated. Study files (YAML with line numbers, ranges and
lists of values), the pydantic models of a study (which validate and open no files), the policy of
what a study becomes when a user changes fields, weather files (one reader per format), load
profiles, site lists and the land mask. All file reading of a request happens here, before a study
runs. It may import :mod:`foldopt.physics` (for model names and default orientations) and the
leaves (:mod:`foldopt.errors`, :mod:`foldopt.names`, :mod:`foldopt.files`).
"""
