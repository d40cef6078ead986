"""Engine: the passes over a study's arrays. The sky of many days and sites at once
(:mod:`~foldopt.engine.sky`), the electrical tables (:mod:`~foldopt.engine.electrical`), the
compiled kernel (:mod:`~foldopt.engine.kernel`, its irradiance loop in :mod:`~foldopt.engine.incidence`)
and its NumPy reference (:mod:`~foldopt.engine.evaluation`),
the daily metrics of a power curve against a load (:mod:`~foldopt.engine.metrics`, their roots by
Brent's method in :mod:`~foldopt.engine.roots`), a buffer's state of charge
(:mod:`~foldopt.engine.storage`), the fold-angle optimisers (:mod:`~foldopt.engine.optimize`) and
the re-folding schedules (:mod:`~foldopt.engine.schedule`). The compiled modules (numba) load
where they run, so that the NumPy path imports no numba.

It reads no study: what it needs of one comes as small frozen options groups
(:mod:`~foldopt.engine.options`: the sky's :class:`~foldopt.engine.options.SkyOptions` and the
cells' :class:`~foldopt.engine.options.ElectricalOptions`), made once by
:func:`foldopt.studies.engine_options.engine_options`, and its arrays as named records
(:mod:`~foldopt.engine.records`, the storage kernel's in :mod:`~foldopt.engine.storage_records`).
Its entry points take the sky first, then those groups keyword-only. It may import
:mod:`foldopt.inputs` (but the study), :mod:`foldopt.physics` and the leaves, never a study or a
view.
"""
