"""The cells' electrical model at their air temperature: which tables a sky's steps take.

An :class:`~foldopt.engine.electrical.Electrical` holds one air temperature (its tables are
built for it). Without a weather file every block of a sky has one; with one, every step has its
own (:attr:`foldopt.engine.sky.Sky.temp_steps`), and each step takes the powers of the two tables
whose air temperatures enclose its own, linearly between them (:func:`temperature_nodes`), in the
kernel and in the reference path alike.

The module may import numpy, :mod:`foldopt.physics` and :mod:`foldopt.engine.electrical`,
:mod:`foldopt.engine.options` and :mod:`foldopt.engine.sky`.
"""

from __future__ import annotations

import functools

import numpy as np

from foldopt.engine.as_built import circuit_parts
from foldopt.engine.electrical import Electrical
from foldopt.engine.options import ElectricalOptions
from foldopt.engine.sky import Sky
from foldopt.physics.pvmodel import PVModel


@functools.lru_cache(maxsize=64)
def rated_power(pv: PVModel, area: float) -> float:
    """A panel's rated power (:meth:`PVModel.rating`) [W]: a converter's default rating.

    Parameters
    ----------
    pv : PVModel
    area : float
        Panel area [m^2].
    """
    return pv.rating(area)


def electrical_settings(
    options: ElectricalOptions, temp_air: float, wind_speed: float | None = None
) -> dict:
    """The keyword arguments (dict) of the :class:`Electrical` of ``options`` whose cells see
    ``temp_air``.

    Parameters
    ----------
    options : ElectricalOptions
    temp_air : float
        Air temperature of the cells [C].
    wind_speed : float, optional
        Wind speed of the tables [m/s]; default the options' (a weather study's sky gives its own,
        :attr:`foldopt.engine.sky.Sky.wind_ref`).
    """
    pv = options.pv()
    return dict(
        pv=pv,
        subpanel_area=options.area / 2.0,
        temp_air=float(temp_air),
        wind_speed=options.wind_speed if wind_speed is None else float(wind_speed),
        temperature_model=options.temperature_model,
        bypass=options.bypass,
        switch_series=options.switch_series,
        converter_efficiency=options.converter_efficiency,
        exact=options.exact,
        circuit=None
        if options.circuit is None
        else circuit_parts(options.circuit, rated_power(pv, options.area)),
    )


@functools.lru_cache(maxsize=64)
def _electrical(settings_items: tuple) -> Electrical:
    return Electrical(**dict(settings_items))


def electrical_for(
    options: ElectricalOptions, temp_air: float, wind_speed: float | None = None
) -> Electrical:
    """The :class:`Electrical` of ``options`` at an air temperature, shared by every caller in this
    process (and its tables by every process, through the disk cache).

    Parameters
    ----------
    options, temp_air, wind_speed
        As :func:`electrical_settings`.
    """
    return _electrical(tuple(electrical_settings(options, temp_air, wind_speed).items()))


def panel_power(sky: Sky, *, poa_global, electrical: ElectricalOptions, area: float | None = None):
    """Power panels deliver to the load over the blocks of a sky (their maximum power, or as the
    circuit is built: :meth:`Electrical.panel_power`), at their cells' air temperature
    (:func:`temperature_nodes`).

    Parameters
    ----------
    sky : Sky
    poa_global : numpy.ndarray
        (n_blocks, n_steps) plane-of-array irradiance [W/m^2].
    electrical : ElectricalOptions
    area : float, optional
        Panel area [m^2]; default the options'.

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_steps) [W].
    """
    area = electrical.area if area is None else area
    power = np.zeros_like(poa_global)
    for temp, weight in node_weights(sky, slice(None), poa_global.shape):
        cells = electrical_for(electrical, temp, sky.wind_ref)
        take = weight > 0
        if take.all():
            # One table at every step (a sky of one air temperature): no copy of the steps.
            power += weight * cells.panel_power(poa_global, area)
        else:
            power[take] += weight[take] * cells.panel_power(poa_global[take], area)
    return power


#: Spacing of the air temperatures of the electrical tables a weather study's steps lie between [C]:
#: the maximum power of a cell is close to linear in its temperature (a temperature coefficient),
#: so that linear interpolation over 5 C errs by well under 0.1 % (tests/test_weather_steps.py).
TEMPERATURE_NODE_STEP = 5.0


def temperature_nodes(sky: Sky, blocks=slice(None)):
    """The air temperatures of the electrical tables a sky's steps need, and where each step lies.

    Without per-step temperatures (``sky.temp_steps``), each block takes the table of its own
    ``temp_air``; with them, each step lies between two tables :data:`TEMPERATURE_NODE_STEP`
    apart and takes their powers linearly (the same in the kernel and the reference path).

    Parameters
    ----------
    sky : Sky
    blocks : slice or list of int, default all

    Returns
    -------
    nodes : numpy.ndarray
        (n_nodes,) ascending air temperatures [C].
    table : numpy.ndarray of int
        (n_selected, n_steps) or (n_selected, 1): the node at or below each step's (or block's).
    weight : numpy.ndarray
        Same shape: how far toward the next node [0, 1).
    """
    if sky.temp_steps is None:
        nodes, table = np.unique(np.atleast_1d(sky.temp_air[blocks]), return_inverse=True)
        return nodes, table.reshape(-1, 1).astype(np.int64), np.zeros((table.size, 1))
    temps = np.atleast_2d(sky.temp_steps[blocks])
    # A step's weight is its place on the lattice of nodes from 0 C, not from the run's coldest
    # node: the same step weighs its two tables to the bit whatever other days the run holds.
    position = temps / TEMPERATURE_NODE_STEP
    lattice = np.floor(position)
    first = int(lattice.min())
    count = int(lattice.max()) - first + 2
    nodes = TEMPERATURE_NODE_STEP * (first + np.arange(count))
    table = (lattice - first).astype(np.int64)
    return nodes, table, position - lattice


def node_weights(sky: Sky, blocks, shape):
    """(air temperature, weight of its tables at every step) of each node a sky's selected blocks
    use, the weights broadcast to ``shape`` (rows over the blocks, steps); they sum to 1 a step."""
    nodes, table, weight = temperature_nodes(sky, blocks)
    weights = []
    for k, temp in enumerate(nodes):
        w = np.where(table == k, 1.0 - weight, 0.0) + np.where(table == k - 1, weight, 0.0)
        if w.any():
            weights.append((float(temp), np.broadcast_to(w, shape)))
    return weights
