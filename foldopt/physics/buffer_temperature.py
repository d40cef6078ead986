"""A buffer's temperature and what it does to the buffer (issue 50): its temperature from the air's,
the usable share of its capacity, its self-discharge, and whether it may charge and discharge.
Arrays in, arrays out; the storage section holds a chemistry's data
(:class:`foldopt.inputs.storage_section.Storage`), :func:`foldopt.engine.storage.simulate` takes
the effects per step (:class:`foldopt.engine.storage.ColdSteps`).

How the cold capacity acts: a battery or a supercapacitor in the cold delivers less of its energy
before its voltage reaches the converter's or the controller's cut-off (the internal resistance
rises and the voltage sags), and delivers it again once warm: the energy is not lost but out of
reach [1]_ [2]_. The model therefore raises the controller's effective cut-off by the share out of
reach, ``floor = min_soc + (1 - k) (1 - min_soc)`` (:func:`cold_cut_off`), ``k`` the usable share
of the capacity at the buffer's temperature, the reconnection level ``restart_soc`` by the same
rule, and leaves the full buffer full: what the cold takes is the bottom of the usable range, the
energy under the raised floor stays stored (and leaks as stored energy does) and comes back when
warm. ``k = 1`` gives ``min_soc`` to the bit.

The module may import numpy.

References
----------
.. [1] Battery University, "BU-502: Discharging at high and low temperatures": cold raises the
   internal resistance and lowers the capacity a cell delivers; the capacity returns when warm.
.. [2] Canbat, LiFePO4 CLI100-12 (12 V 100 Ah), as quoted by Funsong Battery, "How to store
   LiFePO4 batteries": about 80 Ah at 0 C and 70 Ah at -20 C, "only temporary. When the battery
   gets hot, it will return to full capacity".
.. [3] Nanoramic, "FastCAP low temperature ultracapacitor" (FAQ): leakage current below 1 uA at
   -55 C and below 30 uA at 85 C.
"""

from __future__ import annotations

import numpy as np

#: The temperature at which a buffer's stated self-discharge holds [C] (datasheets state it at
#: room temperature, 25 C).
SELF_DISCHARGE_REFERENCE_C = 25.0


def buffer_temperature(temp_air, enclosure_offset_c=0.0):
    """The buffer's temperature: the air's plus its enclosure's offset (a box in the sun warms it,
    a buried or shaded one may be cooler).

    Parameters
    ----------
    temp_air : array_like
        Air temperature [C].
    enclosure_offset_c : float, default 0
        How much warmer the buffer is than the air [C].

    Returns
    -------
    numpy.ndarray
        [C], shaped as ``temp_air``.
    """
    return np.asarray(temp_air, dtype=float) + float(enclosure_offset_c)


def capacity_fraction(temperature, curve):
    """The usable share of a buffer's capacity at a temperature: piecewise linear through a
    datasheet's points, held at the end points beyond them.

    Parameters
    ----------
    temperature : array_like
        The buffer's temperature [C].
    curve : sequence of (float, float) or None
        ``(temperature [C], share [-])`` points, temperatures increasing, shares in (0, 1] not
        falling as the temperature rises; None: all of it usable at every temperature.

    Returns
    -------
    numpy.ndarray
        [-] in (0, 1], shaped as ``temperature``.
    """
    temperature = np.asarray(temperature, dtype=float)
    if curve is None:
        return np.ones(temperature.shape)
    points = np.asarray(curve, dtype=float).reshape(-1, 2)
    return np.interp(temperature, points[:, 0], points[:, 1])


def cold_cut_off(min_soc, fraction):
    """The controller's effective cut-off in the cold: the bottom ``1 - fraction`` of the usable
    range ``[min_soc, 1]`` is out of reach (module docstring); ``fraction`` 1 gives ``min_soc`` to
    the bit. Also the reconnection level, for ``restart_soc`` in place of ``min_soc``.

    Parameters
    ----------
    min_soc : array_like
        The cut-off [-] in [0, 1].
    fraction : array_like
        The usable share of the capacity [-] in (0, 1] (:func:`capacity_fraction`).

    Returns
    -------
    numpy.ndarray
        [-] in [min_soc, 1], broadcast over the inputs.
    """
    min_soc = np.asarray(min_soc, dtype=float)
    return min_soc + (1.0 - np.asarray(fraction, dtype=float)) * (1.0 - min_soc)


def leak_factor(temperature, doubling_c):
    """How many times the stated self-discharge a buffer loses at a temperature: the rate doubles
    every ``doubling_c`` above :data:`SELF_DISCHARGE_REFERENCE_C` and halves below, as a rate
    following Arrhenius' law does over a few tens of degrees ([3]_ bounds a supercapacitor's
    leakage at 1 uA at -55 C and 30 uA at 85 C: a doubling every 140 / log2(30) = 28.5 C).

    Parameters
    ----------
    temperature : array_like
        The buffer's temperature [C].
    doubling_c : float or None
        The rise that doubles the rate [C], above 0; None: the rate is the stated one at every
        temperature.

    Returns
    -------
    numpy.ndarray
        [-] above 0, shaped as ``temperature`` (1 at the reference temperature, and everywhere
        without ``doubling_c``).
    """
    temperature = np.asarray(temperature, dtype=float)
    if doubling_c is None:
        return np.ones(temperature.shape)
    return np.exp2((temperature - SELF_DISCHARGE_REFERENCE_C) / float(doubling_c))


def allowed(temperature, minimum_c):
    """Where a buffer may charge (or discharge): at its temperature ``minimum_c`` or above (a
    charger or a battery's management system blocks it below).

    Parameters
    ----------
    temperature : array_like
        [C].
    minimum_c : float or None
        [C]; None: at every temperature.

    Returns
    -------
    numpy.ndarray of bool
        Shaped as ``temperature``.
    """
    temperature = np.asarray(temperature, dtype=float)
    if minimum_c is None:
        return np.ones(temperature.shape, dtype=bool)
    return temperature >= float(minimum_c)
