"""Study policy: what a study becomes when a user changes some of its fields.

One function, :func:`apply`, turns a study's data and the fields a user changed into the data of
the study that runs. The command line's options, :func:`foldopt.sweep`'s keywords and
:meth:`foldopt.Study.variant` all go through it, so the same request gives the same study however
it is made. The rules, each said back to the user by :func:`apply`'s second value:

- **paper mode stays with the paper's site and day.** A paper-mode study whose site (latitude,
  longitude, altitude), day or weather changes runs in exact mode unless the mode is given: the
  paper's beam-only Eq. 5 gives a level panel at the equator almost no beam, and it has no
  altitude term and no diffuse light;
- a change of mode gives the new mode its own geometry (azimuth-split in paper mode, hinge in
  exact), its own sky (Ineichen with diffuse light in exact mode, the paper's beam-only Meinel
  sky in paper mode) and its own PV model (PVWatts' in exact mode, the paper's ideal one in paper
  mode) unless the geometry, the sky or the PV model is given;
- a new latitude tilts the panel at ``|latitude|`` toward the equator unless tilt or azimuth are
  given; a new latitude or longitude drops the site's name, a new longitude its time zone;
- the planes of an existing array (``panel.planes``) bring their own base orientation (the
  study's tilt and azimuth give way, each unless given) and, like an optimisation that turns the
  panel, take a paper-mode study to exact mode unless the mode is given;
- a weather file brings its own site, year and light (the study's sky, site and day give way; the
  site fields given complete the file's), and a measured file (or a source read as one,
  ``pvgis-hourly``) its own days and step; a weather source is fetched for the study's latitude
  and longitude unless others are given;
- a new tracker model keeps only the tracker's standby draw; a new fold-angle step starts the grid
  at that step; a load profile given without a scale runs as written (scale 1).

The module is a leaf: plain dictionaries in and out, nothing heavy imported.
"""

from __future__ import annotations

import copy

from foldopt.inputs.optimize_section import vary_names
from foldopt.names import (
    FLAT_FOLD_ANGLE,
    HOURLY_WEATHER_FORMATS,
    MEASURED_WEATHER_SOURCES,
    OPTIMIZE_VARIABLES,
    WEATHER_FORMATS,
    canonical,
)

#: Sections of a study whose fields a change merges into (a mapping changes the fields it names);
#: any other field given a mapping (a load profile, a weather file) is replaced whole.
SECTIONS = ("site", "panel", "tracker", "objective", "fold_angles", "near_optimal", "storage")
#: Fields that take a paper-mode study away from the paper's site and day.
AWAY_FROM_PAPER = ("site.latitude", "site.longitude", "site.altitude", "date", "weather")
#: What the policy says where it switches a paper-mode study to exact mode.
EXACT_NOTE = (
    "exact mode (paper mode is for the paper's own site and day: set mode paper to keep it)"
)
#: An optimisation that turns or re-tilts the panel leaves paper mode too: Shin et al.'s Eq. 5 is the
#: angle of incidence only for a surface facing the sun's azimuth, so it would choose the mounting.
MOUNTING_NOTE = (
    "exact mode (the paper's Eq. 5 is no angle of incidence for a re-tilted or turned panel: set "
    "mode paper to keep it)"
)


#: Sections a study may give as one value, and the field that value is.
SHORTHANDS = {"weather": "path", "objective": "statistic", "tracker": "model"}


def set_path(data: dict, path: str, value) -> dict:
    """Set one field of a study's data.

    Parameters
    ----------
    data : dict
    path : str
        A dotted field path (``site.latitude``); missing sections are made.
    value : object

    Returns
    -------
    dict
        A deep copy of ``data`` with ``path`` set to ``value``.
    """
    out = copy.deepcopy(data)
    node = out
    parts = path.split(".")
    for part in parts[:-1]:
        child = node.get(part)
        if isinstance(child, str) and part in SHORTHANDS:
            child = {SHORTHANDS[part]: child}  # weather: FILE is weather: {path: FILE}
        if not isinstance(child, dict):
            child = {}
        node[part] = child
        node = child
    node[parts[-1]] = value
    return out


def flatten(changes: dict) -> dict:
    """Changes as dotted paths.

    Parameters
    ----------
    changes : dict
        Field names or dotted paths to values.

    Returns
    -------
    dict
        A mapping given for a :data:`SECTIONS` field as one change per field it names
        (``panel={"area": 0.1}`` is ``panel.area``); anything else whole.
    """
    flat = {}
    for path, value in changes.items():
        if path in SECTIONS and isinstance(value, dict):
            flat.update({f"{path}.{key}": item for key, item in value.items()})
        else:
            flat[path] = value
    return flat


def touched(given, prefix: str) -> bool:
    """Whether a field, or a field inside it, is among some paths.

    Parameters
    ----------
    given : iterable of str
        Dotted field paths.
    prefix : str
        A dotted field path.

    Returns
    -------
    bool
        Whether any of ``given`` is ``prefix`` or lies inside it.
    """
    return any(path == prefix or path.startswith(prefix + ".") for path in given)


def _section(data: dict, name: str) -> dict:
    """A section of the data as a mapping (a tracker or objective may be written as a name)."""
    value = data.get(name)
    if isinstance(value, str):
        return {"objective": {"statistic": value}, "tracker": {"model": value}}.get(name, {})
    return dict(value) if isinstance(value, dict) else {}


def is_single(value) -> bool:
    """Whether a value is one case, not an axis.

    Parameters
    ----------
    value : object

    Returns
    -------
    bool
        True for a value that is no list, range, list text (``a,b``) or date keyword.
    """
    text = str(value)
    return (
        not isinstance(value, (list, tuple))
        and ":" not in text
        and "," not in text
        and text not in ("year", "equinoxes-solstices")
    )


def _varied(optimize) -> list[str]:
    """The variables an ``optimize`` section varies (all by default); none where it names no list
    (its validation says so)."""
    vary = optimize.get("vary") if isinstance(optimize, dict) else None
    try:
        return list(OPTIMIZE_VARIABLES) if vary is None else vary_names(vary)
    except ValueError:
        return []


def _angle(value) -> bool:
    """Whether ``value`` is a fold angle step a grid can start at: a number in (0, 180] deg (YAML
    reads ``1e-9`` as a string, which the study's field reads as a number)."""
    if isinstance(value, bool):
        return False
    try:
        return 0 < float(value) <= FLAT_FOLD_ANGLE
    except (TypeError, ValueError):
        return False


def _source(weather) -> bool:
    """Whether a ``weather`` change names a source (fetched for the site), not a file."""
    return isinstance(weather, dict) and weather.get("source") is not None


def apply(data: dict, changes: dict, axis_field: str | None = None) -> tuple[dict, list[str]]:
    """The study data that runs when ``changes`` are made to ``data``.

    Parameters
    ----------
    data : dict
        A study's fields (as a YAML study holds them, or ``Study.model_dump``).
    changes : dict
        Field paths (dotted, or a section name with a mapping) to new values; a list or a range
        ``"start:stop:step"`` makes an axis.
    axis_field : str, optional
        The field a sweep varies even where ``changes`` leave it out (``site.latitude`` for a
        latitude sweep, ``date`` for a day sweep): it counts as changed.

    Returns
    -------
    data : dict
        The new study data.
    decided : list of str
        What the policy decided beyond the changes themselves, in the user's words.
    """
    data = copy.deepcopy(dict(data))
    changes = flatten(changes)
    given = set(changes) | ({axis_field} if axis_field else set())
    decided = []
    for name in ("tracker", "objective"):
        if isinstance(data.get(name), str):
            data[name] = _section(data, name)
    weather = changes.get("weather")
    if weather is not None:
        data.pop("sky", None)  # the file's light is shaped by its own clear sky
        if "site" not in given:
            # The file's site: the fields given complete or move it, the study's other place does
            # not (its altitude, name or time zone are of another site). A source is fetched for
            # the study's place: its latitude and longitude stay where none are given.
            site = data.pop("site", None)
            if _source(weather) and isinstance(site, dict):
                place = {key: site[key] for key in ("latitude", "longitude") if key in site}
                data["site"] = place
        if not touched(given, "date"):
            data.pop("date", None)  # the file's year, or a measured file's days
        fmt = changes.get(
            "weather.format", weather.get("format") if isinstance(weather, dict) else None
        )
        try:
            measured = (
                fmt is not None and canonical(fmt, WEATHER_FORMATS) not in HOURLY_WEATHER_FORMATS
            )
        except ValueError:
            measured = False  # no format: the study's validation names it
        if isinstance(weather, dict) and weather.get("source") in MEASURED_WEATHER_SOURCES:
            measured = True  # a source read as a measured file: its own step
        if measured and not touched(given, "step_min"):
            data.pop("step_min", None)  # a measured file's own step
    old_mode = data.get("mode", "exact")
    if (
        old_mode == "paper"
        and "mode" not in given
        and any(touched(given, path) for path in AWAY_FROM_PAPER)
    ):
        data["mode"] = "exact"
        decided.append(EXACT_NOTE)
    optimize = changes.get("optimize", data.get("optimize"))
    if "optimize.vary" in changes:
        optimize = {
            **(optimize if isinstance(optimize, dict) else {}),
            "vary": changes["optimize.vary"],
        }
    planes = touched(given, "panel.planes") and changes.get("panel.planes") is not None
    if (
        data.get("mode", "exact") == "paper"
        and "mode" not in given
        and (
            (touched(given, "optimize") and {"tilt", "azimuth"} & set(_varied(optimize))) or planes
        )
    ):
        data["mode"] = "exact"
        decided.append(MOUNTING_NOTE)
    new_mode = changes.get("mode", data.get("mode", "exact"))
    for field in ("geometry", "sky", "pv_model"):
        if new_mode != old_mode and field not in given:
            data.pop(field, None)  # the new mode's own
    site = data.get("site")
    moved = (
        touched(given, "site.latitude")
        or touched(given, "site.longitude")
        or (weather is not None and "site" not in data)
    )
    if isinstance(site, dict) and moved and not touched(given, "site.name"):
        site.pop("name", None)
    if (
        isinstance(site, dict)
        and touched(given, "site.longitude")
        and not touched(given, "site.timezone")
    ):
        site.pop("timezone", None)  # the new longitude's standard offset
    new_latitude = touched(given, "site.latitude") or (weather is not None and "site" not in data)
    if (
        new_latitude
        and not planes
        and not (touched(given, "panel.tilt") or touched(given, "panel.azimuth"))
    ):
        panel = _section(data, "panel")
        dropped = [panel.pop(key, None) for key in ("tilt", "azimuth")]
        if any(value is not None for value in dropped):
            decided.append("panel tilted at |latitude| toward the equator")
        data["panel"] = panel
    if planes:
        panel = _section(data, "panel")
        dropped = [
            panel.pop(key, None)
            for key in ("tilt", "azimuth")
            if not touched(given, f"panel.{key}")
        ]
        if any(value is not None for value in dropped):
            decided.append("the panel's base orientation from the planes")
        data["panel"] = panel
    if "tracker.model" in given:
        tracker = _section(data, "tracker")
        data["tracker"] = {key: tracker[key] for key in ("standby_w",) if key in tracker}
    step = changes.get("fold_angles.step")
    if (
        "fold_angles.step" in given
        and "fold_angles.start" not in given
        and (_angle(step) or not is_single(step))
    ):
        # A single step out of range is refused as the step alone, not again as the start it
        # would give.
        data["fold_angles"] = {
            "start": step,
            "stop": changes.get("fold_angles.stop", FLAT_FOLD_ANGLE),
            "step": step,
        }
    if (
        "load_profile" in given
        and changes.get("load_profile") is not None
        and "p_load" not in given
    ):
        data["p_load"] = 1.0  # the profile as written, not the study's constant load
    for path, value in changes.items():
        data = set_path(data, path, value)
    if data.get("site") is None:
        data.pop("site", None)
    return data, decided
