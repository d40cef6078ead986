"""The capability matrix: which study sections each kind of run honours, and each command's runs.

A request becomes one kind of run (:data:`RUNS`) by its study: one site and day, a plan of cases,
one fold angle over days, a cloud ensemble, a joint search, a panel sizing or a map. A capability
(:data:`CAPABILITIES`: a buffer, a weather file, a horizon...) is honoured by some runs; in any
other the front door (:func:`foldopt.studies.request.make_request`) refuses it in one line, so
that no command ignores a section silently. The docs' table is drawn from this registry
(``docs/capabilities.rst``, :func:`matrix_rows`), and ``tests/test_capabilities.py`` walks it.

A leaf: data only, nothing of foldopt but :mod:`foldopt.names`.
"""

from __future__ import annotations

import typing

from foldopt.names import Registry

#: The kinds of run a request can be, each with what it evaluates.
RUNS = Registry(
    "run",
    {
        "day": "one site and day",
        "cases": "a plan of cases, each its own best fold angle",
        "annual": "one fold angle over days, for an objective",
        "ensemble": "one fold angle over a cloud ensemble",
        "optimize": "fold angle, tilt and azimuth searched together",
        "sizing": "Shin et al.'s panel sizing",
        "map": "many sites, a year each",
    },
)

#: Each command and the runs its requests can be (a study file decides which ``run`` is).
COMMAND_RUNS = {
    "run": ("day", "cases", "annual", "ensemble", "optimize"),
    "sweep angle": ("day", "annual", "ensemble"),
    "sweep latitude": ("cases", "annual", "ensemble"),
    "sweep day": ("cases", "annual"),
    "sweep load": ("cases", "annual", "ensemble"),
    "optimize": ("optimize",),
    "size": ("sizing",),
    "size --storage": ("day", "annual"),
    "map": ("map",),
}
#: The commands whose requests :func:`foldopt.studies.request.make_request` makes.
COMMANDS = tuple(COMMAND_RUNS)


class Capability(typing.NamedTuple):
    """One capability of a study: the runs that honour it, and what a refusal tells the user.

    Attributes
    ----------
    name : str
        The study section or field that gives it (``storage``, ``site.horizon``).
    describes : str
        What it is, for the docs.
    honoured : tuple of str
        The runs of :data:`RUNS` that take it into their numbers.
    instead : str
        The end of a refusal: where it is honoured, and how to leave it out.
    needs : str
        The capability it refines (``costs`` price a ``storage``'s buffer): where that one is
        refused, its own refusal says it all.
    """

    name: str
    describes: str
    honoured: tuple
    instead: str
    needs: str = ""


_ALL = tuple(RUNS)
#: Every capability the front door checks, in the order the docs list them.
CAPABILITIES = (
    Capability(
        "storage",
        "a buffer behind a charge controller (--storage-wh, --min-soc)",
        ("day", "annual"),
        "a buffer is simulated over one day (foldopt run, sweep angle) or the days of an "
        "objective (--objective) and sized by foldopt size --storage (--set storage=null drops it)",
    ),
    Capability(
        "costs",
        "prices of panel, buffer, hinge and tracker drive: the cheapest panel and buffer of each "
        "kind meeting storage.target (design_space.csv)",
        ("day", "annual"),
        "the least-cost search sizes a buffer with a target over one day or the days of an "
        "objective (foldopt run, sweep angle) (--set costs=null drops it)",
        needs="storage",
    ),
    Capability(
        "weather",
        "a weather file or source: the site's own light (--weather); a map's sites each bring "
        "their own (--weather-dir, or a source: --weather NAME)",
        _ALL,
        "",
    ),
    Capability(
        "weather.members",
        "a cloud ensemble drawn from an hourly file (--members)",
        ("ensemble",),
        "one fold angle is chosen over an ensemble's members by foldopt run or sweep angle "
        "with an objective; leave out weather.members (--members)",
    ),
    Capability(
        "site.horizon",
        "the site's horizon shading its light (--horizon)",
        ("day", "cases", "annual", "ensemble", "optimize", "sizing"),
        "a horizon is of one site: a map's sites would all take it; leave it out",
    ),
    Capability(
        "load_profile",
        "a day's load in watts instead of a constant load (--load-profile)",
        ("day", "cases", "annual", "ensemble", "optimize"),
        "the panel's sizing and a map scale constant loads; give p_load (--p-load)",
    ),
    Capability(
        "panel.planes",
        "an existing array's two halves as they stand (--planes): the base orientation and fold "
        "angle that make them, evaluated beside the best fold",
        ("day", "annual"),
        "an existing array is evaluated as it stands at one site, over a day or the days of an "
        "objective (foldopt run, sweep angle); elsewhere give the base and fold its planes make "
        "(--tilt, --azimuth, --fold-angle), or leave panel.planes out",
    ),
    Capability(
        "optimize",
        "the fold angle, tilt and azimuth searched together (foldopt optimize)",
        ("optimize", "map"),
        "the joint search is foldopt optimize's, or foldopt run's of a study with the section "
        "(--set optimize=null drops it)",
    ),
)

#: Capability name -> its entry.
CAPABILITY = {capability.name: capability for capability in CAPABILITIES}

#: Fields a run sets itself or has no use for: a request that gives one is refused, with why. (A
#: study file may hold them: a map's sites replace its site, and the sizing has no tracker.)
SET_BY_RUN = {
    "sizing": {
        "tracker": "Shin et al.'s panel sizing compares flat and twofold panels, no tracker",
    },
    "map": {
        "site": "a map's sites are its grid (--lat/--lon), --sites CSV (name, latitude, "
        "longitude, altitude, timezone, horizon) or --weather-dir",
        "date": "a map evaluates every day of --year",
        "force_site": "a map's weather files bring their own sites",
    },
}


def refusal(name: str, command: str, run: str) -> str:
    """The one line that refuses a capability a run does not honour.

    Parameters
    ----------
    name : str
        A capability of :data:`CAPABILITIES`.
    command : str
        The command as the user typed it (``sweep latitude``).
    run : str
        The run the request is, one of :data:`RUNS`.

    Returns
    -------
    str
        ``<name>: foldopt <command> (<what the run is>) answers without it; <instead>``.
    """
    return f"{name}: foldopt {command} ({RUNS.describe(run)}) answers without it; {CAPABILITY[name].instead}"


def refusals(names, command: str, run: str) -> list[str]:
    """The lines that refuse the capabilities ``names`` a run does not honour: one each, but a
    capability whose :attr:`~Capability.needs` is refused too is said in that one's line.

    Parameters
    ----------
    names : iterable of str
        Capabilities of :data:`CAPABILITIES` the request gives and its run does not honour.
    command, run : str
        As :func:`refusal`'s.

    Returns
    -------
    list of str
    """
    names = list(dict.fromkeys(names))
    lines = {
        name: refusal(name, command, run) for name in names if CAPABILITY[name].needs not in names
    }
    for name in names:
        needs = CAPABILITY[name].needs
        if needs in lines:
            lines[needs] += f"; and {name}, which goes with it"
    return list(lines.values())


def matrix_rows() -> list[list[str]]:
    """The capability matrix as table rows, for the docs: a header, then a row per capability,
    its name, what it is, and ``yes`` or ``refused`` per run of :data:`RUNS`.

    Returns
    -------
    list of list of str
    """
    rows = [["capability", "what it is", *RUNS]]
    for capability in CAPABILITIES:
        marks = ("yes" if run in capability.honoured else "refused" for run in RUNS)
        rows.append([capability.name, capability.describes, *marks])
    return rows


__all__ = [
    "CAPABILITIES",
    "CAPABILITY",
    "COMMANDS",
    "COMMAND_RUNS",
    "RUNS",
    "SET_BY_RUN",
    "refusal",
    "refusals",
]
