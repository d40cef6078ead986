"""One day's study: flat, twofold and tracked panels at one site, compared.

:class:`Day` is a view of one day of a :class:`foldopt.engine.sky.Sky` (times, sun, light, the electrical
model) that gives the power of each design as arrays over fold angles x time, for reports and for
the paper's heuristic. :func:`run_study` is the day's named steps, each a function returning a
small named result: the sweep of the fold angle through the engine (:class:`FoldSweep`), the
refined optimum (:class:`Optimum`), every design evaluated once with the paper's heuristic
(:class:`Designs`, :class:`Heuristic`), the summary and its notes, the tracker's standby
(:class:`Standby`), the buffer (:class:`foldopt.studies.storage_days.DayStorage`), the
near-optimal range and the time series. The searches they call live in the modules named for
them (:mod:`foldopt.engine.optimize`, :mod:`foldopt.studies.storage_sizing`); what the answer says
of the result, in :mod:`foldopt.studies.result_answers`.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from foldopt.columnar import Columns, TimeIndex, as_frame
from foldopt.engine import evaluation as engines
from foldopt.physics.connections import CONNECTIONS, SWITCH_STATES
from foldopt.inputs.study import Study
from foldopt.engine.metrics import (
    design_condition,
    energy_served,
    load_for_t_solar,
    metric_columns,
    notes,
    per_load,
    relative_to,
    t_solar,
)
from foldopt.engine.optimize import heuristic_fold_angle, noon_valley, optimal_fold_angle
from foldopt.studies.sizing import flat_area_ratio
from foldopt.studies.designs import (
    DESIGNS,
    PLANES_DESIGN,
    Blocks,
    TrackerCurves,
    design_metrics,
    standby_available,
    tracker_curves,
)
from foldopt.studies.objectives import near_optimal
from foldopt.studies.series import half_poa, sky_columns, solar_powered
from foldopt.studies.storage_cold import sky_air_temperature
from foldopt.studies.storage_days import (
    design_columns,
    BufferedDesigns,
    DayStorage,
    day_storage,
)
from foldopt.engine.sky import build_sky
from foldopt.studies.engine_options import engine_options
from foldopt.physics.trackers import TRACKERS
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE


class Day:
    """Sun, light and electrical model over one day, and the power of each design on it.

    Paper mode uses the paper's sun, air mass at sea level and Eq. 5 incidence; exact mode pvlib's
    sun (apparent zenith), Laue's altitude term and the true angle of incidence.

    Parameters
    ----------
    study : Study
        One site and date, its files read (:func:`foldopt.inputs.study_file.with_files`).
    """

    def __init__(self, study: Study):
        self.study = study
        self.options = options = engine_options(study)
        self.sky = sky = build_sky(options.sky, [study.site], [study.date])
        self.electrical = engines.electrical_for(options.electrical, sky.temp_air[0], sky.wind_ref)
        self.step_hours = sky.step_hours
        self.solar_zenith, self.solar_azimuth = sky.solar_zenith[0], sky.solar_azimuth[0]
        self.hour_angle, self.declination = sky.hour_angle[0], sky.declination[0]
        self.sun_vector, self.dni = sky.sun_vector[0], sky.dni[0]
        self.ghi = None if sky.ghi is None else sky.ghi[0]
        self.dhi = None if sky.dhi is None else sky.dhi[0]
        self.transposition = study.sky_transposition()
        #: A load profile's shape over the day, (n_time,) (P_load(t) = p_load x shape(t)); None
        #: for a constant load.
        self.load_shape = None if sky.load_shape is None else sky.load_shape[0]
        #: The load [W]: the study's ``p_load``, or its curve under a load profile, (n_time,).
        self.load_w = study.p_load if self.load_shape is None else study.p_load * self.load_shape
        self._trackers: dict = {}
        self._one_angle: dict = {}

    @property
    def times(self):
        """The day's tz-aware step centres, a :class:`pandas.DatetimeIndex`."""
        return self.sky.grid.times(0)

    def _poa(self, surface_tilt, surface_azimuth, per_step=False):
        """Irradiance on surfaces [W/m^2]: one orientation per row, (k,) -> (k, n_time), or, with
        ``per_step``, one per time step (a tracker), (n_time,) -> (n_time,)."""
        tilt, azimuth = (
            np.asarray(surface_tilt, dtype=float),
            np.asarray(surface_azimuth, dtype=float),
        )
        if per_step:
            return engines.poa(self.sky, tilt[None], azimuth[None])[0]
        return engines.poa(
            self.sky, tilt[..., None], azimuth[..., None], [0], self.study.mode == "paper"
        )

    def flat_power(self):
        """Power of the flat panel over the day [W], shape (n_time,)."""
        panel = self.study.panel
        return engines.panel_power(
            self.sky,
            poa_global=self._poa(np.array([panel.tilt]), np.array([panel.azimuth])),
            electrical=self.options.electrical,
            area=panel.area,
        )[0]

    def tracker_orientation(self, model=None):
        """Surface tilt and azimuth of a tracker over the day.

        Parameters
        ----------
        model : str, optional
            One of :data:`foldopt.names.TRACKERS`; default the study's.

        Returns
        -------
        surface_tilt, surface_azimuth : numpy.ndarray
            [deg], (n_time,).
        """
        return tuple(angle[0] for angle in self.tracker(model).orientation[:2])

    def tracker(self, model=None) -> TrackerCurves:
        """A tracker's orientation, power and own draw over the day, worked out once per model: the
        summary's rows, the standby sweep and the figures all take them from here.

        Parameters
        ----------
        model : str, optional
            One of :data:`foldopt.names.TRACKERS`; default the study's.
        """
        model = model or self.study.tracker.model
        if model not in self._trackers:
            self._trackers[model] = tracker_curves(self.sky, self.study, model)
        return self._trackers[model]

    def tracker_power(self, model=None):
        """Power of the same panel on a tracker [W], shape (n_time,).

        Parameters
        ----------
        model : str, optional
            One of :data:`foldopt.names.TRACKERS`; default the study's.
        """
        return self.tracker(model).power[0]

    def tracker_draw(self, model=None):
        """The tracker's own draw [W] per step, (n_time,): standby while the sun is up, plus its moves.

        Parameters
        ----------
        model : str, optional
            One of :data:`foldopt.names.TRACKERS`; default the study's.
        """
        return self.tracker(model).draw[0]

    def orientation(self, fold_angles):
        """Sub-panel orientations of the study's panel at fold angles.

        Parameters
        ----------
        fold_angles : array_like
            (k,) [deg].

        Returns
        -------
        numpy.ndarray
            (k, 4): tilt and azimuth of the east, then the west sub-panel [deg].
        """
        panel = self.study.panel
        return engines.fold_orientations(
            self.study.geometry, [panel.tilt], [panel.azimuth], np.atleast_1d(fold_angles)
        )[0]

    def connections(self, fold_angles, series: bool = True, with_state: bool = True):
        """Every connection's power and the switching state per step.

        Parameters
        ----------
        fold_angles : array_like
            (k,) [deg].
        series : bool, default True
            False skips the series connection (NaN) when nothing asks for it.
        with_state : bool, default True
            Whether to work out the switching state.

        Returns
        -------
        powers : dict of numpy.ndarray
            (k, n_time) [W] per name of :data:`foldopt.names.CONNECTIONS`.
        state : numpy.ndarray of int or None
            (k, n_time) index into :data:`foldopt.physics.connections.SWITCH_STATES`.
        """
        fold_angles = np.atleast_1d(np.asarray(fold_angles, dtype=float))
        key = (fold_angles.tobytes(), series, with_state)
        if key in self._one_angle:
            return self._one_angle[key]
        powers, state = engines.powers(
            self.sky,
            orientation=self.orientation(fold_angles),
            electrical=self.options.electrical,
            blocks=[0],
            series=series,
            with_state=with_state,
        )
        powers.pop("panel")
        if fold_angles.size == 1:
            # One angle's curves are kept: the heuristic's root search evaluates its bracket twice
            # and ends on its angle, whose curve the summary's row then takes.
            self._one_angle[key] = powers, state
        return powers, state

    def subpanel_power(self, fold_angles):
        """East and west sub-panel powers and their parallel connection [W], each (k, n_time).

        Parameters
        ----------
        fold_angles : array_like
            (k,) [deg].
        """
        powers, _ = self.connections(fold_angles, series=False, with_state=False)
        return powers["east"], powers["west"], powers["parallel"]

    def combined_power(self, fold_angles, connection=None):
        """Deliverable twofold power [W], (k, n_time).

        Parameters
        ----------
        fold_angles : array_like
            (k,) [deg].
        connection : str, optional
            One of :data:`foldopt.names.CONNECTIONS`; default the study's.
        """
        connection = connection or self.study.connection
        series = connection == "series" or self.study.switch_series
        return self.connections(fold_angles, series, with_state=False)[0][connection]


class Standby(NamedTuple):
    """The study's tracker's net ``t_solar`` as its standby draw grows (:func:`standby_sweep`).

    Attributes
    ----------
    table : foldopt.columnar.Columns or pandas.DataFrame
        ``standby_w``, ``t_solar_tracker_net_h``, ``t_solar_twofold_h``: the day's steps hold
        :class:`~foldopt.columnar.Columns`, :attr:`StudyResult.standby` a DataFrame.
    break_even_w : float
        Standby draw [W] above which the twofold panel runs longer; NaN if it never does.
    """

    table: object
    break_even_w: float


@dataclass(frozen=True)
class StudyResult:
    """One study's results (:func:`foldopt.run`).

    The day's tables are held as :class:`foldopt.columnar.Columns` (``sweep_columns``,
    ``summary_columns``, ``timeseries_columns``, ``standby_columns``), which the answer reads
    without pandas; ``sweep``, ``summary``, ``timeseries`` and ``standby`` are them as pandas
    objects, made on first use (the folder's writers, the figures, a user of the API).

    Attributes
    ----------
    study : Study
    day : Day
        The day's sun, light and models.
    sweep : pandas.DataFrame
        Per fold angle of the grid: ``fold_angle_deg``, t_solar [h] and energy [Wh] of every connection.
    summary : pandas.DataFrame
        Per design (``flat``, ``twofold``, ``twofold-heuristic``, ``tracker``, ``tracker-net``...):
        ``fold_angle_deg``, ``t_solar_h``, ``t_solar_contiguous_h``, ``energy_harvested_wh``, ``peak_power_w``,
        ``gain_vs_flat_pct``, ``share_of_tracker_pct``, ``flat_area_ratio``, ``note``.
    timeseries : pandas.DataFrame
        Indexed by the day's tz-aware step centres (``time``): sun [deg], ``dni`` [W/m^2], the power
        [W] of every design at the optimum and the ``switch_state``.
    optimal_fold_angle, heuristic_fold_angle : float
        [deg]; the heuristic is NaN where the paper's rule has no angle among the study's fold
        angles (:func:`foldopt.engine.optimize.heuristic_fold_angle`).
    heuristic_outside : str
        Where the rule's angle lies then: ``below`` the study's first fold angle (its noon valley
        reaches the load even there) or ``above`` its last; ``""`` where the angle is stated.
    near_optimal : dict
        The near-optimal range of the fold angle over the angles evaluated (the sweep's grid and the
        refined optimum, which it always holds) and the recommended angle at its centre
        (:func:`foldopt.studies.objectives.near_optimal`) [deg], its tolerance [h] and the
        recommended angle's ``recommended_t_solar_h`` [h].
    storage : foldopt.studies.storage_days.DayStorage or None
        With the study's ``storage``: the load's powered time with the buffer per design and fold
        angle, and each design's buffer for its target; None for a storage-less study.
    standby : Standby
        :func:`standby_sweep`.
    engine : str
    """

    study: Study
    day: Day
    sweep_columns: Columns
    summary_columns: Columns
    timeseries_columns: Columns
    optimal_fold_angle: float
    heuristic_fold_angle: float
    standby_columns: Standby
    engine: str = DEFAULT_ENGINE
    near_optimal: dict = dataclasses.field(default_factory=dict)
    request: object = None  # the foldopt.studies.request.Request the study came from, if any
    storage: object = None  # the buffer's DayStorage (foldopt.studies.storage_days), if any
    heuristic_outside: str = ""  # where the heuristic's angle lies off the study's fold angles

    @functools.cached_property
    def sweep(self):
        """pandas.DataFrame: the sweep's table (the class's Attributes)."""
        return self.sweep_columns.to_frame()

    @functools.cached_property
    def summary(self):
        """pandas.DataFrame: the summary's table (the class's Attributes)."""
        return self.summary_columns.to_frame()

    @functools.cached_property
    def timeseries(self):
        """pandas.DataFrame: the time series (the class's Attributes)."""
        return self.timeseries_columns.to_frame()

    @functools.cached_property
    def standby(self) -> Standby:
        """The tracker's standby, its table a pandas.DataFrame (the class's Attributes)."""
        table, break_even = self.standby_columns
        return Standby(as_frame(table), break_even)

    @functools.cached_property
    def answer(self):
        """The :class:`foldopt.studies.answer.Answer` every view of this result renders."""
        from foldopt.studies.result_answers import of_study

        return of_study(self)


def run_study(study: Study, engine: str = DEFAULT_ENGINE, request=None) -> StudyResult:
    """Sweep the fold angle and compare flat, twofold and tracker, in the day's named steps.

    :func:`sweep_fold_angles` -> :func:`refine_optimum` -> :func:`compare_designs` (with
    :func:`paper_heuristic`) -> :func:`summarise` -> :func:`standby_sweep` -> :func:`buffer_designs`
    (with a ``storage`` section) -> :func:`near_optimal_range` -> :func:`day_timeseries`.

    Parameters
    ----------
    study : Study
        One site and date.
    engine : {'auto', 'numba', 'numpy'}
        Evaluates the fold-angle sweep (:data:`foldopt.names.ENGINES`).
    request : Request, optional
        The :class:`foldopt.studies.request.Request` the study came from, kept on the result.

    Returns
    -------
    StudyResult
        ``sweep``: metrics per fold angle for the study's connection, ``t_solar`` and energy for
        every connection, and the noon valley of the parallel curve. ``summary``: one row per
        design: ``flat``; ``twofold`` at the sweep's optimum; ``twofold-heuristic`` at the paper's
        angle; with I-V models, ``twofold-<connection>`` for each other connection at its own
        optimum; ``tracker``. ``timeseries``: the day's curves at the optimum, with the state
        switching chose.
    """
    day = Day(study)
    sweep = sweep_fold_angles(day, engine)
    optimum = refine_optimum(day, sweep, day.study.connection)
    designs = compare_designs(day, sweep, optimum, engine)
    summary = summarise(day, designs)
    twofold = summary.row("design", "twofold")["t_solar_h"]
    standby = standby_sweep(day, designs.tracker.power[0], twofold)
    buffered = None
    table = sweep.table
    if day.study.storage is not None:
        buffered = buffer_designs(day, sweep, designs, summary, engine)
        columns = design_columns(buffered.designs)
        summary = summary.join(Columns({c: buffered.designs[c].to_numpy() for c in columns}))
        table = table.assign(powered_h=buffered.powered_by_angle)
    return StudyResult(
        study=day.study,
        day=day,
        sweep_columns=table,
        summary_columns=summary,
        timeseries_columns=day_timeseries(day, optimum, designs, buffered),
        optimal_fold_angle=optimum.fold_angle_deg,
        heuristic_fold_angle=designs.heuristic.fold_angle_deg,
        standby_columns=standby,
        engine=engine,
        near_optimal=near_optimal_range(day, sweep, optimum),
        request=request,
        storage=buffered,
        heuristic_outside=designs.heuristic.outside,
    )


class FoldSweep(NamedTuple):
    """The twofold panel at every fold angle of the study's grid (:func:`sweep_fold_angles`).

    Attributes
    ----------
    fold_angles : numpy.ndarray
        The grid [deg], (k,), ascending.
    table : foldopt.columnar.Columns
        ``sweep.csv``: the metrics of the study's connection, every connection's t_solar and
        energy, and the noon valley of the parallel curve, per fold angle.
    t_solar_h : dict
        Connection of :data:`foldopt.physics.connections.CONNECTIONS` -> t_solar [h], (k,).
    curves : dict
        ``east``, ``west`` and each connection -> power [W], (k, n_time) (:meth:`Day.connections`);
        the series connection NaN where :attr:`series` is False.
    series : bool
        Whether ``curves`` hold the series connection (a load profile's served energy of a
        series-wired study needs it).
    """

    fold_angles: np.ndarray
    table: Columns
    t_solar_h: dict
    curves: dict
    series: bool


def sweep_fold_angles(day: Day, engine: str) -> FoldSweep:
    """The study's fold-angle grid through the engine, every connection at once.

    Parameters
    ----------
    day : Day
    engine : {'auto', 'numba', 'numpy'}

    Returns
    -------
    FoldSweep
    """
    study = day.study
    p_load, shape = study.p_load, day.load_shape
    fold_angles = np.asarray(study.fold_angles.grid())
    metrics = engines.row_metrics(
        day.sky,
        rows=engines.PanelRows(np.zeros(fold_angles.size), day.orientation(fold_angles)),
        loads=[p_load],
        electrical=day.options.electrical,
        outputs=CONNECTIONS,
        contiguous=True,
        engine=engine,
    )
    own = CONNECTIONS.index(study.connection)
    # The grid's curves, once: the noon valley's sub-panels and, under a load profile, the served
    # energy's connection (curves the metrics above do not keep).
    series = shape is not None and (study.connection == "series" or study.switch_series)
    curves, _ = day.connections(fold_angles, series, with_state=False)
    served = (
        None
        if shape is None
        else energy_served(
            curves[study.connection], p_load, shape, day.step_hours, metrics.t_solar[:, own, 0]
        )
    )
    table = Columns(
        {
            "fold_angle_deg": fold_angles,
            **metric_columns(
                metrics.t_solar[:, own, 0],
                metrics.t_solar_contiguous[:, own, 0],
                metrics.energy[:, own],
                metrics.peak[:, own],
                p_load,
                served,
            ),
            "noon_valley_w": noon_valley(curves["east"], curves["west"], curves["parallel"]),
            **{
                name: values
                for index, connection in enumerate(CONNECTIONS)
                for name, values in (
                    (f"t_solar_{connection}_h", metrics.t_solar[:, index, 0]),
                    (f"energy_harvested_{connection}_wh", metrics.energy[:, index]),
                )
            },
        }
    )
    t_solar_h = {connection: metrics.t_solar[:, i, 0] for i, connection in enumerate(CONNECTIONS)}
    return FoldSweep(fold_angles, table, t_solar_h, curves, series)


class Optimum(NamedTuple):
    """A connection's best fold angle (:func:`refine_optimum`).

    Attributes
    ----------
    fold_angle_deg : float
        [deg]: the sweep's best, or a better angle between its neighbours.
    t_solar_h : float
        [h].
    power : numpy.ndarray
        The connection's power at the angle [W], (n_time,): the refinement's curve where the angle
        is one of the refinement's.
    """

    fold_angle_deg: float
    t_solar_h: float
    power: np.ndarray


def refine_optimum(day: Day, sweep: FoldSweep, connection: str) -> Optimum:
    """A connection's best fold angle, the sweep's best refined between its neighbours
    (:func:`foldopt.engine.optimize.optimal_fold_angle`).

    Parameters
    ----------
    day : Day
    sweep : FoldSweep
    connection : str
        One of :data:`foldopt.names.CONNECTIONS`.

    Returns
    -------
    Optimum
    """
    evaluated = {}

    def compared(fold):
        power = day.combined_power(fold, connection)
        evaluated.update(zip(fold.tolist(), power))
        return per_load(power, day.load_shape)

    angle, hours = optimal_fold_angle(
        compared,
        sweep.fold_angles,
        sweep.t_solar_h[connection],
        day.study.p_load,
        day.step_hours,
    )
    power = evaluated.get(angle)
    if power is None:
        power = day.combined_power(np.array([angle]), connection)[0]
    return Optimum(angle, hours, power)


class Heuristic(NamedTuple):
    """The paper's fold angle (:func:`paper_heuristic`).

    Attributes
    ----------
    fold_angle_deg : float
        [deg]; NaN where the rule's angle lies outside the study's fold angles.
    outside : str
        Where it lies then: ``below`` the first fold angle or ``above`` the last; ``""`` else.
    """

    fold_angle_deg: float
    outside: str


def paper_heuristic(day: Day, sweep: FoldSweep, p_flat) -> Heuristic:
    """The paper's rule (Eq. 8): the fold angle whose parallel curve's noon valley meets the load,
    among the study's fold angles (:func:`foldopt.engine.optimize.heuristic_fold_angle`).

    Parameters
    ----------
    day : Day
    sweep : FoldSweep
    p_flat : numpy.ndarray
        The flat panel's power [W], (n_time,): under a load profile its peak is solar noon, whose
        load the valley is set to.

    Returns
    -------
    Heuristic
    """
    p_load, shape = day.study.p_load, day.load_shape
    noon_load = p_load if shape is None else p_load * shape[int(np.argmax(p_flat))]
    fold_angles, curves = sweep.fold_angles, sweep.curves

    def subpanels(fold):
        # An angle of the grid (the root search's bracket) from the grid's curves.
        at = np.flatnonzero(fold_angles == fold[0]) if fold.size == 1 else []
        return (
            tuple(curves[name][at[:1]] for name in ("east", "west", "parallel"))
            if len(at)
            else day.subpanel_power(fold)
        )

    # The rule's angle among the study's fold angles: one outside them is no design of the study.
    angle, outside = heuristic_fold_angle(
        subpanels, noon_load, lo=fold_angles[0], hi=fold_angles[-1]
    )
    return Heuristic(angle, outside)


class Designs(NamedTuple):
    """Every design a day compares, evaluated once (:func:`compare_designs`).

    Attributes
    ----------
    table : foldopt.columnar.Columns
        One row per design as the report shows them (flat, the twofold panels, the trackers):
        ``design``, ``fold_angle_deg`` and :func:`foldopt.engine.metrics.metric_columns`.
    power : dict
        Design -> its power [W], (n_time,); a net tracker's net of its own draw.
    at_optimum : dict
        Connection of :data:`foldopt.physics.connections.CONNECTIONS` -> the twofold panel's power
        at the optimum [W], (n_time,).
    tracker : foldopt.studies.designs.TrackerCurves
        The study's tracker.
    heuristic : Heuristic
    """

    table: Columns
    power: dict
    at_optimum: dict
    tracker: TrackerCurves
    heuristic: Heuristic


def compare_designs(day: Day, sweep: FoldSweep, optimum: Optimum, engine: str) -> Designs:
    """Every design at its angle: flat, twofold at the optimum and the trackers gross and
    net (:func:`foldopt.studies.designs.design_metrics`, as for sweeps, annual studies and maps),
    the paper's heuristic, each other connection at its own optimum and every other tracker.

    Parameters
    ----------
    day : Day
    sweep : FoldSweep
    optimum : Optimum
        The study's connection's.
    engine : {'auto', 'numba', 'numpy'}

    Returns
    -------
    Designs
    """
    study, shape = day.study, day.load_shape
    p_load, step = study.p_load, day.step_hours
    # The study's tracker from the curve the figures draw; the figures and the time series draw
    # the curves the flat and twofold rows were reduced from.
    tracker = day.tracker()
    main = design_metrics(
        day.sky,
        Blocks.of([study]),
        np.array([p_load]),
        np.array([optimum.fold_angle_deg]),
        np.zeros((1, 1), dtype=int),
        engine,
        tracker,
        curves=True,
    )
    drawn = main.pop("curves")
    heuristic = paper_heuristic(day, sweep, drawn["flat"][0])
    others = _other_designs(day, sweep, heuristic)
    stacked = np.stack([power for _, power in others.values()])
    curve = engines.curve_metrics(
        stacked, [p_load], step, contiguous=True, engine=engine, load_shape=shape
    )
    served = (
        None
        if shape is None
        else energy_served(stacked, p_load, shape, step, curve.t_solar[:, 0, 0])
    )
    columns = metric_columns(
        curve.t_solar[:, 0, 0],
        curve.t_solar_contiguous[:, 0, 0],
        curve.energy[:, 0],
        curve.peak[:, 0],
        p_load,
        served,
    )
    # The rows as the report shows them: flat, the twofold panels, then the trackers.
    angle_of = {
        "flat": FLAT_FOLD_ANGLE,
        "twofold": optimum.fold_angle_deg,
        **{name: angle for name, (angle, _) in others.items() if name.startswith("twofold")},
        "tracker": np.nan,
        "tracker-net": np.nan,
        **{name: angle for name, (angle, _) in others.items() if name.startswith("tracker")},
    }
    order = [[*DESIGNS, *others].index(name) for name in angle_of]
    table = Columns(
        {
            "design": np.array(list(angle_of), dtype=object),
            "fold_angle_deg": list(angle_of.values()),
            **{
                name: np.concatenate([main[name][0, 0], values])[order]
                for name, values in columns.items()
            },
        }
    )
    at_optimum = {connection: drawn[connection][0, 0] for connection in CONNECTIONS}
    power = {
        "flat": drawn["flat"][0],
        "twofold": at_optimum[study.connection],
        "tracker": tracker.power[0],
        "tracker-net": tracker.net[0],
        **{name: power for name, (_, power) in others.items()},
    }
    return Designs(table, power, at_optimum, tracker, heuristic)


def _other_designs(day: Day, sweep: FoldSweep, heuristic: Heuristic) -> dict:
    """The designs :func:`foldopt.studies.designs.design_metrics` leaves out: name -> (fold angle
    [deg], NaN for a tracker; power [W], (n_time,)): the paper's heuristic, the planes of an
    existing array as they stand (:data:`PLANES_DESIGN`), with I-V models each
    other connection at its own optimum, and every other tracker model as ``tracker:<model>``,
    gross and net of its own draw."""
    study = day.study
    others = {}
    if np.isfinite(heuristic.fold_angle_deg):
        angle = heuristic.fold_angle_deg
        others["twofold-heuristic"] = (angle, day.combined_power(np.array([angle]))[0])
    planes = study.planes_design()
    if planes is not None:  # the existing array's planes, as they stand
        angle = planes["fold_angle"]
        others[PLANES_DESIGN] = (angle, day.combined_power(np.array([angle]))[0])
    if day.electrical.pv.has_iv:
        for connection in ("parallel", "series", "independent", "switching"):
            if connection != study.connection:
                best = refine_optimum(day, sweep, connection)
                others[f"twofold-{connection}"] = (best.fold_angle_deg, best.power)
    for model in (m for m in TRACKERS if m != study.tracker.model):
        others[f"tracker:{model}"] = (np.nan, day.tracker(model).power[0])
        others[f"tracker:{model}-net"] = (np.nan, day.tracker(model).net[0])
    return others


def summarise(day: Day, designs: Designs) -> Columns:
    """The day's summary: each design against flat and the tracker, the flat panel's area
    that would run the load as long, and each row's note.

    Parameters
    ----------
    day : Day
    designs : Designs

    Returns
    -------
    foldopt.columnar.Columns
        ``designs.table`` with ``gain_vs_flat_pct``, ``share_of_tracker_pct``, ``flat_area_ratio``
        (NaN under a load profile: it is defined for a constant load) and ``note``.
    """
    study, table = day.study, designs.table
    hours = table["t_solar_h"]
    flat_hours = table.row("design", "flat")["t_solar_h"]
    tracker_hours = table.row("design", "tracker")["t_solar_h"]
    # Each row's circuit first: a connection the study's circuit cannot wire (independent's
    # converters, a load wired directly) is compared as it is built and says so; every other design
    # is wired as the circuit says, and says so where its load is beyond the panel's reach.
    wired = {
        f"twofold-{connection}": study.circuit.ignored_by(connection) for connection in CONNECTIONS
    }
    sky = day.sky.conditions()[0]
    condition = [
        "; ".join(filter(None, (wired.get(design) or day.electrical.beyond_reach, sky)))
        for design in table["design"]
    ]
    return table.assign(
        gain_vs_flat_pct=(relative_to(hours, flat_hours) - 1.0) * 100.0,
        share_of_tracker_pct=relative_to(hours, tracker_hours) * 100.0,
        flat_area_ratio=np.array(
            [
                flat_area_ratio(designs.power["flat"], study.p_load, row_hours, day.step_hours)
                if row_hours > 0 and day.load_shape is None
                else np.nan
                for row_hours in hours
            ],
            dtype=float,
        ),
        note=notes(design_condition(condition, table["energy_harvested_wh"].astype(float)), hours),
    )


def standby_sweep(day: Day, p_tracker, twofold_t_solar: float, points: int = 101) -> Standby:
    """The study's tracker's net ``t_solar`` as its standby draw grows, and the break-even draw.

    A standby draw ``s`` while the sun is up leaves the load ``P_pv - drive - s``; over daylight
    that is the gross curve less its drive against the load ``P_load + s``, so every draw is one
    load of a single ``t_solar`` pass, and the break-even draw, where the tracker's net time falls
    to the optimal twofold panel's, is one root search for the load.

    Parameters
    ----------
    day : Day
    p_tracker : array_like
        The tracker's gross power over the day [W].
    twofold_t_solar : float
        ``t_solar`` of the optimal twofold panel [h].
    points : int, default 101
        Standby draws from 0 to twice the load.

    Returns
    -------
    Standby
    """
    study, step = day.study, day.step_hours
    if day.load_shape is not None:  # a standby draw is a load shift only for a constant load
        return Standby(
            Columns(
                {
                    "standby_w": [0.0],
                    "t_solar_tracker_net_h": [np.nan],
                    "t_solar_twofold_h": [twofold_t_solar],
                }
            ),
            float("nan"),
        )
    available = standby_available(
        p_tracker, day.tracker_draw(), day.sky.lit[0], study.tracker.standby_w
    )
    draws = np.linspace(0.0, max(2.0 * study.p_load, 1e-3), points)
    hours = t_solar(available, study.p_load + draws, step)
    load = load_for_t_solar(available, twofold_t_solar, step) if twofold_t_solar > 0 else np.nan
    break_even = max(load - study.p_load, 0.0) if np.isfinite(load) else float("nan")
    table = Columns(
        {"standby_w": draws, "t_solar_tracker_net_h": hours, "t_solar_twofold_h": twofold_t_solar}
    )
    return Standby(table, break_even)


def buffer_designs(
    day: Day, sweep: FoldSweep, designs: Designs, summary: Columns, engine: str
) -> DayStorage:
    """With the study's ``storage``: every row's curve, the one its t_solar was reduced from,
    and the twofold panel at every angle of the grid through the study's buffer
    (:func:`foldopt.studies.storage_days.day_storage`); a net tracker's whole power, with its own
    draw a load beside the device's.

    Parameters
    ----------
    day : Day
    sweep : FoldSweep
    designs : Designs
    summary : foldopt.columnar.Columns
        :func:`summarise`'s: each row's fold angle and t_solar without the buffer.
    engine : {'auto', 'numba', 'numpy'}

    Returns
    -------
    foldopt.studies.storage_days.DayStorage
    """
    study = day.study
    nets = {
        "tracker-net": designs.tracker,
        **{f"tracker:{m}-net": day.tracker(m) for m in TRACKERS if m != study.tracker.model},
    }
    power = {**designs.power, **{name: net.power[0] for name, net in nets.items()}}
    own_series = study.connection == "series" or study.switch_series
    return day_storage(
        study,
        BufferedDesigns(
            fold_angle_deg=dict(zip(summary["design"], summary["fold_angle_deg"], strict=True)),
            power={name: power[name] for name in summary["design"]},
            t_solar_h=summary["t_solar_h"],
            draws={name: net.draw[0] for name, net in nets.items()},
        ),
        fold_angles=sweep.fold_angles,
        grid_power=(
            sweep.curves[study.connection]
            if sweep.series or not own_series
            else day.combined_power(sweep.fold_angles)
        ),
        load=day.load_w if day.load_shape is None else day.load_w[None, :],
        step_hours=day.step_hours,
        engine=engine,
        temp_air=sky_air_temperature(day.sky)[0],
    )


def near_optimal_range(day: Day, sweep: FoldSweep, optimum: Optimum) -> dict:
    """The near-optimal range of the fold angle and the recommended angle at its centre,
    over every angle evaluated: the grid's and the refined optimum, so that it holds the best
    angle (the grid's own range may end on the far side of a refined optimum).

    Parameters
    ----------
    day : Day
    sweep : FoldSweep
    optimum : Optimum

    Returns
    -------
    dict
        :func:`foldopt.studies.objectives.near_optimal`'s [deg] and [h], as floats, and the
        recommended angle's ``recommended_t_solar_h`` [h].
    """
    best = optimum.fold_angle_deg
    others = sweep.fold_angles != best
    angles = np.append(sweep.fold_angles[others], best)
    hours = np.append(sweep.t_solar_h[day.study.connection][others], optimum.t_solar_h)
    order = np.argsort(angles)
    angles, hours = angles[order], hours[order]
    near = {
        key: float(value)
        for key, value in near_optimal(angles, hours, day.study.near_optimal).items()
    }
    recommended = near["recommended_deg"]
    near["recommended_t_solar_h"] = (
        float(hours[angles == recommended][0]) if recommended == recommended else float("nan")
    )
    return near


def day_timeseries(
    day: Day, optimum: Optimum, designs: Designs, buffered: DayStorage | None
) -> Columns:
    """Step 8: ``timeseries.csv``: the day's sun, light and air, each half's plane-of-array
    irradiance at the optimum, the curves of flat, every connection at the optimum and the
    tracker, with the state switching chose (no table's number comes from it: it is the
    reference path's), whether each design runs the load, and the buffer's state of charge
    (:mod:`foldopt.studies.series`).

    Parameters
    ----------
    day : Day
    optimum : Optimum
    designs : Designs
    buffered : foldopt.studies.storage_days.DayStorage or None

    Returns
    -------
    foldopt.columnar.Columns
        Indexed by the day's tz-aware step centres (``time``).
    """
    at_best = designs.at_optimum
    state = day.connections(np.array([optimum.fold_angle_deg]))[1][0]
    sky, load, shape = day.sky, day.study.p_load, day.load_shape
    powered = {"flat": designs.power["flat"], "twofold": at_best[day.study.connection]}
    powered["tracker"] = designs.tracker.power[0]
    return Columns(
        {
            **{name: values[0] for name, values in sky_columns(sky).items()},
            **{
                name: values[0]
                for name, values in half_poa(sky, day.orientation([optimum.fold_angle_deg])).items()
            },
            "p_flat_w": designs.power["flat"],
            **{f"p_{connection}_w": at_best[connection] for connection in CONNECTIONS},
            "p_twofold_w": powered["twofold"],
            "switch_state": np.where(
                at_best["switching"] > 0, np.array(SWITCH_STATES)[state], "off"
            ),
            "p_tracker_w": powered["tracker"],
            "p_load_w": day.load_w,
            **{
                f"solar_powered_{design}": solar_powered(power, load, shape)
                for design, power in powered.items()
            },
            **(
                {}
                if buffered is None
                else {f"soc_{name}_frac": soc for name, soc in buffered.soc.items()}
            ),
        },
        index=TimeIndex(sky.grid.utc_ns[0], sky.grid.timezones[0], name="time"),
    )


def twofold_t_solar(day: Day, fold_angle: float, connection=None) -> float:
    """``t_solar`` [h] of the twofold panel at one fold angle.

    Parameters
    ----------
    day : Day
    fold_angle : float
        [deg].
    connection : str, optional
        One of :data:`foldopt.names.CONNECTIONS`; default the study's.
    """
    power = day.combined_power(np.array([fold_angle]), connection)[0]
    return float(t_solar(power, day.study.p_load, day.step_hours))
