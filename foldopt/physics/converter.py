"""The converter between the panel and the load: the power it delivers for the power it takes.

A maximum-power-point converter holds its input at the connection's maximum power point and
delivers that power times its efficiency at that input. Its models (:data:`foldopt.names.CONVERTER_MODELS`):

- ``ideal``: it delivers its whole input (Shin et al.'s assumption).
- ``pvwatts``: the PVWatts part-load curve [1]_, through ``pvlib.inverter.pvwatts``: with
  ``zeta = P_in / P_rated``, ``eta = eta_nom / eta_ref (-0.0162 zeta - 0.0059 / zeta + 0.9858)``
  (Dobos 2014, Eq. 1-2 of the inverter model, ``eta_ref = 0.9637``), the output never negative
  (below ``zeta`` of about 0.006 it delivers nothing) and clipped at ``eta_nom P_rated``.
- ``curve``: efficiency against input power as a fraction of the rating, as a datasheet's
  efficiency curve or the CEC's weighted points give it: linear between the points, held beyond
  the last; below the first it falls linearly to 0 at no input (a converter delivers nothing of
  nothing); its input is limited at :data:`ZETA_MAX` times its rating.

The rating ``p_rated`` is the converter's DC input [W]: by default the panel's power at STC
(:func:`foldopt.engine.cell_tables.electrical_settings`). Each of the two converters of the ``independent``
connection is sized to its sub-panel (:meth:`Converter.scaled` by one half), so at a given
irradiance it works at the same part load as the whole panel's single converter.

The compiled kernel reads the delivered power from a table on input nodes uniform in
``sqrt(zeta / ZETA_MAX)`` (:func:`delivered_table`): dense at low input, where the PVWatts curve
bends; :func:`table_delivered` is the same read in NumPy, ``tests/test_converter.py`` measures
the table against the exact model.

References
----------
.. [1] A. P. Dobos, "PVWatts Version 5 Manual", NREL/TP-6A20-62641, 2014, inverter model,
   Eq. 1-2 (as pvlib.inverter.pvwatts implements it, with pvlib's GH 541 floor at 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from foldopt.names import CONVERTER_MODELS

#: Top of the kernel's table in input power / rating [-]; beyond it a converter delivers no more
#: than at it (PVWatts has clipped at its rating long before; a curve's converter is taken to
#: limit its input at four times its rating).
ZETA_MAX = 4.0
TABLE_NODES = 2049


@dataclass(frozen=True)
class Converter:
    """One converter model, rated.

    Parameters
    ----------
    model : {'ideal', 'pvwatts', 'curve'}
        One of :data:`foldopt.names.CONVERTER_MODELS`.
    p_rated : float
        DC input rating [W] (> 0).
    efficiency : float, default 0.96
        ``pvwatts``: nominal efficiency ``eta_inv_nom`` [-].
    curve : tuple of (float, float)
        ``curve``: (input power / ``p_rated`` [-], efficiency [-]) points, the fractions strictly
        increasing.

    Raises
    ------
    ValueError
        If ``model`` is unknown, or ``curve`` has no points.
    """

    model: str = "ideal"
    p_rated: float = 1.0
    efficiency: float = 0.96
    curve: tuple = ()

    def __post_init__(self):
        if self.model not in CONVERTER_MODELS:
            raise ValueError(
                f"converter model must be one of {', '.join(CONVERTER_MODELS)}; got {self.model!r}"
            )
        if self.model == "curve" and not self.curve:
            raise ValueError("converter model curve needs its (fraction, efficiency) points")

    @property
    def ideal(self) -> bool:
        return self.model == "ideal"

    def scaled(self, factor: float) -> Converter:
        """The same converter rated ``factor`` times as much (the independent connection's two)."""
        return Converter(self.model, self.p_rated * factor, self.efficiency, self.curve)

    def delivered(self, p_in):
        """Power delivered to the load [W] for the converter's input ``p_in`` [W].

        Parameters
        ----------
        p_in : array_like
            Input power [W], >= 0.

        Returns
        -------
        numpy.ndarray
            [W], shaped as ``p_in``.
        """
        p_in = np.asarray(p_in, dtype=float)
        if self.model == "ideal":
            return p_in
        if self.model == "pvwatts":
            import pvlib

            return pvlib.inverter.pvwatts(p_in, self.p_rated, self.efficiency)
        fraction = np.array([0.0] + [point[0] for point in self.curve])
        efficiency = np.array([0.0] + [point[1] for point in self.curve])
        taken = np.minimum(p_in, ZETA_MAX * self.p_rated)
        return taken * np.interp(taken / self.p_rated, fraction, efficiency)


def delivered_table(converter: Converter) -> np.ndarray:
    """The kernel's table of delivered power / rating [-] on input nodes ``ZETA_MAX * u**2``, ``u``
    uniform on [0, 1] (:data:`TABLE_NODES` of them).

    Parameters
    ----------
    converter : Converter

    Returns
    -------
    numpy.ndarray
        (TABLE_NODES,); a single 0 for the ideal converter, which needs none.
    """
    if converter.ideal:
        return np.zeros(1)
    zeta = ZETA_MAX * np.linspace(0.0, 1.0, TABLE_NODES) ** 2
    return converter.delivered(zeta * converter.p_rated) / converter.p_rated


def table_delivered(p_in, table, p_rated: float):
    """Delivered power [W] read from :func:`delivered_table`, as the compiled kernel reads it.

    Parameters
    ----------
    p_in : array_like
        Input power [W].
    table : numpy.ndarray
        :func:`delivered_table`.
    p_rated : float
        The rating [W] the table was made for.

    Returns
    -------
    numpy.ndarray
        [W], shaped as ``p_in``.
    """
    p_in = np.asarray(p_in, dtype=float)
    zeta = np.clip(p_in / p_rated, 0.0, None)
    # NaN (a power not worked out, as series where unused) stays NaN.
    position = np.sqrt(np.minimum(np.nan_to_num(zeta), ZETA_MAX) / ZETA_MAX) * (table.size - 1)
    index = np.minimum(position.astype(np.intp), table.size - 2)
    weight = position - index
    return np.where(
        np.isnan(zeta),
        np.nan,
        p_rated * (table[index] * (1.0 - weight) + table[index + 1] * weight),
    )
