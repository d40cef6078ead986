"""Studies: the questions foldopt answers. A request becomes the study that runs in one place
(:mod:`~foldopt.studies.request`); every design (flat, twofold at each fold angle, trackers gross
and net) is evaluated in one module (:mod:`~foldopt.studies.designs`); every result carries one
:class:`~foldopt.studies.answer.Answer`. Single days, sweeps and annual groups, maps on Dask,
sizing and the paper's reproduction live here. It may import :mod:`foldopt.engine`,
:mod:`foldopt.inputs`, :mod:`foldopt.physics` and the leaves, never :mod:`foldopt.output`.
"""
