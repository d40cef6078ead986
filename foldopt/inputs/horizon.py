"""Reading a horizon: (azimuth, elevation) points checked into a profile, or a horizon file.

A profile is what :mod:`foldopt.physics.horizon` takes: azimuths [deg] strictly increasing in
[0, 360), clockwise from north, and elevations [deg] in [0, 90] (:func:`horizon_profile`). A
horizon file (:func:`read_horizon`) is one of

- PVGIS's ``printhorizon`` response as JSON [1]_, what ``pvlib.iotools.get_pvgis_horizon`` parses
  [2]_: ``outputs.horizon_profile``, a list of ``{"A": azimuth, "H_hor": elevation}``;
- PVGIS's horizon CSV [1]_: header lines (latitude, longitude), then a table with the columns
  ``A`` (or ``A_hor``) and ``H_hor``, tab separated, then a legend;
- a CSV with the header ``azimuth,elevation`` [deg], azimuth from north.

PVGIS gives azimuths from south (0 = S, 90 = W, -90 = E); they become north-based as pvlib makes
them, ``A + 180``, and the point at ``A = 180`` (north a second time, 360) is dropped [2]_. The
format is told from the content, not from the name.

References
----------
.. [1] European Commission JRC, PVGIS tools, "Horizon profile": the horizon height at 48
   equidistant directions; csv (latitude and longitude, then A_hor, H_hor, A_sun(w), H_sun(w),
   A_sun(s), H_sun(s), with A_hor 0 = S, 90 = W, -90 = E) and json (``inputs.location``,
   ``outputs.horizon_profile`` of ``A`` and ``H_hor``, ``outputs.winter_solstice``,
   ``outputs.summer_solstice``). https://joint-research-centre.ec.europa.eu/pvgis-online-tool/pvgis-tools/horizon-profile_en
.. [2] pvlib-python, ``pvlib.iotools.get_pvgis_horizon`` (0.16): ``data['horizon_azimuth'] +=
   180``, then ``data[data.index < 360]``.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING

from foldopt.errors import ConfigError
from foldopt.inputs.reading import read_input, size_limit

if TYPE_CHECKING:
    import numpy as np

FIELD = "site.horizon"
#: What a horizon file may be, for the messages.
ACCEPTS = (
    "a horizon file is PVGIS printhorizon JSON, PVGIS horizon CSV (columns A and H_hor) or a CSV with "
    "the header azimuth,elevation [deg]"
)
#: Bytes of a horizon file: PVGIS's are some 5 kB; a profile every 0.01 deg is under 1 MB.
MAX_HORIZON_BYTES = size_limit("MAX_HORIZON_BYTES", 1_000_000)
#: Longest value quoted back in a message [characters].
_QUOTE = 40


def _quote(value) -> str:
    text = repr(value)
    return text if len(text) <= _QUOTE else text[: _QUOTE - 3] + "..."


def _number(value) -> float | None:
    """A finite real number (not a bool), or None."""
    if isinstance(value, bool) or not isinstance(value, Real):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _checked(pairs, labels) -> tuple[np.ndarray, np.ndarray]:
    """:func:`horizon_profile`, each point named by its label in the messages."""
    if isinstance(pairs, (str, bytes, dict)) or not hasattr(pairs, "__iter__"):
        raise ValueError(
            f"expected a list of [azimuth, elevation] pairs in degrees; got {type(pairs).__name__}"
        )
    points = {}
    for label, pair in zip(labels, pairs):
        if isinstance(pair, (str, bytes, dict)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise ValueError(
                f"{label}: expected an [azimuth, elevation] pair in degrees; got {_quote(pair)}"
            )
        azimuth, elevation = _number(pair[0]), _number(pair[1])
        if azimuth is None or elevation is None:
            raise ValueError(
                f"{label}: azimuth and elevation must be finite numbers [deg]; got {_quote(pair)}"
            )
        if not 0.0 <= azimuth <= 360.0:
            raise ValueError(
                f"{label}: azimuth {azimuth:g} deg is outside [0, 360] (clockwise from north)"
            )
        if elevation > 90.0:
            raise ValueError(f"{label}: elevation {elevation:g} deg is above 90")
        # 360 is north again; see horizon_profile
        azimuth, elevation = azimuth % 360.0, max(elevation, 0.0)
        if azimuth in points and points[azimuth][1] != elevation:
            other, seen = points[azimuth]
            raise ValueError(
                f"azimuth {azimuth:g} deg is given twice, at {other} and {label}, with elevations "
                f"{seen:g} and {elevation:g} deg"
            )
        points.setdefault(azimuth, (label, elevation))
    if len(points) < 2:
        raise ValueError(f"a horizon needs at least 2 distinct azimuths; got {len(points)}")
    import numpy as np  # where a horizon is given: a study's checks (a --help, a bad value) need no numpy

    azimuths = np.array(sorted(points))
    return azimuths, np.array([points[a][1] for a in azimuths])


def horizon_profile(pairs) -> tuple[np.ndarray, np.ndarray]:
    """A horizon profile from (azimuth, elevation) points, checked.

    Negative elevations become 0: the model's sky ends at the horizontal (its isotropic sky and
    horizon band lie above it) and the ground-reflected light is not changed by a horizon, so a
    horizon below the horizontal (a summit's, a mast's) is the open plain's there.

    Parameters
    ----------
    pairs : sequence of (float, float)
        (azimuth [deg] clockwise from north, in [0, 360], 360 the same as 0; elevation [deg] at most
        90), in any order; a point given twice with one elevation counts once.

    Returns
    -------
    azimuth, elevation : numpy.ndarray
        [deg], sorted by azimuth, strictly increasing in [0, 360): what
        :func:`foldopt.physics.horizon.sky_view_factors` takes.

    Raises
    ------
    ValueError
        One line naming what is wrong (the caller names the field): a point that is no pair of
        finite numbers, an azimuth outside [0, 360], an elevation above 90, an azimuth given twice
        with two elevations, fewer than 2 distinct azimuths.

    Examples
    --------
    >>> azimuth, elevation = horizon_profile([[360, 5], [90, 20.5], [180, -2]])
    >>> print(azimuth, elevation)
    [  0.  90. 180.] [ 5.  20.5  0. ]
    """
    if isinstance(pairs, (str, bytes, dict)) or not hasattr(pairs, "__iter__"):
        return _checked(pairs, [])
    pairs = list(pairs)
    return _checked(pairs, [f"point {k}" for k in range(1, len(pairs) + 1)])


class _Problem(Exception):
    """What is wrong with a horizon file, before the field and the formats are added."""


def _from_pvgis(points) -> list:
    """PVGIS (A from south, H_hor) points north-based, as pvlib turns them, the repeated north dropped."""
    turned = [(label, (azimuth + 180.0, elevation)) for label, (azimuth, elevation) in points]
    return [(label, pair) for label, pair in turned if pair[0] < 360.0]


def _json_points(text: str, path: Path) -> list:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise _Problem(f"{path} is not valid JSON: {error.msg} (line {error.lineno})") from None
    except RecursionError:
        raise _Problem(f"{path}: JSON nested too deeply") from None
    outputs = data.get("outputs") if isinstance(data, dict) else None
    profile = outputs.get("horizon_profile") if isinstance(outputs, dict) else None
    if not isinstance(profile, list):
        raise _Problem(
            f"{path}: JSON without outputs.horizon_profile, the list a PVGIS printhorizon response holds"
        )
    points = []
    for k, entry in enumerate(profile, start=1):
        label = f"outputs.horizon_profile[{k - 1}]"
        if (
            not isinstance(entry, dict)
            or _number(entry.get("A")) is None
            or _number(entry.get("H_hor")) is None
        ):
            raise _Problem(
                f'{path}, {label}: expected {{"A": azimuth, "H_hor": elevation}} (numbers, deg); got '
                f"{_quote(entry)}"
            )
        points.append((label, (float(entry["A"]), float(entry["H_hor"]))))
    return _from_pvgis(points)


def _cells(line: str) -> list[str]:
    """A line's cells, split at tabs, commas, semicolons or spaces, quotes dropped."""
    return [cell.strip('"') for cell in re.split(r"[\t,;\s]+", line.strip()) if cell.strip('"')]


def _table_points(lines: list[str], path: Path) -> list | None:
    """The PVGIS table's (A, H_hor) points, or None where no line heads such a table."""
    for number, line in enumerate(lines):
        names = [cell.lower() for cell in _cells(line)]
        if "h_hor" in names and ("a" in names or "a_hor" in names):
            break
    else:
        return None
    a_col = names.index("a") if "a" in names else names.index("a_hor")
    h_col = names.index("h_hor")
    points = []
    for offset, row in enumerate(lines[number + 1 :], start=number + 2):
        cells = _cells(row)
        try:
            pair = (float(cells[a_col]), float(cells[h_col]))
        except (IndexError, ValueError):
            if points:  # the table ends at its first line that is not one of numbers (the legend)
                break
            raise _Problem(
                f"{path}, line {offset}: expected the numbers of columns A and H_hor [deg]"
            ) from None
        points.append((f"line {offset}", pair))
    if not points:
        raise _Problem(f"{path}: the table of A and H_hor has no rows")
    return _from_pvgis(points)


def _csv_points(lines: list[str], path: Path) -> list | None:
    """The points of a CSV headed ``azimuth,elevation``, or None where it is not headed so."""
    first = next((k for k, line in enumerate(lines) if line.strip()), None)
    if first is None or [cell.lower() for cell in _cells(lines[first])] != ["azimuth", "elevation"]:
        return None
    points = []
    for offset, row in enumerate(
        csv.reader(io.StringIO("\n".join(lines[first + 1 :]))), start=first + 2
    ):
        if not any(cell.strip() for cell in row):
            continue
        try:
            azimuth, elevation = (float(cell) for cell in row)
        except ValueError:
            raise _Problem(
                f"{path}, line {offset}: expected azimuth,elevation (two numbers, deg)"
            ) from None
        points.append((f"line {offset}", (azimuth, elevation)))
    return points


def read_horizon(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """A horizon profile from a file: PVGIS's JSON or CSV, or a CSV of azimuth,elevation.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (module docstring), UTF-8 with or without a byte-order mark, at most
        :data:`MAX_HORIZON_BYTES`.

    Returns
    -------
    azimuth, elevation : numpy.ndarray
        [deg], north-based, as :func:`horizon_profile` returns them.

    Raises
    ------
    foldopt.ConfigError
        One line, ``site.horizon: ...``, naming the file (and the line or entry) and what a horizon
        file may be: missing, empty, binary, not UTF-8, in none of the formats, malformed, or with
        points :func:`horizon_profile` refuses.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = (Path(folder) / "hills.csv").write_text("azimuth,elevation\\n0,5\\n180,12\\n")
    ...     print(*read_horizon(Path(folder) / "hills.csv"))
    [  0. 180.] [ 5. 12.]
    """
    path = Path(path)
    try:
        try:
            text = read_input(path, FIELD, MAX_HORIZON_BYTES, "MAX_HORIZON_BYTES", "horizon file")
        except ConfigError as error:
            raise _Problem(error.errors[0].removeprefix(f"{FIELD}: ")) from None
        if "\x00" in text:
            raise _Problem(f"{path} is binary, not text")
        if not text.strip():
            raise _Problem(f"{path} is empty")
        if text.lstrip().startswith("{"):
            points = _json_points(text, path)
        else:
            lines = text.splitlines()
            points = _csv_points(lines, path)
            if points is None:
                points = _table_points(lines, path)
            if points is None:
                raise _Problem(f"{path} is in none of the horizon formats")
        try:
            return _checked([pair for _, pair in points], [label for label, _ in points])
        except ValueError as error:
            raise _Problem(f"{path}: {error}") from None
    except _Problem as problem:
        raise ConfigError([f"{FIELD}: {problem}; {ACCEPTS}"]) from None
