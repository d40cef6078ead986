"""The ``storage`` section of a study: a small buffer (a supercapacitor bank or a battery) behind a
charge controller that cuts the load off at a low state of charge (:class:`Storage`). Like the
other sections it only validates (:mod:`foldopt.inputs.sections`); the state of charge is
simulated by :mod:`foldopt.engine.storage`.

A study without the section is storage-less: every answer is the ``t_solar`` one. The module may
import pydantic and :mod:`foldopt.names`.
"""

from __future__ import annotations

from pydantic import Field, ValidationInfo, field_validator, model_validator
from pydantic.types import confloat

from foldopt import names
from foldopt.inputs.fields import StrictModel, interval, named

#: The buffer a study's storage is where it names no preset and leaves a field out: lossless, no
#: self-discharge, usable down to empty and reconnected as soon as it holds energy again.
IDEAL = {
    "min_soc": 0.0,
    "hysteresis": 0.0,
    "charge_efficiency": 1.0,
    "discharge_efficiency": 1.0,
    "self_discharge": 0.0,
    # a buffer the temperature does nothing to
    "charge_min_c": None,
    "discharge_min_c": None,
    "capacity_curve": None,
    "self_discharge_doubling_c": None,
}
#: Each preset of :data:`foldopt.names.STORAGE_PRESETS`: the datasheet-typical values of the fields
#: it fills, ``hysteresis`` being how far above ``min_soc`` the load is reconnected (``restart_soc
#: = min_soc + hysteresis``, at most 1). Sources in :class:`Storage`'s References.
PRESETS = {
    # [1] an EDLC's energy is C V^2 / 2: a converter that works down to half the rated voltage
    # leaves a quarter of the energy; a converter's under-voltage lockout releasing some 10 % of
    # the voltage higher (0.55 V_r) reconnects at 0.30 of the energy. [2] ESR losses of a few %
    # at moderate currents; [3] 100 % to 50 % stored energy in 30 to 40 days: 0.98^35 = 0.49.
    "supercapacitor": {
        "min_soc": 0.25,
        "hysteresis": 0.05,
        "charge_efficiency": 0.98,
        "discharge_efficiency": 0.98,
        "self_discharge": 0.02,
        # [2] operating range -40 to 65 C (cell case): charged and discharged down to -40 C; its
        # capacitance is stated at 25 C only, so no cold capacity curve. [7] leakage below 1 uA
        # at -55 C and below 30 uA at 85 C: a doubling every 140 / log2(30) = 28.5 C.
        "charge_min_c": -40.0,
        "discharge_min_c": -40.0,
        "capacity_curve": None,
        "self_discharge_doubling_c": 28.5,
    },
    # [4] 92 % round trip (0.96 x 0.96), its cycle life rated at 80 % depth of discharge (a 20 %
    # cut-off); [5] 2 to 5 %/month self-discharge: 3 %/month is 1 - 0.97^(1/30) = 0.001 a day.
    # A controller's load output reconnects some 10 % of the capacity above its cut-off.
    "lifepo4": {
        "min_soc": 0.20,
        "hysteresis": 0.10,
        "charge_efficiency": 0.96,
        "discharge_efficiency": 0.96,
        "self_discharge": 0.001,
        # [8] charging prohibited below 0 C, discharge -20 to 60 C (a BMS stops both outside:
        # [9]); [10] a 100 Ah pack gives about 80 Ah at 0 C and 70 Ah at -20 C, all of it again
        # when warm (its rated capacity at 25 C).
        "charge_min_c": 0.0,
        "discharge_min_c": -20.0,
        "capacity_curve": ((-20.0, 0.70), (0.0, 0.80), (25.0, 1.0)),
        "self_discharge_doubling_c": None,
    },
    # [11] a Li-ion (NMC/LCO) 18650 cell: charge 0 to 45 C, discharge -20 to 60 C, more than 95 %
    # of its charge left after 30 days at 25 C (5 %/month: 1 - 0.95^(1/30) = 0.0017 a day);
    # [12] lithium at -18 C (0 F) delivers 70 % of its rated capacity. The cut-off, reconnection
    # and efficiencies as the LiFePO4 preset's [4] (no sourced figure of NMC's own).
    "nmc": {
        "min_soc": 0.20,
        "hysteresis": 0.10,
        "charge_efficiency": 0.96,
        "discharge_efficiency": 0.96,
        "self_discharge": 0.0017,
        "charge_min_c": 0.0,
        "discharge_min_c": -20.0,
        "capacity_curve": ((-18.0, 0.70), (25.0, 1.0)),
        "self_discharge_doubling_c": None,
    },
}
#: The fields a preset (or :data:`IDEAL`) fills where a study leaves them out, in the order they
#: are filled (``restart_soc`` from the ``min_soc`` in force).
FILLED = (
    "min_soc",
    "restart_soc",
    "charge_efficiency",
    "discharge_efficiency",
    "self_discharge",
    "charge_min_c",
    "discharge_min_c",
    "capacity_curve",
    "self_discharge_doubling_c",
)
#: The temperatures the cold's fields take [C] (a buffer's datasheet range, and the air's).
COLD_RANGE_C = (-60.0, 60.0)


class StorageTarget(StrictModel):
    """What the buffer is sized for: the load powered ``powered_h`` hours a day on ``days_pct`` of
    the days (:mod:`foldopt.studies.storage_sizing` finds each design's smallest buffer for it).

    Parameters
    ----------
    powered_h : float
        Hours a day the load must run [h] in (0, 24].
    days_pct : float, default 100
        The share of the days that must reach ``powered_h`` [%] in (0, 100] (a repeated clear-sky
        day reaches it on every day or on none).
    years : 'every' or float, default 'every'
        Over a series of several calendar years, the share of the years [%] in (0, 100] that must
        meet the target, a year meeting it where ``days_pct`` of its days reach ``powered_h``;
        ``every`` is 100. The default asks the question a device's designer asks, whether it
        survives the bad year, not the typical one (the days' share over the series as a whole
        would let a good year make up for a bad one). Over one year, or a clear-sky study's
        days, any value is the same target.
    """

    powered_h: interval(0, 24, lo_open=True, unit=" h") = Field(
        description="hours a day the load must run"
    )
    days_pct: interval(0, 100, lo_open=True, unit=" %") = Field(
        100.0, description="share of the days that must reach powered_h"
    )
    years: str | float = Field(
        "every",
        description="share of the years that must meet the target [%], or every",
    )

    @field_validator("years", mode="before")
    @classmethod
    def _every_or_share(cls, value):
        if isinstance(value, str) and value.strip().lower() == "every":
            return "every"
        share = value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
        if share is None or not 0.0 < share <= 100.0:
            raise ValueError("must be every or a share of the years in (0, 100] %")
        return float(share)

    @property
    def years_pct(self) -> float:
        """The share of the years that must meet the target [%] (``every``: 100)."""
        return 100.0 if self.years == "every" else float(self.years)

    def said(self, over_years: bool) -> str:
        """The target as the answer says it, ``24 h every day`` (``over_years``: the days span
        several calendar years, and the share of them is said too)."""
        text = f"{self.powered_h:g} h" + (
            f" on {self.days_pct:g} % of days" if self.days_pct < 100 else " every day"
        )
        if over_years:
            text += (
                " in every year"
                if self.years_pct >= 100
                else f" in {self.years_pct:g} % of the years"
            )
        return text


class Storage(StrictModel):
    """A buffer behind a charge controller: what the load runs on when PV alone does not carry it.

    Per time step, PV above the load serves it and charges the buffer (what does not fit is lost);
    PV below the load is topped up from the buffer; below ``min_soc`` the controller cuts the
    load off until the state of charge climbs back to ``restart_soc``, and while it is off all PV
    charges the buffer (:mod:`foldopt.engine.storage`). A field left out takes its ``preset``'s
    value (:data:`PRESETS`), or without a preset the ideal buffer's (:data:`IDEAL`); a field given
    always wins. What was filled is no setting of the user's: the study's data leave it out, so a
    variant with another preset fills its own.

    Parameters
    ----------
    capacity_wh : float
        The usable energy of the full buffer [Wh] in [0, 1e6]; 0 is the storage-less study, its
        answer exactly the ``t_solar`` one.
    min_soc : float, optional
        The controller's cut-off: the state of charge [-] in [0, 1) at which it disconnects the
        load. Default the preset's, else 0.
    restart_soc : float, optional
        The state of charge [-] in [min_soc, 1] at which it reconnects the load (hysteresis).
        Default ``min_soc`` plus the preset's hysteresis (at most 1), else ``min_soc``.
    charge_efficiency, discharge_efficiency : float, optional
        [-] in (0, 1]: the energy stored of the energy put in, and the energy delivered of the
        energy taken out. Default the preset's, else 1.
    self_discharge : float, optional
        The fraction of the stored energy lost a day [1/day] in [0, 1). Default the preset's,
        else 0.
    max_charge_w, max_discharge_w : float, optional
        The most power the buffer takes in / gives out [W] in (0, 1e6]; default unlimited.
    initial_soc : float, optional
        The state of charge [-] in [0, 1] at the start of the study's first day; default the
        periodic steady state (a repeated clear-sky day is run until its midnight state of charge
        repeats; a weather year starts from the state at its own end). It may lie below
        ``min_soc`` (a buffer delivered flat, or left to self-discharge): the load starts on at
        ``restart_soc`` or above, and below it off, waiting for ``restart_soc``
        (:func:`foldopt.engine.storage.simulate`).
    enclosure_offset_c : float, optional
        How much warmer the buffer is than the air [C] in [-30, 60] (its box in the sun, or
        buried); the buffer's temperature is the weather's air temperature at each step plus it
        (a clear-sky day: the study's ``temp_air``). Default 0.
    cold : bool, optional
        Whether the buffer's temperature acts (the four fields below); false: a buffer the
        temperature does nothing to, every answer as without them. Default true.
    charge_min_c, discharge_min_c : float, optional
        The buffer is not charged / discharged below these temperatures [C] in [-60, 60] (a
        charger's or a battery management system's block). Default the preset's, else none.
    capacity_curve : list of [float, float], optional
        The usable share of the capacity at the buffer's temperature: ``[temperature C, share]``
        points, temperatures in [-60, 60] increasing, shares in (0, 1] not falling as the
        temperature rises, linear between them and held beyond them. The cold puts the bottom
        of the usable range out of reach: it raises the cut-off to ``min_soc + (1 - share) (1 -
        min_soc)`` and the reconnection alike, the energy staying stored until warm
        (:mod:`foldopt.physics.buffer_temperature`). Default the preset's, else all usable.
    self_discharge_doubling_c : float, optional
        The rise in temperature that doubles the self-discharge [C] in (0, 100]; the
        ``self_discharge`` is the one at 25 C. Default the preset's, else the same at every
        temperature.
    preset : str, optional
        One of :data:`foldopt.names.STORAGE_PRESETS`, whose values fill the fields above that
        are left out.
    target : StorageTarget, optional
        What to size the buffer for: the answer then gives each design's smallest capacity
        reaching it.

    Raises
    ------
    ValueError
        For ``restart_soc`` below ``min_soc``, naming both and where each came from.

    References
    ----------
    .. [1] Maxwell Technologies, "Ultracapacitor product guide", doc. 1014627: the energy
       1/2 C V^2, and discharge to half the rated voltage using three quarters of it.
    .. [2] Maxwell Technologies, "Datasheet HC series ultracapacitors", doc. 1013793: ESR DC
       and leakage current of 1 to 150 F cells; the efficiency section of [1].
    .. [3] Battery University, "BU-209: How does a supercapacitor work?": the stored energy
       decreases from 100 to 50 % in 30 to 40 days.
    .. [4] Victron Energy, "Lithium Battery Smart (LFP-Smart) technical data": round trip
       efficiency 92 %, cycle life 2500 cycles at 80 % depth of discharge.
    .. [5] LiFePO4 makers' stated self-discharge: 2 to 3 %/month (Redway, "What is the
       self-discharge rate of LiFePO4 batteries?"), typically 5 %/month (Dakota Lithium, "How
       long will my battery hold a charge?").
    .. [6] PVGIS, "Performance of off-grid PV systems" (SHScalc): battery size [Wh], discharge
       cut-off limit [%], days with the battery full / empty, energy lost / missing.
    .. [7] Nanoramic, "FastCAP low temperature ultracapacitor" (FAQ): expected leakage current
       below 1 uA at -55 C and below 30 uA at 85 C.
    .. [8] Sunland Power, IFR10440 3.2 V 200 mAh LiFePO4 cell specification: charge 0 to 45 C
       ("prohibited to charge below 0 C"), discharge -20 to 60 C.
    .. [9] EPEVER, "How does the system perform in extreme weather conditions?": the battery
       stops charging below 0 C and discharging below -20 C.
    .. [10] Canbat CLI100-12 LiFePO4 (12 V 100 Ah), as quoted by Funsong Battery, "How to store
       LiFePO4 batteries": about 80 Ah at 0 C and 70 Ah at -20 C, full capacity again when warm.
    .. [11] Yok Energy, "Lithium ion cylindrical 18650 standard cell specification summary":
       charge 0 to 45 C, discharge -20 to 60 C, residual capacity > 95 % after 30 days at 25 C.
    .. [12] X2Power, quoted by Class Cycles, "Lithium iron phosphate batteries in cold weather":
       at 0 F lithium discharges at 70 % of its rated capacity.
    """

    capacity_wh: interval(0, 1e6, unit=" Wh") = Field(
        description="usable energy of the full buffer; 0 is storage-less"
    )
    # before the fields it fills: their validators read it
    preset: named(names.STORAGE_PRESETS) | None = Field(
        None, description="fills the fields left out with a chemistry's typical values"
    )
    min_soc: interval(0, 1, hi_open=True) | None = Field(
        None,
        validate_default=True,
        description="the controller's cut-off; default the preset's, else 0",
    )
    restart_soc: interval(0, 1) | None = Field(
        None,
        validate_default=True,
        description="where the load is reconnected, >= min_soc; default min_soc plus the preset's "
        "hysteresis, else min_soc",
    )
    charge_efficiency: interval(0, 1, lo_open=True) | None = Field(
        None, validate_default=True, description="default the preset's, else 1"
    )
    discharge_efficiency: interval(0, 1, lo_open=True) | None = Field(
        None, validate_default=True, description="default the preset's, else 1"
    )
    self_discharge: interval(0, 1, hi_open=True, unit=" per day") | None = Field(
        None,
        validate_default=True,
        description="fraction of the stored energy lost a day; default the preset's, else 0",
    )
    max_charge_w: interval(0, 1e6, lo_open=True, unit=" W") | None = Field(
        None, description="default unlimited"
    )
    max_discharge_w: interval(0, 1e6, lo_open=True, unit=" W") | None = Field(
        None, description="default unlimited"
    )
    initial_soc: interval(0, 1) | None = Field(
        None, description="at the first day's start; default the periodic steady state"
    )
    target: StorageTarget | None = Field(
        None, description="size each design's buffer for it: {powered_h, days_pct}"
    )
    enclosure_offset_c: interval(-30, 60, unit=" C") | None = Field(
        None, description="the buffer's temperature above the air's; default 0"
    )
    cold: bool | None = Field(
        None, description="false: the buffer's temperature does nothing; default true"
    )
    charge_min_c: interval(*COLD_RANGE_C, unit=" C") | None = Field(
        None, validate_default=True, description="no charge below it; default the preset's"
    )
    discharge_min_c: interval(*COLD_RANGE_C, unit=" C") | None = Field(
        None, validate_default=True, description="no discharge below it; default the preset's"
    )
    capacity_curve: (
        tuple[tuple[interval(*COLD_RANGE_C, unit=" C"), confloat(gt=0.0, le=1.0)], ...] | None
    ) = Field(
        None,
        validate_default=True,
        description="[[temperature C, usable share], ...]; default the preset's",
    )
    self_discharge_doubling_c: interval(0, 100, lo_open=True, unit=" C") | None = Field(
        None,
        validate_default=True,
        description="the rise that doubles the self-discharge; default the preset's",
    )

    @field_validator(*FILLED, mode="after")
    @classmethod
    def _fill(cls, value, info: ValidationInfo):
        """A field left out, from the preset or the ideal buffer (``restart_soc`` from the
        ``min_soc`` in force, validated before it): filled, not given (the fields set say so)."""
        if value is not None or "preset" not in info.data:
            return value  # given; or a preset that is no preset, which its own validation names
        preset = info.data["preset"]
        values = PRESETS[preset] if preset is not None else IDEAL
        if info.field_name != "restart_soc":
            return values[info.field_name]
        min_soc = info.data.get("min_soc")
        # Rounded: decimal fractions added in binary (0.2 + 0.1 is 0.30000000000000004).
        return None if min_soc is None else round(min(1.0, min_soc + values["hysteresis"]), 12)

    @field_validator("capacity_curve", mode="after")
    @classmethod
    def _curve_rises(cls, curve):
        if curve is None:
            return curve
        temperatures, shares = [t for t, _ in curve], [k for _, k in curve]
        if not curve or any(b <= a for a, b in zip(temperatures, temperatures[1:])):
            raise ValueError(
                "the points' temperatures must increase (at least one [temperature C, share])"
            )
        if any(b < a for a, b in zip(shares, shares[1:])):
            raise ValueError("the usable share must not fall as the temperature rises")
        return curve

    @model_validator(mode="after")
    def _reconnected_above_cut_off(self):
        if self.restart_soc < self.min_soc:
            source = f"the {self.preset} preset's" if self.preset is not None else "the default"
            said = {name: "" if name not in self.decided else f", {source}" for name in FILLED}
            raise ValueError(
                f"restart_soc ({self.restart_soc:g}{said['restart_soc']}) is below min_soc "
                f"({self.min_soc:g}{said['min_soc']}): the controller reconnects the load at or "
                "above its cut-off; raise restart_soc or lower min_soc"
            )
        return self

    @property
    def decided(self) -> frozenset:
        """The fields the preset, or the ideal buffer, filled: the study's data leave them out."""
        return frozenset(name for name in FILLED if name not in self.model_fields_set)
