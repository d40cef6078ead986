"""The names foldopt accepts, in one registry: configuration, command line and physics share it.

Every model, connection and option that is chosen by name is listed here, once, with the other
spellings a user may type (pvlib's, as in ``simplified_solis``, ``singlediode`` or ``singleaxis``,
and any case). :func:`canonical` turns a spelling into foldopt's name or raises an error that lists
the valid names and the closest ones. The module imports nothing heavy, so that the command line
can check its input and print its help before numpy, pandas or pvlib load.
"""

from __future__ import annotations

import difflib
import re

MODES = ("paper", "exact")
GEOMETRIES = ("azimuth-split", "hinge")
BEAM_SKIES = ("meinel", "hottel")  # beam only
CLEAR_SKIES = ("ineichen", "simplified-solis")  # global, direct and diffuse
SKIES = BEAM_SKIES + CLEAR_SKIES
TRANSPOSITIONS = ("none", "isotropic", "haydavies", "perez")
IAMS = ("none", "ashrae", "physical")
PV_MODELS = ("ideal", "single-diode", "b-model")
TEMPERATURE_MODELS = ("fixed", "sapm")
CONNECTIONS = ("east", "west", "parallel", "series", "independent", "switching")
TRACKERS = ("dual-axis", "equatorial", "dual-axis-steps", "single-axis")
DRIVES = ("motor", "wh-per-degree")
WEATHER_FORMATS = ("tmy3", "epw", "pvgis")
INTERVAL_LABELS = ("start", "end", "centre")
HOTTEL_CLIMATES = ("tropical", "midlatitude-summer", "subarctic-summer", "midlatitude-winter")
ENGINES = ("numba", "numpy")
OUTPUT_FORMATS = ("table", "json")

#: Alexandru's half law as offsets of the afternoon moves from solar noon [h] (foldopt.physics.trackers).
#: His 12 actuating times (local time) pair up symmetrically about 13.319 h: 8.839/17.799,
#: 9.819/16.819, 10.619/16.019, 11.489/15.149, 12.189/14.449, 12.919/13.719. (He gives solar noon
#: as 13.206 h local; the 6.8 min offset is left out, the law being symmetric about solar noon by
#: construction.)
ALEXANDRU_STEP_OFFSETS_H = (0.400, 1.130, 1.830, 2.700, 3.500, 4.480)

#: Other spellings of a name, beyond case, ``_``/`` `` for ``-`` and dropped separators.
ALIASES = {
    "hay-davies": "haydavies",
    "hay_davies": "haydavies",
    "desoto": "single-diode",
    "de-soto": "single-diode",
    "cec": "single-diode",
    "sapm-cell": "sapm",
    "two-axis": "dual-axis",
    "2-axis": "dual-axis",
    "one-axis": "single-axis",
    "1-axis": "single-axis",
    "center": "centre",
    "pvgis-tmy": "pvgis",
}


def _squash(name: str) -> str:
    """A spelling without case or separators: ``Single_Diode`` and ``singlediode`` meet."""
    return re.sub(r"[\s_\-]+", "", name.lower())


def canonical(value, names, field: str = "name"):
    """foldopt's name for ``value`` among ``names``, accepting pvlib's and other spellings.

    Raises
    ------
    ValueError
        Naming the valid names and, where a spelling is close to one, "did you mean ...".
    """
    if not isinstance(value, str):
        return value
    text = value.strip()
    if text in names:
        return text
    lowered = text.lower().replace("_", "-").replace(" ", "-")
    lowered = ALIASES.get(lowered, ALIASES.get(text.lower(), lowered))
    if lowered in names:
        return lowered
    squashed = {_squash(name): name for name in names}
    if _squash(text) in squashed:
        return squashed[_squash(text)]
    close = difflib.get_close_matches(lowered, names, n=2, cutoff=0.6)
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    raise ValueError(f"must be one of {', '.join(names)}{hint}")
