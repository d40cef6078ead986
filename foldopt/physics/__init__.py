"""Physics: the sun, the atmosphere and clear sky, irradiance on a surface, the panel's geometry, PV
models, the ways of connecting two sub-panels and sun trackers, as pure functions of arrays (angles
in degrees, irradiance in W/m^2, power in W), with no I/O and no study objects. Each module is one
physical concept and cites its equations. It may import only :mod:`foldopt.names` and
:mod:`foldopt.errors`, numpy, scipy, pandas and pvlib.
"""
