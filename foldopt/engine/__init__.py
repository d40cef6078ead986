"""Engine: a study's arrays and the passes over them. The sky of many days and sites at once
(:mod:`~foldopt.engine.sky`), the electrical tables (:mod:`~foldopt.engine.electrical`), the
compiled kernel (:mod:`~foldopt.engine.kernel`, its irradiance loop in :mod:`~foldopt.engine.incidence`)
and its NumPy reference (:mod:`~foldopt.engine.evaluation`),
the daily metrics of a power curve against a load (:mod:`~foldopt.engine.metrics`), the fold-angle
optimisers (:mod:`~foldopt.engine.optimize`) and the re-folding schedules
(:mod:`~foldopt.engine.schedule`). It may import :mod:`foldopt.inputs`, :mod:`foldopt.physics` and
the leaves, never a study or a view.
"""
