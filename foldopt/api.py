"""foldopt's Python interface: build a study, run it, sweep it, map it, write its folder.

Everything the command line does goes through these functions; a notebook gets pandas objects in
pvlib's conventions (tz-aware time indexes, tidy tables) and matplotlib Axes.

Examples
--------
>>> import foldopt
>>> study = foldopt.default_study()            # Shin et al.'s pole camera (configs/shin2015.yaml)
>>> result = foldopt.run(study)
>>> round(result.optimal_fold_angle, 1)                 # Shin et al.: 28.5 deg
28.5
>>> float(result.summary.set_index("design").loc["flat", "t_solar_h"].round(2))   # the paper's 7.73 h
7.73
>>> table = foldopt.sweep(study, latitude=[0, 20, 40]).table
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from foldopt.inputs.study_file import default_study_path
from foldopt.inputs.plan import Plan, load_plan
from foldopt.inputs.study import Study
from foldopt.errors import ConfigError
from foldopt.names import DEFAULT_ENGINE


def default_study() -> Study:
    """The embedded study: Shin et al.'s pole camera in Los Angeles on the 2014 autumn equinox
    (``configs/shin2015.yaml``; paper mode, ideal PV model, switching).

    Returns
    -------
    Study
    """
    return load_plan(default_study_path()).base


def load_study(path: str | Path) -> Study | Plan:
    """Read a YAML study (see ``configs/``).

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    Study or Plan
        The study, or a :class:`foldopt.inputs.plan.Plan` where the file sweeps fields (lists, ranges,
        a ``sweep:`` section, a year of dates).

    Raises
    ------
    foldopt.ConfigError
        One ``field: problem`` line per fault, with the YAML line.
    """
    plan = load_plan(path)
    return plan if plan.axes else plan.base


def run(
    study: Study | Plan | str | Path | None = None,
    engine: str = DEFAULT_ENGINE,
    progress: Callable[[float, int], None] | None = None,
    request=None,
):
    """Run a study: one case (every fold angle, the paper's heuristic, flat and trackers) or a plan
    of many cases.

    Parameters
    ----------
    study : Study, Plan, str or pathlib.Path
        A study, a plan, or a YAML file holding either; not with ``request``.
    engine : {'auto', 'numba', 'numpy'}
        :data:`foldopt.names.ENGINES`: by the size of each evaluation (``auto``), the compiled
        kernel, or the NumPy reference path it is tested against.
    progress : callable, optional
        For a plan: ``progress(done, total)`` in days.
    request : foldopt.studies.request.Request, optional
        A request made already (:func:`foldopt.studies.request.make_request`, as the command line
        makes it): its plan runs, and the answer says what it took from the study.

    Returns
    -------
    StudyResult, SweepResult or OptimizeResult
        :class:`foldopt.studies.day.StudyResult` for one case (``summary``, ``sweep``, ``timeseries``
        with a tz-aware index, ``optimal_fold_angle`` [deg]...), :class:`foldopt.studies.sweeps.SweepResult`
        for a plan (``table``: one row per case and design; ``timeseries``: every step of a study
        over many days, :mod:`foldopt.studies.series`), :class:`foldopt.studies.joint.OptimizeResult`
        for a study with an ``optimize`` section (:func:`optimize`); each with ``answer``, the
        :class:`foldopt.studies.answer.Answer` the command line prints.

    Raises
    ------
    foldopt.ConfigError
        For a study file that cannot be read, a study that cannot be run, or a section its run
        does not honour (:mod:`foldopt.capabilities`).
    """
    from foldopt.studies.request import make_request, request_engine

    if request is None:
        request = make_request("run", study)
    plan = request.plan
    engine = request_engine(engine, plan)
    if request.run == "optimize":
        from foldopt.studies.joint import optimize_plan

        return optimize_plan(plan, engine, request)
    if plan.axes or request.run == "ensemble":
        # A cloud ensemble over one day too: one fold angle over its members (a case is one member).
        from foldopt.studies.sweeps import run_plan

        return run_plan(plan, progress, engine, request)
    from foldopt.studies.day import run_study

    return run_study(plan.base, engine, request)


def sweep(
    study: Study | Plan,
    over: str | None = None,
    *,
    axes: dict | None = None,
    engine: str = DEFAULT_ENGINE,
    progress: Callable[[float, int], None] | None = None,
    **fields,
):
    """Evaluate a study at every combination of the values of some fields, as ``foldopt sweep`` does.

    The request goes through :func:`foldopt.studies.request.make_request`, as the command line's
    does, so ``foldopt.sweep(foldopt.default_study(), "latitude", latitude=[0, 20])`` and
    ``foldopt sweep latitude --lat 0,20`` give the same table to the bit: a paper-mode study given
    another site or day runs in exact mode with the hinge geometry, and a new latitude tilts the
    panel at ``|latitude|`` toward the equator, unless those fields are given.

    Parameters
    ----------
    study : Study or Plan
        A study, or a study file's plan (:func:`load_study`), whose lists the fields given replace.
    over : {'angle', 'latitude', 'day', 'load'}, optional
        A sweep's own axis, over its default range where ``fields`` leave it out (latitude
        -60:60:5, day 1:365:7, 20 loads up to the panel's rating); ``angle`` is one case.
    axes : dict, optional
        Dotted field paths to values, for any field (``{"panel.efficiency": [0.18, 0.21]}``).
    engine : {'auto', 'numba', 'numpy'}
    progress : callable, optional
        ``progress(done, total)`` in days.
    **fields
        Field names (``p_load``, ``date``, ``pv_model``...) or the short names of
        :data:`foldopt.studies.request.KEYWORDS` (``latitude``, ``area``, ``tilt``, ``visits``...): a
        value sets the field, a sequence or a range ``"start:stop:step"`` sweeps it; ``date``
        also takes ``"year"``, ``objective`` a statistic (``"worst-month"``); ``planes`` an
        existing array's two ``[surface_tilt, surface_azimuth]`` [deg] (``panel.planes``), and
        ``fold_angle`` one fold angle [deg], as ``--planes`` and ``--fold-angle``.

    Returns
    -------
    SweepResult or StudyResult
        As :func:`run` returns for the plan: a :class:`foldopt.studies.day.StudyResult` for one case
        (``over='angle'`` at one site, day and load, as ``foldopt sweep angle``), otherwise
        ``table``: one row per case (``site_name``, ``latitude``, ``longitude``, ``date``,
        ``dayofyear``, ``p_load_w`` and any other swept field) and design (``flat``, ``twofold``,
        ``tracker``, ``tracker-net``), with ``fold_angle_deg``, ``t_solar_h`` and the other daily
        metrics; ``answer``, the :class:`foldopt.studies.answer.Answer` every view renders. With an
        ``objective`` and several dates, one fold angle per case for all of them.

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the field (a field given twice, by a keyword and ``axes``, is one).

    Examples
    --------
    >>> import foldopt
    >>> result = foldopt.sweep(foldopt.default_study(), latitude=[0, 30], p_load=[2.0, 4.0])
    >>> len(result.table)
    16
    """
    from foldopt.studies.request import make_request

    axes = axes or {}
    if not fields and not axes and over is None:
        raise ConfigError(["sweep: name at least one field to sweep, e.g. p_load=[1, 2, 4]"])
    both = sorted(set(fields) & set(axes))
    if both:
        raise ConfigError(
            [f"{name}: given twice, as a keyword and in axes; give one" for name in both]
        )
    command = "run" if over is None else f"sweep {over}"
    request = make_request(command, study, fields={**fields, **axes})
    return run(engine=engine, progress=progress, request=request)


def optimize(
    study: Study | Plan,
    vary=None,
    *,
    fold_angle=None,
    tilt=None,
    azimuth=None,
    tolerance_h: float | None = None,
    engine: str = DEFAULT_ENGINE,
    **fields,
):
    """The best fold angle, base tilt and base azimuth together, as ``foldopt optimize`` finds them
    (:func:`foldopt.studies.joint.optimize_plan`), with the flat panel's own best tilt and azimuth,
    the default mounting and the tracker.

    The request goes through :func:`foldopt.studies.request.make_request`, as the command line's
    does, so both give the same answer to the bit.

    Parameters
    ----------
    study : Study or Plan
        A study, or a study file's plan (:func:`load_study`: its days and loads are the search's).
    vary : str or sequence of str, optional
        Of ``fold_angle``, ``tilt``, ``azimuth`` [default: all three, or the study's ``optimize.vary``].
    fold_angle, tilt, azimuth : str or sequence of float, optional
        Each variable's range, ``"min:max:step"`` or ``(min, max, step)`` [deg]; defaults: the
        study's fold angles, tilt 0:90:1, azimuth the equator-facing one +-90 by 2.
    tolerance_h : float, optional
        What the search may miss [h] (default 0.01).
    engine : {'auto', 'numba', 'numpy'}
    **fields
        As :func:`sweep`'s: ``date="year"`` and ``objective="worst-month"`` take the objective over
        the days, ``p_load=[1, 2, 4]`` several loads.

    Returns
    -------
    foldopt.studies.joint.OptimizeResult
        ``table`` per load and design (``twofold``, ``flat``, ``twofold-default``, ``flat-default``,
        ``tracker``, ``tracker-net``), ``near_optimal``, ``added``, ``landscape``, ``answer``.

    Raises
    ------
    foldopt.ConfigError
        One line per fault, naming the parameter or the field.

    Examples
    --------
    >>> import foldopt
    >>> result = foldopt.optimize(foldopt.default_study(), vary="fold_angle,tilt", mode="exact", step_min=10)
    >>> best = result.table.set_index("design").loc["twofold"]
    >>> float(best["fold_angle_deg"]), float(best["surface_tilt"])
    (36.0, 32.0)
    """
    from foldopt.studies.request import make_request

    search = {
        "vary": vary,
        "fold_angle": fold_angle,
        "tilt": tilt,
        "azimuth": azimuth,
        "tolerance_h": tolerance_h,
    }
    request = make_request(
        "optimize",
        study,
        fields=fields,
        optimize={name: value for name, value in search.items() if value is not None},
    )
    return run(engine=engine, request=request)


def write(
    result, out: str | Path, overwrite: bool = False, command: list[str] | None = None
) -> Path:
    """Write a result's folder as the command line does: CSV tables, figures, ``report.html`` and
    ``run.json``, atomically (a folder that exists is replaced only with ``overwrite``).

    Parameters
    ----------
    result : StudyResult, SweepResult, SizingResult, Reproduction or OptimizeResult
        What :func:`run`, :func:`sweep`, :func:`size`, :func:`reproduce` or :func:`optimize` returned.
    out : str or pathlib.Path
        The results folder.
    overwrite : bool, default False
        Replace an existing folder (only one foldopt wrote).
    command : list of str, optional
        What ``run.json`` records as the command.

    Returns
    -------
    pathlib.Path
        The folder written.

    Raises
    ------
    OutputExistsError
        If ``out`` exists and ``overwrite`` is false (:mod:`foldopt.errors`).
    OutputError
        If ``out`` cannot be written there, is not foldopt's to replace, or the disk fills.
    """
    from foldopt.output.folders import write_reproduction, write_sizing, write_study, write_sweep
    from foldopt.studies.reproduce import Reproduction
    from foldopt.studies.sizing import SizingResult
    from foldopt.studies.day import StudyResult

    from foldopt.output.folders import write_optimize
    from foldopt.studies.joint import OptimizeResult

    writers = {
        StudyResult: write_study,
        SizingResult: write_sizing,
        Reproduction: write_reproduction,
        OptimizeResult: write_optimize,
    }
    writer = writers.get(type(result), write_sweep)
    writer(result, Path(out), overwrite, command if command is not None else ["foldopt.write"])
    return Path(out)


def size(
    study: Study | None = None,
    areas="0.01:0.5:0.005",
    cost_per_m2: float | None = None,
    cost_per_w: float | None = None,
    c_grid: float | None = None,
    years: float | None = None,
    days_per_year: float | None = None,
    request=None,
):
    """Shin et al. Sec. IV-A panel sizing: the lifetime net benefit of flat and twofold panels of
    every area (:func:`foldopt.studies.sizing.size_panel`).

    Parameters
    ----------
    study : Study, optional
        One case: its site, day and load; not with ``request``.
    areas : array_like or str
        Panel areas [m^2], or a range ``"start:stop:step"``.
    cost_per_m2, cost_per_w : float, optional
        Panel cost [$ per m^2] or [$ per W at STC], at most one; default
        :data:`foldopt.inputs.costs.PAPER_COST_PER_M2` (what Shin et al.'s 0.108 m^2 optimum implies).
    c_grid : float, optional
        Grid energy price [$/kWh]; default :data:`foldopt.inputs.costs.C_GRID` (Shin et al.: 0.22).
    years, days_per_year : float, optional
        Lifetime [years] (default Shin et al.'s 20) and days a year like the study's (365).
    request : foldopt.studies.request.Request, optional
        A ``size`` request made already (:func:`foldopt.studies.request.make_request`, as the
        command line makes it, its costs checked): its study is sized.

    Returns
    -------
    foldopt.studies.sizing.SizingResult
        ``table`` per design and area (``area_m2``, ``fold_angle_deg``, ``t_solar_h``, benefit, cost,
        ``net_benefit_usd``), ``best`` per design, ``parameters``, ``answer``.

    Raises
    ------
    foldopt.ConfigError
        For both costs, a value that is not a finite number in (0, its limit]
        (:data:`foldopt.studies.request.SIZING_LIMITS`, as the command line's), or areas outside
        (0, 1000] m^2.
    """
    from foldopt.inputs import costs
    from foldopt.studies import sizing
    from foldopt.inputs.plan import parse_range
    from foldopt.studies.day import Day
    from foldopt.studies.request import make_request

    errors = []
    if cost_per_m2 is not None and cost_per_w is not None:
        errors.append("cost_per_m2 / cost_per_w: give one panel cost, not both")
    given = {
        "cost_per_m2": cost_per_m2,
        "cost_per_w": cost_per_w,
        "c_grid_usd_per_kwh": c_grid,
        "years": years,
        "days_per_year": days_per_year,
    }
    if request is None and not errors:
        request = make_request("size", study, costs=given)
    if cost_per_m2 is None and cost_per_w is None:
        cost_per_m2 = costs.PAPER_COST_PER_M2
    parameters = {
        **given,
        "cost_per_m2": cost_per_m2,
        "c_grid_usd_per_kwh": costs.C_GRID if c_grid is None else c_grid,
        "years": costs.LIFETIME_YEARS if years is None else years,
        "days_per_year": costs.DAYS_PER_YEAR if days_per_year is None else days_per_year,
    }
    try:
        grid = parse_range(areas) if isinstance(areas, str) else [float(a) for a in areas]
        if not grid or min(grid) <= 0 or max(grid) > 1000:
            errors.append(f"areas = {areas!r}: areas must be in (0, 1000] m^2")
    except (TypeError, ValueError) as error:
        errors.append(f"areas = {areas!r}: {error}")
    if errors:
        raise ConfigError(errors)
    study = request.plan.base
    table = sizing.size_panel(
        Day(study),
        grid,
        parameters["cost_per_m2"],
        parameters["cost_per_w"],
        parameters["c_grid_usd_per_kwh"],
        parameters["years"],
        parameters["days_per_year"],
    )
    return sizing.SizingResult(study, table, sizing.best_areas(table), parameters, request)


def reproduce(engine: str = DEFAULT_ENGINE):
    """Shin et al.'s published values beside foldopt's, in paper and exact mode.

    Parameters
    ----------
    engine : {'auto', 'numba', 'numpy'}, default 'auto'
        As :func:`run`'s.

    Returns
    -------
    foldopt.studies.reproduce.Reproduction
        ``tables``: ``reproduction`` (the embedded study, ideal PV model) and
        ``reproduction_single_diode`` (A-300 single-diode sub-panels with switching), each with
        ``quantity``, ``unit``, ``paper``, ``paper_mode``, ``exact_mode``; ``answer``.
    """
    from foldopt.studies.reproduce import REPRODUCTIONS, Reproduction, reproduce as reproduce_table

    from foldopt.studies.request import request_engine

    study = default_study()
    engine = request_engine(engine, study)
    tables = {
        name: reproduce_table(study, engine, **changes) for name, changes in REPRODUCTIONS.items()
    }
    return Reproduction(tables, study, engine)


def world_map(
    sites: Sequence[dict] | None = None,
    loads: Sequence[float] | None = None,
    out: str | Path | None = None,
    study: dict | None = None,
    relative: bool = False,
    year: int = 2025,
    *,
    request=None,
    scheduler: str | None = None,
    workers: int | None = None,
    sites_per_chunk: int = 0,
    resume: bool = False,
    overwrite: bool = False,
    engine: str = DEFAULT_ENGINE,
    show_load: int = 0,
    show_period: str = "year",
    progress=None,
    announce=None,
    command=None,
    defaults: dict | None = None,
):
    """A map of many sites on Dask (:mod:`foldopt.studies.cluster`), its world maps and its ``report.html``.

    Parameters
    ----------
    sites : sequence of dict, str or pathlib.Path
        From :func:`foldopt.grid_sites`, :func:`foldopt.read_sites` or :func:`foldopt.weather_sites`,
        or a CSV of named sites; not with ``request``.
    loads : float, sequence of float or str
        Loads [W], or with ``relative`` fractions of each site's flat peak; text is a value, a range
        ``start:stop:step`` or a list. Checked as the command line's are
        (:func:`foldopt.studies.map_request.map_request`).
    out : str or pathlib.Path
        The results folder (``map.parquet``, ``map.csv``, figures, ``report.html``, ``run.json``).
    study : dict, optional
        A map's study (:func:`foldopt.map_study`); default the embedded study's panel and models
        in exact mode (with its Ineichen clear sky).
    relative : bool
    year : int
    request : foldopt.studies.request.Request, optional
        A map's request made and checked already (the command line's,
        :func:`foldopt.studies.request.make_request`): its sites, loads, study, year and
        defaults, instead of ``sites``, ``loads``, ``study``, ``relative``, ``year`` and ``show_period``.
    scheduler : str, optional
        A Dask scheduler's address or file; default an embedded cluster of ``workers`` processes.
    sites_per_chunk : int
        Default about 5 s of work per chunk.
    resume, overwrite : bool
        Finish an interrupted map in ``out``; replace ``out``.
    engine : {'auto', 'numba', 'numpy'}
    show_load, show_period
        Which load (index) and period (``year``, ``DJF``...) the world maps show.
    progress, announce : callable, optional
        See :func:`foldopt.run_map`.
    command : list of str, optional
        What ``run.json`` records as the command.
    defaults : dict, optional
        ``{"study": source, "taken": [...]}``: what the answer says it took from the study.

    Returns
    -------
    tuple
        The :class:`foldopt.MapRun`, the figures' file names and the :class:`foldopt.studies.answer.Answer`
        (its ``designs``: the year's rows; its ``near_optimal``: each site's range and recommended
        fold angle).

    Raises
    ------
    foldopt.ConfigError
        For a bad site, load, year, period or study setting, before any cluster starts.
    """
    from dataclasses import replace

    from foldopt.studies.cluster import run_map
    from foldopt.studies.result_answers import of_map
    from foldopt.output.folders import map_figures, write_map_report
    from foldopt.output.gridded import write_grid_netcdf
    from foldopt.studies.request import make_request, request_engine
    from foldopt.studies.worldmap import searched_tilt

    if out is None:
        raise ConfigError(["out: give the map's results folder"])
    if request is None:
        fields = {"year": year, **({"p_load": loads} if loads is not None else {})}
        where = {"sites": sites, "relative": relative, "show_period": show_period}
        request = make_request("map", study, fields=fields, where=where)
    defaults = request.defaults if defaults is None else defaults
    spec = replace(
        request.plan, sites_per_chunk=sites_per_chunk, engine=request_engine(engine, None)
    )
    study, relative = spec.study, spec.relative
    finished = {}

    def finish(run, metadata):
        # In the map's folder before it is marked complete or replaces an earlier map (run_map).
        finished["figures"] = map_figures(
            run.table,
            run.out,
            "map",
            relative,
            show_load,
            show_period,
            tilt=searched_tilt(study) is not None,
        )
        write_grid_netcdf(run.table, run.out, relative, f"foldopt map: {study.name}")
        finished["answer"] = of_map(run, relative, defaults)
        write_map_report(run, finished["figures"], finished["answer"], metadata)

    result = run_map(
        spec,
        Path(out),
        scheduler=scheduler,
        workers=workers,
        resume=resume,
        overwrite=overwrite,
        progress=progress,
        announce=announce,
        metadata={"command": command or ["foldopt.world_map"]},
        finish=finish,
    )
    return result, finished["figures"], finished["answer"]
