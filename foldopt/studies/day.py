"""One day's study: flat, twofold and tracked panels at one site, compared.

:class:`Day` is a view of one day of a :class:`foldopt.engine.sky.Sky` (times, sun, light, the electrical
model) that gives the power of each design as arrays over fold angles x time, for reports and for
the paper's heuristic; :func:`run_study` sweeps the fold angle through the engine, applies the
heuristic and tabulates the comparison, for the study's connection and for the others. The
tracker functions work on whole skies (every day at once).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
import pandas as pd

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
    Blocks,
    TrackerCurves,
    design_metrics,
    standby_available,
    tracker_curves,
)
from foldopt.studies.objectives import near_optimal
from foldopt.studies.storage_answer import day_storage
from foldopt.engine.sky import build_sky
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
        self.sky = sky = build_sky(study, [study.site], [study.date])
        self.electrical = engines.electrical_for(study, sky.temp_air[0], sky.wind_ref)
        self.times = sky.grid.times(0)
        self.step_hours = sky.step_hours
        self.solar_zenith, self.solar_azimuth = sky.solar_zenith[0], sky.solar_azimuth[0]
        self.hour_angle, self.declination = sky.hour_angle[0], sky.declination[0]
        self.sun_vector, self.dni = sky.sun_vector[0], sky.dni[0]
        self.ghi = None if sky.ghi is None else sky.ghi[0]
        self.dhi = None if sky.dhi is None else sky.dhi[0]
        self.transposition = study.sky_transposition()
        self._trackers: dict = {}
        self._one_angle: dict = {}

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
            self.study,
            self._poa(np.array([panel.tilt]), np.array([panel.azimuth])),
            panel.area,
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
            self.study, [panel.tilt], [panel.azimuth], np.atleast_1d(fold_angles)
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
            self.sky, self.study, self.orientation(fold_angles), [0], series, with_state
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


@dataclass(frozen=True)
class StudyResult:
    """One study's results (:func:`foldopt.run`).

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
    storage : foldopt.studies.storage_answer.DayStorage or None
        With the study's ``storage``: the load's powered time with the buffer per design and fold
        angle, and each design's buffer for its target; None for a storage-less study.
    standby : tuple
        (table, break-even draw [W]) of :func:`standby_sweep`.
    engine : str
    """

    study: Study
    day: Day
    sweep: pd.DataFrame
    summary: pd.DataFrame
    timeseries: pd.DataFrame
    optimal_fold_angle: float
    heuristic_fold_angle: float
    standby: tuple  # (table, break-even standby draw [W]) of :func:`standby_sweep`
    engine: str = DEFAULT_ENGINE
    near_optimal: dict = dataclasses.field(default_factory=dict)
    request: object = None  # the foldopt.studies.request.Request the study came from, if any
    storage: object = None  # the buffer's DayStorage (foldopt.studies.storage_answer), if any
    heuristic_outside: str = ""  # where the heuristic's angle lies off the study's fold angles

    @functools.cached_property
    def answer(self):
        """The :class:`foldopt.studies.answer.Answer` every view of this result renders."""
        from foldopt.studies.result_answers import of_study

        return of_study(self)


def _best_angle(day: Day, fold_angles, sweep_t_solar, connection, with_power: bool = False):
    """The best fold angle [deg] and its t_solar [h]: the sweep's best, refined between its
    neighbours; ``with_power``, also its power [W], (n_time,), the refinement's curve where the
    angle is one of the refinement's."""
    shape = None if day.sky.load_shape is None else day.sky.load_shape[0]
    evaluated = {}

    def compared(fold):
        power = day.combined_power(fold, connection)
        evaluated.update(zip(fold.tolist(), power))
        return per_load(power, shape)

    angle, hours = optimal_fold_angle(
        compared, fold_angles, sweep_t_solar, day.study.p_load, day.step_hours
    )
    if not with_power:
        return angle, hours
    power = evaluated.get(angle)
    return (
        angle,
        hours,
        day.combined_power(np.array([angle]), connection)[0] if power is None else power,
    )


def run_study(study: Study, engine: str = DEFAULT_ENGINE, request=None) -> StudyResult:
    """Sweep the fold angle and compare flat, twofold and tracker.

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
    study = day.study
    p_load, step = study.p_load, day.step_hours
    # A load profile: P_load(t) = p_load x shape(t). The flat-area multiple and the standby
    # break-even are defined for a constant load and are left out.
    shape = None if day.sky.load_shape is None else day.sky.load_shape[0]
    fold_angles = np.asarray(study.fold_angles.grid())
    metrics = engines.row_metrics(
        day.sky,
        study,
        np.zeros(fold_angles.size),
        day.orientation(fold_angles),
        [p_load],
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
            curves[study.connection], p_load, shape, step, metrics.t_solar[:, own, 0]
        )
    )
    sweep = pd.DataFrame(
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
        }
    )
    sweep["noon_valley_w"] = noon_valley(curves["east"], curves["west"], curves["parallel"])
    for index, connection in enumerate(CONNECTIONS):
        sweep[f"t_solar_{connection}_h"] = metrics.t_solar[:, index, 0]
        sweep[f"energy_harvested_{connection}_wh"] = metrics.energy[:, index]

    best_angle, best_hours = _best_angle(
        day, fold_angles, sweep["t_solar_h"].to_numpy(), study.connection
    )
    # The designs every study compares, each evaluated once, as for sweeps, annual studies and maps
    # (the study's tracker from the curve the figures draw); the others (the heuristic's angle, the
    # other connections, the other trackers) from their curves. The figures and the time series
    # draw the curves the flat and twofold rows were reduced from.
    tracker = day.tracker()
    main = design_metrics(
        day.sky,
        Blocks.of([study]),
        np.array([p_load]),
        np.array([best_angle]),
        np.zeros((1, 1), dtype=int),
        engine,
        tracker,
        curves=True,
    )
    drawn = main.pop("curves")
    p_flat = drawn["flat"][0]
    # Eq. 8 sets the parallel curve's noon valley to the load: with a profile, the load at solar
    # noon (the flat panel's peak).
    noon_load = p_load if shape is None else p_load * shape[int(np.argmax(p_flat))]

    def subpanels(fold):
        # An angle of the grid (the root search's bracket) from the grid's curves.
        at = np.flatnonzero(fold_angles == fold[0]) if fold.size == 1 else []
        return (
            tuple(curves[name][at[:1]] for name in ("east", "west", "parallel"))
            if len(at)
            else day.subpanel_power(fold)
        )

    # The rule's angle among the study's fold angles: one outside them is no design of the study.
    paper_angle, paper_outside = heuristic_fold_angle(
        subpanels, noon_load, lo=fold_angles[0], hi=fold_angles[-1]
    )

    others = {}
    if np.isfinite(paper_angle):
        others["twofold-heuristic"] = (paper_angle, day.combined_power(np.array([paper_angle]))[0])
    if day.electrical.pv.has_iv:
        for connection in ("parallel", "series", "independent", "switching"):
            if connection != study.connection:
                angle, _, power = _best_angle(
                    day,
                    fold_angles,
                    sweep[f"t_solar_{connection}_h"].to_numpy(),
                    connection,
                    with_power=True,
                )
                others[f"twofold-{connection}"] = (angle, power)
    # Every other tracker model follows the study's as "tracker:<model>"; each net row is what is
    # left for the load after the tracker's own draw.
    for model in (m for m in TRACKERS if m != study.tracker.model):
        others[f"tracker:{model}"] = (np.nan, day.tracker(model).power[0])
        others[f"tracker:{model}-net"] = (np.nan, day.tracker(model).net[0])
    power = np.stack([power for _, power in others.values()])
    curve = engines.curve_metrics(
        power, [p_load], step, contiguous=True, engine=engine, load_shape=shape
    )
    served = (
        None if shape is None else energy_served(power, p_load, shape, step, curve.t_solar[:, 0, 0])
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
        "twofold": best_angle,
        **{name: angle for name, (angle, _) in others.items() if name.startswith("twofold")},
        "tracker": np.nan,
        "tracker-net": np.nan,
        **{name: angle for name, (angle, _) in others.items() if name.startswith("tracker")},
    }
    order = [[*DESIGNS, *others].index(name) for name in angle_of]
    summary = pd.DataFrame(
        {
            "design": list(angle_of),
            "fold_angle_deg": list(angle_of.values()),
            **{
                name: np.concatenate([main[name][0, 0], values])[order]
                for name, values in columns.items()
            },
        }
    )
    by_design = summary.set_index("design")["t_solar_h"]
    flat_hours, tracker_hours = by_design["flat"], by_design["tracker"]
    summary["gain_vs_flat_pct"] = (relative_to(summary["t_solar_h"], flat_hours) - 1.0) * 100.0
    summary["share_of_tracker_pct"] = relative_to(summary["t_solar_h"], tracker_hours) * 100.0
    summary["flat_area_ratio"] = [
        flat_area_ratio(p_flat, p_load, hours, step) if hours > 0 and shape is None else np.nan
        for hours in summary["t_solar_h"]
    ]
    # Each row's circuit first: a connection the study's circuit cannot wire (independent's
    # converters, a load wired directly) is compared as it is built and says so; every other design
    # is wired as the circuit says, and says so where its load is beyond the panel's reach.
    wired = {
        f"twofold-{connection}": study.circuit.ignored_by(connection) for connection in CONNECTIONS
    }
    condition = [
        "; ".join(
            filter(
                None, (wired.get(design) or day.electrical.beyond_reach, day.sky.conditions()[0])
            )
        )
        for design in summary["design"]
    ]
    summary["note"] = notes(
        design_condition(condition, summary["energy_harvested_wh"].to_numpy(float)),
        summary["t_solar_h"].to_numpy(),
    )
    standby = standby_sweep(day, tracker.power[0], by_design["twofold"])
    buffered = None
    if study.storage is not None:
        # Every row's curve, the one its t_solar was reduced from, through the study's buffer; a
        # net tracker's whole power, with its own draw a load beside the device's.
        nets = {
            "tracker-net": tracker,
            **{f"tracker:{m}-net": day.tracker(m) for m in TRACKERS if m != study.tracker.model},
        }
        power_of = {
            "flat": p_flat,
            "twofold": drawn[study.connection][0, 0],
            "tracker": tracker.power[0],
            **{name: power for name, (_, power) in others.items()},
            **{name: net.power[0] for name, net in nets.items()},
        }
        own_series = study.connection == "series" or study.switch_series
        buffered = day_storage(
            study,
            step,
            p_load if shape is None else (p_load * shape)[None, :],
            fold_angles,
            curves[study.connection]
            if series or not own_series
            else day.combined_power(fold_angles),
            {name: (angle, power_of[name]) for name, angle in angle_of.items()},
            summary["t_solar_h"].to_numpy(),
            engine,
            {name: net.draw[0] for name, net in nets.items()},
        )
        summary = pd.concat([summary, buffered.designs.iloc[:, 3:]], axis=1)
        sweep["powered_h"] = buffered.powered_by_angle

    at_best = {connection: drawn[connection][0, 0] for connection in CONNECTIONS}
    # The state switching chose (no table's number comes from it) from the reference path's parts.
    state = day.connections(np.array([best_angle]))[1][0]
    timeseries = pd.DataFrame(
        {
            "solar_zenith": day.solar_zenith,
            "solar_azimuth": day.solar_azimuth,
            "dni": day.dni,
            # The light and air every step of the day used (the weather's, or the clear sky's).
            **({"ghi": day.ghi, "dhi": day.dhi} if day.ghi is not None else {}),
            "temp_air": (
                day.sky.temp_steps[0]
                if day.sky.temp_steps is not None
                else np.full(day.dni.shape, day.sky.temp_air[0])
            ),
            **({"wind_speed": day.sky.wind_speed[0]} if day.sky.wind_speed is not None else {}),
            "p_flat_w": p_flat,
            **{f"p_{connection}_w": at_best[connection] for connection in CONNECTIONS},
            "p_twofold_w": at_best[study.connection],
            "switch_state": np.where(
                at_best["switching"] > 0, np.array(SWITCH_STATES)[state], "off"
            ),
            "p_tracker_w": tracker.power[0],
            "p_load_w": p_load if shape is None else p_load * shape,
            **(
                {}
                if buffered is None
                else {f"soc_{name}_frac": soc for name, soc in buffered.soc.items()}
            ),
        },
        index=pd.DatetimeIndex(day.times, name="time"),
    )
    # The range is taken over every angle evaluated, the refined optimum among the grid's, so that it
    # holds the best angle (the grid's own range may end on the far side of a refined optimum).
    evaluated = sweep.set_index("fold_angle_deg")["t_solar_h"]
    evaluated = pd.concat(
        [evaluated[evaluated.index != best_angle], pd.Series({best_angle: best_hours})]
    ).sort_index()
    near = {
        key: float(value)
        for key, value in near_optimal(
            evaluated.index, evaluated.to_numpy(), study.near_optimal
        ).items()
    }
    recommended = near["recommended_deg"]
    near["recommended_t_solar_h"] = (
        float(evaluated[recommended]) if recommended == recommended else float("nan")
    )
    return StudyResult(
        study,
        day,
        sweep,
        summary,
        timeseries,
        best_angle,
        paper_angle,
        standby,
        engine,
        near,
        request,
        buffered,
        paper_outside,
    )


def standby_sweep(day: Day, p_tracker, twofold_t_solar: float, points: int = 101):
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
    table : pandas.DataFrame
        ``standby_w``, ``t_solar_tracker_net_h``, ``t_solar_twofold_h``.
    break_even_w : float
        Standby draw [W] above which the twofold panel runs longer; NaN if it never does.
    """
    study, step = day.study, day.step_hours
    if day.sky.load_shape is not None:  # a standby draw is a load shift only for a constant load
        return pd.DataFrame(
            {
                "standby_w": [0.0],
                "t_solar_tracker_net_h": [np.nan],
                "t_solar_twofold_h": [twofold_t_solar],
            }
        ), float("nan")
    available = standby_available(
        p_tracker, day.tracker_draw(), day.sky.lit[0], study.tracker.standby_w
    )
    draws = np.linspace(0.0, max(2.0 * study.p_load, 1e-3), points)
    hours = t_solar(available, study.p_load + draws, step)
    load = load_for_t_solar(available, twofold_t_solar, step) if twofold_t_solar > 0 else np.nan
    break_even = max(load - study.p_load, 0.0) if np.isfinite(load) else float("nan")
    table = pd.DataFrame(
        {"standby_w": draws, "t_solar_tracker_net_h": hours, "t_solar_twofold_h": twofold_t_solar}
    )
    return table, break_even


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
