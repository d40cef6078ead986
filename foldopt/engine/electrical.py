"""Per-study electrical evaluation of panels and sub-panel pairs, exact or through tables.

With the air temperature and wind fixed for a study, a sub-panel's cell temperature, and so its
maximum power, depends only on its irradiance; a connected pair's power depends only on the two
irradiances. The fast path tabulates these once per study: a 1-D table of sub-panel maximum power
on irradiance nodes spaced quadratically (dense at low irradiance, where power bends), read by
linear interpolation in sqrt(E), on which the nodes are uniform; and 2-D tables of the parallel and
the series pair as fractions of the two maxima, over the stronger sub-panel's irradiance (the same
nodes) and the weaker/stronger irradiance ratio (:func:`_ratio_nodes`). Both pairs are symmetric,
and along ratio 1 (equal irradiance: a flat fold, or noon) identical sub-panels deliver exactly
their sum, a grid line of the tables that bilinear interpolation keeps exact, so the fast path has
no seam there; each pair's kink runs nearly along the ratio lines. The exact path solves every
step's I-V curves. ``bench/electrical.py`` and ``tests/test_electrical.py`` measure the tables'
error against it.

Tables are kept on disk, named by a hash of everything they depend on (the PV unit's parameters,
the sub-panel area, the temperature settings, the nodes, pvlib's version and
:data:`TABLE_FORMAT`), in foldopt's cache folder (:func:`foldopt.cache.cache_dir`); a second process loads
them instead of solving I-V curves again. A cache file ends with a checksum of its content
(:func:`store_cache`): a damaged one is built again, with a notice. A cache that cannot be written
is skipped.
"""

from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass

import numpy as np

from foldopt.cache import cache_dir, load_cache, store_cache
from foldopt.engine.as_built import PARTS, CircuitParts, alone_power, assemble, pair_power
from foldopt.physics.connections import connection_powers, parallel_power, series_power
from foldopt.physics.pvmodel import PVModel
from foldopt.physics.temperature import cell_temperature

IRRADIANCE_MAX = 1500.0  # [W/m^2], top of the tables; clear-sky beam stays below 1353
TABLE_NODES_1D = 1025
TABLE_NODES_2D = 161
TABLE_NODES_RATIO = 321
TABLE_FORMAT = 6  # bump when the way tables are built changes
#: The brightest light [W/m^2] and the coldest cells [C] of any study: a panel's open-circuit
#: voltage rises with both (a study's air reaches down to -60 C; minutes of cloud enhancement stay
#: below 2000 W/m^2).
BRIGHTEST, COLDEST = 2000.0, -70.0


def _nodes(count):
    return IRRADIANCE_MAX * np.linspace(0.0, 1.0, count) ** 2


def _node_position(poa, count):
    """Fractional index of irradiances on :func:`_nodes`: the nodes are uniform in sqrt(E / E_max)."""
    return np.sqrt(np.clip(poa, 0.0, IRRADIANCE_MAX) / IRRADIANCE_MAX) * (count - 1)


def _ratio_nodes(connection):
    """Weaker/stronger irradiance ratios of a pair table's second axis: uniform in the ratio for
    series (its kink lies near a ratio of Imp/Isc, close to 1), uniform in its square root for
    parallel (its kink, where the weaker sub-panel's Voc falls below the stronger one's maximum-
    power voltage, lies at small ratios)."""
    nodes = np.linspace(0.0, 1.0, TABLE_NODES_RATIO)
    return nodes**2 if connection == "parallel" else nodes


def _linear(values, position):
    """Linear interpolation of a 1-D table at fractional indices."""
    index = np.minimum(position.astype(np.intp), values.size - 2)
    weight = position - index
    return values[index] * (1.0 - weight) + values[index + 1] * weight


def _bilinear(values, first, second):
    """Bilinear interpolation of a 2-D table at fractional indices (cheaper than scipy's generic
    RegularGridInterpolator on these regular index grids)."""
    i = np.minimum(first.astype(np.intp), values.shape[0] - 2)
    j = np.minimum(second.astype(np.intp), values.shape[1] - 2)
    fi, fj = first - i, second - j
    return (values[i, j] * (1.0 - fj) + values[i, j + 1] * fj) * (1.0 - fi) + (
        values[i + 1, j] * (1.0 - fj) + values[i + 1, j + 1] * fj
    ) * fi


@dataclass
class Electrical:
    """Maximum power of panels and deliverable power of sub-panel pairs for one study.

    Parameters
    ----------
    pv : PVModel
        The electrical model of a sub-panel.
    subpanel_area : float
        Area of one sub-panel [m^2].
    temp_air, wind_speed : float, default 25 and 1
        [C], [m/s], constant over the study.
    temperature_model : {'fixed', 'sapm'}
        :func:`foldopt.physics.temperature.cell_temperature`'s model.
    bypass, switch_series : bool, default True and False
        Bypass diodes in series; series as a switching state.
    converter_efficiency : float, default 1
        Efficiency of each converter of the independent architecture [-].
    exact : bool, default False
        Solve every step's I-V curves instead of interpolating the tables.
    circuit : foldopt.engine.as_built.CircuitParts, optional
        The circuit as built; None for Shin et al.'s ideal parts.
    """

    pv: PVModel
    subpanel_area: float
    temp_air: float = 25.0
    wind_speed: float = 1.0
    temperature_model: str = "fixed"
    bypass: bool = True
    switch_series: bool = False
    converter_efficiency: float = 1.0
    exact: bool = False
    circuit: CircuitParts | None = None

    def __post_init__(self):
        self._tables = None

    @property
    def _options(self):
        return {
            "switch_series": self.switch_series,
            "converter_efficiency": self.converter_efficiency,
        }

    def _temperature(self, poa):
        return cell_temperature(poa, self.temp_air, self.wind_speed, self.temperature_model)

    def cache_key(self, name: str) -> str:
        """Hash of everything a table depends on, which names its cache file.

        Parameters
        ----------
        name : {'subpanel', 'parallel', 'series', 'switching', 'alone', 'panel'}
            The table.

        Returns
        -------
        str
            32 hexadecimal digits.
        """
        import pvlib

        settings = (
            TABLE_FORMAT,
            name,
            self.pv.model,
            repr(self.pv.unit),
            self.pv.unit_area,
            self.subpanel_area,
            self.temp_air,
            self.wind_speed,
            self.temperature_model,
            IRRADIANCE_MAX,
            TABLE_NODES_1D,
            TABLE_NODES_2D,
            TABLE_NODES_RATIO,
            pvlib.__version__,
        )
        if self._panel_side_built and name != "subpanel":
            # Only what the table holds: the converter acts after it.
            parts = self.circuit
            settings += (
                repr(parts.blocking),
                repr(parts.bypass),
                parts.load_voltage,
                parts.switch_resistance,
                self.bypass,
                self.switch_series,
            )
        return hashlib.sha256(repr(settings).encode()).hexdigest()[:32]

    @property
    def _panel_side_built(self) -> bool:
        """Whether the tables hold the circuit as built (any part but the converter not ideal)."""
        return self.circuit is not None

    def _table(self, name):
        """A table, loaded from the disk cache or built on first use: ``subpanel`` (1-D, maximum
        power), ``parallel``, ``series`` or ``switching`` (2-D) and, as built, ``alone`` and
        ``panel`` (1-D, at the load's voltage)."""
        if self._tables is None:
            self._tables = {}
        if name not in self._tables:
            path = cache_dir() / "tables" / f"{name}-{self.cache_key(name)}.npz"
            cached = load_cache(path)
            if cached is not None:
                arrays = tuple(cached[f"a{i}"] for i in range(len(cached)))
                self._tables[name] = arrays if len(arrays) == 2 else arrays[0]
                return self._tables[name]
            if name in ("subpanel", "alone", "panel"):
                g1 = _nodes(TABLE_NODES_1D)
                temp_cell = self._temperature(g1)
                if name == "subpanel":
                    power = self.pv.max_power(g1, temp_cell, self.subpanel_area)
                elif name == "alone":
                    power = alone_power(
                        self.circuit, self.pv.curves(g1, temp_cell, self.subpanel_area)
                    )
                else:
                    power = self._flat_direct(g1, temp_cell)
                self._tables[name] = (g1, power)
            else:
                self._tables[name] = self._pair_table(name)
            table = self._tables[name]
            arrays = table if isinstance(table, tuple) else (table,)
            store_cache(path, {f"a{i}": array for i, array in enumerate(arrays)})
        return self._tables[name]

    def _pair_table(self, connection):
        """A pair's power as a fraction of its two maxima over (stronger irradiance, ratio).

        The fraction is smoother than the power and zero-safe. For the ideal circuit, series is
        tabulated without bypass diodes; with ideal ones it is the larger of that and the stronger
        sub-panel alone (:func:`foldopt.physics.connections.series_power`), which needs no table.
        As built, the table holds the pair as built, bypass diodes and all
        (:func:`foldopt.engine.as_built.pair_power`).
        """
        strong, ratio = (
            grid.ravel()
            for grid in np.meshgrid(_nodes(TABLE_NODES_2D), _ratio_nodes(connection), indexing="ij")
        )
        east, west = self._curves(strong), self._curves(strong * ratio)
        bound = east.max_power() + west.max_power()
        if self._panel_side_built:
            power = pair_power(
                self.circuit, connection, east, west, self.bypass, self.switch_series
            )
        elif connection == "parallel":
            power = parallel_power(east, west)
        else:
            power = series_power(east, west, bypass=False)
        with np.errstate(invalid="ignore", divide="ignore"):
            fraction = np.where(bound > 0, power / bound, 1.0).reshape(
                TABLE_NODES_2D, TABLE_NODES_RATIO
            )
        if not self._panel_side_built or self.circuit.panel_side_ideal:
            fraction[:, -1] = (
                1.0  # identical sub-panels at equal irradiance deliver exactly their sum
            )
        return fraction

    def _curves(self, poa):
        """Sub-panels' I-V curves at irradiances ``poa`` (flat), each distinct irradiance's worked
        out once: a pair table's stronger sub-panel takes each of its nodes once a ratio, and half
        the weaker ones' irradiances repeat (products of the nodes)."""
        distinct, index = np.unique(poa, return_inverse=True)
        return self.pv.curves(distinct, self._temperature(distinct), self.subpanel_area).taken(
            index
        )

    def subpanel_power(self, poa):
        """Maximum power of one sub-panel.

        Parameters
        ----------
        poa : array_like
            Plane-of-array irradiance [W/m^2], any shape.

        Returns
        -------
        numpy.ndarray
            [W], shaped as ``poa``.
        """
        return self.max_power(poa, self.subpanel_area)

    def max_power(self, poa, area):
        """Maximum power of a panel of ``area / subpanel_area`` sub-panels in series.

        Parameters
        ----------
        poa : array_like
            Plane-of-array irradiance [W/m^2], any shape.
        area : float
            Panel area [m^2].

        Returns
        -------
        numpy.ndarray
            [W], shaped as ``poa``.
        """
        poa = np.asarray(poa, dtype=float)
        if self.exact or not self.pv.has_iv:
            return self.pv.max_power(poa, self._temperature(poa), area)
        _, p1 = self._table("subpanel")
        return _linear(p1, _node_position(poa, TABLE_NODES_1D)) * (area / self.subpanel_area)

    def panel_power(self, poa, area):
        """Power the whole flat panel (the twofold panel's two sub-panels as one) delivers to the
        load: its maximum power, as built through the converter, or at the load's voltage with
        direct coupling, its halves wired as :attr:`flat_wiring`.

        Parameters
        ----------
        poa : array_like
            Plane-of-array irradiance [W/m^2], any shape.
        area : float
            Panel area [m^2]; with direct coupling, that of the two sub-panels.

        Returns
        -------
        numpy.ndarray
            [W], shaped as ``poa``.
        """
        if self.circuit is None:
            return self.max_power(poa, area)
        side = self._panel_side(poa, area)
        zeros = np.zeros_like(side)
        return assemble(
            self.circuit,
            {**dict.fromkeys(PARTS, zeros), "panel": side},
            switch_series=False,
            converter_efficiency=1.0,
            with_state=False,
        )[0]["panel"]

    def _panel_side(self, poa, area):
        """The whole panel's power on the panel side [W]: its maximum, or at the load's voltage."""
        poa = np.asarray(poa, dtype=float)
        if not self.circuit.direct or not self.pv.has_iv:
            return self.max_power(poa, area)
        if not np.isclose(area, 2.0 * self.subpanel_area):
            raise ValueError(
                f"the direct-coupled panel's table is of area {2.0 * self.subpanel_area:g} m^2, "
                f"not {area:g}"
            )
        if self.exact:
            return self._flat_direct(poa, self._temperature(poa))
        _, p1 = self._table("panel")
        return _linear(p1, _node_position(poa, TABLE_NODES_1D))

    @functools.cached_property
    def flat_wiring(self) -> str | None:
        """How the flat panel's two halves are wired for a direct-coupled load: ``'series'`` (one
        string of all its cells) or ``'parallel'`` (behind the blocking diodes), whichever delivers
        more at the load's voltage at STC (1000 W/m^2, the study's cell temperature); None behind a
        converter, where the flat panel is one string at its maximum power point.

        A designer wires a panel for its load: one string of the whole panel works at twice the
        sub-panel's voltage, so at a sub-panel's voltage it would deliver about half its power and
        flatter the twofold panel.
        """
        if self.circuit is None or not self.circuit.direct or not self.pv.has_iv:
            return None
        stc = np.array([1000.0])
        temp_cell = self._temperature(stc)
        parallel, series = (
            self._flat_wired(stc, temp_cell, wiring)[0] for wiring in ("parallel", "series")
        )
        return "parallel" if parallel > series else "series"

    @functools.cached_property
    def beyond_reach(self) -> str:
        """Why no design wired directly runs, where the load's voltage is above the highest
        open-circuit voltage of the panel's cells (all of them in one string, in :data:`BRIGHTEST`
        light at :data:`COLDEST`): a note for every such design; ``''`` elsewhere."""
        if self.circuit is None or not self.circuit.direct or not self.pv.has_iv:
            return ""
        area = 2.0 * self.subpanel_area
        if (
            self.circuit.load_voltage
            <= self.pv.curves(np.array([BRIGHTEST]), COLDEST, area).v_oc[0]
        ):
            return ""
        stc = self.pv.curves(np.array([1000.0]), 25.0, area).v_oc[0]
        return (
            f"the load's {self.circuit.load_voltage:g} V is above the panel's open-circuit voltage, "
            f"{stc:.3g} V at STC with all its cells in series"
        )

    def _flat_wired(self, poa, temp_cell, wiring):
        half = self.pv.curves(poa, temp_cell, self.subpanel_area)
        if wiring == "parallel":
            return pair_power(self.circuit, "parallel", half, half, self.bypass, False)
        # Equal halves in series are the whole panel's string (units in series): no bypass diode conducts.
        return alone_power(self.circuit, self.pv.curves(poa, temp_cell, 2.0 * self.subpanel_area))

    def _flat_direct(self, poa, temp_cell):
        """The flat panel's power at the load's voltage, wired as :attr:`flat_wiring` [W]."""
        return self._flat_wired(poa, temp_cell, self.flat_wiring)

    def parts(self, poa_east, poa_west, series: bool = True) -> dict:
        """The panel side of the circuit as built (:data:`foldopt.engine.as_built.PARTS`), exact or
        from the tables as the kernel reads them.

        Parameters
        ----------
        poa_east, poa_west : array_like
            Each sub-panel's plane-of-array irradiance [W/m^2], broadcast.
        series : bool, default True
            Whether to work out the series power (NaN otherwise).

        Returns
        -------
        dict of numpy.ndarray
            [W] per part.
        """
        parts = self.circuit
        poa_east, poa_west = np.broadcast_arrays(
            np.asarray(poa_east, float), np.asarray(poa_west, float)
        )
        m_east, m_west = self.subpanel_power(poa_east), self.subpanel_power(poa_west)
        side = {"m_east": m_east, "m_west": m_west}
        if not self.pv.has_iv:
            total = m_east + m_west
            return {
                **side,
                "a_east": m_east,
                "a_west": m_west,
                "parallel": total,
                "series": total,
                "switching": np.maximum(np.maximum(m_east, m_west), total),
                "panel": 2.0 * m_east,
            }
        names = (
            ("parallel",)
            + (("series",) if series else ())
            + (("switching",) if parts.switch_table else ())
        )
        if self.exact:
            east = self.pv.curves(poa_east, self._temperature(poa_east), self.subpanel_area)
            west = self.pv.curves(poa_west, self._temperature(poa_west), self.subpanel_area)
            side.update(
                {
                    name: pair_power(parts, name, east, west, self.bypass, self.switch_series)
                    for name in names
                }
            )
            side["a_east"], side["a_west"] = (
                (alone_power(parts, east), alone_power(parts, west))
                if parts.direct
                else (m_east, m_west)
            )
        else:
            root_east = np.sqrt(np.clip(poa_east, 0.0, IRRADIANCE_MAX) / IRRADIANCE_MAX)
            root_west = np.sqrt(np.clip(poa_west, 0.0, IRRADIANCE_MAX) / IRRADIANCE_MAX)
            strong, weak = np.maximum(root_east, root_west), np.minimum(root_east, root_west)
            with np.errstate(invalid="ignore", divide="ignore"):
                root_ratio = np.where(strong > 0, weak / strong, 1.0)
            at_strong, bound = strong * (TABLE_NODES_2D - 1), m_east + m_west
            for name in names:
                at_ratio = (root_ratio**2 if name == "series" else root_ratio) * (
                    TABLE_NODES_RATIO - 1
                )
                side[name] = (
                    np.clip(_bilinear(self._table(name), at_strong, at_ratio), 0.0, 1.0) * bound
                )
            if parts.direct:
                _, alone = self._table("alone")
                side["a_east"] = _linear(alone, root_east * (TABLE_NODES_1D - 1))
                side["a_west"] = _linear(alone, root_west * (TABLE_NODES_1D - 1))
            else:
                side["a_east"], side["a_west"] = m_east, m_west
        if not parts.switch_table:
            side["switching"] = np.maximum(
                np.maximum(side["a_east"], side["a_west"]), side["parallel"]
            )
        if not series:
            side["series"] = np.full(m_east.shape, np.nan)
        side["panel"] = (
            self._panel_side(poa_east, 2.0 * self.subpanel_area) if parts.direct else 2.0 * m_east
        )
        return side

    def connections(self, poa_east, poa_west, series: bool = True, with_state: bool = True):
        """Every connection's power and the switching state, as :func:`connection_powers`.

        Parameters
        ----------
        poa_east, poa_west : array_like
            Each sub-panel's plane-of-array irradiance [W/m^2], broadcast.
        series : bool, default True
            Whether to work out the series power; without, it is left NaN (and its table
            unbuilt), for callers whose connection and switch do not use it.
        with_state : bool, default True
            Whether to work out the switch state.

        Returns
        -------
        powers : dict of numpy.ndarray
            Power [W] per name of :data:`foldopt.names.CONNECTIONS`.
        state : numpy.ndarray of int or None
            Index into :data:`foldopt.physics.connections.SWITCH_STATES` per step.
        """
        if self.circuit is not None:
            powers, state = assemble(
                self.circuit,
                self.parts(poa_east, poa_west, series),
                with_state=with_state,
                **self._options,
            )
            del powers["panel"]
            return powers, state
        options = {**self._options, "with_state": with_state}
        poa_east, poa_west = np.broadcast_arrays(
            np.asarray(poa_east, float), np.asarray(poa_west, float)
        )
        if not self.pv.has_iv or self.exact:
            p_east, p_west = self.subpanel_power(poa_east), self.subpanel_power(poa_west)
        if not self.pv.has_iv:
            return connection_powers(p_east, p_west, **options)
        if self.exact:
            east = self.pv.curves(poa_east, self._temperature(poa_east), self.subpanel_area)
            west = self.pv.curves(poa_west, self._temperature(poa_west), self.subpanel_area)
            p_parallel = parallel_power(east, west)
            p_series = (
                series_power(east, west, self.bypass) if series else np.full(p_east.shape, np.nan)
            )
            return connection_powers(p_east, p_west, p_parallel, p_series, **options)
        east, west = np.clip(poa_east, 0.0, IRRADIANCE_MAX), np.clip(poa_west, 0.0, IRRADIANCE_MAX)
        # Every table's irradiance nodes are uniform in sqrt(E / E_max): one square root serves all.
        root_east, root_west = np.sqrt(east / IRRADIANCE_MAX), np.sqrt(west / IRRADIANCE_MAX)
        _, p1 = self._table("subpanel")
        p_east = _linear(p1, root_east * (TABLE_NODES_1D - 1))
        p_west = _linear(p1, root_west * (TABLE_NODES_1D - 1))
        bound = p_east + p_west
        strong, weak = np.maximum(root_east, root_west), np.minimum(root_east, root_west)
        with np.errstate(invalid="ignore", divide="ignore"):
            root_ratio = np.where(strong > 0, weak / strong, 1.0)
        at_strong = strong * (TABLE_NODES_2D - 1)
        p_parallel = (
            np.clip(
                _bilinear(self._table("parallel"), at_strong, root_ratio * (TABLE_NODES_RATIO - 1)),
                0.0,
                1.0,
            )
            * bound
        )
        if series:
            fraction = _bilinear(
                self._table("series"), at_strong, root_ratio**2 * (TABLE_NODES_RATIO - 1)
            )
            p_series = np.clip(fraction, 0.0, 1.0) * bound
            if self.bypass:
                p_series = np.maximum(p_series, np.maximum(p_east, p_west))
        else:
            p_series = np.full(p_east.shape, np.nan)
        return connection_powers(p_east, p_west, p_parallel, p_series, **options)
