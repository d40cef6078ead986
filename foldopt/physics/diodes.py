"""Blocking and bypass diodes as built: their forward voltage at the sub-panel's current.

Three models (:data:`foldopt.names.DIODE_MODELS`):

- ``ideal``: no forward drop; the diode only stops reverse current (today's connections).
- ``constant``: a constant forward drop, the datasheet V_F at its rated current, whatever the
  current.
- ``shockley``: Shockley's ideal-diode law [1]_, ``I = I_s (exp(V_j / (n V_t)) - 1)``, with an
  ohmic series resistance, as the DC branch of the SPICE diode model (parameters IS, N, RS [2]_):
  ``V = n V_t ln(1 + I / I_s) + I R_s`` with ``V_t = k T / q``.

A sub-panel of the paper's panel (0.054 m^2 of SunPower A-300 cells, 3.6 cells in series) carries
about 5.5-6 A at 1000 W/m^2 and works at about 2 V, so a blocking diode's 0.4-0.6 V is a large part
of its voltage. :data:`DIODE_PARTS` holds datasheet parts rated for that current; the default,
:data:`DEFAULT_DIODE_PART`, is ON Semiconductor's MBR745, a 7.5 A, 45 V Schottky rectifier.

References
----------
.. [1] W. Shockley, "The theory of p-n junctions in semiconductors and p-n junction transistors",
   Bell System Technical Journal 28(3), 435-489, 1949 (the ideal-diode law).
.. [2] L. W. Nagel, "SPICE2: a computer program to simulate semiconductor circuits", Memorandum
   ERL-M520, University of California, Berkeley, 1975 (the junction diode model: IS, N, RS).
.. [3] ON Semiconductor, "MBR735, MBR745 SWITCHMODE Power Rectifiers", datasheet MBR735/D,
   Rev. 8, March 2009 (Maximum Instantaneous Forward Voltage: 0.57 V at 7.5 A and T_J = 125 C,
   0.84 V at 15 A and T_J = 25 C). International Rectifier's MBR745 (Bulletin PD-2.325 rev. E)
   gives the same figures.
.. [4] Linear Technology (Analog Devices), LTspice standard diode library ``lib/cmp/standard.dio``
   (M. Engelhardt, 1999-2008): ``MBR745 D(Is=159u Rs=.02 N=1.76 ... Iave=7.5 Vpk=45 mfg=OnSemi
   type=Schottky)`` and ``PDS760 D(Is=360n Rs=.016 N=1.04 ... Iave=7 Vpk=60 mfg=Diodes_Inc.
   type=Schottky)``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from foldopt.names import DIODE_MODELS

BOLTZMANN_OVER_CHARGE = 8.617333262e-5  # k / q [V/K] (CODATA 2018, exact)
ZERO_CELSIUS = 273.15  # [K]


@dataclass(frozen=True)
class Diode:
    """One diode's forward characteristic.

    Parameters
    ----------
    model : {'ideal', 'constant', 'shockley'}
        One of :data:`foldopt.names.DIODE_MODELS`.
    forward_voltage : float, default 0
        ``constant``: the forward drop [V].
    saturation_current : float, default 1e-4
        ``shockley``: I_s [A] (SPICE ``IS``).
    ideality : float, default 1
        ``shockley``: n [-] (SPICE ``N``).
    series_resistance : float, default 0
        ``shockley``: R_s [ohm] (SPICE ``RS``).
    temperature : float, default 25
        ``shockley``: junction temperature [C] of the thermal voltage ``k T / q``. The saturation
        current is kept at its model value (SPICE's ``XTI`` and ``EG`` temperature law is left out).
    part : str or None
        The :data:`DIODE_PARTS` entry the values came from, for the record.

    Raises
    ------
    ValueError
        For an unknown model, or a negative or non-finite parameter (a zero saturation current or
        ideality for ``shockley``).
    """

    model: str
    forward_voltage: float = 0.0
    saturation_current: float = 1e-4
    ideality: float = 1.0
    series_resistance: float = 0.0
    temperature: float = 25.0
    part: str | None = None

    def __post_init__(self):
        if self.model not in DIODE_MODELS:
            raise ValueError(
                f"diode model must be one of {', '.join(DIODE_MODELS)}; got {self.model!r}"
            )
        for name in ("forward_voltage", "saturation_current", "ideality", "series_resistance"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"diode {name} must be finite and >= 0; got {value!r}")
        if self.model == "shockley" and not (self.saturation_current > 0 and self.ideality > 0):
            raise ValueError("a shockley diode needs saturation_current > 0 and ideality > 0")
        if not self.temperature > -ZERO_CELSIUS:
            raise ValueError(
                f"diode temperature must be above absolute zero; got {self.temperature!r} C"
            )

    @property
    def n_vth(self) -> float:
        """``n k T / q`` [V]: the ideality times the thermal voltage (pvlib's ``nNsVth`` of one
        junction), the slope of the forward voltage against ln(current)."""
        return self.ideality * BOLTZMANN_OVER_CHARGE * (self.temperature + ZERO_CELSIUS)

    def drop(self, current):
        """Forward voltage at a forward current.

        ``ideal``: 0. ``constant``: ``forward_voltage`` at any current (the datasheet V_F at its
        rated current, taken for every current). ``shockley``: ``n V_t ln(1 + I / I_s) + I R_s``
        (Shockley's law [1]_ solved for the junction voltage, plus the series resistance's drop).

        Parameters
        ----------
        current : array_like
            Forward current [A], >= 0.

        Returns
        -------
        numpy.ndarray
            Forward voltage [V], shaped as ``current``.
        """
        current = np.asarray(current, dtype=float)
        if self.model == "ideal":
            return np.zeros_like(current)
        if self.model == "constant":
            return np.full_like(current, self.forward_voltage)
        return (
            self.n_vth * np.log1p(current / self.saturation_current)
            + current * self.series_resistance
        )

    def resistance(self, current):
        """Differential resistance ``dV/dI`` [ohm] of :meth:`drop` at a forward current.

        Parameters
        ----------
        current : array_like
            Forward current [A], >= 0.

        Returns
        -------
        numpy.ndarray
            ``n V_t / (I + I_s) + R_s`` for ``shockley``, 0 otherwise, shaped as ``current``.
        """
        current = np.asarray(current, dtype=float)
        if self.model != "shockley":
            return np.zeros_like(current)
        return self.n_vth / (current + self.saturation_current) + self.series_resistance


@dataclass(frozen=True)
class DiodePart:
    """A datasheet diode: the forward drop its datasheet states, and its SPICE parameters.

    ``forward_voltage`` is None where no datasheet value has been checked; such a part serves
    the ``shockley`` model only.
    """

    name: str
    description: str
    average_current: float  # [A], rated average forward current
    reverse_voltage: float  # [V], rated peak repetitive reverse voltage
    forward_voltage: float | None  # [V], datasheet V_F
    forward_current: float | None  # [A], at which V_F is stated
    forward_temperature: float | None  # [C], junction temperature at which V_F is stated
    saturation_current: float  # [A], SPICE IS
    ideality: float  # [-], SPICE N
    series_resistance: float  # [ohm], SPICE RS
    sources: str


#: Datasheet parts, by name. Both are rated above the ~6 A a sub-panel carries at 1000 W/m^2.
DIODE_PARTS = {
    "mbr745": DiodePart(
        name="mbr745",
        description="ON Semiconductor MBR745, 7.5 A 45 V Schottky rectifier (TO-220AC)",
        average_current=7.5,
        reverse_voltage=45.0,
        # [3]: maximum instantaneous forward voltage 0.57 V at 7.5 A, T_J = 125 C (a warm
        # junction, as in a sealed junction box). Its SPICE model [4] gives 0.58 V at 5.5 A and
        # 25 C, so one constant drop of 0.57 V stands for both.
        forward_voltage=0.57,
        forward_current=7.5,
        forward_temperature=125.0,
        # [4]: Is = 159 uA, N = 1.76, Rs = 0.02 ohm.
        saturation_current=159e-6,
        ideality=1.76,
        series_resistance=0.02,
        sources="V_F: ON Semiconductor datasheet MBR735/D Rev. 8 (2009); SPICE: LTspice standard.dio",
    ),
    "pds760": DiodePart(
        name="pds760",
        description="Diodes Incorporated PDS760, 7 A 60 V Schottky rectifier (PowerDI 5)",
        average_current=7.0,
        reverse_voltage=60.0,
        forward_voltage=None,
        forward_current=None,
        forward_temperature=None,
        # [4]: Is = 360 nA, N = 1.04, Rs = 0.016 ohm (0.53 V at 5.5 A and 25 C).
        saturation_current=360e-9,
        ideality=1.04,
        series_resistance=0.016,
        sources="SPICE: LTspice standard.dio (mfg Diodes Inc.)",
    ),
}
DEFAULT_DIODE_PART = "mbr745"


def diode(model: str = "constant", part: str | None = DEFAULT_DIODE_PART, **overrides) -> Diode:
    """A diode of one model with a datasheet part's parameters.

    Parameters
    ----------
    model : {'constant', 'ideal', 'shockley'}, default 'constant'
        One of :data:`foldopt.names.DIODE_MODELS`.
    part : str or None, default :data:`DEFAULT_DIODE_PART`
        One of :data:`DIODE_PARTS`; None takes :class:`Diode`'s defaults.
    **overrides
        Fields of :class:`Diode` to set instead of the part's (``forward_voltage=0.4``,
        ``temperature=60``...).

    Returns
    -------
    Diode

    Raises
    ------
    ValueError
        For an unknown model, part or field, or a ``constant`` diode of a part whose datasheet
        drop is not recorded.

    Examples
    --------
    >>> d = diode("shockley")
    >>> print(f"{float(d.drop(5.5)):.3f} V")
    0.583 V
    >>> print(diode("constant", forward_voltage=0.4).drop([0.0, 6.0]))
    [0.4 0.4]
    """
    if model not in DIODE_MODELS:
        raise ValueError(f"diode model must be one of {', '.join(DIODE_MODELS)}; got {model!r}")
    if part is not None and part not in DIODE_PARTS:
        raise ValueError(f"diode part must be one of {', '.join(DIODE_PARTS)}; got {part!r}")
    known = {field.name for field in fields(Diode)} - {"model", "part"}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise ValueError(f"diode fields are {', '.join(sorted(known))}; got {', '.join(unknown)}")
    # An ideal diode uses none of a part's values, so it records none.
    values: dict = {"model": model, "part": part if model != "ideal" else None}
    if part is not None:
        spec = DIODE_PARTS[part]
        if model == "constant" and "forward_voltage" not in overrides:
            if spec.forward_voltage is None:
                with_drop = [
                    name for name, p in DIODE_PARTS.items() if p.forward_voltage is not None
                ]
                raise ValueError(
                    f"part {part!r} has no datasheet forward voltage; give forward_voltage or "
                    f"take one of {', '.join(with_drop)}"
                )
            values["forward_voltage"] = spec.forward_voltage
        if model == "shockley":
            values.update(
                saturation_current=spec.saturation_current,
                ideality=spec.ideality,
                series_resistance=spec.series_resistance,
            )
    return Diode(**{**values, **overrides})
