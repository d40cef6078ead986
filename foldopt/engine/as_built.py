"""The circuit as built in the engine: its parts for one study, their tables, and what each
connection delivers to the load.

Shin et al.'s parts are ideal: diodes without a forward drop, no switch resistance, converters
that deliver their input at the maximum power point. A study's ``circuit`` may change each
(:class:`foldopt.inputs.circuit_section.Circuit`); :func:`circuit_parts` gives the engine's
:class:`CircuitParts` of it, None for the ideal circuit, whose path through the engine is unchanged.

As built, a connection's power has two stages. The panel side: each sub-panel's maximum power
(``m_east``, ``m_west``, the bound of every connection), what it delivers alone (``a_*``: its
maximum power, or with direct coupling its power at the load's voltage), the pair in parallel
behind blocking diodes, in series with bypass diodes, switched (the best of those states with
the switch's resistance in each path) and the whole flat panel (:func:`foldopt.physics.circuit`).
The load side: a maximum-power-point converter delivers its efficiency curve's share of that
(:mod:`foldopt.physics.converter`); the independent connection's two converters are each rated
for one sub-panel. The tables hold the panel side as the ideal circuit's do (pairs as fractions of
the two maxima); :func:`assemble` is the load side, the NumPy mirror of the kernel's
``_built_power``.

The module may import numpy, :mod:`foldopt.physics` and :mod:`foldopt.inputs`' circuit section.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from foldopt.inputs.circuit_section import Circuit
from foldopt.physics import circuit as built
from foldopt.physics.converter import Converter, delivered_table, table_delivered
from foldopt.physics.diodes import Diode

#: The panel-side parts of :func:`assemble`, in the kernel's order.
PARTS = ("m_east", "m_west", "a_east", "a_west", "parallel", "series", "switching", "panel")


@dataclass(frozen=True)
class CircuitParts:
    """The circuit of one study as the engine evaluates it.

    Parameters
    ----------
    blocking, bypass : foldopt.physics.diodes.Diode
        The blocking diode in each parallel path and the bypass diode across each sub-panel.
    converter : foldopt.physics.converter.Converter
        The whole panel's converter, rated.
    load_voltage : float or None
        The load's voltage [V] with direct coupling; None behind a converter.
    switch_resistance : float
        The switch's on-resistance in each sub-panel's path [ohm].
    """

    blocking: Diode
    bypass: Diode
    converter: Converter
    load_voltage: float | None = None
    switch_resistance: float = 0.0

    @property
    def direct(self) -> bool:
        return self.load_voltage is not None

    @property
    def switch_table(self) -> bool:
        """Whether switching needs its own table (a switch resistance changes its states)."""
        return self.switch_resistance > 0.0

    @property
    def panel_side_ideal(self) -> bool:
        """Whether the panel side is the ideal one (only the converter is as built)."""
        return (
            self.blocking.model == "ideal"
            and self.bypass.model == "ideal"
            and not self.direct
            and not self.switch_table
        )

    @property
    def conv_table(self) -> np.ndarray:
        return delivered_table(self.converter)

    @property
    def conv_rated(self) -> float:
        """The kernel's converter rating [W]: 0 for an ideal converter."""
        return 0.0 if self.converter.ideal else float(self.converter.p_rated)


def circuit_parts(circuit: Circuit | None, p_rated: float) -> CircuitParts | None:
    """A study's circuit for the engine, None where every part is ideal.

    Parameters
    ----------
    circuit : foldopt.inputs.circuit_section.Circuit or None
        The circuit as built (:attr:`foldopt.engine.options.ElectricalOptions.circuit`).
    p_rated : float
        The converter's default rating [W]: the panel's maximum power at STC.

    Returns
    -------
    CircuitParts or None
    """
    if circuit is None or circuit.ideal:
        return None
    spec = circuit.converter
    converter = Converter(
        spec.model,
        spec.p_rated or float(p_rated),
        spec.efficiency,
        tuple(tuple(point) for point in spec.curve or ()),
    )
    return CircuitParts(
        circuit.blocking_diode.build(),
        circuit.bypass_diode.build(),
        converter,
        circuit.load_voltage if circuit.coupling == "direct" else None,
        float(circuit.switch_resistance),
    )


def pair_power(parts: CircuitParts, name: str, east, west, bypass: bool, switch_series: bool):
    """The pair's power on the panel side as built [W] (:mod:`foldopt.physics.circuit`).

    Parameters
    ----------
    parts : CircuitParts
    name : {'parallel', 'series', 'switching'}
    east, west : foldopt.physics.pvmodel.IVCurve
    bypass, switch_series : bool
        Bypass diodes in series; series as a switching state.

    Returns
    -------
    numpy.ndarray
    """
    bypass_diode = parts.bypass if bypass else None
    if name == "parallel":
        return built.parallel_power(east, west, parts.blocking, parts.load_voltage)
    if name == "series":
        return built.series_power(east, west, bypass_diode, parts.load_voltage)
    return built.switching_power(
        east,
        west,
        parts.blocking,
        bypass_diode,
        switch_series,
        parts.load_voltage,
        parts.switch_resistance,
    )[0]


def alone_power(parts: CircuitParts, curve):
    """What one sub-panel (or the whole panel) delivers alone on the panel side [W]."""
    return built.alone_power(curve, parts.load_voltage)


def assemble(
    parts: CircuitParts,
    side: dict,
    *,
    switch_series: bool,
    converter_efficiency: float,
    with_state: bool = True,
):
    """Every connection's power delivered to the load [W] from the panel side, as the kernel does.

    Parameters
    ----------
    parts : CircuitParts
    side : dict of numpy.ndarray
        One array per name of :data:`PARTS`, broadcast ("series" may be NaN where unused).
    switch_series : bool
        Whether switching may select series.
    converter_efficiency : float
        The ideal converters' efficiency of ``independent`` [-].
    with_state : bool
        Whether to work out the switch state.

    Returns
    -------
    powers : dict of numpy.ndarray
        Per connection, and ``panel``.
    state : numpy.ndarray of int or None
        Index into :data:`foldopt.physics.connections.SWITCH_STATES` of the best state before the
        switch's resistance, the states' order as the ideal circuit breaks ties (the switching
        power itself includes the resistance).
    """
    table, rated = parts.conv_table, parts.converter.p_rated

    def deliver(power, rating=rated):
        return power if parts.converter.ideal else table_delivered(power, table, rating)

    switching = side["switching"]
    if switch_series and not parts.switch_table:
        switching = np.maximum(switching, side["series"])
    powers = {
        "east": deliver(side["a_east"]),
        "west": deliver(side["a_west"]),
        "parallel": deliver(side["parallel"]),
        "series": deliver(side["series"]),
        "independent": converter_efficiency
        * (deliver(side["m_east"], 0.5 * rated) + deliver(side["m_west"], 0.5 * rated)),
        "switching": deliver(switching),
        "panel": deliver(side["panel"]),
    }
    if not with_state:
        return powers, None
    states = [side["a_east"], side["a_west"], side["parallel"]] + (
        [side["series"]] if switch_series else []
    )
    stacked = np.stack(np.broadcast_arrays(*states))
    best = stacked.max(axis=0)
    return powers, np.argmax(stacked >= best * (1 - 1e-6) - 1e-12, axis=0)
