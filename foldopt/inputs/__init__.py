"""Inputs: what a user hands in, read and validated. Study files and the files a study names
(:mod:`~foldopt.inputs.study_file`: YAML with line numbers, size limits, a weather file's site and a load
profile's day read before validation), ranges, lists and plans of many cases
(:mod:`~foldopt.inputs.plan`), the pydantic models of a study (:mod:`~foldopt.inputs.study`,
:mod:`~foldopt.inputs.sections`; they validate and open no files), the policy of what a study
becomes when a user changes fields, weather files (:mod:`~foldopt.inputs.weather`: one reader per
format and a registry of them), load profiles, lists of sites (:mod:`~foldopt.inputs.sites`), the land mask
and the sizing's constants. All file
reading of a request happens here, before a study runs. It may import :mod:`foldopt.physics` (for
model names, the tracker registry and default orientations) and the leaves (:mod:`foldopt.errors`,
:mod:`foldopt.names`, :mod:`foldopt.files`, :mod:`foldopt.cache`).
"""
