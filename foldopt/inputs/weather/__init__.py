"""Weather: the files a study's light is read from and the services that give them.

A weather file (hourly global, direct and diffuse irradiance, air temperature and wind of a site)
is read by :mod:`~foldopt.inputs.weather.reader`, through one module per format
(:mod:`~foldopt.inputs.weather.tmy3`, :mod:`~foldopt.inputs.weather.epw`,
:mod:`~foldopt.inputs.weather.pvgis`, the measured stations' :mod:`~foldopt.inputs.weather.measured`
and :mod:`~foldopt.inputs.weather.stations`), checked by :mod:`~foldopt.inputs.weather.qc`; its
hourly means become light at every step of a study in :mod:`~foldopt.inputs.weather.downscale`,
and its cloud members in :mod:`~foldopt.inputs.weather.ensemble`.
:mod:`~foldopt.inputs.weather.sources` fetches a file from a public service by name and caches it.

The package may import pandas, pvlib, the leaves (:mod:`foldopt.errors`, :mod:`foldopt.names`,
:mod:`foldopt.cache`), :mod:`foldopt.inputs.reading`, whose
:func:`~foldopt.inputs.reading.check_input` refuses a file that is missing, a folder, a device, a
FIFO or too large before anything reads it, and :mod:`foldopt.inputs.weather_section`. This
``__init__`` imports nothing: a request that names a source or a horizon checks its site
through :mod:`~foldopt.inputs.weather.sources` (the standard library) without loading pandas
and pvlib, which only a file read needs.
"""
