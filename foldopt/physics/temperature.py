"""Cell temperature from irradiance, air temperature and wind, and the wind folded into the air
temperature for tables that hold one wind speed.

The module may import numpy, pvlib and :mod:`foldopt.names`.
"""

from __future__ import annotations

import numpy as np

from foldopt.names import TEMPERATURE_MODELS


def cell_temperature(poa_global, temp_air, wind_speed, model="fixed"):
    """Cell temperature from irradiance, air temperature and wind.

    ``fixed``: the air temperature (a cell held at it, e.g. 25 C = STC). ``sapm``: pvlib's SAPM
    cell temperature, open rack glass/polymer (King et al. 2004, SAND2004-3535, Eq. 11 and 12).

    Parameters
    ----------
    poa_global : array_like
        Plane-of-array irradiance [W/m^2].
    temp_air : float or array_like
        Air temperature [C].
    wind_speed : float or array_like
        Wind speed [m/s] (``sapm`` only).
    model : {'fixed', 'sapm'}
        Temperature model.

    Returns
    -------
    numpy.ndarray
        Cell temperature [C], shaped as ``poa_global``.

    Raises
    ------
    ValueError
        If ``model`` is not one of :data:`foldopt.names.TEMPERATURE_MODELS`.
    """
    if model == "fixed":
        return np.broadcast_to(np.asarray(temp_air, dtype=float), np.shape(poa_global)).copy()
    if model == "sapm":
        import pvlib

        params = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
        return np.asarray(pvlib.temperature.sapm_cell(poa_global, temp_air, wind_speed, **params))
    raise ValueError(
        f"temperature_model must be one of {', '.join(TEMPERATURE_MODELS)}; got {model!r}"
    )


def irradiance_coefficient(wind_speed, model="fixed"):
    """How much warmer than the air a cell is per irradiance, ``c`` in ``T_cell = T_air + c E``.

    ``fixed``: 0. ``sapm``: ``exp(a + b WS) + dT / 1000 W/m^2`` (King et al. 2004, SAND2004-3535,
    Eq. 11 and 12; open rack glass/polymer), :func:`cell_temperature`'s.

    Parameters
    ----------
    wind_speed : float or array_like
        Wind speed [m/s].
    model : {'fixed', 'sapm'}

    Returns
    -------
    float or numpy.ndarray
        [C / (W/m^2)].
    """
    if model == "fixed":
        return np.zeros_like(np.asarray(wind_speed, dtype=float))
    if model == "sapm":
        import pvlib

        params = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
        return np.exp(params["a"] + params["b"] * np.asarray(wind_speed, dtype=float)) + (
            params["deltaT"] / 1000.0
        )
    raise ValueError(
        f"temperature_model must be one of {', '.join(TEMPERATURE_MODELS)}; got {model!r}"
    )


def equivalent_temp_air(temp_air, wind_speed, wind_ref, irradiance, model="fixed"):
    """The air temperature at which a cell in wind ``wind_ref`` is as warm as in ``wind_speed``.

    The electrical tables hold one wind speed; a weather file's wind at each step is folded into
    the air temperature instead. SAPM's cell temperature is ``E exp(a + b WS) + T_air + E/1000 dT``
    (King et al. 2004, SAND2004-3535, Eq. 11 and 12), so at irradiance ``E`` the equivalent air
    temperature is ``T_air + E (exp(a + b WS) - exp(a + b WS_ref))``, exact where ``E`` is the
    sub-panel's own plane-of-array irradiance. With the horizontal global light for ``E`` the
    error is ``(E_poa - E) (exp(a + b WS) - exp(a + b WS_ref))``: at most about 2 C for a
    sub-panel 300 W/m^2 brighter than the horizontal in a wind 5 m/s from ``wind_ref``.

    Parameters
    ----------
    temp_air : array_like
        Air temperature [C].
    wind_speed : array_like
        Wind speed [m/s].
    wind_ref : float
        The wind speed of the tables [m/s].
    irradiance : array_like
        Irradiance standing for the sub-panels' [W/m^2].
    model : {'fixed', 'sapm'}
        :func:`cell_temperature`'s model; ``fixed`` ignores the wind.

    Returns
    -------
    numpy.ndarray
        [C], broadcast over the inputs.
    """
    temp_air = np.asarray(temp_air, dtype=float)
    if model != "sapm":
        return np.broadcast_to(
            temp_air, np.broadcast_shapes(temp_air.shape, np.shape(irradiance))
        ).copy()
    import pvlib

    params = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_polymer"]
    a, b = params["a"], params["b"]
    return temp_air + np.asarray(irradiance, dtype=float) * (
        np.exp(a + b * np.asarray(wind_speed, dtype=float)) - np.exp(a + b * wind_ref)
    )
