"""The checks of a weather file's rows: hourly, finite and physically possible.

A file is checked once, when it is read, and any fault raises
:class:`~foldopt.errors.WeatherError`: one line naming the file, where (``line N`` of a TMY3 or
EPW file, counting its 2 or 8 header lines; ``record N`` of a PVGIS file's
``outputs.tmy_hourly``; or the header field or column) and why. When several rows fail the same
check, the first is named and the rest counted. Nothing is filled in silently, with one
documented exception: a file without any air temperature or wind speed column at all gets 20 C
and 1 m/s (:data:`DEFAULT_TEMP_AIR`, :data:`DEFAULT_WIND_SPEED`), as foldopt always did.

Each format's reader checks the file itself (:mod:`foldopt.inputs.weather`): not empty, at least
one row after its header, no February 29 (pvlib reads a TMY3 file's as March 1, and an EPW
file's cannot be coerced to a year without one), readable by pvlib (any exception of pvlib's
reader is the file not being readable, with its reason; a PVGIS file that is not JSON is named
with the line and column of the fault), and its header's site: latitude in [-90, 90] deg,
longitude in [-180, 180] deg, a finite altitude and a time zone offset in [-12, 14] h (UTC-12 to
UTC+14, the offsets in use). :func:`check_rows` then checks:

* The columns: ``ghi``, ``dni`` and ``dhi`` must exist; ``temp_air`` and ``wind_speed`` may be
  absent (see above) but, if present, are checked like the others.
* The rows: hourly and strictly increasing once the year is coerced (no duplicate hour); every
  value used a finite number; and within physical bounds, evaluated at the interval centre of the
  file's own convention (its format's ``interval_label``, whatever ``label`` a study gives):

  - ``0 <= ghi <= 1.5 E0`` and ``0 <= dni <= E0`` (:data:`MAX_GHI_PER_EXTRA`,
    :data:`MAX_DNI_PER_EXTRA`), where ``E0`` is the extraterrestrial normal irradiance of the day
    (pvlib ``irradiance.get_extra_radiation``, 1320 to 1414 W/m^2); ``0 <= dhi``. These take the
    multipliers of BSRN's "physically possible" limits as QCRad applies them [1]_ [2]_ (pvanalytics
    ``quality.irradiance.check_irradiance_limits_qcrad``): ``-4 <= ghi <= 1.5 E0 mu0^1.2 + 100``,
    ``-4 <= dni <= E0`` and ``-4 <= dhi <= 0.95 E0 mu0^1.2 + 50`` W/m^2, ``mu0`` the cosine of the
    solar zenith; without the zenith term, so that no bound hangs on the file's clock (which the
    beam test below checks), and with no negative light, which no typical year holds.
  - ``dhi <= 1.10 ghi + 10 W/m^2`` (:data:`DHI_TOLERANCE`): BSRN's comparison test bounds the
    diffuse ratio ``dhi / ghi`` by 1.05 for solar zenith angles below 75 deg and 1.10 from 75 to
    93 deg where ``ghi > 50 W/m^2`` [1]_ [2]_ (pvanalytics
    ``quality.irradiance.check_irradiance_consistency_qcrad``); foldopt takes 1.10 at every
    zenith, and the 10 W/m^2 covers the dim hours the test leaves out and the rounding of files
    that store whole W/m^2.
  - ``dni max(cos(zenith), 0) <= ghi + 50 W/m^2`` (:data:`BEAM_TOLERANCE`), the solar zenith
    from pvlib ``solarposition.get_solarposition`` at the file's site and the interval centre:
    the beam cannot bring more light to the ground than the global light. This is the one-sided
    form of QCRad's closure test, ``ghi / (dni cos(zenith) + dhi)`` in [0.92, 1.08] below 75 deg
    and [0.85, 1.15] from 75 to 93 deg where the sum exceeds 50 W/m^2 [2]_, which a typical
    year's modelled hours need not meet. A file whose clock, site or columns are wrong breaks it
    at low sun (a clock one hour off gives 90 to 94 W/m^2 on the Greensboro TMY3 sample).
  - ``temp_air`` in [-90, 65] C (world records -89.2 C at Vostok, 56.7 C at Death Valley [3]_),
    ``wind_speed`` in [0, 120] m/s (world record gust 113 m/s at Barrow Island [3]_). These and
    the irradiance bounds catch EPW's missing-value markers (9999 W/m^2, 99.9 C, 999 m/s [4]_).

  The tolerances sit above the worst residuals of real files, measured on pvlib's TMY3 samples
  (723170TYA.CSV, 703165TY.csv), an EPW written from the first (tests/test_weather_year.py), and
  the EPW and PVGIS files of pvlib's own tests (NLD_Amsterdam062400_IWEC.epw,
  tmy_45.000_8.000_2005_2023.epw and .json): ``dhi - ghi`` is at most 0.00 W/m^2 in all of them;
  ``dni cos(zenith) - ghi`` at most 0.00 W/m^2 but in PVGIS's EPW (25.6 W/m^2: its light comes
  about half an hour later than EPW's hour-ending stamps say); GHI reaches 0.77 E0 and DNI
  0.72 E0. Each of these files reads in 0.1 to 0.2 s, the checks included.

References
----------
.. [1] C. N. Long, E. G. Dutton, "BSRN Global Network recommended QC tests, V2.0", BSRN
   Technical Report, 2002.
.. [2] C. N. Long, Y. Shi, "An automated quality assessment and control algorithm for surface
   radiation measurements", The Open Atmospheric Science Journal 2, 23-37, 2008 (QCRad).
.. [3] World Meteorological Organization, World Weather and Climate Extremes Archive,
   https://wmo.asu.edu/.
.. [4] EnergyPlus, Auxiliary Programs, "Energyplus Weather File (EPW) Data Dictionary" (missing
   values of each field).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from foldopt.inputs.weather.formats import HOUR, WeatherFormat

#: The columns of a weather frame, in order.
COLUMNS = ("ghi", "dni", "dhi", "temp_air", "wind_speed")
_UNITS = {"ghi": "W/m^2", "dni": "W/m^2", "dhi": "W/m^2", "temp_air": "C", "wind_speed": "m/s"}
#: Air temperature [C] and wind speed [m/s] of a file without such a column at all.
DEFAULT_TEMP_AIR = 20.0
DEFAULT_WIND_SPEED = 1.0
#: Bounds of GHI and DNI as multiples of the extraterrestrial normal irradiance of the day.
MAX_GHI_PER_EXTRA = 1.5
MAX_DNI_PER_EXTRA = 1.0
#: ``dhi <= (1 + fraction) ghi + absolute`` [-, W/m^2]: BSRN's diffuse-ratio bound 1.10 [1]_,
#: plus 10 W/m^2 for dim hours and rounding. Worst on the real files (module docstring): 0.00 W/m^2.
DHI_TOLERANCE = (0.10, 10.0)
#: ``dni max(cos(zenith), 0) <= ghi + BEAM_TOLERANCE`` [W/m^2]. Worst on the real files: 0.00 W/m^2
#: (TMY3 samples, the EPW written from one, IWEC Amsterdam EPW, PVGIS JSON) and 25.6 W/m^2 (PVGIS EPW,
#: 2025-02-27 16:00-17:00: DNI 592, GHI 139 W/m^2, zenith 73.8 deg); a one-hour clock error on the
#: Greensboro TMY3 gives 90 to 94 W/m^2.
BEAM_TOLERANCE = 50.0
#: Air temperature [C] and wind speed [m/s] bounds (world records, module docstring [3]_).
TEMP_AIR_BOUNDS = (-90.0, 65.0)
WIND_SPEED_BOUNDS = (0.0, 120.0)


def check_rows(
    data: pd.DataFrame, fmt: WeatherFormat, index: pd.DatetimeIndex, site: dict, where, fail
) -> pd.DataFrame:
    """The rows' checks (module docstring).

    Parameters
    ----------
    data : pandas.DataFrame
        pvlib's frame of the file.
    fmt : WeatherFormat
        The file's format.
    index : pandas.DatetimeIndex
        The rows' stamps as the format's reader returns them (its ``interval_label``), the year
        coerced.
    site : dict
        The file's site: ``latitude``, ``longitude`` [deg], ``altitude`` [m].
    where : callable
        ``where(i)``: where row ``i`` is in the file (``line 5``).
    fail : callable
        ``fail(message)``: the error to raise.

    Returns
    -------
    pandas.DataFrame
        :data:`COLUMNS` and ``cloud_cover`` (the total sky cover [0-1], NaN where unknown) as
        floats (``ghi``, ``dni``, ``dhi`` [W/m^2], ``temp_air`` [C],
        ``wind_speed`` [m/s]), in file order, indexed by ``index``.
    """
    kind = fmt.label
    label = fmt.interval_label
    utc = " UTC" if fmt.to_local is not None else ""

    def at(i: int) -> str:
        start = index[i] - HOUR if label == "end" else index[i]
        return f"{where(i)} ({start:%Y-%m-%d %H:%M}-{start + HOUR:%H:%M}{utc})"

    def refuse(bad, describe) -> None:
        bad = np.flatnonzero(bad)
        if bad.size:
            more = f"; and {bad.size - 1} more rows" if bad.size > 1 else ""
            raise fail(f"{at(bad[0])}: {describe(bad[0])}{more}")

    for key in ("ghi", "dni", "dhi"):
        if key not in data.columns:
            raise fail(
                f"column {key} missing: no {fmt.columns[key]!r} in {fmt.columns_at} of this {kind} file"
            )
    # Time: hourly and strictly increasing once the year is coerced.
    step = np.diff(index.as_unit("ns").asi8)
    hour = HOUR.value
    refuse(
        index.duplicated(keep="first"),
        lambda i: f"the same hour as {where(int(np.argmax(index == index[i])))}",
    )
    refuse(np.r_[False, step < 0], lambda i: f"before {at(i - 1)}: rows must run forward in time")
    refuse(
        np.r_[False, step > hour],
        lambda i: f"{step[i - 1] / hour:g} h after {at(i - 1)}: rows must be hourly",
    )
    refuse(
        np.r_[False, (step > 0) & (step < hour)],
        lambda i: f"{step[i - 1] / 6e10:g} min after {at(i - 1)}: rows must be hourly",
    )
    # Values: finite numbers; a column of air temperature or wind speed may be absent altogether.
    values = {}
    for key in COLUMNS:
        if key not in data.columns:
            values[key] = np.full(
                len(data), DEFAULT_TEMP_AIR if key == "temp_air" else DEFAULT_WIND_SPEED
            )
            continue
        raw = data[key]
        values[key] = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)

        def not_finite(i, key=key, raw=raw):
            text = raw.iloc[i]
            if (
                text is None
                or (isinstance(text, float) and math.isnan(text))
                or not str(text).strip()
            ):
                return f"{key} has no value (empty or NaN)"
            return f"{key} = {str(text).strip()[:20]}: not a finite number"

        refuse(~np.isfinite(values[key]), not_finite)
    ghi, dni, dhi = values["ghi"], values["dni"], values["dhi"]

    def value(key: str, i: int) -> str:
        text = f"{key} = {values[key][i]:g} {_UNITS[key]}"
        if key in fmt.missing and values[key][i] == fmt.missing[key]:
            text += f" ({kind}'s missing-value marker)"
        return text

    # Physical bounds, at the interval centres of the file's own convention.
    centres = index + (HOUR / 2 if label == "start" else -HOUR / 2)
    import pvlib

    extra = np.asarray(pvlib.irradiance.get_extra_radiation(centres.day_of_year), dtype=float)
    for key in ("ghi", "dni", "dhi"):
        refuse(values[key] < 0, lambda i, key=key: f"{value(key, i)}: must be >= 0")
    refuse(
        ghi > MAX_GHI_PER_EXTRA * extra,
        lambda i: (
            f"{value('ghi', i)}: must be <= {MAX_GHI_PER_EXTRA * extra[i]:.0f} W/m^2, "
            f"{MAX_GHI_PER_EXTRA:g} times the extraterrestrial normal irradiance that day"
        ),
    )
    refuse(
        dni > MAX_DNI_PER_EXTRA * extra,
        lambda i: (
            f"{value('dni', i)}: must be <= {MAX_DNI_PER_EXTRA * extra[i]:.0f} W/m^2, "
            f"the extraterrestrial normal irradiance that day"
        ),
    )
    for key, (lo, hi) in (("temp_air", TEMP_AIR_BOUNDS), ("wind_speed", WIND_SPEED_BOUNDS)):
        refuse(
            (values[key] < lo) | (values[key] > hi),
            lambda i, key=key, lo=lo, hi=hi: (
                f"{value(key, i)}: must be in [{lo:g}, {hi:g}] {_UNITS[key]}"
            ),
        )
    fraction, absolute = DHI_TOLERANCE
    refuse(
        dhi > (1.0 + fraction) * ghi + absolute,
        lambda i: (
            f"{value('dhi', i)} exceeds {value('ghi', i)}: the diffuse light is part of the global "
            f"(tolerance {fraction:.0%} + {absolute:g} W/m^2)"
        ),
    )
    # The sun where there is direct light only: a row without any brings no beam to the ground
    # (ghi >= 0 above). pvlib's SPA is elementwise: those rows' zenith is the whole year's.
    lit = np.flatnonzero(dni > 0)
    zenith, beam = np.full(len(dni), np.nan), np.zeros(len(dni))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pvlib reads DatetimeIndex.dayofyear, deprecated by pandas
        if lit.size:
            zenith[lit] = pvlib.solarposition.get_solarposition(
                centres[lit], site["latitude"], site["longitude"], site["altitude"]
            )["zenith"].to_numpy(dtype=float)
    beam[lit] = dni[lit] * np.maximum(np.cos(np.radians(zenith[lit])), 0.0)
    refuse(
        beam > ghi + BEAM_TOLERANCE,
        lambda i: (
            f"{value('dni', i)} at solar zenith {zenith[i]:.1f} deg brings {beam[i]:.0f} W/m^2 to "
            f"the ground, more than {value('ghi', i)} (tolerance {BEAM_TOLERANCE:g} W/m^2): "
            f"is the file's site, clock or a column wrong?"
        ),
    )
    # The total sky cover, where the format has one: only a cloud ensemble reads it, so a value
    # out of [0, 1] (a missing-value marker: EPW's 99) is unknown, not a fault.
    cover = np.full(len(data), np.nan)
    if fmt.cover is not None and fmt.cover[0] in data.columns:
        cover = (
            pd.to_numeric(data[fmt.cover[0]], errors="coerce").to_numpy(dtype=float) / fmt.cover[1]
        )
        cover = np.where((cover >= 0.0) & (cover <= 1.0), cover, np.nan)
    values["cloud_cover"] = cover
    return pd.DataFrame(values, index=index.rename(None))
