"""The circuit as built, as a study gives it (:class:`Circuit`): diodes, the converter, the coupling
to the load and the switch.

Every part defaults to the ideal one of Shin et al. (no forward drop, every converter delivering
its input at the maximum power point, no switch resistance), so a study without ``circuit`` is the
paper's. The physics is :mod:`foldopt.physics.diodes`, :mod:`foldopt.physics.circuit` and
:mod:`foldopt.physics.converter`.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, field_validator, model_validator

from foldopt import names
from foldopt.inputs.fields import StrictModel, interval, named


def _by_model(value):
    """``blocking_diode: constant`` is ``blocking_diode: {model: constant}``."""
    return {"model": value} if isinstance(value, str) else value


class DiodeSpec(StrictModel):
    """A diode's forward-voltage model (:class:`foldopt.physics.diodes.Diode`).

    Parameters
    ----------
    model : {'ideal', 'constant', 'shockley'}
        One of :data:`foldopt.names.DIODE_MODELS`.
    part : str, optional
        A datasheet part of :data:`foldopt.physics.diodes.DIODE_PARTS` whose values are the
        defaults; default :data:`foldopt.physics.diodes.DEFAULT_DIODE_PART`.
    forward_voltage : float, optional
        ``constant``: [V] in [0, 5].
    saturation_current, ideality, series_resistance : float, optional
        ``shockley``: [A] in (0, 1], [-] in [0.5, 5], [ohm] in [0, 10].
    """

    model: named(names.DIODE_MODELS) = "ideal"
    part: str | None = Field(
        None, description="a datasheet part; default foldopt.physics.diodes.DEFAULT_DIODE_PART"
    )
    forward_voltage: interval(0, 5, unit=" V") | None = Field(
        None, description="constant; default the part's"
    )
    saturation_current: interval(0, 1, lo_open=True, unit=" A") | None = Field(
        None, description="shockley; default the part's"
    )
    ideality: interval(0.5, 5) | None = Field(None, description="shockley; default the part's")
    series_resistance: interval(0, 10, unit=" ohm") | None = Field(
        None, description="shockley; default the part's"
    )

    @field_validator("part")
    @classmethod
    def _known_part(cls, part):
        if part is not None:
            from foldopt.physics.diodes import DIODE_PARTS  # the parts' table, only when named

            if part not in DIODE_PARTS:
                raise ValueError(f"must be one of {', '.join(DIODE_PARTS)}")
        return part

    def idle_settings(self, field: str) -> list[str]:
        """``field.name = value: why`` for each value this model does not use."""
        rules = (
            ("part", self.model != "ideal", "is only used by a constant or shockley diode"),
            ("forward_voltage", self.model == "constant", "is only used by model constant"),
            ("saturation_current", self.model == "shockley", "is only used by model shockley"),
            ("ideality", self.model == "shockley", "is only used by model shockley"),
            ("series_resistance", self.model == "shockley", "is only used by model shockley"),
        )
        return [
            f"{field}.{name} = {getattr(self, name)!r}: {why}"
            for name, used, why in rules
            if not used and getattr(self, name) is not None
        ]

    def describe(self) -> str:
        """The diode in words: ``shockley (SB560)``, ``constant 0.4 V``."""
        if self.model == "ideal":
            return "ideal"
        from foldopt.physics.diodes import DEFAULT_DIODE_PART

        given = ", ".join(
            f"{name} {getattr(self, name):g}"
            for name in ("forward_voltage", "saturation_current", "ideality", "series_resistance")
            if getattr(self, name) is not None
        )
        return f"{self.model} ({self.part or DEFAULT_DIODE_PART}{', ' + given if given else ''})"

    def build(self):
        """The diode (:func:`foldopt.physics.diodes.diode`)."""
        from foldopt.physics.diodes import DEFAULT_DIODE_PART, diode

        overrides = {
            name: getattr(self, name)
            for name in ("forward_voltage", "saturation_current", "ideality", "series_resistance")
            if getattr(self, name) is not None
        }
        return diode(self.model, self.part or DEFAULT_DIODE_PART, **overrides)


_CurvePoint = tuple[interval(0, 10, lo_open=True), interval(0, 1)]


class ConverterSpec(StrictModel):
    """The maximum-power-point converter (:class:`foldopt.physics.converter.Converter`).

    Parameters
    ----------
    model : {'ideal', 'pvwatts', 'curve'}
        One of :data:`foldopt.names.CONVERTER_MODELS`.
    efficiency : float
        ``pvwatts``: the nominal efficiency [-] in (0, 1]; default 0.96 (pvlib's).
    p_rated : float, optional
        DC input rating [W] in (0, 1e6]; default the panel's power at STC.
    curve : list of (float, float), optional
        ``curve``: (input power / rating [-] in (0, 10], efficiency [-] in [0, 1]), the fractions
        increasing.
    """

    model: named(names.CONVERTER_MODELS) = "ideal"
    efficiency: interval(0, 1, lo_open=True) = Field(
        0.96, description="pvwatts: nominal efficiency"
    )
    p_rated: interval(0, 1e6, lo_open=True, unit=" W") | None = Field(
        None, description="DC input rating; default the panel's power at STC"
    )
    curve: Annotated[list[_CurvePoint], Field(min_length=1, max_length=100)] | None = Field(
        None, description="curve: [input power / rating, efficiency] points"
    )

    @model_validator(mode="after")
    def _curve_given(self):
        if self.model == "curve" and self.curve is None:
            raise ValueError(
                "model curve: give its points, circuit.converter.curve = [[input power / rating, "
                "efficiency], ...], e.g. [[0.1, 0.90], [0.5, 0.95], [1.0, 0.94]]"
            )
        if self.curve is not None and any(b[0] <= a[0] for a, b in zip(self.curve, self.curve[1:])):
            raise ValueError("curve: the input fractions must increase from point to point")
        return self

    def idle_settings(self, field: str) -> list[str]:
        """``field.name = value: why`` for each value this model does not use."""
        rules = (
            ("efficiency", self.model == "pvwatts", 0.96, "is only used by model pvwatts"),
            ("p_rated", self.model != "ideal", None, "is only used by model pvwatts or curve"),
            ("curve", self.model == "curve", None, "is only used by model curve"),
        )
        return [
            f"{field}.{name} = {getattr(self, name)!r}: {why}"
            for name, used, default, why in rules
            if not used and getattr(self, name) != default
        ]


class Circuit(StrictModel):
    """How the two sub-panels reach the load, as built.

    Parameters
    ----------
    blocking_diode : DiodeSpec
        The diode in each sub-panel's path in parallel (connections parallel and switching);
        default ideal.
    bypass_diode : DiodeSpec
        The diode across each sub-panel in series (with ``bypass_diodes``); default ideal.
    converter : ConverterSpec
        The maximum-power-point converter; default ideal.
    coupling : {'mppt', 'direct'}
        A converter, or the load wired to the panel at ``load_voltage``.
    load_voltage : float, optional
        ``direct``: the load's voltage [V] in (0, 1000].
    switch_resistance : float
        The on-resistance of the reconfigurable connection's switch in each sub-panel's path
        [ohm] in [0, 10]; default 0.
    """

    blocking_diode: DiodeSpec = DiodeSpec()
    bypass_diode: DiodeSpec = DiodeSpec()
    converter: ConverterSpec = ConverterSpec()
    coupling: named(names.COUPLINGS) = "mppt"
    load_voltage: interval(0, 1000, lo_open=True, unit=" V") | None = Field(
        None, description="direct: the load's"
    )
    switch_resistance: interval(0, 10, unit=" ohm") = Field(
        0.0, description="switching: each path's switch"
    )

    @field_validator("blocking_diode", "bypass_diode", "converter", mode="before")
    @classmethod
    def _part_by_model(cls, value):
        return _by_model(value)

    @model_validator(mode="after")
    def _coupled(self):
        if self.coupling == "direct" and self.load_voltage is None:
            raise ValueError(
                "coupling 'direct': give the load's voltage, circuit.load_voltage (e.g. 5)"
            )
        if self.coupling == "direct" and self.converter.model != "ideal":
            raise ValueError(
                f"converter {self.converter.model!r} with coupling 'direct': a direct-coupled load has "
                f"no converter; leave circuit.converter out, or set circuit.coupling mppt"
            )
        return self

    @property
    def ideal(self) -> bool:
        """Whether every part is Shin et al.'s ideal one (the engine's plain path)."""
        return (
            self.blocking_diode.model == "ideal"
            and self.bypass_diode.model == "ideal"
            and self.converter.model == "ideal"
            and self.coupling == "mppt"
            and self.switch_resistance == 0.0
        )

    @property
    def needs_iv(self) -> bool:
        """Whether a part needs the sub-panels' I-V curves (all but the converter do)."""
        return (
            self.blocking_diode.model != "ideal"
            or self.bypass_diode.model != "ideal"
            or self.coupling == "direct"
            or self.switch_resistance > 0.0
        )

    def describe(self) -> str:
        """The circuit in words, for the answer's question."""
        if self.coupling == "direct":
            load = f"load direct-coupled at {self.load_voltage:g} V"
        elif self.converter.model == "ideal":
            load = "ideal MPPT converter"
        else:
            spec = self.converter
            rating = f"{spec.p_rated:g} W" if spec.p_rated is not None else "the panel's STC power"
            curve = (
                f"nominal {spec.efficiency:g}"
                if spec.model == "pvwatts"
                else f"{len(spec.curve)} points"
            )
            load = f"MPPT converter {spec.model} ({curve}, rated {rating})"
        parts = [
            load,
            f"blocking diodes {self.blocking_diode.describe()}",
            f"bypass diodes {self.bypass_diode.describe()}",
        ]
        if self.switch_resistance:
            parts.append(f"switch {self.switch_resistance:g} ohm")
        return ", ".join(parts)

    def ignored_by(self, connection: str) -> str | None:
        """How a connection is wired where it cannot be wired as this circuit says, None where it can.

        The independent connection is a converter per sub-panel (Shin et al.'s upper bound of
        switching): with a load wired directly it keeps its converters. A study cannot take it as its
        own connection then (:meth:`idle_settings`); a comparison row of it says so in its note.

        Parameters
        ----------
        connection : str
            One of :data:`foldopt.names.CONNECTIONS`.

        Returns
        -------
        str or None
            The note of a design of that connection.
        """
        if self.coupling == "direct" and connection == "independent":
            return f"with a converter per sub-panel, not the load wired directly at {self.load_voltage:g} V"
        return None

    def idle_settings(self, connection: str, series_used: bool, iv_model: bool) -> list[str]:
        """Values of the circuit that the study's connection and PV model do not use, or cannot.

        Parameters
        ----------
        connection : str
            The study's connection.
        series_used : bool
            Whether series with bypass diodes is used (connection series, or switching with
            switch_series, and ``bypass_diodes``).
        iv_model : bool
            Whether the PV model has an I-V curve.

        Returns
        -------
        list of str
            ``circuit.field = value: why`` lines.
        """
        parallel_used = connection in ("parallel", "switching")
        lines = [
            *self.blocking_diode.idle_settings("circuit.blocking_diode"),
            *self.bypass_diode.idle_settings("circuit.bypass_diode"),
            *self.converter.idle_settings("circuit.converter"),
        ]
        rules = (
            (
                "blocking_diode.model",
                self.blocking_diode.model,
                "ideal",
                parallel_used,
                "is only used where parallel is (connection parallel or switching)",
            ),
            (
                "bypass_diode.model",
                self.bypass_diode.model,
                "ideal",
                series_used,
                "is only used where series is, with bypass_diodes (connection series, or switching with "
                "switch_series)",
            ),
            (
                "switch_resistance",
                self.switch_resistance,
                0.0,
                connection == "switching",
                "is only used by connection switching",
            ),
            (
                "load_voltage",
                self.load_voltage,
                None,
                self.coupling == "direct",
                "is only used by coupling direct",
            ),
        )
        lines += [
            f"circuit.{name} = {value!r}: {why}"
            for name, value, default, used, why in rules
            if not used and value != default
        ]
        if self.ignored_by(connection):
            lines.append(
                f"connection = {connection!r}: needs a converter per sub-panel; a direct-coupled load "
                f"(circuit.coupling direct) has none"
            )
        if not iv_model:
            needing = [
                (name, value)
                for name, value, default in (
                    ("blocking_diode.model", self.blocking_diode.model, "ideal"),
                    ("bypass_diode.model", self.bypass_diode.model, "ideal"),
                    ("coupling", self.coupling, "mppt"),
                    ("switch_resistance", self.switch_resistance, 0.0),
                )
                if value != default
            ]
            lines += [
                f"circuit.{name} = {value!r}: needs the sub-panels' I-V curves: pv_model single-diode or "
                f"b-model"
                for name, value in needing
            ]
        return lines
