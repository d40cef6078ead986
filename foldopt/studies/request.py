"""Requests: a study and the fields a user changed, turned into the plan that runs.

:func:`plan_request` is the one place where a request becomes a study: the command line's
``run``, ``sweep ...`` and ``size`` and the API's :func:`foldopt.sweep` and
:meth:`foldopt.Study.variant` all call it (or its policy, :func:`foldopt.inputs.policy.apply`), so the
same request gives the same plan, to the bit, whichever way it is made. It applies the study
policy, each sweep axis's default range and the year of day-of-year ranges, and lists what the
answer took from the study rather than from the request (:attr:`Request.taken`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from foldopt.inputs import policy
from foldopt.inputs.config import Plan, make_plan
from foldopt.errors import ConfigError

#: A sweep's axis -> the field it varies (``angle`` varies the fold angle of one case).
SWEEP_AXES = {"angle": None, "latitude": "site.latitude", "day": "date", "load": "p_load"}
#: Each sweep axis's range where the request leaves it out (``load``: see :func:`_default_loads`).
DEFAULT_RANGES = {"site.latitude": "-60:60:5", "date": "1:365:7"}
#: Short names of fields inside a section, for :func:`foldopt.sweep`'s keywords.
KEYWORDS = {
    "latitude": "site.latitude", "longitude": "site.longitude", "altitude": "site.altitude",
    "timezone": "site.timezone", "area": "panel.area", "efficiency": "panel.efficiency", "tilt": "panel.tilt",
    "azimuth": "panel.azimuth", "standby_w": "tracker.standby_w", "visits": "objective.visits",
}
#: Loads of a load sweep's default range: shares of the panel's rating (area x 1000 W/m^2 x efficiency).
DEFAULT_LOAD_SHARES = 20
_ISO_DATE = re.compile(r"^(\d{4})-\d\d-\d\d$")


@dataclass(frozen=True)
class Request:
    """A request made into a plan.

    Attributes
    ----------
    plan : Plan
        What runs: the study and its sweep axes.
    source : str
        The study the request started from (a file, or ``the given study``).
    taken : tuple of str
        What the answer took from the study or from defaults, not from the request.
    """

    plan: Plan
    source: str
    taken: tuple

    @property
    def defaults(self) -> dict | None:
        """``{"study": source, "taken": [...]}``, or None where nothing was taken."""
        return {"study": self.source, "taken": list(self.taken)} if self.taken else None


def _default_loads(data: dict) -> list[float]:
    panel = data.get("panel") or {}
    rating = float(panel.get("area", 0.1)) * 1000.0 * float(panel.get("efficiency", 0.2))
    return [round(rating * share / DEFAULT_LOAD_SHARES, 4) for share in range(1, DEFAULT_LOAD_SHARES + 1)]


def plan_request(data: dict, changes: dict | None = None, *, axis: str | None = None, source: str = "the given study",
                 name: str | None = None) -> Request:
    """The plan of a study with some fields changed, and what it took from the study.

    Parameters
    ----------
    data : dict
        The study's fields (a YAML study's data, or :meth:`foldopt.Study.data`).
    changes : dict, optional
        Dotted field paths (or sections with mappings) to values: a value sets the field, a list or
        a range ``"start:stop:step"`` makes it an axis; ``date`` also takes ``"year"`` and
        ``"equinoxes-solstices"``, ``year`` the year of day-of-year ranges.
    axis : {'angle', 'latitude', 'day', 'load'}, optional
        A sweep's own axis: its field takes :data:`DEFAULT_RANGES` where ``changes`` leave it out,
        and ``angle`` is one case (with a weather file, one fold angle for the file's year).
    source : str
        How the answer names the study the request started from.
    name : str, optional
        The plan's study name (default the study's).

    Returns
    -------
    Request

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the field.
    """
    if axis is not None and axis not in SWEEP_AXES:
        raise ConfigError([f"sweep: unknown axis {axis!r}; one of {', '.join(SWEEP_AXES)}"])
    changes = policy.flatten(dict(changes or {}))
    field = SWEEP_AXES.get(axis)
    if field is not None and field in changes and policy.is_single(changes[field]):
        raise ConfigError([f"{field}: sweep {axis} needs a range start:stop:step or a list"])
    new, decided = policy.apply(data, changes, field)
    if field is not None and field not in changes:
        new = policy.set_path(new, field, _default_loads(new) if field == "p_load" else DEFAULT_RANGES[field])
    if axis == "angle" and new.get("weather") is not None and "objective" not in new and not (
            "date" in changes and policy.is_single(changes["date"])):
        new["objective"] = {"statistic": "mean"}  # a year of weather at one fold angle
    study_year = _ISO_DATE.match(str(data.get("date", "")))
    if "year" not in new and study_year:
        new["year"] = int(study_year.group(1))  # days of year are the study's year's
    if name is not None:
        new["name"] = name
    plan = make_plan(new)
    if axis == "angle":
        varied = [path for path, _ in plan.axes if not (path == "date" and plan.base.objective is not None)]
        if varied:
            raise ConfigError([f"sweep angle: one site, day and load; {', '.join(varied)} vary (use sweep latitude, "
                               "day or load)"])
    return Request(plan, source, tuple(_taken(plan, changes, field, new, decided)))


def _taken(plan: Plan, changes: dict, field: str | None, data: dict, decided: list[str]) -> list[str]:
    """What a request took from its study and its defaults, for the answer's "from" line."""
    from foldopt.inputs.loads import load_text

    study = plan.base
    given = set(changes)
    weather = "weather" in given
    taken = []
    if field is not None and field not in given:
        if field == "p_load":
            taken.append(f"{DEFAULT_LOAD_SHARES} loads, 5 % to 100 % of {data['p_load'][-1]:g} W (default range)")
        else:
            year = f" of {data['year']}" if field == "date" and data.get("year") else ""
            label = {"site.latitude": "latitude", "date": "day"}[field]
            taken.append(f"{label} {DEFAULT_RANGES[field]}{year} (default range)")
    if not policy.touched(given, "site") and not weather and field != "site.latitude":
        taken.append(f"site {study.site.latitude:g}, {study.site.longitude:g}")
    if "date" not in given and not weather and field != "date":
        taken.append(f"date {study.date}")
    if "panel.area" not in given:
        taken.append(f"panel {study.panel.area:g} m^2")
    if "p_load" not in given and field != "p_load":
        taken.append(load_text(study))
    if "mode" not in given:
        taken.append(policy.EXACT_NOTE if policy.EXACT_NOTE in decided else f"{study.mode} mode")
    if "pv_model" not in given:
        taken.append(f"{study.pv_model} PV model")
    taken += [item for item in decided if item != policy.EXACT_NOTE]
    return taken



def size_request(plan: Plan, source: str, cost_given: bool) -> Request:
    """A sizing's request: the study's one case, and what the sizing took from it (the site, day,
    load and efficiency, and the paper's panel cost where no cost is given)."""
    from foldopt.inputs.loads import load_text
    from foldopt.inputs.costs import PAPER_COST_PER_M2

    study = plan.base
    taken = [f"site, day, {load_text(study)}, efficiency {study.panel.efficiency:g}"]
    if not cost_given:
        taken.append(f"panel cost {PAPER_COST_PER_M2:g} $/m^2 (what Shin et al.'s 0.108 m^2 optimum implies; "
                     "cost_per_m2 or cost_per_w)")
    return Request(plan, source, tuple(taken))
