"""Electrical models of one (sub-)panel: its I-V curve and maximum power.

Four models (foldopt SPEC, "PV electrical model"):

- ``ideal``: P = efficiency * area * irradiance; no I-V curve.
- ``single-diode``: the five-parameter model of De Soto et al. [1]_ through pvlib
  (``calcparams_desoto``, or ``calcparams_cec`` for modules of pvlib's CEC database [2]_). The
  default unit is the SunPower A-300 cell that Shin et al. name; any CEC module can be chosen.
- ``b-model``: the empirical model of Robles Algarin et al. [3]_ Eq. 8-11 (after Ortiz-Rivera
  [4]_), with the 200 W panel of their Table 1.
- ``pvwatts``: PVWatts' DC model [5]_ through ``pvlib.pvsystem.pvwatts_dc``, the rating
  efficiency x area x 1000 W/m^2, less a system loss; no I-V curve.

A panel of a given area is ``m = area / unit_area`` identical units (cells or modules) in series,
``m`` kept fractional so that power scales exactly with area: a series string multiplies the
unit's voltage by ``m`` at the same current (for the single-diode model ``a``, ``R_s`` and
``R_sh`` scale by ``m``).

References
----------
.. [1] W. De Soto, S. A. Klein, W. A. Beckman, "Improvement and validation of a model for
   photovoltaic array performance", Solar Energy 80(1), 78-88, 2006.
.. [2] A. P. Dobos, "An improved coefficient calculator for the California Energy Commission
   6 parameter photovoltaic module model", J. Solar Energy Eng. 134, 2012.
.. [3] C. Robles Algarin, A. Ospino Castro, J. Casas Naranjo, "Dual-Axis Solar Tracker for Using
   in Photovoltaic Systems", Eq. 8 (I-V curve), 9 (V_x), 10 (I_x), 11 (fit of b), Table 1.
.. [4] E. I. Ortiz-Rivera, F. Z. Peng, "Analytical model for a photovoltaic module using the
   electrical characteristics provided by the manufacturer data sheet", IEEE PESC 2005.
.. [5] A. P. Dobos, "PVWatts Version 5 Manual", NREL/TP-6A20-62641, 2014, Eq. 1 (DC power) and
   Eq. 3 (system losses).
.. [6] A. Jain, A. Kapoor, "Exact analytical solutions of the parameters of real solar cells using
   Lambert W-function", Solar Energy Materials and Solar Cells 81(2), 269-277, 2004.
"""

from __future__ import annotations

import difflib
import functools
import operator
import re
from dataclasses import dataclass

import numpy as np

from foldopt.names import IV_MODELS, PV_MODELS
from foldopt.physics.temperature import irradiance_coefficient

IRRADIANCE_REF = 1000.0  # [W/m^2], STC
TEMPERATURE_REF = 25.0  # [C], STC


@dataclass(frozen=True)
class DiodeUnit:
    """Reference (STC) single-diode parameters of one unit, De Soto form [1]_.

    Names and units as ``pvlib.pvsystem.calcparams_desoto``'s; ``adjust`` is the CEC model's
    temperature-coefficient adjustment [%] (``calcparams_cec``), None selects De Soto.
    """

    name: str
    area: float  # [m^2]
    I_L_ref: float  # [A]
    I_o_ref: float  # [A]
    R_s: float  # [ohm]
    R_sh_ref: float  # [ohm]
    a_ref: float  # [V]
    alpha_sc: float  # [A/C]
    EgRef: float = 1.121  # [eV]
    dEgdT: float = -0.0002677  # [1/K]
    adjust: float | None = None


#: SunPower A-300 cell (125 mm pseudo-square, 149.45 cm^2). Typical STC ratings as commonly
#: quoted from SunPower's A-300 datasheet: Voc 0.670 V, Isc 5.90 A, Vmp 0.560 V, Imp 5.54 A
#: (3.10 W), dVoc/dT -1.9 mV/C; alpha_sc taken as +0.05 %/C of Isc (typical of c-Si). pvlib's
#: ``fit_desoto`` diverges on these data (it drives R_sh negative), so the five De Soto equations
#: (Isc, Voc, the MPP point, dP/dV = 0 at the MPP, dVoc/dT) were solved by bounded least squares
#: with pvlib's ``i_from_v`` / ``calcparams_desoto``; every residual is below 1e-11. The fit gives
#: -0.34 %/C in power (datasheet: -0.38 %/C) and 19.8 % efficiency at 100 W/m^2 (20.8 % at STC).
A300_CELL = DiodeUnit(
    name="SunPower A-300 cell",
    area=0.014945,
    I_L_ref=5.906561,
    I_o_ref=9.967257e-12,
    R_s=5.925657e-3,
    R_sh_ref=5.328437,
    a_ref=2.473579e-2,
    alpha_sc=5.90 * 0.0005,
)


@functools.cache
def _cec_modules():
    import pvlib

    return pvlib.pvsystem.retrieve_sam("CECMod")


def _squashed(name: str) -> str:
    return re.sub(r"[^0-9a-z]", "", name.lower())


@functools.cache
def _squashed_modules() -> dict:
    """Every module of the database by its squashed name (:func:`_squashed`), worked out once: a
    module is looked up by each PV model that names it."""
    return {_squashed(module): module for module in _cec_modules().columns}


def cec_module_name(name: str) -> str:
    """The exact name in pvlib's bundled CEC database [2]_ of a module given by any part of it,
    without regard to case and punctuation: ``CS5P-220M`` is ``Canadian_Solar_Inc__CS5P_220M``.

    Parameters
    ----------
    name : str
        The module's name in the database, or any part of it.

    Returns
    -------
    str
        The database's column name of the module (``pvlib.pvsystem.retrieve_sam("CECMod")``).

    Raises
    ------
    ValueError
        Where no module matches (with the closest names) or several do (with some of them).
    """
    modules = _cec_modules().columns
    if name in modules:
        return name
    key = _squashed(name)
    squashed = _squashed_modules()
    if key in squashed:
        return squashed[key]
    matches = [module for short, module in squashed.items() if key and key in short]
    if len(matches) == 1:
        return matches[0]
    if matches:
        raise ValueError(
            f"module {name!r} matches {len(matches)} modules of pvlib's CEC database, such as "
            f"{', '.join(matches[:4])}; give more of the name"
        )
    close = [squashed[short] for short in difflib.get_close_matches(key, squashed, n=4, cutoff=0.6)]
    hint = f"; did you mean {', '.join(close)}?" if close else ""
    raise ValueError(f"module {name!r} is not in pvlib's CEC database{hint}")


def cec_module(name: str) -> DiodeUnit:
    """A module of pvlib's bundled CEC database [2]_ as a single-diode unit.

    Parameters
    ----------
    name : str
        The module's name, or any part of it (:func:`cec_module_name`).

    Returns
    -------
    DiodeUnit
        Its reference parameters and area, with the CEC ``Adjust`` [%].

    Raises
    ------
    ValueError
        Where no module or several match ``name``.
    """
    name = cec_module_name(name)
    modules = _cec_modules()
    m = modules[name]
    return DiodeUnit(
        name=name,
        area=float(m["A_c"]),
        I_L_ref=float(m["I_L_ref"]),
        I_o_ref=float(m["I_o_ref"]),
        R_s=float(m["R_s"]),
        R_sh_ref=float(m["R_sh_ref"]),
        a_ref=float(m["a_ref"]),
        alpha_sc=float(m["alpha_sc"]),
        adjust=float(m["Adjust"]),
    )


@dataclass(frozen=True)
class BModelPanel:
    """A panel of the b-model [3]_ Eq. 8-10, as rated at STC."""

    name: str
    i_sc: float  # [A]
    v_oc: float  # [V]
    v_mp: float  # [V]
    i_mp: float  # [A]
    tc_v: float  # [V/C]
    tc_i: float  # [A/C]
    v_max: float  # [V], 103 % of Voc [3]
    v_min: float  # [V], 85 % of Voc [3]

    @property
    def b(self) -> float:
        """Characteristic constant fitted from the rated MPP (Eq. 8 with Eq. 11's 1 - e^(-1/b) = 1)."""
        return fit_b(self.v_oc, self.i_sc, self.v_mp, self.i_mp)

    @property
    def p_mp(self) -> float:
        return self.v_mp * self.i_mp


#: Robles Algarin et al. Table 1: the 200 W panel of their tracker tests.
ROBLES_200W = BModelPanel(
    name="Robles Algarin et al. 200 W panel (Table 1)",
    i_sc=8.21,
    v_oc=32.1,
    v_mp=26.01,
    i_mp=7.69,
    tc_v=-0.07,
    tc_i=0.002,
    v_max=33.06,
    v_min=27.28,
)


def fit_b(v_x, i_x, voltage, current):
    """The b-model constant from one I-V point, Robles Algarin et al. Eq. 8 with Eq. 11.

    With ``1 - exp(-1/b) ~ 1``, Eq. 8 gives ``I / I_x = 1 - exp((V / V_x - 1) / b)``, so
    ``b = (V / V_x - 1) / ln(1 - I / I_x)``.

    Parameters
    ----------
    v_x, i_x : array_like
        The curve's end points [V], [A]: open-circuit voltage and short-circuit current.
    voltage, current : array_like
        A point of the curve [V], [A], usually the maximum-power point.

    Returns
    -------
    numpy.ndarray
        b [-].

    Examples
    --------
    The 200 W panel of Robles Algarin et al. Table 1 (their b = 0.068):

    >>> print(round(float(fit_b(32.1, 8.21, 26.01, 7.69)), 4))
    0.0688
    """
    return (voltage / v_x - 1.0) / np.log(1.0 - current / i_x)


@dataclass(frozen=True)
class IVCurve:
    """I-V curves of many (sub-)panels at once; parameters are arrays of one shape.

    ``current(V)`` and ``voltage(I)`` accept arrays of the parameters' shape or with one extra
    trailing axis (a grid of operating points per curve).

    Parameters
    ----------
    model : {'single-diode', 'b-model'}
    params : tuple of numpy.ndarray
        ``single-diode``: ``photocurrent, saturation_current, resistance_series,
        resistance_shunt, nNsVth`` [A, A, ohm, ohm, V], pvlib's ``i_from_v`` order.
        ``b-model``: ``v_x, i_x, b`` [V, A, -] (Robles Algarin et al. Eq. 8-10).
    """

    model: str
    params: tuple

    def _params(self, x):
        return [trailing_axes(p, x) for p in self.params]

    @functools.cached_property
    def _terms(self):
        """The terms of :meth:`current` and :meth:`voltage` that depend on the parameters alone,
        worked out once a curve: a pair's golden-section search calls both some 40 times on the
        same curves (:func:`foldopt.physics.connections.parallel_power`).

        For the single-diode model these are the terms of pvlib's Lambert-W solutions
        (``pvlib.pvsystem.i_from_v`` and ``v_from_i``, method ``lambertw``: Jain and Kapoor [6]_
        Eq. 2 and 3, in the shunt conductance ``G_sh = 1 / R_sh``), each computed as pvlib computes
        it; :meth:`current` and :meth:`voltage` do pvlib's remaining operations in its order, so
        they return pvlib's values to the bit. None where this pvlib solves otherwise (it does
        not expose its Lambert W): pvlib's functions are called then.
        """
        if self.model == "b-model":
            v_x, i_x, b = self.params
            return {"scale": i_x / -np.expm1(-1.0 / b)}
        import pvlib.singlediode

        if not hasattr(pvlib.singlediode, "_lambertw_pvlib"):
            return None
        # Contiguous, as pvlib's masked copies are: NumPy may take another loop (and other last
        # bits) for its transcendental functions on strided arrays.
        il, io, rs, rsh, a = (np.ascontiguousarray(p, dtype=float) for p in self.params)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            gsh = 1.0 / rsh
            denominator = rs * gsh + 1.0
            i_scale, v_scale = a * denominator, gsh * a
            return {
                # i_from_v: Lambert W where R_s > 0, explicit where R_s = 0.
                "i_lambert": 0.0 < rs,
                "i_explicit": 0.0 == rs,
                "i_factor": rs * io / i_scale,
                "i_shift": rs * (il + io),
                "i_scale": i_scale,
                "i_offset": il + io,
                "denominator": denominator,
                "a_over_rs": a / rs,
                # v_from_i: Lambert W where G_sh > 0, explicit where G_sh = 0 (R_sh infinite).
                "v_lambert": 0.0 < gsh,
                "v_explicit": 0.0 == gsh,
                "v_factor": io / v_scale,
                "v_scale": v_scale,
                "v_log": np.log(io) - np.log(gsh) - np.log(a),
                "gsh": gsh,
            }

    @functools.cached_property
    def _explicit_anywhere(self):
        """Whether any curve takes :meth:`current`'s and :meth:`voltage`'s explicit forms (R_s = 0,
        R_sh infinite): elsewhere they skip them."""
        terms = self._terms
        return not np.all(terms["i_lambert"]), not np.all(terms["v_lambert"])

    @functools.cached_property
    def _by_rank(self):
        """:meth:`_diode_terms`' shaped terms and parameters by the rank of what they meet."""
        return {}

    def _diode_terms(self, x):
        """:attr:`_terms` and the parameters, shaped to broadcast against ``x`` (once a rank: a
        search asks at the same rank some 40 times)."""
        rank = np.ndim(x)
        if rank not in self._by_rank:
            names = tuple(self._terms)
            shaped = [trailing_axes(p, x) for p in (*self._terms.values(), *self.params)]
            self._by_rank[rank] = dict(zip(names, shaped)), shaped[len(names) :]
        return self._by_rank[rank]

    def current(self, voltage):
        """Current of each curve at a voltage.

        Parameters
        ----------
        voltage : array_like
            [V], of the parameters' shape or with one extra trailing axis.

        Returns
        -------
        numpy.ndarray
            Current [A]; negative beyond open circuit.
        """
        if self.model == "single-diode":
            import pvlib

            if self._terms is None:
                return pvlib.pvsystem.i_from_v(voltage, *self._params(voltage))
            t, (il, io, _, _, a) = self._diode_terms(voltage)
            # The Lambert-W argument may overflow to inf where the explicit form holds instead.
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                w = pvlib.singlediode._lambertw_pvlib(
                    t["i_factor"] * np.exp((t["i_shift"] + voltage) / t["i_scale"])
                )
                current = (t["i_offset"] - voltage * t["gsh"]) / t["denominator"] - t[
                    "a_over_rs"
                ] * w
                if not self._explicit_anywhere[0]:
                    return current
                explicit = il - io * np.expm1(voltage / a) - t["gsh"] * voltage
            return np.where(t["i_lambert"], current, np.where(t["i_explicit"], explicit, np.nan))
        v_x, i_x, b = self._params(voltage)
        scale = trailing_axes(self._terms["scale"], voltage)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(v_x > 0, scale * -np.expm1((voltage / v_x - 1.0) / b), 0.0)

    def voltage(self, current):
        """Voltage of each curve at a current.

        Parameters
        ----------
        current : array_like
            [A], of the parameters' shape or with one extra trailing axis.

        Returns
        -------
        numpy.ndarray
            Voltage [V]; NaN or negative beyond short circuit.
        """
        if self.model == "single-diode":
            # pvlib's Lambert-W overflows for practically dark cells; `lit` handles those.
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                import pvlib

                if self._terms is None:
                    return pvlib.pvsystem.v_from_i(current, *self._params(current))
                t, (il, io, rs, _, a) = self._diode_terms(current)
                exponent = (-current + il + io) / t["v_scale"]
                argument = t["v_factor"] * np.exp(exponent)
                # Where the argument overflows, Lambert W from its logarithm.
                overflow = np.isinf(argument)
                finite = ~overflow
                w = np.empty_like(argument)
                w[finite] = pvlib.singlediode._lambertw_pvlib(argument[finite])
                if np.any(overflow):
                    w[overflow] = pvlib.singlediode._log_lambertw((t["v_log"] + exponent)[overflow])
                voltage = (t["i_offset"] - current) / t["gsh"] - current * rs - a * w
                if not self._explicit_anywhere[1]:
                    return voltage
                explicit = a * np.log1p((il - current) / io) - current * rs
            return np.where(t["v_lambert"], voltage, np.where(t["v_explicit"], explicit, np.nan))
        v_x, i_x, b = self._params(current)
        scale = trailing_axes(self._terms["scale"], current)
        with np.errstate(divide="ignore", invalid="ignore"):
            return v_x * (1.0 + b * np.log1p(-current / scale))

    def taken(self, indices) -> IVCurve:
        """The curves at ``indices`` (as ``numpy.take``, a curve as often as it is indexed), with
        the derived values it holds (short-circuit current, open-circuit voltage, maximum-power
        point) worked out once a curve rather than once a copy: an electrical table pairs each
        stronger sub-panel's curve with every ratio, and many weaker sub-panels share an
        irradiance.

        Parameters
        ----------
        indices : array_like of int
            Into the curves (flat).

        Returns
        -------
        IVCurve
            Shaped as ``indices``.
        """
        copies = IVCurve(self.model, tuple(np.take(p, indices) for p in self.params))
        vars(copies)["_taken_from"] = (self, indices)
        for name in ("i_sc", "v_oc", "_mpp"):
            value = copies.per_curve(operator.attrgetter(name))
            vars(copies)[name] = (
                tuple(map(_kept, value)) if isinstance(value, tuple) else _kept(value)
            )
        return copies

    def per_curve(self, function):
        """``function(curves)``, an array of one value per curve or a tuple of such arrays, worked
        out once per distinct curve where these curves were taken from fewer (:meth:`taken`).

        Parameters
        ----------
        function : callable
            Of an :class:`IVCurve`, each curve's values independent of the others'.

        Returns
        -------
        numpy.ndarray or tuple of numpy.ndarray
            Shaped as the curves.
        """
        if "_taken_from" not in vars(self):
            return function(self)
        curves, indices = vars(self)["_taken_from"]
        value = function(curves)
        if isinstance(value, tuple):
            return tuple(np.take(v, indices) for v in value)
        return np.take(value, indices)

    @functools.cached_property
    def i_sc(self):
        return _kept(np.nan_to_num(self.current(np.zeros_like(self.params[0]))))

    @property
    def lit(self):
        """Whether each curve sources any current worth modelling (short-circuit current > 1 nA).

        For practically dark cells pvlib's ``v_from_i`` returns NaN or absurd voltages (1e24 V seen
        at 70 C); such sub-panels are taken as delivering nothing.
        """
        return self.i_sc > 1e-9

    @functools.cached_property
    def v_oc(self):
        if self.model == "b-model":
            return self.params[0]
        return _kept(
            np.where(self.lit, np.nan_to_num(self.voltage(np.zeros_like(self.params[0]))), 0.0)
        )

    def mpp(self):
        """Maximum power [W] and its voltage [V] of each curve (both 0 for a dark curve), worked
        out once a curve (read-only arrays: an electrical table's pair asks for them twice, its
        bound and its connection)."""
        return self._mpp

    @functools.cached_property
    def _mpp(self):
        if self.model == "single-diode":
            import pvlib

            mpp = pvlib.pvsystem.max_power_point(*self.params, method="newton")
            lit = self.lit
            power = np.clip(np.nan_to_num(np.asarray(mpp["p_mp"], dtype=float)), 0.0, None)
            return _kept(np.where(lit, power, 0.0)), _kept(
                np.where(lit, np.nan_to_num(np.asarray(mpp["v_mp"], dtype=float)), 0.0)
            )
        # Eq. 8: dP/dV = 0 has the closed form v = b (W(e^(1 + 1/b)) - 1), v = V / V_x, for all
        # irradiances; Lambert's W of the log-argument avoids overflow for small b.
        v_x, i_x, b = self.params
        w = _lambertw_exp(1.0 + 1.0 / b)
        v_mp = v_x * b * (w - 1.0)
        return _kept(np.where(v_x > 0, v_mp * self.current(v_mp), 0.0)), _kept(
            np.where(v_x > 0, v_mp, 0.0)
        )

    def max_power(self):
        """Maximum power [W] of each curve (a new array)."""
        return self.mpp()[0].copy()


def trailing_axes(value, like):
    """``value`` (of the curves' shape) with trailing axes of 1 to broadcast against ``like``."""
    value = np.asarray(value)
    return np.reshape(value, value.shape + (1,) * (np.ndim(like) - value.ndim))


def _kept(values):
    """``values`` made read-only (a NumPy scalar is already): an :class:`IVCurve` keeps it for every
    later reader."""
    if isinstance(values, np.ndarray):
        values.flags.writeable = False
    return values


def _lambertw_exp(x):
    """W(e^x) for large x, by Newton iteration on w + ln w = x."""
    x = np.asarray(x, dtype=float)
    from scipy.special import lambertw

    w = np.where(x < 50, np.real(lambertw(np.exp(np.minimum(x, 50)))), x - np.log(x))
    for _ in range(4):
        w = w - (w + np.log(w) - x) / (1.0 + 1.0 / w)
    return w


@dataclass(frozen=True)
class PVModel:
    """One electrical model, sized per (sub-)panel area.

    Parameters
    ----------
    model : {'ideal', 'single-diode', 'b-model', 'pvwatts'}
    efficiency : float
        ``ideal``: conversion efficiency [-]. ``pvwatts``: the rating per area at 1000 W/m^2 and
        25 C, / 1000 W/m^2 [-]. ``b-model``: sets the 200 W panel's area, which Robles Algarin et
        al. do not give, as ``p_mp / (efficiency * 1000 W/m^2)``.
    module : str or None
        ``single-diode``: a CEC module name; None is the A-300 cell.
    gamma_pdc : float, default -0.0037
        ``pvwatts``: temperature coefficient of power [1/C].
    losses : float, default 0
        ``pvwatts``: system losses [-], a fraction of the DC power.

    Raises
    ------
    ValueError
        If ``model`` is not one of :data:`foldopt.names.PV_MODELS`.
    """

    model: str = "ideal"
    efficiency: float = 0.2
    module: str | None = None
    gamma_pdc: float = -0.0037
    losses: float = 0.0

    def __post_init__(self):
        if self.model not in PV_MODELS:
            raise ValueError(f"pv_model must be one of {', '.join(PV_MODELS)}; got {self.model!r}")

    @functools.cached_property
    def unit(self):
        if self.model == "single-diode":
            return A300_CELL if self.module is None else cec_module(self.module)
        if self.model == "b-model":
            return ROBLES_200W
        return None

    @property
    def unit_area(self) -> float:
        """Area of one unit (cell or module) [m^2]."""
        if self.model == "b-model":
            return self.unit.p_mp / (self.efficiency * IRRADIANCE_REF)
        return self.unit.area

    @property
    def has_iv(self) -> bool:
        return self.model in IV_MODELS

    def rating(self, area) -> float:
        """A panel's rated power [W]: its maximum power at STC (1000 W/m^2, cells at 25 C); for
        PVWatts its nameplate ``pdc0``, before the system losses (a converter and a price per
        watt are sized on it).

        Parameters
        ----------
        area : float
            Panel area [m^2].
        """
        if self.model == "pvwatts":
            return self.efficiency * area * IRRADIANCE_REF
        return float(self.max_power(np.array([IRRADIANCE_REF]), TEMPERATURE_REF, area)[0])

    def power_terms(self, temp_air, wind_speed, temperature_model, area):
        """The maximum power of a model without I-V curve as ``a E + q E^2`` of the irradiance E.

        Exact for the ideal model (``a = efficiency area``, ``q = 0``) and for PVWatts with a cell
        temperature linear in the irradiance, ``T_cell = T_air + c E``
        (:func:`foldopt.physics.temperature.irradiance_coefficient`): with ``k = efficiency area
        (1 - losses)``, ``a = k (1 + gamma_pdc (T_air - 25 C))`` and ``q = k gamma_pdc c``. The
        compiled kernel evaluates the power so, without tables.

        Parameters
        ----------
        temp_air, wind_speed : float
            [C], [m/s].
        temperature_model : str
            One of :data:`foldopt.names.TEMPERATURE_MODELS`.
        area : float
            Panel area [m^2].

        Returns
        -------
        a, q : float
            [W / (W/m^2)], [W / (W/m^2)^2].

        Raises
        ------
        ValueError
            For a model with an I-V curve.
        """
        if self.model == "ideal":
            return self.efficiency * area, 0.0
        if self.model != "pvwatts":
            raise ValueError(f"the {self.model} model's power is not a polynomial")
        k = self.efficiency * area * (1.0 - self.losses)
        c = irradiance_coefficient(wind_speed, temperature_model)
        a = k * (1.0 + self.gamma_pdc * (temp_air - TEMPERATURE_REF))
        return a, float(k * self.gamma_pdc * c)

    def curves(self, poa_global, temp_cell, area) -> IVCurve:
        """I-V curves of panels of a given area.

        ``single-diode``: the reference parameters moved to the operating conditions by De Soto
        [1]_ or the CEC [2]_ (pvlib's ``calcparams_desoto`` / ``calcparams_cec``), for
        ``area / unit_area`` units in series. ``b-model``: Robles Algarin et al. [3]_ Eq. 9 and 10
        with s = the units in series and p = 1.

        Parameters
        ----------
        poa_global : array_like
            Plane-of-array irradiance [W/m^2].
        temp_cell : array_like
            Cell temperature [C], broadcast against ``poa_global``.
        area : float
            Panel area [m^2].

        Returns
        -------
        IVCurve
            One curve per element of ``poa_global``.

        Raises
        ------
        ValueError
            For the ``ideal`` model, which has no I-V curve.
        """
        poa = np.asarray(poa_global, dtype=float)
        temp_cell = np.broadcast_to(np.asarray(temp_cell, dtype=float), poa.shape)
        units = area / self.unit_area
        u = self.unit
        if self.model == "single-diode":
            args = (poa, temp_cell, u.alpha_sc, u.a_ref, u.I_L_ref, u.I_o_ref, u.R_sh_ref, u.R_s)
            # R_sh scales as 1/irradiance: at vanishing irradiance it overflows to inf, harmlessly.
            import pvlib

            with np.errstate(over="ignore", divide="ignore"):
                if u.adjust is None:
                    il, io, rs, rsh, nnsvth = pvlib.pvsystem.calcparams_desoto(
                        *args, EgRef=u.EgRef, dEgdT=u.dEgdT
                    )
                else:
                    il, io, rs, rsh, nnsvth = pvlib.pvsystem.calcparams_cec(
                        *args, u.adjust, EgRef=u.EgRef, dEgdT=u.dEgdT
                    )
            shape = poa.shape
            params = (il, io, rs * units, rsh * units, nnsvth * units)
            return IVCurve(
                self.model,
                tuple(np.broadcast_to(np.asarray(p, dtype=float), shape) for p in params),
            )
        if self.model == "b-model":
            ratio = poa / IRRADIANCE_REF
            # Eq. 9 (s = units in series) and Eq. 10 (p = 1). At zero irradiance I_x = 0.
            v_x = units * (
                ratio * u.tc_v * (temp_cell - TEMPERATURE_REF)
                + u.v_max
                - (u.v_max - u.v_min)
                * np.exp(ratio * np.log((u.v_max - u.v_oc) / (u.v_max - u.v_min)))
            )
            i_x = ratio * (u.i_sc + u.tc_i * (temp_cell - TEMPERATURE_REF))
            v_x = np.where(i_x > 0, v_x, 0.0)
            return IVCurve(self.model, (v_x, np.clip(i_x, 0.0, None), np.full(poa.shape, u.b)))
        raise ValueError("the ideal model has no I-V curve")

    def max_power(self, poa_global, temp_cell, area):
        """Maximum power of panels of a given area.

        Parameters
        ----------
        poa_global : array_like
            Plane-of-array irradiance [W/m^2].
        temp_cell : array_like
            Cell temperature [C], broadcast against ``poa_global`` (not used by ``ideal``).
        area : float
            Panel area [m^2].

        Returns
        -------
        numpy.ndarray
            Power at the maximum-power point [W], shaped as ``poa_global``.
        """
        if self.model == "ideal":
            return self.efficiency * area * np.asarray(poa_global, dtype=float)
        if self.model == "pvwatts":
            import pvlib

            pdc0 = self.efficiency * area * IRRADIANCE_REF
            poa = np.asarray(poa_global, dtype=float)
            dc = pvlib.pvsystem.pvwatts_dc(poa, temp_cell, pdc0, self.gamma_pdc, TEMPERATURE_REF)
            return np.asarray(dc, dtype=float) * (1.0 - self.losses)
        return self.curves(poa_global, temp_cell, area).max_power()
